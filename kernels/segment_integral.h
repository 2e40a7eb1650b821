/* kernels/segment_integral.h — partial pre-integration of one linear segment (§3–4 and Figure 6 of
 * seeds/001_cd12fd6b76f9cf96.txt): ψ from the γ-table of host/optics/psi_table.h, one piece by Eq. 2–4,
 * and a whole segment (s_f, s_b, l) split at the transfer function's control points. Shared by
 * kernels/harc.cl (ray casting) and kernels/projtet.cl (cell projection, per fragment). OpenCL C 1.2. */
#ifndef CLVR_SEGMENT_INTEGRAL_H
#define CLVR_SEGMENT_INTEGRAL_H

#include "clvr_common.h"

/* ψ of Eq. 4 from the γ-table of host/optics/psi_table.h (bilinear; same arithmetic as PsiTable::lookup).
 * This and harc_piece are inlined into the loops that call them: PoCL otherwise calls harc_piece once per
 * piece with the color and transmittance through memory (harc's walk 4 % slower, BENCHMARKS.md). */
__attribute__((always_inline)) float harc_psi(global const float* psi, const int n, float tau_l_front, float tau_l_back)
{
    const float f = fmin(tau_l_front, 1e30f), b = fmin(tau_l_back, 1e30f);
    const float n1 = (float)(n - 1);
    const float x = f / (1.0f + f) * n1, y = b / (1.0f + b) * n1;
    const int i = min((int)x, n - 2), j = min((int)y, n - 2);
    const float fx = x - (float)i, fy = y - (float)j;
    global const float* r0 = psi + j * n + i;
    global const float* r1 = r0 + n;
    const float a = r0[0] + fx * (r0[1] - r0[0]);
    const float c = r1[0] + fx * (r1[1] - r1[0]);
    return a + fy * (c - a);
}

/* One linear piece of length l with (C, τ) = cf at the front and cb at the back (Eq. 2, I_0 = 0):
 * composited under what is in front: color += T I, T *= ζ. */
__attribute__((always_inline)) void harc_piece(global const float* psi, const int psi_n, const float4 cf,
                                               const float4 cb, const float l, float3* color, float* transmittance)
{
    const float tf = cf.w * l, tb = cb.w * l;
    if (tf == 0.0f && tb == 0.0f)  /* τ is linear along the piece, so 0 all along it: ζ = ψ = 1, nothing to add */
        return;
    const float zeta = clvr_exp2(-0.5f * M_LOG2E_F * (tf + tb));  /* Eq. 3 */
    const float p = harc_psi(psi, psi_n, tf, tb);        /* Eq. 4 */
    const float3 c = cb.xyz * (p - zeta) + cf.xyz * (1.0f - p);  /* Eq. 2 */
    *color += *transmittance * c;
    *transmittance *= zeta;
}

/* Transfer function (kernels/transfer_function.h's layout: s, then values, then slopes) at x, given
 * k = the number of control points <= x (0 .. n). */
float4 harc_tf_at(global const float* tf, const int n, const int k, const float x)
{
    global const float* value = tf + ((n + 3) & ~3);
    global const float* slope = value + 4 * n;
    if (k == 0)
        return vload4(0, value);
    if (k == n)
        return vload4(n - 1, value);
    return vload4(k - 1, value) + (x - tf[k - 1]) * vload4(k - 1, slope);
}

/* The number of control points s_i <= x (upper bound), by bisection. */
int harc_upper(global const float* tf, const int n, const float x)
{
    int lo = 0, hi = n;
    while (lo < hi) {
        const int mid = (lo + hi) >> 1;
        if (tf[mid] <= x)
            lo = mid + 1;
        else
            hi = mid;
    }
    return lo;
}

/* One end of a segment: the scalar s, k = the number of control points <= s, and the transfer function
 * there (harc_tf_at(tf, n, k, s)). */
typedef struct {
    float s;
    int k;
    float4 c;
} HarcTfPoint;

HarcTfPoint harc_tf_point(global const float* tf, const int n, const float s)
{
    HarcTfPoint q;
    q.s = s;
    q.k = harc_upper(tf, n, s);
    q.c = harc_tf_at(tf, n, q.k, s);
    return q;
}

/* The segment from front.s (ray parameter 0) to s_b (length l) inside one tetrahedron, split at every
 * control point strictly between them (Figure 5's s_iso / next_s_iso: the first control point past the
 * current s in the direction of travel; searching with a strict inequality from the current s returns
 * next_s_iso exactly where Figure 6 has to step past s_f == s_iso). Returns the number of pieces, and in
 * *back the segment's back end: its k comes from the split's own walk over the control points (no second
 * search), so a ray walk can hand it to the next cell as that segment's front (kernels/harc.cl). */
int harc_segment_from(global const float* tf, const int n, global const float* psi, const int psi_n,
                      const HarcTfPoint front, const float s_b, const float l, float3* color, float* transmittance,
                      HarcTfPoint* back)
{
    const float s_f = front.s;
    float4 c_front = front.c;
    if (!(s_b != s_f)) {  /* s constant along the ray: one piece with constant C and τ */
        harc_piece(psi, psi_n, c_front, c_front, l, color, transmittance);
        *back = front;
        return 1;
    }
    const float inv_ds = 1.0f / (s_b - s_f);
    global const float* value = tf + ((n + 3) & ~3);
    float lambda_front = 0.0f;
    int pieces = 0, k_b;
    if (s_b > s_f) {
        int k = front.k;
        for (; k < n && tf[k] < s_b; ++k) {  /* tf[k] > s_f: the next iso-surface ahead */
            const float lambda = l * ((tf[k] - s_f) * inv_ds);
            const float4 c_iso = vload4(k, value);
            harc_piece(psi, psi_n, c_front, c_iso, lambda - lambda_front, color, transmittance);
            c_front = c_iso;
            lambda_front = lambda;
            ++pieces;
        }
        /* tf[k] >= s_b (or k == n): the points <= s_b are those before k, and tf[k] if it equals s_b
         * (the points increase strictly, so at most one does). */
        k_b = k < n && tf[k] <= s_b ? k + 1 : k;
    } else {
        /* Points equal to s_f are at the front end, not ahead: start below them. */
        int k = front.k - 1;
        while (k >= 0 && tf[k] >= s_f)
            --k;
        for (; k >= 0 && tf[k] > s_b; --k) {
            const float lambda = l * ((tf[k] - s_f) * inv_ds);
            const float4 c_iso = vload4(k, value);
            harc_piece(psi, psi_n, c_front, c_iso, lambda - lambda_front, color, transmittance);
            c_front = c_iso;
            lambda_front = lambda;
            ++pieces;
        }
        k_b = k + 1;  /* tf[0 .. k] <= s_b < tf[k + 1] */
    }
    back->s = s_b;
    back->k = k_b;
    back->c = harc_tf_at(tf, n, k_b, s_b);
    harc_piece(psi, psi_n, c_front, back->c, l - lambda_front, color, transmittance);
    return pieces + 1;
}

/* The same from the scalars at both ends (kernels/projtet.cl: one fragment's segment). */
int harc_segment(global const float* tf, const int n, global const float* psi, const int psi_n, const float s_f,
                 const float s_b, const float l, float3* color, float* transmittance)
{
    HarcTfPoint back;
    return harc_segment_from(tf, n, psi, psi_n, harc_tf_point(tf, n, s_f), s_b, l, color, transmittance, &back);
}

#endif
