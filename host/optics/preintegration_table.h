// host/optics/preintegration_table.h — the 3D table of full pre-integration (HARC-Full in
// seeds/001_cd12fd6b76f9cf96.txt §1 and Figure 8; Röttger et al. 2000, Roettger & Ertl 2002): for one
// transfer function, the premultiplied color and opacity of every segment along which s goes linearly
// from s_f (front, nearer the eye) to s_b (back) over a length l. kernels/harc.cl's "full" integration
// looks each cell's segment up in it instead of splitting it at control points. Unlike the ψ table of
// partial pre-integration (host/optics/psi_table.h) it depends on the transfer function: a change rebuilds it.
#pragma once

#include "host/model/transfer_function.h"

#include <glm/glm.hpp>

#include <cstdint>
#include <vector>

namespace clvr {

// Default resolution of the harc renderer: 64 x 64 samples in (s_f, s_b) and 64 in l (4 MiB).
inline constexpr int kFullTableScalarSamples = 64;
inline constexpr int kFullTableLengthSamples = 64;

struct PreintegrationTable {
    int scalarSamples = 0;   // NS: samples of s_f and of s_b
    int lengthSamples = 0;   // NL: samples of l
    double sLo = 0.0, sHi = 1.0;  // s_f, s_b sample i is at sLo + i (sHi - sLo) / (NS - 1)
    double lMax = 1.0;            // l sample k is at k lMax / (NL - 1), world units
    // values[(k * NS + j) * NS + i] = (premultiplied r, g, b, opacity α = 1 - T) of the segment
    // s_f = scalar(i), s_b = scalar(j), l = length(k). glm::vec4 has float4's 16 bytes.
    std::vector<glm::vec4> values;

    double scalar(int i) const { return sLo + (sHi - sLo) * i / (scalarSamples - 1); }
    double length(int k) const { return lMax * k / (lengthSamples - 1); }
    std::uint64_t bytes() const { return values.size() * sizeof(glm::vec4); }

    // Trilinear interpolation at (s_f, s_b, l) with s clamped to [sLo, sHi] and l to [0, lMax]: the
    // same float arithmetic as kernels/harc.cl's harc_full_lookup.
    glm::vec4 lookup(float sFront, float sBack, float l) const;
};

// Builds the table over s in [sLo, sHi] (sHi > sLo) and l in [0, lMax] (lMax > 0), 2 <= NS, NL. Every
// entry is the exact integral of host/optics/segment_integral.h (the segment cut at the control points, each
// piece in closed form, in double), rounded to float. `threads` host threads (<= 0: one per hardware
// thread) share the l slices.
PreintegrationTable buildPreintegrationTable(const TransferFunction& tf, double sLo, double sHi, double lMax,
                                             int scalarSamples, int lengthSamples, int threads = 0);

}  // namespace clvr
