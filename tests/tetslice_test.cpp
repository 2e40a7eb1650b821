// tests/tetslice_test.cpp — direct slicing of tetrahedral grids through cell faces (host/render/tet/tetslice.h):
// options, the active cell lists against a brute-force cut test, and images against the exact
// tetrahedral reference (host/reference/tet_reference.h): a convex box grid and boxes with a gap (both
// cameras), the paper's meshes (bluntfin, the oxygen post) and a non-convex TetGen mesh, each with the
// error falling as the slice count grows; identical bits twice; a transfer-function change.
#include "host/render/tet/tetslice.h"

#include "host/io/mesh_io.h"
#include "host/model/scene.h"
#include "host/reference/tet_reference.h"
#include "host/runtime/errors.h"
#include "tests/support/mesh_fixtures.h"
#include "tests/support/test_util.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <map>
#include <random>
#include <string>
#include <vector>

namespace clvr {
namespace {

using nlohmann::json;

TEST(TetsliceOptions, ParsesAndRejects)
{
    EXPECT_EQ(parseTetsliceOptions(json::object()).slices, 256);
    EXPECT_EQ(parseTetsliceOptions(json{{"slices", 64}}).slices, 64);
    EXPECT_DOUBLE_EQ(parseTetsliceOptions(json{{"slice_spacing", 0.01}}).sliceSpacing, 0.01);
    EXPECT_THROW(parseTetsliceOptions(json{{"slices", 0}}), InputError);
    EXPECT_THROW(parseTetsliceOptions(json{{"slices", "many"}}), InputError);
    EXPECT_THROW(parseTetsliceOptions(json{{"slice_spacing", -1.0}}), InputError);
    EXPECT_THROW(parseTetsliceOptions(json{{"slices", 8}, {"slice_spacing", 0.1}}), InputError);
    EXPECT_THROW(parseTetsliceOptions(json{{"integration", "full"}}), InputError);  // harc's, not ours
    EXPECT_EQ(parseTetsliceOptions(json::object()).path, TetsliceOptions::Path::Fused);
    EXPECT_EQ(parseTetsliceOptions(json{{"path", "raster"}}).path, TetsliceOptions::Path::Raster);
    EXPECT_THROW(parseTetsliceOptions(json{{"path", "gpu"}}), InputError);
}

// Every slice's active list holds exactly the cells it cuts (zMin <= depth(k) <= zMax), walked back to front.
TEST(TetsliceActiveCells, EachSliceListsExactlyTheCellsItCuts)
{
    std::mt19937 rng(7);
    std::uniform_real_distribution<double> at(-0.5, 10.5), size(0.0, 1.5);
    std::vector<double> zMin(2000), zMax(2000);
    for (std::size_t c = 0; c < zMin.size(); ++c) {
        zMin[c] = at(rng);
        zMax[c] = zMin[c] + (c % 7 == 0 ? 0.0 : size(rng));  // some flat cells
    }
    const double depthMin = 0.0, deltaS = 0.1;
    const int count = 100;
    ActiveCellLists lists(zMin, zMax, depthMin, deltaS, count);
    std::uint64_t listedOnce = 0;
    std::vector<int> seen(zMin.size(), 0);
    for (int n = 0; n < count; ++n) {
        std::vector<std::uint32_t> got = lists.next();
        const int k = lists.slice();
        ASSERT_EQ(k, count - 1 - n);
        const double depth = depthMin + (k + 0.5) * deltaS;
        std::vector<std::uint32_t> want;
        for (std::uint32_t c = 0; c < zMin.size(); ++c)
            if (zMin[c] <= depth && depth <= zMax[c])
                want.push_back(c);
        std::sort(got.begin(), got.end());
        ASSERT_EQ(got, want) << "slice " << k;
        for (std::uint32_t c : got)
            listedOnce += seen[c]++ == 0 ? 1 : 0;
    }
    EXPECT_EQ(lists.cellsListed(), listedOnce);
    EXPECT_GT(listedOnce, 100u);
    EXPECT_LT(listedOnce, zMin.size());  // thin cells between slices and cells outside the slab are never drawn
    EXPECT_THROW(lists.next(), InternalError);
}

using test::meshCamera;
using test::parallelView;
using test::perspective;

Scene makeScene(const Camera& camera, const TransferFunction& tf, int size, json options = json::object())
{
    return test::meshScene("tetslice", camera, tf, size, std::move(options));
}

Image4f renderTetslice(const Scene& scene, const TetMesh& mesh, FrameStats* statsOut = nullptr)
{
    auto renderer = makeTetsliceRenderer(test::device(), scene, mesh);
    FrameStats stats;
    Image4f image = renderer->render(stats);
    if (statsOut)
        *statsOut = stats;
    return image;
}

// The worst channel's max and mean absolute error.
struct Error {
    double maxAbs = 0.0, meanAbs = 0.0;
};

Error errorOf(const char* what, int slices, const Image4f& image, const Image4d& expected)
{
    const test::ImageError e = test::imageError(image, expected);
    EXPECT_EQ(e.nanCount, 0u) << what;
    Error out;
    for (int ch = 0; ch < 4; ++ch) {
        out.maxAbs = std::max(out.maxAbs, e.maxAbs[ch]);
        out.meanAbs = std::max(out.meanAbs, e.meanAbs[ch]);
    }
    std::printf("%s, %d slices: max |error| %.3g, mean %.3g\n", what, slices, out.maxAbs, out.meanAbs);
    return out;
}

// The mesh against the exact reference at each slice count, on both paths: the mean error falls at every
// step, and the finest within `finalMean` (mean) and `finalMax` (max). And the paths against each other: the
// same slices and the same linear field per cell, interpolated between the cell's faces (raster) or
// evaluated at the ray's point (fused), so they differ by float rounding — in the faces' interpolated
// depths and scalars, ~1e-6 of the range — except where a slice lies within that rounding of a face, and a
// pixel counts a sample on one path and not on the other (the raster path's face coverage by pixel center,
// the fused path's walk). Bound: mean 2e-4, at most 2 % of the pixels over 1e-3 (measured: see the lines).
void expectConvergence(const std::string& what, const TetMesh& mesh, const Scene& base, const std::vector<int>& counts,
                       double finalMean, double finalMax)
{
    const Image4d expected = tetReferenceIntegral(mesh, base.transferFunction, *base.camera, base.image);
    std::map<int, Image4f> fused;
    for (const char* path : {"fused", "raster"}) {
        double lastMean = 1e30;
        Error e;
        for (const int n : counts) {
            Scene scene = base;
            scene.options = json{{"slices", n}, {"path", path}};
            FrameStats stats;
            const Image4f image = renderTetslice(scene, mesh, &stats);
            e = errorOf((what + ", " + path).c_str(), n, image, expected);
            EXPECT_LT(e.meanAbs, lastMean) << what << ", " << path << ", " << n << " slices";
            lastMean = e.meanAbs;
            EXPECT_EQ(stats.extra["slices"].get<int>(), n);
            EXPECT_EQ(stats.extra["path"], path);
            if (std::string(path) == "fused") {
                fused.emplace(n, image);
                continue;
            }
            Image4d raster(image.width(), image.height());
            for (std::size_t i = 0; i < image.pixelCount(); ++i)
                raster.pixels()[i] = glm::dvec4(image.pixels()[i]);
            const Image4f& f = fused.at(n);
            const test::ImageError d = test::imageError(f, raster);
            int differing = 0;
            for (std::size_t i = 0; i < f.pixelCount(); ++i) {
                const glm::dvec4 diff = glm::abs(glm::dvec4(f.pixels()[i]) - raster.pixels()[i]);
                differing += std::max({diff.r, diff.g, diff.b, diff.a}) > 1e-3;
            }
            const double dMax = std::max({d.maxAbs.r, d.maxAbs.g, d.maxAbs.b, d.maxAbs.a});
            const double dMean = std::max({d.meanAbs.r, d.meanAbs.g, d.meanAbs.b, d.meanAbs.a});
            std::printf("%s, %d slices: fused vs raster max %.3g, mean %.3g, %d pixels over 1e-3\n", what.c_str(), n,
                        dMax, dMean, differing);
            EXPECT_LE(dMean, 2e-4) << what << ", " << n << " slices";
            EXPECT_LE(differing, static_cast<int>(f.pixelCount() / 50)) << what << ", " << n << " slices";
        }
        EXPECT_LT(e.meanAbs, finalMean) << what << ", " << path;
        EXPECT_LT(e.maxAbs, finalMax) << what << ", " << path;
    }
}

TransferFunction rampTf() { return test::rampTransferFunction(); }

TEST(Tetslice, ConvexBoxGridConvergesToTheExactIntegral)
{
    const TetMesh mesh = test::boxMesh({{{0.0, 0.0, 0.0}, {1.0, 1.0, 1.0}, 4}}, {0.6, 0.25, -0.4}, 0.35);
    for (const bool parallel : {false, true}) {
        Camera camera = perspective({1.9, 1.4, 2.6}, {0.5, 0.5, 0.5}, 35.0);
        if (parallel) {
            camera.parallel = true;
            camera.parallelScale = 1.0;
        }
        expectConvergence(parallel ? "box grid, parallel" : "box grid, perspective", mesh,
                          makeScene(camera, rampTf(), 64), {32, 128, 512}, 2e-3, 2e-2);
    }
}

// Two boxes with a gap along the view direction: slices in the gap cut no cell; their back face and
// front face belong to different cells, so they add nothing.
TEST(Tetslice, GapBetweenBoxesAddsNothing)
{
    const TetMesh mesh = test::boxMesh({{{0.0, 0.0, 0.0}, {1.0, 1.0, 0.4}, 3}, {{0.0, 0.0, 0.7}, {1.0, 1.0, 1.1}, 3}},
                                       {0.3, 0.5, 0.2}, 0.1);
    const Camera camera = perspective({0.9, 0.7, 3.2}, {0.5, 0.5, 0.5}, 40.0);
    expectConvergence("two boxes with a gap", mesh, makeScene(camera, rampTf(), 64), {32, 128, 512}, 2e-3, 2e-2);
}

TEST(Tetslice, IdenticalBitsTwiceAndCellCounts)
{
    const TetMesh mesh = test::boxMesh({{{0.0, 0.0, 0.0}, {1.0, 1.0, 1.0}, 3}}, {0.6, 0.25, -0.4}, 0.35);
    const Scene scene =
        makeScene(perspective({1.9, 1.4, 2.6}, {0.5, 0.5, 0.5}, 35.0), rampTf(), 48, json{{"slices", 64}, {"path", "raster"}});
    auto renderer = makeTetsliceRenderer(test::device(), scene, mesh);
    FrameStats a, b;
    const Image4f first = renderer->render(a);
    const Image4f second = renderer->render(b);
    ASSERT_EQ(first.pixels().size(), second.pixels().size());
    EXPECT_EQ(std::memcmp(first.pixels().data(), second.pixels().data(), first.pixels().size() * sizeof(glm::vec4)), 0);
    const auto perSlice = a.extra["cells_per_slice"].get<std::vector<std::uint64_t>>();
    ASSERT_EQ(perSlice.size(), 64u);
    std::uint64_t sum = 0;
    for (std::uint64_t n : perSlice)
        sum += n;
    EXPECT_EQ(sum, a.extra["cells_drawn"].get<std::uint64_t>());
    // Each slice draws only the cells it cuts: a cell of this 3x3x3 grid spans about a third of the
    // slab's depth, so well under half of all (cell, slice) pairs; every cell is cut by some slice.
    EXPECT_LT(sum * 2, mesh.tets.size() * perSlice.size());
    EXPECT_EQ(a.extra["cells_listed"].get<std::uint64_t>(), mesh.tets.size());
    EXPECT_GT(a.extra["raster_triangles"].get<std::uint64_t>(), sum);  // about 4 faces per drawn cell
}

TEST(Tetslice, TransferFunctionChangeEqualsAFreshRenderer)
{
    const TetMesh mesh = test::boxMesh({{{0.0, 0.0, 0.0}, {1.0, 1.0, 1.0}, 3}}, {0.6, 0.25, -0.4}, 0.35);
    for (const char* path : {"fused", "raster"}) {
        const Scene scene =
            makeScene(perspective({1.9, 1.4, 2.6}, {0.5, 0.5, 0.5}, 35.0), rampTf(), 32, json{{"slices", 48}, {"path", path}});
        Scene other = scene;
        other.transferFunction = TransferFunction({{0.0, {1.0, 0.0, 0.0}, 2.0}, {1.0, {0.0, 1.0, 1.0}, 0.5}});
        auto renderer = makeTetsliceRenderer(test::device(), scene, mesh);
        FrameStats stats;
        renderer->render(stats);
        renderer->setTransferFunction(other.transferFunction);
        const Image4f changed = renderer->render(stats);
        const Image4f fresh = renderTetslice(other, mesh);
        EXPECT_EQ(std::memcmp(changed.pixels().data(), fresh.pixels().data(), fresh.pixels().size() * sizeof(glm::vec4)), 0)
            << path;
    }
}

// ---- the paper's meshes and a non-convex TetGen mesh ----------------------------------------------------

TEST(TetsliceMeshes, BluntfinConverges)
{
    TetMesh mesh = loadMesh(json{{"file", test::sharedData("bluntfin/bluntfinxyz.bin")},
                                 {"q_file", test::sharedData("bluntfin/bluntfinq.bin")},
                                 {"scalar", "density"}},
                            "/");
    const TransferFunction tf = test::bluntfinTransferFunction();
    expectConvergence("bluntfin", mesh, makeScene(meshCamera(mesh), tf, 48), {64, 256, 1024}, 2e-3, 5e-2);
}

TEST(TetsliceMeshes, PostConverges)
{
    TetMesh mesh = loadMesh(json{{"file", test::sharedData("post/post.vtk")}}, "/");
    const TransferFunction tf = test::postTransferFunction(mesh);
    expectConvergence("post", mesh, makeScene(meshCamera(mesh), tf, 48), {64, 256, 1024}, 2e-3, 5e-2);
}

// The shipped torus (a TetGen mesh made from data/surfaces at load time), seen nearly edge-on so that
// rays cross the near tube, the hole and the far tube.
TEST(TetsliceMeshes, TetgenTorusThroughItsHoleConverges)
{
    Scene scene = loadScene(test::repoData("scenes/torus.json"));
    const TetMesh mesh = loadMesh(*scene.mesh);
    scene.technique = "tetslice";
    scene.image.width = scene.image.height = 48;
    scene.camera = perspective({0.3, -2.6, 0.35}, {0.0, 0.0, 0.0}, 40.0);
    expectConvergence("torus through its hole", mesh, scene, {64, 256, 1024}, 2e-3, 5e-2);
}

}  // namespace
}  // namespace clvr

namespace clvr {
namespace {

// Inverted cells are reoriented by checkMesh and counted in --stats (tets_reoriented), degenerate ones too.
TEST(Tetslice, StatsCountReorientedAndDegenerateCells)
{
    TetMesh mesh = test::boxMesh({{{0.0, 0.0, 0.0}, {1.0, 1.0, 1.0}, 2}}, {0.6, 0.25, -0.4}, 0.35);
    checkMesh(mesh);  // the Kuhn split orients half the cells negatively
    ASSERT_GT(mesh.tetsReoriented, 0u);
    auto renderer = makeTetsliceRenderer(test::device(), makeScene(test::perspective({1.9, 1.4, 2.6}), rampTf(), 16,
                                                                   json{{"slices", 8}}), mesh);
    FrameStats stats;
    renderer->render(stats);
    EXPECT_EQ(stats.extra["tets_reoriented"].get<std::uint64_t>(), mesh.tetsReoriented);
    EXPECT_EQ(stats.extra["tets_degenerate"].get<std::uint64_t>(), mesh.tetsDegenerate);
}

// Renderer::setCamera, both paths: pointed at new cameras (the slices planned again: their count and depths
// follow the view) the renderer draws what a new renderer draws, bit for bit; a wider image it refuses.
TEST(Tetslice, SetCameraEqualsANewRenderer)
{
    const TetMesh mesh = test::boxMesh({{{0.0, 0.0, 0.0}, {1.0, 1.0, 1.0}, 3}}, {0.6, 0.25, -0.4}, 0.35);
    const Camera parallel = parallelView({2.2, -0.9, 1.1}, {0.5, 0.5, 0.5}, 0.9);
    const std::vector<Camera> cameras = {perspective({1.9, 1.4, 2.6}, {0.5, 0.5, 0.5}, 35.0),
                                         perspective({-0.8, 2.5, 0.3}, {0.5, 0.5, 0.5}, 35.0), parallel};
    for (const char* path : {"fused", "raster"})
        for (const json& slices : {json{{"slices", 40}}, json{{"slice_spacing", 0.05}}}) {
            json options = slices;
            options["path"] = path;
            test::expectSetCameraEqualsNewRenderer(
                makeScene(cameras[0], rampTf(), 29, options),
                [&](const Scene& s) { return makeTetsliceRenderer(test::device(), s, mesh); }, cameras, options.dump());
        }
}

// Ray packets on the fused path (harc's walk sampling the slices, 8 pixels per work-item): the same bits and the
// same steps and samples as one pixel per work-item — a grid from outside, parallel, two boxes with a gap (rays
// leave and re-enter), slices by count and by spacing, widths that leave lanes out of the image.
TEST(Tetslice, PacketsAreBitIdenticalToOnePixelPerWorkItem)
{
    const TetMesh grid = test::boxMesh({{{0.0, 0.0, 0.0}, {1.0, 1.0, 1.0}, 3}}, {0.6, 0.25, -0.4}, 0.35);
    const TetMesh gap = test::boxMesh({{{0.0, 0.0, 0.0}, {1.0, 1.0, 0.4}, 3}, {{0.0, 0.0, 0.7}, {1.0, 1.0, 1.1}, 3}},
                                      {0.3, 0.5, 0.2}, 0.1);
    const Camera parallel = parallelView({2.2, -0.9, 1.1}, {0.5, 0.5, 0.5}, 0.9);
    struct Case {
        const char* name;
        const TetMesh* mesh;
        Camera camera;
        json options;
    };
    const Case cases[] = {{"grid", &grid, perspective({1.9, 1.4, 2.6}, {0.5, 0.5, 0.5}, 35.0), {{"slices", 40}}},
                          {"grid, parallel, by spacing", &grid, parallel, {{"slice_spacing", 0.03}}},
                          {"gap", &gap, perspective({0.9, 0.7, 3.2}, {0.5, 0.5, 0.5}, 40.0), {{"slices", 64}}}};
    for (const Case& c : cases)
        for (const int width : {61, 5}) {
            Scene scene = makeScene(c.camera, rampTf(), width, c.options);
            scene.image.height = 33;
            const FrameStats stats = test::expectPacketsEqualPixels(
                scene, [&](const Scene& s, FrameStats& st) { return renderTetslice(s, *c.mesh, &st); }, {"steps"},
                std::string(c.name) + ", width " + std::to_string(width));
            EXPECT_GT(stats.samples, 0u) << c.name;
        }
}

}  // namespace
}  // namespace clvr
