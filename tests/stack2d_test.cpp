// tests/stack2d_test.cpp — 2D texture stacks: options, stack choice per view, slice planning (order,
// weights, slabs), the image against the CPU reference integral with the error falling as
// intermediate slices are added (the artifact of plain stacks), both cameras, identical bits.
#include "host/render/grid/stack2d.h"

#include "host/runtime/errors.h"
#include "host/io/generators.h"
#include "host/optics/gradient_volume.h"
#include "host/reference/reference_integral.h"
#include "host/optics/reflectance_map.h"
#include "host/render/renderer.h"
#include "tests/support/test_util.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <map>
#include <set>

namespace clvr {
namespace {

using nlohmann::json;

constexpr double kTauMax = 8.0;

Camera perspectiveCamera()  // the camera of tests/slice3d_test.cpp: 28 degrees off the z axis
{
    return test::obliquePerspectiveCamera(40.0);
}

Camera parallelCamera()  // ... and its parallel one: x stack, 32 degrees off the x axis
{
    return test::obliqueParallelCamera(1.8);
}

Scene makeScene(const Camera& camera, int size, json options = json::object())
{
    Scene s;
    s.technique = "stack2d";
    s.camera = camera;
    s.image = ImageSpec{size, size, {0.1, 0.2, 0.3}};
    s.transferFunction = test::designTransferFunction();
    s.options = std::move(options);
    return s;
}

const Volume& marschnerLobb41()
{
    static const Volume v = generateVolume("marschner-lobb", {41, 41, 41});
    return v;
}

// The reference of each camera, computed once per process (seconds each).
const Image4d& reference(const Camera& camera, int size)
{
    static std::map<std::pair<bool, int>, Image4d> cache;
    const auto key = std::make_pair(camera.parallel, size);
    auto it = cache.find(key);
    if (it == cache.end()) {
        ReferenceStats stats;
        ReferenceOptions options;
        options.stats = &stats;
        const Scene scene = makeScene(camera, size);
        it = cache.emplace(key, referenceIntegral(marschnerLobb41(), scene.transferFunction, camera, scene.image, options))
                 .first;
        EXPECT_EQ(stats.raysNotConverged, 0u);
    }
    return it->second;
}

double maxChannel(const glm::dvec4& v) { return std::max({v.r, v.g, v.b, v.a}); }

// Smallest |cos| between a pixel's ray and the stack axis over the image: the longest slab.
double minCos(const Camera& camera, int size, int axis)
{
    double c = 1.0;
    for (int y = 0; y < size; ++y)
        for (int x = 0; x < size; ++x) {
            const Ray r = camera.ray(x, y, size, size);
            c = std::min(c, std::abs(glm::normalize(r.direction)[axis]));
        }
    return c;
}

// ---- options, stack choice, planning -----------------------------------------------------------

void expectInputError(const json& options, const std::string& fragment)
{
    try {
        parseStack2dOptions(options);
        ADD_FAILURE() << "no InputError for " << options.dump();
    } catch (const InputError& e) {
        EXPECT_NE(std::string(e.what()).find(fragment), std::string::npos) << e.what();
    }
}

TEST(Stack2dOptions, BadOptionsThrowInputErrorNamingTheKey)
{
    expectInputError({{"foo", 1}}, "options.foo: unknown option for stack2d (known: intermediate, reflectance_map_size, slices_per_polygon, clip_texture, path, empty_space_skipping, early_termination, packets)");
    expectInputError({{"slices_per_polygon", 0}}, "options.slices_per_polygon: must be an integer in [1, 64], got 0");
    expectInputError({{"slices_per_polygon", 65}}, "options.slices_per_polygon");
    EXPECT_EQ(parseStack2dOptions({{"slices_per_polygon", 4}}).slicesPerPolygon, 4);
    expectInputError({{"reflectance_map_size", 0}}, "options.reflectance_map_size: must be an integer in [1, 1024]");
    expectInputError({{"intermediate", -1}}, "options.intermediate: must be an integer in [0, 64], got -1");
    expectInputError({{"intermediate", 65}}, "options.intermediate");
    expectInputError({{"intermediate", 1.5}}, "options.intermediate");
    expectInputError({{"intermediate", "2"}}, "options.intermediate");
    expectInputError(json::array(), "options: must be an object");
    EXPECT_EQ(parseStack2dOptions({{"intermediate", 3}}).intermediate, 3);
    EXPECT_EQ(parseStack2dOptions(json()).intermediate, 0);
}


TEST(Stack2dAxis, TheStackMostParallelToTheViewDirectionIsChosen)
{
    Camera c;
    c.position = {0.3, -0.2, 4.0};
    EXPECT_EQ(stackAxis(c), 2);
    c.position = {-4.0, 1.0, 0.5};
    EXPECT_EQ(stackAxis(c), 0);
    c.position = {0.5, 3.0, -2.9};
    c.viewUp = {1.0, 0.0, 0.0};
    EXPECT_EQ(stackAxis(c), 1);
    EXPECT_EQ(stackAxis(parallelCamera()), 0);
}

TEST(Stack2dAxis, RotatingTheCameraSwitchesTheStack)
{
    // The camera on a circle in the x-z plane around the volume: the z stack up to 45 degrees, the x
    // stack beyond, z again past 135; the renderer reports the stack it drew.
    const char* expected[] = {"z", "z", "x", "x", "z", "z"};
    const double degrees[] = {0.0, 40.0, 50.0, 120.0, 140.0, 180.0};
    for (int i = 0; i < 6; ++i) {
        Camera c;
        const double a = glm::radians(degrees[i]);
        c.position = {4.0 * std::sin(a), 0.3, 4.0 * std::cos(a)};
        FrameStats stats;
        test::renderScene(makeScene(c, 8), marschnerLobb41(), &stats);
        EXPECT_EQ(stats.extra["axis"], expected[i]) << degrees[i] << " degrees";
    }
}

TEST(Stack2dPlan, SlicesTileTheBoxBackToFrontWithLerpWeights)
{
    const glm::dvec3 origin(-1.0, 0.5, 2.0), spacing(0.5, 0.25, 0.2);
    const glm::ivec3 dims(5, 7, 9);
    for (const int intermediate : {0, 3}) {
        for (const bool parallel : {false, true}) {
            Camera c;
            c.position = {0.2, 1.1, -3.0};  // below the z range: the nearest plane is z = 2
            c.focalPoint = {0.0, 1.0, 2.5};
            c.parallel = parallel;
            const std::vector<StackSlice> s = planStack(c, origin, spacing, dims, 2, intermediate);
            ASSERT_EQ(s.size(), static_cast<std::size_t>(8 * (intermediate + 1) + 1));
            double total = 0.0;
            for (std::size_t i = 0; i < s.size(); ++i) {
                total += s[i].thickness;
                EXPECT_DOUBLE_EQ(s[i].lower + s[i].weight, s[i].position);
                EXPECT_GE(s[i].weight, 0.0f);
                EXPECT_LT(s[i].weight, 1.0f);
                if (i > 0) {
                    EXPECT_LT(s[i].position, s[i - 1].position) << "back (high z) to front";
                }
            }
            EXPECT_NEAR(total, 8 * 0.2, 1e-12);  // the slabs cover the box's z extent exactly
            EXPECT_DOUBLE_EQ(s.front().thickness, 0.1 / (intermediate + 1));
            EXPECT_DOUBLE_EQ(s.back().position, 0.0);
        }
    }
    // A camera inside the z range: planes farther from it in either direction come first.
    Camera inside;
    inside.position = {0.0, 1.0, 2.7};  // grid z coordinate 3.5
    inside.focalPoint = {0.0, 1.0, 0.0};
    const std::vector<StackSlice> s = planStack(inside, origin, spacing, dims, 2, 0);
    EXPECT_EQ(s.front().position, 8.0);
    EXPECT_TRUE((s.back().position == 3.0 || s.back().position == 4.0));
}

// ---- against the reference ---------------------------------------------------------------------

struct Measured {
    test::ImageError error;
    double deltaMax = 0.0;  // the longest slab along any pixel's ray
};

Measured measure(const Camera& camera, int size, int intermediate, const std::string& path)
{
    const Image4f image =
        test::renderScene(makeScene(camera, size, {{"intermediate", intermediate}, {"path", path}}), marschnerLobb41());
    Measured m;
    m.error = test::imageError(image, reference(camera, size));
    const double spacing = 2.0 / 40.0;
    m.deltaMax = spacing / (intermediate + 1) / minCos(camera, size, stackAxis(camera));
    std::printf("[ measured ] %s, %s, intermediate %d: max %.3g %.3g %.3g %.3g, mean %.2g %.2g %.2g %.2g, "
                "Delta_max %.4f\n",
                path.c_str(), camera.parallel ? "parallel" : "perspective", intermediate, m.error.maxAbs.r, m.error.maxAbs.g,
                m.error.maxAbs.b, m.error.maxAbs.a, m.error.meanAbs.r, m.error.meanAbs.g, m.error.meanAbs.b,
                m.error.meanAbs.a, m.deltaMax);
    return m;
}

void expectErrorFallsWithIntermediateSlices(const Camera& camera)
{
    const int size = 64;
    for (const char* path : {"fused", "raster"}) {
        double previousMean = 1e30;
        for (const int intermediate : {0, 1, 3}) {
            const Measured m = measure(camera, size, intermediate, path);
            EXPECT_EQ(m.error.nanCount, 0u);
            // Tolerance (docs/stack2d.md): a ray entering or leaving through a side face of the box (parallel
            // to the slices) gains or loses at most one slab's opacity there, max <= 2 (1 - exp(-tau_max
            // Delta_max)); the mean is first order in the slab, c tau_max Delta_max with c = 0.02 as slice3d's.
            const double maxTolerance = 2.0 * (1.0 - std::exp(-kTauMax * m.deltaMax));
            const double meanTolerance = 0.02 * kTauMax * m.deltaMax;
            EXPECT_LE(maxChannel(m.error.maxAbs), maxTolerance) << path << ", intermediate " << intermediate;
            EXPECT_LE(maxChannel(m.error.meanAbs), meanTolerance) << path << ", intermediate " << intermediate;
            // The artifact of plain stacks: the error falls as intermediate slices are added.
            EXPECT_LT(maxChannel(m.error.meanAbs), previousMean) << path << ", intermediate " << intermediate;
            previousMean = maxChannel(m.error.meanAbs);
        }
    }
}

TEST(Stack2dReference, PerspectiveErrorFallsWithIntermediateSlices)
{
    expectErrorFallsWithIntermediateSlices(perspectiveCamera());
}

TEST(Stack2dReference, ParallelErrorFallsWithIntermediateSlices)
{
    expectErrorFallsWithIntermediateSlices(parallelCamera());
}

TEST(Stack2dRender, TwoRendersGiveIdenticalBits)
{
    const Scene scene = makeScene(perspectiveCamera(), 24, {{"intermediate", 1}});
    auto renderer = makeRenderer(test::device(), scene, marschnerLobb41());
    FrameStats stats;
    const Image4f a = renderer->render(stats);
    const Image4f b = renderer->render(stats);
    const Image4f c = test::renderScene(scene, marschnerLobb41());
    ASSERT_EQ(a.pixels().size(), b.pixels().size());
    EXPECT_EQ(std::memcmp(a.pixels().data(), b.pixels().data(), a.pixels().size() * sizeof(glm::vec4)), 0);
    EXPECT_EQ(std::memcmp(a.pixels().data(), c.pixels().data(), a.pixels().size() * sizeof(glm::vec4)), 0);
    EXPECT_EQ(stats.extra["slices"], 81);
    // three stacks, the transfer function, and the fused path's empty-space radii (one byte per brick of 4^3 cells)
    EXPECT_EQ(renderer->residentBytes(), 3u * 41 * 41 * 41 * 4 + 4 * (4 + 8 * 3) + 10 * 10 * 10);
}

TEST(Stack2dRender, NewTransferFunctionGivesTheImageOfANewRenderer)
{
    Scene scene = makeScene(parallelCamera(), 24, {{"intermediate", 1}});
    auto renderer = makeRenderer(test::device(), scene, marschnerLobb41());
    const TransferFunction other({{0.2, {0.1, 0.9, 0.3}, 0.0}, {0.6, {0.9, 0.2, 0.1}, 12.0}, {0.9, {1, 1, 1}, 2.0}});
    renderer->setTransferFunction(other);
    FrameStats stats;
    const Image4f a = renderer->render(stats);
    scene.transferFunction = other;
    const Image4f b = test::renderScene(scene, marschnerLobb41());
    EXPECT_EQ(std::memcmp(a.pixels().data(), b.pixels().data(), a.pixels().size() * sizeof(glm::vec4)), 0);
}

// ---- shaded (diffuse shading of semi-transparent volumes) ----------------------------------------

const Volume& sphere33()
{
    static const Volume v = generateVolume("sphere", {33, 33, 33});
    return v;
}

// The shaded scene of tests/blend_test.cpp: shells of "sphere" (gradient length 1), two lights.
Scene shadedScene(const Camera& camera, json options)
{
    Scene s = makeScene(camera, 40, std::move(options));
    s.transferFunction = TransferFunction({{0.2, {0.2, 0.4, 1.0}, 0.0}, {0.3, {0.3, 0.6, 1.0}, 3.0},
                                           {0.5, {1.0, 0.8, 0.3}, 6.0}, {0.6, {1.0, 0.9, 0.7}, 0.0}});
    s.lighting = test::twoLightLighting();
    return s;
}

Image4d shadedReference(const Scene& scene)
{
    static const std::vector<glm::vec4> gradients = sobelGradientVolume(sphere33());
    const ReferenceShading shading{&gradients, scene.lighting, -scene.camera->forward()};
    ReferenceOptions options;
    options.shading = &shading;
    return referenceIntegral(sphere33(), scene.transferFunction, *scene.camera, scene.image, options);
}

// Tolerance: as unshaded, with the emission scaled by the largest shade, 0.15 + (0.7 + 0.3) +
// 0.5 (0.7 + 0.3) = 1.65 (a slab's color is at most 1.65 alpha), plus the map's quantization bound
// (reflectanceMapBound) for the max; tau_max = 6, spacing 2/32.
TEST(Stack2dShaded, MatchesShadedReferenceAndErrorFallsWithIntermediateSlices)
{
    const int size = 40;
    for (const Camera& camera : {perspectiveCamera(), parallelCamera()})
        for (const char* path : {"fused", "raster"}) {
            double previousMean = 1e30;
            Scene first;
            for (const int intermediate : {0, 3}) {
                const Scene scene =
                    shadedScene(camera, {{"intermediate", intermediate}, {"reflectance_map_size", 256}, {"path", path}});
                if (intermediate == 0)
                    first = scene;
                FrameStats stats;
                const Image4f image = test::renderScene(scene, sphere33(), &stats);
                EXPECT_EQ(stats.extra["shaded"], true);
                const Image4d expected = shadedReference(first);
                const test::ImageError e = test::imageError(image, expected);
                const double deltaMax = 2.0 / 32.0 / (intermediate + 1) / minCos(camera, size, stackAxis(camera));
                std::printf("[ measured ] shaded %s, %s, intermediate %d: max %.3g %.3g %.3g %.3g, mean %.2g %.2g %.2g %.2g, "
                            "Delta_max %.4f\n",
                            path, camera.parallel ? "parallel" : "perspective", intermediate, e.maxAbs.r, e.maxAbs.g, e.maxAbs.b,
                            e.maxAbs.a, e.meanAbs.r, e.meanAbs.g, e.meanAbs.b, e.meanAbs.a, deltaMax);
                const double slab = 1.0 - std::exp(-6.0 * deltaMax);
                const double mapBound = reflectanceMapBound(scene.lighting, 256);
                EXPECT_TRUE(test::imagesNear(image, expected, {.maxAbs = 2.0 * 1.65 * slab + mapBound,
                                                               .meanAbs = 1.65 * 0.02 * 6.0 * deltaMax}))
                    << path << ", " << (camera.parallel ? "parallel" : "perspective") << ", intermediate " << intermediate;
                EXPECT_LT(maxChannel(e.meanAbs), previousMean);
                previousMean = maxChannel(e.meanAbs);
            }
        }
}

TEST(Stack2dShaded, LightsChangeTheImage)
{
    const Scene shaded = shadedScene(perspectiveCamera(), {{"intermediate", 1}});
    Scene unshaded = shaded;
    unshaded.lighting = Lighting{};
    const Image4f a = test::renderScene(shaded, sphere33()), b = test::renderScene(unshaded, sphere33());
    Image4d bd(b.width(), b.height());
    for (std::size_t i = 0; i < b.pixelCount(); ++i)
        bd.pixels()[i] = glm::dvec4(b.pixels()[i]);
    const test::ImageError e = test::imageError(a, bd);
    EXPECT_GT(e.maxAbs.b, 0.1);      // shading changes the color ...
    EXPECT_LT(e.maxAbs.a, 1e-6);     // ... never the opacity (tau is not shaded)
}

// ---- shaded iso-surfaces ----------------------------------------------------------------------

// The iso-surface 0.5 of "sphere" (1 - |p|) is the sphere of radius 0.5, seen by both cameras; no
// transfer function, so the surface is white: ambient + diffuse max(0, N.L), N the outward normal.
// Rays that pass the sphere by more than a margin must give the background (A = 0), rays through its
// inner part the surface (A = 1) with the analytic shade. Margin and shade tolerance: the hit lies on
// the first slice inside the surface, up to one slab Delta behind it, and the Sobel gradient of the
// trilinear field tilts the normal. Measured (48x48, 3 intermediate slices): no pixel wrong by coverage
// with a margin of 0.03 (half a grid spacing); shade error over the 88 (perspective) and 68 (parallel)
// inner pixels max 0.011 / 0.018, mean 0.0034 / 0.0045. Bounds: 0.04 and 0.01, about twice that.
TEST(Stack2dIso, SphereSilhouetteAndShadeMatchTheAnalyticSurface)
{
    const double r = 0.5, ambient = 0.15, diffuse = 0.8;
    const glm::dvec3 light = glm::normalize(glm::dvec3(0.4, 0.6, 1.0));
    for (const Camera& camera : {perspectiveCamera(), parallelCamera()})
        for (const char* path : {"fused", "raster"}) {
            Scene scene = makeScene(camera, 48    , {{"intermediate", 3}, {"path", path}});
            scene.transferFunction = TransferFunction();
            scene.iso = test::isoSpec(0.5, {0.4, 0.6, 1.0}, ambient, diffuse);
            FrameStats stats;
            const Image4f image = test::renderScene(scene, sphere33(), &stats);
            EXPECT_EQ(stats.extra["iso"], true);
            int inside = 0, outside = 0;
            double maxShadeError = 0.0, meanShadeError = 0.0;
            for (int y = 0; y < 48; ++y)
                for (int x = 0; x < 48; ++x) {
                    const glm::vec4 p = image.pixels()[static_cast<std::size_t>(y) * 48 + x];
                    const Ray ray = camera.ray(x, y, 48, 48);
                    const double tc = -glm::dot(ray.origin, ray.direction);  // closest approach to the center
                    const double d = glm::length(ray.origin + tc * ray.direction);
                    if (d > r + 0.03) {
                        ++outside;
                        EXPECT_EQ(p.a, 0.0f) << x << ", " << y;
                        EXPECT_NEAR(p.b, 0.3, 1e-6) << x << ", " << y;
                    } else if (d < r - 0.03) {
                        ASSERT_EQ(p.a, 1.0f) << x << ", " << y;
                        if (d > 0.35)
                            continue;  // near the silhouette the slab offset moves the normal most
                        ++inside;
                        const glm::dvec3 hit = ray.origin + (tc - std::sqrt(r * r - d * d)) * ray.direction;
                        const double shade = ambient + diffuse * std::max(0.0, glm::dot(glm::normalize(hit), light));
                        const double e = std::abs(p.r - shade);
                        maxShadeError = std::max(maxShadeError, e);
                        meanShadeError += e;
                        EXPECT_EQ(p.r, p.b);  // white surface
                    }
                }
            meanShadeError /= std::max(inside, 1);
            std::printf("[ measured ] iso %s, %s: %d inner pixels, shade error max %.3g mean %.3g; %d outside\n",
                        path, camera.parallel ? "parallel" : "perspective", inside, maxShadeError, meanShadeError, outside);
            EXPECT_GT(inside, 50);
            EXPECT_GT(outside, 1000);
            EXPECT_LT(maxShadeError, 0.04);
            EXPECT_LT(meanShadeError, 0.01);
        }
}

// ---- several slices per polygon (seeds/003's multi-texture speed-up) --------------------------------

// Grouping keeps every slice that can be seen exactly once, never mixes the two sides of a perspective
// camera, and keeps each side's back-to-front order; groups hold at most k slices.
TEST(Stack2dPolygons, GroupsKeepEachSideInOrderAndNeverMixSides)
{
    const glm::ivec3 dims(5, 5, 9);
    const glm::dvec3 origin(-1.0, -1.0, -0.8), spacing(0.5, 0.5, 0.2);
    Camera inside;  // grid z coordinate 3.5 + a plane exactly at the camera with intermediate 1
    inside.position = {0.0, 1.0, -0.8 + 0.2 * 3.5};
    inside.focalPoint = {0.0, 1.0, -0.8};
    for (const Camera& camera : {inside, perspectiveCamera(), parallelCamera()})
        for (const int k : {2, 3, 8}) {
            const std::vector<StackSlice> order = planStack(camera, origin, spacing, dims, 2, 1);
            const SliceGroups g = groupStackSlices(order, camera, origin, spacing, 2, k);
            const double camZ = (camera.position.z - origin.z) / spacing.z;
            std::size_t expected = 0;
            for (const StackSlice& slice : order)
                expected += camera.parallel || slice.position != camZ;
            EXPECT_EQ(g.slices.size(), expected);
            if (!camera.parallel && camera.position == inside.position) {
                EXPECT_EQ(expected, order.size() - 1);  // the plane through the camera is dropped
            }
            int next = 0;
            for (const auto& [first, count] : g.groups) {
                EXPECT_EQ(first, next);
                EXPECT_GE(count, 1);
                EXPECT_LE(count, k);
                next = first + count;
                for (int j = first + 1; j < first + count; ++j) {
                    const double a = g.slices[j - 1].position - camZ, b = g.slices[j].position - camZ;
                    if (!camera.parallel) {
                        EXPECT_GT(a * b, 0.0) << "a group mixes the sides of the camera";
                        EXPECT_GT(std::abs(a), std::abs(b)) << "back to front within a group";
                    }
                }
            }
            EXPECT_EQ(next, static_cast<int>(g.slices.size()));
            // each side's slices appear in planStack's order
            for (const int side : {1, -1}) {
                std::vector<double> want, got;
                for (const StackSlice& slice : order)
                    if (camera.parallel ? side == 1 : (slice.position - camZ) * side > 0.0)
                        want.push_back(slice.position);
                for (const StackSlice& slice : g.slices)
                    if (camera.parallel ? side == 1 : (slice.position - camZ) * side > 0.0)
                        got.push_back(slice.position);
                EXPECT_EQ(want, got);
            }
        }
}

// One quad for k slices gives the image of one quad per slice: each slice is sampled where the
// pixel's ray meets its plane and composited in the fragment ("over" is associative). The texture
// coordinates come from the ray (float, from the camera) instead of the rasterizer's interpolated
// attributes, whose vertices are snapped to sub-pixel positions: samples move by up to a few
// thousandths of a texel, and pixels change by up to about 1e-3 (measured: 73 to 457 of 4096 pixels
// by more than 1e-4, at most 13 by more than 1e-2). And whether a ray that meets a slice plane within
// rounding of the box's side faces samples that slice is decided by the rasterizer's edge functions
// with one quad per slice, by the ray's hit point with several: such a pixel takes or loses one slab,
// at most 1 - exp(-tau_max Delta_max) (0.37 for the parallel camera without intermediate slices;
// measured max 0.30). Bounds: that max; at most 24 pixels (0.6 %) differ by more than 1e-2; mean
// <= 3e-4 (measured 4.8e-5 to 1.3e-4, 20x below the stack's own mean error against the reference);
// and the error against the reference integral is that of one quad per slice within 5 % (mean).
// The quads drop from n to ceil(n / k) (the camera is outside the box's range along the axis).
TEST(Stack2dPolygons, SeveralSlicesPerPolygonGiveTheImageOfOneQuadPerSlice)
{
    const int size = 64;
    for (const Camera& camera : {perspectiveCamera(), parallelCamera()})
        for (const int intermediate : {0, 1}) {
            FrameStats oneStats;
            const Image4f one = test::renderScene(makeScene(camera, size, {{"intermediate", intermediate}, {"path", "raster"}}),
                                                  marschnerLobb41(), &oneStats);
            Image4d oned(size, size);
            for (std::size_t i = 0; i < one.pixelCount(); ++i)
                oned.pixels()[i] = glm::dvec4(one.pixels()[i]);
            const double deltaMax = 2.0 / 40.0 / (intermediate + 1) / minCos(camera, size, stackAxis(camera));
            for (const int k : {2, 5}) {
                FrameStats stats;
                const Image4f image = test::renderScene(
                    makeScene(camera, size, {{"intermediate", intermediate}, {"slices_per_polygon", k}}),
                    marschnerLobb41(), &stats);
                const test::ImageError e = test::imageError(image, oned);
                std::printf("[ measured ] %s, intermediate %d, %d slices per polygon: max %.3g, mean %.3g, "
                            "%d polygons for %d slices\n",
                            camera.parallel ? "parallel" : "perspective", intermediate, k, maxChannel(e.maxAbs),
                            maxChannel(e.meanAbs), stats.extra["polygons"].get<int>(), stats.extra["slices"].get<int>());
                EXPECT_EQ(e.nanCount, 0u);
                EXPECT_LE(maxChannel(e.maxAbs), 1.0 - std::exp(-kTauMax * deltaMax));
                EXPECT_LE(maxChannel(e.meanAbs), 3e-4);
                int differing = 0;
                for (std::size_t i = 0; i < image.pixelCount(); ++i)
                    differing += maxChannel(glm::abs(glm::dvec4(image.pixels()[i]) - oned.pixels()[i])) > 1e-2;
                EXPECT_LE(differing, 24) << "pixels differing by more than 1e-2";
                const double oneError = maxChannel(test::imageError(one, reference(camera, size)).meanAbs);
                const double error = maxChannel(test::imageError(image, reference(camera, size)).meanAbs);
                EXPECT_LE(error, 1.05 * oneError) << "mean error against the reference";
                const int slices = oneStats.extra["slices"].get<int>();
                EXPECT_EQ(stats.extra["polygons"].get<int>(), (slices + k - 1) / k);  // the camera is outside the box's z range
                EXPECT_LT(stats.extra["triangles"].get<int>(), oneStats.extra["triangles"].get<int>() / k + 4);
            }
        }
}

// The same for shaded volumes and for iso-surfaces (the front-most sample at or above the iso-value
// of the group, as the alpha test and the drawing order keep it). Shaded: the bounds above (measured
// max 9.2e-4, mean 9.4e-6). Iso: identical coverage, and the shade moves with the sample position
// (the gradient sampled a few thousandths of a texel away, or where a ray meets the surface within
// that of a slice, the hit on the neighbouring slice): measured over the 48x48 sphere max 0.025,
// mean 1.6e-4 / 2.3e-4 (perspective / parallel) over the covered pixels. Bounds: max 0.04 —
// Stack2dIso's bound on the stack's own shade error against the analytic surface — and mean 2e-3.
TEST(Stack2dPolygons, ShadedAndIsoSurfacesWithSeveralSlicesPerPolygon)
{
    for (const Camera& camera : {perspectiveCamera(), parallelCamera()}) {
        const Image4f a = test::renderScene(shadedScene(camera, {{"intermediate", 1}, {"path", "raster"}}), sphere33());
        const Image4f b = test::renderScene(shadedScene(camera, {{"intermediate", 1}, {"slices_per_polygon", 4}}), sphere33());
        Image4d ad(a.width(), a.height());
        for (std::size_t i = 0; i < a.pixelCount(); ++i)
            ad.pixels()[i] = glm::dvec4(a.pixels()[i]);
        const test::ImageError e = test::imageError(b, ad);
        std::printf("[ measured ] shaded %s, 4 slices per polygon: max %.3g, mean %.3g\n",
                    camera.parallel ? "parallel" : "perspective", maxChannel(e.maxAbs), maxChannel(e.meanAbs));
        EXPECT_LE(maxChannel(e.maxAbs), 0.05);
        EXPECT_LE(maxChannel(e.meanAbs), 3e-4);

        Scene iso = makeScene(camera, 48, {{"intermediate", 3}, {"path", "raster"}});
        iso.transferFunction = TransferFunction();
        iso.iso = test::isoSpec(0.5, {0.4, 0.6, 1.0}, 0.15, 0.8);
        const Image4f isoOne = test::renderScene(iso, sphere33());
        iso.options["slices_per_polygon"] = 6;
        const Image4f isoSix = test::renderScene(iso, sphere33());
        int coverageDiffers = 0, covered = 0;
        double shadeMax = 0.0, shadeSum = 0.0;
        for (std::size_t i = 0; i < isoOne.pixelCount(); ++i) {
            coverageDiffers += isoOne.pixels()[i].a != isoSix.pixels()[i].a;
            if (isoOne.pixels()[i].a == 0.0f)
                continue;
            const double d = std::abs(isoOne.pixels()[i].r - isoSix.pixels()[i].r);
            shadeMax = std::max(shadeMax, d);
            shadeSum += d;
            ++covered;
        }
        const double shadeMean = shadeSum / std::max(covered, 1);
        std::printf("[ measured ] iso %s, 6 slices per polygon: %d pixels differ in coverage, shade max %.3g, mean %.2g "
                    "over %d covered pixels\n",
                    camera.parallel ? "parallel" : "perspective", coverageDiffers, shadeMax, shadeMean, covered);
        EXPECT_EQ(coverageDiffers, 0);
        EXPECT_GT(covered, 100);
        EXPECT_LE(shadeMax, 0.04);
        EXPECT_LE(shadeMean, 2e-3);
    }
}

// ---- the fused path (kernels/stack2d.cl stack2d_fused) ------------------------------------------------

// In the box [-1, 1]^3, looking past the center: the planes on both sides of the eye, the near ones clipped.
Camera insideCamera()
{
    Camera c;
    c.position = {0.35, 0.45, 0.55};
    c.focalPoint = {0.0, -0.1, 0.0};
    c.viewAngle = 70.0;
    return c;
}

struct PathDifference {
    double maxAbs = 0.0, meanAbs = 0.0;  // largest channel, over all pixels
    int differing = 0;                   // pixels with a channel differing by more than 1e-3
    std::uint64_t fusedSamples = 0, rasterFragments = 0;
};

// The fused path's image against the raster path's for the same scene.
PathDifference comparePaths(Scene scene, const Volume& volume)
{
    scene.options["path"] = "fused";
    FrameStats fusedStats, rasterStats;
    const Image4f fused = test::renderScene(scene, volume, &fusedStats);
    scene.options["path"] = "raster";
    const Image4f raster = test::renderScene(scene, volume, &rasterStats);
    EXPECT_EQ(fusedStats.extra["path"], "fused");
    EXPECT_EQ(rasterStats.extra["path"], "raster");
    PathDifference d;
    for (std::size_t i = 0; i < fused.pixelCount(); ++i) {
        const double e = maxChannel(glm::abs(glm::dvec4(fused.pixels()[i]) - glm::dvec4(raster.pixels()[i])));
        d.maxAbs = std::max(d.maxAbs, e);
        d.meanAbs += e;
        d.differing += e > 1e-3;
    }
    d.meanAbs /= static_cast<double>(fused.pixelCount());
    d.fusedSamples = fusedStats.samples;
    d.rasterFragments = rasterStats.samples;
    return d;
}

const char* cameraName(const Camera& camera)
{
    return camera.parallel ? "parallel" : (camera.position.x < 1.0 ? "inside" : "perspective");
}

// The fused kernel samples the same planes as the quads, at the ray's point on each instead of the
// rasterizer's interpolated texture coordinates of vertices snapped to 1/256 pixel (docs/raster.md), and
// a pixel whose center lies within that snapping of a quad's edge can be covered on one path and not on
// the other: that plane's slab, at most `slab` (1 - exp(-tau_max Delta_max), times the largest color),
// on a few pixels along the box's silhouette. Everywhere else the two are equal up to rounding and the
// snapping's sample offsets (< 1e-3 per pixel, 1.6e-5 on the mean at most as measured). Bounds: max one
// slab; at most 2 % of the pixels over 1e-3; the mean at most those pixels' slabs spread over the image,
// plus 5e-5.
void expectPathsAgree(const PathDifference& d, double slab, int pixels, const std::string& what)
{
    EXPECT_LE(d.maxAbs, slab) << what;
    EXPECT_LE(d.differing, pixels / 50) << what;
    EXPECT_LE(d.meanAbs, d.differing * slab / pixels + 5e-5) << what;
}

// Measured (64x64, Marschner–Lobb 41^3): 5-29 pixels over 1e-3 outside, max 0.056-0.30 (one slab at
// the silhouette), mean 3.8e-5-1.5e-4; the camera inside the box: 0-1 pixels, max 1.1e-3.
TEST(Stack2dFused, EqualsTheQuadsOfTheRasterPath)
{
    const int size = 64;
    for (const Camera& camera : {perspectiveCamera(), parallelCamera(), insideCamera()})
        for (const int intermediate : {0, 1, 3}) {
            const PathDifference d = comparePaths(makeScene(camera, size, {{"intermediate", intermediate}}), marschnerLobb41());
            const double deltaMax = 2.0 / 40.0 / (intermediate + 1) / minCos(camera, size, stackAxis(camera));
            std::printf("[ measured ] fused vs raster, %s, intermediate %d: max %.3g, mean %.3g, %d pixels over 1e-3; "
                        "samples %llu, fragments %llu\n",
                        cameraName(camera), intermediate, d.maxAbs, d.meanAbs, d.differing,
                        static_cast<unsigned long long>(d.fusedSamples), static_cast<unsigned long long>(d.rasterFragments));
            expectPathsAgree(d, 1.0 - std::exp(-kTauMax * deltaMax), size * size,
                             std::string(cameraName(camera)) + ", intermediate " + std::to_string(intermediate));
        }
}

// The same for shaded volumes (the RGBA stacks, the reflectance map; a slab's color is at most 1.65
// alpha, tau_max 6, as in Stack2dShaded) and for iso-surfaces (the first sample at or above the iso-value,
// as the alpha test and the drawing order keep it; a pixel can differ where a sample lies within the
// snapping's offset of the iso-value). Measured: shaded 0-4 pixels over 1e-3, max 2.8e-3; iso 1-3
// pixels, max 0.093, mean 1.4e-5-6.9e-5.
TEST(Stack2dFused, ShadedAndIsoSurfacesEqualTheRasterPath)
{
    for (const Camera& camera : {perspectiveCamera(), parallelCamera(), insideCamera()}) {
        const PathDifference shaded = comparePaths(shadedScene(camera, {{"intermediate", 1}}), sphere33());
        std::printf("[ measured ] fused vs raster, shaded %s: max %.3g, mean %.3g, %d pixels over 1e-3\n",
                    cameraName(camera), shaded.maxAbs, shaded.meanAbs, shaded.differing);
        const double deltaMax = 2.0 / 32.0 / 2.0 / minCos(camera, 40, stackAxis(camera));
        expectPathsAgree(shaded, 1.65 * (1.0 - std::exp(-6.0 * deltaMax)), 40 * 40, std::string("shaded, ") + cameraName(camera));

        Scene iso = makeScene(camera, 48, {{"intermediate", 3}});
        iso.transferFunction = TransferFunction();
        iso.iso = test::isoSpec(0.5, {0.4, 0.6, 1.0}, 0.15, 0.8);
        const PathDifference surface = comparePaths(iso, sphere33());
        std::printf("[ measured ] fused vs raster, iso %s: max %.3g, mean %.3g, %d pixels over 1e-3; samples %llu, "
                    "fragments %llu\n",
                    cameraName(camera), surface.maxAbs, surface.meanAbs, surface.differing,
                    static_cast<unsigned long long>(surface.fusedSamples),
                    static_cast<unsigned long long>(surface.rasterFragments));
        EXPECT_LE(surface.differing, 48 * 48 / 200) << cameraName(camera);
        EXPECT_LE(surface.meanAbs, 2e-3) << cameraName(camera);
        // the fused kernel stops at the first hit
        EXPECT_LT(surface.fusedSamples, surface.rasterFragments) << cameraName(camera);
    }
}

// Empty-space skipping steps over bricks where tau is 0 (or, for iso-surfaces, where every value lies below
// the iso-value): the same image bit for bit, with samples stepped over. A transfer function that is 0 on
// the lower half of Marschner–Lobb's range leaves bricks empty.
TEST(Stack2dFused, EmptySpaceSkippingLeavesTheSameBits)
{
    for (const Camera& camera : {perspectiveCamera(), parallelCamera(), insideCamera()})
        for (const bool iso : {false, true}) {
            Scene on = makeScene(camera, 48, {{"intermediate", 1}});
            on.transferFunction = TransferFunction({{0.0, {0, 0, 0}, 0.0}, {0.55, {0.2, 0.5, 0.9}, 0.0},
                                                    {0.7, {1.0, 0.8, 0.3}, 6.0}, {1.0, {1, 1, 1}, 2.0}});
            if (iso) {
                on.transferFunction = TransferFunction();
                on.iso = test::isoSpec(0.75, {0.4, 0.6, 1.0}, 0.15, 0.8);
            }
            Scene off = on;
            off.options["empty_space_skipping"] = false;
            FrameStats son, soff;
            const Image4f a = test::renderScene(on, marschnerLobb41(), &son);
            const Image4f b = test::renderScene(off, marschnerLobb41(), &soff);
            EXPECT_TRUE(son.extra["empty_space_skipping"].get<bool>());
            EXPECT_FALSE(soff.extra["empty_space_skipping"].get<bool>());
            EXPECT_EQ(std::memcmp(a.pixels().data(), b.pixels().data(), a.pixels().size() * sizeof(glm::vec4)), 0)
                << cameraName(camera) << (iso ? ", iso" : "");
            const auto skipped = son.extra["skipped"].get<std::uint64_t>();
            std::printf("[ measured ] skipping, %s%s: %llu empty bricks, %llu of %llu samples stepped over\n",
                        cameraName(camera), iso ? ", iso" : "",
                        static_cast<unsigned long long>(son.extra["empty_bricks"].get<std::uint64_t>()),
                        static_cast<unsigned long long>(skipped), static_cast<unsigned long long>(son.samples));
            EXPECT_GT(skipped, son.samples / 20);
            EXPECT_EQ(soff.extra["skipped"].get<std::uint64_t>(), 0u);
            if (!iso) {  // both count every plane met in the box (iso-surfaces stop at the hit, earlier with skipping)
                EXPECT_EQ(son.samples, soff.samples);
            }
        }
}

// Early ray termination at opacity a: a pixel stops once 1 - T >= a, so what it leaves out is at most
// T <= 1 - a of every channel (the background is weighted by T as well).
TEST(Stack2dFused, EarlyTerminationLeavesOutAtMostTheRemainingTransmittance)
{
    Scene scene = makeScene(perspectiveCamera(), 64, {{"intermediate", 1}, {"empty_space_skipping", false}});
    scene.transferFunction = test::designTransferFunction(40.0);  // dense: many rays become opaque
    FrameStats full, early;
    const Image4f a = test::renderScene(scene, marschnerLobb41(), &full);
    scene.options["early_termination"] = 0.95;
    const Image4f b = test::renderScene(scene, marschnerLobb41(), &early);
    double maxDiff = 0.0;
    for (std::size_t i = 0; i < a.pixelCount(); ++i)
        maxDiff = std::max(maxDiff, maxChannel(glm::abs(glm::dvec4(a.pixels()[i]) - glm::dvec4(b.pixels()[i]))));
    std::printf("[ measured ] early termination 0.95: max difference %.3g, samples %llu -> %llu\n", maxDiff,
                static_cast<unsigned long long>(full.samples), static_cast<unsigned long long>(early.samples));
    EXPECT_LE(maxDiff, 0.05 + 1e-6);
    EXPECT_GT(maxDiff, 0.0);
    EXPECT_LT(early.samples, full.samples * 9 / 10);
}

// The packet kernel (stack2d_fused_packet: 8 pixels of a row per work-item, one per float8 lane) computes each
// lane with the one-pixel kernel's expressions: the images must be the same bits (memcmp) and the planes met the
// same count. Plain rendering with and without intermediate slices, empty-space skipping on and off, early
// termination, rows of 61 and 5 pixels, the oblique, parallel and inside cameras, and a 150-degree camera whose
// rays see the stack's planes from both sides (those packets render their pixels one by one). Shaded stacks,
// iso-surfaces and clip textures keep one pixel per work-item (stats "packets").
TEST(Stack2dFused, PacketsAreBitIdenticalToOnePixelPerWorkItem)
{
    Camera wide;  // inside the box, so that its rays along the planes still meet the data
    wide.position = {0.1, -0.05, 0.3};
    wide.focalPoint = {0.6, 0.3, -1.0};  // 25 degrees off -z: the z stack; the image's far corners look past 90
    wide.viewAngle = 150.0;
    const TransferFunction threshold({{0.0, {0, 0, 0}, 0.0}, {0.55, {0.2, 0.5, 0.9}, 0.0}, {0.7, {1.0, 0.8, 0.3}, 6.0},
                                      {1.0, {1, 1, 1}, 2.0}});
    const json sets[] = {{{"intermediate", 1}},
                         {{"intermediate", 0}},
                         {{"intermediate", 1}, {"empty_space_skipping", false}},
                         {{"intermediate", 2}, {"early_termination", 0.9}}};
    int compared = 0;
    for (const Camera& camera : {perspectiveCamera(), parallelCamera(), insideCamera(), wide})
        for (const TransferFunction& tf : {threshold, test::designTransferFunction()})
            for (const json& options : sets)
                for (int width : {61, 5}) {
                    Scene packets = makeScene(camera, width, options);
                    packets.options["packets"] = true;  // the default on CPU devices only
                    packets.image.height = 47;
                    packets.transferFunction = tf;
                    Scene pixels = packets;
                    pixels.options["packets"] = false;
                    FrameStats ps, qs;
                    const Image4f p = test::renderScene(packets, marschnerLobb41(), &ps);
                    const Image4f q = test::renderScene(pixels, marschnerLobb41(), &qs);
                    const std::string label = std::string(camera.viewAngle > 100.0 ? "wide" : cameraName(camera)) + " " +
                                              options.dump() + " width " + std::to_string(width);
                    EXPECT_TRUE(test::sameBits(p, q)) << label;
                    EXPECT_TRUE(ps.extra["packets"].get<bool>()) << label;
                    EXPECT_FALSE(qs.extra["packets"].get<bool>()) << label;
                    EXPECT_EQ(ps.samples, qs.samples) << label;
                    EXPECT_GT(qs.samples, 0u) << label;
                    ++compared;
                }
    EXPECT_EQ(compared, 4 * 2 * 4 * 2);
    FrameStats shaded, iso;
    test::renderScene(shadedScene(perspectiveCamera(), {{"intermediate", 1}, {"packets", true}}), sphere33(), &shaded);
    Scene isoScene = makeScene(perspectiveCamera(), 24, {{"intermediate", 1}, {"packets", true}});
    isoScene.transferFunction = TransferFunction();
    isoScene.iso = test::isoSpec(0.75, {0.4, 0.6, 1.0}, 0.15, 0.8);
    test::renderScene(isoScene, marschnerLobb41(), &iso);
    EXPECT_FALSE(shaded.extra["packets"].get<bool>());
    EXPECT_FALSE(iso.extra["packets"].get<bool>());
}

// "path" and the options that only one path has.
TEST(Stack2dFused, PathOptions)
{
    EXPECT_EQ(parseStack2dOptions(json::object()).path, Stack2dOptions::Path::Fused);
    EXPECT_EQ(parseStack2dOptions({{"path", "raster"}}).path, Stack2dOptions::Path::Raster);
    EXPECT_EQ(parseStack2dOptions({{"slices_per_polygon", 2}}).path, Stack2dOptions::Path::Raster);
    expectInputError({{"path", "gpu"}}, "options.path: must be \"fused\" or \"raster\", got \"gpu\"");
    expectInputError({{"path", "fused"}, {"slices_per_polygon", 2}},
                     "options.path: \"fused\" does not work with slices_per_polygon > 1");
    expectInputError({{"path", "raster"}, {"early_termination", 0.9}},
                     "options.early_termination: is only available on the fused path");
    expectInputError({{"empty_space_skipping", 1}}, "options.empty_space_skipping: must be true or false");
    FrameStats stats;
    test::renderScene(makeScene(perspectiveCamera(), 16, {{"slices_per_polygon", 3}}), marschnerLobb41(), &stats);
    EXPECT_EQ(stats.extra["path"], "raster");
    EXPECT_EQ(stats.extra["polygons"], 14);  // 41 planes, 3 per quad
}

// Renderer::setCamera: pointed at cameras that draw other stacks (z, x, y and the eye inside) the renderer plans
// its slices again, renames its bricks for the new stack, rebuilds the reflectance map and the slice table and
// turns the headlight, and renders the bits a new renderer renders, on both paths and in every mode; a wider
// image it refuses.
TEST(Stack2dRender, SetCameraEqualsANewRenderer)
{
    Camera alongY = perspectiveCamera();
    alongY.position = {0.4, -3.2, 0.7};
    const std::vector<Camera> cameras = {perspectiveCamera(), parallelCamera(), alongY, insideCamera()};
    std::set<int> axes;
    for (const Camera& c : cameras)
        axes.insert(stackAxis(c));
    ASSERT_EQ(axes.size(), 3u) << "the cameras draw all three stacks";
    // blobs on a grid of three sizes, zero on the lower part of the range: empty bricks, other ones per stack, for
    // the fused path to rename and skip
    const Volume blobs = generateVolume("blobs", {41, 36, 27});
    const TransferFunction sparse({{0.0, {0, 0, 0}, 0.0}, {0.45, {0, 0, 0}, 0.0}, {0.7, {1, 0.5, 0}, 6.0}, {1.0, {1, 1, 1}, 12.0}});
    struct Case {
        const char* name;
        json options;
        int mode;  // 0 plain, 1 shaded, 2 iso-surface
    };
    const Case cases[] = {{"fused", {{"intermediate", 1}}, 0},
                          {"fused, one pixel per work-item", {{"packets", false}}, 0},
                          {"raster", {{"path", "raster"}}, 0},
                          {"raster, 3 slices per polygon", {{"path", "raster"}, {"slices_per_polygon", 3}}, 0},
                          {"fused, clip texture", {{"clip_texture", {{"shape", "sphere"}, {"center", {0.1, -0.1, 0.2}}, {"radius", 0.55}}}}, 0},
                          {"fused, shaded", json::object(), 1},
                          {"raster, shaded", {{"path", "raster"}}, 1},
                          {"fused, iso-surface", json::object(), 2},
                          {"raster, iso-surface, 2 slices per polygon", {{"path", "raster"}, {"slices_per_polygon", 2}}, 2}};
    for (const Case& c : cases) {
        Scene scene = c.mode == 1 ? shadedScene(cameras[0], c.options) : makeScene(cameras[0], 29, c.options);
        scene.image.width = scene.image.height = 29;
        if (c.mode == 0)
            scene.transferFunction = sparse;
        if (c.mode == 2) {
            scene.transferFunction = TransferFunction();
            scene.iso = test::isoSpec(0.5, {0.4, 0.6, 1.0}, 0.15, 0.8);
            scene.iso->light.reset();  // the headlight: it turns with the camera
        }
        test::expectSetCameraEqualsNewRenderer(scene, c.mode == 0 ? blobs : sphere33(), cameras, c.name);
    }
}

}  // namespace
}  // namespace clvr
