// tests/support/mesh_fixtures.h — what the mesh techniques' tests share (tests/harc_test.cpp,
// tests/tetslice_test.cpp, tests/tetiso_test.cpp): boxes of Kuhn-split cubes with a globally linear field
// (whose exact integral tests/harc_test.cpp computes independently, host/reference/tet_reference.h too), a
// perspective camera, and a scene for a mesh technique.
#pragma once

#include "host/model/camera.h"
#include "host/model/mesh.h"
#include "host/model/scene.h"
#include "host/model/transfer_function.h"

#include <glm/glm.hpp>
#include <nlohmann/json.hpp>

#include <string>
#include <utility>
#include <vector>

namespace clvr::test {

// Boxes of n x n x n cubes, each cube split into 6 tetrahedra along its main diagonal (Kuhn: conforming
// between cubes), scalar s(x) = dot(gradient, x) + offset at the points.
struct Box {
    glm::dvec3 lo, hi;
    int n;
};

// The box [lo, hi] as a grid of n.x x n.y x n.z cubes, 6 tetrahedra each (Freudenthal's split: the same diagonal in
// every cube, so neighbours share faces), its points x fastest.
inline void addGrid(TetMesh& mesh, const glm::dvec3& lo, const glm::dvec3& hi, const glm::ivec3& n)
{
    const unsigned base = static_cast<unsigned>(mesh.points.size());
    const glm::ivec3 m = n + 1;
    for (int k = 0; k < m.z; ++k)
        for (int j = 0; j < m.y; ++j)
            for (int i = 0; i < m.x; ++i)
                mesh.points.push_back(lo + (hi - lo) * glm::dvec3(i, j, k) / glm::dvec3(n));
    auto id = [&](int i, int j, int k) { return base + static_cast<unsigned>((k * m.y + j) * m.x + i); };
    const int perms[6][3] = {{0, 1, 2}, {0, 2, 1}, {1, 0, 2}, {1, 2, 0}, {2, 0, 1}, {2, 1, 0}};
    for (int k = 0; k < n.z; ++k)
        for (int j = 0; j < n.y; ++j)
            for (int i = 0; i < n.x; ++i)
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

inline void addBox(TetMesh& mesh, const Box& box)
{
    addGrid(mesh, box.lo, box.hi, glm::ivec3(box.n));
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

// Five control points on [0, 1] with tau up to 6 per unit and color kinks (the harc, tetslice and
// pre-integration tests' transfer function): segments of length 1.5 reach optical depths near 9.
inline TransferFunction rampTransferFunction()
{
    return TransferFunction({{0.0, {0.0, 0.0, 0.2}, 0.0},
                             {0.3, {1.0, 0.5, 0.0}, 3.0},
                             {0.55, {0.2, 1.0, 0.3}, 0.5},
                             {0.8, {1.0, 1.0, 1.0}, 6.0},
                             {1.0, {0.3, 0.2, 1.0}, 1.0}});
}

// The real-mesh tests' camera (harc, projtet, tetslice, tetiso): fitted to the bounds, looking at their
// centre from the oblique direction (1.3, 0.9, 2.2) times the bounding radius, 34 degrees; parallel with
// a parallel scale of 0.8 bounding radii.
inline Camera meshCamera(const TetMesh& mesh, bool parallel = false)
{
    const glm::dvec3 lo = mesh.boundsMin(), hi = mesh.boundsMax(), center = 0.5 * (lo + hi);
    const double radius = 0.5 * glm::length(hi - lo);
    Camera camera;
    camera.focalPoint = center;
    camera.position = center + radius * glm::dvec3(1.3, 0.9, 2.2);
    camera.viewUp = {0.0, 1.0, 0.0};
    camera.viewAngle = 34.0;
    if (parallel) {
        camera.parallel = true;
        camera.parallelScale = 0.8 * radius;
    }
    return camera;
}

// The bluntfin tests' transfer function on its density (0.2 .. 4, tau up to 1.5 per unit).
inline TransferFunction bluntfinTransferFunction()
{
    return TransferFunction({{0.2, {0.0, 0.0, 0.3}, 0.0},
                             {0.8, {0.1, 0.3, 1.0}, 0.1},
                             {1.5, {0.2, 1.0, 0.3}, 0.4},
                             {2.5, {1.0, 0.8, 0.1}, 0.8},
                             {4.0, {1.0, 0.2, 0.1}, 1.5}});
}

// The oxygen post tests' transfer function: on the mesh's scalar range, tau up to 8 per bounding diagonal.
inline TransferFunction postTransferFunction(const TetMesh& mesh)
{
    const glm::dvec2 range = mesh.scalarRange();
    auto at = [&](double f) { return range.x + f * (range.y - range.x); };
    const double size = glm::length(mesh.boundsMax() - mesh.boundsMin());
    return TransferFunction({{at(0.0), {0.1, 0.1, 0.5}, 0.0},
                             {at(0.3), {0.2, 0.6, 1.0}, 1.0 / size},
                             {at(0.6), {0.9, 0.9, 0.2}, 3.0 / size},
                             {at(1.0), {1.0, 0.3, 0.1}, 8.0 / size}});
}

// A perspective camera with +y up.
inline Camera perspective(glm::dvec3 position, glm::dvec3 focal = {0.5, 0.5, 0.5}, double angle = 35.0)
{
    Camera c;
    c.position = position;
    c.focalPoint = focal;
    c.viewUp = {0.0, 1.0, 0.0};
    c.viewAngle = angle;
    return c;
}

// A parallel camera with +y up, `scale` half the view's height.
inline Camera parallelView(glm::dvec3 position, glm::dvec3 focal, double scale)
{
    Camera c = perspective(position, focal);
    c.parallel = true;
    c.parallelScale = scale;
    return c;
}

// A size x size scene of `technique` with `camera`, `tf`, `options`, on the background (0.1, 0.2, 0.3).
inline Scene meshScene(const std::string& technique, const Camera& camera, const TransferFunction& tf, int size,
                       nlohmann::json options = nlohmann::json::object())
{
    Scene s;
    s.technique = technique;
    s.camera = camera;
    s.image = ImageSpec{size, size, {0.1, 0.2, 0.3}};
    s.transferFunction = tf;
    s.options = std::move(options);
    return s;
}

}  // namespace clvr::test
