// host/reference/tet_reference.cpp — the exact emission-absorption integral on linear tetrahedra: rays clipped
// against each tetrahedron's 4 face planes (candidates from a uniform grid of bounding boxes), segments
// cut at transfer-function control points, each linear piece integrated in closed form (Eq. 2-4 of
// seeds/001_cd12fd6b76f9cf96.txt; derivation and numerical care in docs/tet-reference.md).
#include "host/reference/tet_reference.h"

#include "host/runtime/parallel.h"

#include <algorithm>
#include <array>
#include <atomic>
#include <cmath>
#include <limits>
#include <mutex>

namespace clvr {
namespace {

using Real = long double;  // the special functions and the small-depth series (80-bit on x86-64)

constexpr Real kSqrtPi = 1.772453850905516027298167483341145182797549456122387128213807789852911L;

// erfcx(x) = exp(x^2) erfc(x), x >= 0. Below 10 from erfcl (x^2 is exact enough in long double: the
// relative error of expl(x^2) is about x^2 * 5e-20 <= 5e-18); above, the asymptotic series
// 1/(x sqrt(pi)) sum (-1)^n (2n-1)!! / (2x^2)^n, whose smallest term at x >= 10 is below 1e-40.
Real erfcx(Real x)
{
    if (x < 10.0L)
        return std::exp(x * x) * std::erfc(x);
    const Real r = 1.0L / (2.0L * x * x);
    Real term = 1.0L, sum = 1.0L;
    for (int n = 1; n < 60; ++n) {
        term *= -(2 * n - 1) * r;
        sum += term;
        if (std::fabs(term) < 1e-22L)
            break;
    }
    return sum / (x * kSqrtPi);
}

// Dawson's integral F(x) = exp(-x^2) ∫0^x exp(t^2) dt, x >= 0. Below 7 from the series of positive terms
// exp(-x^2) sum x^(2n+1) / (n! (2n+1)) (no cancellation; at most ~300 terms); above, the asymptotic
// series 1/(2x) sum (2n-1)!! / (2x^2)^n, whose smallest term at x >= 7 is about 1e-21.
Real dawson(Real x)
{
    if (x < 7.0L) {
        const Real x2 = x * x;
        Real term = x, sum = x;  // term = x^(2n+1) / n!
        for (int n = 1; n < 1000; ++n) {
            term *= x2 / n;
            const Real add = term / (2 * n + 1);
            sum += add;
            if (add < sum * 1e-21L)
                break;
        }
        return std::exp(-x2) * sum;
    }
    const Real r = 1.0L / (2.0L * x * x);
    Real term = 1.0L, sum = 1.0L;
    for (int n = 1; n < 200; ++n) {
        const Real next = term * (2 * n - 1) * r;
        if (next > term)  // past the smallest term of the asymptotic series
            break;
        term = next;
        sum += term;
        if (term < 1e-22L * sum)
            break;
    }
    return sum / (2.0L * x);
}

// 1 - psi for max(a, b) <= 2: psi = ∫0^1 exp(-T(t)) dt with T(t) = a t + c t^2, c = (b - a)/2, so
// 1 - psi = sum_{n>=1} (-1)^(n+1) / n! ∫0^1 T^n dt, ∫0^1 T^n = sum_j C(n,j) a^(n-j) c^j / (n+j+1).
// |T| <= 2: the terms fall like 3^n 2^n / n!; cancellation at most e^6 * eps_long ~ 2e-17.
Real oneMinusPsiSeries(Real a, Real b)
{
    const Real c = 0.5L * (b - a);
    Real sum = 0.0L, factorial = 1.0L, aToN = 1.0L;
    for (int n = 1; n <= 60; ++n) {
        factorial *= n;
        // a^n as a running product, not powl: powl was two thirds of the time of building a full
        // pre-integration table (host/optics/preintegration_table.cpp); n <= 60 roundings cost < 4e-18.
        aToN *= a;
        // ∫0^1 T^n dt, binomial over powers of a and c
        Real integral = 0.0L, binom = 1.0L, an = aToN, cj = 1.0L;
        for (int j = 0; j <= n; ++j) {
            const Real anj = (a == 0.0L) ? (j == n ? 1.0L : 0.0L) : an;
            integral += binom * anj * cj / (n + j + 1);
            binom = binom * (n - j) / (j + 1);
            cj *= c;
            if (a != 0.0L)
                an /= a;
        }
        const Real term = integral / factorial;
        sum += (n % 2 == 1) ? term : -term;
        if (std::fabs(term) <= 1e-21L * std::fabs(sum))
            break;
    }
    return sum;
}

}  // namespace

PsiZeta psiZeta(double a, double b)
{
    PsiZeta r;
    const double m = std::max(a, b);
    if (!(m > 0.0))
        return r;  // transparent: psi = zeta = 1
    // in long double: a + b rounded in double would cost (a + b) * 1e-16 relative in zeta
    const Real halfDepth = 0.5L * (static_cast<Real>(a) + static_cast<Real>(b));
    r.zeta = static_cast<double>(std::exp(-halfDepth));
    r.oneMinusZeta = static_cast<double>(-std::expm1(-halfDepth));
    if (m <= 2.0) {
        const Real w = oneMinusPsiSeries(a, b);
        r.oneMinusPsi = static_cast<double>(w);
        r.psi = static_cast<double>(1.0L - w);
        r.psiMinusZeta = static_cast<double>(static_cast<Real>(r.oneMinusZeta) - w);
        return r;
    }
    const Real A = a, B = b, d = B - A;
    Real psi;
    if (std::fabs(d) <= 1e-8L * m) {
        // Nearly constant tau: psi = (1 - e^-a)/a - (d/2) ∫0^1 t^2 e^(-a t) dt + O(d^2), a >= 1 here,
        // the dropped term below (d^2/8) ∫ t^4 e^(-a t) <= 1e-16 * 4e-2 relative.
        const Real ea = std::exp(-A);
        const Real psi0 = -std::expm1(-A) / A;
        const Real m2 = (2.0L - ea * (A * A + 2.0L * A + 2.0L)) / (A * A * A);
        psi = psi0 - 0.5L * d * m2;
    } else {
        // Complete the square in T(t) = a t + d t^2 / 2 with k = sqrt(|d|/2), x0 = a/(2k), x1 = b/(2k):
        // d > 0: psi = (sqrt(pi)/2) (erfcx(x0) - zeta erfcx(x1)) / k
        // d < 0: psi = (F(x0) - zeta F(x1)) / k              (F: Dawson's integral)
        // since x0^2 - x1^2 = -(a + b)/2 in both cases (docs/tet-reference.md).
        const Real k = std::sqrt(0.5L * std::fabs(d));
        const Real x0 = A / (2.0L * k), x1 = B / (2.0L * k);
        const Real zeta = std::exp(-0.5L * (A + B));
        if (d > 0.0L)
            psi = 0.5L * kSqrtPi * (erfcx(x0) - zeta * erfcx(x1)) / k;
        else
            psi = (dawson(x0) - zeta * dawson(x1)) / k;
    }
    r.psi = static_cast<double>(psi);
    r.oneMinusPsi = static_cast<double>(1.0L - psi);
    r.psiMinusZeta = static_cast<double>(psi - std::exp(-0.5L * (A + B)));
    return r;
}

glm::dvec4 integrateLinearPiece(glm::dvec3 colorF, double tauF, glm::dvec3 colorB, double tauB, double l)
{
    // Eq. 2 of seeds/001 written front to back: I = C_b (psi - zeta) + C_f (1 - psi), opacity 1 - zeta.
    const PsiZeta p = psiZeta(tauF * l, tauB * l);
    return glm::dvec4(colorB * p.psiMinusZeta + colorF * p.oneMinusPsi, p.oneMinusZeta);
}

// ---- geometry ---------------------------------------------------------------------------------------

TetAccel::TetAccel(const TetMesh& mesh)
{
    const auto& P = mesh.points;
    if (mesh.tets.empty() || P.empty())
        return;
    lo_ = glm::dvec3(std::numeric_limits<double>::infinity());
    hi_ = -lo_;
    for (const glm::uvec4& t : mesh.tets)
        for (int i = 0; i < 4; ++i) {
            lo_ = glm::min(lo_, P[t[i]]);
            hi_ = glm::max(hi_, P[t[i]]);
        }
    const glm::dvec3 ext = hi_ - lo_;
    const double extent = std::max({ext.x, ext.y, ext.z});
    const double minVolume6 = 1e-12 * extent * extent * extent;  // checkMesh's zero-volume threshold

    tets_.reserve(mesh.tets.size());
    meshIndex_.reserve(mesh.tets.size());
    // Canonical order of a face's points: by position (then index), so that two tetrahedra sharing a
    // face, even through duplicated points at a seam, compute the same plane bit for bit.
    auto before = [&](std::uint32_t i, std::uint32_t j) {
        const glm::dvec3 &p = P[i], &q = P[j];
        if (p.x != q.x) return p.x < q.x;
        if (p.y != q.y) return p.y < q.y;
        if (p.z != q.z) return p.z < q.z;
        return i < j;
    };
    for (std::size_t t = 0; t < mesh.tets.size(); ++t) {
        const glm::uvec4 v = mesh.tets[t];
        const double volume6 = glm::dot(P[v[1]] - P[v[0]], glm::cross(P[v[2]] - P[v[0]], P[v[3]] - P[v[0]]));
        if (!(std::fabs(volume6) > minVolume6)) {
            ++skipped_;
            continue;
        }
        Tet tet{};
        for (int i = 0; i < 4; ++i) {
            std::array<std::uint32_t, 3> f;
            for (int j = 0, k = 0; j < 4; ++j)
                if (j != i)
                    f[k++] = v[j];
            std::sort(f.begin(), f.end(), before);
            glm::dvec3 n = glm::cross(P[f[1]] - P[f[0]], P[f[2]] - P[f[0]]);
            double w = -glm::dot(n, P[f[0]]);
            double h = glm::dot(n, P[v[i]]) + w;
            if (h > 0.0) {  // make the inside negative (exact: a sign flip)
                n = -n;
                w = -w;
                h = -h;
                tet.flipped |= 1u << i;
            }
            tet.plane[i] = glm::dvec4(n, w);
            tet.height[i] = h;
            tet.scalar[i] = mesh.scalars[v[i]];
        }
        tets_.push_back(tet);
        meshIndex_.push_back(static_cast<std::uint32_t>(t));
    }

    // Uniform grid, about one cell per tetrahedron, cells as cubic as the box allows.
    const double n = static_cast<double>(std::max<std::size_t>(tets_.size(), 1));
    const glm::dvec3 e = glm::max(ext, glm::dvec3(extent * 1e-6 + 1e-300));
    const double cell = std::cbrt(e.x * e.y * e.z / n);
    dims_ = glm::clamp(glm::ivec3(glm::ceil(e / cell)), glm::ivec3(1), glm::ivec3(256));
    hi_ = lo_ + e;
    cellSize_ = e / glm::dvec3(dims_);
    const glm::dvec3 pad = cellSize_ * 1e-6;  // boxes a hair larger: no tet lost to DDA rounding
    auto cellRange = [&](const Tet&, std::size_t t, glm::ivec3& c0, glm::ivec3& c1) {
        const glm::uvec4 v = mesh.tets[meshIndex_[t]];
        glm::dvec3 bmin = P[v[0]], bmax = P[v[0]];
        for (int i = 1; i < 4; ++i) {
            bmin = glm::min(bmin, P[v[i]]);
            bmax = glm::max(bmax, P[v[i]]);
        }
        c0 = glm::clamp(glm::ivec3(glm::floor((bmin - pad - lo_) / cellSize_)), glm::ivec3(0), dims_ - 1);
        c1 = glm::clamp(glm::ivec3(glm::floor((bmax + pad - lo_) / cellSize_)), glm::ivec3(0), dims_ - 1);
    };
    const std::size_t cells = static_cast<std::size_t>(dims_.x) * dims_.y * dims_.z;
    cellStart_.assign(cells + 1, 0);
    auto cellIndex = [&](int x, int y, int z) { return (static_cast<std::size_t>(z) * dims_.y + y) * dims_.x + x; };
    for (int pass = 0; pass < 2; ++pass) {
        std::vector<std::uint32_t> fill;
        if (pass == 1) {
            for (std::size_t c = 0; c < cells; ++c)
                cellStart_[c + 1] += cellStart_[c];
            cellTets_.resize(cellStart_[cells]);
            fill.assign(cellStart_.begin(), cellStart_.end() - 1);
        }
        for (std::size_t t = 0; t < tets_.size(); ++t) {
            glm::ivec3 c0, c1;
            cellRange(tets_[t], t, c0, c1);
            for (int z = c0.z; z <= c1.z; ++z)
                for (int y = c0.y; y <= c1.y; ++y)
                    for (int x = c0.x; x <= c1.x; ++x) {
                        if (pass == 0)
                            ++cellStart_[cellIndex(x, y, z) + 1];
                        else
                            cellTets_[fill[cellIndex(x, y, z)]++] = static_cast<std::uint32_t>(t);
                    }
        }
    }
}

namespace {

// [t0, t1] (t0 >= 0) of the ray inside the box [lo, hi]; false if it misses.
bool clipToBox(const Ray& ray, glm::dvec3 lo, glm::dvec3 hi, double& t0, double& t1)
{
    t0 = 0.0;
    t1 = std::numeric_limits<double>::infinity();
    for (int a = 0; a < 3; ++a) {
        if (ray.direction[a] == 0.0) {
            if (ray.origin[a] < lo[a] || ray.origin[a] > hi[a])
                return false;
            continue;
        }
        double ta = (lo[a] - ray.origin[a]) / ray.direction[a], tb = (hi[a] - ray.origin[a]) / ray.direction[a];
        if (ta > tb)
            std::swap(ta, tb);
        t0 = std::max(t0, ta);
        t1 = std::min(t1, tb);
    }
    return t1 >= t0;
}

}  // namespace

std::vector<TetSegment> traceRay(const TetAccel& accel, const Ray& ray)
{
    std::vector<TetSegment> out;
    if (accel.tets_.empty())
        return out;
    const glm::dvec3 margin = accel.cellSize_ * 1e-6;
    double t0, t1;
    if (!clipToBox(ray, accel.lo_ - margin, accel.hi_ + margin, t0, t1))
        return out;

    // Candidates: every tetrahedron listed in a grid cell the ray passes (3D DDA, Amanatides & Woo).
    std::vector<std::uint32_t> candidates;
    const glm::ivec3 dims = accel.dims_;
    const glm::dvec3 start = ray.origin + t0 * ray.direction;
    glm::ivec3 c = glm::clamp(glm::ivec3(glm::floor((start - accel.lo_) / accel.cellSize_)), glm::ivec3(0), dims - 1);
    glm::ivec3 step;
    glm::dvec3 tNext, tDelta;
    for (int a = 0; a < 3; ++a) {
        const double d = ray.direction[a];
        if (d > 0.0) {
            step[a] = 1;
            tNext[a] = (accel.lo_[a] + (c[a] + 1) * accel.cellSize_[a] - ray.origin[a]) / d;
            tDelta[a] = accel.cellSize_[a] / d;
        } else if (d < 0.0) {
            step[a] = -1;
            tNext[a] = (accel.lo_[a] + c[a] * accel.cellSize_[a] - ray.origin[a]) / d;
            tDelta[a] = -accel.cellSize_[a] / d;
        } else {
            step[a] = 0;
            tNext[a] = std::numeric_limits<double>::infinity();
            tDelta[a] = std::numeric_limits<double>::infinity();
        }
    }
    for (;;) {
        const std::size_t cell = (static_cast<std::size_t>(c.z) * dims.y + c.y) * dims.x + c.x;
        candidates.insert(candidates.end(), accel.cellTets_.begin() + accel.cellStart_[cell],
                          accel.cellTets_.begin() + accel.cellStart_[cell + 1]);
        const int a = (tNext.x <= tNext.y && tNext.x <= tNext.z) ? 0 : (tNext.y <= tNext.z ? 1 : 2);
        if (tNext[a] > t1)
            break;
        c[a] += step[a];
        if (c[a] < 0 || c[a] >= dims[a])
            break;
        tNext[a] += tDelta[a];
    }
    std::sort(candidates.begin(), candidates.end());
    candidates.erase(std::unique(candidates.begin(), candidates.end()), candidates.end());

    // Clip the ray against the 4 face planes: n.(o + λ d) + w <= 0 on every face.
    for (const std::uint32_t t : candidates) {
        const TetAccel::Tet& tet = accel.tets_[t];
        double lamIn = 0.0, lamOut = std::numeric_limits<double>::infinity();
        double v[4], den[4];
        bool miss = false;
        for (int i = 0; i < 4 && !miss; ++i) {
            const glm::dvec3 n(tet.plane[i]);
            v[i] = glm::dot(n, ray.origin) + tet.plane[i].w;
            den[i] = glm::dot(n, ray.direction);
            if (den[i] > 0.0)
                lamOut = std::min(lamOut, -v[i] / den[i]);
            else if (den[i] < 0.0)
                lamIn = std::max(lamIn, -v[i] / den[i]);
            else if (v[i] > 0.0 || (v[i] == 0.0 && (tet.flipped >> i & 1u)))
                miss = true;  // parallel: outside; in the shared plane only the unflipped side counts
        }
        if (miss || !(lamOut > lamIn))
            continue;
        // Barycentric coordinates are linear in λ: b_i(λ) = (v_i + λ den_i) / height_i.
        double sIn = 0.0, sOut = 0.0;
        for (int i = 0; i < 4; ++i) {
            sIn += (v[i] + lamIn * den[i]) / tet.height[i] * tet.scalar[i];
            sOut += (v[i] + lamOut * den[i]) / tet.height[i] * tet.scalar[i];
        }
        out.push_back({accel.meshIndex_[t], lamIn, lamOut, sIn, sOut});
    }
    std::sort(out.begin(), out.end(), [](const TetSegment& p, const TetSegment& q) {
        if (p.lambdaIn != q.lambdaIn) return p.lambdaIn < q.lambdaIn;
        if (p.lambdaOut != q.lambdaOut) return p.lambdaOut < q.lambdaOut;
        return p.tet < q.tet;
    });
    return out;
}

// ---- integration ------------------------------------------------------------------------------------

namespace {

glm::dvec4 integrate(const std::vector<TetSegment>& segments, const TransferFunction& tf, std::uint64_t& pieces)
{
    const auto& cps = tf.points();
    glm::dvec3 intensity(0.0);
    double transmittance = 1.0;
    std::vector<double> cuts;  // s values at which the segment is cut, from s_in to s_out
    for (const TetSegment& seg : segments) {
        const double L = seg.lambdaOut - seg.lambdaIn;
        const double sF = seg.sIn, sB = seg.sOut;
        cuts.clear();
        cuts.push_back(sF);
        if (sF < sB) {
            for (const ControlPoint& p : cps)
                if (p.s > sF && p.s < sB)
                    cuts.push_back(p.s);
        } else if (sF > sB) {
            for (auto it = cps.rbegin(); it != cps.rend(); ++it)
                if (it->s < sF && it->s > sB)
                    cuts.push_back(it->s);
        }
        cuts.push_back(sB);
        // Between consecutive cuts s, τ and C are linear in λ: one closed-form piece each.
        glm::dvec4 front = tf(sF);
        double fracFront = 0.0;
        for (std::size_t k = 1; k < cuts.size(); ++k) {
            const double fracBack = (k + 1 == cuts.size()) ? 1.0 : (cuts[k] - sF) / (sB - sF);
            const glm::dvec4 back = tf(cuts[k]);
            const double l = L * (fracBack - fracFront);
            const glm::dvec4 piece = integrateLinearPiece(glm::dvec3(front), front.a, glm::dvec3(back), back.a, l);
            intensity += transmittance * glm::dvec3(piece);
            transmittance *= 1.0 - piece.a;
            ++pieces;
            front = back;
            fracFront = fracBack;
        }
    }
    return glm::dvec4(intensity, 1.0 - transmittance);
}

}  // namespace

glm::dvec4 integrateSegments(const std::vector<TetSegment>& segments, const TransferFunction& tf)
{
    std::uint64_t pieces = 0;
    return integrate(segments, tf, pieces);
}

Image4d tetReferenceIntegral(const TetAccel& accel, const TransferFunction& tf, const Camera& camera,
                             const ImageSpec& image, const TetReferenceOptions& options)
{
    Image4d out(image.width, image.height);
    std::atomic<int> nextRow{0};
    std::mutex statsMutex;
    TetReferenceStats total;
    auto worker = [&] {
        TetReferenceStats local;
        for (int y; (y = nextRow.fetch_add(1)) < image.height;) {
            for (int x = 0; x < image.width; ++x) {
                const std::vector<TetSegment> segments = traceRay(accel, camera.ray(x, y, image.width, image.height));
                const glm::dvec4 v = integrate(segments, tf, local.pieces);
                local.rays += segments.empty() ? 0 : 1;
                local.segments += segments.size();
                local.maxSegmentsPerRay = std::max(local.maxSegmentsPerRay, static_cast<int>(segments.size()));
                // Final pixel of DESIGN.md: I + (1 - A) * background, alpha = A.
                out.at(x, y) = glm::dvec4(glm::dvec3(v) + (1.0 - v.a) * image.background, v.a);
            }
        }
        std::lock_guard lock(statsMutex);
        total.rays += local.rays;
        total.segments += local.segments;
        total.pieces += local.pieces;
        total.maxSegmentsPerRay = std::max(total.maxSegmentsPerRay, local.maxSegmentsPerRay);
    };
    runOnThreads(options.threads, image.height, worker);
    if (options.stats)
        *options.stats = total;
    return out;
}

Image4d tetReferenceIntegral(const TetMesh& mesh, const TransferFunction& tf, const Camera& camera,
                             const ImageSpec& image, const TetReferenceOptions& options)
{
    return tetReferenceIntegral(TetAccel(mesh), tf, camera, image, options);
}

}  // namespace clvr
