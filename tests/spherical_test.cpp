// tests/spherical_test.cpp — pixel textures on spherical domains: options, shell planning, the sphere's
// faces and seam, one shell's pixel pass against a direct per-pixel evaluation, the image against the
// CPU reference integral with the error falling as shells and segments grow, the color-matrix bias
// rotating φ, and the technique chosen from a scene file.
#include "host/render/grid/spherical.h"

#include "host/runtime/errors.h"
#include "host/io/generators.h"
#include "host/render/renderer.h"
#include "host/reference/spherical_reference.h"
#include "host/io/volume_io.h"
#include "raster/reference/texture.h"
#include "tests/support/test_util.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>

namespace clvr {
namespace {

using nlohmann::json;

TransferFunction atmosphereTransferFunction()
{
    // s in [0,1] (the atmosphere field); tau per world unit, the domain is 1 deep (r 0.5 .. 1).
    return TransferFunction({{0.0, {0.1, 0.2, 0.6}, 0.0}, {0.4, {0.3, 0.6, 1.0}, 1.5}, {1.0, {1.0, 1.0, 0.9}, 6.0}});
}
constexpr double kTauMax = 6.0;

Camera obliqueCamera()  // outside the domain, 35 degrees above the equator
{
    Camera c;
    c.position = {2.6, 1.4, 2.1};
    c.viewUp = {0.0, 0.0, 1.0};
    c.viewAngle = 40.0;
    return c;
}

Camera insideCamera()  // inside the outer shells, outside the inner ones
{
    Camera c;
    c.position = {0.8, 0.0, 0.1};
    c.focalPoint = {0.0, 0.3, 0.0};
    c.viewUp = {0.0, 0.0, 1.0};
    c.viewAngle = 70.0;
    return c;
}

Camera parallelBallCamera()  // parallel, towards the full ball of ballOptions()
{
    Camera c;
    c.position = {0.4 - 3.0, 0.3 - 1.0, -0.2 + 1.5};
    c.focalPoint = {0.4, 0.3, -0.2};
    c.viewUp = {0.0, 0.0, 1.0};
    c.parallel = true;
    c.parallelScale = 1.1;
    return c;
}

// A full ball (r_min = 0) of radius 0.9 off the origin.
nlohmann::json ballOptions()
{
    return {{"r_min", 0.0}, {"r_max", 0.9}, {"center", {0.4, 0.3, -0.2}}};
}

const Volume& atmosphere()  // (φ, θ, r) grid; φ = 0 and φ = 2π columns agree
{
    static const Volume v = generateVolume("atmosphere", {33, 17, 12});
    return v;
}

Scene makeScene(const Camera& camera, int size, json options = json::object())
{
    Scene s;
    s.technique = "spherical";
    s.camera = camera;
    s.image = ImageSpec{size, size, {0.05, 0.05, 0.1}};
    s.transferFunction = atmosphereTransferFunction();
    s.options = std::move(options);
    return s;
}

std::string optionError(const json& options)
{
    try {
        parseSphericalOptions(options);
    } catch (const InputError& e) {
        return e.what();
    }
    return "";
}

TEST(SphericalOptions, BadOptionsAreOneClearLine)
{
    const std::vector<std::pair<json, std::string>> cases = {
        {{{"shells", -3}}, "options.shells: must be an integer in [2, 4096], got -3"},
        {{{"shells", 1}}, "options.shells: must be an integer in [2, 4096], got 1"},
        {{{"shells", 2.5}}, "options.shells: must be an integer in [2, 4096], got 2.5"},
        {{{"segments", 3}}, "options.segments: must be an integer in [4, 1024], got 3"},
        {{{"r_min", 1.0}, {"r_max", 1.0}}, "options.r_max: must be greater than r_min (1.000000), got 1.000000"},
        {{{"r_min", 2.0}}, "options.r_max: must be greater than r_min (2.000000), got 1.000000"},
        {{{"r_min", -0.5}}, "options.r_min: must be >= 0, got -0.5"},
        {{{"r_max", "big"}}, "options.r_max: must be a finite number, got \"big\""},
        {{{"center", {0, 0}}}, "options.center: must be a list of 3 numbers, got [0,0]"},
        {{{"bias", {0, 0}}}, "options.bias: must be a list of 4 (or 3) numbers, got [0,0]"},
        {{{"color_matrix", {1, 0, 0}}}, "options.color_matrix: must be 4 rows of 4 numbers, got [1,0,0]"},
        {{{"opacity", "exact"}}, "options.opacity: must be \"path\" or \"radial\", got \"exact\""},
        {{{"slices", 8}}, "options.slices: unknown option for spherical (known: shells, segments, r_min, r_max, "
                          "center, color_matrix, scale, bias, opacity, path, early_termination, packets)"},
    };
    for (const auto& [options, message] : cases) {
        const std::string got = optionError(options);
        EXPECT_EQ(got, message) << options.dump();
        EXPECT_EQ(got.find('\n'), std::string::npos);
    }
    EXPECT_EQ(optionError({{"shells", 8}, {"segments", 12}, {"r_min", 0.0}, {"bias", {0.25, 0, 0}}}), "");
    EXPECT_EQ(optionError({{"packets", "yes"}}).rfind("options.packets:", 0), 0u) << optionError({{"packets", "yes"}});
    EXPECT_EQ(optionError({{"packets", nullptr}}), "");
}

TEST(SphericalOptions, SceneWithBadOptionFailsInMakeRenderer)
{
    const Scene scene = makeScene(obliqueCamera(), 8, {{"shells", 0}});
    EXPECT_THROW(makeRenderer(test::device(), scene, atmosphere()), InputError);
    Scene lit = makeScene(obliqueCamera(), 8);
    lit.lighting.lights = {DirectionalLight{}};  // from +z, white
    try {
        makeRenderer(test::device(), lit, atmosphere());
        ADD_FAILURE() << "no error for a scene with lights";
    } catch (const InputError& e) {
        EXPECT_STREQ(e.what(), "lights: technique spherical renders unshaded (no \"lights\")");
    }
}

TEST(Spherical, ShellSlabsTileTheDomain)
{
    SphericalOptions o;
    o.domain.rMin = 0.3;
    o.domain.rMax = 1.1;
    o.shells = 9;
    const std::vector<Shell> shells = planShells(o);
    ASSERT_EQ(shells.size(), 9u);
    EXPECT_EQ(shells.front().radius, 0.3);
    EXPECT_EQ(shells.back().radius, 1.1);
    EXPECT_EQ(shells.front().rLo, 0.3);
    EXPECT_EQ(shells.back().rHi, 1.1);
    for (std::size_t k = 1; k < shells.size(); ++k) {
        EXPECT_NEAR(shells[k].rLo, shells[k - 1].rHi, 1e-15);  // no gap, no overlap
        EXPECT_NEAR(shells[k].radius - shells[k - 1].radius, 0.1, 1e-15);
    }
}

TEST(Spherical, CoordinatesOfKnownPoints)
{
    const SphericalDomain d{{1.0, 2.0, 3.0}, 0.5, 1.5};
    const auto near = [](glm::dvec3 a, glm::dvec3 b) { return glm::length(a - b) < 1e-12; };
    EXPECT_TRUE(near(sphericalCoordinates(d, {2.0, 2.0, 3.0}), {0.0, 0.5, 0.5}));    // +x: φ 0, equator, r 1
    EXPECT_TRUE(near(sphericalCoordinates(d, {1.0, 3.5, 3.0}), {0.25, 0.5, 1.0}));   // +y: φ π/2, r 1.5
    EXPECT_TRUE(near(sphericalCoordinates(d, {0.0, 2.0, 3.0}), {0.5, 0.5, 0.5}));    // -x: φ π
    EXPECT_TRUE(near(sphericalCoordinates(d, {1.0, 1.5, 3.0}), {0.75, 0.5, 0.0}));   // -y: φ 3π/2, r 0.5
    EXPECT_TRUE(near(sphericalCoordinates(d, {1.0, 2.0, 4.0}), {0.0, 0.0, 0.5}));    // north pole
    EXPECT_TRUE(near(sphericalCoordinates(d, {1.0, 2.0, 2.0}), {0.0, 1.0, 0.5}));    // south pole
}

// Every triangle of the tessellation faces outwards (counter-clockwise seen from outside), and no
// triangle spans more than one segment in u: the seam has its own vertices at u = 1.
TEST(Spherical, SphereTrianglesFaceOutwardsAndKeepTheSeam)
{
    const int segments = 12;
    const glm::dvec3 center(0.5, -0.25, 1.0);
    const std::vector<raster::Vertex> v = sphereTriangles(center, 2.0, 0.3, segments, glm::dmat4(1.0));
    ASSERT_EQ(v.size(), static_cast<std::size_t>(3 * (2 * segments * (segments / 2 - 2) + 2 * segments)));
    for (std::size_t t = 0; t < v.size(); t += 3) {
        const glm::dvec3 a(v[t].position), b(v[t + 1].position), c(v[t + 2].position);
        const glm::dvec3 normal = glm::cross(b - a, c - a);
        EXPECT_GT(glm::dot(normal, (a + b + c) / 3.0 - center), 0.0) << "triangle " << t / 3;
        double uMin = 1.0, uMax = 0.0;
        for (int k = 0; k < 3; ++k) {
            uMin = std::min(uMin, double(v[t + k].attributes[0].x));
            uMax = std::max(uMax, double(v[t + k].attributes[0].x));
            EXPECT_FLOAT_EQ(v[t + k].attributes[0].z, 0.3f);
            EXPECT_FLOAT_EQ(v[t + k].attributes[0].w, 1.0f);
        }
        EXPECT_LE(uMax - uMin, 1.0 / segments + 1e-7) << "triangle " << t / 3;
    }
}

// One pass, as specified: the shell's far hemisphere then its near hemisphere, each blended over
// what is there, against the same steps done per pixel on the host from the coordinate buffer the
// raster stage produced (tests/raster_test.cpp and pixel_transfer_test.cpp hold those to their own
// references): φ wrap, the texture sampled by raster::reference::sampleTexture (double), the transfer
// function, the ray's length in the slab (double), alpha, "over".
TEST(Spherical, ShellPassMatchesDirectEvaluation)
{
    const int size = 64;
    // A φ bias makes the wrap matter; perspective camera outside.
    Scene scene = makeScene(obliqueCamera(), size, {{"shells", 6}, {"segments", 24}, {"bias", {0.3, 0.0, 0.0}}});
    SphericalRenderer renderer(test::device(), scene, atmosphere());
    Device& device = test::device();
    const glm::ivec3 n = atmosphere().dims;
    raster::TextureDesc desc = renderer.texture().desc();
    const TransferFunction tf = atmosphereTransferFunction();
    const PixelRays rays(renderer.camera(), size, size);
    const SphericalDomain domain;

    renderer.image().clearColor(device, glm::vec4(0.0f));
    Image4d expected(size, size, glm::dvec4(0.0));
    std::size_t covered = 0;
    const std::size_t shell = 3;
    for (const bool back : {true, false}) {
        renderer.renderPass(shell, back);
        const Image4f coords = renderer.coordinates().readColor(device);
        const std::vector<std::uint8_t> stencil = renderer.coordinates().readStencil(device);
        const Shell& s = renderer.shells()[shell];
        for (int y = 0; y < size; ++y)
            for (int x = 0; x < size; ++x) {
                if (!stencil[static_cast<std::size_t>(y) * size + x])
                    continue;
                ++covered;
                glm::dvec3 st(coords.at(x, y));
                const double s0 = 0.5 / n.x, period = (n.x - 1.0) / n.x;
                const double u = (st.x - s0) / period;
                st.x = s0 + (u - std::floor(u)) * period;
                const double value = raster::reference::sampleTexture(desc, atmosphere().values, st, 3).x;
                const glm::dvec4 c = tf(value);
                const Ray ray = rays.at(x, y);
                const glm::dvec3 oc = domain.center - ray.origin;
                const double tc = glm::dot(oc, ray.direction);
                const glm::dvec3 off = oc - tc * ray.direction;
                const double p2 = glm::dot(off, off);
                const double hHi = std::sqrt(std::max(s.rHi * s.rHi - p2, 0.0));
                const double inner = renderer.shells()[shell - 1].radius;  // a ray missing it: whole path
                const double hLo = p2 >= inner * inner ? 0.0 : std::sqrt(std::max(s.rLo * s.rLo - p2, 0.0));
                const double t0 = back ? tc + hLo : tc - hHi, t1 = back ? tc + hHi : tc - hLo;
                const double len = std::max(t1 - std::max(t0, 0.0), 0.0);
                const double alpha = 1.0 - std::exp(-c.w * len);
                expected.at(x, y) = glm::dvec4(glm::dvec3(c) * alpha, alpha) + (1.0 - alpha) * expected.at(x, y);
            }
    }
    EXPECT_GT(covered, static_cast<std::size_t>(size * size / 4));  // both hemispheres cover a disc
    // Float32 throughout. The texture value: coordinates from float32 interpolation, differences of
    // ~1e-7 times the texel count (33) times the data slope (~6 per unit) ~ 2e-5. The slab length
    // is ill-conditioned near the shell's silhouette: p^2 in float has an error ~1e-7 r^2, and
    // h = sqrt(r^2 - p^2) then errs by ~1e-7 / (2 h); at h ~ 0.01 that is 5e-6 of length, times
    // tau <= 6: 3e-5 of alpha (only in the few pixels that close to the silhouette). Measured max
    // 1e-6, mean 6e-8; tolerance max 5e-5 (the bounds above), mean 2e-6.
    const Image4f actual = renderer.image().readColor(device);
    const test::ImageError e = test::imageError(actual, expected);
    std::printf("shell pass: max %.2e mean %.2e (alpha channel)\n", e.maxAbs.a, e.meanAbs.a);
    EXPECT_TRUE(test::imagesNear(actual, expected, {.maxAbs = 5e-5, .meanAbs = 2e-6}));
}

// Seen from +x, the center pixel's near hemisphere is the meridian φ = 0 (u 0 or 1) and its far one
// φ = π (u 0.5): culling keeps the hemisphere each pass asks for.
TEST(Spherical, NearAndFarPassesDrawTheRightHemisphere)
{
    Camera camera;
    camera.position = {3.0, 0.0, 0.0};
    camera.viewUp = {0.0, 0.0, 1.0};
    const int size = 33;  // odd: a pixel center on the axis
    Scene scene = makeScene(camera, size, {{"shells", 2}, {"segments", 16}});
    SphericalRenderer renderer(test::device(), scene, atmosphere());
    const glm::ivec3 n = atmosphere().dims;
    auto uAtCenter = [&](bool back) {
        renderer.renderPass(1, back);
        const Image4f coords = renderer.coordinates().readColor(test::device());
        return (coords.at(size / 2, size / 2).x - 0.5 / n.x) / ((n.x - 1.0) / n.x);  // undo the texel map
    };
    const double uFar = uAtCenter(true), uNear = uAtCenter(false);
    EXPECT_NEAR(uFar, 0.5, 1e-5);
    EXPECT_TRUE(std::abs(uNear) < 1e-5 || std::abs(uNear - 1.0) < 1e-5) << uNear;
}

struct Measured {
    test::ImageError error;
    double maxAbs = 0.0, meanAbs = 0.0;  // over r, g, b, a
};
Measured measure(const Image4f& actual, const Image4d& expected)
{
    Measured m;
    m.error = test::imageError(actual, expected);
    for (int c = 0; c < 4; ++c) {
        m.maxAbs = std::max(m.maxAbs, m.error.maxAbs[c]);
        m.meanAbs = std::max(m.meanAbs, m.error.meanAbs[c]);
    }
    return m;
}

const Image4d& obliqueReference(int size)
{
    static const Image4d image = [&] {
        double residual = 0.0;
        SphericalReferenceOptions o;
        o.tolerance = 1e-6;
        o.maxResidual = &residual;
        const Image4d r = sphericalReferenceIntegral(atmosphere(), atmosphereTransferFunction(), obliqueCamera(),
                                                     makeScene(obliqueCamera(), size).image, SphericalDomain{},
                                                     raster::PixelTransfer{}, o);
        EXPECT_LT(residual, 1e-6);  // converged: the midpoint rule's remaining error is below that
        return r;
    }();
    return image;
}

// The full render against the reference integral, and the error falling as shells and segments grow,
// on both paths (the fused path meets the exact spheres: segments do not matter there).
TEST(SphericalRender, ConvergesToTheReferenceIntegral)
{
    const int size = 64;
    const Image4d& reference = obliqueReference(size);
    for (const char* path : {"fused", "raster"}) {
        std::vector<Measured> errors;
        Image4f image;
        for (const int k : {8, 16, 32, 64}) {
            image = test::renderScene(
                makeScene(obliqueCamera(), size, {{"shells", k + 1}, {"segments", 2 * k}, {"path", path}}), atmosphere());
            errors.push_back(measure(image, reference));
            std::printf("%s, shells %3d segments %3d: max %.4f mean %.5f\n", path, k + 1, 2 * k, errors.back().maxAbs,
                        errors.back().meanAbs);
        }
        // Measured (PoCL 3.1): mean 0.0292, 0.0103, 0.0036, 0.0013 (about second order in the shell
        // spacing), max 0.69, 0.46, 0.25, 0.15 (about the square root: see below).
        for (std::size_t i = 1; i < errors.size(); ++i) {
            EXPECT_LT(errors[i].meanAbs, 0.5 * errors[i - 1].meanAbs) << i;
            EXPECT_LT(errors[i].maxAbs, 0.8 * errors[i - 1].maxAbs) << i;
            EXPECT_EQ(errors[i].error.nanCount, 0u);
        }
        // 65 shells, 128 segments. The mean: each shell's sample stands for its slab (a midpoint rule in
        // r, second order, dr = 1/64), plus the tessellation (chords r (1 - cos(pi/128)) = 3e-4 of the
        // radius, linear (u, v) across a triangle): measured 0.0013, tolerance 0.002. The max sits where
        // rays graze a shell inside the dense layer (tau up to 6): the chord of such a ray through the
        // slab is ~2 sqrt(2 r dr) = 0.3 long and is classified by the one sample where the ray meets the
        // sphere, an error that shrinks only as sqrt(dr); measured 0.149, tolerance 0.2.
        EXPECT_TRUE(test::imagesNear(image, reference, {.maxAbs = 0.2, .meanAbs = 0.002})) << path;
        // The fused path has no tessellation error: measured max 0.061, mean 0.0010 at 65 shells.
        if (std::string(path) == "fused") {
            EXPECT_TRUE(test::imagesNear(image, reference, {.maxAbs = 0.1, .meanAbs = 0.0015}));
        }
    }
}

// The radial opacity (the paper's plain blending) ignores the oblique path: clearly too transparent
// against the reference, while the path opacity is close (the reason it is the default).
TEST(SphericalRender, RadialOpacityUnderestimatesObliquePaths)
{
    const int size = 64;
    const Image4d& reference = obliqueReference(size);
    for (const char* drawing : {"fused", "raster"}) {
        const json base = {{"shells", 33}, {"segments", 64}, {"path", drawing}};
        json radial = base;
        radial["opacity"] = "radial";
        const Measured path = measure(test::renderScene(makeScene(obliqueCamera(), size, base), atmosphere()), reference);
        const Measured flat = measure(test::renderScene(makeScene(obliqueCamera(), size, radial), atmosphere()), reference);
        std::printf("%s: path: max %.4f mean %.5f; radial: max %.4f mean %.5f\n", drawing, path.maxAbs, path.meanAbs,
                    flat.maxAbs, flat.meanAbs);
        EXPECT_GT(flat.meanAbs, 3.0 * path.meanAbs) << drawing;
    }
}

// The color matrix's bias on u rotates the data in φ (seeds/000 §2.2: transformations "without
// manipulating and re-loading the texture"): bias u + 0.25 on the data equals the data rotated by a
// quarter turn (a whole number of grid columns, 32 / 4 = 8) with no bias.
TEST(SphericalRender, BiasOnPhiEqualsRotatedData)
{
    const int size = 48;
    const Volume& data = atmosphere();
    Volume rotated = data;
    const glm::ivec3 n = data.dims;
    const int period = n.x - 1, shift = period / 4;
    for (int k = 0; k < n.z; ++k)
        for (int j = 0; j < n.y; ++j)
            for (int i = 0; i < n.x; ++i)
                rotated.values[(static_cast<std::size_t>(k) * n.y + j) * n.x + i] = data.at((i + shift) % period, j, k);
    for (const char* path : {"fused", "raster"}) {
        const json base = {{"shells", 12}, {"segments", 32}, {"path", path}};
        json biased = base;
        biased["bias"] = {0.25, 0.0, 0.0};
        const Image4f viaBias = test::renderScene(makeScene(obliqueCamera(), size, biased), data);
        const Image4f viaData = test::renderScene(makeScene(obliqueCamera(), size, base), rotated);
        const Image4f plain = test::renderScene(makeScene(obliqueCamera(), size, base), data);
        Image4d want(size, size);
        for (std::size_t i = 0; i < want.pixelCount(); ++i)
            want.pixels()[i] = glm::dvec4(viaData.pixels()[i]);
        // The same samples up to float rounding of the texture coordinate (u + 0.25 then the wrap, ~1e-7)
        // times 32 texels times the data slope (< 10 per unit u): ~3e-5 in value, a little more in color.
        // Measured max 5e-7, mean 2e-8.
        const test::ImageError e = test::imageError(viaBias, want);
        std::printf("%s: bias vs rotated data: max %.2e mean %.2e (alpha channel)\n", path, e.maxAbs.a, e.meanAbs.a);
        EXPECT_TRUE(test::imagesNear(viaBias, want, {.maxAbs = 5e-5, .meanAbs = 2e-6})) << path;
        // ... and the rotation shows: the unrotated image differs by far more than that.
        EXPECT_GT(measure(plain, want).maxAbs, 0.05) << path;
    }
}

// A camera inside the domain (inside the outer shells, outside the inner ones): the back-to-front
// order still holds; the image matches the reference as from outside.
TEST(SphericalRender, CameraInsideTheDomain)
{
    const Camera camera = insideCamera();
    const int size = 48;
    Scene scene = makeScene(camera, size, {{"shells", 65}, {"segments", 128}});
    SphericalReferenceOptions o;
    const Image4d reference = sphericalReferenceIntegral(atmosphere(), atmosphereTransferFunction(), camera, scene.image,
                                                         SphericalDomain{}, raster::PixelTransfer{}, o);
    for (const char* path : {"fused", "raster"}) {
        scene.options["path"] = path;
        const Image4f image = test::renderScene(scene, atmosphere());
        const Measured m = measure(image, reference);
        std::printf("%s, inside: max %.4f mean %.5f\n", path, m.maxAbs, m.meanAbs);
        // Measured (raster) max 0.050, mean 0.00044; tolerances as the outside view's (max 0.2, mean 0.002).
        EXPECT_TRUE(test::imagesNear(image, reference, {.maxAbs = 0.2, .meanAbs = 0.002})) << path;
    }
}

// A parallel camera (rays from the image plane, the slab length from the parallel ray) over a full
// ball (r_min = 0: the innermost sphere has radius 0 and is skipped; the next one takes the whole path
// of the rays through it) off the origin.
TEST(SphericalRender, ParallelCameraFullBall)
{
    const Camera camera = parallelBallCamera();
    const int size = 48;
    json options = {{"shells", 65}, {"segments", 128}};
    options.update(ballOptions());
    Scene scene = makeScene(camera, size, options);
    const SphericalOptions parsed = parseSphericalOptions(options);
    const Image4d reference = sphericalReferenceIntegral(atmosphere(), atmosphereTransferFunction(), camera, scene.image,
                                                         parsed.domain, raster::PixelTransfer{});
    for (const char* path : {"fused", "raster"}) {
        scene.options["path"] = path;
        const Image4f image = test::renderScene(scene, atmosphere());
        const Measured m = measure(image, reference);
        std::printf("%s, parallel    , full ball: max %.4f mean %.5f\n", path, m.maxAbs, m.meanAbs);
        // Measured max 0.108, mean 0.0034 (129 shells, 256 segments: 0.076, 0.0016): the shell spacing is
        // 0.9/64 here against 0.5/64 in the perspective test, and the layer 1.8 times deeper in world
        // units, so a larger mean. Tolerance max 0.2, mean 0.005.
        EXPECT_TRUE(test::imagesNear(image, reference, {.maxAbs = 0.2, .meanAbs = 0.005})) << path;
    }
}

TEST(SphericalRender, TwoRendersGiveIdenticalBits)
{
    for (const char* path : {"fused", "raster"}) {
        const Scene scene = makeScene(obliqueCamera(), 32, {{"shells", 8}, {"segments", 16}, {"path", path}});
        auto renderer = makeRenderer(test::device(), scene, atmosphere());
        FrameStats stats;
        const Image4f a = renderer->render(stats), b = renderer->render(stats);
        ASSERT_EQ(a.pixelCount(), b.pixelCount());
        EXPECT_EQ(std::memcmp(a.pixels().data(), b.pixels().data(), a.pixelCount() * sizeof(glm::vec4)), 0) << path;
        EXPECT_EQ(stats.extra["shells"].get<int>(), 8);
        EXPECT_EQ(stats.extra["path"], path);
    }
}

// An edited transfer function gives the image a new renderer gives (Renderer::setTransferFunction).
TEST(SphericalRender, SetTransferFunctionEqualsNewRenderer)
{
    for (const char* path : {"fused", "raster"}) {
        Scene scene = makeScene(obliqueCamera(), 32, {{"shells", 8}, {"segments", 16}, {"path", path}});
        auto renderer = makeRenderer(test::device(), scene, atmosphere());
        FrameStats stats;
        const Image4f before = renderer->render(stats);
        const TransferFunction edited({{0.0, {1, 0, 0}, 0.5}, {1.0, {0, 1, 0}, 3.0}});
        renderer->setTransferFunction(edited);
        const Image4f after = renderer->render(stats);
        scene.transferFunction = edited;
        const Image4f fresh = test::renderScene(scene, atmosphere());
        EXPECT_EQ(std::memcmp(after.pixels().data(), fresh.pixels().data(), after.pixelCount() * sizeof(glm::vec4)), 0);
        EXPECT_NE(std::memcmp(after.pixels().data(), before.pixels().data(), after.pixelCount() * sizeof(glm::vec4)), 0);
    }
}

TEST(SphericalRender, SceneFileSelectsTheTechnique)
{
    const std::string text = R"({
      "technique": "spherical",
      "volume": {"generator": "atmosphere", "dims": [17, 9, 6]},
      "camera": {"position": [2.6, 1.4, 2.1], "focal_point": [0, 0, 0], "view_up": [0, 0, 1], "view_angle": 40},
      "image": {"width": 16, "height": 16},
      "transfer_function": {"points": [[0, 0,0,0, 0], [1, 1,1,1, 4]]},
      "options": {"shells": 4, "segments": 8, "r_min": 0.4, "r_max": 0.9}
    })";
    const Scene scene = parseScene(text, "inline.json", ".");
    EXPECT_EQ(scene.technique, "spherical");
    const Volume volume = generateVolume("atmosphere", {17, 9, 6});
    const Image4f image = test::renderScene(scene, volume);
    double alpha = 0.0;
    for (const glm::vec4& p : image.pixels())
        alpha = std::max(alpha, double(p.a));
    EXPECT_GT(alpha, 0.05);
}

// data/scenes/atmosphere.json (the picture in docs/spherical.md) loads and renders, small, against the
// reference. Its transfer function reaches tau 14, so rays grazing the shells inside the dense layer
// (closest distance 0.77-0.85 from the center, lower left) carry the largest shell-sampling error
// (docs/spherical.md, "Approximations"): measured at 48 shells max 0.32 in 4 of 1024 pixels, mean 0.0032;
// tolerance max 0.4, mean 0.005.
TEST(SphericalRender, AtmosphereSceneFileRenders)
{
    const Scene scene = loadScene(test::repoData("scenes/atmosphere.json"),
                                  {"image={\"width\":32,\"height\":32,\"background\":[0,0,0.02]}",
                                   "volume.dims=[33,17,12]", "options.shells=48", "options.segments=96"});
    ASSERT_EQ(scene.technique, "spherical");
    const Volume volume = loadVolume(*scene.volume);
    const SphericalOptions options = parseSphericalOptions(scene.options);
    const Image4d reference = sphericalReferenceIntegral(volume, scene.transferFunction, *scene.camera, scene.image,
                                                         options.domain, options.transfer);
    for (const char* path : {"fused", "raster"}) {
        Scene s = scene;
        s.options["path"] = path;
        const Image4f image = test::renderScene(s, volume);
        const Measured m = measure(image, reference);
        std::printf("%s, atmosphere.json at 32x32, 48 shells: max %.4f mean %.5f\n", path, m.maxAbs, m.meanAbs);
        EXPECT_TRUE(test::imagesNear(image, reference, {.maxAbs = 0.4, .meanAbs = 0.005})) << path;
    }
}

// ---- the fused path (kernels/spherical.cl spherical_fused) ----------------------------------------------

// The shell passes interpolate (u, v) across the tessellation's flat triangles and cover the inscribed
// polyhedron; the fused kernel computes both at the exact sphere. So the passes converge to the fused image
// as the tessellation refines: the mean difference falls about 4x per doubling of the segments (the
// chord error, second order), and at every tessellation the fused image is at least as close to the
// reference. Measured: see the printed lines.
TEST(SphericalFused, ThePassesConvergeToItAsTheTessellationRefines)
{
    const int size = 64;
    const Image4d& reference = obliqueReference(size);
    const Image4f fused = test::renderScene(makeScene(obliqueCamera(), size, {{"shells", 33}}), atmosphere());
    Image4d fusedd(size, size);
    for (std::size_t i = 0; i < fused.pixelCount(); ++i)
        fusedd.pixels()[i] = glm::dvec4(fused.pixels()[i]);
    const Measured fusedError = measure(fused, reference);
    double previous = 1e30;
    for (const int segments : {16, 32, 64, 128}) {
        const Image4f raster = test::renderScene(
            makeScene(obliqueCamera(), size, {{"shells", 33}, {"segments", segments}, {"path", "raster"}}), atmosphere());
        const Measured d = measure(raster, fusedd);
        const Measured rasterError = measure(raster, reference);
        std::printf("segments %3d: raster vs fused max %.4f mean %.6f; vs the reference raster %.5f, fused %.5f\n",
                    segments, d.maxAbs, d.meanAbs, rasterError.meanAbs, fusedError.meanAbs);
        EXPECT_LT(d.meanAbs, 0.5 * previous) << segments;
        previous = d.meanAbs;
        EXPECT_LE(fusedError.meanAbs, rasterError.meanAbs * 1.02) << segments;
    }
    EXPECT_LT(previous, 1e-3);  // 128 segments (measured 5.2e-4; 256 segments, not run here: 1.0e-4)
}

// Early ray termination at opacity a: a pixel stops once 1 - T >= a, so what it leaves out is at most
// T <= 1 - a of every channel; fewer samples.
TEST(SphericalFused, EarlyTerminationLeavesOutAtMostTheRemainingTransmittance)
{
    Scene scene = makeScene(obliqueCamera(), 48, {{"shells", 33}});
    scene.transferFunction = TransferFunction({{0.0, {0.1, 0.2, 0.6}, 2.0}, {1.0, {1.0, 1.0, 0.9}, 30.0}});
    FrameStats full, early;
    const Image4f a = test::renderScene(scene, atmosphere(), &full);
    scene.options["early_termination"] = 0.9;
    const Image4f b = test::renderScene(scene, atmosphere(), &early);
    double maxDiff = 0.0;
    for (std::size_t i = 0; i < a.pixelCount(); ++i) {
        const glm::dvec4 d = glm::abs(glm::dvec4(a.pixels()[i]) - glm::dvec4(b.pixels()[i]));
        maxDiff = std::max({maxDiff, d.r, d.g, d.b, d.a});
    }
    std::printf("early termination 0.9: max difference %.3g, samples %llu -> %llu\n", maxDiff,
                static_cast<unsigned long long>(full.samples), static_cast<unsigned long long>(early.samples));
    EXPECT_LE(maxDiff, 0.1 + 1e-6);
    EXPECT_GT(maxDiff, 0.0);
    EXPECT_LT(early.samples, full.samples * 9 / 10);
}

// Ray packets (kernels/spherical.cl's spherical_fused_packet): 8 pixels of a row per work-item, each lane doing
// spherical_fused's arithmetic, so the images are the same bits as one pixel per work-item — from outside,
// from inside the shells (lanes whose innermost sphere differs start the far pass at different shells; some
// hits lie behind the eye), with a parallel camera over a full ball off the origin, with radial opacity, a
// rotating color matrix and φ bias (the wrap), early termination (lanes stop at different shells), and rows
// of 61 and 5 pixels (a packet part outside the image).
TEST(SphericalFused, PacketsAreBitIdenticalToOnePixelPerWorkItem)
{
    const json rotate = {{0, -1, 0, 0}, {1, 0, 0, 0}, {0, 0, 1, 0}, {0, 0, 0, 1}};
    const json sets[] = {{{"shells", 33}},
                         {{"shells", 17}, {"opacity", "radial"}},
                         {{"shells", 33}, {"early_termination", 0.6}},
                         {{"shells", 24}, {"color_matrix", rotate}, {"bias", {0.3, 0.0, 0.0, 0.0}}}};
    const TransferFunction dense({{0.0, {0.1, 0.2, 0.6}, 2.0}, {0.5, {0.8, 0.4, 0.2}, 12.0}, {1.0, {1.0, 1.0, 0.9}, 30.0}});
    int compared = 0;
    for (const Camera& camera : {obliqueCamera(), insideCamera(), parallelBallCamera()})
        for (const json& set : sets)
            for (int width : {61, 5}) {
                json options = set;
                if (camera.parallel)
                    options.update(ballOptions());
                options["packets"] = true;
                Scene packets = makeScene(camera, width, options);
                packets.image.height = 43;
                if (set.contains("early_termination"))
                    packets.transferFunction = dense;
                Scene pixels = packets;
                pixels.options["packets"] = false;
                FrameStats ps, qs;
                const Image4f p = test::renderScene(packets, atmosphere(), &ps);
                const Image4f q = test::renderScene(pixels, atmosphere(), &qs);
                const std::string label = options.dump() + " width " + std::to_string(width) +
                                          (camera.parallel ? " parallel" : camera.position.x == 0.8 ? " inside" : " outside");
                EXPECT_TRUE(test::sameBits(p, q)) << label;
                EXPECT_TRUE(ps.extra["packets"].get<bool>()) << label;
                EXPECT_FALSE(qs.extra["packets"].get<bool>()) << label;
                EXPECT_EQ(ps.samples, qs.samples) << label;
                EXPECT_GT(qs.samples, 0u) << label;
                ++compared;
            }
    EXPECT_EQ(compared, 3 * 4 * 2);
}

// Renderer::setCamera: pointed at new cameras, the renderer gives the images new renderers give, bit for bit
// (fused with and without packets, the shell passes, radial opacity); a new image size is refused.
TEST(SphericalRender, SetCameraEqualsANewRenderer)
{
    Camera farther = obliqueCamera();
    farther.position = {-2.0, 2.9, -1.2};
    const std::vector<Camera> cameras = {obliqueCamera(), insideCamera(), farther};
    const json sets[] = {{{"shells", 17}},
                         {{"shells", 17}, {"packets", false}},
                         {{"shells", 9}, {"segments", 16}, {"path", "raster"}},
                         {{"shells", 12}, {"opacity", "radial"}, {"path", "raster"}, {"segments", 12}}};
    for (const json& options : sets)
        test::expectSetCameraEqualsNewRenderer(makeScene(cameras[0], 29, options), atmosphere(), cameras, options.dump());
    test::expectSetCameraEqualsNewRenderer(makeScene(obliqueCamera(), 29, ballOptions()), atmosphere(),
                                           {obliqueCamera(), parallelBallCamera()}, "parallel, full ball");
}

TEST(SphericalFused, PathOptions)
{
    EXPECT_EQ(parseSphericalOptions(json::object()).path, SphericalOptions::Path::Fused);
    EXPECT_EQ(parseSphericalOptions({{"path", "raster"}}).path, SphericalOptions::Path::Raster);
    EXPECT_EQ(optionError({{"path", "gpu"}}), "options.path: must be \"fused\" or \"raster\", got \"gpu\"");
    EXPECT_EQ(optionError({{"path", "raster"}, {"early_termination", 0.5}}),
              "options.early_termination: is only available on the fused path (the blending stage cannot stop a pixel)");
    EXPECT_NE(optionError({{"early_termination", 0.0}}), "");
}

TEST(Generators, AtmosphereIsPeriodicInPhiAndConstantAtThePoles)
{
    const Volume v = generateVolume("atmosphere", {25, 13, 7});
    for (int k = 0; k < 7; ++k) {
        for (int j = 0; j < 13; ++j)
            EXPECT_NEAR(v.at(0, j, k), v.at(24, j, k), 1e-6);
        for (int i = 0; i < 25; ++i) {
            EXPECT_NEAR(v.at(i, 0, k), v.at(0, 0, k), 1e-6);
            EXPECT_NEAR(v.at(i, 12, k), v.at(0, 12, k), 1e-6);
        }
    }
    const glm::dvec2 range = v.range();
    EXPECT_GE(range.x, 0.0);
    EXPECT_LE(range.y, 1.0);
    EXPECT_GT(range.y - range.x, 0.5);
}

}  // namespace
}  // namespace clvr
