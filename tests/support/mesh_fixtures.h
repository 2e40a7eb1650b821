// tests/support/mesh_fixtures.h — tetrahedral meshes made in code for the mesh techniques' tests
// (tests/harc_test.cpp, tests/tetslice_test.cpp): boxes of Kuhn-split cubes with a globally linear field,
// whose exact integral tests/harc_test.cpp computes independently and host/reference/tet_reference.h too.
#pragma once

#include "host/model/mesh.h"

#include <glm/glm.hpp>

#include <vector>

namespace clvr::test {

// Boxes of n x n x n cubes, each cube split into 6 tetrahedra along its main diagonal (Kuhn: conforming
// between cubes), scalar s(x) = dot(gradient, x) + offset at the points.
struct Box {
    glm::dvec3 lo, hi;
    int n;
};

inline void addBox(TetMesh& mesh, const Box& box)
{
    const unsigned base = static_cast<unsigned>(mesh.points.size());
    const int m = box.n + 1;
    for (int k = 0; k < m; ++k)
        for (int j = 0; j < m; ++j)
            for (int i = 0; i < m; ++i)
                mesh.points.push_back(box.lo + (box.hi - box.lo) * glm::dvec3(i, j, k) / static_cast<double>(box.n));
    auto id = [&](int i, int j, int k) { return base + static_cast<unsigned>((k * m + j) * m + i); };
    const int perms[6][3] = {{0, 1, 2}, {0, 2, 1}, {1, 0, 2}, {1, 2, 0}, {2, 0, 1}, {2, 1, 0}};
    for (int k = 0; k < box.n; ++k)
        for (int j = 0; j < box.n; ++j)
            for (int i = 0; i < box.n; ++i)
                for (const auto& perm : perms) {
                    glm::ivec3 c(i, j, k);
                    glm::uvec4 tet;
                    tet[0] = id(c.x, c.y, c.z);
                    for (int s = 0; s < 3; ++s) {
                        c[perm[s]] += 1;
                        tet[s + 1] = id(c.x, c.y, c.z);
                    }
                    mesh.tets.push_back(tet);
                }
}

inline TetMesh boxMesh(const std::vector<Box>& boxes, const glm::dvec3& gradient, double offset)
{
    TetMesh mesh;
    mesh.source = "boxes";
    for (const Box& b : boxes)
        addBox(mesh, b);
    for (const glm::dvec3& p : mesh.points)
        mesh.scalars.push_back(glm::dot(gradient, p) + offset);
    mesh.tetsRead = mesh.tets.size();
    return mesh;
}

}  // namespace clvr::test
