// tests/reference_integral_test.cpp — the CPU reference integral against closed forms: constant
// media (I = C (1 - exp(-tau L))), a linear ramp of extinction (A = 1 - exp(-∫tau)), background
// compositing and empty volumes, for perspective and parallel cameras.
#include "host/reference/reference_integral.h"

#include "tests/support/test_util.h"

#include <cmath>

namespace clvr {
namespace {

// A volume of dims n^3 over the box [lo, hi] whose value at grid point (i, j, k) is f(world position).
template <typename F>
Volume makeVolume(glm::ivec3 dims, glm::dvec3 lo, glm::dvec3 hi, F f)
{
    Volume v;
    v.dims = dims;
    v.origin = lo;
    v.spacing = (hi - lo) / glm::dvec3(dims - 1);
    v.source = "test volume";
    v.values.resize(v.voxelCount());
    for (int k = 0; k < dims.z; ++k)
        for (int j = 0; j < dims.y; ++j)
            for (int i = 0; i < dims.x; ++i)
                v.values[(static_cast<std::size_t>(k) * dims.y + j) * dims.x + i] =
                    static_cast<float>(f(v.origin + glm::dvec3(i, j, k) * v.spacing));
    return v;
}

TransferFunction constantTf(glm::dvec3 color, double tau)
{
    return TransferFunction({{0.0, color, tau}, {1.0, color, tau}});
}

// Entry and exit of a ray through an axis-aligned box, found by bisection on the inside test
// (independent of clipRayToBox's slab arithmetic). Coarse scan for the first inside point.
bool chordByBisection(const Ray& ray, glm::dvec3 lo, glm::dvec3 hi, double& tIn, double& tOut)
{
    auto inside = [&](double t) {
        const glm::dvec3 p = ray.origin + t * ray.direction;
        return glm::all(glm::greaterThanEqual(p, lo)) && glm::all(glm::lessThanEqual(p, hi));
    };
    const double tMax = 100.0, dt = 1e-3;
    double t = 0.0;
    if (!inside(0.0)) {
        while (t < tMax && !inside(t))
            t += dt;
        if (t >= tMax)
            return false;
        double a = t - dt, b = t;  // a outside, b inside
        for (int i = 0; i < 100; ++i) {
            const double m = 0.5 * (a + b);
            (inside(m) ? b : a) = m;
        }
        tIn = b;
    } else {
        tIn = 0.0;
    }
    double a = tIn, b = tIn;
    while (inside(b + dt))
        b += dt;
    a = b;  // inside
    b = b + dt;  // outside
    for (int i = 0; i < 100; ++i) {
        const double m = 0.5 * (a + b);
        (inside(m) ? a : b) = m;
    }
    tOut = a;
    return true;
}

Camera perspectiveCamera()
{
    Camera c;
    c.position = {1.3, 0.9, 3.1};  // oblique: rays leave through side faces too
    c.focalPoint = {0.05, -0.1, 0.0};
    c.viewUp = {0.0, 1.0, 0.0};
    c.viewAngle = 40.0;
    return c;
}

Camera parallelCamera()
{
    Camera c;
    c.position = {0.2, -0.1, 5.0};
    c.focalPoint = {0.2, -0.1, 0.0};
    c.parallel = true;
    c.parallelScale = 1.3;
    return c;
}

void checkConstantMedium(const Camera& camera)
{
    const glm::dvec3 lo(-1.0, -0.8, -0.6), hi(0.9, 1.0, 0.7);
    const Volume v = makeVolume({5, 6, 7}, lo, hi, [](glm::dvec3) { return 0.5; });
    const glm::dvec3 color(0.9, 0.5, 0.2);
    const double tau = 1.7;
    ImageSpec spec{48, 40, {0.1, 0.2, 0.3}};
    const Image4d img = referenceIntegral(v, constantTf(color, tau), camera, spec);
    int hits = 0;
    double worst = 0.0;
    for (int y = 0; y < spec.height; ++y)
        for (int x = 0; x < spec.width; ++x) {
            const Ray ray = camera.ray(x, y, spec.width, spec.height);
            double t0 = 0, t1 = 0;
            double length = 0.0;
            if (chordByBisection(ray, lo, hi, t0, t1)) {
                length = t1 - t0;
                ++hits;
            }
            const double a = 1.0 - std::exp(-tau * length);
            const glm::dvec4 want(color * a + (1.0 - a) * spec.background, a);
            const glm::dvec4 d = glm::abs(img.at(x, y) - want);
            worst = std::max({worst, d.r, d.g, d.b, d.a});
        }
    EXPECT_GT(hits, spec.width * spec.height / 8);
    EXPECT_LT(hits, spec.width * spec.height);  // some background pixels too
    EXPECT_LT(worst, 1e-6);
}

TEST(ReferenceIntegral, ConstantMediumPerspectiveMatchesChordFormula) { checkConstantMedium(perspectiveCamera()); }

TEST(ReferenceIntegral, ConstantMediumParallelMatchesChordFormula) { checkConstantMedium(parallelCamera()); }

// tau(s) = tauMax * s with s linear in world position: ∫tau along a chord is tauMax * L * (s_in + s_out) / 2,
// and with a constant color I = C A, A = 1 - exp(-∫tau). The midpoint rule is not exact here (the
// transmittance is a curved function along the ray), so this checks convergence to the tolerance.
void checkLinearRamp(const Camera& camera)
{
    const glm::dvec3 lo(-1.0), hi(1.0);
    auto field = [](glm::dvec3 p) { return 0.5 + 0.2 * p.x - 0.15 * p.y + 0.1 * p.z; };  // trilinear-exact
    const Volume v = makeVolume({9, 9, 9}, lo, hi, field);
    const glm::dvec3 color(0.3, 0.8, 1.0);
    const double tauMax = 3.0;
    const TransferFunction tf({{0.0, color, 0.0}, {1.0, color, tauMax}});
    ImageSpec spec{40, 40, {0.0, 0.0, 0.0}};
    ReferenceStats stats;
    ReferenceOptions options;
    options.stats = &stats;
    const Image4d img = referenceIntegral(v, tf, camera, spec, options);
    double worst = 0.0;
    for (int y = 0; y < spec.height; ++y)
        for (int x = 0; x < spec.width; ++x) {
            const Ray ray = camera.ray(x, y, spec.width, spec.height);
            double t0 = 0, t1 = 0, opticalDepth = 0.0;
            if (chordByBisection(ray, lo, hi, t0, t1))
                opticalDepth = tauMax * (t1 - t0) *
                               0.5 * (field(ray.origin + t0 * ray.direction) + field(ray.origin + t1 * ray.direction));
            const double a = 1.0 - std::exp(-opticalDepth);
            const glm::dvec4 d = glm::abs(img.at(x, y) - glm::dvec4(color * a, a));
            worst = std::max({worst, d.r, d.g, d.b, d.a});
        }
    EXPECT_LT(worst, 1e-6);
    EXPECT_EQ(stats.raysNotConverged, 0u);
    EXPECT_LT(stats.maxResidual, options.tolerance);
    EXPECT_GT(stats.rays, 0u);
}

TEST(ReferenceIntegral, LinearRampPerspectiveConverges) { checkLinearRamp(perspectiveCamera()); }

TEST(ReferenceIntegral, LinearRampParallelConverges) { checkLinearRamp(parallelCamera()); }

// ReferenceOptions::intervals (clipping): only the given pieces of the chord count. A constant
// medium over the first and last thirds of each chord gives A = 1 - exp(-tau 2L/3) and I = C A
// (the pieces composited front to back); no pieces give the background exactly.
TEST(ReferenceIntegral, IntervalsIntegrateOnlyTheirPieces)
{
    const glm::dvec3 lo(-1.0, -0.8, -0.6), hi(0.9, 1.0, 0.7);
    const Volume v = makeVolume({5, 6, 7}, lo, hi, [](glm::dvec3) { return 0.5; });
    const glm::dvec3 color(0.9, 0.5, 0.2);
    const double tau = 1.7;
    const ImageSpec spec{32, 24, {0.1, 0.2, 0.3}};
    const Camera camera = perspectiveCamera();
    ReferenceOptions options;
    options.intervals = [](const Ray&, double t0, double t1) {
        const double third = (t1 - t0) / 3.0;
        return std::vector<glm::dvec2>{{t0, t0 + third}, {t1 - third, t1}};
    };
    const Image4d img = referenceIntegral(v, constantTf(color, tau), camera, spec, options);
    double worst = 0.0;
    int hits = 0;
    for (int y = 0; y < spec.height; ++y)
        for (int x = 0; x < spec.width; ++x) {
            const Ray ray = camera.ray(x, y, spec.width, spec.height);
            double t0 = 0, t1 = 0, length = 0.0;
            if (chordByBisection(ray, lo, hi, t0, t1)) {
                length = 2.0 * (t1 - t0) / 3.0;
                ++hits;
            }
            const double a = 1.0 - std::exp(-tau * length);
            const glm::dvec4 d = glm::abs(img.at(x, y) - glm::dvec4(color * a + (1.0 - a) * spec.background, a));
            worst = std::max({worst, d.r, d.g, d.b, d.a});
        }
    EXPECT_GT(hits, spec.width * spec.height / 8);
    EXPECT_LT(worst, 1e-6);
    options.intervals = [](const Ray&, double, double) { return std::vector<glm::dvec2>{}; };
    const Image4d none = referenceIntegral(v, constantTf(color, tau), camera, spec, options);  // kept alive
    for (const glm::dvec4& p : none.pixels())
        ASSERT_EQ(p, glm::dvec4(spec.background, 0.0));
}

TEST(ReferenceIntegral, EmptyVolumeGivesBackgroundExactly)
{
    const Volume v = makeVolume({4, 4, 4}, glm::dvec3(-1.0), glm::dvec3(1.0), [](glm::dvec3 p) { return p.x; });
    const ImageSpec spec{32, 24, {0.25, 0.5, 0.75}};
    for (const Camera& camera : {perspectiveCamera(), parallelCamera()}) {
        const Image4d img = referenceIntegral(v, constantTf({1.0, 1.0, 1.0}, 0.0), camera, spec);
        for (const glm::dvec4& p : img.pixels())
            ASSERT_EQ(p, glm::dvec4(spec.background, 0.0));
    }
}

TEST(ReferenceIntegral, OpaqueMediumHidesBackground)
{
    // tau L >= 100 * 0.5: A = 1 - exp(-50) ~ 1; the integration stops once the transmittance is below
    // tolerance * 1e-3 = 1e-9, so A is within 1e-9 of 1 and rgb within 1e-9 of C.
    const Volume v = makeVolume({3, 3, 3}, glm::dvec3(-1.0), glm::dvec3(1.0), [](glm::dvec3) { return 0.5; });
    const ImageSpec spec{16, 16, {1.0, 0.0, 1.0}};
    Camera camera = parallelCamera();
    camera.parallelScale = 0.5;  // every ray hits the box through its front face
    const Image4d img = referenceIntegral(v, constantTf({0.2, 0.4, 0.6}, 100.0), camera, spec);
    for (const glm::dvec4& p : img.pixels()) {
        EXPECT_NEAR(p.r, 0.2, 1e-9);
        EXPECT_NEAR(p.g, 0.4, 1e-9);
        EXPECT_NEAR(p.b, 0.6, 1e-9);
        EXPECT_NEAR(p.a, 1.0, 1e-9);
    }
}

TEST(ReferenceIntegral, ClipRayToBox)
{
    const Ray ray{{0.0, 0.0, 5.0}, {0.0, 0.0, -1.0}};
    double t0, t1;
    ASSERT_TRUE(clipRayToBox(ray, glm::dvec3(-1.0), glm::dvec3(1.0), 0.0, t0, t1));
    EXPECT_DOUBLE_EQ(t0, 4.0);
    EXPECT_DOUBLE_EQ(t1, 6.0);
    EXPECT_FALSE(clipRayToBox({{2.0, 0.0, 5.0}, {0.0, 0.0, -1.0}}, glm::dvec3(-1.0), glm::dvec3(1.0), 0.0, t0, t1));
    EXPECT_FALSE(clipRayToBox({{0.0, 0.0, 5.0}, {0.0, 0.0, 1.0}}, glm::dvec3(-1.0), glm::dvec3(1.0), 0.0, t0, t1));
    // From inside: starts at tMin.
    ASSERT_TRUE(clipRayToBox({{0.0, 0.0, 0.5}, {0.0, 0.0, -1.0}}, glm::dvec3(-1.0), glm::dvec3(1.0), 0.0, t0, t1));
    EXPECT_DOUBLE_EQ(t0, 0.0);
    EXPECT_DOUBLE_EQ(t1, 1.5);
}

}  // namespace
}  // namespace clvr
