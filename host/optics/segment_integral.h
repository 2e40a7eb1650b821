// host/optics/segment_integral.h — the exact emission-absorption integral (DESIGN.md's optical model) of
// one linear piece and of a ray's segments through linear cells, each cut at the transfer function's
// control points so that τ and C are linear on every piece, each piece integrated in closed form
// (Williams, Max & Stein 1998; Moreland & Angel 2004; seeds/001 Eq. 2-4) — no quadrature. Production code
// (the full pre-integration table is built from it) and the core of the tetrahedral CPU reference.
#pragma once

#include "host/model/transfer_function.h"

#include <glm/glm.hpp>

#include <cstdint>
#include <vector>

namespace clvr {

// ---- one linear piece -------------------------------------------------------------------------------

// The two transfer-function-free terms of a linear piece of optical depths a = tau_f l (front, the end
// nearer the eye) and b = tau_b l (back): zeta = exp(-(a + b)/2) (Eq. 3) and
// psi = ∫0^1 exp(-∫0^t (a (1-u) + b u) du) dt (Eq. 4, written from the front), with their complements
// computed without cancellation.
struct PsiZeta {
    double psi = 1.0;
    double zeta = 1.0;
    double oneMinusPsi = 0.0;   // 1 - psi
    double psiMinusZeta = 0.0;  // psi - zeta
    double oneMinusZeta = 0.0;  // 1 - zeta: the piece's opacity
};
// a, b >= 0 and finite (optical depths, dimensionless). Relative error a few 1e-16 (see docs).
PsiZeta psiZeta(double a, double b);

// A linear piece of length l (world units) whose extinction goes from tauF (front) to tauB (back) and
// emitted color from colorF to colorB: premultiplied color C_b (psi - zeta) + C_f (1 - psi) in rgb and
// opacity 1 - zeta in a. Composite front to back as I += T * rgb, T *= 1 - a.
glm::dvec4 integrateLinearPiece(glm::dvec3 colorF, double tauF, glm::dvec3 colorB, double tauB, double l);

// A ray's passage through one tetrahedron: ray parameters (world units along the unit direction) and
// the linearly interpolated scalar at both ends.
struct TetSegment {
    std::uint32_t tet = 0;
    double lambdaIn = 0.0;
    double lambdaOut = 0.0;
    double sIn = 0.0;
    double sOut = 0.0;
};

// The composited (I.r, I.g, I.b, A) of one ray's segments, front to back (no background).
// `pieces`, when not null, is incremented by the number of linear pieces integrated.
glm::dvec4 integrateSegments(const std::vector<TetSegment>& segments, const TransferFunction& tf,
                             std::uint64_t* pieces = nullptr);

}  // namespace clvr
