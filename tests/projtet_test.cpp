// tests/projtet_test.cpp — cell projection in visibility order (host/render/tet/projtet.h): options, the
// Shirley-Tuchman classes, the visibility order (every interior face's constraint kept, no cycles on a
// convex grid), convex box grids against the exact tetrahedral reference (perspective and parallel) and
// against harc, the centre-distance order's larger error, and identical bits twice.
#include "host/render/tet/projtet.h"

#include "host/io/mesh_io.h"
#include "host/reference/tet_reference.h"
#include "host/render/tet/harc.h"
#include "host/runtime/errors.h"
#include "tests/support/mesh_fixtures.h"
#include "tests/support/test_util.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <string>
#include <vector>

namespace clvr {
namespace {

using nlohmann::json;
using test::Box;
using test::boxMesh;
using test::perspective;

Scene makeScene(const Camera& camera, const TransferFunction& tf, int size, json options = json::object())
{
    return test::meshScene("projtet", camera, tf, size, std::move(options));
}

Image4f renderProjtet(const Scene& scene, const TetMesh& mesh, FrameStats* statsOut = nullptr)
{
    auto renderer = makeProjtetRenderer(test::device(), scene, mesh, buildTopology(mesh));
    FrameStats stats;
    Image4f image = renderer->render(stats);
    if (statsOut)
        *statsOut = stats;
    return image;
}

test::ImageError printError(const std::string& what, const Image4f& actual, const Image4d& expected)
{
    const test::ImageError e = test::imageError(actual, expected);
    std::printf("%s: max |error| (%.2g %.2g %.2g %.2g), mean (%.2g %.2g %.2g %.2g)\n", what.c_str(), e.maxAbs.r,
                e.maxAbs.g, e.maxAbs.b, e.maxAbs.a, e.meanAbs.r, e.meanAbs.g, e.meanAbs.b, e.meanAbs.a);
    return e;
}

double worst(const glm::dvec4& v) { return std::max(std::max(v.r, v.g), std::max(v.b, v.a)); }

Camera boxCamera(bool parallel)
{
    Camera camera = perspective({1.9, 1.4, 2.6});
    if (parallel) {
        camera.parallel = true;
        camera.parallelScale = 1.0;
    }
    return camera;
}

TEST(ProjtetOptions, ParsesAndRejects)
{
    EXPECT_EQ(parseProjtetOptions(json::object()).order, ProjtetOptions::Order::Mpvonc);
    EXPECT_EQ(parseProjtetOptions(json{{"order", "centroid"}}).order, ProjtetOptions::Order::Centroid);
    EXPECT_EQ(parseProjtetOptions(json{{"order", "mpvonc"}}).order, ProjtetOptions::Order::Mpvonc);
    EXPECT_THROW(parseProjtetOptions(json{{"order", "depth"}}), InputError);
    EXPECT_THROW(parseProjtetOptions(json{{"order", 1}}), InputError);
    EXPECT_THROW(parseProjtetOptions(json{{"slices", 3}}), InputError);
}

TEST(ProjtetClassify, ShirleyTuchmanClasses)
{
    // One vertex inside the others' triangle: class 1, three triangles around it.
    const ProjectedTet a = classifyProjection({glm::dvec2(0.2, 0.2), {0.0, 0.0}, {1.0, 0.0}, {0.0, 1.0}});
    EXPECT_EQ(a.kind, ProjectedTet::Kind::Class1);
    EXPECT_EQ(a.thickVertex, 0);
    EXPECT_EQ(a.triangleCount, 3);
    // A convex quadrilateral: class 2, the diagonals (0,2) x (1,3) cross at (0.5, 0.5).
    const ProjectedTet b = classifyProjection({glm::dvec2(0.0, 0.0), {1.0, 0.0}, {1.0, 1.0}, {0.0, 1.0}});
    EXPECT_EQ(b.kind, ProjectedTet::Kind::Class2);
    EXPECT_EQ(b.triangleCount, 4);
    EXPECT_NEAR(b.thick.x, 0.5, 1e-15);
    EXPECT_NEAR(b.thick.y, 0.5, 1e-15);
    // All four on a line: nothing to draw.
    EXPECT_EQ(classifyProjection({glm::dvec2(0.0), {1.0, 1.0}, {2.0, 2.0}, {3.0, 3.0}}).kind,
              ProjectedTet::Kind::Degenerate);
    // The triangles' areas add up to the silhouette's (the hull), for both classes.
    const std::array<glm::dvec2, 4> pa = {glm::dvec2(0.2, 0.2), {0.0, 0.0}, {1.0, 0.0}, {0.0, 1.0}};
    const std::array<glm::dvec2, 4> pb = {glm::dvec2(0.0, 0.0), {1.0, 0.0}, {1.0, 1.0}, {0.0, 1.0}};
    const struct { const ProjectedTet* t; const std::array<glm::dvec2, 4>* p; double hull; } cases[] = {
        {&a, &pa, 0.5}, {&b, &pb, 1.0}};
    for (const auto& c : cases) {
        double area = 0.0;
        for (int k = 0; k < c.t->triangleCount; ++k) {
            auto at = [&](int i) { return i == 4 ? c.t->thick : (*c.p)[i]; };
            const glm::dvec2 u = at(c.t->triangles[k][1]) - at(c.t->triangles[k][0]);
            const glm::dvec2 v = at(c.t->triangles[k][2]) - at(c.t->triangles[k][0]);
            area += 0.5 * std::abs(u.x * v.y - u.y * v.x);
        }
        EXPECT_NEAR(area, c.hull, 1e-12);
    }
}

// Every interior face: the cell behind it (seen from the eye) comes first in the order; no cycles on
// a convex grid, perspective and parallel.
TEST(ProjtetOrder, MpvoncKeepsEveryFaceConstraintOnAConvexGrid)
{
    const TetMesh mesh = boxMesh({{{0.0, 0.0, 0.0}, {1.0, 1.0, 1.0}, 4}}, {0.6, 0.25, -0.4}, 0.35);
    const TetTopology topology = buildTopology(mesh);
    const VisibilitySorter sorter(mesh, topology);
    for (const bool parallel : {false, true}) {
        const Camera camera = boxCamera(parallel);
        const VisibilitySorter::Result r = sorter.sort(camera, ProjtetOptions::Order::Mpvonc);
        ASSERT_EQ(r.order.size(), mesh.tets.size());
        EXPECT_EQ(r.cyclesBroken, 0u);
        std::vector<std::size_t> place(mesh.tets.size());
        for (std::size_t i = 0; i < r.order.size(); ++i)
            place[r.order[i]] = i;
        std::size_t checked = 0;
        for (std::uint32_t t = 0; t < mesh.tets.size(); ++t)
            for (std::uint32_t f = 0; f < 4; ++f) {
                const std::int32_t n = topology.neighbor[t][f];
                if (n < 0)
                    continue;
                const std::array<glm::dvec3, 3> p = outwardFace(mesh, t, f);
                const glm::dvec3 normal = glm::cross(p[1] - p[0], p[2] - p[0]);
                const double side = parallel ? -glm::dot(normal, camera.forward()) : glm::dot(normal, camera.position - p[0]);
                if (side > 1e-12) {
                    EXPECT_LT(place[t], place[n]) << "cell " << t << " is behind " << n;
                }
                ++checked;
            }
        EXPECT_GT(checked, mesh.tets.size());
        // The centroid order breaks some of them on this grid of slivers (what the technique option shows).
        const VisibilitySorter::Result c = sorter.sort(camera, ProjtetOptions::Order::Centroid);
        EXPECT_EQ(c.order.size(), mesh.tets.size());
    }
}

TEST(Projtet, ConvexBoxGridMatchesExactReference)
{
    const std::vector<Box> boxes = {{{0.0, 0.0, 0.0}, {1.0, 1.0, 1.0}, 4}};  // 384 tets
    const TetMesh mesh = boxMesh(boxes, {0.6, 0.25, -0.4}, 0.35);
    const TransferFunction tf = test::rampTransferFunction();
    for (const bool parallel : {false, true}) {
        const Camera camera = boxCamera(parallel);
        const Scene scene = makeScene(camera, tf, 64);
        FrameStats stats;
        const Image4f image = renderProjtet(scene, mesh, &stats);
        const Image4d expected = tetReferenceIntegral(mesh, tf, camera, scene.image);
        printError(parallel ? "box grid, parallel" : "box grid, perspective", image, expected);
        // harc's tolerance: float32 geometry and the 512^2 ψ table, optical depths up to ~9.
        EXPECT_TRUE(test::imagesNear(image, expected, {.maxAbs = 2e-3, .meanAbs = 2e-4}));
        EXPECT_EQ(stats.extra["order_cycles_broken"].get<std::uint64_t>(), 0u);
        EXPECT_EQ(stats.extra["cells_class1"].get<std::uint64_t>() + stats.extra["cells_class2"].get<std::uint64_t>() +
                      stats.extra["cells_degenerate_projection"].get<std::uint64_t>(),
                  mesh.tets.size());
        EXPECT_EQ(stats.extra["cells_near_plane"].get<std::uint64_t>(), 0u);
    }
}

// Non-convex: two boxes with a gap along the view and an L of three boxes. Cells of different boxes
// share no face, so only the distance priority orders them (docs/projtet.md): right on these.
TEST(Projtet, NonConvexBoxesMatchExactReference)
{
    const glm::dvec3 gradient(0.3, 0.5, 0.2);
    const std::vector<std::vector<Box>> cases = {
        {{{0.0, 0.0, 0.0}, {1.0, 1.0, 0.4}, 3}, {{0.0, 0.0, 0.7}, {1.0, 1.0, 1.1}, 3}},
        {{{0.0, 0.0, 0.0}, {0.5, 0.5, 0.5}, 2}, {{0.5, 0.0, 0.0}, {1.0, 0.5, 0.5}, 2}, {{0.0, 0.5, 0.0}, {0.5, 1.0, 0.5}, 2}},
    };
    const TransferFunction tf = test::rampTransferFunction();
    for (std::size_t k = 0; k < cases.size(); ++k)
        for (const bool parallel : {false, true}) {
            const TetMesh mesh = boxMesh(cases[k], gradient, 0.1);
            const Camera camera = boxCamera(parallel);
            const Scene scene = makeScene(camera, tf, 64);
            const Image4f image = renderProjtet(scene, mesh);
            const Image4d expected = tetReferenceIntegral(mesh, tf, camera, scene.image);
            const std::string what = std::string(k == 0 ? "gap" : "L") + (parallel ? ", parallel" : ", perspective");
            printError(what, image, expected);
            EXPECT_TRUE(test::imagesNear(image, expected, {.maxAbs = 2e-3, .meanAbs = 2e-4})) << what;
        }
}

// The camera inside the mesh: cells with a point at or behind the near plane are drawn as their front
// faces in clip space (clipped by the raster stage); only the ray part in front of the eye counts.
TEST(Projtet, CameraInsideTheMesh)
{
    const TetMesh mesh = boxMesh({{{0.0, 0.0, 0.0}, {1.0, 1.0, 1.0}, 4}}, {0.6, 0.25, -0.4}, 0.35);
    const TransferFunction tf = test::rampTransferFunction();
    const Camera camera = perspective({0.55, 0.45, 0.8}, {0.5, 0.5, 0.0}, 60.0);
    const Scene scene = makeScene(camera, tf, 64);
    FrameStats stats;
    const Image4f image = renderProjtet(scene, mesh, &stats);
    const Image4d expected = tetReferenceIntegral(mesh, tf, camera, scene.image);
    printError("camera inside", image, expected);
    std::printf("camera inside: %llu cells at the near plane\n",
                static_cast<unsigned long long>(stats.extra["cells_near_plane"].get<std::uint64_t>()));
    EXPECT_GT(stats.extra["cells_near_plane"].get<std::uint64_t>(), 0u);
    EXPECT_TRUE(test::imagesNear(image, expected, {.maxAbs = 2e-3, .meanAbs = 2e-4}));
}

TEST(Projtet, AgreesWithHarc)
{
    const TetMesh mesh = boxMesh({{{0.0, 0.0, 0.0}, {1.0, 1.0, 1.0}, 3}}, {0.5, -0.3, 0.45}, 0.2);
    const TransferFunction tf = test::rampTransferFunction();
    for (const bool parallel : {false, true}) {
        const Camera camera = boxCamera(parallel);
        Scene scene = makeScene(camera, tf, 64);
        const Image4f image = renderProjtet(scene, mesh);
        scene.technique = "harc";
        FrameStats harcStats;
        const Image4f harc = makeHarcRenderer(test::device(), scene, mesh, buildTopology(mesh))->render(harcStats);
        Image4d harcD(harc.width(), harc.height());
        for (std::size_t p = 0; p < harc.pixelCount(); ++p)
            harcD.pixels()[p] = glm::dvec4(harc.pixels()[p]);
        printError(parallel ? "vs harc, parallel" : "vs harc, perspective", image, harcD);
        EXPECT_TRUE(test::imagesNear(image, harcD, {.maxAbs = 2e-3, .meanAbs = 2e-4}));
    }
}

// The centre-distance sort is wrong where a large cell's centre is nearer than a small neighbour's in
// front of it: a Kuhn grid graded by x^4 per axis (cells from 1/256 to 0.68 wide), opaque transfer function.
TetMesh gradedBox(int n)
{
    TetMesh mesh = boxMesh({{{0.0, 0.0, 0.0}, {1.0, 1.0, 1.0}, n}}, {0.6, 0.25, -0.4}, 0.35);
    for (std::size_t p = 0; p < mesh.points.size(); ++p) {
        glm::dvec3& x = mesh.points[p];
        x = x * x * x * x;
        mesh.scalars[p] = glm::dot(glm::dvec3(0.6, 0.25, -0.4), x) + 0.35 + 0.3 * x.x * x.y;
    }
    return mesh;
}

TEST(Projtet, CentroidOrderErrsWhereMpvoncDoesNot)
{
    const TetMesh mesh = gradedBox(4);
    const TransferFunction tf({{0.0, {1.0, 0.1, 0.0}, 8.0}, {0.5, {0.0, 1.0, 0.2}, 1.0}, {1.2, {0.1, 0.2, 1.0}, 10.0}});
    const Camera camera = perspective({1.7, 0.9, 2.3});
    const Scene scene = makeScene(camera, tf, 64);
    const Image4d expected = tetReferenceIntegral(mesh, tf, camera, scene.image);
    const Image4f exact = renderProjtet(scene, mesh);
    FrameStats stats;
    const Image4f centroid = renderProjtet(makeScene(camera, tf, 64, json{{"order", "centroid"}}), mesh, &stats);
    const test::ImageError e = printError("mpvonc order", exact, expected);
    const test::ImageError c = printError("centroid order", centroid, expected);
    EXPECT_TRUE(test::imagesNear(exact, expected, {.maxAbs = 2e-3, .meanAbs = 2e-4}));
    EXPECT_EQ(stats.extra["order"].get<std::string>(), "centroid");
    EXPECT_GT(worst(c.maxAbs), 2e-2);
    EXPECT_GT(worst(c.maxAbs), 10.0 * worst(e.maxAbs));
    EXPECT_GT(worst(c.meanAbs), 2.0 * worst(e.meanAbs));
}

TEST(Projtet, IdenticalBitsTwice)
{
    const TetMesh mesh = boxMesh({{{0.0, 0.0, 0.0}, {1.0, 1.0, 1.0}, 3}}, {0.6, 0.25, -0.4}, 0.35);
    const Scene scene = makeScene(boxCamera(false), test::rampTransferFunction(), 48);
    auto renderer = makeProjtetRenderer(test::device(), scene, mesh, buildTopology(mesh));
    FrameStats stats;
    const Image4f a = renderer->render(stats);
    const Image4f b = renderer->render(stats);
    ASSERT_EQ(a.pixelCount(), b.pixelCount());
    EXPECT_EQ(std::memcmp(a.pixels().data(), b.pixels().data(), a.pixelCount() * sizeof(a.pixels()[0])), 0);
}

TEST(Projtet, RejectsAnEmptyMesh)
{
    TetMesh mesh;
    mesh.source = "empty";
    const Scene scene = makeScene(boxCamera(false), test::rampTransferFunction(), 16);
    EXPECT_THROW(makeProjtetRenderer(test::device(), scene, mesh, buildTopology(mesh)), InputError);
}

}  // namespace
}  // namespace clvr

// ---- the paper's mesh against the exact tetrahedral reference ---------------------------------------
namespace clvr {
namespace {

// bluntfin (PLOT3D, 224,874 tets) at 64², harc's mesh-test camera and transfer function
// (tests/harc_test.cpp), perspective and parallel; the centroid order's error printed beside.
TEST(ProjtetMeshes, BluntfinMatchesExactReference)
{
    TetMesh mesh = loadMesh(json{{"file", test::sharedData("bluntfin/bluntfinxyz.bin")},
                                 {"q_file", test::sharedData("bluntfin/bluntfinq.bin")},
                                 {"scalar", "density"}},
                            "/");
    const TransferFunction tf({{0.2, {0.0, 0.0, 0.3}, 0.0},
                               {0.8, {0.1, 0.3, 1.0}, 0.1},
                               {1.5, {0.2, 1.0, 0.3}, 0.4},
                               {2.5, {1.0, 0.8, 0.1}, 0.8},
                               {4.0, {1.0, 0.2, 0.1}, 1.5}});
    const glm::dvec3 lo = mesh.boundsMin(), hi = mesh.boundsMax(), center = 0.5 * (lo + hi);
    const double radius = 0.5 * glm::length(hi - lo);
    const TetTopology topology = buildTopology(mesh);
    for (const bool parallel : {false, true}) {
        Camera camera;
        camera.focalPoint = center;
        camera.position = center + radius * glm::dvec3(1.3, 0.9, 2.2);
        camera.viewUp = {0.0, 1.0, 0.0};
        camera.viewAngle = 34.0;
        if (parallel) {
            camera.parallel = true;
            camera.parallelScale = 0.8 * radius;
        }
        const Scene scene = makeScene(camera, tf, 64);
        const Image4d expected = tetReferenceIntegral(mesh, tf, camera, scene.image);
        FrameStats stats;
        const Image4f image = makeProjtetRenderer(test::device(), scene, mesh, topology)->render(stats);
        const std::string what = std::string("bluntfin") + (parallel ? ", parallel" : ", perspective");
        printError(what, image, expected);
        EXPECT_TRUE(test::imagesNear(image, expected, {.maxAbs = 2e-3, .meanAbs = 2e-4})) << what;
        std::printf("%s: %llu cycles broken, class 1 %llu, class 2 %llu\n", what.c_str(),
                    static_cast<unsigned long long>(stats.extra["order_cycles_broken"].get<std::uint64_t>()),
                    static_cast<unsigned long long>(stats.extra["cells_class1"].get<std::uint64_t>()),
                    static_cast<unsigned long long>(stats.extra["cells_class2"].get<std::uint64_t>()));
        const Scene centroidScene = makeScene(camera, tf, 64, json{{"order", "centroid"}});
        const Image4f centroid = makeProjtetRenderer(test::device(), centroidScene, mesh, topology)->render(stats);
        const test::ImageError c = printError(what + ", centroid order", centroid, expected);
        const test::ImageError e = test::imageError(image, expected);
        EXPECT_GT(worst(c.maxAbs), 10.0 * worst(e.maxAbs)) << what;  // measured: 1.9e-5 vs 7.4e-3 (perspective)
    }
}

}  // namespace
}  // namespace clvr
