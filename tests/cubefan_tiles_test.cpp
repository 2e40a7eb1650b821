// tests/cubefan_tiles_test.cpp — cubefan's tile path ("path": "tiles", host/render/grid/cubefan.h): the selected
// cubes ordered for the eye, boxed, binned to tiles and met by each tile's rays. Against the walk of the fused path
// (the same chords, found another way) and the exact integral of the cube field; its packets against one pixel per
// work-item bit for bit; early termination.
#include "host/render/grid/cubefan.h"

#include "host/io/generators.h"
#include "host/reference/cube_reference.h"
#include "raster/reference/pixel_transfer.h"
#include "tests/support/test_util.h"

#include <gtest/gtest.h>

#include <cstdio>
#include <string>

namespace clvr {
namespace {

using nlohmann::json;

Scene makeScene(const Camera& camera, const TransferFunction& tf, int width, int height, json options)
{
    Scene s;
    s.technique = "cubefan";
    s.camera = camera;
    s.image = ImageSpec{width, height, {0.1, 0.2, 0.3}};
    s.transferFunction = tf;
    s.options = std::move(options);
    return s;
}

Image4f render(const Scene& scene, const Volume& volume, FrameStats& stats)
{
    return makeCubefanRenderer(test::device(), scene, volume)->render(stats);
}

double worst(const glm::dvec4& v) { return std::max(std::max(v.r, v.g), std::max(v.b, v.a)); }

std::uint64_t count(const FrameStats& s, const char* key) { return s.extra[key].get<std::uint64_t>(); }

Camera eyeInside()
{
    Camera c;
    c.position = {0.13, -0.07, 0.41};
    c.focalPoint = {0.3, 0.2, -1.0};
    c.viewAngle = 70.0;
    return c;
}

// A parallel view straight down z with the image spanning the cube field: every pixel centre on a cube face (the
// rays run in the planes between columns of cubes, or through their middles).
Camera downTheAxis()
{
    Camera c;
    c.parallel = true;
    c.focalPoint = glm::dvec3(0.0);
    c.position = {0.0, 0.0, 3.0};
    c.viewUp = {0, 1, 0};
    c.parallelScale = 20.0 / 19.0;
    return c;
}

// The tile path's chords are the walk's, each from its own slab test instead of the walk's last exit: the images
// agree to float rounding, and with error 0 both are the exact integral of the cube field. An image 61 x 43 (neither
// a multiple of the 8 x 4 tiles), tolerances 0, 0.1 and 0.3, four views (the eye inside the volume among them).
TEST(CubefanTiles, DrawTheWalksImage)
{
    const Volume volume = generateVolume("marschner-lobb", {20, 20, 20});
    const TransferFunction tf = test::designTransferFunction();
    const struct {
        const char* name;
        Camera camera;
    } views[] = {{"perspective", test::obliquePerspectiveCamera(30.0)},
                 {"parallel", test::obliqueParallelCamera(1.3)},
                 {"eye inside", eyeInside()},
                 {"down the z axis", downTheAxis()}};
    for (const auto& view : views)
        for (const double tolerance : {0.0, 0.1, 0.3}) {
            const std::string what = std::string(view.name) + ", error " + std::to_string(tolerance);
            FrameStats tileStats, walkStats;
            const Image4f tiles =
                render(makeScene(view.camera, tf, 61, 43, {{"error", tolerance}, {"path", "tiles"}}), volume, tileStats);
            const Image4f walk =
                render(makeScene(view.camera, tf, 61, 43, {{"error", tolerance}, {"path", "fused"}}), volume, walkStats);
            EXPECT_EQ(tileStats.extra["path"], "tiles");
            EXPECT_EQ(walkStats.extra["path"], "fused");
            EXPECT_EQ(count(tileStats, "cubes"), count(walkStats, "cubes")) << what;
            // the chords that add color: the walk also counts a cube it leaves where it entered (a zero chord)
            const double crossed = static_cast<double>(count(tileStats, "cubes_crossed"));
            EXPECT_GT(crossed, 0.0) << what;
            EXPECT_LE(crossed, static_cast<double>(count(walkStats, "cubes_crossed"))) << what;
            EXPECT_GT(crossed, 0.99 * static_cast<double>(count(walkStats, "cubes_crossed"))) << what;
            const test::ImageError e = test::imageError(tiles, clvr::raster::reference::toDouble(walk));
            std::printf("tiles vs walk, %s: max |error| %.2e, mean %.2e; %llu chords, %llu tile entries\n", what.c_str(),
                        worst(e.maxAbs), worst(e.meanAbs), static_cast<unsigned long long>(crossed),
                        static_cast<unsigned long long>(count(tileStats, "tile_entries")));
            EXPECT_EQ(e.nanCount, 0u);
            EXPECT_LT(worst(e.maxAbs), 2e-5) << what;
            // Fewer than half as many tile entries as chords on these volumes (0.05-0.34 measured): no cube is listed
            // where no ray sees it. With an eye inside the volume, the cubes behind it boxed as the whole image had made
            // 245 k entries for 61 k chords, and the cubes crossing its plane so boxed 53 k; clipped at z_near, 7 k.
            EXPECT_LT(static_cast<double>(count(tileStats, "tile_entries")), 0.5 * crossed) << what;
            if (tolerance == 0.0) {
                const Image4d exact = cubeFieldIntegral(volume, tf, view.camera, makeScene(view.camera, tf, 61, 43, {}).image);
                EXPECT_TRUE(test::imagesNear(tiles, exact, {.maxAbs = 1e-4, .meanAbs = 1e-6})) << what;
            }
        }
}

// One pixel per work-item (cubefan_tiles) and a tile per work-item (cubefan_tiles_packet, two rows of 8 as 16
// lanes) are the same bits, and count the same chords: perspective, parallel, the eye inside, down an axis;
// tolerances 0, 0.1 and 0.3 and early termination; images 61 and 5 wide, 23 rows (a last tile of 3).
TEST(CubefanTiles, PacketsAreBitIdenticalToOnePixelPerWorkItem)
{
    const Volume blobs = generateVolume("blobs", {41, 37, 30});
    const TransferFunction sparse({{0.0, {0, 0, 0}, 0.0}, {0.35, {0, 0, 0}, 0.0}, {0.6, {1, 0.5, 0}, 6.0}, {1.0, {1, 1, 1}, 14.0}});
    const Camera cameras[] = {test::obliquePerspectiveCamera(30.0), test::obliqueParallelCamera(1.3), eyeInside(),
                              downTheAxis()};
    const json sets[] = {{{"error", 0.0}}, {{"error", 0.1}}, {{"error", 0.3}}, {{"error", 0.05}, {"early_termination", 0.6}}};
    int compared = 0;
    for (const Camera& camera : cameras)
        for (json set : sets)
            for (const int width : {61, 5}) {
                set["path"] = "tiles";
                const Scene scene = makeScene(camera, sparse, width, 23, set);
                const FrameStats stats = test::expectPacketsEqualPixels(
                    scene, [&](const Scene& s, FrameStats& st) { return render(s, blobs, st); }, {"cubes_crossed"},
                    set.dump() + " width " + std::to_string(width) + " camera " + std::to_string(&camera - cameras));
                EXPECT_GT(count(stats, "cubes_crossed"), 0u) << set.dump();
                ++compared;
            }
    EXPECT_EQ(compared, 4 * 4 * 2);
}

// Early termination on the tile path: a pixel stops taking cubes once its opacity reaches the threshold, so it
// differs from the full image by at most 1 - threshold, reaches the threshold where the full image does, and is the
// same bits where it never does; fewer chords in all.
TEST(CubefanTiles, EarlyTerminationStopsAtTheThreshold)
{
    const Volume volume = generateVolume("marschner-lobb", {20, 20, 20});
    const TransferFunction tf = test::designTransferFunction(4.0);
    const Camera camera = test::obliquePerspectiveCamera(30.0);
    const double threshold = 0.6;
    FrameStats fullStats, earlyStats;
    const Image4f full = render(makeScene(camera, tf, 48, 48, {{"path", "tiles"}}), volume, fullStats);
    const Image4f early =
        render(makeScene(camera, tf, 48, 48, {{"path", "tiles"}, {"early_termination", threshold}}), volume, earlyStats);
    EXPECT_LT(count(earlyStats, "cubes_crossed"), count(fullStats, "cubes_crossed"));
    EXPECT_GT(test::expectEarlyTermination(full, early, threshold), 48 * 48 / 10);
}

}  // namespace
}  // namespace clvr
