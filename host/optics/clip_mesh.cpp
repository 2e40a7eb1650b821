// host/optics/clip_mesh.cpp — clip surfaces: the scene's "mesh" spec, the readers (host/io/surface_io.h for .off
// and ASCII .stl, as TetGen reads them; small ones here for .obj and binary .stl), the generators, the closedness check, and ray parity for the CPU reference.
#include "host/optics/clip_mesh.h"

#include "host/runtime/errors.h"
#include "host/runtime/file_io.h"
#include "host/model/json_values.h"
#include "host/io/surface_io.h"

#include <nlohmann/json.hpp>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstring>
#include <fstream>
#include <map>
#include <numbers>
#include <sstream>

namespace clvr {

namespace fs = std::filesystem;

namespace {

using nlohmann::json;

// Adds the fan of a polygon (indices into mesh.points).
void addPolygon(ClipMesh& mesh, const std::vector<std::uint32_t>& polygon)
{
    for (std::size_t i = 1; i + 1 < polygon.size(); ++i)
        mesh.triangles.push_back({polygon[0], polygon[i], polygon[i + 1]});
}

ClipMesh readObj(const fs::path& path)
{
    std::ifstream in(path);
    if (!in)
        throw InputError(path.string() + ": cannot open");
    ClipMesh mesh;
    mesh.source = path.string();
    std::string line;
    for (int number = 1; std::getline(in, line); ++number) {
        std::istringstream s(line);
        std::string op;
        if (!(s >> op) || op[0] == '#')
            continue;
        const std::string where = path.string() + ":" + std::to_string(number) + ": ";
        if (op == "v") {
            glm::dvec3 p;
            if (!(s >> p.x >> p.y >> p.z) || !std::isfinite(p.x) || !std::isfinite(p.y) || !std::isfinite(p.z))
                throw InputError(where + "a vertex needs three finite coordinates");
            mesh.points.push_back(p);
        } else if (op == "f") {
            // "a", "a/t", "a/t/n" or "a//n": the position index is the part before the first '/';
            // 1-based, or negative counting back from the last vertex read so far.
            std::vector<std::uint32_t> polygon;
            for (std::string word; s >> word;) {
                long long i = 0;
                try {
                    std::size_t used = 0;
                    i = std::stoll(word, &used);
                    if (used != word.size() && word[used] != '/')
                        throw std::invalid_argument(word);
                } catch (const std::exception&) {
                    throw InputError(where + "bad face index \"" + word + "\"");
                }
                const long long n = static_cast<long long>(mesh.points.size());
                const long long index = i > 0 ? i - 1 : n + i;
                if (i == 0 || index < 0 || index >= n)
                    throw InputError(where + "face index " + word + " names no vertex read so far (" +
                                     std::to_string(n) + ")");
                polygon.push_back(static_cast<std::uint32_t>(index));
            }
            if (polygon.size() < 3)
                throw InputError(where + "a face needs at least 3 vertices");
            addPolygon(mesh, polygon);
        }
        // vt, vn, o, g, s, usemtl, mtllib, l, ...: not geometry of a closed surface; ignored.
    }
    return mesh;
}

// Binary STL, which tetgenio::load_stl does not read: an 80-byte header, a little-endian uint32
// triangle count, then per triangle 12 floats (normal, 3 corners) and a 2-byte attribute count.
// Recognised by its exact size, 84 + 50 n (an ASCII file of that size would have to start "solid"
// and still match by chance).
bool isBinaryStl(const fs::path& path, std::uint32_t& count)
{
    std::ifstream in(path, std::ios::binary);
    char header[84];
    if (!in.read(header, 84))
        return false;
    count = static_cast<std::uint32_t>(static_cast<unsigned char>(header[80])) |
            static_cast<std::uint32_t>(static_cast<unsigned char>(header[81])) << 8 |
            static_cast<std::uint32_t>(static_cast<unsigned char>(header[82])) << 16 |
            static_cast<std::uint32_t>(static_cast<unsigned char>(header[83])) << 24;
    return fs::file_size(path) == 84 + 50ull * count;
}

ClipMesh readBinaryStl(const fs::path& path, std::uint32_t count)
{
    std::ifstream in(path, std::ios::binary);
    in.seekg(84);
    ClipMesh mesh;
    mesh.source = path.string();
    for (std::uint32_t t = 0; t < count; ++t) {
        unsigned char record[50];
        if (!in.read(reinterpret_cast<char*>(record), 50))
            throw InputError(path.string() + ": binary STL ends inside triangle " + std::to_string(t));
        const std::uint32_t base = static_cast<std::uint32_t>(mesh.points.size());
        for (int corner = 0; corner < 3; ++corner) {
            glm::dvec3 p;
            for (int axis = 0; axis < 3; ++axis) {
                const unsigned char* b = record + 12 + 12 * corner + 4 * axis;
                const std::uint32_t bits = b[0] | b[1] << 8 | b[2] << 16 | static_cast<std::uint32_t>(b[3]) << 24;
                float f;
                std::memcpy(&f, &bits, 4);
                p[axis] = f;
            }
            mesh.points.push_back(p);
        }
        mesh.triangles.push_back({base, base + 1, base + 2});
    }
    return mesh;
}

// .off and ASCII .stl: read as TetGen reads them (host/io/surface_io.h), polygons fanned into triangles.
ClipMesh readPlcSurface(const fs::path& path)
{
    const Plc plc = readPlc(path);
    if (plc.points.empty() || plc.facets.empty())
        throw InputError(path.string() + ": could not read a surface from it (no points or no faces)");
    ClipMesh mesh;
    mesh.source = path.string();
    mesh.points = plc.points;
    for (const PlcFacet& facet : plc.facets)
        for (const std::vector<int>& corners : facet.polygons) {
            std::vector<std::uint32_t> polygon;
            for (int c : corners)  // readPlc has checked every corner against the point count
                polygon.push_back(static_cast<std::uint32_t>(c - plc.firstNumber));
            addPolygon(mesh, polygon);
        }
    return mesh;
}

// Adds triangle (a, b, c) of a convex generated surface, turned so that it faces away from `inside`.
void addOutward(ClipMesh& mesh, std::uint32_t a, std::uint32_t b, std::uint32_t c, const glm::dvec3& inside)
{
    const glm::dvec3 &pa = mesh.points[a], &pb = mesh.points[b], &pc = mesh.points[c];
    const glm::dvec3 normal = glm::cross(pb - pa, pc - pa);
    if (glm::dot(normal, (pa + pb + pc) / 3.0 - inside) >= 0.0)
        mesh.triangles.push_back({a, b, c});
    else
        mesh.triangles.push_back({a, c, b});
}

// Edge functions of the projected points (Woop, Benthin, Wald 2013): E(a, b) = a.x b.y - a.y b.x.
// E(b, a) is computed from the same two rounded products, so it is exactly -E(a, b); an FMA would
// round only one of them, so CMakeLists.txt builds this file with -ffp-contract=off.
double edgeFunction(const glm::dvec2& a, const glm::dvec2& b) { return a.x * b.y - a.y * b.x; }

// Tie rule for a line through edge p -> q (E = 0) of a triangle oriented positively: exactly one of
// p -> q and q -> p owns it, so the two triangles sharing an edge count one crossing between them.
bool ownsEdge(const glm::dvec2& p, const glm::dvec2& q) { return q.y > p.y || (q.y == p.y && q.x < p.x); }

}  // namespace

ClipMeshSpec parseClipMeshSpec(const json& spec, const std::string& key)
{
    ClipMeshSpec s;
    if (spec.is_string()) {
        s.file = spec.get<std::string>();
        if (s.file.empty())
            badKey(key, "must name a surface file (.off, .stl, .obj), got \"\"");
        return s;
    }
    if (!spec.is_object())
        badKey(key, "must be a file name or an object with \"file\" or \"generator\", got " + spec.dump());
    if (spec.contains("file") == spec.contains("generator"))
        badKey(key, "give either \"file\" or \"generator\"");
    auto check = [&](std::initializer_list<const char*> known) {
        std::string list;
        for (const char* k : known)
            list += (list.empty() ? "" : ", ") + std::string(k);
        for (const auto& item : spec.items()) {
            const std::string& k = item.key();  // not a structured binding: clang 14 cannot capture one
            if (std::none_of(known.begin(), known.end(), [&](const char* n) { return k == n; }))
                badKey(key + "." + k, "unknown key (known: " + list + ")");
        }
    };
    if (spec.contains("file")) {
        check({"file", "scale", "translate"});
        if (!spec["file"].is_string() || spec["file"].get<std::string>().empty())
            badKey(key + ".file", "must be a file name (.off, .stl, .obj), got " + spec["file"].dump());
        s.file = spec["file"].get<std::string>();
        if (spec.contains("scale")) {
            const json& v = spec["scale"];
            s.scale = v.is_number() ? glm::dvec3(v.get<double>()) : jsonVec3(v, key + ".scale");
            // Zero would flatten the mesh; negative mirrors it (closeClipMesh then turns it outward again).
            if (!std::isfinite(s.scale.x) || s.scale.x == 0.0 || s.scale.y == 0.0 || s.scale.z == 0.0)
                badKey(key + ".scale", "must be a finite non-zero number or [x, y, z] of them, got " + v.dump());
        }
        if (spec.contains("translate"))
            s.translate = jsonVec3(spec["translate"], key + ".translate");
        return s;
    }
    const json& g = spec["generator"];
    s.generator = g.is_string() ? g.get<std::string>() : "";
    if (s.generator == "box") {
        check({"generator", "min", "max"});
        if (spec.contains("min"))
            s.min = jsonVec3(spec["min"], key + ".min");
        if (spec.contains("max"))
            s.max = jsonVec3(spec["max"], key + ".max");
        if (!(s.min.x < s.max.x && s.min.y < s.max.y && s.min.z < s.max.z))
            badKey(key + ".max", "must be greater than min in x, y and z");
        return s;
    }
    if (s.generator != "sphere" && s.generator != "cylinder")
        badKey(key + ".generator", "must be \"box\", \"sphere\" or \"cylinder\", got " + g.dump());
    if (s.generator == "sphere")
        check({"generator", "center", "radius", "segments"});
    else
        check({"generator", "center", "axis", "radius", "height", "segments"});
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
    if (spec.contains("segments")) {
        const json& v = spec["segments"];
        if (!v.is_number_integer() || v.get<long long>() < 3 || v.get<long long>() > 4096)
            badKey(key + ".segments", "must be an integer in [3, 4096], got " + v.dump());
        s.segments = v.get<int>();
    }
    return s;
}

ClipMesh readSurface(const fs::path& path)
{
    if (!fs::is_regular_file(path))
        throw InputError(path.string() + ": no such file (clip mesh)");
    const std::string ext = asciiLower(path.extension().string());
    if (ext == ".obj")
        return readObj(path);
    std::uint32_t count = 0;
    if (ext == ".stl" && isBinaryStl(path, count))
        return readBinaryStl(path, count);
    if (ext == ".off" || ext == ".stl")
        return readPlcSurface(path);
    throw InputError(path.string() + ": unknown surface format \"" + ext + "\" (.off, .stl, .obj)");
}

ClipMesh boxMesh(const glm::dvec3& lo, const glm::dvec3& hi)
{
    ClipMesh mesh;
    mesh.source = "box";
    for (int c = 0; c < 8; ++c)
        mesh.points.push_back({(c & 1) ? hi.x : lo.x, (c & 2) ? hi.y : lo.y, (c & 4) ? hi.z : lo.z});
    const glm::dvec3 inside = 0.5 * (lo + hi);
    // Face `axis` at side s: the corners with that bit = s, in a cycle over the other two bits.
    for (int axis = 0; axis < 3; ++axis)
        for (int side = 0; side < 2; ++side) {
            const int bit = 1 << axis, j = 1 << ((axis + 1) % 3), l = 1 << ((axis + 2) % 3);
            const std::uint32_t base = side ? bit : 0;
            const std::uint32_t q[4] = {base, base | j, base | j | l, base | l};
            addOutward(mesh, q[0], q[1], q[2], inside);
            addOutward(mesh, q[0], q[2], q[3], inside);
        }
    return mesh;
}

ClipMesh sphereMesh(const glm::dvec3& center, double radius, int segments)
{
    ClipMesh mesh;
    mesh.source = "sphere";
    const int rings = std::max(segments / 2, 2);
    const double pi = std::numbers::pi;
    mesh.points.push_back(center + glm::dvec3(0, 0, radius));   // north pole: 0
    mesh.points.push_back(center - glm::dvec3(0, 0, radius));   // south pole: 1
    for (int i = 1; i < rings; ++i)
        for (int j = 0; j < segments; ++j) {
            const double theta = pi * i / rings, phi = 2.0 * pi * j / segments;
            mesh.points.push_back(center + radius * glm::dvec3(std::sin(theta) * std::cos(phi),
                                                               std::sin(theta) * std::sin(phi), std::cos(theta)));
        }
    auto at = [&](int ring, int j) { return static_cast<std::uint32_t>(2 + (ring - 1) * segments + j % segments); };
    for (int j = 0; j < segments; ++j) {
        addOutward(mesh, 0, at(1, j), at(1, j + 1), center);
        addOutward(mesh, 1, at(rings - 1, j), at(rings - 1, j + 1), center);
        for (int i = 1; i + 1 < rings; ++i) {
            addOutward(mesh, at(i, j), at(i + 1, j), at(i + 1, j + 1), center);
            addOutward(mesh, at(i, j), at(i + 1, j + 1), at(i, j + 1), center);
        }
    }
    return mesh;
}

ClipMesh cylinderMesh(const glm::dvec3& center, const glm::dvec3& axis, double radius, double height, int segments)
{
    ClipMesh mesh;
    mesh.source = "cylinder";
    const glm::dvec3 a = glm::normalize(axis);
    const glm::dvec3 helper = std::abs(a.x) < 0.9 ? glm::dvec3(1, 0, 0) : glm::dvec3(0, 1, 0);
    const glm::dvec3 e1 = glm::normalize(glm::cross(helper, a)), e2 = glm::cross(a, e1);
    const glm::dvec3 bottom = center - 0.5 * height * a, top = center + 0.5 * height * a;
    mesh.points.push_back(bottom);  // 0
    mesh.points.push_back(top);     // 1
    for (int j = 0; j < segments; ++j) {
        const double phi = 2.0 * std::numbers::pi * j / segments;
        const glm::dvec3 r = radius * (std::cos(phi) * e1 + std::sin(phi) * e2);
        mesh.points.push_back(bottom + r);  // 2 + 2j
        mesh.points.push_back(top + r);     // 3 + 2j
    }
    auto b = [&](int j) { return static_cast<std::uint32_t>(2 + 2 * (j % segments)); };
    for (int j = 0; j < segments; ++j) {
        addOutward(mesh, 0, b(j), b(j + 1), center);
        addOutward(mesh, 1, b(j) + 1, b(j + 1) + 1, center);
        addOutward(mesh, b(j), b(j + 1), b(j + 1) + 1, center);
        addOutward(mesh, b(j), b(j + 1) + 1, b(j) + 1, center);
    }
    return mesh;
}

double signedVolume(const ClipMesh& mesh)
{
    double v = 0.0;
    for (const auto& t : mesh.triangles)
        v += glm::dot(mesh.points[t[0]], glm::cross(mesh.points[t[1]], mesh.points[t[2]]));
    return v / 6.0;
}

void closeClipMesh(ClipMesh& mesh)
{
    if (mesh.triangles.empty())
        throw InputError(mesh.source + ": the clip mesh has no triangles");
    for (const glm::dvec3& p : mesh.points)
        if (!std::isfinite(p.x) || !std::isfinite(p.y) || !std::isfinite(p.z))
            throw InputError(mesh.source + ": the clip mesh has a point that is not finite");
    std::vector<glm::dvec3> points;
    const std::vector<std::uint32_t> remap = mergeIdenticalPoints(mesh.points, points);
    std::vector<std::array<std::uint32_t, 3>> triangles;
    for (const auto& t : mesh.triangles) {
        const std::array<std::uint32_t, 3> r = {remap[t[0]], remap[t[1]], remap[t[2]]};
        if (r[0] != r[1] && r[1] != r[2] && r[2] != r[0])
            triangles.push_back(r);
    }
    // Closed and consistently oriented: each undirected edge is walked as often one way as the other.
    std::map<std::pair<std::uint32_t, std::uint32_t>, int> balance;
    for (const auto& t : triangles)
        for (int e = 0; e < 3; ++e) {
            const std::uint32_t a = t[e], b = t[(e + 1) % 3];
            balance[{std::min(a, b), std::max(a, b)}] += a < b ? 1 : -1;
        }
    for (const auto& [edge, n] : balance)
        if (n != 0) {
            const glm::dvec3 &a = points[edge.first], &b = points[edge.second];
            std::ostringstream s;
            s << mesh.source << ": the clip mesh is not a closed, consistently oriented surface (edge ("
              << a.x << ", " << a.y << ", " << a.z << ") - (" << b.x << ", " << b.y << ", " << b.z
              << ") has unmatched triangles: a hole, or neighbours with opposite windings)";
            throw InputError(s.str());
        }
    mesh.points = std::move(points);
    mesh.triangles = std::move(triangles);
    const double volume = signedVolume(mesh);
    if (!(volume != 0.0))
        throw InputError(mesh.source + ": the clip mesh encloses no volume");
    if (volume < 0.0)
        for (auto& t : mesh.triangles)
            std::swap(t[1], t[2]);
}

ClipMesh loadClipMesh(const ClipMeshSpec& spec, const fs::path& baseDir)
{
    ClipMesh mesh;
    if (!spec.file.empty()) {
        const fs::path path = fs::path(spec.file).is_absolute() ? fs::path(spec.file) : baseDir / spec.file;
        mesh = readSurface(path);
        for (glm::dvec3& p : mesh.points)
            p = p * spec.scale + spec.translate;
    } else if (spec.generator == "box") {
        mesh = boxMesh(spec.min, spec.max);
    } else if (spec.generator == "sphere") {
        mesh = sphereMesh(spec.center, spec.radius, spec.segments);
    } else if (spec.generator == "cylinder") {
        mesh = cylinderMesh(spec.center, spec.axis, spec.radius, spec.height, spec.segments);
    } else {
        throw InputError("clip mesh: unknown generator \"" + spec.generator + "\"");
    }
    closeClipMesh(mesh);
    return mesh;
}

std::vector<double> rayCrossings(const ClipMesh& mesh, const Ray& ray)
{
    // Project every point once into the ray's frame: (x, y) across it, z along it (t for a unit direction).
    const glm::dvec3 d = glm::normalize(ray.direction);
    const glm::dvec3 helper = std::abs(d.x) < 0.9 ? glm::dvec3(1, 0, 0) : glm::dvec3(0, 1, 0);
    const glm::dvec3 u = glm::normalize(glm::cross(helper, d)), v = glm::cross(d, u);
    const double length = glm::length(ray.direction);
    std::vector<glm::dvec3> q(mesh.points.size());
    for (std::size_t i = 0; i < q.size(); ++i) {
        const glm::dvec3 r = mesh.points[i] - ray.origin;
        q[i] = {glm::dot(r, u), glm::dot(r, v), glm::dot(r, d)};
    }
    std::vector<double> crossings;
    for (const auto& t : mesh.triangles) {
        const glm::dvec2 p[3] = {glm::dvec2(q[t[0]]), glm::dvec2(q[t[1]]), glm::dvec2(q[t[2]])};
        // e[i] belongs to the edge opposite point i: (i+1) -> (i+2).
        double e[3];
        for (int i = 0; i < 3; ++i)
            e[i] = edgeFunction(p[(i + 1) % 3], p[(i + 2) % 3]);
        const double det = e[0] + e[1] + e[2];
        if (det == 0.0)
            continue;  // edge-on: the line lies in the triangle's plane or misses it
        const bool flip = det < 0.0;  // orient positively: reverse the edges and negate e
        bool hit = true;
        for (int i = 0; i < 3 && hit; ++i) {
            const double ei = flip ? -e[i] : e[i];
            const glm::dvec2 &a = p[(i + 1) % 3], &b = p[(i + 2) % 3];
            hit = ei > 0.0 || (ei == 0.0 && (flip ? ownsEdge(b, a) : ownsEdge(a, b)));
        }
        if (hit)
            crossings.push_back((e[0] * q[t[0]].z + e[1] * q[t[1]].z + e[2] * q[t[2]].z) / det / length);
    }
    std::sort(crossings.begin(), crossings.end());
    return crossings;
}

std::vector<glm::dvec2> clipIntervals(const ClipMesh& mesh, const Ray& ray, double t0, double t1, bool inverse)
{
    const std::vector<double> c = rayCrossings(mesh, ray);
    const std::size_t n = c.size();
    std::vector<glm::dvec2> out;
    // Between c[j-1] and c[j] (c[-1] = -inf, c[n] = +inf) the ray beyond crosses n - j times.
    for (std::size_t j = 0; j <= n; ++j) {
        const bool inside = (n - j) % 2 == 1;
        if (inside == inverse)
            continue;
        const double a = std::max(t0, j == 0 ? t0 : c[j - 1]);
        const double b = std::min(t1, j == n ? t1 : c[j]);
        if (!(b > a))
            continue;
        if (!out.empty() && out.back().y == a)
            out.back().y = b;  // a double crossing at one point (a grazed edge): no gap
        else
            out.push_back({a, b});
    }
    return out;
}

bool insideClipMesh(const ClipMesh& mesh, const glm::dvec3& p)
{
    const Ray ray{p, glm::normalize(glm::dvec3(0.5773502691896258, 0.6133132, 0.5391))};
    const std::vector<double> c = rayCrossings(mesh, ray);
    return std::count_if(c.begin(), c.end(), [](double t) { return t > 0.0; }) % 2 == 1;
}

}  // namespace clvr
