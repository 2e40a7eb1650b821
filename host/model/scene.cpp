// host/model/scene.cpp — scene JSON (DESIGN.md, "Scene files and the command line"): parsing with line and
// column on malformed text, `--set` overrides, key-by-key validation, the embedded default scene, and
// the camera that fits a bounding box. Every error is an InputError that starts with the file's name, but
// those of "volume" and "mesh" (host/model/data_spec.cpp), which keep the readers' messages.
#include "host/model/scene.h"

#include "host/runtime/errors.h"

#include <glm/gtc/constants.hpp>

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <fstream>
#include <limits>
#include <set>
#include <sstream>
#include <string_view>

namespace clvr {
namespace {

using nlohmann::json;

// data/scenes/default.json, byte for byte (tests/scene_test.cpp holds the two equal).
constexpr std::string_view kDefaultSceneJson = R"json({
  "technique": "slice3d",
  "volume": {"generator": "marschner-lobb", "dims": [128, 128, 128]},
  "camera": {
    "position": [3.3, 2.4, 4.8],
    "focal_point": [0, 0, 0],
    "view_up": [0, 1, 0],
    "view_angle": 30
  },
  "image": {"width": 512, "height": 512, "background": [0, 0, 0]},
  "transfer_function": {
    "points": [
      [0.00, 0.00, 0.00, 0.00, 0.0],
      [0.35, 0.10, 0.20, 0.80, 0.0],
      [0.45, 0.20, 0.40, 1.00, 2.0],
      [0.55, 0.20, 0.90, 0.50, 0.0],
      [0.72, 1.00, 0.80, 0.20, 0.0],
      [0.80, 1.00, 0.50, 0.10, 6.0],
      [0.88, 1.00, 0.20, 0.10, 0.0],
      [1.00, 1.00, 1.00, 1.00, 20.0]
    ]
  },
  "options": {"slices": 256}
}
)json";

constexpr int kMaxImageSize = 16384;

std::string joinKeys(std::initializer_list<std::string_view> keys)
{
    std::string out;
    for (std::string_view k : keys) {
        if (!out.empty())
            out += ", ";
        out += k;
    }
    return out;
}

std::string keyPath(const std::string& parent, std::string_view key)
{
    return parent.empty() ? std::string(key) : parent + "." + std::string(key);
}

// 1-based line and column of byte offset `pos` (0-based) in `text`.
std::pair<std::size_t, std::size_t> lineColumn(std::string_view text, std::size_t pos)
{
    pos = std::min(pos, text.size());
    std::size_t line = 1, column = 1;
    for (std::size_t i = 0; i < pos; ++i) {
        if (text[i] == '\n') {
            ++line;
            column = 1;
        } else {
            ++column;
        }
    }
    return {line, column};
}

// nlohmann's message without its "[json.exception...] parse error at line L, column C: " prefix.
std::string parseErrorDetail(const json::parse_error& e)
{
    std::string what = e.what();
    const std::size_t colon = what.find(": ");
    if (what.rfind("[json.exception", 0) == 0 && colon != std::string::npos)
        what = what.substr(colon + 2);
    return what;
}

// Parses `text`; a duplicated object key is an error too (nlohmann would silently keep the last one).
json parseJson(std::string_view text, const std::string& label, std::string_view kind = "JSON")
{
    std::vector<std::set<std::string>> seen;  // keys of each object being parsed, innermost last
    std::string duplicate;
    json::parser_callback_t callback = [&](int, json::parse_event_t event, json& parsed) {
        if (event == json::parse_event_t::object_start) {
            seen.emplace_back();
        } else if (event == json::parse_event_t::object_end) {
            if (!seen.empty())
                seen.pop_back();
        } else if (event == json::parse_event_t::key && !seen.empty() && parsed.is_string()) {
            if (!seen.back().insert(parsed.get<std::string>()).second && duplicate.empty())
                duplicate = parsed.get<std::string>();
        }
        return true;
    };
    json result;
    try {
        result = json::parse(text.begin(), text.end(), callback);
    } catch (const json::parse_error& e) {
        // e.byte: 1-based index of the last byte read, where the parser gave up.
        const auto [line, column] = lineColumn(text, e.byte > 0 ? e.byte - 1 : 0);
        throw InputError(label + ": malformed " + std::string(kind) + " at line " + std::to_string(line) + ", column " +
                         std::to_string(column) + ": " + parseErrorDetail(e));
    } catch (const json::out_of_range& e) {
        // A number too large for a double ("1e999" would be infinite): point at its first occurrence.
        const std::string what = e.what();
        const std::size_t q0 = what.find('\''), q1 = what.rfind('\'');
        const std::string literal = q0 != std::string::npos && q1 > q0 ? what.substr(q0 + 1, q1 - q0 - 1) : "";
        const std::size_t at = literal.empty() ? std::string_view::npos : text.find(literal);
        std::string where;
        if (at != std::string_view::npos) {
            const auto [line, column] = lineColumn(text, at);
            where = " at line " + std::to_string(line) + ", column " + std::to_string(column);
        }
        throw InputError(label + ": malformed " + std::string(kind) + where + ": number " +
                         (literal.empty() ? std::string("out of range") : literal + " is out of range") +
                         " (every number must be finite)");
    }
    if (!duplicate.empty())
        throw InputError(label + ": duplicate key \"" + duplicate + "\"");
    return result;
}

// Splits "a.b.c" into its keys; `where` prefixes the error for an empty key.
std::vector<std::string> splitPath(const std::string& path, const std::string& where)
{
    std::vector<std::string> keys;
    std::size_t start = 0;
    while (true) {
        const std::size_t dot = path.find('.', start);
        keys.push_back(path.substr(start, dot == std::string::npos ? std::string::npos : dot - start));
        if (keys.back().empty())
            throw InputError(where + ": empty key in path \"" + path + "\"");
        if (dot == std::string::npos)
            return keys;
        start = dot + 1;
    }
}

// Applies one `--set path=json` to `root`: intermediate objects are created; the value is parsed as
// JSON, or taken as a plain string when it is not JSON (so technique=slice3d works).
void applyOverride(json& root, const std::string& override, const std::string& label)
{
    const std::string where = label + ": --set \"" + override + "\"";
    const std::size_t eq = override.find('=');
    if (eq == std::string::npos || eq == 0)
        throw InputError(where + ": expected path=value, e.g. camera.view_angle=20");
    const std::string path = override.substr(0, eq);
    const std::string valueText = override.substr(eq + 1);

    const std::vector<std::string> keys = splitPath(path, where);

    json value;
    const std::size_t first = valueText.find_first_not_of(" \t");
    const char lead = first == std::string::npos ? '\0' : valueText[first];
    if (json::accept(valueText)) {
        value = json::parse(valueText);
    } else if (lead == '{' || lead == '[' || lead == '"') {
        // Clearly meant as JSON: say where it breaks rather than passing it on as a string.
        value = parseJson(valueText, where, "value");
    } else {
        value = valueText;
    }

    json* node = &root;
    std::string walked;
    for (std::size_t i = 0; i + 1 < keys.size(); ++i) {
        walked = keyPath(walked, keys[i]);
        json& child = (*node)[keys[i]];
        if (child.is_null())
            child = json::object();
        else if (!child.is_object())
            throw InputError(where + ": \"" + walked + "\" is not an object");
        node = &child;
    }
    (*node)[keys.back()] = std::move(value);
}

// Checks one JSON value against what the scene format allows; `label` prefixes every message.
class Checker {
public:
    explicit Checker(std::string label) : label_(std::move(label)) {}

    [[noreturn]] void fail(const std::string& message) const { throw InputError(label_ + ": " + message); }

    const std::string& label() const { return label_; }

    void object(const json& v, const std::string& path) const
    {
        if (!v.is_object())
            fail(path + " must be an object");
    }

    void knownKeys(const json& obj, const std::string& path, std::initializer_list<std::string_view> known) const
    {
        for (const auto& [key, value] : obj.items()) {
            if (std::find(known.begin(), known.end(), key) == known.end())
                fail("unknown key \"" + keyPath(path, key) + "\" (known: " + joinKeys(known) + ")");
        }
    }

    double number(const json& v, const std::string& path) const
    {
        if (!v.is_number())
            fail(path + " must be a number");
        const double x = v.get<double>();
        if (!std::isfinite(x))
            fail(path + " must be a finite number");
        return x;
    }

    int integer(const json& v, const std::string& path, int lo, int hi) const
    {
        if (!v.is_number_integer())
            fail(path + " must be an integer");
        const auto x = v.get<std::int64_t>();
        if (x < lo || x > hi)
            fail(path + " must be in " + std::to_string(lo) + ".." + std::to_string(hi) + ", got " + v.dump());
        return static_cast<int>(x);
    }

    std::string string(const json& v, const std::string& path) const
    {
        if (!v.is_string())
            fail(path + " must be a string");
        return v.get<std::string>();
    }

    glm::dvec3 vec3(const json& v, const std::string& path) const
    {
        if (!v.is_array() || v.size() != 3)
            fail(path + " must be an array of 3 numbers");
        return {number(v[0], path + "[0]"), number(v[1], path + "[1]"), number(v[2], path + "[2]")};
    }

    glm::dvec3 color(const json& v, const std::string& path) const
    {
        const glm::dvec3 c = vec3(v, path);
        for (int i = 0; i < 3; ++i)
            if (c[i] < 0.0 || c[i] > 1.0)
                fail(path + " must have components in [0, 1]");
        return c;
    }

    double nonNegative(const json& v, const std::string& path) const
    {
        const double x = number(v, path);
        if (x < 0.0)
            fail(path + " must be >= 0, got " + v.dump());
        return x;
    }

private:
    std::string label_;
};

Camera parseCamera(const Checker& check, const json& v)
{
    check.object(v, "camera");
    check.knownKeys(v, "camera",
                    {"position", "focal_point", "view_up", "view_angle", "projection", "parallel_scale"});
    Camera camera;
    if (v.contains("position"))
        camera.position = check.vec3(v["position"], "camera.position");
    if (v.contains("focal_point"))
        camera.focalPoint = check.vec3(v["focal_point"], "camera.focal_point");
    if (v.contains("view_up"))
        camera.viewUp = check.vec3(v["view_up"], "camera.view_up");
    if (v.contains("view_angle"))
        camera.viewAngle = check.number(v["view_angle"], "camera.view_angle");
    if (v.contains("projection")) {
        const std::string p = check.string(v["projection"], "camera.projection");
        if (p != "perspective" && p != "parallel")
            check.fail("camera.projection must be \"perspective\" or \"parallel\", got \"" + p + "\"");
        camera.parallel = p == "parallel";
    }
    if (v.contains("parallel_scale"))
        camera.parallelScale = check.number(v["parallel_scale"], "camera.parallel_scale");
    try {
        camera.validate();
    } catch (const InputError& e) {
        check.fail(e.what());
    }
    return camera;
}

ImageSpec parseImage(const Checker& check, const json& v)
{
    check.object(v, "image");
    check.knownKeys(v, "image", {"width", "height", "background"});
    ImageSpec image;
    if (v.contains("width"))
        image.width = check.integer(v["width"], "image.width", 1, kMaxImageSize);
    if (v.contains("height"))
        image.height = check.integer(v["height"], "image.height", 1, kMaxImageSize);
    if (v.contains("background"))
        image.background = check.color(v["background"], "image.background");
    return image;
}

TransferFunction parseTransferFunction(const Checker& check, const json& v)
{
    check.object(v, "transfer_function");
    check.knownKeys(v, "transfer_function", {"points"});
    if (!v.contains("points"))
        check.fail("transfer_function.points is missing (a list of [s, r, g, b, tau])");
    const json& points = v["points"];
    if (!points.is_array())
        check.fail("transfer_function.points must be an array of [s, r, g, b, tau]");
    std::vector<ControlPoint> out;
    for (std::size_t i = 0; i < points.size(); ++i) {
        const std::string path = "transfer_function.points[" + std::to_string(i) + "]";
        const json& p = points[i];
        if (!p.is_array() || p.size() != 5)
            check.fail(path + " must be an array of 5 numbers [s, r, g, b, tau]");
        ControlPoint cp;
        cp.s = check.number(p[0], path + "[0]");
        for (int c = 0; c < 3; ++c)
            cp.color[c] = check.number(p[c + 1], path + "[" + std::to_string(c + 1) + "]");
        cp.tau = check.number(p[4], path + "[4]");
        out.push_back(cp);
    }
    try {
        return TransferFunction(std::move(out));
    } catch (const InputError& e) {
        check.fail(e.what());
    }
}

IsoSpec parseIso(const Checker& check, const json& v)
{
    check.object(v, "iso");
    check.knownKeys(v, "iso", {"value", "shading", "light", "ambient", "diffuse"});
    if (!v.contains("value"))
        check.fail("iso.value is missing");
    IsoSpec iso;
    iso.value = check.number(v["value"], "iso.value");
    if (v.contains("shading")) {
        const std::string s = check.string(v["shading"], "iso.shading");
        if (s == "gradient")
            iso.shading = IsoSpec::Shading::Gradient;
        else if (s == "gradientless")
            iso.shading = IsoSpec::Shading::Gradientless;
        else if (s == "none")
            iso.shading = IsoSpec::Shading::None;
        else
            check.fail("iso.shading must be \"gradient\", \"gradientless\" or \"none\", got \"" + s + "\"");
    }
    if (v.contains("light")) {
        const glm::dvec3 l = check.vec3(v["light"], "iso.light");
        if (glm::length(l) == 0.0)
            check.fail("iso.light must not be the zero vector");
        iso.light = glm::normalize(l);
    }
    if (v.contains("ambient"))
        iso.ambient = check.nonNegative(v["ambient"], "iso.ambient");
    if (v.contains("diffuse"))
        iso.diffuse = check.nonNegative(v["diffuse"], "iso.diffuse");
    return iso;
}

std::vector<DirectionalLight> parseLights(const Checker& check, const json& v)
{
    if (!v.is_array())
        check.fail("lights must be an array of {\"direction\": [x,y,z], \"color\": [r,g,b]}");
    std::vector<DirectionalLight> lights;
    for (std::size_t i = 0; i < v.size(); ++i) {
        const std::string path = "lights[" + std::to_string(i) + "]";
        check.object(v[i], path);
        check.knownKeys(v[i], path, {"direction", "color"});
        if (!v[i].contains("direction"))
            check.fail(path + ".direction is missing");
        DirectionalLight light;
        const glm::dvec3 d = check.vec3(v[i]["direction"], path + ".direction");
        if (glm::length(d) == 0.0)
            check.fail(path + ".direction must not be the zero vector");
        light.direction = glm::normalize(d);
        if (v[i].contains("color"))
            light.color = check.color(v[i]["color"], path + ".color");
        lights.push_back(light);
    }
    return lights;
}

Material parseMaterial(const Checker& check, const json& v)
{
    check.object(v, "material");
    check.knownKeys(v, "material", {"ambient", "diffuse", "specular", "shininess"});
    Material m;
    const std::pair<const char*, double*> fields[] = {
        {"ambient", &m.ambient}, {"diffuse", &m.diffuse}, {"specular", &m.specular}, {"shininess", &m.shininess}};
    for (const auto& [key, field] : fields)
        if (v.contains(key))
            *field = check.nonNegative(v[key], keyPath("material", key));
    return m;
}

// Applies one `--unset path` to `root`: the key is removed; a path that is not in the scene is an error.
void applyUnset(json& root, const std::string& path, const std::string& label)
{
    const std::string where = label + ": --unset \"" + path + "\"";
    if (path.empty())
        throw InputError(where + ": expected a key path, e.g. camera or options.slices");
    const std::vector<std::string> keys = splitPath(path, where);
    json* node = &root;
    for (std::size_t i = 0; i + 1 < keys.size(); ++i) {
        if (!node->is_object() || !node->contains(keys[i]))
            break;
        node = &(*node)[keys[i]];
    }
    if (!node->is_object() || !node->contains(keys.back()))
        throw InputError(where + ": the scene has no key \"" + path + "\"");
    node->erase(keys.back());
}

Scene parseSceneJson(json root, const std::string& label, const std::filesystem::path& baseDir,
                     const std::vector<std::string>& overrides, const std::vector<std::string>& unsets)
{
    const Checker check(label);
    if (!root.is_object())
        check.fail("a scene must be a JSON object, got " + std::string(root.type_name()));
    for (const std::string& u : unsets)
        applyUnset(root, u, label);
    for (const std::string& o : overrides)
        applyOverride(root, o, label);

    check.knownKeys(root, "", {"technique", "volume", "mesh", "camera", "image", "transfer_function", "options",
                               "iso", "lights", "material", "distribution"});
    Scene scene;
    scene.baseDir = baseDir;
    if (root.contains("technique")) {
        scene.technique = check.string(root["technique"], "technique");
        if (scene.technique.empty())
            check.fail("technique must not be empty");
    }
    for (const char* key : {"volume", "mesh"}) {
        if (root.contains(key))
            check.object(root[key], key);
    }
    if (root.contains("volume"))
        scene.volume = parseVolumeSpec(root["volume"], baseDir);
    if (root.contains("mesh"))
        scene.mesh = parseMeshSpec(root["mesh"], baseDir);
    if (!scene.volume && !scene.mesh)
        check.fail("the scene has neither \"volume\" nor \"mesh\"");
    if (root.contains("camera"))
        scene.camera = parseCamera(check, root["camera"]);
    if (root.contains("image"))
        scene.image = parseImage(check, root["image"]);
    if (root.contains("options")) {
        check.object(root["options"], "options");
        scene.options = root["options"];
    }
    if (root.contains("distribution")) {
        scene.distribution = check.string(root["distribution"], "distribution");
        try {
            checkDistribution(scene.distribution, "distribution");
        } catch (const InputError& e) {
            check.fail(e.what());  // with the scene's label
        }
    }
    if (root.contains("iso"))
        scene.iso = parseIso(check, root["iso"]);
    if (root.contains("lights"))
        scene.lighting.lights = parseLights(check, root["lights"]);
    if (root.contains("material"))
        scene.lighting.material = parseMaterial(check, root["material"]);
    if (root.contains("transfer_function"))
        scene.transferFunction = parseTransferFunction(check, root["transfer_function"]);
    else if (!scene.iso)
        check.fail("transfer_function is missing (only iso-surface scenes, with \"iso\", may leave it out)");
    return scene;
}

}  // namespace

const char* shadingName(IsoSpec::Shading shading)
{
    switch (shading) {
    case IsoSpec::Shading::Gradient: return "gradient";
    case IsoSpec::Shading::Gradientless: return "gradientless";
    case IsoSpec::Shading::None: return "none";
    }
    throw InternalError("shadingName: unknown IsoSpec::Shading " + std::to_string(static_cast<int>(shading)));
}

void checkDistribution(const std::string& name, const std::string& where)
{
    if (name != "sort-last" && name != "sort-first" && name != "frames")
        throw InputError(where + ": unknown distribution \"" + name + "\" (known: sort-last, sort-first, frames)");
}

Scene parseScene(const std::string& text, const std::string& label, const std::filesystem::path& baseDir,
                 const std::vector<std::string>& overrides, const std::vector<std::string>& unsets)
{
    return parseSceneJson(parseJson(text, label), label, baseDir, overrides, unsets);
}

Scene loadScene(const std::filesystem::path& path, const std::vector<std::string>& overrides,
                const std::vector<std::string>& unsets)
{
    const std::string label = path.string();
    std::error_code ec;
    if (std::filesystem::is_directory(path, ec))
        throw InputError(label + ": is a directory, not a scene file");
    if (!std::filesystem::exists(path, ec))
        throw InputError(label + ": no such scene file");
    std::ifstream in(path, std::ios::binary);
    if (!in)
        throw InputError(label + ": cannot open the scene file for reading");
    std::ostringstream text;
    text << in.rdbuf();
    if (in.bad())
        throw InputError(label + ": read error");
    return parseScene(text.str(), label, path.parent_path(), overrides, unsets);
}

Scene defaultScene(const std::vector<std::string>& overrides, const std::vector<std::string>& unsets)
{
    return parseScene(std::string(kDefaultSceneJson), "default scene", {}, overrides, unsets);
}

Camera fitCamera(const glm::dvec3& lo, const glm::dvec3& hi, double viewAngle)
{
    // vtkRenderer::ResetCamera: the bounding sphere of the box fills the view angle; the camera looks
    // down -z at the center with +y up.
    const glm::dvec3 center = 0.5 * (lo + hi);
    double radius = 0.5 * glm::length(hi - lo);
    if (!(radius > 0.0) || !std::isfinite(radius))
        radius = 1.0;
    const double halfAngle = glm::radians(viewAngle) * 0.5;
    const double distance = radius / std::sin(halfAngle);
    Camera camera;
    camera.focalPoint = center;
    camera.position = center + glm::dvec3(0.0, 0.0, distance);
    camera.viewUp = {0.0, 1.0, 0.0};
    camera.viewAngle = viewAngle;
    camera.parallelScale = radius;
    return camera;
}

}  // namespace clvr
