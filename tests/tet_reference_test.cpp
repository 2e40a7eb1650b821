// tests/tet_reference_test.cpp — the exact tetrahedral reference against independent truths: psi and
// zeta against adaptive long-double quadrature; a constant tetrahedron against C (1 - exp(-tau L));
// linear fields on split cubes and perturbed grids against a fine RK4 of the same ray; transfer-function
// split invariance; non-convex meshes (gap composition); background; camera placement; speed printout.
#include "host/reference/tet_reference.h"

#include "host/reference/reference_integral.h"
#include "tests/support/test_util.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <functional>
#include <numbers>

namespace clvr {
namespace {

using Real = long double;

// ---- independent truths -----------------------------------------------------------------------------

// Gauss-Legendre nodes and weights on [-1, 1] by Newton on P_n, in long double.
struct GaussLegendre {
    std::vector<Real> x, w;
    explicit GaussLegendre(int n)
    {
        for (int i = 0; i < n; ++i) {
            Real z = std::cos(std::numbers::pi_v<Real> * (i + 0.75L) / (n + 0.5L)), dp = 0.0L;
            for (int it = 0; it < 100; ++it) {
                Real p0 = 1.0L, p1 = z;
                for (int k = 2; k <= n; ++k) {
                    const Real p2 = ((2 * k - 1) * z * p1 - (k - 1) * p0) / k;
                    p0 = p1;
                    p1 = p2;
                }
                dp = n * (z * p1 - p0) / (z * z - 1.0L);
                const Real dz = p1 / dp;
                z -= dz;
                if (std::fabs(dz) < 1e-21L)
                    break;
            }
            x.push_back(z);
            w.push_back(2.0L / ((1.0L - z * z) * dp * dp));
        }
    }
    Real operator()(const std::function<Real(Real)>& f, Real lo, Real hi) const
    {
        const Real c = 0.5L * (lo + hi), h = 0.5L * (hi - lo);
        Real sum = 0.0L;
        for (std::size_t i = 0; i < x.size(); ++i)
            sum += w[i] * f(c + h * x[i]);
        return sum * h;
    }
};

// Adaptive bisection until halving changes a piece by less than `tol` (absolute, the same for every
// piece), by less than 1e-300 (below every quantity tested: subnormal long doubles lose their
// relative precision) or by less than the round-off floor. A rough pass fixes the scale; the second asks for 1e-16
// of it per piece (long double: eps 1.1e-19).
Real adaptive(const std::function<Real(Real)>& f, Real lo, Real hi, Real whole, Real tol, int depth)
{
    static const GaussLegendre gl(12);
    const Real mid = 0.5L * (lo + hi);
    const Real left = gl(f, lo, mid), right = gl(f, mid, hi);
    const Real change = std::fabs(left + right - whole);
    if (depth > 60 || change <= tol || change <= 1e-300L || change <= 1e-17L * (std::fabs(left) + std::fabs(right)))
        return left + right;
    return adaptive(f, lo, mid, left, tol, depth + 1) + adaptive(f, mid, hi, right, tol, depth + 1);
}
Real adaptive(const std::function<Real(Real)>& f)
{
    // exp(-T) has its boundary layer at t = 0 (T grows from 0): pre-split at 10^-k so that no layer,
    // however thin, falls between the nodes of the first rule.
    static const GaussLegendre gl(12);
    std::vector<Real> edges{0.0L};
    for (int k = 18; k >= 1; --k)
        edges.push_back(std::pow(10.0L, -k));
    edges.push_back(1.0L);
    Real rough = 0.0L;
    for (std::size_t i = 0; i + 1 < edges.size(); ++i) {
        const Real whole = gl(f, edges[i], edges[i + 1]);
        rough += adaptive(f, edges[i], edges[i + 1], whole, 1e-8L * std::fabs(whole), 0);
    }
    Real sum = 0.0L;
    for (std::size_t i = 0; i + 1 < edges.size(); ++i)
        sum += adaptive(f, edges[i], edges[i + 1], gl(f, edges[i], edges[i + 1]), 1e-17L * std::fabs(rough), 0);
    return sum;
}

// A linear scalar field and a transfer function with kinks inside its range.
double linearField(glm::dvec3 p) { return 0.15 + 0.5 * p.x - 0.3 * p.y + 0.45 * p.z; }

TransferFunction kinkedTf()
{
    return TransferFunction({{0.0, {0.1, 0.2, 0.9}, 0.2},
                             {0.3, {0.9, 0.3, 0.1}, 4.0},
                             {0.45, {0.2, 1.0, 0.3}, 0.5},
                             {0.7, {1.0, 1.0, 1.0}, 7.0},
                             {0.9, {0.5, 0.1, 0.6}, 0.0}});
}

// Brute force on one ray: RK4 of T' = -tau T, I' = C tau T with the transfer function of the exact
// field, the chord [t0, t1] cut where the field crosses a control point (smooth pieces: 4th order;
// 1600 steps a piece leave ~1e-14, 400 steps ~3e-12: the 4^4 ratio of a 4th-order method).
glm::dvec4 bruteForce(const Ray& ray, const std::vector<std::pair<double, double>>& chords, const TransferFunction& tf,
                      const std::function<double(glm::dvec3)>& field, int stepsPerPiece = 1600)
{
    double T = 1.0;
    glm::dvec3 I(0.0);
    for (auto [t0, t1] : chords) {
        std::vector<double> cuts{t0, t1};
        const double s0 = field(ray.origin + t0 * ray.direction), s1 = field(ray.origin + t1 * ray.direction);
        for (const ControlPoint& p : tf.points())
            if ((p.s - s0) * (p.s - s1) < 0.0)
                cuts.push_back(t0 + (t1 - t0) * (p.s - s0) / (s1 - s0));
        std::sort(cuts.begin(), cuts.end());
        auto rhs = [&](double t, double Tv) {
            const glm::dvec4 c = tf(field(ray.origin + t * ray.direction));
            return std::pair{-c.a * Tv, glm::dvec3(c) * c.a * Tv};
        };
        for (std::size_t k = 0; k + 1 < cuts.size(); ++k) {
            const double h = (cuts[k + 1] - cuts[k]) / stepsPerPiece;
            for (int i = 0; i < stepsPerPiece; ++i) {
                const double t = cuts[k] + i * h;
                const auto [k1, j1] = rhs(t, T);
                const auto [k2, j2] = rhs(t + 0.5 * h, T + 0.5 * h * k1);
                const auto [k3, j3] = rhs(t + 0.5 * h, T + 0.5 * h * k2);
                const auto [k4, j4] = rhs(t + h, T + h * k3);
                T += h / 6.0 * (k1 + 2.0 * k2 + 2.0 * k3 + k4);
                I += h / 6.0 * (j1 + 2.0 * j2 + 2.0 * j3 + j4);
            }
        }
    }
    return glm::dvec4(I, 1.0 - T);
}

// ---- meshes built here (independent of the mesh readers) --------------------------------------------

// A grid of cells over [lo, hi], each split into the 6 Kuhn tetrahedra around its main diagonal (the
// same split in every cell: conforming). Interior points moved by up to `perturb` cell sizes; cells
// for which keep(i, j, k) is false left out. Scalars from `field` at the (moved) points.
TetMesh gridMesh(glm::ivec3 n, glm::dvec3 lo, glm::dvec3 hi, double perturb, std::uint64_t seed,
                 const std::function<double(glm::dvec3)>& field,
                 const std::function<bool(int, int, int)>& keep = [](int, int, int) { return true; })
{
    TetMesh m;
    m.source = "test grid";
    test::Rng rng(seed);
    const glm::dvec3 h = (hi - lo) / glm::dvec3(n);
    auto id = [&](int i, int j, int k) { return static_cast<std::uint32_t>((k * (n.y + 1) + j) * (n.x + 1) + i); };
    for (int k = 0; k <= n.z; ++k)
        for (int j = 0; j <= n.y; ++j)
            for (int i = 0; i <= n.x; ++i) {
                glm::dvec3 p = lo + glm::dvec3(i, j, k) * h;
                if (i > 0 && i < n.x && j > 0 && j < n.y && k > 0 && k < n.z)
                    p += perturb * h * glm::dvec3(rng.uniform(-1, 1), rng.uniform(-1, 1), rng.uniform(-1, 1));
                m.points.push_back(p);
                m.scalars.push_back(field(p));
            }
    const int perms[6][3] = {{0, 1, 2}, {0, 2, 1}, {1, 0, 2}, {1, 2, 0}, {2, 0, 1}, {2, 1, 0}};
    for (int k = 0; k < n.z; ++k)
        for (int j = 0; j < n.y; ++j)
            for (int i = 0; i < n.x; ++i) {
                if (!keep(i, j, k))
                    continue;
                for (const auto& p : perms) {
                    glm::ivec3 c(i, j, k);
                    glm::uvec4 t;
                    t[0] = id(c.x, c.y, c.z);
                    for (int v = 0; v < 3; ++v) {
                        c[p[v]] += 1;
                        t[v + 1] = id(c.x, c.y, c.z);
                    }
                    m.tets.push_back(t);
                }
            }
    m.tetsRead = m.tets.size();
    return m;
}

TetMesh unitCube6(const std::function<double(glm::dvec3)>& field)
{
    return gridMesh({1, 1, 1}, glm::dvec3(0.0), glm::dvec3(1.0), 0.0, 1, field);
}

Camera obliqueCamera()
{
    Camera c;
    c.position = {2.1, 1.6, 2.9};
    c.focalPoint = {0.5, 0.45, 0.5};
    c.viewAngle = 45.0;
    return c;
}

double maxAbsDiff(const Image4d& a, const Image4d& b)
{
    double m = 0.0;
    for (std::size_t i = 0; i < a.pixelCount(); ++i) {
        const glm::dvec4 d = glm::abs(a.pixels()[i] - b.pixels()[i]);
        m = std::max({m, d.r, d.g, d.b, d.a});
        if (glm::any(glm::isnan(a.pixels()[i])))
            return std::numeric_limits<double>::infinity();
    }
    return m;
}

// ---- tests ------------------------------------------------------------------------------------------

TEST(TetReferencePsiZeta, MatchesAdaptiveQuadrature)
{
    const std::vector<double> taus{0.0, 1e-200, 1e-12, 1e-5, 0.01, 0.3, 1.0, 1.0 + 1e-10, 1.7, 2.0,
                                   2.0000001, 3.0, 10.0, 60.0, 1e3, 1e6};
    const std::vector<double> lengths{1e-3, 1.0, 2.5};
    double worst[3] = {0.0, 0.0, 0.0};
    int cases = 0;
    for (double tf : taus)
        for (double tb : taus)
            for (double l : lengths) {
                const Real a = tf * l, b = tb * l;  // the same (rounded) depths psiZeta gets
                const PsiZeta p = psiZeta(tf * l, tb * l);
                auto T = [&](Real t) { return a * t + 0.5L * (b - a) * t * t; };
                // T(1) - T(t) = (1 - t)(a (1 - t)/2 + b (1 + t)/2): no cancellation
                auto rest = [&](Real t) { return (1.0L - t) * (0.5L * a * (1.0L - t) + 0.5L * b * (1.0L + t)); };
                const Real psi = adaptive([&](Real t) { return std::exp(-T(t)); });
                const Real omp = adaptive([&](Real t) { return -std::expm1(-T(t)); });
                const Real pmz = adaptive([&](Real t) { return std::exp(-T(t)) * -std::expm1(-rest(t)); });
                const Real zeta = std::exp(-0.5L * (a + b));
                const double got[3] = {p.psi, p.oneMinusPsi, p.psiMinusZeta};
                const Real want[3] = {psi, omp, pmz};
                for (int q = 0; q < 3; ++q) {
                    if (want[q] == 0.0L) {
                        EXPECT_EQ(got[q], 0.0) << "a=" << tf * l << " b=" << tb * l << " q=" << q;
                        continue;
                    }
                    const double rel = static_cast<double>(std::fabs((got[q] - want[q]) / want[q]));
                    worst[q] = std::max(worst[q], rel);
                    EXPECT_LT(rel, 1e-12) << "a=" << tf * l << " b=" << tb * l << " q=" << q << " got " << got[q]
                                          << " want " << static_cast<double>(want[q]);
                }
                EXPECT_NEAR(p.zeta, static_cast<double>(zeta), 1e-15 * static_cast<double>(zeta));
                ++cases;
            }
    std::printf("[ psi/zeta ] %d cases: max relative error psi %.2e, 1-psi %.2e, psi-zeta %.2e\n", cases, worst[0],
                worst[1], worst[2]);
}

TEST(TetReferencePiece, ConstantTauMatchesChordClosedForm)
{
    const glm::dvec3 C(0.9, 0.4, 0.1);
    for (double tau : {0.0, 1e-9, 0.7, 2.3, 40.0, 1e5})
        for (double L : {1e-4, 0.7, 3.0}) {
            const glm::dvec4 v = integrateLinearPiece(C, tau, C, tau, L);
            const double alpha = -std::expm1(-tau * L);
            for (int c = 0; c < 3; ++c)
                EXPECT_NEAR(v[c], C[c] * alpha, 1e-15) << tau << " " << L;
            EXPECT_NEAR(v.a, alpha, 1e-16);
        }
}

TEST(TetReferenceTrace, SingleTetConstantMedium)
{
    TetMesh m;
    m.points = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
    m.scalars = {0.5, 0.5, 0.5, 0.5};
    m.tets = {{0, 1, 2, 3}};
    const TetAccel accel(m);
    // Along +x at y = 0.1, z = 0.2: in through x = 0, out through x + y + z = 1 at x = 0.7.
    const Ray ray{{-2.0, 0.1, 0.2}, {1.0, 0.0, 0.0}};
    const std::vector<TetSegment> segs = traceRay(accel, ray);
    ASSERT_EQ(segs.size(), 1u);
    EXPECT_NEAR(segs[0].lambdaIn, 2.0, 1e-15);
    EXPECT_NEAR(segs[0].lambdaOut, 2.7, 1e-15);
    EXPECT_NEAR(segs[0].sIn, 0.5, 1e-15);
    EXPECT_NEAR(segs[0].sOut, 0.5, 1e-15);

    const glm::dvec3 C(0.9, 0.4, 0.1);
    const double tau = 2.3;
    const TransferFunction tf({{0.0, C, tau}, {1.0, C, tau}});
    Camera cam;
    cam.position = ray.origin;
    cam.focalPoint = ray.origin + ray.direction;
    const Image4d img = tetReferenceIntegral(m, tf, cam, {.width = 1, .height = 1});
    const double alpha = 1.0 - std::exp(-tau * 0.7);
    for (int c = 0; c < 3; ++c)
        EXPECT_NEAR(img.at(0, 0)[c], C[c] * alpha, 1e-14);
    EXPECT_NEAR(img.at(0, 0).a, alpha, 1e-14);
}

TEST(TetReferenceTrace, ConvexMeshSegmentsTileTheChordExactly)
{
    const TetMesh m = gridMesh({5, 4, 6}, {-0.5, 0.0, 0.2}, {0.7, 1.1, 1.3}, 0.25, 7, linearField);
    const TetAccel accel(m);
    test::Rng rng(11);
    int rays = 0;
    for (int r = 0; r < 300; ++r) {
        const glm::dvec3 target(rng.uniform(-0.5, 0.7), rng.uniform(0.0, 1.1), rng.uniform(0.2, 1.3));
        const glm::dvec3 origin = target + 3.0 * glm::normalize(glm::dvec3(rng.uniform(-1, 1), rng.uniform(-1, 1),
                                                                             rng.uniform(-1, 1)));
        const Ray ray{origin, glm::normalize(target - origin)};
        const std::vector<TetSegment> segs = traceRay(accel, ray);
        double t0, t1;
        ASSERT_TRUE(clipRayToBox(ray, {-0.5, 0.0, 0.2}, {0.7, 1.1, 1.3}, 0.0, t0, t1));
        ASSERT_FALSE(segs.empty());
        EXPECT_NEAR(segs.front().lambdaIn, t0, 1e-13);
        EXPECT_NEAR(segs.back().lambdaOut, t1, 1e-13);
        for (std::size_t i = 0; i + 1 < segs.size(); ++i) {
            // Shared faces give bit-identical crossings (canonical planes): no gap, no overlap.
            EXPECT_EQ(segs[i].lambdaOut, segs[i + 1].lambdaIn) << "ray " << r << " segment " << i;
            // s from each tet's own barycentrics: equal to rounding, amplified by thin tets' small heights
            EXPECT_NEAR(segs[i].sOut, segs[i + 1].sIn, 1e-13);
        }
        for (const TetSegment& s : segs) {
            EXPECT_NEAR(s.sIn, linearField(ray.origin + s.lambdaIn * ray.direction), 1e-14);
            EXPECT_NEAR(s.sOut, linearField(ray.origin + s.lambdaOut * ray.direction), 1e-14);
        }
        ++rays;
    }
    EXPECT_EQ(rays, 300);
}

// Every pixel of `mesh` (covering exactly the box [lo, hi], linear field) against the RK4 brute force.
void expectMatchesBruteForce(const TetMesh& mesh, glm::dvec3 lo, glm::dvec3 hi, const Camera& cam, double tol)
{
    const TransferFunction tf = kinkedTf();
    const ImageSpec spec{.width = 11, .height = 9};
    const Image4d img = tetReferenceIntegral(mesh, tf, cam, spec);
    double worst = 0.0;
    int hits = 0;
    for (int y = 0; y < spec.height; ++y)
        for (int x = 0; x < spec.width; ++x) {
            const Ray ray = cam.ray(x, y, spec.width, spec.height);
            double t0, t1;
            glm::dvec4 want(0.0);
            if (clipRayToBox(ray, lo, hi, 0.0, t0, t1)) {
                want = bruteForce(ray, {{t0, t1}}, tf, linearField);
                ++hits;
            }
            const glm::dvec4 d = glm::abs(img.at(x, y) - want);
            worst = std::max({worst, d.r, d.g, d.b, d.a});
        }
    EXPECT_GT(hits, 20);
    EXPECT_LT(worst, tol);
    std::printf("[ brute force ] %zu tets, %d rays through the mesh: max |diff| %.2e\n", mesh.tets.size(), hits, worst);
}

TEST(TetReferenceIntegral, LinearFieldSixTetCubeMatchesBruteForce)
{
    expectMatchesBruteForce(unitCube6(linearField), glm::dvec3(0.0), glm::dvec3(1.0), obliqueCamera(), 1e-12);
}

TEST(TetReferenceIntegral, LinearFieldPerturbedGridMatchesBruteForce)
{
    // A linear field is reproduced exactly by any linear tetrahedral mesh: the image may not depend on it.
    const TetMesh m = gridMesh({4, 3, 5}, glm::dvec3(0.0), glm::dvec3(1.0), 0.25, 3, linearField);
    expectMatchesBruteForce(m, glm::dvec3(0.0), glm::dvec3(1.0), obliqueCamera(), 1e-12);
    Camera par = obliqueCamera();
    par.parallel = true;
    par.parallelScale = 0.9;
    expectMatchesBruteForce(m, glm::dvec3(0.0), glm::dvec3(1.0), par, 1e-12);
}

TEST(TetReferenceIntegral, IndependentOfCollinearControlPoints)
{
    const TetMesh m = gridMesh({4, 4, 4}, glm::dvec3(0.0), glm::dvec3(1.0), 0.2, 5, linearField);
    const TransferFunction tf = kinkedTf();
    std::vector<ControlPoint> finer;
    for (std::size_t i = 0; i < tf.points().size(); ++i) {
        finer.push_back(tf.points()[i]);
        if (i + 1 < tf.points().size())
            for (double f : {0.25, 0.5, 0.9}) {  // collinear points: the same function
                const double s = tf.points()[i].s + f * (tf.points()[i + 1].s - tf.points()[i].s);
                const glm::dvec4 v = tf(s);
                finer.push_back({s, glm::clamp(glm::dvec3(v), 0.0, 1.0), v.a});
            }
    }
    const ImageSpec spec{.width = 24, .height = 20, .background = {0.1, 0.2, 0.3}};
    const Image4d a = tetReferenceIntegral(m, tf, obliqueCamera(), spec);
    const Image4d b = tetReferenceIntegral(m, TransferFunction(finer), obliqueCamera(), spec);
    const double d = maxAbsDiff(a, b);
    EXPECT_LT(d, 1e-12);
    std::printf("[ split ] %zu -> %zu control points: max |diff| %.2e\n", tf.points().size(), finer.size(), d);
}

TEST(TetReferenceNonConvex, LShapeRayCrossesTheNotch)
{
    // Cells (0,0), (1,0), (0,1) of a 2x2x1 grid: the notch is cell (1,1).
    const TetMesh m = gridMesh({2, 2, 1}, glm::dvec3(0.0), glm::dvec3(2.0, 2.0, 1.0), 0.0, 1, linearField,
                               [](int i, int j, int) { return !(i == 1 && j == 1); });
    const TetAccel accel(m);
    // In at x = 0 (y = 1.8), out into the notch at x = 1 (y = 1.3), in again at x = 1.6 (y = 1), out at x = 2.
    const glm::dvec3 dir = glm::normalize(glm::dvec3(1.0, -0.5, 0.0));
    const Ray ray{{-0.5, 2.05, 0.5}, dir};
    const double k = std::sqrt(1.25);
    const std::vector<TetSegment> segs = traceRay(accel, ray);
    ASSERT_GE(segs.size(), 2u);
    std::vector<std::pair<double, double>> parts{{segs.front().lambdaIn, segs.front().lambdaOut}};
    for (std::size_t i = 1; i < segs.size(); ++i) {
        if (segs[i].lambdaIn == parts.back().second)
            parts.back().second = segs[i].lambdaOut;
        else
            parts.push_back({segs[i].lambdaIn, segs[i].lambdaOut});
    }
    ASSERT_EQ(parts.size(), 2u);
    EXPECT_NEAR(parts[0].first, 0.5 * k, 1e-14);
    EXPECT_NEAR(parts[0].second, 1.5 * k, 1e-14);
    EXPECT_NEAR(parts[1].first, 2.1 * k, 1e-14);
    EXPECT_NEAR(parts[1].second, 2.5 * k, 1e-14);

    const TransferFunction tf = kinkedTf();
    const glm::dvec4 got = integrateSegments(segs, tf);
    const glm::dvec4 want = bruteForce(ray, parts, tf, linearField);
    const glm::dvec4 d = glm::abs(got - want);
    EXPECT_LT(std::max({d.r, d.g, d.b, d.a}), 1e-12);
    // The gap contributes nothing: the two parts composite front to back.
    std::vector<TetSegment> front, back;
    for (const TetSegment& s : segs)
        (s.lambdaIn < parts[0].second ? front : back).push_back(s);
    const glm::dvec4 f = integrateSegments(front, tf), b = integrateSegments(back, tf);
    const glm::dvec4 composed(glm::dvec3(f) + (1.0 - f.a) * glm::dvec3(b), 1.0 - (1.0 - f.a) * (1.0 - b.a));
    EXPECT_LT(glm::length(got - composed), 1e-15);
}

TEST(TetReferenceNonConvex, DisjointBoxesCompositeFrontToBack)
{
    auto box = [](glm::dvec3 lo, glm::dvec3 hi, std::uint64_t seed) {
        return gridMesh({3, 3, 2}, lo, hi, 0.2, seed, linearField);
    };
    const TetMesh back = box({0.0, 0.0, 0.0}, {1.0, 1.0, 0.6}, 1), front = box({0.1, 0.0, 1.2}, {1.0, 0.9, 1.8}, 2);
    TetMesh both = back;
    const auto offset = static_cast<std::uint32_t>(both.points.size());
    both.points.insert(both.points.end(), front.points.begin(), front.points.end());
    both.scalars.insert(both.scalars.end(), front.scalars.begin(), front.scalars.end());
    for (glm::uvec4 t : front.tets)
        both.tets.push_back(t + offset);
    Camera cam;
    cam.position = {0.6, 0.4, 5.0};
    cam.focalPoint = {0.5, 0.45, 0.5};
    cam.viewAngle = 20.0;
    const ImageSpec spec{.width = 16, .height = 16};
    const TransferFunction tf = kinkedTf();
    const Image4d all = tetReferenceIntegral(both, tf, cam, spec);
    const Image4d f = tetReferenceIntegral(front, tf, cam, spec), b = tetReferenceIntegral(back, tf, cam, spec);
    Image4d composed(spec.width, spec.height);
    int crossing = 0;
    for (std::size_t i = 0; i < composed.pixelCount(); ++i) {
        const glm::dvec4 pf = f.pixels()[i], pb = b.pixels()[i];
        composed.pixels()[i] = glm::dvec4(glm::dvec3(pf) + (1.0 - pf.a) * glm::dvec3(pb), 1.0 - (1.0 - pf.a) * (1.0 - pb.a));
        crossing += (pf.a > 0.0 && pb.a > 0.0) ? 1 : 0;
    }
    EXPECT_GT(crossing, 50);  // most rays cross both boxes and the gap between them
    EXPECT_LT(maxAbsDiff(all, composed), 1e-14);
}

TEST(TetReferenceIntegral, BackgroundCompositing)
{
    const TetMesh m = gridMesh({3, 3, 3}, glm::dvec3(0.0), glm::dvec3(1.0), 0.2, 9, linearField);
    const TetAccel accel(m);
    Camera cam = obliqueCamera();
    cam.viewAngle = 70.0;  // wide: some rays miss
    const glm::dvec3 bg(0.2, 0.5, 0.9);
    const Image4d black = tetReferenceIntegral(accel, kinkedTf(), cam, {.width = 20, .height = 16});
    const Image4d lit = tetReferenceIntegral(accel, kinkedTf(), cam, {.width = 20, .height = 16, .background = bg});
    int misses = 0, hits = 0;
    for (std::size_t i = 0; i < black.pixelCount(); ++i) {
        const glm::dvec4 p = black.pixels()[i], q = lit.pixels()[i];
        EXPECT_EQ(p.a, q.a);
        for (int c = 0; c < 3; ++c)
            EXPECT_NEAR(q[c], p[c] + (1.0 - p.a) * bg[c], 1e-15);
        if (p.a == 0.0) {
            ++misses;
            EXPECT_EQ(glm::dvec3(q), bg);
        } else {
            ++hits;
        }
    }
    EXPECT_GT(misses, 0);
    EXPECT_GT(hits, 0);
}

TEST(TetReferenceIntegral, CamerasPutAnOffCenterTetInTheRightQuadrant)
{
    const glm::dvec3 c(0.5, 0.4, 0.0);
    TetMesh m;
    for (glm::dvec3 o : {glm::dvec3(1, 1, 1), glm::dvec3(1, -1, -1), glm::dvec3(-1, 1, -1), glm::dvec3(-1, -1, 1)}) {
        m.points.push_back(c + 0.15 * o);
        m.scalars.push_back(1.0);
    }
    m.tets = {{0, 1, 2, 3}};
    const TransferFunction tf({{0.0, {1, 1, 1}, 5.0}, {2.0, {1, 1, 1}, 5.0}});
    const int n = 32;
    for (bool parallel : {false, true}) {
        Camera cam;  // at (0, 0, 4) looking at the origin, y up
        cam.parallel = parallel;
        cam.parallelScale = 1.0;
        const Image4d img = tetReferenceIntegral(m, tf, cam, {.width = n, .height = n});
        int covered = 0;
        for (int y = 0; y < n; ++y)
            for (int x = 0; x < n; ++x)
                if (img.at(x, y).a > 0.0) {
                    ++covered;
                    EXPECT_GE(x, n / 2) << "parallel " << parallel;  // +x: right half
                    EXPECT_LT(y, n / 2) << "parallel " << parallel;  // +y: top half (row 0 at the top)
                }
        EXPECT_GT(covered, 4);
        // The centroid's pixel: perspective x = (1 + 0.5 / (4 tan 15°)) / 2 * 32 = 23.5, row (1 - 0.4 / (4 tan 15°)) / 2 * 32 = 10.0;
        // parallel (scale 1) x = 24, row 9.6.
        const double t = 4.0 * std::tan(15.0 * std::numbers::pi / 180.0);
        const int px = parallel ? 24 : static_cast<int>((1.0 + 0.5 / t) / 2.0 * n);
        const int py = parallel ? 9 : static_cast<int>((1.0 - 0.4 / t) / 2.0 * n);
        EXPECT_GT(img.at(px, py).a, 0.3) << "parallel " << parallel << " pixel " << px << "," << py;
    }
}

TEST(TetReferenceSpeed, PerturbedGridOf245kTetsAt64x64)
{
    // 40x32x32 cells x 6 = 245,760 tetrahedra (bluntfin has 224,874). A printout, not a timed test.
    auto t0 = std::chrono::steady_clock::now();
    const TetMesh m = gridMesh({40, 32, 32}, glm::dvec3(0.0), {1.25, 1.0, 1.0}, 0.2, 13, linearField);
    auto t1 = std::chrono::steady_clock::now();
    const TetAccel accel(m);
    auto t2 = std::chrono::steady_clock::now();
    Camera cam;
    cam.position = {2.4, 1.5, 2.6};
    cam.focalPoint = {0.62, 0.5, 0.5};
    TetReferenceStats stats;
    const Image4d img = tetReferenceIntegral(accel, kinkedTf(), cam, {.width = 64, .height = 64}, {.stats = &stats});
    auto t3 = std::chrono::steady_clock::now();
    auto ms = [](auto a, auto b) { return std::chrono::duration<double, std::milli>(b - a).count(); };
    EXPECT_EQ(accel.tetCount(), 245760u);
    EXPECT_GT(stats.rays, 1000u);
    std::printf("[ speed ] %zu tets: mesh %.0f ms, accel %.0f ms (grid %dx%dx%d), 64x64 render %.0f ms (2 threads); "
                "%llu rays, %llu segments (max %d per ray), %llu pieces\n",
                accel.tetCount(), ms(t0, t1), ms(t1, t2), accel.gridDims().x, accel.gridDims().y, accel.gridDims().z,
                ms(t2, t3), static_cast<unsigned long long>(stats.rays), static_cast<unsigned long long>(stats.segments),
                stats.maxSegmentsPerRay, static_cast<unsigned long long>(stats.pieces));
    (void)img;
}

}  // namespace
}  // namespace clvr
