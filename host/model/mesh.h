// host/model/mesh.h — a tetrahedral mesh as DESIGN.md defines it: points with one scalar each, tetrahedra
// as 4 point indices, linear interpolation inside a tetrahedron. Face i of a tetrahedron is the face
// opposite its vertex i.
#pragma once

#include <glm/glm.hpp>

#include <array>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

namespace clvr {

// A mesh cut from a larger one (sort-last cluster rendering, host/cluster/partition.h): its cells are
// those meeting the box [lo, hi], and a renderer integrates each ray only inside that box, in the
// coordinates of the full mesh's box [fullLo, fullHi] (so that every part computes as the whole would).
struct MeshPart {
    glm::dvec3 lo{0.0}, hi{0.0};
    glm::dvec3 fullLo{0.0}, fullHi{0.0};
};

struct TetMesh {
    std::vector<glm::dvec3> points;
    std::vector<double> scalars;        // one per point, data units
    std::vector<glm::uvec4> tets;       // point indices; positively oriented after checkMesh()
    std::string source;                 // file or generator, for messages

    // What checkMesh() found; --stats reports tetsRead as `tets` and tetsDegenerate as `tets_degenerate`.
    std::uint64_t tetsRead = 0;         // as read or split, before degenerate ones are dropped
    std::uint64_t tetsDegenerate = 0;   // zero volume: dropped
    std::uint64_t tetsReoriented = 0;   // inverted: vertex order fixed
    // Adjacency as a file gave it (TetGen .neigh): neighbors[t][i] is the tetrahedron across face i of t,
    // -1 on the boundary; empty when there was none. checkMesh keeps it in step with reoriented cells
    // and forgets it when cells are dropped; buildTopology checks it and then uses it.
    std::vector<std::array<std::int32_t, 4>> neighbors;
    std::optional<MeshPart> part;  // set only on a part of a larger mesh (sort-last); see MeshPart

    glm::dvec3 boundsMin() const;
    glm::dvec3 boundsMax() const;
    glm::dvec2 scalarRange() const;
};

// Validates and normalizes a mesh in place: InputError naming the first offending cell for an index
// out of range, NaN/infinite coordinates or scalars, a scalar count that differs from the point count;
// inverted tetrahedra are reoriented; zero-volume ones (|6V| <= 1e-12 * scale^3) are counted and dropped.
// Positive orientation means signedVolume6(p0, p1, p2, p3) > 0 for the tetrahedron's points in order.
void checkMesh(TetMesh& mesh);

// Six times the signed volume of (p0, p1, p2, p3): dot(p1 - p0, cross(p2 - p0, p3 - p0)).
double signedVolume6(const glm::dvec3& p0, const glm::dvec3& p1, const glm::dvec3& p2, const glm::dvec3& p3);

// Cell adjacency: neighbor[t][i] is the tetrahedron across face i of t, or -1 on the boundary.
// Faces are matched by their points' positions (coincident points are welded), so curvilinear grids
// that close on themselves with duplicated points (O-grids) are connected across the seam.
// InputError for a face shared by three or more tetrahedra (naming the first such cell).
// When mesh.neighbors is given (a TetGen .neigh) it is used instead of matching faces, after checking
// that every pair it names shares that face's three points and names each other: InputError naming the
// first cell where it does not.
struct TetTopology {
    std::vector<std::array<std::int32_t, 4>> neighbor;
    struct BoundaryFace {
        std::uint32_t tet;
        std::uint32_t face;  // 0..3, the face opposite vertex `face`
    };
    std::vector<BoundaryFace> boundary;
};
TetTopology buildTopology(const TetMesh& mesh);

// The three points of face `face` of tetrahedron `tet` (the face opposite its vertex `face`), wound so
// that (p1 - p0) x (p2 - p0) points out of the tetrahedron: counter-clockwise seen from outside.
std::array<glm::dvec3, 3> outwardFace(const TetMesh& mesh, std::uint32_t tet, std::uint32_t face);

}  // namespace clvr
