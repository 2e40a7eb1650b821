// tests/bench_test.cpp — correctness (never timing) of clvr bench: the ceiling loop (tools/ceiling.h),
// whose image must be the emission-absorption integral of the scene as host/reference/reference_integral.h computes
// it, and the mesh side (tools/bench_mesh.h): the harc bench scenes, the figures from a frame's stats, the
// TetGen mesh cache and the peer's files. tools/*.cpp are not in the test binary, so their files are
// compiled in here.
#include "tools/bench_mesh.cpp"
#include "tools/bench_suites.cpp"
#include "tools/ceiling.cpp"
#include "tools/ceiling_cubefan.cpp"
#include "tools/ceiling_harc.cpp"
#include "tools/ceiling_iso3d.cpp"
#include "tools/ceiling_projtet.cpp"
#include "tools/ceiling_spherical.cpp"
#include "tools/ceiling_stack2d.cpp"

#include "host/runtime/errors.h"
#include "host/io/generators.h"
#include "host/io/mesh_io.h"
#include "host/reference/reference_integral.h"
#include "host/render/grid/cubefan.h"
#include "host/reference/tet_reference.h"
#include "raster/reference/pixel_transfer.h"
#include "host/render/renderer.h"
#include "host/render/tet/tetiso.h"
#include "host/render/tet/tetslice.h"
#include "tests/support/mesh_fixtures.h"
#include "tests/support/test_util.h"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <random>
#include <filesystem>
#include <fstream>
#include <sstream>

namespace {

clvr::TransferFunction testTransferFunction()
{
    return clvr::TransferFunction({{0.0, {0.0, 0.0, 0.0}, 0.0},
                                   {0.3, {0.1, 0.2, 0.8}, 1.0},
                                   {0.7, {0.9, 0.6, 0.2}, 3.0},
                                   {1.0, {1.0, 1.0, 1.0}, 4.0}});
}

TEST(Ceiling, MatchesReferenceIntegralOnMarschnerLobb)
{
    const clvr::Volume volume = clvr::generateVolume("marschner-lobb", {41, 37, 33});  // odd sizes
    const clvr::TransferFunction tf = testTransferFunction();
    clvr::tools::CeilingScene scene;
    scene.camera.position = {2.5, 1.5, 3.0};
    scene.camera.viewAngle = 40.0;
    scene.width = 61;
    scene.height = 47;
    scene.background = {0.2, 0.3, 0.4};
    scene.options.slices = 2048;  // deltaS ~ 0.0014 world units: far below the voxel size 0.05
    const clvr::tools::Ceiling ceiling(volume, tf, scene);
    const clvr::tools::CeilingResult result = ceiling.render(2);

    clvr::ImageSpec spec;
    spec.width = scene.width;
    spec.height = scene.height;
    spec.background = scene.background;
    clvr::ReferenceOptions options;
    options.tolerance = 1e-5;
    const clvr::Image4d expected = clvr::referenceIntegral(volume, tf, scene.camera, spec, options);
    // Slice sums with deltaS ~ 0.0014 against the converged integral: O(deltaS^2) quadrature error
    // inside, float accumulation over ~1400 terms ~1e-4. What
    // dominates is the part of a ray before its first and after its last slice (up to deltaS each,
    // optical depth 4 * 0.0014 = 6e-3), largest on short grazing chords (measured: max 4.2e-3 in
    // alpha, mean 1.2e-4).
    EXPECT_TRUE(clvr::test::imagesNear(result.image, expected, {.maxAbs = 6e-3, .meanAbs = 3e-4}));
    EXPECT_GT(result.samples, 0u);
}

// How two images of one size differ: the pixels that differ by more than `threshold` in some channel, the largest
// and the mean channel difference.
struct PixelsApart {
    std::size_t over = 0;
    double max = 0.0, mean = 0.0;
};
PixelsApart pixelsApart(const clvr::Image4f& a, const clvr::Image4f& b, float threshold = 1e-5f)
{
    PixelsApart r;
    for (std::size_t p = 0; p < a.pixelCount(); ++p) {
        const glm::vec4 d = glm::abs(a.pixels()[p] - b.pixels()[p]);
        const float m = std::max({d.r, d.g, d.b, d.a});
        r.over += m > threshold ? 1 : 0;
        r.max = std::max(r.max, static_cast<double>(m));
        r.mean += static_cast<double>(d.r + d.g + d.b + d.a) / 4.0;
    }
    r.mean /= static_cast<double>(a.pixelCount());
    return r;
}

// slice3d's ceiling loop with a clip mesh and with pre-integrated slabs does the fused kernel's work: the same
// samples, and the same image up to float rounding — the loop's layers come from the CPU reference rasterizer
// in double, the kernel's from the raster stage in float, so a sample within rounding of a surface, or a pixel
// on the mesh's silhouette, may fall the other way (measured: a few pixels of each image); its exp against
// clvr_exp2. Two-pass, naive and inverse, perspective and parallel, back to front and front to back.
TEST(Ceiling, ClipsAndPreintegratesLikeTheKernel)
{
    const clvr::Volume volume = clvr::generateVolume("marschner-lobb", {41, 37, 33});
    const nlohmann::json sphere = {{"generator", "sphere"}, {"center", {0.1, -0.05, 0.0}}, {"radius", 0.75}, {"segments", 48}};
    struct Case {
        std::string what;
        nlohmann::json options;
    };
    const std::vector<Case> cases = {
        {"two-pass", {{"slices", 90}, {"path", "fused"}, {"clip", {{"mesh", sphere}}}}},
        {"two-pass inverse, front to back",
         {{"slices", 90}, {"path", "fused"}, {"order", "front-to-back"}, {"clip", {{"mesh", sphere}, {"inverse", true}}}}},
        {"naive", {{"slices", 90}, {"path", "fused"}, {"clip", {{"mesh", sphere}, {"method", "naive"}}}}},
        {"preintegrated", {{"slices", 60}, {"integration", "preintegrated"}, {"order", "front-to-back"}}},
        {"preintegrated, early termination",
         {{"slices", 60}, {"integration", "preintegrated"}, {"order", "front-to-back"}, {"early_termination", 0.6}}},
    };
    for (const clvr::Camera& camera : {clvr::test::obliquePerspectiveCamera(30.0), clvr::test::obliqueParallelCamera(1.3)})
        for (const Case& c : cases) {
            const std::string what = c.what + (camera.parallel ? ", parallel" : ", perspective");
            clvr::Scene scene;
            scene.technique = "slice3d";
            scene.camera = camera;
            scene.image = clvr::ImageSpec{56, 48, {0.05, 0.05, 0.1}};
            scene.transferFunction = testTransferFunction();
            scene.options = c.options;
            clvr::FrameStats stats;
            const clvr::Image4f kernel = clvr::test::renderScene(scene, volume, &stats);
            clvr::tools::CeilingScene cs;
            cs.camera = camera;
            cs.width = scene.image.width;
            cs.height = scene.image.height;
            cs.background = scene.image.background;
            cs.options = clvr::parseSlice3dOptions(scene.options);
            if (cs.options.clip)
                cs.clipMesh = clvr::loadClipMesh(cs.options.clip->mesh, {});
            const clvr::tools::Ceiling ceiling(volume, scene.transferFunction, cs);
            const clvr::tools::CeilingResult result = ceiling.render(2);
            const PixelsApart d = pixelsApart(kernel, result.image);
            std::printf("[ measured ] slice3d ceiling vs kernel (%s): %zu of %zu pixels over 1e-5, max %.2g, mean %.2g; "
                        "samples %llu vs %llu\n",
                        what.c_str(), d.over, kernel.pixelCount(), d.max, d.mean,
                        static_cast<unsigned long long>(result.samples), static_cast<unsigned long long>(stats.samples));
            EXPECT_LE(d.over * 100, kernel.pixelCount()) << what;  // at most 1 % of the pixels
            EXPECT_LT(d.mean, 2e-4) << what;
            EXPECT_GT(result.samples, 10000u) << what;
            EXPECT_EQ(result.samples, stats.samples) << what;  // with early termination: up to where the ray stopped
        }
}

// spherical's ceiling loop (tools/ceiling_spherical.h) does the fused kernel's work in plain C++: the same image
// up to float rounding (exp against clvr_exp2, operations the OpenCL compiler may contract; measured max ~1e-6)
// and the same shell hits but for rays that graze a sphere within rounding. Perspective from outside (with a
// φ bias), from inside the domain, and parallel over a full ball with early termination.
TEST(SphericalCeiling, DoesTheFusedKernelsWork)
{
    const clvr::Volume volume = clvr::generateVolume("atmosphere", {33, 17, 12});
    struct Case {
        clvr::Camera camera;
        nlohmann::json options;
    };
    clvr::Camera outside;
    outside.position = {2.6, 1.4, 2.1};
    outside.viewUp = {0.0, 0.0, 1.0};
    outside.viewAngle = 40.0;
    clvr::Camera inside;
    inside.position = {0.8, 0.0, 0.1};
    inside.focalPoint = {0.0, 0.3, 0.0};
    inside.viewUp = {0.0, 0.0, 1.0};
    inside.viewAngle = 70.0;
    clvr::Camera parallel;
    parallel.position = {-2.6, -0.7, 1.3};
    parallel.focalPoint = {0.4, 0.3, -0.2};
    parallel.viewUp = {0.0, 0.0, 1.0};
    parallel.parallel = true;
    parallel.parallelScale = 1.1;
    for (const Case& c : {Case{outside, {{"shells", 33}, {"bias", {0.3, 0.0, 0.0}}}}, Case{inside, {{"shells", 24}}},
                          Case{parallel, {{"shells", 40}, {"r_min", 0.0}, {"r_max", 0.9}, {"center", {0.4, 0.3, -0.2}},
                                          {"early_termination", 0.95}}}}) {
        clvr::Scene scene;
        scene.technique = "spherical";
        scene.camera = c.camera;
        scene.image = clvr::ImageSpec{48, 40, {0.05, 0.05, 0.1}};
        scene.transferFunction = clvr::TransferFunction({{0.0, {0.1, 0.2, 0.6}, 0.5}, {0.4, {0.3, 0.6, 1.0}, 1.5},
                                                         {1.0, {1.0, 1.0, 0.9}, 6.0}});
        scene.options = c.options;
        clvr::FrameStats stats;
        const clvr::Image4f kernel = clvr::test::renderScene(scene, volume, &stats);
        const clvr::tools::SphericalCeiling ceiling(volume, scene.transferFunction, *scene.camera, scene.image,
                                                    clvr::parseSphericalOptions(scene.options));
        const clvr::tools::CeilingResult result = ceiling.render(2);
        const clvr::Image4d want = clvr::raster::reference::toDouble(kernel);
        const clvr::test::ImageError e = clvr::test::imageError(result.image, want);
        std::printf("[ measured ] spherical ceiling vs kernel (%s): max %.3g, mean %.3g; samples %llu vs %llu\n",
                    c.options.dump().c_str(), std::max({e.maxAbs.r, e.maxAbs.g, e.maxAbs.b, e.maxAbs.a}),
                    std::max({e.meanAbs.r, e.meanAbs.g, e.meanAbs.b, e.meanAbs.a}),
                    static_cast<unsigned long long>(result.samples), static_cast<unsigned long long>(stats.samples));
        EXPECT_TRUE(clvr::test::imagesNear(result.image, want, {.maxAbs = 1e-4, .meanAbs = 1e-6}));
        EXPECT_GT(result.samples, 1000u);
        EXPECT_LE(std::abs(static_cast<double>(result.samples) - static_cast<double>(stats.samples)),
                  1e-4 * static_cast<double>(stats.samples) + 2.0);
    }
}

// stack2d's ceiling loop (tools/ceiling_stack2d.h) does the fused kernel's work in plain C++ (without the
// empty-space skipping, which leaves the kernel's image bit for bit): the same image up to float rounding and
// the same planes met in the box. Perspective (z stack, 1 intermediate slice), parallel (x stack, plain), a
// camera inside the box (3 intermediate slices, early termination).
TEST(Stack2dCeiling, DoesTheFusedKernelsWork)
{
    const clvr::Volume volume = clvr::generateVolume("marschner-lobb", {41, 37, 33});
    clvr::Camera inside;
    inside.position = {0.35, 0.45, 0.55};
    inside.focalPoint = {0.0, -0.1, 0.0};
    inside.viewAngle = 70.0;
    struct Case {
        clvr::Camera camera;
        nlohmann::json options;
    };
    for (const Case& c : {Case{clvr::test::obliquePerspectiveCamera(40.0), {{"intermediate", 1}}},
                          Case{clvr::test::obliqueParallelCamera(1.8), {{"intermediate", 0}}},
                          Case{inside, {{"intermediate", 3}, {"early_termination", 0.9}}}}) {
        clvr::Scene scene;
        scene.technique = "stack2d";
        scene.camera = c.camera;
        scene.image = clvr::ImageSpec{48, 40, {0.1, 0.2, 0.3}};
        scene.transferFunction = testTransferFunction();
        scene.options = c.options;
        clvr::FrameStats stats;
        const clvr::Image4f kernel = clvr::test::renderScene(scene, volume, &stats);
        const clvr::Stack2dOptions options = clvr::parseStack2dOptions(scene.options);
        ASSERT_TRUE(clvr::tools::stack2dCeilingFits(scene, options));
        const clvr::tools::Stack2dCeiling ceiling(volume, scene.transferFunction, *scene.camera, scene.image, options);
        const clvr::tools::CeilingResult result = ceiling.render(2);
        const clvr::Image4d want = clvr::raster::reference::toDouble(kernel);
        const clvr::test::ImageError e = clvr::test::imageError(result.image, want);
        std::printf("[ measured ] stack2d ceiling vs kernel (%s): max %.3g, mean %.3g; samples %llu vs %llu\n",
                    c.options.dump().c_str(), std::max({e.maxAbs.r, e.maxAbs.g, e.maxAbs.b, e.maxAbs.a}),
                    std::max({e.meanAbs.r, e.meanAbs.g, e.meanAbs.b, e.meanAbs.a}),
                    static_cast<unsigned long long>(result.samples), static_cast<unsigned long long>(stats.samples));
        EXPECT_TRUE(clvr::test::imagesNear(result.image, want, {.maxAbs = 1e-4, .meanAbs = 1e-6}));
        EXPECT_GT(result.samples, 1000u);
        if (!c.options.contains("early_termination")) {  // both count every plane met in the box
            EXPECT_LE(std::abs(static_cast<double>(result.samples) - static_cast<double>(stats.samples)),
                      1e-4 * static_cast<double>(stats.samples) + 2.0);
        }
    }
    clvr::Scene shaded;
    shaded.lighting = clvr::test::twoLightLighting();
    EXPECT_FALSE(clvr::tools::stack2dCeilingFits(shaded, clvr::Stack2dOptions{}));
}

// ---------------------------------------------------------------------------------------------------
// BenchMesh: the harc bench scenes and the figures of seeds/001 Tables 2-3.

std::filesystem::path benchScene(const std::string& name)
{
    return std::filesystem::path(CLVR_SOURCE_DIR) / "data/scenes/bench" / name;
}

// cubefan's ceiling loop (tools/ceiling_cubefan.h) does the fused kernel's walk in plain C++ over the same selection
// grid: the same image up to float rounding (exp against clvr_exp2, the transfer function's slopes, the camera's
// rays in float; measured max ~1e-6) and the same cubes crossed but for rays through a cube's edge within rounding.
// Perspective from outside and from inside the volume, parallel, exact cubes (0 %), merged ones, early termination.
TEST(CubefanCeiling, DoesTheFusedKernelsWork)
{
    const clvr::Volume blobs = clvr::generateVolume("blobs", {41, 37, 30});
    const clvr::TransferFunction sparse({{0.0, {0, 0, 0}, 0.0}, {0.35, {0, 0, 0}, 0.0}, {0.6, {1, 0.5, 0}, 6.0},
                                         {1.0, {1, 1, 1}, 14.0}});
    clvr::Camera inside;
    inside.position = {0.13, -0.07, 0.41};
    inside.focalPoint = {0.3, 0.2, -1.0};
    inside.viewAngle = 70.0;
    const clvr::Camera cameras[] = {clvr::test::obliquePerspectiveCamera(30.0), clvr::test::obliqueParallelCamera(1.3),
                                    inside};
    const nlohmann::json sets[] = {{{"error", 0.0}}, {{"error", 0.1}, {"path", "fused"}},
                                   {{"error", 0.05}, {"early_termination", 0.6}, {"path", "fused"}}};
    for (const clvr::Camera& camera : cameras)
        for (const nlohmann::json& set : sets) {
            clvr::Scene scene;
            scene.technique = "cubefan";
            scene.camera = camera;
            scene.image = clvr::ImageSpec{52, 44, {0.05, 0.05, 0.1}};
            scene.transferFunction = sparse;
            scene.options = set;
            clvr::FrameStats stats;
            const clvr::Image4f kernel = clvr::test::renderScene(scene, blobs, &stats);
            const clvr::tools::CubefanCeiling ceiling(blobs, sparse, *scene.camera, scene.image,
                                                      clvr::parseCubefanOptions(set));
            const clvr::tools::CeilingResult result = ceiling.render(2);
            const clvr::test::ImageError e = clvr::test::imageError(result.image, clvr::raster::reference::toDouble(kernel));
            std::printf("[ measured ] cubefan ceiling vs kernel (%s, camera %d): max %.3g, mean %.3g; cubes crossed %llu vs %llu\n",
                        set.dump().c_str(), static_cast<int>(&camera - cameras),
                        std::max({e.maxAbs.r, e.maxAbs.g, e.maxAbs.b, e.maxAbs.a}),
                        std::max({e.meanAbs.r, e.meanAbs.g, e.meanAbs.b, e.meanAbs.a}),
                        static_cast<unsigned long long>(result.samples), static_cast<unsigned long long>(stats.samples));
            EXPECT_TRUE(clvr::test::imagesNear(result.image, clvr::raster::reference::toDouble(kernel),
                                               {.maxAbs = 1e-4, .meanAbs = 1e-6}))
                << set.dump();
            EXPECT_GT(result.samples, 500u) << set.dump();
            EXPECT_LE(std::abs(static_cast<double>(result.samples) - static_cast<double>(stats.samples)),
                      1e-4 * static_cast<double>(stats.samples) + 2.0)
                << set.dump();
        }
}

// An iso3d scene rendered by clvr and by the ceiling loop (which must fit it), on 2 threads.
struct Iso3dCeilingRun {
    clvr::Image4f kernel;
    clvr::FrameStats stats;
    clvr::tools::CeilingResult ceiling;
};
Iso3dCeilingRun runIso3dCeiling(const clvr::Volume& volume, const clvr::Scene& scene)
{
    Iso3dCeilingRun run;
    run.kernel = clvr::test::renderScene(scene, volume, &run.stats);
    const clvr::Iso3dOptions options = clvr::parseIso3dOptions(scene.options);
    EXPECT_TRUE(clvr::tools::iso3dCeilingFits(options, *scene.iso)) << scene.options.dump();
    run.ceiling = clvr::tools::Iso3dCeiling(volume, scene, *scene.camera, options).render(2);
    return run;
}

// The iso3d scene both iso3d ceiling tests render: Marschner–Lobb's surface at 0.55 on 56x48, with these options.
clvr::Scene iso3dCeilingScene(const clvr::Camera& camera, clvr::IsoSpec::Shading shading, nlohmann::json options)
{
    clvr::Scene scene;
    scene.technique = "iso3d";
    scene.camera = camera;
    scene.image = clvr::ImageSpec{56, 48, {0.05, 0.05, 0.1}};
    scene.transferFunction = clvr::TransferFunction({{0.0, {0.2, 0.4, 0.9}, 1.0}, {1.0, {1.0, 0.8, 0.3}, 1.0}});
    scene.iso = clvr::IsoSpec{};
    scene.iso->value = 0.55;
    scene.iso->shading = shading;
    scene.options = std::move(options);
    return scene;
}

// iso3d's ceiling loop (tools/ceiling_iso3d.h) does the fused path's work: the same samples taken (empty bricks
// skipped sample by sample where the kernel steps over runs) and the same surface, shaded through the same color
// matrix — the image up to float rounding but for pixels whose sample lies within rounding of the iso-value.
// Perspective and parallel, gradient shading and none, with and without empty-space skipping.
TEST(Iso3dCeiling, DoesTheFusedPathsWork)
{
    const clvr::Volume volume = clvr::generateVolume("marschner-lobb", {41, 41, 41});
    std::uint64_t hitPixels = 0;
    for (const clvr::Camera& camera : {clvr::test::obliquePerspectiveCamera(30.0), clvr::test::obliqueParallelCamera(1.3)})
        for (const clvr::IsoSpec::Shading shading : {clvr::IsoSpec::Shading::Gradient, clvr::IsoSpec::Shading::None})
            for (const bool skip : {true, false}) {
                const clvr::Scene scene =
                    iso3dCeilingScene(camera, shading, {{"slices", 90}, {"empty_space_skipping", skip}});
                const std::string what = std::string(shading == clvr::IsoSpec::Shading::None ? "unshaded" : "shaded") +
                                         (skip ? ", skipping" : "") + (camera.parallel ? ", parallel" : "");
                const Iso3dCeilingRun run = runIso3dCeiling(volume, scene);
                const clvr::Image4f& kernel = run.kernel;
                const clvr::FrameStats& stats = run.stats;
                const clvr::tools::CeilingResult& result = run.ceiling;
                const std::size_t differ = pixelsApart(kernel, result.image).over;
                for (const glm::vec4& p : kernel.pixels())
                    hitPixels += p.a > 0.5f ? 1 : 0;
                std::printf("[ measured ] iso3d ceiling vs kernel (%s): %zu of %zu pixels over 1e-5; samples %llu vs %llu\n",
                            what.c_str(), differ, kernel.pixelCount(), static_cast<unsigned long long>(result.samples),
                            static_cast<unsigned long long>(stats.samples));
                EXPECT_LE(differ * 200, kernel.pixelCount()) << what;  // at most 0.5 % of the pixels
                EXPECT_GT(result.samples, 1000u) << what;
                EXPECT_LE(std::abs(static_cast<double>(result.samples) - static_cast<double>(stats.samples)),
                          1e-3 * static_cast<double>(stats.samples))
                    << what;
            }
    EXPECT_GT(hitPixels, 8u * 56u * 48u / 10u);  // the surface covers a good part of the images
}

// The same loop on iso3d's raster path, unbricked and in bricks (§3.1): the image of the slice draws up to the
// sample points' rounding — the draws interpolate positions across slice polygons whose vertices the raster stage
// snaps to 1/256 pixel, the loop adds z d to o, as iso3d's fused path does, which tests/iso3d_test.cpp holds
// within 1.2e-3 of the draws on Marschner–Lobb's normals (measured here: 1.2e-3 shaded, and 4 pixels whose hit
// fell on another slice; unshaded, none over 1e-5) — and the bricked loop's image the unbricked loop's bit for bit
// (each brick samples its own texels at g - lo, the same cell and weights). It tests fewer fragments than the
// draws make (it stops at each pixel's hit).
TEST(Iso3dCeiling, DoesTheRasterPathsWorkBrickedOrNot)
{
    const clvr::Volume volume = clvr::generateVolume("marschner-lobb", {41, 37, 33});
    for (const clvr::Camera& camera : {clvr::test::obliquePerspectiveCamera(30.0), clvr::test::obliqueParallelCamera(1.3)})
        for (const clvr::IsoSpec::Shading shading : {clvr::IsoSpec::Shading::Gradient, clvr::IsoSpec::Shading::None}) {
            clvr::Image4f unbricked;
            for (const nlohmann::json& bricks : {nlohmann::json(nullptr), nlohmann::json{2, 3, 2}}) {
                clvr::Scene scene = iso3dCeilingScene(camera, shading, {{"slices", 90}, {"path", "raster"}});
                if (!bricks.is_null())
                    scene.options["bricks"] = bricks;
                const std::string what = std::string(shading == clvr::IsoSpec::Shading::None ? "unshaded" : "shaded") +
                                         (bricks.is_null() ? "" : ", bricks") + (camera.parallel ? ", parallel" : "");
                const Iso3dCeilingRun run = runIso3dCeiling(volume, scene);
                const clvr::Image4f& kernel = run.kernel;
                const clvr::FrameStats& stats = run.stats;
                const clvr::tools::CeilingResult& result = run.ceiling;
                const PixelsApart d = pixelsApart(kernel, result.image, 2e-3f);
                std::size_t hits = 0;
                for (const glm::vec4& p : kernel.pixels())
                    hits += p.a > 0.5f ? 1 : 0;
                std::printf("[ measured ] iso3d raster ceiling vs draws (%s): %zu of %zu pixels over 2e-3, max %.2g, mean "
                            "%.2g; fragments %llu tested vs %llu drawn; %zu hits\n",
                            what.c_str(), d.over, kernel.pixelCount(), d.max, d.mean, static_cast<unsigned long long>(result.samples),
                            static_cast<unsigned long long>(stats.samples), hits);
                EXPECT_LE(d.over * 200, kernel.pixelCount()) << what;  // another slice's sample: at most 0.5 % of the pixels
                EXPECT_LT(d.mean, 3e-4) << what;
                EXPECT_GT(hits * 5, kernel.pixelCount()) << what;      // the surface covers a good part of the image
                EXPECT_GT(result.samples, 1000u) << what;
                EXPECT_LT(result.samples, stats.samples) << what;
                if (bricks.is_null())
                    unbricked = result.image;
                else
                    EXPECT_EQ(pixelsApart(unbricked, result.image).max, 0.0) << what;
            }
        }
}

TEST(BenchMesh, BluntfinScenesHaveTheStatedControlPointsAndImageSize)
{
    for (const auto& [name, points] : {std::pair{"harc-bluntfin-10.json", 11}, std::pair{"harc-bluntfin-255.json", 256},
                                       std::pair{"harc-bluntfin-10-full.json", 11}}) {
        const clvr::Scene scene = clvr::loadScene(benchScene(name));
        // Partial pre-integration (the default) but for the -full scene, which is the 10-segment one.
        const bool full = std::string(name).find("-full") != std::string::npos;
        EXPECT_EQ(scene.options.is_object() ? scene.options.value("integration", std::string("partial")) : "partial",
                  full ? "full" : "partial")
            << name;
        EXPECT_EQ(scene.technique, "harc") << name;
        EXPECT_EQ(scene.transferFunction.points().size(), static_cast<std::size_t>(points)) << name;
        EXPECT_EQ(scene.image.width, 512) << name;
        EXPECT_EQ(scene.image.height, 512) << name;
        EXPECT_FALSE(scene.camera) << name << ": like data/scenes/bluntfin.json, the camera is fitted to the mesh";
        ASSERT_TRUE(scene.mesh.has_value()) << name;
        EXPECT_EQ(scene.mesh->kind, clvr::MeshSpec::Kind::Plot3d) << name;
        EXPECT_EQ(scene.mesh->scalar, "density") << name;
        // The same data as data/scenes/bluntfin.json (whose paths are one folder shallower).
        const clvr::Scene reference = clvr::loadScene(std::filesystem::path(CLVR_SOURCE_DIR) / "data/scenes/bluntfin.json");
        ASSERT_TRUE(reference.mesh.has_value());
        EXPECT_EQ(std::filesystem::weakly_canonical(scene.mesh->file), std::filesystem::weakly_canonical(reference.mesh->file))
            << name;
        // Equal steps of s over the same range, so the two differ only in how finely they split a cell.
        const auto& p = scene.transferFunction.points();
        EXPECT_DOUBLE_EQ(p.front().s, 0.19) << name;
        EXPECT_DOUBLE_EQ(p.back().s, 4.98) << name;
        for (std::size_t i = 1; i < p.size(); ++i)
            EXPECT_NEAR(p[i].s - p[i - 1].s, (4.98 - 0.19) / (points - 1), 1e-6) << name << " point " << i;
    }
}

// The 1M scene's TetGen parameters, meshed as clvr bench meshes them (about 7 s of TetGen on one core;
// measured 1,163,474 tetrahedra). TetGen's -a bounds each tetrahedron's volume, so the torus (volume 0.719)
// needs at least 0.719 / max_volume = 575k; refinement leaves about twice that.
TEST(BenchMesh, TetgenSceneMeshesToAMillionTetrahedra)
{
    const clvr::Scene scene = clvr::loadScene(benchScene("harc-tetgen-1m.json"));
    EXPECT_EQ(scene.technique, "harc");
    EXPECT_EQ(scene.image.width, 512);
    EXPECT_EQ(scene.image.height, 512);
    ASSERT_TRUE(scene.camera);
    ASSERT_TRUE(scene.mesh && scene.mesh->kind == clvr::MeshSpec::Kind::Surface);
    const clvr::TetMesh mesh = clvr::loadMesh(*scene.mesh);
    EXPECT_GE(mesh.tets.size(), 1000000u);
    EXPECT_EQ(mesh.tetsDegenerate, 0u);
    EXPECT_EQ(mesh.scalars.size(), mesh.points.size());
}

TEST(BenchMesh, FiguresFromAFrameRecord)
{
    const nlohmann::json extra = {{"tets", 225000}, {"tets_rendered", 224874}, {"steps", 3000000},
                                  {"bytes_per_tet", 80.25}, {"pieces", 5000000}};
    const clvr::tools::MeshFigures f = clvr::tools::meshFigures(extra, 250.0);
    EXPECT_EQ(f.tets, 224874u);  // tets_rendered, not tets as read
    EXPECT_EQ(f.steps, 3000000u);
    EXPECT_DOUBLE_EQ(f.fps, 4.0);
    EXPECT_DOUBLE_EQ(f.tetsPerS, 224874.0 * 4.0);
    EXPECT_DOUBLE_EQ(f.stepsPerS, 12.0e6);
    EXPECT_DOUBLE_EQ(f.bytesPerTet, 80.25);
    EXPECT_DOUBLE_EQ(f.frameMs, 250.0);
}

TEST(BenchMesh, FiguresNeedMeshStatsAndAPositiveTime)
{
    const nlohmann::json extra = {{"tets_rendered", 10}, {"steps", 20}, {"bytes_per_tet", 80.0}};
    EXPECT_THROW(clvr::tools::meshFigures(extra, 0.0), clvr::InputError);
    EXPECT_THROW(clvr::tools::meshFigures(extra, -1.0), clvr::InputError);
    for (const char* key : {"tets_rendered", "steps", "bytes_per_tet"}) {
        nlohmann::json missing = extra;
        missing.erase(key);
        try {
            clvr::tools::meshFigures(missing, 10.0);
            ADD_FAILURE() << "no error without " << key;
        } catch (const clvr::InputError& e) {
            EXPECT_NE(std::string(e.what()).find(key), std::string::npos) << e.what();
        }
    }
    // The cell-face techniques count the cells they draw instead of traversal steps.
    nlohmann::json faces = extra;
    faces.erase("steps");
    faces["cells_drawn"] = 7;
    EXPECT_EQ(clvr::tools::meshFigures(faces, 10.0).steps, 7u);
    // projtet: each fragment integrates one segment.
    nlohmann::json projected = extra;
    projected.erase("steps");
    projected["raster_fragments"] = 9;
    EXPECT_EQ(clvr::tools::meshFigures(projected, 10.0).steps, 9u);
}

// A small surface scene: meshed once, then read from the cache as the same mesh; another option meshes again.
TEST(BenchMesh, MeshCacheReturnsTheMeshTetgenMade)
{
    clvr::test::TempDir dir;
    const std::string text = R"({"technique": "harc",
        "mesh": {"surface": ")" + clvr::test::repoData("surfaces/torus.off") + R"(", "max_volume": 0.002, "scalar": "blobs"},
        "transfer_function": {"points": [[0, 0, 0, 0, 0], [1, 1, 1, 1, 1]]}})";
    const clvr::Scene scene = clvr::parseScene(text, "test scene", dir.path());
    int meshed = 0;
    const auto progress = [&](const std::string& line) {
        ++meshed;
        EXPECT_NE(line.find("TetGen"), std::string::npos) << line;
    };
    const clvr::TetMesh made = clvr::tools::loadBenchMesh(scene, "small", dir / "cache", progress);
    EXPECT_EQ(meshed, 1);
    EXPECT_GE(made.tets.size(), static_cast<std::size_t>(0.7193 / 0.002));  // the -a bound again
    const clvr::TetMesh cached = clvr::tools::loadBenchMesh(scene, "small", dir / "cache", progress);
    EXPECT_EQ(meshed, 1) << "the second load must read the cache";
    ASSERT_EQ(cached.tets.size(), made.tets.size());
    ASSERT_EQ(cached.points.size(), made.points.size());
    EXPECT_EQ(cached.tets, made.tets);
    EXPECT_EQ(cached.points, made.points);    // written with 17 digits: exact
    EXPECT_EQ(cached.scalars, made.scalars);
    EXPECT_EQ(cached.tetsRead, made.tetsRead);

    clvr::Scene other = scene;
    other.mesh->maxVolume = 0.004;
    EXPECT_NE(clvr::tools::meshCacheKey(*other.mesh), clvr::tools::meshCacheKey(*scene.mesh));
    clvr::tools::loadBenchMesh(other, "small", dir / "cache", progress);
    EXPECT_EQ(meshed, 2);
}

TEST(BenchMesh, PeerSceneHoldsTheSameTetrahedraCameraAndTransferFunction)
{
    clvr::test::TempDir dir;
    const clvr::Scene scene = clvr::loadScene(benchScene("harc-bluntfin-10.json"));
    clvr::TetMesh mesh;
    mesh.points = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1}, {1, 1, 1}};
    mesh.scalars = {0.5, 1.0, 2.0, 3.0, 4.5};
    mesh.tets = {{0, 1, 2, 3}, {1, 2, 3, 4}};
    clvr::checkMesh(mesh);
    const clvr::Camera camera = clvr::fitCamera(mesh.boundsMin(), mesh.boundsMax());
    clvr::tools::writePeerMeshScene(scene, mesh, camera, dir / "mesh.vtk", dir / "peer.json");

    const nlohmann::json peer = nlohmann::json::parse(clvr::test::readFile(dir / "peer.json"));
    EXPECT_EQ(peer["transfer_function"]["points"].size(), 11u);
    EXPECT_EQ(peer["image"]["width"], 512);
    const clvr::Scene reread = clvr::parseScene(peer.dump(), "peer.json", dir.path());  // a valid clvr scene
    ASSERT_TRUE(reread.camera);
    EXPECT_EQ(reread.camera->position, camera.position);
    EXPECT_EQ(reread.camera->focalPoint, camera.focalPoint);
    EXPECT_EQ(reread.camera->viewAngle, camera.viewAngle);
    for (std::size_t i = 0; i < scene.transferFunction.points().size(); ++i) {
        EXPECT_EQ(reread.transferFunction.points()[i].s, scene.transferFunction.points()[i].s);
        EXPECT_EQ(reread.transferFunction.points()[i].tau, scene.transferFunction.points()[i].tau);
    }
    const clvr::TetMesh vtk = clvr::readVtkUnstructured(peer["mesh"]["file"].get<std::string>(), "scalars");
    EXPECT_EQ(vtk.tets, mesh.tets);
    EXPECT_EQ(vtk.points, mesh.points);
    ASSERT_EQ(vtk.scalars.size(), mesh.scalars.size());
    for (std::size_t i = 0; i < mesh.scalars.size(); ++i)
        EXPECT_FLOAT_EQ(static_cast<float>(vtk.scalars[i]), static_cast<float>(mesh.scalars[i]));  // float SCALARS
}

// The two bluntfin scenes on a small image: both render, the rays cross the same cells, and 255 segments
// split them into more pieces than 10 (what the bench compares). Counts only; no timing.
TEST(BenchMesh, BluntfinScenesRenderAndMoreSegmentsSplitMore)
{
    const clvr::Scene scene10 = clvr::loadScene(benchScene("harc-bluntfin-10.json"), {"image={\"width\":24,\"height\":20}"});
    const clvr::Scene scene255 = clvr::loadScene(benchScene("harc-bluntfin-255.json"), {"image={\"width\":24,\"height\":20}"});
    const clvr::TetMesh mesh = clvr::loadMesh(*scene10.mesh);
    clvr::FrameStats stats10, stats255;
    const clvr::Image4f image10 = clvr::makeMeshRenderer(clvr::test::device(), scene10, mesh)->render(stats10);
    const clvr::Image4f image255 = clvr::makeMeshRenderer(clvr::test::device(), scene255, mesh)->render(stats255);
    EXPECT_EQ(image10.width(), 24);
    EXPECT_EQ(image255.height(), 20);
    const clvr::tools::MeshFigures f10 = clvr::tools::meshFigures(stats10.extra, 1.0);
    const clvr::tools::MeshFigures f255 = clvr::tools::meshFigures(stats255.extra, 1.0);
    EXPECT_EQ(f10.tets, f255.tets);
    EXPECT_EQ(f10.tets, mesh.tets.size());  // tets_rendered: after the degenerate ones are dropped
    EXPECT_EQ(stats10.extra["tets"].get<std::uint64_t>(), 39u * 31u * 31u * 6u);  // as split: 40x32x32 points, 6 per cell
    EXPECT_GT(f10.tets, 39u * 31u * 31u * 6u * 99 / 100);
    EXPECT_GT(f10.steps, 0u);
    EXPECT_EQ(f10.steps, f255.steps);
    EXPECT_GT(stats255.extra["pieces"].get<std::uint64_t>(), stats10.extra["pieces"].get<std::uint64_t>());
}

// harc's ceiling loop (tools/ceiling_harc.h) does the kernel's work: the same cells entered and pieces
// integrated, the same image up to float rounding (PoCL fuses multiply-adds, the C++ loop does not; its
// exp2 is the library's, the kernel's clvr_exp2). On bluntfin, 512² (clvr bench), the counts are equal too.
void expectCeilingWalksLikeTheKernel(const clvr::Scene& scene, const clvr::TetMesh& mesh, double maxDiff)
{
    const clvr::TetTopology topology = clvr::buildTopology(mesh);
    clvr::FrameStats stats;
    const clvr::Image4f kernel = clvr::makeHarcRenderer(clvr::test::device(), scene, mesh, topology)->render(stats);
    const clvr::tools::HarcCeiling ceiling(mesh, topology, scene.transferFunction, *scene.camera, scene.image,
                                           clvr::parseHarcOptions(scene.options));
    const clvr::tools::HarcCeilingResult result = ceiling.render(2);
    EXPECT_GT(result.steps, 0u);
    EXPECT_EQ(result.steps, stats.extra["steps"].get<std::uint64_t>());
    EXPECT_EQ(result.pieces, stats.extra["pieces"].get<std::uint64_t>());
    EXPECT_TRUE(clvr::test::imagesNear(result.image, clvr::raster::reference::toDouble(kernel),
                                       {.maxAbs = maxDiff, .meanAbs = maxDiff / 10.0}));
}

TEST(HarcCeiling, WalksLikeTheKernelAndMatchesTheExactIntegral)
{
    // Two boxes with a gap between them along the view (the ray re-enters at its next entry crossing), and
    // an eye inside an L of two boxes (every ray starts in the eye's cell): as Harc.NonConvexRayContinues-
    // BehindTheGap and Harc.EyeInsideTheMeshStartsEveryRayInItsCell, with their tolerances.
    const glm::dvec3 gradient(0.3, 0.35, -0.4);
    struct Case {
        std::vector<clvr::test::Box> boxes;
        clvr::Camera camera;
    };
    const std::vector<Case> cases = {
        {{{{0.0, 0.0, 0.0}, {1.0, 1.0, 0.4}, 3}, {{0.0, 0.0, 0.7}, {1.0, 1.0, 1.2}, 3}},
         clvr::test::perspective({0.4, 0.6, 3.0}, {0.5, 0.5, 0.6}, 40.0)},
        {{{{0.0, 0.0, 0.0}, {2.0, 1.0, 1.0}, 4}, {{0.0, 1.0, 0.0}, {1.0, 2.0, 1.0}, 3}},
         clvr::test::perspective({0.55, 0.45, 0.6}, {1.6, 1.3, 0.3}, 95.0)},
    };
    for (const Case& c : cases) {
        clvr::TetMesh mesh = clvr::test::boxMesh(c.boxes, gradient, 0.4);
        clvr::checkMesh(mesh);
        const clvr::TransferFunction tf = clvr::test::rampTransferFunction();
        const clvr::Scene scene = clvr::test::meshScene("harc", c.camera, tf, 40);
        const clvr::tools::HarcCeiling ceiling(mesh, clvr::buildTopology(mesh), tf, c.camera, scene.image,
                                               clvr::parseHarcOptions(scene.options));
        const clvr::Image4d expected = clvr::tetReferenceIntegral(mesh, tf, c.camera, scene.image);
        EXPECT_TRUE(clvr::test::imagesNear(ceiling.render(2).image, expected, {.maxAbs = 2e-3, .meanAbs = 2e-4}));
        expectCeilingWalksLikeTheKernel(scene, mesh, 1e-5);
        // The whole segment at once: the average of its ends' colors and extinctions, or full pre-integration's
        // table (built as harc builds it, looked up with its float arithmetic).
        for (const nlohmann::json& options : {nlohmann::json{{"integration", "average"}},
                                              nlohmann::json{{"integration", "full"}, {"full_table", {24, 16}}}}) {
            SCOPED_TRACE(options.dump());
            expectCeilingWalksLikeTheKernel(clvr::test::meshScene("harc", c.camera, tf, 40, options), mesh, 1e-5);
        }
    }
}

// projtet's ceiling loop (tools/ceiling_projtet.h) draws what the renderer draws: the same image up to float
// rounding (the raster stage's blending and PoCL's contracted multiply-adds; measured max 1.2e-7), within the exact
// integral's tolerance of it, and one segment per ray and cell it meets — as many as harc's walk enters cells
// (harc's steps), and no more than the fragments of the grown silhouettes the raster stage covers. Two boxes with a
// gap along the view (perspective and parallel) and an eye inside an L of boxes (cells cut by the near plane).
TEST(ProjtetCeiling, DrawsLikeTheRendererAndMatchesTheExactIntegral)
{
    const glm::dvec3 gradient(0.3, 0.35, -0.4);
    struct Case {
        std::vector<clvr::test::Box> boxes;
        clvr::Camera camera;
    };
    const std::vector<clvr::test::Box> gap = {{{0.0, 0.0, 0.0}, {1.0, 1.0, 0.4}, 3}, {{0.0, 0.0, 0.7}, {1.0, 1.0, 1.2}, 3}};
    const std::vector<Case> cases = {
        {gap, clvr::test::perspective({0.4, 0.6, 3.0}, {0.5, 0.5, 0.6}, 40.0)},
        {gap, clvr::test::parallelView({2.5, -1.5, 1.8}, {0.5, 0.5, 0.6}, 0.9)},
        {{{{0.0, 0.0, 0.0}, {2.0, 1.0, 1.0}, 4}, {{0.0, 1.0, 0.0}, {1.0, 2.0, 1.0}, 3}},
         clvr::test::perspective({0.55, 0.45, 0.6}, {1.6, 1.3, 0.3}, 95.0)},
    };
    for (const Case& c : cases) {
        clvr::TetMesh mesh = clvr::test::boxMesh(c.boxes, gradient, 0.4);
        clvr::checkMesh(mesh);
        const clvr::TetTopology topology = clvr::buildTopology(mesh);
        const clvr::TransferFunction tf = clvr::test::rampTransferFunction();
        const clvr::Scene scene = clvr::test::meshScene("projtet", c.camera, tf, 40, {{"path", "raster"}});
        clvr::FrameStats stats, harcStats;
        const clvr::Image4f kernel = clvr::makeMeshRenderer(clvr::test::device(), scene, mesh)->render(stats);
        clvr::makeHarcRenderer(clvr::test::device(), clvr::test::meshScene("harc", c.camera, tf, 40), mesh, topology)
            ->render(harcStats);
        const clvr::tools::ProjtetCeiling ceiling(mesh, topology, tf, c.camera, scene.image,
                                                  clvr::parseProjtetOptions(scene.options));
        const clvr::tools::ProjtetCeilingResult result = ceiling.render(2);
        const std::uint64_t fragments = stats.extra["raster_fragments"].get<std::uint64_t>();
        const std::uint64_t steps = harcStats.extra["steps"].get<std::uint64_t>();
        const PixelsApart d = pixelsApart(kernel, result.image);
        std::printf("[ measured ] projtet ceiling: %zu pixels over 1e-5 (max %.2g); %llu segments, harc's steps %llu, "
                    "fragments %llu, %llu pixels tested\n",
                    d.over, d.max, static_cast<unsigned long long>(result.segments), static_cast<unsigned long long>(steps),
                    static_cast<unsigned long long>(fragments), static_cast<unsigned long long>(result.pixelsTested));
        EXPECT_TRUE(clvr::test::imagesNear(result.image, clvr::raster::reference::toDouble(kernel),
                                           {.maxAbs = 1e-5, .meanAbs = 1e-6}));
        EXPECT_TRUE(clvr::test::imagesNear(result.image, clvr::tetReferenceIntegral(mesh, tf, c.camera, scene.image),
                                           {.maxAbs = 2e-3, .meanAbs = 2e-4}));
        EXPECT_GT(result.segments, 1000u);
        EXPECT_LE(std::abs(static_cast<double>(result.segments) - static_cast<double>(steps)), 2e-3 * static_cast<double>(steps));
        EXPECT_LE(result.segments, fragments);
        EXPECT_GE(result.pixelsTested, result.segments);
    }
}

// The same loop on tetslice's fused path (harc's walk sampling the slices tetsliceWalkOptions plans): the same cells
// entered and slices taken as the kernel, the same image up to float rounding; the cells shuffled as a mesher may
// number them, so that the loop walks harc's Morton order (harcCellOrder) as the renderer does.
TEST(HarcCeiling, WalksTetslicesSlicesLikeTheKernel)
{
    const glm::dvec3 gradient(0.3, 0.35, -0.4);
    clvr::TetMesh mesh = clvr::test::boxMesh({{{0.0, 0.0, 0.0}, {1.0, 1.0, 0.4}, 4}, {{0.0, 0.0, 0.7}, {1.0, 1.0, 1.2}, 4}},
                                             gradient, 0.4);
    clvr::checkMesh(mesh);
    std::mt19937 random(5);
    std::shuffle(mesh.tets.begin(), mesh.tets.end(), random);
    const clvr::TetTopology topology = clvr::buildTopology(mesh);
    const std::vector<std::uint32_t> slot = clvr::harcCellOrder(mesh, topology);
    ASSERT_FALSE(std::is_sorted(slot.begin(), slot.end()));  // the loop walks a reordered mesh
    for (const clvr::Camera& camera : {clvr::test::perspective({0.4, 0.6, 3.0}, {0.5, 0.5, 0.6}, 40.0),
                                       clvr::test::parallelView({2.5, -1.5, 1.8}, {0.5, 0.5, 0.6}, 0.9)}) {
        clvr::Scene scene = clvr::test::meshScene("tetslice", camera, clvr::test::rampTransferFunction(), 40,
                                                  {{"slices", 70}, {"path", "fused"}});
        clvr::FrameStats stats;
        const clvr::Image4f kernel = clvr::makeMeshRenderer(clvr::test::device(), scene, mesh)->render(stats);
        const clvr::HarcOptions walk = clvr::tetsliceWalkOptions(scene, mesh, clvr::parseTetsliceOptions(scene.options));
        ASSERT_EQ(walk.integration, clvr::HarcOptions::Integration::Slices);
        const clvr::tools::HarcCeiling ceiling(mesh, topology, scene.transferFunction, *scene.camera, scene.image, walk);
        const clvr::tools::HarcCeilingResult result = ceiling.render(2);
        EXPECT_GT(result.pieces, 1000u);
        EXPECT_EQ(result.steps, stats.extra["steps"].get<std::uint64_t>());
        EXPECT_EQ(result.pieces, stats.samples);  // slices taken
        EXPECT_TRUE(clvr::test::imagesNear(result.image, clvr::raster::reference::toDouble(kernel),
                                           {.maxAbs = 1e-5, .meanAbs = 1e-6}));
    }
}

// And on tetiso's fused path (harc's walk to each ray's first crossing of the iso-value, shaded from the vertex
// normals tetisoWalkOptions hands harc): the same cells entered and rays that hit, the same image up to float
// rounding; interpolated and equal weights, unshaded; the cells shuffled so that the loop walks harc's Morton order.
TEST(HarcCeiling, WalksTetisosFirstCrossingLikeTheKernel)
{
    clvr::TetMesh mesh = clvr::test::boxMesh({{{0.0, 0.0, 0.0}, {1.0, 1.0, 0.4}, 4}, {{0.0, 0.0, 0.7}, {1.0, 1.0, 1.2}, 4}},
                                             glm::dvec3(0.3, 0.35, -0.4), 0.4);
    for (std::size_t i = 0; i < mesh.points.size(); ++i)  // a cone: the normals differ from point to point
        mesh.scalars[i] = 1.0 - glm::length(mesh.points[i] - glm::dvec3(0.5, 0.45, 0.55));
    clvr::checkMesh(mesh);
    std::mt19937 random(9);
    std::shuffle(mesh.tets.begin(), mesh.tets.end(), random);
    const clvr::TetTopology topology = clvr::buildTopology(mesh);
    struct Case {
        const char* name;
        nlohmann::json options;
        clvr::IsoSpec::Shading shading;
    };
    for (const Case& c : {Case{"interpolated", {{"path", "fused"}}, clvr::IsoSpec::Shading::Gradient},
                          Case{"equal", {{"path", "fused"}, {"weights", "equal"}}, clvr::IsoSpec::Shading::Gradient},
                          Case{"unshaded", {{"path", "fused"}}, clvr::IsoSpec::Shading::None}}) {
        clvr::Scene scene = clvr::test::meshScene("tetiso", clvr::test::perspective({0.4, 0.6, 3.0}, {0.5, 0.5, 0.6}, 40.0),
                                                  clvr::test::rampTransferFunction(), 40, c.options);
        scene.iso = clvr::IsoSpec{};
        scene.iso->value = 0.62;
        scene.iso->shading = c.shading;
        clvr::FrameStats stats;
        const clvr::Image4f kernel = clvr::makeMeshRenderer(clvr::test::device(), scene, mesh)->render(stats);
        const clvr::HarcOptions walk = clvr::tetisoWalkOptions(scene, mesh);
        ASSERT_EQ(walk.integration, clvr::HarcOptions::Integration::Iso);
        const clvr::tools::HarcCeiling ceiling(mesh, topology, scene.transferFunction, *scene.camera, scene.image, walk);
        const clvr::tools::HarcCeilingResult result = ceiling.render(2);
        EXPECT_GT(result.pieces, 100u) << c.name;  // rays that hit (195 of 1600)
        EXPECT_LT(result.pieces, 1600u) << c.name;  // and rays that miss
        EXPECT_EQ(result.steps, stats.extra["steps"].get<std::uint64_t>()) << c.name;
        EXPECT_EQ(result.pieces, stats.extra["pixels_hit"].get<std::uint64_t>()) << c.name;
        EXPECT_TRUE(clvr::test::imagesNear(result.image, clvr::raster::reference::toDouble(kernel),
                                           {.maxAbs = 1e-5, .meanAbs = 1e-6}))
            << c.name;
    }
}

}  // namespace

// ---- resample-then-shade bench scenes (tools/make_rts_bench.py, `clvr bench --suite rts`) --------------

namespace {

std::vector<std::filesystem::path> benchScenesStartingWith(const std::string& prefix)
{
    std::vector<std::filesystem::path> out;
    for (const auto& entry : std::filesystem::directory_iterator(std::filesystem::path(CLVR_SOURCE_DIR) / "data/scenes/bench"))
        if (entry.path().filename().string().starts_with(prefix))
            out.push_back(entry.path());
    std::sort(out.begin(), out.end());
    return out;
}

}  // namespace

// Every scene is valid (loadScene checks every key), 512x512, planes or blend; the opaque transfer
// function is the translucent one with 25x the extinction at every control point; the engine's
// "no-ert" and "no-skip" scenes differ from their base scene in that one option only.
TEST(BenchRts, ScenesAreValidAndDifferOnlyWhereTheyShould)
{
    const std::vector<std::filesystem::path> files = benchScenesStartingWith("rts-");
    ASSERT_EQ(files.size(), 16u);  // 3 volumes x 2 transfer functions x 2 techniques + 4 planes on/off
    for (const auto& file : files) {
        const clvr::Scene scene = clvr::loadScene(file);
        EXPECT_TRUE(scene.technique == "planes" || scene.technique == "blend") << file;
        EXPECT_EQ(scene.image.width, 512) << file;
        EXPECT_EQ(scene.image.height, 512) << file;
        const std::string name = file.filename().string();
        const auto at = name.find("-opaque");
        if (at != std::string::npos && name.find("-no-") == std::string::npos) {
            std::string translucentName = name;
            translucentName.replace(at, 7, "-translucent");
            const clvr::Scene translucent = clvr::loadScene(file.parent_path() / translucentName);
            const auto& o = scene.transferFunction.points();
            const auto& t = translucent.transferFunction.points();
            ASSERT_EQ(o.size(), t.size()) << name;
            for (std::size_t i = 0; i < o.size(); ++i) {
                EXPECT_EQ(o[i].s, t[i].s) << name;
                EXPECT_NEAR(o[i].tau, 25.0 * t[i].tau, 1e-6 * (1.0 + o[i].tau)) << name << " point " << i;
            }
        }
        for (const char* off : {"-no-ert", "-no-skip"}) {
            const auto cut = name.find(off);
            if (cut == std::string::npos)
                continue;
            const std::string baseName = name.substr(0, cut) + ".json";
            const clvr::Scene base = clvr::loadScene(file.parent_path() / baseName);
            nlohmann::json diff = nlohmann::json::diff(base.options, scene.options);
            ASSERT_EQ(diff.size(), 1u) << name << ": " << diff.dump();
            EXPECT_EQ(diff[0]["path"], std::string(off) == "-no-ert" ? "/early_termination" : "/opacity_threshold")
                << name;
        }
    }
}

// ---- the other regular-grid bench scenes (tools/make_regular_bench.py, `clvr bench --suite regular`) -----

// The suite lists exactly the reg-* files there are; every scene loads, is 512x512 and names the technique
// its file name says; each clip scene is its raster-path baseline plus the clip mesh and nothing else
// (each clip-texture scene its fused baseline plus the clip texture, each bricked iso-surface its
// unbricked one plus the budget),
// each k1 stack is its plain stack with one intermediate slice, and each p4 stack its k1 stack with four
// slices per polygon.
TEST(BenchRegular, ScenesAreValidAndPairsDifferOnlyWhereTheyShould)
{
    const std::vector<std::filesystem::path> files = benchScenesStartingWith("reg-");
    std::vector<std::string> listed = clvr::tools::benchSuiteScenes("regular");
    std::vector<std::string> present;
    for (const auto& file : files)
        present.push_back(file.filename().string());
    std::sort(listed.begin(), listed.end());
    EXPECT_EQ(listed, present);
    // 3 volumes x (iso3d fused and raster, bricked iso3d, 4 stacks, raster baseline, clip mesh, fused
    // baseline, fused clip mesh, clip texture) + the gradientless engine + the clipped stack on the engine +
    // spherical fused and raster
    ASSERT_EQ(files.size(), 40u);
    for (const auto& file : files) {
        const clvr::Scene scene = clvr::loadScene(file);
        const std::string name = file.filename().string();
        EXPECT_EQ(scene.image.width, 512) << name;
        EXPECT_EQ(scene.image.height, 512) << name;
        const std::string expected = name.starts_with("reg-iso3d")       ? "iso3d"
                                     : name.starts_with("reg-stack2d")   ? "stack2d"
                                     : name.starts_with("reg-spherical") ? "spherical"
                                                                         : "slice3d";
        EXPECT_EQ(scene.technique, expected) << name;
        auto differsOnlyIn = [&](const std::string& baseName, const std::string& path) {
            const clvr::Scene base = clvr::loadScene(file.parent_path() / baseName);
            const nlohmann::json diff = nlohmann::json::diff(base.options, scene.options);
            ASSERT_EQ(diff.size(), 1u) << name << ": " << diff.dump();
            EXPECT_EQ(diff[0]["path"], path) << name;
            EXPECT_EQ(base.volume, scene.volume) << name;
        };
        if (name.starts_with("reg-clip-"))
            differsOnlyIn("reg-slice3d-raster-" + name.substr(9), "/clip");
        if (name.starts_with("reg-clipmesh-"))
            differsOnlyIn("reg-slice3d-" + name.substr(13), "/clip");
        if ((name.starts_with("reg-iso3d-") || name.starts_with("reg-stack2d-") || name.starts_with("reg-spherical-")) &&
            name.ends_with("-raster.json"))
            differsOnlyIn(name.substr(0, name.size() - 12) + ".json", "/path");
        if (name.ends_with("-bricked.json"))
            differsOnlyIn(name.substr(0, name.size() - 13) + ".json", "/brick_budget");
        if (name.ends_with("-k1-cliptex.json"))
            differsOnlyIn(name.substr(0, name.size() - 13) + ".json", "/clip_texture");
        if (name.starts_with("reg-cliptex-"))
            differsOnlyIn("reg-slice3d-" + name.substr(12), "/clip_texture");
        if (name.ends_with("-k1.json"))
            differsOnlyIn(name.substr(0, name.size() - 8) + ".json", "/intermediate");
        if (name.ends_with("-p4.json"))
            differsOnlyIn(name.substr(0, name.size() - 8) + ".json", "/slices_per_polygon");
    }
}

// ---- cell-face bench scenes (tools/make_tetfaces_bench.py, `clvr bench --suite tetfaces`) --------------

// The suite lists exactly the tetfaces-* files; every scene is valid, 400x400 as seeds/000's experiments,
// and each harc scene is its tetslice twin with only the technique and the options changed.
TEST(BenchTetfaces, ScenesAreValidAndHarcTwinsDifferOnlyInTheTechnique)
{
    const std::vector<std::filesystem::path> files = benchScenesStartingWith("tetfaces-");
    std::vector<std::string> listed = clvr::tools::benchSuiteScenes("tetfaces");
    std::vector<std::string> present;
    for (const auto& file : files)
        present.push_back(file.filename().string());
    std::sort(listed.begin(), listed.end());
    EXPECT_EQ(listed, present);
    // 4 meshes x (tetslice's face draws, its fused path, harc) + the automaton x (the two tetiso, the two
    // tetslice, harc)
    ASSERT_EQ(files.size(), 17u);
    for (const auto& file : files) {
        const clvr::Scene scene = clvr::loadScene(file);
        const std::string name = file.filename().string();
        EXPECT_EQ(scene.image.width, 400) << name;
        EXPECT_EQ(scene.image.height, 400) << name;
        EXPECT_TRUE(name.ends_with("-" + scene.technique + ".json")) << name;
        if (scene.technique == "harc") {
            std::string twin = name;
            twin.replace(twin.size() - std::string("harc.json").size(), std::string::npos, "tetslice.json");
            const clvr::Scene other = clvr::loadScene(file.parent_path() / twin);
            EXPECT_TRUE(*scene.mesh == *other.mesh) << name;
            EXPECT_EQ(scene.camera->position, other.camera->position) << name;
            EXPECT_EQ(other.options["slices"].get<int>(), 400) << name;
            EXPECT_EQ(other.options["path"], "raster") << name;  // seeds/000's method
        }
        if (name.ends_with("-fused-tetiso.json")) {  // its face-draw twin but for the path
            const clvr::Scene other = clvr::loadScene(file.parent_path() / "tetfaces-automaton-tetiso.json");
            EXPECT_TRUE(*scene.mesh == *other.mesh) << name;
            EXPECT_EQ(scene.iso->value, other.iso->value) << name;
            EXPECT_EQ(scene.options["path"], "fused") << name;
            EXPECT_EQ(other.options["path"], "raster") << name;
        }
        if (name.ends_with("-fused-tetslice.json")) {  // its face-draw twin but for the path
            std::string twin = name;
            twin.replace(twin.find("-fused-tetslice.json"), std::string::npos, "-tetslice.json");
            const clvr::Scene other = clvr::loadScene(file.parent_path() / twin);
            EXPECT_TRUE(*scene.mesh == *other.mesh) << name;
            EXPECT_EQ(scene.options["path"], "fused") << name;
            nlohmann::json raster = scene.options;
            raster["path"] = "raster";
            EXPECT_EQ(raster, other.options) << name;
        }
    }
}

// ---- cubefan bench scenes (tools/make_cubefan_bench.py, `clvr bench --suite cubefan`) ---------------------

// The suite lists exactly the cubefan-* files in the order clvr bench needs (each group's full-quality scene
// first: error 0, 1024 slices); every scene is the engine at 512x512 with one camera and transfer function.
TEST(BenchCubefan, ScenesShareTheViewAndEachGroupStartsWithItsFullQualityScene)
{
    const std::vector<std::filesystem::path> files = benchScenesStartingWith("cubefan-");
    const std::vector<std::string> listed = clvr::tools::benchSuiteScenes("cubefan");
    std::vector<std::string> present, sorted = listed;
    for (const auto& file : files)
        present.push_back(file.filename().string());
    std::sort(sorted.begin(), sorted.end());
    EXPECT_EQ(sorted, present);
    ASSERT_EQ(listed.size(), 18u);
    EXPECT_EQ(listed.front(), "cubefan-engine-e0.json");
    EXPECT_EQ(listed[11], "cubefan-slice3d-1024.json");
    const clvr::Scene first = clvr::loadScene(files.front().parent_path() / listed.front());
    EXPECT_EQ(first.options["error"].get<double>(), 0.0);
    for (const std::string& name : listed) {
        const clvr::Scene scene = clvr::loadScene(files.front().parent_path() / name);
        EXPECT_EQ(scene.image.width, 512) << name;
        EXPECT_EQ(scene.camera->position, first.camera->position) << name;
        EXPECT_EQ(scene.transferFunction.points().size(), first.transferFunction.points().size()) << name;
        EXPECT_EQ(scene.technique, name.starts_with("cubefan-engine-") ? "cubefan" : "slice3d") << name;
        if (name.starts_with("cubefan-engine-")) {  // e: the paper's fans, x: exact chords on the raster path, f: fused,
            const clvr::CubefanOptions o = clvr::parseCubefanOptions(scene.options);  // t: tiles
            EXPECT_EQ(o.path, name[15] == 'f'   ? clvr::CubefanOptions::Path::Fused
                              : name[15] == 't' ? clvr::CubefanOptions::Path::Tiles
                                                : clvr::CubefanOptions::Path::Raster)
                << name;
            EXPECT_EQ(o.exactThickness, name[15] == 'x') << name;
        }
    }
}

// ---- accuracy bench scenes (tools/make_accuracy_bench.py, `clvr bench --suite accuracy --reference`) ------

// The suite lists exactly the acc-* files; each is slice3d with the view and transfer function of its
// original bench scene (reg-slice3d-ml256, slice3d-engine), only the slice count and integration changed.
TEST(BenchAccuracy, ScenesAreTheBenchViewsWithOnlySlicesAndIntegrationChanged)
{
    const std::vector<std::filesystem::path> files = benchScenesStartingWith("acc-");
    const std::vector<std::string> listed = clvr::tools::benchSuiteScenes("accuracy");
    std::vector<std::string> present, sorted = listed;
    for (const auto& file : files)
        present.push_back(file.filename().string());
    std::sort(sorted.begin(), sorted.end());
    EXPECT_EQ(sorted, present);
    ASSERT_EQ(listed.size(), 24u);
    const std::filesystem::path dir = files.front().parent_path();
    for (const std::string& name : listed) {
        const clvr::Scene scene = clvr::loadScene(dir / name);
        const clvr::Scene original =
            clvr::loadScene(dir / (name.starts_with("acc-ml256-") ? "reg-slice3d-ml256.json" : "slice3d-engine.json"));
        EXPECT_EQ(scene.technique, "slice3d") << name;
        EXPECT_EQ(scene.camera->position, original.camera->position) << name;
        EXPECT_EQ(scene.image.width, original.image.width) << name;
        ASSERT_EQ(scene.transferFunction.points().size(), original.transferFunction.points().size()) << name;
        for (std::size_t i = 0; i < scene.transferFunction.points().size(); ++i)
            EXPECT_EQ(scene.transferFunction.points()[i].tau, original.transferFunction.points()[i].tau) << name;
        const clvr::Slice3dOptions o = clvr::parseSlice3dOptions(scene.options);
        EXPECT_EQ(o.preintegrated, name.find("-pre-") != std::string::npos) << name;
        EXPECT_EQ(std::to_string(o.slices) + ".json", name.substr(name.rfind('-') + 1)) << name;
    }
}

// ---- projtet bench scenes (`clvr bench --suite projtet`) --------------------------------------------------

// Each projtet scene is its harc twin with only the technique changed, and the suite lists each pair
// harc first; harc-post.json is data/scenes/post.json's scene.
TEST(BenchProjtet, EveryProjtetSceneIsItsHarcTwin)
{
    const std::vector<std::string> listed = clvr::tools::benchSuiteScenes("projtet");
    ASSERT_EQ(listed.size(), 6u);
    const std::filesystem::path dir = benchScenesStartingWith("harc-").front().parent_path();
    for (std::size_t i = 0; i < listed.size(); i += 2) {
        ASSERT_TRUE(listed[i].starts_with("harc-")) << listed[i];
        EXPECT_EQ("projtet-" + listed[i].substr(5), listed[i + 1]);
        const std::string harc = clvr::test::readFile(dir / listed[i]);
        std::string projtet = clvr::test::readFile(dir / listed[i + 1]);
        const std::string tag = "\"technique\": \"projtet\"";
        ASSERT_NE(projtet.find(tag), std::string::npos) << listed[i + 1];
        projtet.replace(projtet.find(tag), tag.size(), "\"technique\": \"harc\"");
        EXPECT_EQ(projtet, harc) << listed[i + 1];
        EXPECT_EQ(clvr::loadScene(dir / listed[i + 1]).technique, "projtet");
    }
    const clvr::Scene post = clvr::loadScene(dir / "harc-post.json");
    const clvr::Scene original = clvr::loadScene(clvr::test::repoData("scenes/post.json"));
    EXPECT_EQ(std::filesystem::weakly_canonical(post.mesh->file), std::filesystem::weakly_canonical(original.mesh->file));
    EXPECT_EQ(post.mesh->scalar, original.mesh->scalar);
    EXPECT_EQ(post.transferFunction.points().size(), original.transferFunction.points().size());
    EXPECT_EQ(post.camera->position, original.camera->position);
}
