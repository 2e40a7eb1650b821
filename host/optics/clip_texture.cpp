// host/optics/clip_texture.cpp — the stencil texture of slice3d's clip_texture option: parsing, signed-distance
// textures of analytic shapes, voxel masks, the placement as texture coordinates, and the reference
// intervals (exact for shapes; the texture's own crossings for any texture).
#include "host/optics/clip_texture.h"

#include "host/runtime/errors.h"
#include "host/model/json_values.h"
#include "host/io/volume_io.h"

#include <nlohmann/json.hpp>

#include <algorithm>
#include <cmath>
#include <limits>

namespace clvr {
namespace {

using nlohmann::json;
namespace fs = std::filesystem;

// Analytic textures: this many texels of margin around the shape's bounding box on each side, so the
// shape never touches the box of texel centers and the zero level set is interpolated inside it.
constexpr int kMarginTexels = 2;
constexpr int kMinResolution = 8, kMaxResolution = 512;

glm::dmat3 matrix3(const json& v, const std::string& key)
{
    auto row = [](const json& r) {
        return r.is_array() && r.size() == 3 && std::all_of(r.begin(), r.end(), [](const json& x) { return x.is_number(); });
    };
    if (!v.is_array() || v.size() != 3 || !std::all_of(v.begin(), v.end(), row))
        badKey(key, "must be a 3x3 matrix [[a, b, c], [d, e, f], [g, h, i]] (rows), got " + v.dump());
    glm::dmat3 m;
    double norm = 0.0;
    for (int r = 0; r < 3; ++r)
        for (int c = 0; c < 3; ++c) {
            const double x = v[r][c].get<double>();
            if (!std::isfinite(x))
                badKey(key, "must be finite, got " + v.dump());
            m[c][r] = x;  // glm is column-major
            norm = std::max(norm, std::abs(x));
        }
    if (!(std::abs(glm::determinant(m)) > 1e-12 * norm * norm * norm))
        badKey(key, "must be invertible (its determinant is 0), got " + v.dump());
    return m;
}

// The shape's axis-aligned bounding box, before the placement.
void shapeBounds(const ClipTextureSpec& s, glm::dvec3& lo, glm::dvec3& hi)
{
    switch (s.shape) {
    case ClipTextureSpec::Shape::Sphere:
        lo = s.center - s.radius;
        hi = s.center + s.radius;
        return;
    case ClipTextureSpec::Shape::Box:
        lo = s.min;
        hi = s.max;
        return;
    case ClipTextureSpec::Shape::Cylinder: {
        const glm::dvec3 a = glm::normalize(s.axis);
        const glm::dvec3 e = 0.5 * s.height * glm::abs(a) + s.radius * glm::sqrt(glm::max(1.0 - a * a, 0.0));
        lo = s.center - e;
        hi = s.center + e;
        return;
    }
    case ClipTextureSpec::Shape::Mask:
        break;
    }
    lo = hi = glm::dvec3(0.0);
}

// The ray in the shape's own frame (before the placement): the parameter t is unchanged.
Ray toShapeFrame(const glm::dvec3& pivot, const ClipTextureSpec& s, const Ray& ray)
{
    const glm::dmat3 inv = glm::inverse(s.matrix);
    return {pivot + inv * (ray.origin - pivot - s.offset), inv * ray.direction};
}

// Roots of A t^2 + B t + C = 0 (A > 0) where the quadratic is negative: false when it never is.
bool negativeBetween(double A, double B, double C, double& ta, double& tb)
{
    const double disc = B * B - 4.0 * A * C;
    if (!(disc > 0.0))
        return false;
    const double q = -0.5 * (B + std::copysign(std::sqrt(disc), B));
    double r0 = q / A, r1 = q != 0.0 ? C / q : r0;
    if (r0 > r1)
        std::swap(r0, r1);
    ta = r0;
    tb = r1;
    return true;
}

// Where lo <= w + t d <= hi along one axis; false when nowhere.
bool slab(double w, double d, double lo, double hi, double& ta, double& tb)
{
    if (d == 0.0) {
        ta = -std::numeric_limits<double>::infinity();
        tb = std::numeric_limits<double>::infinity();
        return w >= lo && w <= hi;
    }
    ta = (lo - w) / d;
    tb = (hi - w) / d;
    if (ta > tb)
        std::swap(ta, tb);
    return true;
}

// The pieces of [t0, t1] inside [a, b] (inverse: outside it).
std::vector<glm::dvec2> piecesOf(bool hit, double a, double b, double t0, double t1, bool inverse)
{
    std::vector<glm::dvec2> out;
    const double lo = std::max(a, t0), hi = std::min(b, t1);
    const bool overlap = hit && lo < hi;
    if (!inverse) {
        if (overlap)
            out.push_back({lo, hi});
        return out;
    }
    if (!overlap)
        return {{t0, t1}};
    if (lo > t0)
        out.push_back({t0, lo});
    if (hi < t1)
        out.push_back({hi, t1});
    return out;
}

}  // namespace

ClipTextureSpec parseClipTextureSpec(const json& spec, const std::string& key)
{
    if (!spec.is_object())
        badKey(key, "must be an object such as {\"shape\": \"sphere\", \"center\": [0, 0, 0], \"radius\": 0.5} or "
                    "{\"mask\": \"mask.nrrd\"}, got " + spec.dump());
    if (spec.contains("shape") == spec.contains("mask"))
        badKey(key, "give either \"shape\" (\"sphere\", \"box\" or \"cylinder\") or \"mask\" (a volume file)");
    ClipTextureSpec s;
    std::vector<std::string> known;
    if (spec.contains("mask")) {
        s.shape = ClipTextureSpec::Shape::Mask;
        known = {"mask", "inverse", "offset", "matrix"};
        const json& m = spec["mask"];
        if (m.is_string() && !m.get<std::string>().empty()) {
            s.maskFile = m.get<std::string>();
            s.maskSpec = json{{"file", s.maskFile}}.dump();
        } else if (m.is_object() && m.contains("file") && m["file"].is_string()) {
            s.maskFile = m["file"].get<std::string>();
            s.maskSpec = m.dump();
        } else {
            badKey(key + ".mask", "must be a volume file name (.nrrd, .nhdr, .vtk) or a volume object "
                                  "{\"file\": ..., \"dims\": ...}, got " + m.dump());
        }
    } else {
        const json& g = spec["shape"];
        const std::string name = g.is_string() ? g.get<std::string>() : "";
        if (name == "sphere") {
            s.shape = ClipTextureSpec::Shape::Sphere;
            known = {"shape", "center", "radius", "resolution", "inverse", "offset", "matrix"};
        } else if (name == "box") {
            s.shape = ClipTextureSpec::Shape::Box;
            known = {"shape", "min", "max", "resolution", "inverse", "offset", "matrix"};
        } else if (name == "cylinder") {
            s.shape = ClipTextureSpec::Shape::Cylinder;
            known = {"shape", "center", "axis", "radius", "height", "resolution", "inverse", "offset", "matrix"};
        } else {
            badKey(key + ".shape", "must be \"sphere\", \"box\" or \"cylinder\", got " + g.dump());
        }
    }
    std::string list;
    for (const std::string& k : known)
        list += (list.empty() ? "" : ", ") + k;
    for (const auto& [k, v] : spec.items())
        if (std::find(known.begin(), known.end(), k) == known.end())
            badKey(key + "." + k, "unknown key (known: " + list + ")");
    if (spec.contains("center"))
        s.center = jsonVec3(spec["center"], key + ".center");
    if (spec.contains("radius"))
        s.radius = jsonPositive(spec["radius"], key + ".radius");
    if (spec.contains("height"))
        s.height = jsonPositive(spec["height"], key + ".height");
    if (spec.contains("axis")) {
        s.axis = jsonVec3(spec["axis"], key + ".axis");
        if (glm::length(s.axis) == 0.0)
            badKey(key + ".axis", "must not be zero");
    }
    if (spec.contains("min"))
        s.min = jsonVec3(spec["min"], key + ".min");
    if (spec.contains("max"))
        s.max = jsonVec3(spec["max"], key + ".max");
    if (s.shape == ClipTextureSpec::Shape::Box && !(s.min.x < s.max.x && s.min.y < s.max.y && s.min.z < s.max.z))
        badKey(key + ".max", "must be greater than min in x, y and z");
    if (spec.contains("resolution")) {
        const json& v = spec["resolution"];
        if (!v.is_number_integer() || v.get<long long>() < kMinResolution || v.get<long long>() > kMaxResolution)
            badKey(key + ".resolution", "must be an integer in [" + std::to_string(kMinResolution) + ", " +
                                            std::to_string(kMaxResolution) + "], got " + v.dump());
        s.resolution = v.get<int>();
    }
    if (spec.contains("inverse")) {
        if (!spec["inverse"].is_boolean())
            badKey(key + ".inverse", "must be true or false, got " + spec["inverse"].dump());
        s.inverse = spec["inverse"].get<bool>();
    }
    if (spec.contains("offset"))
        s.offset = jsonVec3(spec["offset"], key + ".offset");
    if (spec.contains("matrix"))
        s.matrix = matrix3(spec["matrix"], key + ".matrix");
    return s;
}

double shapeSignedDistance(const ClipTextureSpec& s, const glm::dvec3& p)
{
    switch (s.shape) {
    case ClipTextureSpec::Shape::Sphere:
        return glm::length(p - s.center) - s.radius;
    case ClipTextureSpec::Shape::Box: {
        const glm::dvec3 q = glm::abs(p - 0.5 * (s.min + s.max)) - 0.5 * (s.max - s.min);
        return glm::length(glm::max(q, 0.0)) + std::min(std::max({q.x, q.y, q.z}), 0.0);
    }
    case ClipTextureSpec::Shape::Cylinder: {
        const glm::dvec3 a = glm::normalize(s.axis), w = p - s.center;
        const double h = glm::dot(w, a);
        const glm::dvec2 d(glm::length(w - h * a) - s.radius, std::abs(h) - 0.5 * s.height);
        return std::min(std::max(d.x, d.y), 0.0) + glm::length(glm::max(d, 0.0));
    }
    case ClipTextureSpec::Shape::Mask:
        break;
    }
    return std::numeric_limits<double>::infinity();
}

void addClipTextureStats(nlohmann::json& extra, const ClipTexture& texture, const ClipTextureSpec& spec)
{
    const glm::ivec3 n = texture.dims();
    extra["clip_texture"] = texture.source;
    extra["clip_texture_dims"] = {n.x, n.y, n.z};
    extra["clip_texture_inverse"] = spec.inverse;
}

ClipTexture makeClipTexture(const ClipTextureSpec& spec, const fs::path& baseDir)
{
    ClipTexture t;
    t.desc.channels = 1;
    t.desc.filter = raster::Filter::Linear;
    t.desc.wrap = raster::Wrap::ClampToEdge;  // outside the box of texel centers is decided by the caller
    if (spec.shape == ClipTextureSpec::Shape::Mask) {
        const fs::path path = fs::path(spec.maskFile).is_absolute() ? fs::path(spec.maskFile) : baseDir / spec.maskFile;
        if (!fs::is_regular_file(path))
            throw InputError(path.string() + ": no such file (clip texture mask)");
        Volume mask;
        try {
            mask = loadVolume(json::parse(spec.maskSpec), baseDir);  // validated: NaN is an InputError
        } catch (const InputError& e) {
            throw InputError(std::string("options.clip_texture.mask: ") + e.what());  // "volume: ..." would mislead
        }
        t.source = mask.source;
        t.desc.width = mask.dims.x;
        t.desc.height = mask.dims.y;
        t.desc.depth = mask.dims.z;
        t.origin = mask.origin;
        t.spacing = mask.spacing;
        std::vector<float> scratch;
        const std::vector<float>& values = mask.floats(scratch);
        t.texels.resize(values.size());
        // Inside where the mask's value is > 0.5: store 0.5 - value, so that inside is < 0 as for shapes.
        std::transform(values.begin(), values.end(), t.texels.begin(), [](float v) { return 0.5f - v; });
        t.pivot = t.origin + 0.5 * glm::dvec3(mask.dims - 1) * t.spacing;
        raster::validate(t.desc, t.texels.size());
        return t;
    }
    // Signed distance, sampled on a grid of cubic texels over the bounding box plus the margin, centered
    // on the box. Linear filtering of a distance field thresholded at 0 puts the boundary where the
    // field's trilinear interpolant crosses 0: exact where the field is linear across a texel (flat
    // faces), within ~h^2 / (8 radius) on curved parts, and within a texel only where faces meet.
    glm::dvec3 lo, hi;
    shapeBounds(spec, lo, hi);
    const glm::dvec3 extent = hi - lo;
    const double longest = std::max({extent.x, extent.y, extent.z});
    const double h = longest / (spec.resolution - 1 - 2 * kMarginTexels);
    glm::ivec3 n;
    for (int a = 0; a < 3; ++a)
        n[a] = static_cast<int>(std::ceil(extent[a] / h - 1e-9)) + 1 + 2 * kMarginTexels;
    t.pivot = 0.5 * (lo + hi);
    t.spacing = glm::dvec3(h);
    t.origin = t.pivot - 0.5 * glm::dvec3(n - 1) * h;
    t.desc.width = n.x;
    t.desc.height = n.y;
    t.desc.depth = n.z;
    t.source = spec.shape == ClipTextureSpec::Shape::Sphere ? "sphere"
               : spec.shape == ClipTextureSpec::Shape::Box  ? "box"
                                                            : "cylinder";
    t.texels.resize(static_cast<std::size_t>(n.x) * n.y * n.z);
    std::size_t i = 0;
    for (int z = 0; z < n.z; ++z)
        for (int y = 0; y < n.y; ++y)
            for (int x = 0; x < n.x; ++x)
                t.texels[i++] = static_cast<float>(shapeSignedDistance(spec, t.origin + glm::dvec3(x, y, z) * h));
    raster::validate(t.desc, t.texels.size());
    return t;
}

glm::dmat4 clipTextureCoordinates(const ClipTexture& t, const glm::dvec3& offset, const glm::dmat3& matrix)
{
    // q = pivot + M^-1 (p - pivot - offset): the point of the unmoved texture; then texel-center
    // coordinates g = (q - origin) / spacing and GL's normalized u = (g + 0.5) / n.
    const glm::dmat3 inv = glm::inverse(matrix);
    const glm::dvec3 n(t.dims());
    const glm::dvec3 scale = 1.0 / (t.spacing * n);
    const glm::dvec3 shift = t.pivot - inv * (t.pivot + offset);
    glm::dmat4 m(0.0);
    for (int r = 0; r < 3; ++r) {
        for (int c = 0; c < 3; ++c)
            m[c][r] = scale[r] * inv[c][r];
        m[3][r] = scale[r] * shift[r] + (0.5 - t.origin[r] / t.spacing[r]) / n[r];
    }
    m[3][3] = 1.0;
    return m;
}

std::vector<glm::dvec2> shapeClipIntervals(const ClipTextureSpec& s, const Ray& ray, double t0, double t1)
{
    glm::dvec3 lo, hi;
    shapeBounds(s, lo, hi);
    const Ray r = toShapeFrame(0.5 * (lo + hi), s, ray);
    double a = 0.0, b = 0.0;
    bool hit = false;
    switch (s.shape) {
    case ClipTextureSpec::Shape::Sphere: {
        const glm::dvec3 w = r.origin - s.center;
        hit = negativeBetween(glm::dot(r.direction, r.direction), 2.0 * glm::dot(w, r.direction),
                              glm::dot(w, w) - s.radius * s.radius, a, b);
        break;
    }
    case ClipTextureSpec::Shape::Box: {
        a = -std::numeric_limits<double>::infinity();
        b = std::numeric_limits<double>::infinity();
        hit = true;
        for (int k = 0; k < 3 && hit; ++k) {
            double ta, tb;
            hit = slab(r.origin[k], r.direction[k], s.min[k], s.max[k], ta, tb);
            a = std::max(a, ta);
            b = std::min(b, tb);
        }
        break;
    }
    case ClipTextureSpec::Shape::Cylinder: {
        const glm::dvec3 ax = glm::normalize(s.axis), w = r.origin - s.center;
        const double wa = glm::dot(w, ax), da = glm::dot(r.direction, ax);
        const glm::dvec3 wp = w - wa * ax, dp = r.direction - da * ax;
        double ra = 0.0, rb = 0.0;
        const double A = glm::dot(dp, dp), C = glm::dot(wp, wp) - s.radius * s.radius;
        bool radial;
        if (A <= 1e-24 * glm::dot(r.direction, r.direction)) {  // along the axis: inside the tube or never
            radial = C < 0.0;
            ra = -std::numeric_limits<double>::infinity();
            rb = std::numeric_limits<double>::infinity();
        } else {
            radial = negativeBetween(A, 2.0 * glm::dot(wp, dp), C, ra, rb);
        }
        double ca, cb;
        const bool caps = slab(wa, da, -0.5 * s.height, 0.5 * s.height, ca, cb);
        hit = radial && caps;
        a = std::max(ra, ca);
        b = std::min(rb, cb);
        break;
    }
    case ClipTextureSpec::Shape::Mask:
        break;
    }
    return piecesOf(hit, a, b, t0, t1, s.inverse);
}

bool insideClipTexture(const ClipTexture& t, const glm::dmat4& coordinates, const glm::dvec3& p)
{
    const glm::ivec3 dims = t.dims();
    const glm::dvec3 u = glm::dvec3(coordinates * glm::dvec4(p, 1.0));
    const glm::dvec3 g = u * glm::dvec3(dims) - 0.5;  // texel-center coordinates
    for (int a = 0; a < 3; ++a)
        if (!(g[a] >= 0.0 && g[a] <= dims[a] - 1))
            return false;
    const glm::ivec3 i0 = glm::clamp(glm::ivec3(glm::floor(g)), glm::ivec3(0), glm::max(dims - 2, 0));
    const glm::dvec3 f = g - glm::dvec3(i0);
    auto v = [&](int dx, int dy, int dz) {
        const glm::ivec3 i = glm::min(i0 + glm::ivec3(dx, dy, dz), dims - 1);
        return static_cast<double>(t.texels[(static_cast<std::size_t>(i.z) * dims.y + i.y) * dims.x + i.x]);
    };
    const double c00 = v(0, 0, 0) * (1 - f.x) + v(1, 0, 0) * f.x;
    const double c10 = v(0, 1, 0) * (1 - f.x) + v(1, 1, 0) * f.x;
    const double c01 = v(0, 0, 1) * (1 - f.x) + v(1, 0, 1) * f.x;
    const double c11 = v(0, 1, 1) * (1 - f.x) + v(1, 1, 1) * f.x;
    return (c00 * (1 - f.y) + c10 * f.y) * (1 - f.z) + (c01 * (1 - f.y) + c11 * f.y) * f.z < 0.0;
}

std::vector<glm::dvec2> textureClipIntervals(const ClipTexture& t, const glm::dmat4& coordinates, bool inverse,
                                             const Ray& ray, double t0, double t1, double step)
{
    std::vector<glm::dvec2> out;
    if (!(t1 > t0))
        return out;
    auto keep = [&](double s) { return insideClipTexture(t, coordinates, ray.origin + s * ray.direction) != inverse; };
    const long long n = std::max<long long>(1, static_cast<long long>(std::ceil((t1 - t0) / step)));
    const double h = (t1 - t0) / static_cast<double>(n);
    const double eps = 1e-12 * (t1 - t0);
    bool state = keep(t0);
    double start = t0;
    for (long long i = 1; i <= n; ++i) {
        const double s = i == n ? t1 : t0 + static_cast<double>(i) * h;
        if (keep(s) == state)
            continue;
        double lo = t0 + static_cast<double>(i - 1) * h, hi = s;  // keep(lo) == state != keep(hi)
        while (hi - lo > eps) {
            const double mid = 0.5 * (lo + hi);
            (keep(mid) == state ? lo : hi) = mid;
        }
        const double change = 0.5 * (lo + hi);
        if (state)
            out.push_back({start, change});
        else
            start = change;
        state = !state;
    }
    if (state && t1 > start)
        out.push_back({start, t1});
    return out;
}

}  // namespace clvr
