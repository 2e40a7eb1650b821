// tools/ceiling_segment.h — kernels/segment_integral.h in plain C++ for the ceiling loops: partial pre-integration
// of one linear segment (seeds/001 §3–4, Figure 6) with ψ from the same γ-table (host/optics/psi_table.h) and the
// transfer function in packTransferFunction's blocks (s, values, slopes), function for function in float. Shared
// by harc's ceiling (tools/ceiling_harc.h, the walk's segments) and slice3d's (tools/ceiling.h, the pre-integrated
// slabs). Not part of the library.
#pragma once

#include "host/model/transfer_function.h"
#include "host/optics/psi_table.h"
#include "host/render/transfer_function_upload.h"

#include <glm/glm.hpp>

#include <algorithm>
#include <cmath>
#include <vector>

namespace clvr::tools {

class CeilingSegments {
public:
    // One end of a segment: kernels/segment_integral.h's HarcTfPoint (s, the number of control points <= s, and
    // the transfer function there).
    struct Point {
        float s;
        int k;
        glm::vec4 c;
    };

    explicit CeilingSegments(const TransferFunction& tf) : psi_(psiTable())
    {
        const std::vector<float> packed = packTransferFunction(tf);
        const std::size_t n = tf.points().size(), m = (n + 3) / 4 * 4;
        for (std::size_t i = 0; i < n; ++i) {
            s_.push_back(packed[i]);
            value_.emplace_back(packed[m + 4 * i], packed[m + 4 * i + 1], packed[m + 4 * i + 2], packed[m + 4 * i + 3]);
            const float* slope = &packed[m + 4 * n + 4 * i];
            slope_.emplace_back(slope[0], slope[1], slope[2], slope[3]);
        }
    }

    // harc_psi: ψ of Eq. 4, bilinear in the γ-table.
    float psi(float tauLFront, float tauLBack) const
    {
        const int n = psi_.size;
        const float f = std::min(tauLFront, 1e30f), b = std::min(tauLBack, 1e30f);
        const float n1 = static_cast<float>(n - 1);
        const float x = f / (1.0f + f) * n1, y = b / (1.0f + b) * n1;
        const int i = std::min(static_cast<int>(x), n - 2), j = std::min(static_cast<int>(y), n - 2);
        const float fx = x - static_cast<float>(i), fy = y - static_cast<float>(j);
        const float* r0 = psi_.values.data() + j * n + i;
        const float* r1 = r0 + n;
        const float a = r0[0] + fx * (r0[1] - r0[0]);
        const float c = r1[0] + fx * (r1[1] - r1[0]);
        return a + fy * (c - a);
    }

    // harc_piece: one linear piece of length l (Eq. 2–4) composited under what is in front.
    void piece(const glm::vec4& cf, const glm::vec4& cb, float l, glm::vec3& color, float& transmittance) const
    {
        const float tf = cf.w * l, tb = cb.w * l;
        if (tf == 0.0f && tb == 0.0f)
            return;
        const float zeta = std::exp2(-0.5f * 1.44269504f * (tf + tb));
        const float p = psi(tf, tb);
        color += transmittance * (glm::vec3(cb) * (p - zeta) + glm::vec3(cf) * (1.0f - p));
        transmittance *= zeta;
    }

    // harc_tf_at: the transfer function at x given k = the number of control points <= x.
    glm::vec4 tfAt(int k, float x) const
    {
        const int n = count();
        if (k == 0)
            return value_[0];
        if (k == n)
            return value_[n - 1];
        return value_[k - 1] + (x - s_[k - 1]) * slope_[k - 1];
    }

    // harc_upper: the number of control points s_i <= x, by bisection.
    int upper(float x) const
    {
        int lo = 0, hi = count();
        while (lo < hi) {
            const int mid = (lo + hi) >> 1;
            if (s_[mid] <= x)
                lo = mid + 1;
            else
                hi = mid;
        }
        return lo;
    }

    // harc_tf_point
    Point point(float s) const
    {
        const int k = upper(s);
        return {s, k, tfAt(k, s)};
    }

    // harc_segment_from: the segment from front.s to sB (length l) split at the control points strictly between
    // its ends; returns the pieces, and in `back` its back end (the next segment's front).
    int segment(const Point& front, float sB, float l, glm::vec3& color, float& transmittance, Point& back) const
    {
        const int n = count();
        const float sF = front.s;
        glm::vec4 cFront = front.c;
        if (!(sB != sF)) {
            piece(cFront, cFront, l, color, transmittance);
            back = front;
            return 1;
        }
        const float invDs = 1.0f / (sB - sF);
        float lambdaFront = 0.0f;
        int pieces = 0, kB;
        if (sB > sF) {
            int k = front.k;
            for (; k < n && s_[k] < sB; ++k) {
                const float lambda = l * ((s_[k] - sF) * invDs);
                piece(cFront, value_[k], lambda - lambdaFront, color, transmittance);
                cFront = value_[k];
                lambdaFront = lambda;
                ++pieces;
            }
            kB = k < n && s_[k] <= sB ? k + 1 : k;
        } else {
            int k = front.k - 1;
            while (k >= 0 && s_[k] >= sF)
                --k;
            for (; k >= 0 && s_[k] > sB; --k) {
                const float lambda = l * ((s_[k] - sF) * invDs);
                piece(cFront, value_[k], lambda - lambdaFront, color, transmittance);
                cFront = value_[k];
                lambdaFront = lambda;
                ++pieces;
            }
            kB = k + 1;
        }
        back = {sB, kB, tfAt(kB, sB)};
        piece(cFront, back.c, l - lambdaFront, color, transmittance);
        return pieces + 1;
    }

    int count() const { return static_cast<int>(s_.size()); }

private:
    const PsiTable& psi_;
    std::vector<float> s_;            // control points' s (packTransferFunction's first block)
    std::vector<glm::vec4> value_;    // their (r, g, b, tau)
    std::vector<glm::vec4> slope_;    // d(r, g, b, tau)/ds of the segment after each point
};

}  // namespace clvr::tools
