// tests/blend_test.cpp — the Blend method (seeds/004 §3.2): options, the shaded image against the CPU shaded
// reference integral (parallel and perspective), error falling with the slice count, the opacity threshold
// within its bound, and agreement with planes on the same scene.
#include "host/render/grid/blend.h"

#include "host/runtime/errors.h"
#include "host/io/generators.h"
#include "host/optics/gradient_volume.h"
#include "host/reference/reference_integral.h"
#include "host/optics/reflectance_map.h"
#include "tests/support/test_util.h"

#include <cmath>
#include <cstdio>

namespace clvr {
namespace {

using nlohmann::json;

const Volume& sphere33()
{
    static const Volume v = generateVolume("sphere", {33, 33, 33});
    return v;
}

// As tests/planes_test.cpp: shells of "sphere" where the gradient has length 1, two lights.
Scene makeScene(const Camera& camera, json options)
{
    Scene s;
    s.technique = "blend";
    s.camera = camera;
    s.image = ImageSpec{40, 40, {0.1, 0.2, 0.3}};
    s.transferFunction = TransferFunction({{0.2, {0.2, 0.4, 1.0}, 0.0}, {0.3, {0.3, 0.6, 1.0}, 3.0},
                                           {0.5, {1.0, 0.8, 0.3}, 6.0}, {0.6, {1.0, 0.9, 0.7}, 0.0}});
    s.options = std::move(options);
    s.lighting = test::twoLightLighting();
    return s;
}

Camera perspectiveCamera()
{
    return test::obliquePerspectiveCamera(40.0);
}

Camera parallelCamera()
{
    return test::obliqueParallelCamera(1.2);
}

Image4f render(const Scene& scene, FrameStats* statsOut = nullptr)
{
    auto renderer = makeRenderer(test::device(), scene, sphere33());
    FrameStats stats;
    Image4f image = renderer->render(stats);
    if (statsOut)
        *statsOut = stats;
    return image;
}

Image4d shadedReference(const Scene& scene)
{
    static const std::vector<glm::vec4> gradients = sobelGradientVolume(sphere33());
    const ReferenceShading shading{&gradients, scene.lighting, -scene.camera->forward()};
    ReferenceOptions options;
    options.shading = &shading;
    return referenceIntegral(sphere33(), scene.transferFunction, *scene.camera, scene.image, options);
}

Image4d asExpected(const Image4f& a)
{
    Image4d out(a.width(), a.height());
    for (std::size_t i = 0; i < a.pixelCount(); ++i)
        out.pixels()[i] = glm::dvec4(a.pixels()[i]);
    return out;
}

void expectInputError(const json& options, const std::string& fragment)
{
    try {
        parseBlendOptions(options);
        ADD_FAILURE() << "no InputError for " << options.dump();
    } catch (const InputError& e) {
        EXPECT_NE(std::string(e.what()).find(fragment), std::string::npos) << e.what();
    }
}

TEST(BlendOptions, BadOptionsThrowInputErrorNamingTheKey)
{
    const BlendOptions d = parseBlendOptions(json::object());
    EXPECT_EQ(d.slices, 256);
    EXPECT_EQ(d.reflectanceMapSize, 128);
    expectInputError({{"early_termination", 0.9}}, "options.early_termination: unknown option for blend");
    expectInputError({{"slices", 0}}, "options.slices");
    expectInputError({{"slices", 2.5}}, "options.slices");
    expectInputError({{"slice_spacing", -1}}, "options.slice_spacing");
    expectInputError({{"slices", 8}, {"slice_spacing", 0.1}}, "options.slice_spacing");
    expectInputError({{"opacity_threshold", 1}}, "options.opacity_threshold");
    expectInputError({{"reflectance_map_size", 0}}, "options.reflectance_map_size");
}

// 256 slices over the box's depth range (delta_s ~ 0.013 world units), map n = 256. The error is the
// slab quadrature — first order once shaded, because the shade jumps along a ray (piecewise-constant map,
// the two-sided flip where N.V changes sign) — plus the map bound (0.031) and float. Measured (perspective,
// parallel): max 6.6e-4, 6.5e-4; mean 2.4e-5, 4.7e-5 (worst rgb). Tolerances: max = map bound + 1e-2,
// mean 2e-3 (as planes').
TEST(Blend, ShadedMatchesReferenceBothCameras)
{
    for (const Camera& camera : {perspectiveCamera(), parallelCamera()}) {
        const Scene scene = makeScene(camera, {{"slices", 256}, {"reflectance_map_size", 256}});
        const Image4f image = render(scene);
        const Image4d expected = shadedReference(scene);
        const test::ImageError e = test::imageError(image, expected);
        std::printf("[ measured ] blend %s: max rgb %.2e %.2e %.2e a %.2e; mean rgb %.2e %.2e %.2e a %.2e\n",
                    camera.parallel ? "parallel" : "perspective", e.maxAbs.r, e.maxAbs.g, e.maxAbs.b, e.maxAbs.a,
                    e.meanAbs.r, e.meanAbs.g, e.meanAbs.b, e.meanAbs.a);
        const double mapBound = reflectanceMapBound(scene.lighting, 256);
        EXPECT_TRUE(test::imagesNear(image, expected, {.maxAbs = mapBound + 1e-2, .meanAbs = 2e-3}));
    }
}

TEST(Blend, ErrorFallsWithSliceCount)
{
    const Scene coarse = makeScene(perspectiveCamera(), {{"slices", 32}, {"reflectance_map_size", 1024}});
    Scene fine = coarse;
    fine.options["slices"] = 256;
    const Image4d expected = shadedReference(coarse);
    const double ec = test::imageError(render(coarse), expected).meanAbs.b;
    const double ef = test::imageError(render(fine), expected).meanAbs.b;
    std::printf("[ measured ] blend mean b error, 32 slices: %.2e, 256 slices: %.2e\n", ec, ef);
    EXPECT_LT(ef, ec / 3.0);
}

// Writing a sample of alpha <= t clear changes the pixel by at most alpha times the largest emission
// (shade <= 0.15 + (0.7 + 0.3) + 0.5 (0.7 + 0.3) = 1.65, color <= 1) per sample, N t 1.65 over N slices.
TEST(Blend, OpacityThresholdWithinBound)
{
    const Scene off = makeScene(parallelCamera(), {{"slices", 128}});
    Scene on = off;
    on.options["opacity_threshold"] = 0.01;
    FrameStats statsOff, statsOn;
    const Image4f a = render(off, &statsOff);
    const Image4f b = render(on, &statsOn);
    EXPECT_GT(statsOn.extra["samples_below_threshold"].get<std::uint64_t>(),
              statsOff.extra["samples_below_threshold"].get<std::uint64_t>());
    const double bound = 128 * 0.01 * 1.65;
    EXPECT_TRUE(test::imagesNear(b, asExpected(a), {.maxAbs = bound, .meanAbs = bound}));
    EXPECT_LT(test::imageError(b, asExpected(a)).meanAbs.b, 0.01);
}

// The two methods approximate the same integral: planes (no early termination) and blend agree within
// the sum of their tolerances against the reference (measured well inside).
// Renderer::setCamera: pointed at new cameras, blend gives the images new renderers give, bit for bit (the
// slices and the reflectance map follow the eye); a new image size is refused.
TEST(Blend, SetCameraEqualsANewRenderer)
{
    Camera behind = perspectiveCamera();
    behind.position = 2.0 * behind.focalPoint - behind.position;
    test::expectSetCameraEqualsNewRenderer(makeScene(perspectiveCamera(), {{"slices", 48}}), sphere33(),
                                           {perspectiveCamera(), parallelCamera(), behind}, "blend");
}

TEST(Blend, AgreesWithPlanes)
{
    const Scene blend = makeScene(perspectiveCamera(), {{"slices", 256}});
    Scene planes = blend;
    planes.technique = "planes";
    planes.options = {{"early_termination", 1.0}};
    const Image4f a = render(blend), b = render(planes);
    EXPECT_TRUE(test::imagesNear(a, asExpected(b), {.maxAbs = 0.03, .meanAbs = 2e-3}));
}

}  // namespace
}  // namespace clvr
