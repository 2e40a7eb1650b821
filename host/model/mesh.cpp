// host/model/mesh.cpp — checkMesh (validation, reorientation, degenerate cells) and buildTopology (face
// matching on welded point positions). Both are O(n log n): points are welded by sorting their
// coordinates, faces are matched by sorting their welded, sorted point ids; nothing is quadratic.
#include "host/model/mesh.h"

#include "host/runtime/errors.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <numeric>
#include <sstream>
#include <tuple>

namespace clvr {

namespace {

std::string cellName(const TetMesh& mesh, std::size_t t)
{
    return (mesh.source.empty() ? std::string("mesh") : mesh.source) + ": tetrahedron " + std::to_string(t);
}

bool finite3(const glm::dvec3& p)
{
    return std::isfinite(p.x) && std::isfinite(p.y) && std::isfinite(p.z);
}

}  // namespace

double signedVolume6(const glm::dvec3& p0, const glm::dvec3& p1, const glm::dvec3& p2, const glm::dvec3& p3)
{
    return glm::dot(p1 - p0, glm::cross(p2 - p0, p3 - p0));
}

glm::dvec3 TetMesh::boundsMin() const
{
    glm::dvec3 lo(std::numeric_limits<double>::infinity());
    for (const glm::dvec3& p : points)
        lo = glm::min(lo, p);
    return points.empty() ? glm::dvec3(0.0) : lo;
}

glm::dvec3 TetMesh::boundsMax() const
{
    glm::dvec3 hi(-std::numeric_limits<double>::infinity());
    for (const glm::dvec3& p : points)
        hi = glm::max(hi, p);
    return points.empty() ? glm::dvec3(0.0) : hi;
}

glm::dvec2 TetMesh::scalarRange() const
{
    if (scalars.empty())
        return glm::dvec2(0.0);
    const auto [lo, hi] = std::minmax_element(scalars.begin(), scalars.end());
    return glm::dvec2(*lo, *hi);
}

void checkMesh(TetMesh& mesh)
{
    const std::string source = mesh.source.empty() ? std::string("mesh") : mesh.source;
    const std::size_t n = mesh.points.size();
    if (mesh.scalars.size() != n)
        throw InputError(source + ": " + std::to_string(mesh.scalars.size()) + " scalars for " + std::to_string(n) +
                         " points (one scalar per point)");
    if (n > std::numeric_limits<std::uint32_t>::max())
        throw InputError(source + ": " + std::to_string(n) + " points, the limit is 2^32 - 1");
    if (mesh.tets.size() > static_cast<std::size_t>(std::numeric_limits<std::int32_t>::max()))
        throw InputError(source + ": " + std::to_string(mesh.tets.size()) + " tetrahedra, the limit is 2^31 - 1");
    if (mesh.tetsRead < mesh.tets.size())
        mesh.tetsRead = mesh.tets.size();

    // Indices, coordinates and scalars, cell by cell: the first offending cell is named.
    std::vector<char> used(n, 0);
    for (std::size_t t = 0; t < mesh.tets.size(); ++t) {
        const glm::uvec4 c = mesh.tets[t];
        for (int k = 0; k < 4; ++k) {
            if (c[k] >= n)
                throw InputError(cellName(mesh, t) + " has point index " + std::to_string(c[k]) +
                                 ", out of range (the mesh has " + std::to_string(n) + " points)");
            const glm::dvec3& p = mesh.points[c[k]];
            if (!finite3(p))
                throw InputError(cellName(mesh, t) + " has point " + std::to_string(c[k]) + " with a non-finite coordinate (" +
                                 numberText(p.x) + " " + numberText(p.y) + " " + numberText(p.z) + ")");
            if (!std::isfinite(mesh.scalars[c[k]]))
                throw InputError(cellName(mesh, t) + " has point " + std::to_string(c[k]) + " with a non-finite scalar (" +
                                 numberText(mesh.scalars[c[k]]) + ")");
            used[c[k]] = 1;
        }
    }
    // Unused points are never interpolated, but they would spoil the bounds.
    for (std::size_t i = 0; i < n; ++i)
        if (!used[i] && (!finite3(mesh.points[i]) || !std::isfinite(mesh.scalars[i])))
            throw InputError(source + ": point " + std::to_string(i) + " (used by no tetrahedron) is not finite");

    // Orientation and degenerate cells, relative to the size of the mesh.
    const glm::dvec3 extent = mesh.boundsMax() - mesh.boundsMin();
    const double scale = std::max({extent.x, extent.y, extent.z});
    const double threshold = 1e-12 * scale * scale * scale;
    if (!mesh.neighbors.empty() && mesh.neighbors.size() != mesh.tets.size())
        throw InputError(source + ": adjacency for " + std::to_string(mesh.neighbors.size()) + " tetrahedra, the mesh has " +
                         std::to_string(mesh.tets.size()));
    std::size_t kept = 0;
    for (std::size_t t = 0; t < mesh.tets.size(); ++t) {
        glm::uvec4 c = mesh.tets[t];
        const double v6 = signedVolume6(mesh.points[c[0]], mesh.points[c[1]], mesh.points[c[2]], mesh.points[c[3]]);
        if (!(std::abs(v6) > threshold) || c[0] == c[1] || c[0] == c[2] || c[0] == c[3] || c[1] == c[2] ||
            c[1] == c[3] || c[2] == c[3]) {
            ++mesh.tetsDegenerate;
            continue;
        }
        if (v6 < 0.0) {
            std::swap(c[2], c[3]);  // faces 2 and 3 swap with their opposite vertices
            if (!mesh.neighbors.empty())
                std::swap(mesh.neighbors[t][2], mesh.neighbors[t][3]);
            ++mesh.tetsReoriented;
        }
        if (!mesh.neighbors.empty())
            mesh.neighbors[kept] = mesh.neighbors[t];
        mesh.tets[kept++] = c;
    }
    mesh.tets.resize(kept);
    // Dropped cells renumber the others and leave holes that face matching (with welding) handles.
    if (kept != mesh.neighbors.size())
        mesh.neighbors.clear();
}

namespace {

// The positions of the three points of face f of tetrahedron c (the face opposite vertex f), sorted:
// faces are the same when their points coincide, as buildTopology's welding has it.
std::array<std::tuple<double, double, double>, 3> faceKey(const TetMesh& mesh, const glm::uvec4& c, int f)
{
    std::array<std::tuple<double, double, double>, 3> key{};
    int k = 0;
    for (int i = 0; i < 4; ++i)
        if (i != f) {
            const glm::dvec3& p = mesh.points[c[i]];
            key[k++] = {p.x, p.y, p.z};
        }
    std::sort(key.begin(), key.end());
    return key;
}

// buildTopology from a given adjacency (a TetGen .neigh), checked pair by pair.
TetTopology topologyFromNeighbors(const TetMesh& mesh, const std::string& source)
{
    TetTopology topo;
    topo.neighbor = mesh.neighbors;
    const std::size_t nt = mesh.tets.size();
    for (std::size_t t = 0; t < nt; ++t)
        for (int f = 0; f < 4; ++f) {
            const std::int32_t n = topo.neighbor[t][f];
            if (n == -1) {
                topo.boundary.push_back({static_cast<std::uint32_t>(t), static_cast<std::uint32_t>(f)});
                continue;
            }
            const std::string cell = source + ": tetrahedron " + std::to_string(t) + ", face " + std::to_string(f);
            if (n < 0 || static_cast<std::size_t>(n) >= nt || static_cast<std::size_t>(n) == t)
                throw InputError(cell + ": neighbor " + std::to_string(n) + " is not another tetrahedron of the mesh");
            const auto key = faceKey(mesh, mesh.tets[t], f);
            int back = -1;
            for (int g = 0; g < 4 && back < 0; ++g)
                if (faceKey(mesh, mesh.tets[n], g) == key)
                    back = g;
            if (back < 0)
                throw InputError(cell + ": the adjacency names tetrahedron " + std::to_string(n) +
                                 " as its neighbor, but they do not share that face");
            if (topo.neighbor[n][back] != static_cast<std::int32_t>(t))
                throw InputError(cell + ": the adjacency is not symmetric (tetrahedron " + std::to_string(n) +
                                 " does not name it back)");
        }
    return topo;
}

}  // namespace

TetTopology buildTopology(const TetMesh& mesh)
{
    const std::size_t n = mesh.points.size();
    const std::size_t nt = mesh.tets.size();
    const std::string source = mesh.source.empty() ? std::string("mesh") : mesh.source;
    // Faces are numbered 4 * tet + face in 32 bits below: at most 2^30 tetrahedra (the readers allow 2^31 - 1).
    if (nt > (std::size_t{1} << 30))
        throw InputError(source + ": " + std::to_string(nt) + " tetrahedra, the limit for cell adjacency is 2^30 "
                                                              "(faces are numbered 4 tet + face in 32 bits)");
    if (!mesh.neighbors.empty() && mesh.neighbors.size() == nt)
        return topologyFromNeighbors(mesh, source);

    // Weld: points with exactly the same position get the same id (-0.0 equals 0.0 under <).
    std::vector<std::uint32_t> order(n);
    std::iota(order.begin(), order.end(), 0u);
    const auto less = [&](std::uint32_t a, std::uint32_t b) {
        const glm::dvec3 &p = mesh.points[a], &q = mesh.points[b];
        if (p.x != q.x)
            return p.x < q.x;
        if (p.y != q.y)
            return p.y < q.y;
        return p.z < q.z;
    };
    std::sort(order.begin(), order.end(), less);
    std::vector<std::uint32_t> weld(n);
    for (std::size_t i = 0; i < n; ++i)
        weld[order[i]] = (i > 0 && !less(order[i - 1], order[i])) ? weld[order[i - 1]] : order[i];

    // Every face, keyed by its three welded ids sorted; then sorted so that shared faces are adjacent.
    struct Face {
        std::uint32_t a, b, c;
        std::uint32_t tf;  // tet * 4 + face
    };
    std::vector<Face> faces(4 * nt);
    for (std::size_t t = 0; t < nt; ++t) {
        const glm::uvec4 c = mesh.tets[t];
        for (std::uint32_t f = 0; f < 4; ++f) {
            if (c[f] >= n || c[(f + 1) % 4] >= n || c[(f + 2) % 4] >= n || c[(f + 3) % 4] >= n)
                throw InternalError(cellName(mesh, t) + " has a point index out of range (call checkMesh first)");
            std::uint32_t v[3] = {weld[c[(f + 1) % 4]], weld[c[(f + 2) % 4]], weld[c[(f + 3) % 4]]};
            if (v[0] > v[1])
                std::swap(v[0], v[1]);
            if (v[1] > v[2])
                std::swap(v[1], v[2]);
            if (v[0] > v[1])
                std::swap(v[0], v[1]);
            faces[4 * t + f] = Face{v[0], v[1], v[2], static_cast<std::uint32_t>(4 * t + f)};
        }
    }
    std::sort(faces.begin(), faces.end(), [](const Face& x, const Face& y) {
        if (x.a != y.a)
            return x.a < y.a;
        if (x.b != y.b)
            return x.b < y.b;
        if (x.c != y.c)
            return x.c < y.c;
        return x.tf < y.tf;
    });

    TetTopology topo;
    topo.neighbor.assign(nt, {-1, -1, -1, -1});
    std::uint64_t firstBad = std::numeric_limits<std::uint64_t>::max();
    std::size_t badCount = 0;
    for (std::size_t i = 0; i < faces.size();) {
        std::size_t j = i + 1;
        while (j < faces.size() && faces[j].a == faces[i].a && faces[j].b == faces[i].b && faces[j].c == faces[i].c)
            ++j;
        if (j - i == 2) {
            const std::uint32_t x = faces[i].tf, y = faces[i + 1].tf;
            topo.neighbor[x / 4][x % 4] = static_cast<std::int32_t>(y / 4);
            topo.neighbor[y / 4][y % 4] = static_cast<std::int32_t>(x / 4);
        } else if (j - i > 2) {
            firstBad = std::min<std::uint64_t>(firstBad, faces[i].tf / 4);  // tf is sorted within a run
            badCount += j - i;
        }
        i = j;
    }
    if (badCount > 0) {
        const glm::uvec4 c = mesh.tets[firstBad];
        throw InputError(cellName(mesh, firstBad) + " (points " + std::to_string(c[0]) + " " + std::to_string(c[1]) + " " +
                         std::to_string(c[2]) + " " + std::to_string(c[3]) +
                         ") has a face shared by three or more tetrahedra (a non-manifold mesh)");
    }
    for (std::size_t t = 0; t < nt; ++t)
        for (std::uint32_t f = 0; f < 4; ++f)
            if (topo.neighbor[t][f] < 0)
                topo.boundary.push_back({static_cast<std::uint32_t>(t), f});
    return topo;
}

std::array<glm::dvec3, 3> outwardFace(const TetMesh& mesh, std::uint32_t tet, std::uint32_t face)
{
    const glm::uvec4 c = mesh.tets[tet];
    std::array<glm::dvec3, 3> p;
    int n = 0;
    for (std::uint32_t i = 0; i < 4; ++i)
        if (i != face)
            p[n++] = mesh.points[c[i]];
    if (glm::dot(glm::cross(p[1] - p[0], p[2] - p[0]), mesh.points[c[face]] - p[0]) > 0.0)
        std::swap(p[1], p[2]);  // the normal pointed at the opposite vertex: inward
    return p;
}

}  // namespace clvr
