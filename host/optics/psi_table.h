// host/optics/psi_table.h — ψ of partial pre-integration (Eq. 4 of seeds/001_cd12fd6b76f9cf96.txt, Moreland &
// Angel 2004) as a 2D table over γ = τl / (1 + τl) ∈ [0, 1], so the whole range τl ∈ [0, ∞) fits.
// The table depends on nothing else (not the transfer function): it is built once per process.
//
//   ψ(τ_f l, τ_b l) = ∫_0^1 exp(-(F u + (B - F) u² / 2)) du,  F = τ_f l, B = τ_b l,
//
// u the distance from the segment's front end (towards the eye) in units of l; this is Eq. 4 with
// λ = 1 - u. The segment's color is then Eq. 2: C_b (ψ - ζ) + C_f (1 - ψ), opacity 1 - ζ.
#pragma once

#include <vector>

namespace clvr {

// Resolution used by the harc renderer: 512 x 512 samples (1 MiB as float32).
inline constexpr int kPsiTableSize = 512;

// ψ by quadrature in double (16-point Gauss-Legendre on 15 panels graded towards u = 0; relative
// error below 1e-12 for F, B <= 1e4). F = τ_f l >= 0, B = τ_b l >= 0; infinite values give the limit 0.
double psiNumerical(double tauLFront, double tauLBack);

// The table: values[j * size + i] = ψ at γ_f = i / (size - 1), γ_b = j / (size - 1); the last row and
// column (γ = 1, τl = ∞) hold the limit 0.
struct PsiTable {
    int size = 0;
    std::vector<float> values;
    // Bilinear lookup in (γ_f, γ_b), the same arithmetic as kernels/harc.cl's harc_psi (float).
    float lookup(float tauLFront, float tauLBack) const;
};

PsiTable buildPsiTable(int size);

// The process-wide table of kPsiTableSize, built on first use (thread-safe).
const PsiTable& psiTable();

}  // namespace clvr
