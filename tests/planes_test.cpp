// tests/planes_test.cpp — the Planes method (seeds/004 §3.1): options, the shaded image against the CPU
// shaded reference integral (parallel and perspective), unshaded against the plain reference, early ray
// termination and the opacity threshold within their bounds, the reflectance map's size showing within its
// bound, identical bits twice, orientation.
#include "host/render/grid/planes.h"

#include "host/runtime/errors.h"
#include "host/io/generators.h"
#include "host/optics/gradient_volume.h"
#include "host/io/image_io.h"
#include "host/reference/reference_integral.h"
#include "host/optics/reflectance_map.h"
#include "tests/support/test_util.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>

namespace clvr {
namespace {

using nlohmann::json;

// "sphere" (1 - |p|): shells of radius 0.4 .. 0.75 are visible. The gradient has length 1 wherever tau > 0
// (the center, where it vanishes, is transparent), so the normals are well defined.
TransferFunction shellTransferFunction()
{
    return TransferFunction({{0.2, {0.2, 0.4, 1.0}, 0.0}, {0.3, {0.3, 0.6, 1.0}, 3.0},
                             {0.5, {1.0, 0.8, 0.3}, 6.0}, {0.6, {1.0, 0.9, 0.7}, 0.0}});
}

const Volume& sphere33()
{
    static const Volume v = generateVolume("sphere", {33, 33, 33});
    return v;
}


Camera perspectiveCamera()
{
    return test::obliquePerspectiveCamera(40.0);
}

Camera parallelCamera()
{
    return test::obliqueParallelCamera(1.2);
}

Scene makeScene(const Camera& camera, json options, bool shaded = true, int size = 40)
{
    Scene s;
    s.technique = "planes";
    s.camera = camera;
    s.image = ImageSpec{size, size, {0.1, 0.2, 0.3}};
    s.transferFunction = shellTransferFunction();
    s.options = std::move(options);
    if (shaded) {
        s.lighting = test::twoLightLighting();
    }
    return s;
}

Image4d shadedReference(const Scene& scene, const Volume& volume)
{
    static const std::vector<glm::vec4> gradients = sobelGradientVolume(volume);
    ReferenceShading shading{&gradients, scene.lighting, -scene.camera->forward()};
    ReferenceStats stats;
    ReferenceOptions options;
    options.stats = &stats;
    if (shading.lighting.shaded())
        options.shading = &shading;
    Image4d image = referenceIntegral(volume, scene.transferFunction, *scene.camera, scene.image, options);
    EXPECT_EQ(stats.raysNotConverged, 0u);
    return image;
}

void report(const char* what, const Image4f& a, const Image4d& b)
{
    const test::ImageError e = test::imageError(a, b);
    std::printf("[ measured ] %s: max |diff| rgb %.2e %.2e %.2e a %.2e; mean rgb %.2e %.2e %.2e a %.2e\n", what,
                e.maxAbs.r, e.maxAbs.g, e.maxAbs.b, e.maxAbs.a, e.meanAbs.r, e.meanAbs.g, e.meanAbs.b, e.meanAbs.a);
}

// ---- options ---------------------------------------------------------------------------------

void expectInputError(const json& options, const std::string& fragment)
{
    try {
        parsePlanesOptions(options);
        ADD_FAILURE() << "no InputError for " << options.dump();
    } catch (const InputError& e) {
        EXPECT_NE(std::string(e.what()).find(fragment), std::string::npos) << e.what();
    }
}

TEST(PlanesOptions, DefaultsAndValues)
{
    const PlanesOptions d = parsePlanesOptions(json::object());
    EXPECT_EQ(d.sampleSpacing, 0.0);
    EXPECT_EQ(d.earlyTermination, 0.99);
    EXPECT_EQ(d.opacityThreshold, 0.0);
    EXPECT_EQ(d.reflectanceMapSize, 128);
    const PlanesOptions o = parsePlanesOptions(
        {{"sample_spacing", 0.01}, {"early_termination", 1}, {"opacity_threshold", 0.02}, {"reflectance_map_size", 7}});
    EXPECT_EQ(o.sampleSpacing, 0.01);
    EXPECT_EQ(o.earlyTermination, 1.0);
    EXPECT_EQ(o.opacityThreshold, 0.02);
    EXPECT_EQ(o.reflectanceMapSize, 7);
}

TEST(PlanesOptions, BadOptionsThrowInputErrorNamingTheKey)
{
    expectInputError({{"slices", 4}}, "options.slices: unknown option for planes (known: sample_spacing");
    expectInputError({{"sample_spacing", 0}}, "options.sample_spacing");
    expectInputError({{"sample_spacing", "fine"}}, "options.sample_spacing");
    expectInputError({{"early_termination", 0}}, "options.early_termination");
    expectInputError({{"early_termination", 1.5}}, "options.early_termination");
    expectInputError({{"opacity_threshold", -0.1}}, "options.opacity_threshold");
    expectInputError({{"opacity_threshold", 1}}, "options.opacity_threshold");
    expectInputError({{"reflectance_map_size", 0}}, "options.reflectance_map_size");
    expectInputError({{"reflectance_map_size", 1025}}, "options.reflectance_map_size");
    expectInputError({{"reflectance_map_size", 8.5}}, "options.reflectance_map_size");
    EXPECT_THROW(test::renderScene(makeScene(perspectiveCamera(), {{"sample_spacing", 1e-7}}), sphere33()), InputError);
}

// ---- against the reference -------------------------------------------------------------------

// Shaded, no early termination, no threshold, a fine map (n = 256): what remains is the midpoint rule at
// h <= 1/32 (half the grid spacing 1/16) against the converged integral, the map's quantization (at most
// reflectanceMapBound(n = 256) = 0.031 per sample for this lighting, times color <= 1, times A <= 1; its
// mean over samples is far smaller) and float. Measured (perspective, parallel): max 4.1e-3, 1.25e-2;
// mean 1.7e-4, 6.1e-4 (worst rgb channel). Tolerances: max = the map bound + 5e-3 for sampling, mean 2e-3.
TEST(Planes, ShadedMatchesReferenceBothCameras)
{
    for (const Camera& camera : {perspectiveCamera(), parallelCamera()}) {
        const Scene scene = makeScene(camera, {{"early_termination", 1.0}, {"reflectance_map_size", 256}});
        const Image4f image = test::renderScene(scene, sphere33());
        const Image4d expected = shadedReference(scene, sphere33());
        report(camera.parallel ? "shaded parallel" : "shaded perspective", image, expected);
        const double mapBound = reflectanceMapBound(scene.lighting, 256);
        EXPECT_NEAR(mapBound, 0.031, 1e-3);
        EXPECT_TRUE(test::imagesNear(image, expected, {.maxAbs = mapBound + 5e-3, .meanAbs = 2e-3}));
    }
}

// Unshaded (no lights): the integral slice3d approximates; only the midpoint rule and float remain.
// Measured max 2.4e-3, mean 8.6e-5.
TEST(Planes, UnshadedMatchesReference)
{
    const Scene scene = makeScene(perspectiveCamera(), {{"early_termination", 1.0}}, false);
    const Image4f image = test::renderScene(scene, sphere33());
    const Image4d expected = shadedReference(scene, sphere33());
    report("unshaded", image, expected);
    EXPECT_TRUE(test::imagesNear(image, expected, {.maxAbs = 5e-3, .meanAbs = 5e-4}));
}

// The error falls as the samples get denser (midpoint rule, second order), down to the map's floor.
TEST(Planes, ErrorFallsWithSampleSpacing)
{
    const Scene coarse = makeScene(perspectiveCamera(), {{"early_termination", 1.0}, {"sample_spacing", 0.25},
                                                         {"reflectance_map_size", 1024}});
    Scene fine = coarse;
    fine.options["sample_spacing"] = 0.0625;
    const Image4d expected = shadedReference(coarse, sphere33());
    const test::ImageError ec = test::imageError(test::renderScene(coarse, sphere33()), expected);
    const test::ImageError ef = test::imageError(test::renderScene(fine, sphere33()), expected);
    std::printf("[ measured ] mean rgb error at spacing 0.25: %.2e, at 0.0625: %.2e\n", ec.meanAbs.r, ef.meanAbs.r);
    EXPECT_LT(ef.meanAbs.r, ec.meanAbs.r / 3.0);
}

// ---- optimizations within their bounds -------------------------------------------------------

// Largest emitted color times shade of the scene: tf color <= 1, shade <= ka + sum_l max(color_l) (kd + ks).
double maxEmission(const Scene& scene)
{
    const Lighting l = scene.lighting;
    double shade = l.material.ambient;
    for (const DirectionalLight& light : l.lights)
        shade += std::max({light.color.r, light.color.g, light.color.b}) * (l.material.diffuse + l.material.specular);
    return shade;
}

// Stopping once A >= e leaves out the rest of the ray, whose contribution is at most T <= 1 - e times the
// largest emission (color), and at most 1 - e in alpha.
TEST(Planes, EarlyTerminationWithinBound)
{
    const Scene off = makeScene(perspectiveCamera(), {{"early_termination", 1.0}});
    Scene on = off;
    on.options["early_termination"] = 0.9;
    FrameStats statsOff, statsOn;
    const Image4f a = test::renderScene(off, sphere33(), &statsOff);
    const Image4f b = test::renderScene(on, sphere33(), &statsOn);
    EXPECT_GT(statsOn.extra["rays_terminated"].get<std::uint64_t>(), 0u);
    EXPECT_EQ(statsOff.extra["rays_terminated"].get<std::uint64_t>(), 0u);
    EXPECT_LT(statsOn.samples, statsOff.samples);
    Image4d expected(a.width(), a.height());
    for (std::size_t i = 0; i < a.pixelCount(); ++i)
        expected.pixels()[i] = glm::dvec4(a.pixels()[i]);
    const double bound = 0.1 * std::max(1.0, maxEmission(off)) + 1e-5;
    report("early termination 0.9 vs off", b, expected);
    EXPECT_TRUE(test::imagesNear(b, expected, {.maxAbs = bound, .meanAbs = bound}));
}

// Skipping a sample of opacity alpha <= t changes the pixel by at most alpha times the largest emission
// (one layer less in the stack); over a ray of at most N samples: N t maxEmission.
TEST(Planes, OpacityThresholdWithinBound)
{
    const Scene off = makeScene(parallelCamera(), {{"early_termination", 1.0}});
    Scene on = off;
    const double t = 0.02;
    on.options["opacity_threshold"] = t;
    FrameStats statsOff, statsOn;
    const Image4f a = test::renderScene(off, sphere33(), &statsOff);
    const Image4f b = test::renderScene(on, sphere33(), &statsOn);
    const auto below = statsOn.extra["samples_below_threshold"].get<std::uint64_t>();
    EXPECT_GT(below, statsOff.extra["samples_below_threshold"].get<std::uint64_t>());
    Image4d expected(a.width(), a.height());
    for (std::size_t i = 0; i < a.pixelCount(); ++i)
        expected.pixels()[i] = glm::dvec4(a.pixels()[i]);
    const double n = std::ceil(2.0 * std::sqrt(3.0) / (0.5 * 2.0 / 32.0));  // box diagonal / default spacing
    const double bound = n * t * std::max(1.0, maxEmission(off));
    report("opacity threshold 0.02 vs 0", b, expected);
    EXPECT_TRUE(test::imagesNear(b, expected, {.maxAbs = bound, .meanAbs = bound}));
    // A looser check that means something: the threshold only removes faint samples, the image stays close.
    EXPECT_LT(test::imageError(b, expected).meanAbs.r, 0.02);
}

// A coarse map (n = 4) against a fine one (n = 1024): per sample the shades differ by at most
// reflectanceMapBound(4) + reflectanceMapBound(1024); the pixel by that times the largest color (1) times A.
TEST(Planes, ReflectanceMapSizeWithinItsBound)
{
    const Scene fine = makeScene(perspectiveCamera(), {{"early_termination", 1.0}, {"reflectance_map_size", 1024}});
    Scene coarse = fine;
    coarse.options["reflectance_map_size"] = 4;
    const Image4f a = test::renderScene(fine, sphere33());
    const Image4f b = test::renderScene(coarse, sphere33());
    Image4d expected(a.width(), a.height());
    for (std::size_t i = 0; i < a.pixelCount(); ++i)
        expected.pixels()[i] = glm::dvec4(a.pixels()[i]);
    const Lighting l = fine.lighting;
    const double bound = reflectanceMapBound(l, 4) + reflectanceMapBound(l, 1024) + 1e-5;
    report("map n=4 vs n=1024", b, expected);
    EXPECT_TRUE(test::imagesNear(b, expected, {.maxAbs = bound, .meanAbs = bound}));
    EXPECT_GT(test::imageError(b, expected).maxAbs.r, 1e-3);  // the coarse map does show
}

// ---- determinism and orientation -------------------------------------------------------------

TEST(Planes, IdenticalBitsTwice)
{
    const Scene scene = makeScene(perspectiveCamera(), json::object());
    auto renderer = makeRenderer(test::device(), scene, sphere33());
    FrameStats stats;
    const Image4f a = renderer->render(stats);
    const Image4f b = renderer->render(stats);
    EXPECT_EQ(std::memcmp(a.pixels().data(), b.pixels().data(), a.pixelCount() * sizeof(glm::vec4)), 0);
}

// Renderer::setCamera: pointed at new cameras, planes gives the images new renderers give, bit for bit, shaded
// (the reflectance map faces the new eye) and unshaded; a new image size is refused.
TEST(Planes, SetCameraEqualsANewRenderer)
{
    Camera behind = perspectiveCamera();
    behind.position = 2.0 * behind.focalPoint - behind.position;  // the other side
    for (bool shaded : {true, false})
        test::expectSetCameraEqualsNewRenderer(makeScene(perspectiveCamera(), json::object(), shaded, 31), sphere33(),
                                               {perspectiveCamera(), parallelCamera(), behind},
                                               shaded ? "shaded" : "unshaded");
}

// A blob at world (-0.5, +0.5, 0) seen from +z with y up lands in the image's upper left (row 0 at the
// top), both cameras; lit from the upper left, its upper-left half is the brighter.
TEST(Planes, AsymmetricBlobLandsUpperLeftLitFromUpperLeft)
{
    Volume v;
    v.dims = {24, 24, 24};
    v.origin = glm::dvec3(-1.0);
    v.spacing = glm::dvec3(2.0 / 23.0);
    v.source = "blob";
    for (int k = 0; k < 24; ++k)
        for (int j = 0; j < 24; ++j)
            for (int i = 0; i < 24; ++i) {
                const glm::dvec3 p = v.origin + glm::dvec3(i, j, k) * v.spacing - glm::dvec3(-0.5, 0.5, 0.0);
                v.values.push_back(static_cast<float>(std::exp(-glm::dot(p, p) / 0.05)));
            }
    Camera perspective;  // +z, looking at the origin, y up
    Camera parallel = perspective;
    parallel.parallel = true;
    parallel.parallelScale = 1.2;
    for (const Camera& camera : {perspective, parallel}) {
        Scene scene = makeScene(camera, json::object(), true, 48);
        scene.image.background = glm::dvec3(0.0);
        scene.transferFunction = TransferFunction({{0.3, {1, 1, 1}, 0.0}, {0.4, {1, 1, 1}, 60.0}});
        scene.lighting.lights = {{glm::normalize(glm::dvec3(-1.0, 1.0, 1.0)), glm::dvec3(1.0)}};
        const Image4f image = test::renderScene(scene, v);
        std::filesystem::create_directories("test_output");
        writeImage(std::string("test_output/planes_blob_") + (camera.parallel ? "parallel" : "perspective") + ".png", image);
        double alpha[2][2] = {}, light = 0.0, dark = 0.0, sum = 0.0;
        glm::dvec2 center(0.0);  // the blob's alpha centroid, pixels
        for (int y = 0; y < 48; ++y)
            for (int x = 0; x < 48; ++x) {
                alpha[y / 24][x / 24] += image.at(x, y).a;
                center += static_cast<double>(image.at(x, y).a) * glm::dvec2(x, y);
                sum += image.at(x, y).a;
            }
        center /= sum;
        for (int y = 0; y < 48; ++y)  // its upper-left half against its lower-right half
            for (int x = 0; x < 48; ++x)
                if (image.at(x, y).a > 0.5)
                    (x - center.x + y - center.y < 0.0 ? light : dark) += image.at(x, y).r;
        EXPECT_GT(alpha[0][0], 1.0);
        EXPECT_GT(alpha[0][0], 20.0 * (alpha[0][1] + alpha[1][0] + alpha[1][1]));
        EXPECT_GT(light, 1.5 * dark);
    }
}

}  // namespace
}  // namespace clvr
