// host/optics/psi_table.cpp — ψ of Eq. 4 (seeds/001) by quadrature, and its γ-parameterized 2D table.
#include "host/optics/psi_table.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <mutex>

namespace clvr {
namespace {

constexpr int kGaussPoints = 16;

struct GaussLegendre {
    std::array<double, kGaussPoints> x{}, w{};  // nodes and weights on [-1, 1]
    GaussLegendre()
    {
        const double pi = std::acos(-1.0);
        for (int i = 0; i < kGaussPoints; ++i) {
            double z = std::cos(pi * (i + 0.75) / (kGaussPoints + 0.5));
            double dp = 0.0;
            for (int it = 0; it < 100; ++it) {  // Newton on P_n
                double p0 = 1.0, p1 = z;
                for (int k = 2; k <= kGaussPoints; ++k) {
                    const double p2 = ((2.0 * k - 1.0) * z * p1 - (k - 1.0) * p0) / k;
                    p0 = p1;
                    p1 = p2;
                }
                dp = kGaussPoints * (z * p1 - p0) / (z * z - 1.0);
                const double dz = p1 / dp;
                z -= dz;
                if (std::abs(dz) < 1e-16)
                    break;
            }
            x[i] = z;
            w[i] = 2.0 / ((1.0 - z * z) * dp * dp);
        }
    }
};

const GaussLegendre& gauss()
{
    static const GaussLegendre g;
    return g;
}

}  // namespace

double psiNumerical(double tauLFront, double tauLBack)
{
    const double f = tauLFront, b = tauLBack;
    if (std::isinf(f) || std::isinf(b))
        return 0.0;
    const GaussLegendre& g = gauss();
    // Panels [0, 2^-14], [2^-14, 2^-13], ..., [1/2, 1]: the integrand falls off on the scale
    // min(1/F, 1/sqrt(B)) from u = 0, so each panel sees a smooth, slowly varying exponential.
    double sum = 0.0;
    double lo = 0.0, hi = std::ldexp(1.0, -14);
    while (lo < 1.0) {
        const double half = 0.5 * (hi - lo), mid = 0.5 * (hi + lo);
        double panel = 0.0;
        for (int k = 0; k < kGaussPoints; ++k) {
            const double u = mid + half * g.x[k];
            panel += g.w[k] * std::exp(-(f * u + 0.5 * (b - f) * u * u));
        }
        sum += half * panel;
        lo = hi;
        hi = std::min(1.0, 2.0 * hi);
    }
    return sum;
}

PsiTable buildPsiTable(int size)
{
    PsiTable t;
    t.size = size;
    t.values.assign(static_cast<std::size_t>(size) * size, 0.0f);
    auto tauL = [size](int i) {
        const double gamma = static_cast<double>(i) / (size - 1);
        return i == size - 1 ? INFINITY : gamma / (1.0 - gamma);  // γ = τl / (1 + τl)
    };
    for (int j = 0; j < size; ++j)
        for (int i = 0; i < size; ++i)
            t.values[static_cast<std::size_t>(j) * size + i] = static_cast<float>(psiNumerical(tauL(i), tauL(j)));
    return t;
}

float PsiTable::lookup(float tauLFront, float tauLBack) const
{
    // Same operations and order as kernels/harc.cl (harc_psi).
    const float n1 = static_cast<float>(size - 1);
    const float f = std::min(tauLFront, 1e30f), b = std::min(tauLBack, 1e30f);  // γ(∞) = 1, not ∞/∞
    const float x = f / (1.0f + f) * n1, y = b / (1.0f + b) * n1;
    const int i = std::min(static_cast<int>(x), size - 2), j = std::min(static_cast<int>(y), size - 2);
    const float fx = x - static_cast<float>(i), fy = y - static_cast<float>(j);
    const float* r0 = values.data() + static_cast<std::size_t>(j) * size + i;
    const float* r1 = r0 + size;
    const float a = r0[0] + fx * (r0[1] - r0[0]);
    const float c = r1[0] + fx * (r1[1] - r1[0]);
    return a + fy * (c - a);
}

const PsiTable& psiTable()
{
    static std::once_flag once;
    static PsiTable table;
    std::call_once(once, [] { table = buildPsiTable(kPsiTableSize); });
    return table;
}

}  // namespace clvr
