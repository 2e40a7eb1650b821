// kernels/harc.cl — hardware-assisted ray casting of tetrahedral meshes with partial pre-integration
// (§3–4 and Figure 6 of seeds/001_cd12fd6b76f9cf96.txt). One work-item per pixel walks its ray from
// tetrahedron to tetrahedron through the adjacency, splits each tetrahedron's segment at the transfer
// function's control points, integrates each piece by Eq. 2 with ζ (Eq. 3) and ψ (Eq. 4, 2D table),
// and composites front to back; or, with full pre-integration (HARC-Full, Figure 8), looks each whole
// segment up in a 3D table over (s_f, s_b, l) built for the transfer function (host/optics/preintegration_table.h).
// Entry points come from a per-pixel list of boundary-face crossings
// sorted by depth (host/render/tet/harc.cpp); after the ray leaves the mesh it re-enters at the next one.
// The host has validated everything; this file only does arithmetic.
#include "clvr_common.h"

/* Per tetrahedron, 5 float4 = 80 bytes (Table 1 of seeds/001 uses 96), host/render/tet/harc.h:
 *   [0..2] barycentric planes (h_i, k_i), i = 0, 1, 2: b_i(x) = dot(h_i, x) + k_i is 1 at vertex i and
 *          0 on face i (the face opposite vertex i). The fourth is recomputed, Σ b_i = 1:
 *          h_3 = -(h_0 + h_1 + h_2), k_3 = 1 - (k_0 + k_1 + k_2).
 *   [3]    gradient g and scalar term g0 of Eq. 6: s(x) = dot(g, x) + g0.
 *   [4]    adjacency a_0..a_3 (as_int4): across face i, neighbor * 4 + the neighbor's face that is
 *          face i (the next cell's entry face, with no second load), or -1 on the boundary.
 * Face i is left along d where dot(h_i, d) < 0, at λ_i = λ + b_i(p) / -dot(h_i, d). */
#define HARC_TET_FLOAT4S 5

#define HARC_INTEGRATION_PARTIAL 0
#define HARC_INTEGRATION_AVERAGE 1
#define HARC_INTEGRATION_FULL 2

/* ψ of Eq. 4 from the γ-table of host/optics/psi_table.h (bilinear; same arithmetic as PsiTable::lookup). */
float harc_psi(global const float* psi, const int n, float tau_l_front, float tau_l_back)
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
void harc_piece(global const float* psi, const int psi_n, const float4 cf, const float4 cb, const float l,
                float3* color, float* transmittance)
{
    const float tf = cf.w * l, tb = cb.w * l;
    const float zeta = exp(-0.5f * (tf + tb));          /* Eq. 3 */
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

/* The segment from s_f (front, ray parameter 0) to s_b (back, length l) inside one tetrahedron,
 * split at every control point strictly between s_f and s_b (Figure 5's s_iso / next_s_iso: the
 * first control point past the current s in the direction of travel; searching with a strict
 * inequality from the current s returns next_s_iso exactly where Figure 6 has to step past
 * s_f == s_iso). Returns the number of pieces. */
int harc_segment(global const float* tf, const int n, global const float* psi, const int psi_n, const float s_f,
                 const float s_b, const float l, float3* color, float* transmittance)
{
    const int k_f = harc_upper(tf, n, s_f);
    float4 c_front = harc_tf_at(tf, n, k_f, s_f);
    if (!(s_b != s_f)) {  /* s constant along the ray: one piece with constant C and τ */
        harc_piece(psi, psi_n, c_front, c_front, l, color, transmittance);
        return 1;
    }
    const float inv_ds = 1.0f / (s_b - s_f);
    global const float* value = tf + ((n + 3) & ~3);
    float lambda_front = 0.0f;
    int pieces = 0;
    if (s_b > s_f) {
        for (int k = k_f; k < n && tf[k] < s_b; ++k) {  /* tf[k] > s_f: the next iso-surface ahead */
            const float lambda = l * ((tf[k] - s_f) * inv_ds);
            const float4 c_iso = vload4(k, value);
            harc_piece(psi, psi_n, c_front, c_iso, lambda - lambda_front, color, transmittance);
            c_front = c_iso;
            lambda_front = lambda;
            ++pieces;
        }
    } else {
        /* Points equal to s_f are at the front end, not ahead: start below them. */
        int k = k_f - 1;
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
    }
    const float4 c_back = harc_tf_at(tf, n, harc_upper(tf, n, s_b), s_b);
    harc_piece(psi, psi_n, c_front, c_back, l - lambda_front, color, transmittance);
    return pieces + 1;
}

/* The plain average-of-endpoints segment (the comparison of issue 3 part 6): constant C and τ, the
 * means of their values at s_f and s_b: C (1 - exp(-τ l)). */
void harc_segment_average(global const float* tf, const int n, const float s_f, const float s_b, const float l,
                          float3* color, float* transmittance)
{
    const float4 c = 0.5f * (harc_tf_at(tf, n, harc_upper(tf, n, s_f), s_f) +
                             harc_tf_at(tf, n, harc_upper(tf, n, s_b), s_b));
    const float zeta = exp(-c.w * l);
    *color += *transmittance * (1.0f - zeta) * c.xyz;
    *transmittance *= zeta;
}

/* Full pre-integration: trilinear lookup of the segment (s_f -> s_b over length l) in the table of
 * host/optics/preintegration_table.h, table[(k * ns + j) * ns + i] = (premultiplied rgb, α) at s_f sample i,
 * s_b sample j, l sample k. params = (s of sample 0, samples per unit s, samples per unit l); s is
 * clamped to the sampled range and l to l_max (no segment is longer than the longest tet edge). Manual
 * interpolation on a plain buffer, so that it runs where 3D images of float4 are missing or small; the
 * same float arithmetic as PreintegrationTable::lookup. */
float4 harc_full_lookup(global const float4* table, const int ns, const int nl, const float4 params,
                        const float s_f, const float s_b, const float l)
{
    const float ns1 = (float)(ns - 1), nl1 = (float)(nl - 1);
    const float x = clamp((s_f - params.x) * params.y, 0.0f, ns1);
    const float y = clamp((s_b - params.x) * params.y, 0.0f, ns1);
    const float z = clamp(l * params.z, 0.0f, nl1);
    const int i = min((int)x, ns - 2), j = min((int)y, ns - 2), k = min((int)z, nl - 2);
    const float fx = x - (float)i, fy = y - (float)j, fz = z - (float)k;
    global const float4* c = table + ((size_t)k * ns + j) * ns + i;
    const size_t dj = (size_t)ns, dk = (size_t)ns * ns;
    const float4 c00 = c[0] + fx * (c[1] - c[0]);
    const float4 c10 = c[dj] + fx * (c[dj + 1] - c[dj]);
    const float4 c01 = c[dk] + fx * (c[dk + 1] - c[dk]);
    const float4 c11 = c[dk + dj] + fx * (c[dk + dj + 1] - c[dk + dj]);
    const float4 c0 = c00 + fy * (c10 - c00);
    const float4 c1 = c01 + fy * (c11 - c01);
    return c0 + fz * (c1 - c0);
}

/* One work-item per pixel. entries[offsets[p] .. offsets[p+1]) are the boundary front-face crossings
 * of pixel p's ray, sorted by ray parameter: (λ as float bits, tet * 4 + face). Camera: position,
 * forward, right, up (orthonormal, relative to the mesh's shifted origin); params: x = tan(view_angle
 * / 2) or parallel_scale, y = aspect, z = 1 for a parallel camera. Ray e + λ d, |d| = 1, as
 * host/model/camera.cpp's Camera::ray. stats[p] = (steps, 1 if the step bound stopped the ray, pieces).
 * integration: HARC_INTEGRATION_*; full_table, full_ns, full_nl, full_params: harc_full_lookup's table
 * (a one-element dummy unless integration is full). Out: (I + T background, 1 - T). */
kernel void harc_render(global float4* out, global uint* stats, const int width, const int height,
                        global const float4* tets, global const uint* offsets, global const int2* entries,
                        global const float* tf, const int tf_count, global const float* psi, const int psi_n,
                        const float4 cam_position, const float4 cam_forward, const float4 cam_right,
                        const float4 cam_up, const float4 cam_params, const uint max_steps, const int integration,
                        const float ert_alpha, const float4 background, global const float4* full_table,
                        const int full_ns, const int full_nl, const float4 full_params)
{
    CLVR_GUARD_2D(width, height);
    const int x = (int)get_global_id(0), y = (int)get_global_id(1);
    const int p = y * width + x;
    const float ndc_x = ((float)x + 0.5f) / (float)width * 2.0f - 1.0f;
    const float ndc_y = 1.0f - ((float)y + 0.5f) / (float)height * 2.0f;
    const float sx = ndc_x * cam_params.x * cam_params.y, sy = ndc_y * cam_params.x;
    float3 e, d;
    if (cam_params.z != 0.0f) {
        e = cam_position.xyz + sx * cam_right.xyz + sy * cam_up.xyz;
        d = cam_forward.xyz;
    } else {
        e = cam_position.xyz;
        d = normalize(cam_forward.xyz + sx * cam_right.xyz + sy * cam_up.xyz);
    }

    float3 color = (float3)(0.0f);
    float transmittance = 1.0f;
    uint steps = 0, bounded = 0, pieces = 0;
    float lambda_done = -INFINITY;  /* where the ray last left the mesh */
    const uint end = offsets[p + 1];
    for (uint k = offsets[p]; k < end && !bounded; ++k) {
        const int2 entry = entries[k];
        float lambda = as_float(entry.x);
        /* Crossings the walk has passed (and duplicates on shared edges) lie before lambda_done. */
        if (lambda < lambda_done - 1e-5f * (1.0f + fabs(lambda_done)))
            continue;
        lambda = fmax(lambda, lambda_done);
        int t = entry.y >> 2;
        int entry_face = entry.y & 3;
        for (;;) {
            if (steps >= max_steps) {
                bounded = 1;
                break;
            }
            ++steps;
            global const float4* tet = tets + (size_t)t * HARC_TET_FLOAT4S;
            const float4 p0 = tet[0], p1 = tet[1], p2 = tet[2], grad = tet[3];
            const int4 adj = as_int4(tet[4]);
            const float4 p3 = (float4)(-(p0.xyz + p1.xyz + p2.xyz), 1.0f - (p0.w + p1.w + p2.w));
            const float3 pos = e + lambda * d;
            /* Exit: the nearest face ahead, not the one the ray came in through (Figure 6 lines 3–8). */
            float step = INFINITY;
            int exit_face = -1;
            const float4 planes[4] = {p0, p1, p2, p3};
            for (int i = 0; i < 4; ++i) {
                const float hd = dot(planes[i].xyz, d);
                if (i != entry_face && hd < 0.0f) {
                    const float s = fmax(dot(planes[i].xyz, pos) + planes[i].w, 0.0f) / -hd;
                    if (s < step) {
                        step = s;
                        exit_face = i;
                    }
                }
            }
            if (exit_face < 0) {  /* grazing a degenerate cell: leave the mesh here */
                lambda_done = lambda;
                break;
            }
            const float lambda_exit = lambda + step;
            const float s_f = dot(grad.xyz, pos) + grad.w;                       /* Eq. 6 */
            const float s_b = dot(grad.xyz, e + lambda_exit * d) + grad.w;
            if (integration == HARC_INTEGRATION_FULL) {
                /* The whole segment at once: no split at control points (the table has them inside). */
                const float4 c = harc_full_lookup(full_table, full_ns, full_nl, full_params, s_f, s_b, step);
                color += transmittance * c.xyz;
                transmittance *= 1.0f - c.w;
                ++pieces;
            } else if (integration == HARC_INTEGRATION_AVERAGE) {
                harc_segment_average(tf, tf_count, s_f, s_b, step, &color, &transmittance);
                ++pieces;
            } else {
                pieces += (uint)harc_segment(tf, tf_count, psi, psi_n, s_f, s_b, step, &color, &transmittance);
            }
            if (1.0f - transmittance >= ert_alpha) {  /* early ray termination (off: ert_alpha = 2) */
                k = end;
                break;
            }
            const int next = exit_face == 0 ? adj.x : (exit_face == 1 ? adj.y : (exit_face == 2 ? adj.z : adj.w));
            lambda = lambda_exit;
            if (next < 0) {
                lambda_done = lambda_exit;
                break;
            }
            t = next >> 2;
            entry_face = next & 3;
        }
        if (k >= end)
            break;
    }
    out[p] = (float4)(color + transmittance * background.xyz, 1.0f - transmittance);
    stats[3 * p + 0] = steps;
    stats[3 * p + 1] = bounded;
    stats[3 * p + 2] = pieces;
}
