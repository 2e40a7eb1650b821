// tests/cubefan_render_test.cpp — the cubefan renderer (host/render/grid/cubefan.h) against the exact
// integral of the piecewise-constant cube field (host/reference/cube_reference.h): error 0 in
// perspective and parallel, the eye inside the volume, the three opacity modes, and the image error of
// the hierarchy as a function of the tolerance.
#include "host/render/grid/cubefan.h"

#include "host/io/generators.h"
#include "host/io/volume_io.h"
#include "host/reference/cube_reference.h"
#include "host/runtime/errors.h"
#include "raster/reference/pixel_transfer.h"
#include "tests/support/test_util.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

namespace clvr {
namespace {

using nlohmann::json;

Scene makeScene(const Camera& camera, const TransferFunction& tf, int size, json options = json::object())
{
    Scene s;
    s.technique = "cubefan";
    s.camera = camera;
    s.image = ImageSpec{size, size, {0.1, 0.2, 0.3}};
    s.transferFunction = tf;
    s.options = std::move(options);
    return s;
}

Image4f render(const Scene& scene, const Volume& volume, FrameStats* statsOut = nullptr)
{
    FrameStats stats;
    Image4f image = makeCubefanRenderer(test::device(), scene, volume)->render(stats);
    if (statsOut)
        *statsOut = stats;
    return image;
}

double worst(const glm::dvec4& v) { return std::max(std::max(v.r, v.g), std::max(v.b, v.a)); }

test::ImageError printError(const std::string& what, const Image4f& actual, const Image4d& expected)
{
    const test::ImageError e = test::imageError(actual, expected);
    std::printf("%s: max |error| %.2e, mean %.2e\n", what.c_str(), worst(e.maxAbs), worst(e.meanAbs));
    return e;
}

// Marschner-Lobb on 20^3 points in [-1, 1]^3 (cubes of 0.105), DESIGN.md's transfer function with tau
// up to 8: optical depths up to 1.5 per cube, so the cubes' exponentials are far from linear.
Volume smallVolume() { return generateVolume("marschner-lobb", {20, 20, 20}); }

std::uint64_t count(const FrameStats& s, const char* key) { return s.extra[key].get<std::uint64_t>(); }

TEST(CubefanOptions, ParsesAndRejects)
{
    const CubefanOptions o = parseCubefanOptions({{"error", 0.18}, {"opacity", "linear"}, {"texture_size", 64}});
    EXPECT_EQ(o.error, 0.18);
    EXPECT_EQ(o.opacity, CubefanOptions::Opacity::Linear);
    EXPECT_EQ(o.textureSize, 64);
    EXPECT_EQ(parseCubefanOptions({{"opacity", "exp"}}).opacity, CubefanOptions::Opacity::Exp);
    EXPECT_TRUE(parseCubefanOptions({{"thickness", "exact"}}).exactThickness);
    EXPECT_FALSE(parseCubefanOptions({{"thickness", "interpolated"}}).exactThickness);
    // The fused path by default at error 0, the tile path where cubes merge; the fans' options take the raster path
    // unless another is asked for.
    EXPECT_EQ(parseCubefanOptions(json::object()).path, CubefanOptions::Path::Fused);
    EXPECT_EQ(parseCubefanOptions({{"error", 0.0}}).path, CubefanOptions::Path::Fused);
    EXPECT_EQ(parseCubefanOptions({{"error", 0.01}}).path, CubefanOptions::Path::Tiles);
    EXPECT_EQ(parseCubefanOptions({{"error", 0.2}, {"path", "fused"}}).path, CubefanOptions::Path::Fused);
    EXPECT_EQ(parseCubefanOptions({{"path", "tiles"}}).path, CubefanOptions::Path::Tiles);
    EXPECT_EQ(parseCubefanOptions({{"error", 0.2}, {"thickness", "exact"}}).path, CubefanOptions::Path::Raster);
    EXPECT_EQ(parseCubefanOptions({{"error", 0.2}, {"early_termination", 0.9}}).earlyTermination, 0.9);
    EXPECT_EQ(o.path, CubefanOptions::Path::Raster);
    EXPECT_EQ(parseCubefanOptions({{"thickness", "exact"}}).path, CubefanOptions::Path::Raster);
    EXPECT_EQ(parseCubefanOptions({{"path", "raster"}}).path, CubefanOptions::Path::Raster);
    EXPECT_EQ(parseCubefanOptions({{"opacity", "texture"}, {"thickness", "interpolated"}}).path, CubefanOptions::Path::Fused);
    for (const json& bad : {json{{"error", -0.1}}, json{{"error", 1.5}}, json{{"error", "0.1"}}, json{{"thickness", 1}},
                            json{{"opacity", "gouraud"}}, json{{"texture_size", 1}}, json{{"texture_size", 1e4}},
                            json{{"path", "fans"}}, json{{"path", "fused"}, {"opacity", "exp"}},
                            json{{"path", "fused"}, {"thickness", "exact"}}, json{{"path", "tiles"}, {"opacity", "exp"}},
                            json{{"early_termination", 0.0}},
                            json{{"path", "raster"}, {"early_termination", 0.9}}, json{{"opacity", "exp"}, {"early_termination", 0.9}}})
        EXPECT_THROW(parseCubefanOptions(bad), InputError) << bad.dump();
}

TEST(CubefanTexture, TexelsHoldOneMinusExpOfTheProduct)
{
    const int n = 9;
    const double k = 7.5;
    const std::vector<float> t = expOpacityTexels(n, k);
    ASSERT_EQ(t.size(), 81u);
    for (int j = 0; j < n; ++j)
        for (int i = 0; i < n; ++i)
            EXPECT_NEAR(t[j * n + i], 1.0 - std::exp(-k * (i / 8.0) * (j / 8.0)), 1e-7) << i << "," << j;
    EXPECT_EQ(t[0], 0.0f);
    EXPECT_EQ(t[8], 0.0f);  // v = 0: no extinction, no opacity at any length
}

// Error 0: every voxel is its own cube (or a merged cube of equal voxels), so the image is the cube
// field's exact integral up to the thickness's linear interpolation across each triangle (exact for
// parallel projection, §7), the 512^2 texture's bilinear error and float rounding. The largest errors
// (a few pixels in 4096 over 1e-3) sit on the volume's silhouette, where faces seen edge-on project to
// slivers a small fraction of a pixel wide and the raster stage's 1/256-pixel vertex snapping moves
// their thickness gradient by a few per cent; the mean stays at 1e-4.
TEST(CubefanRenderer, ErrorZeroMatchesTheExactCubeFieldIntegral)
{
    const Volume volume = smallVolume();
    const TransferFunction tf = test::designTransferFunction();
    for (const bool parallel : {false, true}) {
        const Camera camera = parallel ? test::obliqueParallelCamera(1.3) : test::obliquePerspectiveCamera(30.0);
        const std::string view = parallel ? "parallel" : "perspective";
        const Image4d expected = cubeFieldIntegral(volume, tf, camera, makeScene(camera, tf, 64).image);
        double errorOf[4] = {0, 0, 0, 0};
        int m = 0;
        for (const char* opacity : {"texture", "exp", "linear", "exact thickness"}) {
            const bool exact = std::string(opacity) == "exact thickness";
            const json options = exact ? json{{"thickness", "exact"}} : json{{"opacity", opacity}, {"path", "raster"}};
            FrameStats stats;
            const Image4f image = render(makeScene(camera, tf, 64, options), volume, &stats);
            const test::ImageError e = printError(view + ", " + opacity, image, expected);
            errorOf[m++] = worst(e.maxAbs);
            EXPECT_EQ(e.nanCount, 0u);
            EXPECT_EQ(count(stats, "cubes_near_plane"), 0u);
            EXPECT_EQ(count(stats, "cubes_class1") + count(stats, "cubes_class2") + count(stats, "cubes_class3a") +
                          count(stats, "cubes_class3b") + count(stats, "cubes_as_back_faces") + count(stats, "cubes_culled"),
                      count(stats, "cubes"));
            EXPECT_EQ(count(stats, "cubes_as_back_faces") == count(stats, "cubes") - count(stats, "cubes_culled"), exact);
            if (exact) {  // the chord per fragment: float rounding only
                EXPECT_TRUE(test::imagesNear(image, expected, {.maxAbs = 5e-4, .meanAbs = 1e-5})) << view;
            }
            if (std::string(opacity) != "linear") {
                EXPECT_TRUE(test::imagesNear(image, expected, {.maxAbs = 1e-2, .meanAbs = 4e-4})) << view << ", " << opacity;
            }
        }
        // Linear opacity across a cube whose optical depth reaches 1.5 is visibly wrong (§7).
        EXPECT_GT(errorOf[2], 5.0 * errorOf[0]) << view;
        // The texture is what the fragments read: at 512^2 (k = l_max tau_max = 1.5 here) it is the
        // exponential to 1e-5; at 4^2 its bilinear error shows.
        const Image4d expD = clvr::raster::reference::toDouble(render(makeScene(camera, tf, 64, {{"opacity", "exp"}}), volume));
        const Image4f texture = render(makeScene(camera, tf, 64, {{"path", "raster"}}), volume);
        const Image4f coarse = render(makeScene(camera, tf, 64, {{"texture_size", 4}}), volume);
        const double tableError = worst(test::imageError(texture, expD).maxAbs);
        const double coarseError = worst(test::imageError(coarse, expD).maxAbs);
        std::printf("%s: texture 512^2 vs exp %.2e, 4^2 vs exp %.2e\n", view.c_str(), tableError, coarseError);
        EXPECT_LT(tableError, 1e-5) << view;
        EXPECT_GT(coarseError, 1e-3) << view;
    }
}

// The eye inside the volume: the cubes at the near plane (the one holding the eye among them) are drawn as
// their back faces with the chord per fragment; cubes behind the eye or beside the view are culled. With
// exact thickness every cube takes that path, so the bound is the far view's. With the fans the cubes
// close to the eye cover many pixels, and across them the screen-linear thickness departs from the
// perspective chord (§7's approximation: the template test prints it): a looser bound.
TEST(CubefanRenderer, EyeInsideTheVolume)
{
    const Volume volume = smallVolume();
    const TransferFunction tf = test::designTransferFunction(2.0);
    Camera camera;
    camera.position = {0.13, -0.07, 0.41};
    camera.focalPoint = {0.3, 0.2, -1.0};
    camera.viewAngle = 70.0;
    const Image4d expected = cubeFieldIntegral(volume, tf, camera, makeScene(camera, tf, 64).image);
    for (const bool exact : {true, false}) {
        const Scene scene = makeScene(camera, tf, 64, {{"thickness", exact ? "exact" : "interpolated"}, {"path", "raster"}});
        FrameStats stats;
        const Image4f image = render(scene, volume, &stats);
        const std::string what = exact ? "eye inside, exact thickness" : "eye inside, fans";
        printError(what, image, expected);
        std::printf("%s: %llu cubes, %llu at the near plane, %llu culled\n", what.c_str(),
                    static_cast<unsigned long long>(count(stats, "cubes")),
                    static_cast<unsigned long long>(count(stats, "cubes_near_plane")),
                    static_cast<unsigned long long>(count(stats, "cubes_culled")));
        EXPECT_GT(count(stats, "cubes_near_plane"), 0u);
        EXPECT_GT(count(stats, "cubes_culled"), count(stats, "cubes") / 4);
        if (!exact) {  // from inside, every template is drawn: cubes in the eye's rows and columns show 1 or 2 faces
            for (const char* key : {"cubes_class1", "cubes_class2", "cubes_class3a", "cubes_class3b"})
                EXPECT_GT(count(stats, key), 0u) << key;
        }
        if (exact) {
            EXPECT_TRUE(test::imagesNear(image, expected, {.maxAbs = 2e-3, .meanAbs = 2e-4})) << what;
        } else {
            EXPECT_TRUE(test::imagesNear(image, expected, {.maxAbs = 2e-2, .meanAbs = 3e-3})) << what;
        }
    }
}

// With a tolerance the octree merges cubes: fewer cubes and triangles, and an image error against the
// full-resolution cube field that grows with the tolerance (printed as a table, docs/cubefan.md).
TEST(CubefanRenderer, ToleranceTradesCubesForError)
{
    const Volume volume = generateVolume("marschner-lobb", {33, 33, 33});
    const TransferFunction tf = test::designTransferFunction();
    const Camera camera = test::obliquePerspectiveCamera(30.0);
    const Scene base = makeScene(camera, tf, 64);
    const Image4d expected = cubeFieldIntegral(volume, tf, camera, base.image);
    std::uint64_t lastCubes = 0, lastTriangles = 0;
    double errorAtZero = 0.0;
    std::printf("error tolerance | cubes | triangles | max |error| | mean |error|\n");
    for (const double tolerance : {0.0, 0.05, 0.1, 0.2, 0.4}) {
        FrameStats stats;
        const Image4f image = render(makeScene(camera, tf, 64, {{"error", tolerance}, {"path", "raster"}}), volume, &stats);
        const test::ImageError e = test::imageError(image, expected);
        const std::uint64_t cubes = count(stats, "cubes"), triangles = count(stats, "triangles");
        std::printf("%.2f | %llu | %llu | %.3e | %.3e\n", tolerance, static_cast<unsigned long long>(cubes),
                    static_cast<unsigned long long>(triangles), worst(e.maxAbs), worst(e.meanAbs));
        EXPECT_EQ(e.nanCount, 0u);
        if (tolerance == 0.0) {
            errorAtZero = worst(e.meanAbs);
            EXPECT_TRUE(test::imagesNear(image, expected, {.maxAbs = 1e-2, .meanAbs = 4e-4}));
        } else {
            EXPECT_LT(cubes, lastCubes) << tolerance;
            EXPECT_LT(triangles, lastTriangles) << tolerance;
            EXPECT_GT(worst(e.meanAbs), 10.0 * errorAtZero) << tolerance;  // merged cubes: visibly coarser
        }
        lastCubes = cubes;
        lastTriangles = triangles;
    }
}

// The engine (the Figure 9 experiment's data and view, data/scenes/engine-cubefan.json, at 96^2): error 0
// against the exact cube-field integral, then 18 % and 48 % with fewer cubes and a growing error.
TEST(CubefanRenderer, EngineAtTheThreeTolerancesOfFigure9)
{
    const Volume volume = readNrrd(test::sharedData("engine/engine.nrrd"));
    const TransferFunction tf({{0, {0, 0, 0}, 0}, {60, {0, 0, 0}, 0}, {90, {0.3, 0.5, 0.9}, 0.01},
                               {160, {0.6, 0.7, 0.9}, 0.02}, {200, {1.0, 0.7, 0.3}, 0.08}, {255, {1.0, 1.0, 0.9}, 0.2}});
    Camera camera;
    camera.position = {560, -260, 330};
    camera.focalPoint = {127.5, 127.5, 63.5};
    camera.viewUp = {0, 0, 1};
    const Scene scene = makeScene(camera, tf, 96);
    const Image4d expected = cubeFieldIntegral(volume, tf, camera, scene.image);
    for (const char* path : {"raster", "fused"}) {
        std::uint64_t lastCubes = ~std::uint64_t(0);
        double lastError = 0.0;
        for (const double tolerance : {0.0, 0.18, 0.48}) {
            Scene s = scene;
            s.options = {{"error", tolerance}, {"path", path}};
            FrameStats stats;
            const Image4f image = render(s, volume, &stats);
            const test::ImageError e =
                printError(std::string("engine, ") + path + ", error " + std::to_string(tolerance), image, expected);
            const std::uint64_t cubes = count(stats, "cubes");
            EXPECT_LT(cubes, lastCubes);
            if (std::string(path) == "fused") {  // the walk steps over the empty bricks (the image shows it changes nothing)
                EXPECT_GT(count(stats, "empty_bricks"), 0u);
            }
            if (tolerance == 0.0 && std::string(path) == "raster")  // the fans' interpolated thickness
                EXPECT_TRUE(test::imagesNear(image, expected, {.maxAbs = 1e-2, .meanAbs = 2e-4}));
            else if (tolerance == 0.0)  // every chord exact: float rounding only
                EXPECT_TRUE(test::imagesNear(image, expected, {.maxAbs = 5e-4, .meanAbs = 1e-6}));
            else
                EXPECT_GT(worst(e.meanAbs), 2.0 * lastError) << tolerance;
            lastCubes = cubes;
            lastError = worst(e.meanAbs);
        }
    }
}

TEST(CubefanRenderer, IdenticalBitsTwiceAndAfterATransferFunctionEdit)
{
    const Volume volume = smallVolume();
    const Camera camera = test::obliquePerspectiveCamera(30.0);
    for (const char* path : {"raster", "fused"}) {
        const Scene scene = makeScene(camera, test::designTransferFunction(), 48, {{"error", 0.1}, {"path", path}});
        auto renderer = makeCubefanRenderer(test::device(), scene, volume);
        FrameStats stats;
        const Image4f a = renderer->render(stats);
        const Image4f b = renderer->render(stats);
        EXPECT_TRUE(a.pixels() == b.pixels()) << path;
        // A new transfer function changes tau_max (the texture's k) and the transparent cubes (the fused
        // path's selection grid).
        const TransferFunction other = test::designTransferFunction(20.0);
        renderer->setTransferFunction(other);
        const Image4f edited = renderer->render(stats);
        Scene fresh = scene;
        fresh.transferFunction = other;
        EXPECT_TRUE(edited.pixels() == render(fresh, volume).pixels()) << path;
        EXPECT_FALSE(edited.pixels() == a.pixels()) << path;
    }
}

// The fused path walks each pixel's ray through the same selected cubes and adds every chord exactly:
// the image of the raster path with exact thickness (each fragment's own chord through its cube's back
// faces), up to float rounding in a different order of operations (front to back against the blending's
// back to front). Perspective, parallel, the eye inside the volume, at several tolerances (merged cubes of
// 2 to 16 voxels); the cubes counted are the same; at tolerance 0 both are the exact cube-field integral.
TEST(CubefanFused, IsTheExactThicknessImageOfTheRasterPath)
{
    const Volume volume = generateVolume("marschner-lobb", {33, 33, 33});
    const TransferFunction tf = test::designTransferFunction();
    Camera inside;
    inside.position = {0.13, -0.07, 0.41};
    inside.focalPoint = {0.3, 0.2, -1.0};
    inside.viewAngle = 70.0;
    const struct { const char* name; Camera camera; } views[] = {
        {"perspective", test::obliquePerspectiveCamera(30.0)}, {"parallel", test::obliqueParallelCamera(1.3)}, {"eye inside", inside}};
    for (const auto& view : views)
        for (const double tolerance : {0.0, 0.1, 0.3}) {
            const std::string what = std::string(view.name) + ", error " + std::to_string(tolerance);
            FrameStats fusedStats, rasterStats;
            const Image4f fused =
                render(makeScene(view.camera, tf, 64, {{"error", tolerance}, {"path", "fused"}}), volume, &fusedStats);
            const Image4f raster =
                render(makeScene(view.camera, tf, 64, {{"error", tolerance}, {"thickness", "exact"}}), volume, &rasterStats);
            EXPECT_EQ(fusedStats.extra["path"], "fused");
            EXPECT_EQ(rasterStats.extra["path"], "raster");
            EXPECT_EQ(count(fusedStats, "cubes"), count(rasterStats, "cubes")) << what;
            EXPECT_GT(count(fusedStats, "cubes_crossed"), 0u) << what;
            const Image4d rasterD = clvr::raster::reference::toDouble(raster);
            const test::ImageError e = printError("fused vs raster (exact thickness), " + what, fused, rasterD);
            EXPECT_EQ(e.nanCount, 0u);
            // The raster path's exact thickness is itself within 5e-4 of the integral (ErrorZero... above).
            EXPECT_TRUE(test::imagesNear(fused, rasterD, {.maxAbs = 5e-4, .meanAbs = 2e-6})) << what;
            if (tolerance == 0.0) {
                const Image4d expected = cubeFieldIntegral(volume, tf, view.camera, makeScene(view.camera, tf, 64).image);
                printError("fused vs the cube-field integral, " + what, fused, expected);
                EXPECT_TRUE(test::imagesNear(fused, expected, {.maxAbs = 1e-4, .meanAbs = 1e-6})) << what;
            }
        }
}

// Rays along the grid's axes (a parallel view straight down z, then down -x, with pixel centres on the
// cubes' faces): the walk's exits along the two axes the ray does not move on lie at infinity, and
// every ray runs in the plane between two columns of cubes or through their middles. Against the exact
// integral.
TEST(CubefanFused, AxisAlignedRays)
{
    const Volume volume = smallVolume();  // 20^3 in [-1, 1]^3: cubes 2/19 wide, faces at -1 - 1/19 + k 2/19
    const TransferFunction tf = test::designTransferFunction();
    for (const glm::dvec3 direction : {glm::dvec3(0, 0, -1), glm::dvec3(-1, 0, 0)}) {
        Camera camera;
        camera.parallel = true;
        camera.focalPoint = glm::dvec3(0.0);
        camera.position = -3.0 * direction;
        camera.viewUp = direction.z != 0.0 ? glm::dvec3(0, 1, 0) : glm::dvec3(0, 0, 1);
        camera.parallelScale = 20.0 / 19.0;  // the image spans the cube field: 40 pixels, two per cube
        const Scene scene = makeScene(camera, tf, 40);
        const Image4d expected = cubeFieldIntegral(volume, tf, camera, scene.image);
        const Image4f image = render(scene, volume);
        const test::ImageError e = printError("axis-aligned rays", image, expected);
        EXPECT_EQ(e.nanCount, 0u);
        EXPECT_TRUE(test::imagesNear(image, expected, {.maxAbs = 2e-4, .meanAbs = 2e-6}));
    }
}

// Early termination stops a ray once its opacity reaches the threshold: what is left behind can add at
// most 1 - threshold to any channel, the opacity itself reaches it, and fewer cubes are crossed; a
// pixel whose opacity stays below it is the same bits.
TEST(CubefanFused, EarlyTerminationStopsAtTheThreshold)
{
    const Volume volume = smallVolume();
    const TransferFunction tf = test::designTransferFunction(4.0);
    const Camera camera = test::obliquePerspectiveCamera(30.0);
    FrameStats fullStats, earlyStats;
    const Image4f full = render(makeScene(camera, tf, 48), volume, &fullStats);
    const double threshold = 0.6;
    const Image4f early = render(makeScene(camera, tf, 48, {{"early_termination", threshold}}), volume, &earlyStats);
    EXPECT_LT(count(earlyStats, "cubes_crossed"), count(fullStats, "cubes_crossed"));
    EXPECT_GT(test::expectEarlyTermination(full, early, threshold), 48 * 48 / 10);
}

// Ray packets: cubefan_fused_packet walks 8 pixels' rays as vector lanes, each through its own cubes. The
// same bits as one pixel per work-item, and the same cubes crossed and stepped over: perspective, parallel,
// rays along the axes (two directions at 1e-30), the eye inside, three tolerances, a transfer function that
// makes cubes transparent (the walk's empty-brick steps), early termination, and widths that leave lanes
// out of the image (61) or hold a single partial packet (5).
TEST(CubefanFused, PacketsAreBitIdenticalToOnePixelPerWorkItem)
{
    const Volume blobs = generateVolume("blobs", {41, 37, 30});
    const TransferFunction sparse({{0.0, {0, 0, 0}, 0.0}, {0.35, {0, 0, 0}, 0.0}, {0.6, {1, 0.5, 0}, 6.0}, {1.0, {1, 1, 1}, 14.0}});
    Camera inside;
    inside.position = {0.13, -0.07, 0.41};
    inside.focalPoint = {0.3, 0.2, -1.0};
    inside.viewAngle = 70.0;
    Camera down;
    down.parallel = true;
    down.focalPoint = glm::dvec3(0.0);
    down.position = {0.0, 0.0, 3.0};
    down.viewUp = {0, 1, 0};
    down.parallelScale = 1.1;
    const Camera cameras[] = {test::obliquePerspectiveCamera(30.0), test::obliqueParallelCamera(1.3), inside, down};
    const json sets[] = {{{"error", 0.0}}, {{"error", 0.1}, {"path", "fused"}}, {{"error", 0.3}, {"path", "fused"}},
                         {{"error", 0.05}, {"early_termination", 0.6}, {"path", "fused"}}};
    int compared = 0;
    std::uint64_t steppedOver = 0;
    for (const Camera& camera : cameras)
        for (const json& set : sets)
            for (const int width : {61, 5}) {
                Scene scene = makeScene(camera, sparse, width, set);
                scene.image.height = 23;
                const FrameStats stats = test::expectPacketsEqualPixels(
                    scene, [&](const Scene& s, FrameStats& st) { return render(s, blobs, &st); },
                    {"cubes_crossed", "cubes_stepped_over"},
                    set.dump() + " width " + std::to_string(width) + " camera " + std::to_string(&camera - cameras));
                EXPECT_GT(count(stats, "cubes_crossed"), 0u) << set.dump();
                steppedOver += count(stats, "cubes_stepped_over");
                ++compared;
            }
    EXPECT_EQ(compared, 4 * 4 * 2);
    EXPECT_GT(steppedOver, 0u);  // the transparent cubes' steps were compared too
}

// Renderer::setCamera, both paths: pointed at new cameras (perspective, parallel, the eye inside) the renderer
// gives the bits a new renderer gives — the fused walk with and without packets, the fans selecting and
// projecting for the new eye —; a wider image it refuses.
TEST(CubefanRenderer, SetCameraEqualsANewRenderer)
{
    const Volume volume = generateVolume("marschner-lobb", {21, 21, 21});
    Camera inside;
    inside.position = {0.13, -0.07, 0.41};
    inside.focalPoint = {0.3, 0.2, -1.0};
    inside.viewAngle = 70.0;
    const std::vector<Camera> cameras = {test::obliquePerspectiveCamera(30.0), test::obliqueParallelCamera(1.3), inside};
    Scene scene = makeScene(cameras[0], test::designTransferFunction(), 23);
    for (const json& options : {json{{"error", 0.1}}, json{{"error", 0.1}, {"packets", false}},
                                json{{"error", 0.1}, {"path", "fused"}}, json{{"error", 0.1}, {"path", "raster"}},
                                json{{"thickness", "exact"}}}) {
        scene.options = options;
        test::expectSetCameraEqualsNewRenderer(scene, volume, cameras, options.dump());
    }
}

}  // namespace
}  // namespace clvr
