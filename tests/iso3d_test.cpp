// tests/iso3d_test.cpp — iso-surfaces by the alpha test (seeds/000 §3): options; the color matrix; the exact
// first-hit reference on fields with known hits; the hit depth of the slices within one slice spacing of the
// reference, coverage differing only at silhouettes; gradient shading against the reference's shade.
#include "host/render/grid/iso3d.h"

#include "host/runtime/errors.h"
#include "host/io/generators.h"
#include "host/reference/iso_reference.h"
#include "host/io/volume_io.h"
#include "tests/support/test_util.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>

namespace clvr {
namespace {

using nlohmann::json;

const Volume& sphere33()
{
    static const Volume v = generateVolume("sphere", {33, 33, 33});
    return v;
}

const Volume& marschnerLobb41()
{
    static const Volume v = generateVolume("marschner-lobb", {41, 41, 41});
    return v;
}

Camera perspectiveCamera()
{
    return test::obliquePerspectiveCamera(24.0);
}

Camera parallelCamera()
{
    return test::obliqueParallelCamera(1.2);
}

Camera insideCamera()
{
    Camera c;  // in the box [-1, 1]^3, outside the sphere of radius 0.5, looking past its centre
    c.position = {0.55, 0.7, 0.8};
    c.focalPoint = {0.0, -0.1, 0.0};
    c.viewAngle = 70.0;
    return c;
}

Scene makeScene(const Camera& camera, double iso, json options = json::object())
{
    Scene s;
    s.technique = "iso3d";
    s.camera = camera;
    s.image = ImageSpec{64, 64, {0.1, 0.2, 0.3}};
    s.transferFunction = TransferFunction({{0.0, {1.0, 0.8, 0.6}, 0.0}, {1.0, {1.0, 0.8, 0.6}, 1.0}});
    s.iso = test::isoSpec(iso, {0.4, 0.6, 1.0}, 0.1, 0.9);
    s.options = std::move(options);
    return s;
}

// Slices against the reference, per pixel: hit depth where both hit, and coverage.
struct HitComparison {
    double deltaS = 0.0;
    double maxDepthError = 0.0;     // max |z - z_ref| where both hit
    std::size_t bothHit = 0, overOneSlice = 0;  // ... and how many of those exceed deltaS
    std::size_t coverageDiffers = 0, coverageDiffersInside = 0;  // one hits, the other not; not at a silhouette
    Image4f image;
    IsoReference reference;
};

// Float rounding of the sample positions and of the depth buffer read back as eye depth: a few ulp of
// depths ~4 (ulp 4.8e-7) through ~10 operations.
constexpr double kDepthSlack = 1e-5;

HitComparison compareHits(const Scene& scene, const Volume& volume)
{
    HitComparison r;
    auto renderer = makeIso3dRenderer(test::device(), scene, volume);
    FrameStats stats;
    r.image = renderer->render(stats);
    const std::vector<double> z = renderer->hitDepth();
    r.deltaS = renderer->sliceSpacing();
    r.reference = isoReference(volume, *scene.camera, scene.image, isoSurface(scene, *scene.camera));
    const int w = scene.image.width, h = scene.image.height;
    auto refHit = [&](int x, int y) { return std::isfinite(r.reference.eyeDepth[static_cast<std::size_t>(y) * w + x]); };
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
            const std::size_t i = static_cast<std::size_t>(y) * w + x;
            const bool hit = std::isfinite(z[i]);
            if (hit && refHit(x, y)) {
                ++r.bothHit;
                const double e = std::abs(z[i] - r.reference.eyeDepth[i]);
                r.maxDepthError = std::max(r.maxDepthError, e);
                if (e > r.deltaS + kDepthSlack)
                    ++r.overOneSlice;
            } else if (hit != refHit(x, y)) {
                ++r.coverageDiffers;
                if (!test::atSilhouette(refHit, x, y, w, h))
                    ++r.coverageDiffersInside;
            }
        }
    std::printf("iso3d hits: deltaS %.4g, both hit %zu, max |dz| %.4g (%.3f deltaS), over deltaS %zu, coverage differs %zu "
                "(%zu not at a silhouette)\n",
                r.deltaS, r.bothHit, r.maxDepthError, r.maxDepthError / r.deltaS, r.overOneSlice, r.coverageDiffers,
                r.coverageDiffersInside);
    return r;
}

TEST(Iso3dOptions, Parses)
{
    EXPECT_EQ(parseIso3dOptions(json::object()).slices, 256);
    EXPECT_EQ(parseIso3dOptions(json{{"slices", 64}}).slices, 64);
    EXPECT_DOUBLE_EQ(parseIso3dOptions(json{{"slice_spacing", 0.01}}).sliceSpacing, 0.01);
    EXPECT_DOUBLE_EQ(parseIso3dOptions(json{{"gradientless_step", 0.05}}).gradientlessStep, 0.05);
    EXPECT_DOUBLE_EQ(parseIso3dOptions(json{{"gradientless_scale", 3.0}}).gradientlessScale, 3.0);
    Scene s = makeScene(parallelCamera(), 0.5);
    s.iso->shading = IsoSpec::Shading::Gradientless;
    EXPECT_EQ(isoSurface(s, *s.camera).shading, IsoSurface::Shading::Gradientless);
}

TEST(Iso3dOptions, RejectsBadValuesNamingTheKey)
{
    auto message = [](const json& o) {
        try {
            parseIso3dOptions(o);
        } catch (const InputError& e) {
            return std::string(e.what());
        }
        return std::string("no error");
    };
    EXPECT_EQ(message(json{{"slices", 0}}).rfind("options.slices: ", 0), 0u);
    EXPECT_EQ(message(json{{"slices", 1.5}}).rfind("options.slices: ", 0), 0u);
    EXPECT_EQ(message(json{{"slice_spacing", -1}}).rfind("options.slice_spacing: ", 0), 0u);
    EXPECT_EQ(message(json{{"slices", 8}, {"slice_spacing", 0.1}}).rfind("options.slice_spacing: ", 0), 0u);
    EXPECT_EQ(message(json{{"gradientless_step", 0}}).rfind("options.gradientless_step: ", 0), 0u);
    EXPECT_EQ(message(json{{"gradientless_scale", "x"}}).rfind("options.gradientless_scale: ", 0), 0u);
    EXPECT_EQ(message(json{{"order", "front-to-back"}}).rfind("options.order: unknown option", 0), 0u);
    EXPECT_EQ(message(json{{"path", "gpu"}}).rfind("options.path: ", 0), 0u);
    EXPECT_EQ(message(json{{"path", "fused"}, {"bricks", {2, 2, 2}}}).rfind("options.path: ", 0), 0u);
    EXPECT_EQ(message(json{{"path", "fused"}, {"interior", true}}).rfind("options.path: ", 0), 0u);
}

TEST(Iso3dOptions, PathIsFusedUnlessBricksOrInteriorNeedTheRasterStage)
{
    EXPECT_EQ(parseIso3dOptions(json::object()).path, Iso3dOptions::Path::Fused);
    EXPECT_EQ(parseIso3dOptions(json{{"path", "raster"}}).path, Iso3dOptions::Path::Raster);
    EXPECT_EQ(parseIso3dOptions(json{{"bricks", {2, 1, 1}}}).path, Iso3dOptions::Path::Raster);
    EXPECT_EQ(parseIso3dOptions(json{{"brick_budget", 1 << 20}}).path, Iso3dOptions::Path::Raster);
    EXPECT_EQ(parseIso3dOptions(json{{"interior", true}}).path, Iso3dOptions::Path::Raster);
    EXPECT_EQ(parseIso3dOptions(json{{"interior", false}}).path, Iso3dOptions::Path::Fused);
}

TEST(Iso3dOptions, RejectsMissingIso)
{
    Scene s = makeScene(parallelCamera(), 0.5);
    s.iso.reset();
    try {
        makeRenderer(test::device(), s, sphere33());
        ADD_FAILURE() << "no error";
    } catch (const InputError& e) {
        EXPECT_EQ(std::string(e.what()).rfind("iso: ", 0), 0u) << e.what();
    }
}

// The paper's CM applied to an encoded normal (0.5 N + 0.5, 1) gives (<L,N>, <L,N>, <L,N>, 1); with the
// material value in alpha it is off by (1 - alpha) <L, (1,1,1)>, which iso3d's transfer (the -1 in the bias)
// is not.
TEST(Iso3dColorMatrix, IsThePapersProductAndTheTransferIsExactForAnyAlpha)
{
    const glm::dvec3 light = glm::normalize(glm::dvec3(0.4, -0.6, 1.0));
    const glm::dvec3 normal = glm::normalize(glm::dvec3(-0.3, 0.8, 0.5));
    const glm::dmat3 r = glm::dmat3(glm::dvec3(0, 1, 0), glm::dvec3(-1, 0, 0), glm::dvec3(0, 0, 1));
    for (const glm::dmat3& rotation : {glm::dmat3(1.0), r}) {
        const double d = glm::dot(light, rotation * normal);
        const glm::dvec4 c = isoColorMatrix(light, rotation) * glm::dvec4(0.5 * normal + 0.5, 1.0);
        for (int k = 0; k < 3; ++k)
            EXPECT_NEAR(c[k], d, 1e-15);
        EXPECT_NEAR(c.w, 1.0, 1e-15);
        const glm::dvec4 off = isoColorMatrix(light, rotation) * glm::dvec4(0.5 * normal + 0.5, 0.3);
        EXPECT_NEAR(off.x, d + 0.7 * glm::dot(light, rotation * glm::dvec3(1.0)), 1e-15);

        IsoSurface iso;
        iso.light = light;
        iso.ambient = 0.15;
        iso.diffuse = 0.8;
        iso.color = {1.0, 0.5, 0.25};
        const raster::PixelTransfer xf = isoShadingTransfer(iso, rotation);
        const glm::vec4 p = xf.bias + xf.scale * (xf.colorMatrix * glm::vec4(glm::vec3(0.5 * normal + 0.5), 0.3f));
        for (int k = 0; k < 3; ++k)  // float matrix and vectors: a few ulp of 1
            EXPECT_NEAR(p[k], iso.color[k] * (0.8 * d + 0.15), 1e-6) << k;
        EXPECT_FLOAT_EQ(p.w, 0.3f);
    }
}

// A field linear in x is its own trilinear interpolant: the hit is where x reaches the iso-value.
TEST(IsoReference, FirstHitOnLinearFieldIsExact)
{
    Volume v;
    v.dims = {5, 4, 3};
    v.spacing = {0.5, 1.0, 2.0};
    v.origin = {-1.0, 0.0, 0.0};
    for (int k = 0; k < v.dims.z; ++k)
        for (int j = 0; j < v.dims.y; ++j)
            for (int i = 0; i < v.dims.x; ++i)
                v.values.push_back(static_cast<float>(-1.0 + 0.5 * i));  // = x
    const Ray ray{{-3.0, 1.3, 2.1}, glm::normalize(glm::dvec3(1.0, 0.1, 0.05))};
    const std::optional<double> t = firstIsoHit(v, ray, 0.3);
    ASSERT_TRUE(t);
    EXPECT_NEAR(ray.origin.x + *t * ray.direction.x, 0.3, 1e-12);
    // Entering above the iso-value: the hit is the entry into the box (x = -1 there, -1 >= -2).
    const std::optional<double> entry = firstIsoHit(v, ray, -2.0);
    ASSERT_TRUE(entry);
    EXPECT_NEAR(ray.origin.x + *entry * ray.direction.x, -1.0, 1e-12);
    EXPECT_FALSE(firstIsoHit(v, ray, 1.5));                          // above every value
    EXPECT_FALSE(firstIsoHit(v, Ray{{-3.0, 1.3, 2.1}, {-1, 0, 0}}, 0.3));  // misses the box
}

// A crossing inside one cell that the cell's end values do not show (the cubic rises above iso and falls
// back): bracketing per cell end alone would miss it, the turning points find it.
TEST(IsoReference, FindsCrossingBetweenCellEnds)
{
    Volume v;
    v.dims = {2, 2, 2};
    v.values = {0, 1, 1, 0, 1, 0, 0, 0};  // along the diagonal f(s, s, s) = 3 s (1 - s)^2: 0 at both ends, 4/9 at 1/3
    const Ray ray{{0.0, 0.0, 0.0}, glm::normalize(glm::dvec3(1.0, 1.0, 1.0))};
    const std::optional<double> t = firstIsoHit(v, ray, 0.4);
    ASSERT_TRUE(t);
    const double s = *t / std::sqrt(3.0);
    EXPECT_NEAR(*v.sample(glm::dvec3(s)), 0.4, 1e-12);
    EXPECT_LT(s, 1.0 / 3.0);  // the first of the two crossings
}

TEST(Iso3d, HitDepthWithinOneSliceSpacingPerspective)
{
    const HitComparison r = compareHits(makeScene(perspectiveCamera(), 0.5, {{"slices", 128}}), sphere33());
    ASSERT_GT(r.bothHit, 500u);
    // The first slice sample at or above iso lies at most one slice behind the crossing (the field rises
    // monotonically through the sphere's shell); float sampling adds ~1e-6.
    EXPECT_LE(r.maxDepthError, r.deltaS + kDepthSlack);
    EXPECT_EQ(r.overOneSlice, 0u);
    EXPECT_EQ(r.coverageDiffersInside, 0u);
    EXPECT_LE(r.coverageDiffers, 40u);  // measured 0; a grazing ray's chord shorter than a slice is missed
}

TEST(Iso3d, HitDepthWithinOneSliceSpacingParallel)
{
    const HitComparison r = compareHits(makeScene(parallelCamera(), 0.3, {{"slice_spacing", 0.02}}), sphere33());
    ASSERT_GT(r.bothHit, 500u);
    EXPECT_LE(r.maxDepthError, r.deltaS + kDepthSlack);
    EXPECT_EQ(r.overOneSlice, 0u);
    EXPECT_EQ(r.coverageDiffersInside, 0u);
    EXPECT_LE(r.coverageDiffers, 40u);
}

// Marschner-Lobb: thin ridges that slices can step over; misses are then a later hit (more than one slice
// behind) or no hit. Bounded, and falling as the slices get denser.
TEST(Iso3d, MarschnerLobbThinFeaturesBounded)
{
    const HitComparison coarse = compareHits(makeScene(perspectiveCamera(), 0.5, {{"slices", 64}}), marschnerLobb41());
    const HitComparison fine = compareHits(makeScene(perspectiveCamera(), 0.5, {{"slices", 512}}), marschnerLobb41());
    ASSERT_GT(fine.bothHit, 1000u);
    EXPECT_LE(fine.overOneSlice + fine.coverageDiffers, coarse.overOneSlice + coarse.coverageDiffers);
    EXPECT_LE(fine.overOneSlice, fine.bothHit / 50);
}

TEST(Iso3d, GradientShadingMatchesReference)
{
    for (const Camera& camera : {perspectiveCamera(), parallelCamera()}) {
        const HitComparison r = compareHits(makeScene(camera, 0.5, {{"slices", 256}}), sphere33());
        glm::dvec4 maxErr(0.0), sumErr(0.0);
        std::size_t n = 0;
        for (int y = 0; y < r.image.height(); ++y)
            for (int x = 0; x < r.image.width(); ++x) {
                const glm::vec4 a = r.image.at(x, y);
                const glm::dvec4 e = r.reference.image.at(x, y);
                if (a.w != 1.0f || e.w != 1.0)
                    continue;  // coverage is judged above
                const glm::dvec4 d = glm::abs(glm::dvec4(a) - e);
                maxErr = glm::max(maxErr, d);
                sumErr += d;
                ++n;
            }
        ASSERT_GT(n, 500u);
        const glm::dvec4 meanErr = sumErr / static_cast<double>(n);
        std::printf("iso3d gradient shading: max |diff| rgb %.4g %.4g %.4g, mean %.4g %.4g %.4g over %zu pixels\n",
                    maxErr.x, maxErr.y, maxErr.z, meanErr.x, meanErr.y, meanErr.z, n);
        for (int c = 0; c < 3; ++c) {
            EXPECT_LE(maxErr[c], 0.05) << "channel " << c;
            EXPECT_LE(meanErr[c], 0.01) << "channel " << c;
        }
    }
}

// Shading error against the reference over the pixels where both hit: max and mean per rgb channel.
struct ShadeError {
    glm::dvec3 maxAbs{0.0}, meanAbs{0.0};
    std::size_t pixels = 0;
};

ShadeError shadeError(const Image4f& image, const Image4d& reference)
{
    ShadeError r;
    glm::dvec3 sum(0.0);
    for (int y = 0; y < image.height(); ++y)
        for (int x = 0; x < image.width(); ++x) {
            const glm::vec4 a = image.at(x, y);
            const glm::dvec4 e = reference.at(x, y);
            if (a.w != 1.0f || e.w != 1.0)
                continue;
            const glm::dvec3 d = glm::abs(glm::dvec3(a) - glm::dvec3(e));
            r.maxAbs = glm::max(r.maxAbs, d);
            sum += d;
            ++r.pixels;
        }
    r.meanAbs = r.pixels ? sum / static_cast<double>(r.pixels) : sum;
    return r;
}

// Gradientless shading: forward differences of the value towards the light through the pixel texture.
// On "sphere" (1 - |p|, a distance field: |grad| = 1, the paper's condition) it approximates the same
// diffuse term; the error is the forward difference's (second order in Delta = the grid spacing 0.0625,
// about Delta/2 times the curvature 1/r = 2: ~0.06 at worst) plus the slice offset of the hit.
TEST(Iso3d, GradientlessShadingOnDistanceField)
{
    for (const Camera& camera : {perspectiveCamera(), parallelCamera()}) {
        // k = 1 / Delta, the paper's (unit gradient); Delta defaults to the grid spacing 2/32.
        Scene s = makeScene(camera, 0.5, {{"slices", 256}, {"gradientless_scale", 16.0}});
        s.iso->shading = IsoSpec::Shading::Gradientless;
        const HitComparison hits = compareHits(s, sphere33());
        Scene g = s;
        g.iso->shading = IsoSpec::Shading::Gradient;
        const IsoReference reference = isoReference(sphere33(), camera, s.image, isoSurface(g, *g.camera));
        const ShadeError e = shadeError(hits.image, reference.image);
        std::printf("iso3d gradientless shading: max |diff| rgb %.4g %.4g %.4g, mean %.4g %.4g %.4g over %zu pixels\n",
                    e.maxAbs.x, e.maxAbs.y, e.maxAbs.z, e.meanAbs.x, e.meanAbs.y, e.meanAbs.z, e.pixels);
        ASSERT_GT(e.pixels, 500u);  // hit depths are judged above; these are the same slices
        for (int c = 0; c < 3; ++c) {
            EXPECT_LE(e.maxAbs[c], 0.1) << "channel " << c;
            EXPECT_LE(e.meanAbs[c], 0.04) << "channel " << c;
        }
    }
}

// Where |grad| varies over the surface the difference is scaled by it: on Marschner-Lobb (|grad| from ~0 to
// ~20 per world unit) no one scale fits (default: the median at the surface), and the gradientless shade is
// wrong by far more than the gradient-shaded one. Stated, not hidden.
TEST(Iso3d, GradientlessShadingFailsWhereGradientIsNotUnit)
{
    Scene s = makeScene(perspectiveCamera(), 0.5, {{"slices", 256}});
    s.iso->shading = IsoSpec::Shading::Gradientless;
    const HitComparison lessHits = compareHits(s, marschnerLobb41());
    Scene g = s;
    g.iso->shading = IsoSpec::Shading::Gradient;
    const HitComparison gradHits = compareHits(g, marschnerLobb41());
    const ShadeError less = shadeError(lessHits.image, gradHits.reference.image);
    const ShadeError grad = shadeError(gradHits.image, gradHits.reference.image);
    std::printf("iso3d Marschner-Lobb mean |diff| red: gradientless %.4g, gradient %.4g\n", less.meanAbs.x,
                grad.meanAbs.x);
    // Measured 0.196 against 0.104 (the gradient-shaded error here is itself large: unit normals of a
    // 41^3 Marschner-Lobb vary fast between grid points, so interpolation shortens them a lot).
    EXPECT_GT(less.meanAbs.x, 1.5 * grad.meanAbs.x);
}

TEST(Iso3d, MedianGradientAtIsoOfDistanceFieldIsAboutOne)
{
    // 1 - |p| has |grad| = 1; the Sobel smoothing across the axes shortens it a little on a curved shell.
    EXPECT_NEAR(medianGradientAtIso(sphere33(), 0.5), 1.0, 0.05);
}

// |p| on [-1,1]^3: every box face is at or above 1, so with iso 0.6 the plain alpha test stops at the box
// entry everywhere (Figure 7, left); the multi-pass shows the sphere of radius 0.6 where the values fall
// below the iso-value (Figure 7, right). Its reference is the first hit of -|p| >= -0.6, whose normal
// +grad|p| is the one the interior pass shows.
Volume radiusVolume(float sign)
{
    Volume v;
    v.dims = {33, 33, 33};
    v.spacing = glm::dvec3(2.0 / 32.0);
    v.origin = glm::dvec3(-1.0);
    for (int k = 0; k < 33; ++k)
        for (int j = 0; j < 33; ++j)
            for (int i = 0; i < 33; ++i)
                v.values.push_back(sign * static_cast<float>(glm::length(v.origin + glm::dvec3(i, j, k) * v.spacing)));
    v.source = "radius";
    return v;
}

TEST(Iso3d, InteriorMultiPassFigure7)
{
    const Volume radius = radiusVolume(1.0f), negated = radiusVolume(-1.0f);
    for (const Camera& camera : {perspectiveCamera(), parallelCamera()}) {
        Scene s = makeScene(camera, 0.6, {{"slices", 256}});
        // Without the multi-pass: every pixel of the box is locked at its entry.
        {
            auto plain = makeIso3dRenderer(test::device(), s, radius);
            FrameStats stats;
            plain->render(stats);
            const std::vector<double> z = plain->hitDepth();
            std::size_t inner = 0, hits = 0;
            const IsoReference entry = isoReference(radius, camera, s.image, isoSurface(s, *s.camera));  // hits at the entry
            for (std::size_t i = 0; i < z.size(); ++i) {
                hits += std::isfinite(z[i]);
                if (std::isfinite(z[i]) && std::isfinite(entry.eyeDepth[i]))
                    inner += std::abs(z[i] - entry.eyeDepth[i]) <= plain->sliceSpacing() + kDepthSlack;
            }
            EXPECT_GT(hits, 1500u);
            // Every hit within a slice of the box entry, but for a few pixels on the box's silhouette (measured
            // 8 of 3950): the float inside test rejects a sample on the face, the next slice is taken.
            EXPECT_GE(inner + 20, hits);
        }
        s.options["interior"] = true;
        auto renderer = makeIso3dRenderer(test::device(), s, radius);
        FrameStats stats;
        const Image4f image = renderer->render(stats);
        const std::vector<double> z = renderer->hitDepth();
        IsoSurface inside = isoSurface(s, *s.camera);
        inside.value = -0.6;
        const IsoReference reference = isoReference(negated, camera, s.image, inside);
        std::size_t both = 0, over = 0, differ = 0;
        double maxErr = 0.0;
        for (std::size_t i = 0; i < z.size(); ++i) {
            const bool a = std::isfinite(z[i]), b = std::isfinite(reference.eyeDepth[i]);
            if (a && b) {
                ++both;
                const double e = std::abs(z[i] - reference.eyeDepth[i]);
                maxErr = std::max(maxErr, e);
                over += e > renderer->sliceSpacing() + kDepthSlack;
            } else if (a != b) {
                ++differ;
            }
        }
        const ShadeError e = shadeError(image, reference.image);
        std::printf("iso3d interior: both hit %zu, max |dz| %.3f deltaS, over %zu, coverage differs %zu; shading max %.4g "
                    "mean %.4g (red)\n",
                    both, maxErr / renderer->sliceSpacing(), over, differ, e.maxAbs.x, e.meanAbs.x);
        EXPECT_GT(both, 500u);
        EXPECT_LE(over, 5u);  // measured 2 (perspective, 1.03 deltaS): grazing rays, where float sample positions move the crossing
        EXPECT_LE(differ, 40u);  // silhouette pixels of the inner sphere (measured 0)
        EXPECT_LE(e.maxAbs.x, 0.05);
        EXPECT_LE(e.meanAbs.x, 0.01);
    }
}

TEST(Iso3d, BackgroundWhereNoHitAndIdenticalBits)
{
    Scene s = makeScene(perspectiveCamera(), 0.5, {{"slices", 64}});
    auto renderer = makeRenderer(test::device(), s, sphere33());
    FrameStats stats;
    const Image4f a = renderer->render(stats);
    const Image4f b = renderer->render(stats);
    ASSERT_EQ(a.pixels().size(), b.pixels().size());
    EXPECT_EQ(std::memcmp(a.pixels().data(), b.pixels().data(), a.pixels().size() * sizeof(glm::vec4)), 0);
    const glm::vec4 corner = a.at(0, 0);
    EXPECT_EQ(corner, glm::vec4(0.1f, 0.2f, 0.3f, 0.0f));
    // Above every value: nothing at all.
    s.iso->value = 1.5;
    const Image4f none = makeRenderer(test::device(), s, sphere33())->render(stats);
    for (const glm::vec4& p : none.pixels())
        ASSERT_EQ(p.w, 0.0f);
}

// ---- The fused path: the slice draws' frame buffer, per pixel in one kernel ----

struct FusedVsRaster {
    std::size_t hits = 0, coverageDiffers = 0, sliceDiffers = 0, colorOver = 0;  // colorOver: same slice, > 1e-4
    double maxColorDiff = 0.0;  // where both hit the same slice
    std::uint64_t fusedSamples = 0, rasterFragments = 0;
};

// The same scene on both paths. A pixel's hit is on the same slice when the eye depths agree within a tenth
// of a slice; there the final colors (after the shading passes, which both paths share) differ only by the
// rounding of the sample point (the draws interpolate world positions across the slice polygon, the
// fused kernel adds z d to the eye; the draws snap the polygons' vertices).
FusedVsRaster compareFused(const Scene& scene, const Volume& volume)
{
    Scene fusedScene = scene, rasterScene = scene;
    fusedScene.options["path"] = "fused";
    rasterScene.options["path"] = "raster";
    auto fused = makeIso3dRenderer(test::device(), fusedScene, volume);
    auto raster = makeIso3dRenderer(test::device(), rasterScene, volume);
    FrameStats fs, rs;
    const Image4f fi = fused->render(fs), ri = raster->render(rs);
    EXPECT_EQ(fs.extra["path"], "fused");
    EXPECT_EQ(rs.extra["path"], "raster");
    const std::vector<double> fz = fused->hitDepth(), rz = raster->hitDepth();
    const double deltaS = fused->sliceSpacing();
    FusedVsRaster r;
    r.fusedSamples = fs.samples;
    r.rasterFragments = rs.samples;
    for (std::size_t i = 0; i < fz.size(); ++i) {
        const bool fh = std::isfinite(fz[i]), rh = std::isfinite(rz[i]);
        r.hits += rh;
        if (fh != rh) {
            ++r.coverageDiffers;
            continue;
        }
        if (!fh) {
            EXPECT_EQ(fi.pixels()[i], ri.pixels()[i]) << "background pixel " << i;
            continue;
        }
        if (std::abs(fz[i] - rz[i]) > 0.1 * deltaS) {
            ++r.sliceDiffers;
            continue;
        }
        const glm::vec4 d = glm::abs(fi.pixels()[i] - ri.pixels()[i]);
        const double m = std::max({d.r, d.g, d.b, d.a});
        r.maxColorDiff = std::max(r.maxColorDiff, m);
        r.colorOver += m > 1e-4;
    }
    std::printf("iso3d fused vs raster: %zu hits, coverage differs %zu, other slice %zu, same slice max |color diff| "
                "%.3g (%zu over 1e-4); samples %llu fused, %llu raster fragments\n",
                r.hits, r.coverageDiffers, r.sliceDiffers, r.maxColorDiff, r.colorOver,
                static_cast<unsigned long long>(r.fusedSamples), static_cast<unsigned long long>(r.rasterFragments));
    return r;
}

void expectFusedLikeRaster(const FusedVsRaster& r, std::size_t minHits = 300)
{
    EXPECT_GT(r.hits, minHits);
    // A sample whose alpha lies within rounding of the reference can pass on one path and not on the other:
    // then the pixel shows the next slice (or, at a silhouette, nothing). A handful, not a pattern.
    EXPECT_LE(r.coverageDiffers, r.hits / 200 + 2);
    EXPECT_LE(r.sliceDiffers, r.hits / 200 + 2);
    // On the same slice the sample points differ by the rasterizer's vertex snapping (1/256 pixel,
    // docs/raster.md): nothing on the sphere's smooth normals (< 1e-4), up to 1.2e-3 on Marschner–Lobb's
    // (a 64² image of a 41³ grid: about a voxel per pixel).
    EXPECT_LE(r.maxColorDiff, 2e-3);
    // The fused kernel stops at the first hit: fewer samples than the draws' fragments.
    EXPECT_LT(r.fusedSamples, r.rasterFragments);
}

TEST(Iso3dFused, LeavesTheSliceDrawsFrameBufferOnTheSphere)
{
    for (const Camera& camera : {perspectiveCamera(), parallelCamera(), insideCamera()})
        for (const char* shading : {"gradient", "none", "gradientless"}) {
            SCOPED_TRACE(shading);
            Scene s = makeScene(camera, 0.5, {{"slices", 96}});
            s.iso->shading = test::shadingNamed(shading);
            expectFusedLikeRaster(compareFused(s, sphere33()));
        }
}

TEST(Iso3dFused, LeavesTheSliceDrawsFrameBufferOnMarschnerLobb)
{
    for (const Camera& camera : {perspectiveCamera(), parallelCamera()})
        expectFusedLikeRaster(compareFused(makeScene(camera, 0.5, {{"slices", 128}}), marschnerLobb41()));
}

// Empty-space skipping steps over bricks whose values all lie below the iso-value: the same frame, bit for
// bit, with fewer samples.
TEST(Iso3dFused, EmptySpaceSkippingLeavesTheSameBits)
{
    struct Case {
        const Volume* volume;
        Camera camera;
    };
    for (const Case& c : {Case{&sphere33(), perspectiveCamera()}, Case{&sphere33(), insideCamera()},
                          Case{&marschnerLobb41(), parallelCamera()}}) {
        Scene on = makeScene(c.camera, 0.5, {{"slices", 128}}), off = on;
        off.options["empty_space_skipping"] = false;
        FrameStats son, soff;
        auto ron = makeIso3dRenderer(test::device(), on, *c.volume);
        const Image4f ion = ron->render(son);
        const Image4f ioff = makeIso3dRenderer(test::device(), off, *c.volume)->render(soff);
        EXPECT_TRUE(son.extra["empty_space_skipping"].get<bool>());
        EXPECT_FALSE(soff.extra["empty_space_skipping"].get<bool>());
        EXPECT_GT(son.extra["empty_bricks"].get<std::uint64_t>(), 0u);
        ASSERT_EQ(ion.pixels().size(), ioff.pixels().size());
        EXPECT_EQ(std::memcmp(ion.pixels().data(), ioff.pixels().data(), ion.pixels().size() * sizeof(glm::vec4)), 0);
        EXPECT_LT(son.samples, soff.samples);
        std::printf("iso3d empty-space skipping: %llu empty bricks, samples %llu -> %llu\n",
                    static_cast<unsigned long long>(son.extra["empty_bricks"].get<std::uint64_t>()),
                    static_cast<unsigned long long>(soff.samples), static_cast<unsigned long long>(son.samples));
    }
}

TEST(Iso3dFused, HitsWithinOneSliceOfTheExactFirstHit)
{
    for (const Camera& camera : {perspectiveCamera(), parallelCamera()}) {
        const HitComparison r = compareHits(makeScene(camera, 0.5, {{"slices", 128}, {"path", "fused"}}), sphere33());
        ASSERT_GT(r.bothHit, 500u);
        EXPECT_LE(r.maxDepthError, r.deltaS + kDepthSlack);
        EXPECT_EQ(r.overOneSlice, 0u);
        EXPECT_EQ(r.coverageDiffersInside, 0u);
    }
}

// ---- Bricking (§3.1) ----

TEST(Iso3dBricking, GridSharesFacePointsAndFitsTheBudget)
{
    const glm::ivec3 dims(33, 33, 33);
    // 17^3 grid points x 16 bytes: exactly 2x2x2 bricks of 16 cells (+ the shared face).
    const MemoryBricks g = planBricks(dims, 16, 17ull * 17 * 17 * 16);
    EXPECT_EQ(g.counts, glm::ivec3(2, 2, 2));
    EXPECT_EQ(g.maxBytes(), 17ull * 17 * 17 * 16);
    EXPECT_EQ(g.lo({1, 0, 0}).x, 16);
    EXPECT_EQ(g.hi({0, 0, 0}).x, 16) << "neighbours share the face's grid points";
    EXPECT_EQ(g.hi({1, 1, 1}), glm::ivec3(32));
    // One byte less: more bricks, each fitting.
    const MemoryBricks h = planBricks(dims, 16, 17ull * 17 * 17 * 16 - 1);
    EXPECT_GT(h.count(), 8);
    EXPECT_LE(h.maxBytes(), 17ull * 17 * 17 * 16 - 1);
    // The whole volume fits: one brick.
    EXPECT_EQ(planBricks(dims, 16, 33ull * 33 * 33 * 16).count(), 1);
    // The smallest brick: 2x2x2 points; everything split into single cells.
    const MemoryBricks tiny = planBricks({5, 4, 3}, 16, 128);
    EXPECT_EQ(tiny.counts, glm::ivec3(4, 3, 2));
    EXPECT_EQ(tiny.maxBytes(), 128u);
    // 3x2x5 on 41^3: slabs of 13 or 14 cells along x, every cell in exactly one slab.
    const MemoryBricks f = splitBricks({41, 41, 41}, {3, 2, 5}, 16);
    EXPECT_EQ(f.starts[0], (std::vector<int>{0, 13, 26, 40}));
    EXPECT_EQ(f.starts[2], (std::vector<int>{0, 8, 16, 24, 32, 40}));
    EXPECT_EQ(f.maxBytes(), 15ull * 21 * 9 * 16);
}

TEST(Iso3dBricking, BadBudgetsAndCombinationsNameTheOption)
{
    auto message = [](const json& options, const std::string& shading = "gradient") {
        Scene s = makeScene(perspectiveCamera(), 0.5, options);
        s.iso->shading = test::shadingNamed(shading);
        try {
            makeIso3dRenderer(test::device(), s, sphere33());
        } catch (const InputError& e) {
            return std::string(e.what());
        }
        return std::string("no error");
    };
    EXPECT_EQ(message({{"brick_budget", 100}}),
              "options.brick_budget: 100 bytes is less than the smallest brick, 2x2x2 grid points x 16 bytes = 128 bytes");
    EXPECT_EQ(message({{"brick_budget", 0}}).rfind("options.brick_budget: must be a positive integer", 0), 0u);
    EXPECT_EQ(message({{"brick_budget", 1.5}}).rfind("options.brick_budget: must be a positive integer", 0), 0u);
    EXPECT_EQ(message({{"bricks", {2, 2}}}).rfind("options.bricks: must be [nx, ny, nz]", 0), 0u);
    EXPECT_EQ(message({{"bricks", {2, 33, 1}}}),
              "options.bricks: axis 1 has 32 cells, so from 1 to 32 bricks, got 33");
    EXPECT_EQ(message({{"bricks", {2, 2, 2}}, {"brick_budget", 100000}}),
              "options.bricks: give either brick_budget or bricks, not both");
    EXPECT_EQ(message({{"bricks", {2, 1, 1}}}, "gradientless").rfind("options.bricks: gives 2x1x1 bricks, and bricking "
                                                                     "works with iso.shading \"gradient\" or \"none\" only",
                                                                     0),
              0u);
    EXPECT_EQ(message({{"brick_budget", 100000}, {"interior", true}}).rfind("options.brick_budget: gives 2x2x2 bricks", 0), 0u);
    // Budgets that hold the whole volume are no bricking at all, so those combinations work.
    EXPECT_EQ(message({{"brick_budget", 33 * 33 * 33 * 20}}, "gradientless"), "no error");
    EXPECT_EQ(message({{"bricks", {1, 1, 1}}, {"interior", true}}), "no error");
}

// Every pixel-center ray from the eye, stepped finely: the bricks it passes must come in brickOrder's order.
std::size_t orderViolations(const MemoryBricks& grid, const Camera& camera, const Volume& v)
{
    const std::vector<glm::ivec3> order = brickOrder(grid, camera, v.origin, v.spacing);
    std::vector<int> rank(static_cast<std::size_t>(grid.count()));
    for (std::size_t i = 0; i < order.size(); ++i)
        rank[static_cast<std::size_t>(order[i].x + grid.counts.x * (order[i].y + grid.counts.y * order[i].z))] =
            static_cast<int>(i);
    const PixelRays rays(camera, 24, 24);
    std::size_t violations = 0;
    for (int y = 0; y < 24; ++y)
        for (int x = 0; x < 24; ++x) {
            const Ray r = rays.at(x, y);
            int last = -1;
            for (double t = 0.0; t < 8.0; t += 1e-3) {
                const glm::dvec3 g = (r.origin + t * r.direction - v.origin) / v.spacing;
                glm::ivec3 b;
                bool inside = true;
                for (int a = 0; a < 3; ++a) {
                    if (g[a] < 0.0 || g[a] > v.dims[a] - 1) {
                        inside = false;
                        break;
                    }
                    b[a] = 0;
                    while (b[a] + 1 < grid.counts[a] && g[a] >= grid.starts[a][b[a] + 1])
                        ++b[a];
                }
                if (!inside)
                    continue;
                const int k = rank[static_cast<std::size_t>(b.x + grid.counts.x * (b.y + grid.counts.y * b.z))];
                if (k < last)
                    ++violations;
                last = std::max(last, k);
            }
        }
    return violations;
}

TEST(Iso3dBricking, OrderIsFrontToBackForEveryRay)
{
    const Volume& v = marschnerLobb41();
    const MemoryBricks grid = splitBricks(v.dims, {3, 2, 5}, 16);
    EXPECT_EQ(orderViolations(grid, perspectiveCamera(), v), 0u);
    EXPECT_EQ(orderViolations(grid, parallelCamera(), v), 0u);
    EXPECT_EQ(orderViolations(grid, insideCamera(), v), 0u);
    // A camera close above a flat grid of 8x1x8 bricks, looking across it.
    Camera near;
    near.position = {0.9, 0.95, 1.3};
    near.focalPoint = {0.9, -1.0, -1.0};
    near.viewAngle = 90.0;
    EXPECT_EQ(orderViolations(splitBricks(v.dims, {8, 1, 8}, 16), near, v), 0u);
}

struct BrickedVsUnbricked {
    std::size_t pixels = 0, colorDiffers = 0, depthDiffers = 0, coverageDiffers = 0, hits = 0;
    nlohmann::json stats;
};

BrickedVsUnbricked compareBricked(const Camera& camera, const Volume& volume, const json& bricking,
                                  const std::string& shading = "gradient", int slices = 96)
{
    json plain = {{"slices", slices}, {"path", "raster"}};  // bricking is a raster-path pass: compare like with like
    json bricked = plain;
    bricked.update(bricking);
    Scene a = makeScene(camera, 0.5, plain), b = makeScene(camera, 0.5, bricked);
    a.iso->shading = test::shadingNamed(shading);
    b.iso->shading = test::shadingNamed(shading);
    auto ra = makeIso3dRenderer(test::device(), a, volume);
    auto rb = makeIso3dRenderer(test::device(), b, volume);
    FrameStats sa, sb;
    const Image4f ia = ra->render(sa), ib = rb->render(sb);
    const std::vector<double> za = ra->hitDepth(), zb = rb->hitDepth();
    BrickedVsUnbricked r;
    r.stats = sb.extra;
    r.pixels = za.size();
    for (std::size_t i = 0; i < za.size(); ++i) {
        const bool ha = std::isfinite(za[i]), hb = std::isfinite(zb[i]);
        r.hits += ha;
        r.coverageDiffers += ha != hb;
        r.depthDiffers += ha && hb && za[i] != zb[i];
        r.colorDiffers += std::memcmp(&ia.pixels()[i], &ib.pixels()[i], sizeof(glm::vec4)) != 0;
    }
    std::printf("iso3d bricked %s vs unbricked: %d bricks, %zu hits, coverage differs %zu, depth differs %zu, "
                "color differs %zu (of %zu)\n",
                bricking.dump().c_str(), sb.extra["bricks"].get<int>(), r.hits, r.coverageDiffers, r.depthDiffers,
                r.colorDiffers, r.pixels);
    return r;
}

void expectIdentical(const BrickedVsUnbricked& r, std::size_t minHits = 300)
{
    EXPECT_GT(r.hits, minHits);
    EXPECT_EQ(r.coverageDiffers, 0u);
    EXPECT_EQ(r.depthDiffers, 0u);
    EXPECT_EQ(r.colorDiffers, 0u);
}

TEST(Iso3dBricking, IdenticalToUnbrickedOnSpherePerspectiveAndParallel)
{
    for (const Camera& camera : {perspectiveCamera(), parallelCamera()}) {
        const BrickedVsUnbricked r8 = compareBricked(camera, sphere33(), {{"brick_budget", 17 * 17 * 17 * 16}});
        EXPECT_EQ(r8.stats["bricks"], 8);
        EXPECT_EQ(r8.stats["brick_bytes"], 17 * 17 * 17 * 16);
        EXPECT_EQ(r8.stats["resident_bytes"], 17 * 17 * 17 * 16);
        EXPECT_EQ(r8.stats["brick_uploads"], 8);
        expectIdentical(r8);
        const BrickedVsUnbricked r30 = compareBricked(camera, sphere33(), {{"bricks", {3, 2, 5}}});
        EXPECT_EQ(r30.stats["bricks"], 30);
        expectIdentical(r30);
        const BrickedVsUnbricked r1 = compareBricked(camera, sphere33(), {{"brick_budget", 1 << 30}});
        EXPECT_EQ(r1.stats["bricks"], 1);
        EXPECT_EQ(r1.stats["brick_uploads"], 0);
        expectIdentical(r1);
    }
}

TEST(Iso3dBricking, IdenticalToUnbrickedOnMarschnerLobb)
{
    expectIdentical(compareBricked(perspectiveCamera(), marschnerLobb41(), {{"bricks", {3, 2, 5}}}, "gradient", 128));
    expectIdentical(compareBricked(parallelCamera(), marschnerLobb41(), {{"brick_budget", 21 * 21 * 21 * 16}}, "none", 128));
}

TEST(Iso3dBricking, IdenticalWithTheCameraInsideTheBrickGrid)
{
    expectIdentical(compareBricked(insideCamera(), sphere33(), {{"bricks", {3, 2, 5}}}));
    expectIdentical(compareBricked(insideCamera(), marschnerLobb41(), {{"bricks", {2, 2, 2}}}, "gradient", 128));
}

TEST(Iso3dBricking, BrickedHitsWithinOneSliceOfTheExactFirstHit)
{
    // The bricked render against the exact reference directly (not only against the unbricked render).
    const HitComparison r = compareHits(makeScene(perspectiveCamera(), 0.5, {{"slices", 128}, {"bricks", {2, 3, 2}}}),
                                        sphere33());
    ASSERT_GT(r.bothHit, 500u);
    EXPECT_LE(r.maxDepthError, r.deltaS + kDepthSlack);
    EXPECT_EQ(r.overOneSlice, 0u);
    EXPECT_EQ(r.coverageDiffersInside, 0u);
}

// The default light (no "iso.light") is the headlight, -forward, in iso3d and stack2d alike: the same
// bits as that light given explicitly, and not world +z (iso3d's old default).
TEST(Iso3dHeadlight, Iso3dAndStack2dShareTheHeadlightDefault)
{
    for (const char* name : {"iso3d", "stack2d"}) {
        SCOPED_TRACE(name);
        Scene unlit = makeScene(perspectiveCamera(), 0.5);
        unlit.technique = name;
        unlit.iso->light.reset();
        Scene headlight = unlit, fromZ = unlit;
        headlight.iso->light = -unlit.camera->forward();
        fromZ.iso->light = glm::dvec3(0.0, 0.0, 1.0);
        FrameStats stats;
        const Image4f a = makeRenderer(test::device(), unlit, sphere33())->render(stats);
        const Image4f b = makeRenderer(test::device(), headlight, sphere33())->render(stats);
        const Image4f c = makeRenderer(test::device(), fromZ, sphere33())->render(stats);
        EXPECT_TRUE(a.pixels() == b.pixels());
        EXPECT_FALSE(a.pixels() == c.pixels());
    }
}

// data/scenes/headsq.json as iso3d at the skin (1150) without a light, 96x96, 128 slices: world +z (the
// old default) lit the skin from behind as this camera sees it, covered pixels (18 % of the image) averaged
// 0.11 in (r + g + b) / 3; the headlight gives 0.45. The bound sits between the two.
constexpr double kHeadsqMinLuminance = 0.3;

TEST(Iso3dHeadlight, HeadsqSkinIsLitWithoutALight)
{
    const Scene scene = loadScene(test::repoData("scenes/headsq.json"),
                                  {"technique=iso3d", "iso.value=1150", "image.width=96", "image.height=96",
                                   "options.slices=128"});
    const Volume volume = loadVolume(*scene.volume);
    FrameStats stats;
    const Image4f image = makeRenderer(test::device(), scene, volume)->render(stats);
    std::size_t covered = 0;
    double luminance = 0.0;
    for (const glm::vec4& p : image.pixels()) {
        if (p.a <= 0.0f)
            continue;
        ++covered;
        luminance += (p.r + p.g + p.b) / 3.0;
    }
    ASSERT_GT(covered, image.pixelCount() / 10) << "the head covers too little of the image";
    EXPECT_GT(luminance / covered, kHeadsqMinLuminance) << "covered pixels are nearly black";
}

// Renderer::setCamera: pointed at new cameras (perspective, parallel, inside the box) the renderer plans its
// slices again and turns the headlight with the view, and renders the bits a new renderer renders — the fused
// walk, the slice draws, bricks, gradientless shading's shifted lookup —; a wider image it refuses.
TEST(Iso3d, SetCameraEqualsANewRenderer)
{
    const std::vector<Camera> cameras = {perspectiveCamera(), parallelCamera(), insideCamera()};
    const json sets[] = {{{"slices", 96}}, {{"slices", 96}, {"path", "raster"}}, {{"slices", 64}, {"bricks", {2, 1, 2}}}};
    for (const json& options : sets)
        for (const IsoSpec::Shading shading : {IsoSpec::Shading::Gradient, IsoSpec::Shading::Gradientless}) {
            if (options.contains("bricks") && shading == IsoSpec::Shading::Gradientless)
                continue;  // refused: gradientless shading's lookup leaves the brick
            Scene scene = makeScene(cameras[0], 0.5, options);
            scene.image.width = scene.image.height = 37;
            scene.iso->light.reset();  // the headlight: it turns with the camera
            scene.iso->shading = shading;
            test::expectSetCameraEqualsNewRenderer(scene, sphere33(), cameras,
                                                   options.dump() + (shading == IsoSpec::Shading::Gradient ? " gradient"
                                                                                                           : " gradientless"));
        }
}

}  // namespace
}  // namespace clvr
