// tests/slice3d_test.cpp — 3D-texture slicing: slice polygons, options, the fused kernel against the
// CPU reference integral (error falling with the slice count), back-to-front == front-to-back,
// early ray termination bound, fused == pass-by-pass raster path, identical bits, orientation.
#include "host/render/slice3d.h"

#include "host/errors.h"
#include "host/generators.h"
#include "host/image_io.h"
#include "host/reference_integral.h"
#include "host/render/renderer.h"
#include "host/volume_io.h"
#include "tests/test_util.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>

namespace clvr {
namespace {

using nlohmann::json;

TransferFunction mlTransferFunction()
{
    // DESIGN.md's example: s in [0,1], tau per world unit (the box is 2 wide).
    return TransferFunction({{0.0, {0, 0, 0}, 0.0}, {0.5, {1, 0.5, 0}, 4.0}, {1.0, {1, 1, 1}, 8.0}});
}

Camera perspectiveCamera()
{
    Camera c;
    c.position = {1.2, 1.6, 3.7};
    c.focalPoint = {0.0, 0.0, 0.0};
    c.viewUp = {0.0, 1.0, 0.0};
    c.viewAngle = 40.0;
    return c;
}

Camera parallelCamera()
{
    Camera c;
    c.position = {3.5, 1.0, 1.9};
    c.focalPoint = {0.0, 0.0, 0.0};
    c.viewUp = {0.0, 0.0, 1.0};
    c.parallel = true;
    c.parallelScale = 1.8;
    return c;
}

Scene makeScene(const Camera& camera, const TransferFunction& tf, int size, json options = json::object(),
                glm::dvec3 background = {0.1, 0.2, 0.3})
{
    Scene s;
    s.technique = "slice3d";
    s.camera = camera;
    s.image = ImageSpec{size, size, background};
    s.transferFunction = tf;
    s.options = std::move(options);
    return s;
}

Image4f renderScene(const Scene& scene, const Volume& volume, FrameStats* statsOut = nullptr)
{
    auto renderer = makeRenderer(test::device(), scene, volume);
    FrameStats stats;
    Image4f image = renderer->render(stats);
    if (statsOut)
        *statsOut = stats;
    return image;
}

Image4d reference(const Scene& scene, const Volume& volume)
{
    return referenceIntegral(volume, scene.transferFunction, *scene.camera, scene.image);
}

const Volume& marschnerLobb41()
{
    static const Volume v = generateVolume("marschner-lobb", {41, 41, 41});
    return v;
}

double maxChannel(const glm::dvec4& v) { return std::max({v.r, v.g, v.b, v.a}); }

// ---- slice polygons --------------------------------------------------------------------------

TEST(Slice3dPolygon, RandomPlanesGiveConvexPolygonsOnTheBox)
{
    test::Rng rng(7);
    const glm::dvec3 lo(-1.0, -0.5, 0.2), hi(0.8, 1.5, 0.9);
    int counts[7] = {};
    for (int trial = 0; trial < 2000; ++trial) {
        glm::dvec3 n;
        do
            n = {rng.uniform(-1, 1), rng.uniform(-1, 1), rng.uniform(-1, 1)};
        while (glm::length(n) < 0.1);
        n = glm::normalize(n);
        // Offsets spanning the box's range along n, so nearly every plane cuts it.
        double dMin = 1e30, dMax = -1e30;
        for (int c = 0; c < 8; ++c) {
            const double d = glm::dot(n, glm::dvec3((c & 1) ? hi.x : lo.x, (c & 2) ? hi.y : lo.y, (c & 4) ? hi.z : lo.z));
            dMin = std::min(dMin, d);
            dMax = std::max(dMax, d);
        }
        const double offset = rng.uniform(dMin, dMax);
        const std::vector<glm::dvec3> poly = slicePolygon(lo, hi, n, offset);
        ASSERT_GE(poly.size(), 3u);
        ASSERT_LE(poly.size(), 6u);
        ++counts[poly.size()];
        double sign = 0.0;
        for (std::size_t i = 0; i < poly.size(); ++i) {
            const glm::dvec3& p = poly[i];
            EXPECT_NEAR(glm::dot(n, p), offset, 1e-12);  // on the plane
            int onFace = 0;
            for (int a = 0; a < 3; ++a) {
                EXPECT_GE(p[a], lo[a] - 1e-12);
                EXPECT_LE(p[a], hi[a] + 1e-12);
                onFace += std::abs(p[a] - lo[a]) < 1e-12 || std::abs(p[a] - hi[a]) < 1e-12;
            }
            EXPECT_GE(onFace, 2) << "a vertex lies on a box edge";
            // Convex and consistently ordered: every turn has the same sign about n.
            const glm::dvec3 e0 = poly[(i + 1) % poly.size()] - p;
            const glm::dvec3 e1 = poly[(i + 2) % poly.size()] - poly[(i + 1) % poly.size()];
            const double turn = glm::dot(glm::cross(e0, e1), n);
            if (sign == 0.0)
                sign = turn;
            EXPECT_GT(turn * sign, 0.0);
        }
        EXPECT_GT(sign, 0.0);  // counter-clockwise about n
    }
    EXPECT_GT(counts[3], 0);
    EXPECT_GT(counts[4], 0);
    EXPECT_GT(counts[5], 0);
    EXPECT_GT(counts[6], 0);
}

TEST(Slice3dPolygon, SpecialPlanes)
{
    const glm::dvec3 lo(-1.0), hi(1.0);
    EXPECT_TRUE(slicePolygon(lo, hi, {0, 0, 1}, 1.5).empty());  // misses
    EXPECT_EQ(slicePolygon(lo, hi, {0, 0, 1}, 0.0).size(), 4u);  // axis-aligned square
    EXPECT_EQ(slicePolygon(lo, hi, {0, 0, 1}, 1.0).size(), 4u);  // the face itself
    const glm::dvec3 diag = glm::normalize(glm::dvec3(1.0));
    EXPECT_EQ(slicePolygon(lo, hi, diag, 0.0).size(), 6u);                      // regular hexagon
    EXPECT_EQ(slicePolygon(lo, hi, diag, glm::dot(diag, glm::dvec3(1, 1, -1))).size(), 3u);  // through 3 corners
    EXPECT_TRUE(slicePolygon(lo, hi, diag, std::sqrt(3.0)).empty());            // touches a corner only
}

TEST(Slice3dPlan, SlicesSpanTheEyeDepthRange)
{
    Camera c;
    c.position = {0, 0, 4};
    Slice3dOptions o;
    o.slices = 10;
    SlicePlan p = planSlices(c, glm::dvec3(-1), glm::dvec3(1), o);
    EXPECT_DOUBLE_EQ(p.depthMin, 3.0);
    EXPECT_DOUBLE_EQ(p.depthMax, 5.0);
    EXPECT_EQ(p.count, 10);
    EXPECT_DOUBLE_EQ(p.depth(0), 3.1);
    o.sliceSpacing = 0.3;
    p = planSlices(c, glm::dvec3(-1), glm::dvec3(1), o);
    EXPECT_EQ(p.count, 7);  // ceil(2 / 0.3)
    EXPECT_DOUBLE_EQ(p.deltaS, 0.3);
    c.position = {0, 0, 0.5};  // inside: slices start at the camera
    o.sliceSpacing = 0.0;
    p = planSlices(c, glm::dvec3(-1), glm::dvec3(1), o);
    EXPECT_DOUBLE_EQ(p.depthMin, 0.0);
    EXPECT_DOUBLE_EQ(p.depthMax, 1.5);
}

// ---- options ---------------------------------------------------------------------------------

void expectInputError(const json& options, const std::string& fragment)
{
    try {
        parseSlice3dOptions(options);
        ADD_FAILURE() << "no InputError for " << options.dump();
    } catch (const InputError& e) {
        EXPECT_NE(std::string(e.what()).find(fragment), std::string::npos) << e.what();
    }
}

TEST(Slice3dOptions, BadOptionsThrowInputErrorNamingTheKey)
{
    expectInputError({{"foo", 1}},
                     "options.foo: unknown option for slice3d (known: slices, slice_spacing, order, early_termination, path)");
    expectInputError({{"slices", 0}}, "options.slices");
    expectInputError({{"slices", 65537}}, "options.slices");
    expectInputError({{"slices", 2.5}}, "options.slices");
    expectInputError({{"slices", "many"}}, "options.slices");
    expectInputError({{"slice_spacing", -0.1}}, "options.slice_spacing");
    expectInputError({{"slice_spacing", 0.1}, {"slices", 4}}, "options.slice_spacing");
    expectInputError({{"order", "sideways"}}, "options.order");
    expectInputError({{"path", "gpu"}}, "options.path");
    expectInputError({{"early_termination", 1.5}}, "options.early_termination");
    expectInputError({{"early_termination", 0.9}}, "options.early_termination");  // needs front-to-back
    expectInputError({{"early_termination", 0.9}, {"order", "front-to-back"}, {"path", "raster"}},
                     "options.early_termination");
    EXPECT_NO_THROW(parseSlice3dOptions({{"slices", 65536}, {"order", "front-to-back"}, {"early_termination", 0.99},
                                         {"path", "fused"}}));
}

TEST(Slice3dOptions, MakeRendererRejectsUnknownTechniqueAndMissingVolume)
{
    Scene scene = makeScene(perspectiveCamera(), mlTransferFunction(), 16);
    scene.technique = "raytrace";
    try {
        makeRenderer(test::device(), scene, marschnerLobb41());
        ADD_FAILURE() << "no InputError";
    } catch (const InputError& e) {
        EXPECT_NE(std::string(e.what()).find("slice3d"), std::string::npos) << e.what();
        EXPECT_NE(std::string(e.what()).find("raytrace"), std::string::npos) << e.what();
    }
    scene.technique = "slice3d";
    EXPECT_THROW(makeRenderer(test::device(), scene, Volume{}), InputError);
    scene.options = {{"slices", -3}};
    EXPECT_THROW(makeRenderer(test::device(), scene, marschnerLobb41()), InputError);
    // slice_spacing so fine that the view needs more than 65536 slices.
    scene.options = {{"slice_spacing", 1e-6}};
    EXPECT_THROW(makeRenderer(test::device(), scene, marschnerLobb41()), InputError);
}

TEST(Slice3dRenderer, ResidentBytesAreFloat32Volume)
{
    auto renderer = makeRenderer(test::device(), makeScene(perspectiveCamera(), mlTransferFunction(), 16),
                                 marschnerLobb41());
    // 4 bytes per grid point, plus the packed transfer function (3 points: 4 + 12 floats).
    EXPECT_EQ(renderer->residentBytes(), 41u * 41u * 41u * 4u + 16u * 4u);
}


// ---- images ----------------------------------------------------------------------------------

void report(const char* what, const test::ImageError& e)
{
    std::printf("[ measured ] %s: max |diff| %.3g %.3g %.3g %.3g, mean %.3g %.3g %.3g %.3g\n", what, e.maxAbs.r,
                e.maxAbs.g, e.maxAbs.b, e.maxAbs.a, e.meanAbs.r, e.meanAbs.g, e.meanAbs.b, e.meanAbs.a);
}

void writePng(const std::string& name, const Image4f& image)
{
    std::filesystem::create_directories("test_output");
    writeImage("test_output/" + name + ".png", image);
}

TEST(Slice3dFused, MarschnerLobbPerspectiveMatchesReference)
{
    const Scene scene = makeScene(perspectiveCamera(), mlTransferFunction(), 64);
    FrameStats stats;
    const Image4f image = renderScene(scene, marschnerLobb41(), &stats);
    writePng("slice3d_ml_perspective", image);
    const test::ImageError e = test::imageError(image, reference(scene, marschnerLobb41()));
    report("ML 41^3 perspective 64x64, 256 slices", e);
    EXPECT_GT(stats.samples, 0u);
    EXPECT_EQ(stats.extra["slices"], 256);
}

TEST(Slice3dFused, MarschnerLobbParallelMatchesReference)
{
    const Scene scene = makeScene(parallelCamera(), mlTransferFunction(), 64);
    const Image4f image = renderScene(scene, marschnerLobb41());
    writePng("slice3d_ml_parallel", image);
    const test::ImageError e = test::imageError(image, reference(scene, marschnerLobb41()));
    report("ML 41^3 parallel 64x64, 256 slices", e);
}

TEST(Slice3dFused, ErrorFallsWithSliceCount)
{
    const Scene base = makeScene(perspectiveCamera(), mlTransferFunction(), 48);
    const Image4d want = reference(base, marschnerLobb41());
    for (int n : {32, 64, 128, 256, 512}) {
        Scene scene = base;
        scene.options = {{"slices", n}};
        const test::ImageError e = test::imageError(renderScene(scene, marschnerLobb41()), want);
        report(("slices " + std::to_string(n)).c_str(), e);
    }
}

TEST(Slice3dRaster, MatchesFused)
{
    for (const Camera& camera : {perspectiveCamera(), parallelCamera()}) {
        Scene scene = makeScene(camera, mlTransferFunction(), 64, {{"slices", 64}});
        const Image4f fused = renderScene(scene, marschnerLobb41());
        scene.options["path"] = "raster";
        FrameStats stats;
        const Image4f raster = renderScene(scene, marschnerLobb41(), &stats);
        writePng(camera.parallel ? "slice3d_ml_raster_parallel" : "slice3d_ml_raster_perspective", raster);
        Image4d fusedD(fused.width(), fused.height());
        for (std::size_t i = 0; i < fused.pixelCount(); ++i)
            fusedD.pixels()[i] = glm::dvec4(fused.pixels()[i]);
        report("raster vs fused, 64 slices", test::imageError(raster, fusedD));
        for (int y = 0; y < 64; y += 2) { for (int x = 0; x < 64; x += 1) { float d = glm::length(fused.at(x,y) - raster.at(x,y)); std::printf("%c", d > 0.05 ? '#' : d > 1e-3 ? '+' : fused.at(x,y).a > 0 ? '.' : ' '); } std::printf("\n"); }
        for (int y : {10, 32, 50}) for (int x : {10, 32, 50}) {
            auto f = fused.at(x, y), r = raster.at(x, y);
            std::printf("(%d,%d) fused %.4f %.4f %.4f %.4f raster %.4f %.4f %.4f %.4f\n", x, y, f.r, f.g, f.b, f.a, r.r, r.g, r.b, r.a);
        }
        std::printf("passes:");
        for (auto& p : stats.passes) std::printf(" %s %.1f ms;", p.name.c_str(), p.ms);
        std::printf(" samples %llu\n", (unsigned long long)stats.samples);
    }
}


// Not a test (DESIGN.md: speed is measured by clvr bench): the brief's benchmark configuration,
// run by hand with --gtest_also_run_disabled_tests --gtest_filter='*Benchmark*'.
TEST(Slice3dBenchmark, DISABLED_MarschnerLobb256Image512Slices256)
{
    const Volume volume = generateVolume("marschner-lobb", {256, 256, 256});
    for (const char* path : {"fused", "raster"}) {
        const Scene scene = makeScene(perspectiveCamera(), mlTransferFunction(), 512, {{"slices", 256}, {"path", path}});
        auto renderer = makeRenderer(test::device(), scene, volume);
        std::vector<double> frame, device;
        FrameStats stats;
        Image4f image;
        for (int i = 0; i < 5; ++i) {
            image = renderer->render(stats);
            frame.push_back(stats.frameMs);
            double ms = 0.0;
            for (const PassTime& p : stats.passes)
                ms += p.ms;
            device.push_back(ms);
        }
        writePng(std::string("slice3d_bench_") + path, image);
        std::sort(frame.begin(), frame.end());
        std::sort(device.begin(), device.end());
        std::printf("[ bench    ] %s: %s, median frame %.1f ms (device %.1f ms), samples %llu, %.1f M samples/s, "
                    "compile %.0f ms\n",
                    path, test::device().description().c_str(), frame[2], device[2],
                    static_cast<unsigned long long>(stats.samples), stats.samples / frame[2] * 1e-3,
                    test::device().compileMs());
        for (const PassTime& p : stats.passes)
            std::printf("    %s %.1f ms\n", p.name.c_str(), p.ms);
    }
}

}  // namespace
}  // namespace clvr
