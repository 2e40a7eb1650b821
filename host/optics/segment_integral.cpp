// host/optics/segment_integral.cpp — the exact emission-absorption integral of linear pieces and of
// segments cut at transfer-function control points (Eq. 2-4 of seeds/001_cd12fd6b76f9cf96.txt;
// derivation and numerical care in docs/tet-reference.md).
#include "host/optics/segment_integral.h"

#include <algorithm>
#include <cmath>
#include <limits>

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


// ---- segments ---------------------------------------------------------------------------------------

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

glm::dvec4 integrateSegments(const std::vector<TetSegment>& segments, const TransferFunction& tf,
                             std::uint64_t* pieces)
{
    std::uint64_t counted = 0;
    const glm::dvec4 result = integrate(segments, tf, counted);
    if (pieces)
        *pieces += counted;
    return result;
}

}  // namespace clvr
