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
#include "harc_params.h"
#include "ray.h"
#include "packet.h"
#include "segment_integral.h"
#include "segment_integral8.h"
#include "transfer_function.h"

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
#define HARC_INTEGRATION_SLICES 3
#define HARC_INTEGRATION_ISO 4

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

/* tetslice's fused path (HARC_INTEGRATION_SLICES; host/render/tet/tetslice.cpp): the slices of constant eye
 * depth z_k = z0 + k ds (k < count) whose ray parameter λ_k = z_k / df lies in this cell's [seg_f, seg_b),
 * each one sample of the cell's linear field s(x) = dot(grad, x) + g0 at e + λ_k d — the scalar
 * seeds/000 §4.2 interpolates between the cell's two faces at the slice —, classified and composited front
 * to back with alpha = 1 - exp(-tau ds / df) (ds / df: the ray's length between slices; df = dot(d, forward),
 * the eye depth per unit λ). λ_k is the same expression in every cell, so a slice on a shared face is taken
 * once, by the cell beyond it. Returns the slices taken. */
uint harc_slices(global const float* tf, const int tf_count, const float4 slices, const float df, const float3 e,
                 const float3 d, const float4 grad, const float seg_f, const float seg_b, float3* color,
                 float* transmittance)
{
    const float z0 = slices.x, ds = slices.y;
    const int count = (int)slices.z;
    const float neg_log2e = -(ds / df) * M_LOG2E_F;
    int k = max((int)ceil((seg_f * df - z0) / ds) - 1, 0); /* one before the first, for rounding */
    uint taken = 0;
    for (; k < count; ++k) {
        const float lambda_k = (z0 + (float)k * ds) / df;
        if (!(lambda_k < seg_b))
            break;
        if (lambda_k < seg_f)
            continue;
        const float4 ct = clvr_tf_eval(tf, tf_count, harc_dot3(grad.xyz, e + lambda_k * d) + grad.w);
        const float alpha = 1.0f - clvr_exp2(ct.w * neg_log2e);
        *color += (*transmittance * alpha) * ct.xyz;
        *transmittance *= 1.0f - alpha;
        ++taken;
    }
    return taken;
}

/* tetiso's fused path (HARC_INTEGRATION_ISO; host/render/tet/tetiso.cpp): the cell's linear field crosses the
 * iso-value between its entry point (scalar s_f, at λ seg_f) and exit point (s_b, at seg_b) — upwards where
 * s_f <= iso < s_b, downwards where s_f >= iso > s_b, the alpha tests of the raster path's back and front
 * faces (seeds/000 §4.1) — at q = (iso - s_f) / (s_b - s_f). The shade is the raster path's (1 - q) I_f +
 * q I_b: I at a point is color (ambient + diffuse <light, N>) with N the vertex normals interpolated
 * barycentrically (Gouraud on the cell's faces), linear in N, so the blend of the two shades is the shade
 * of the blended normal. normals: the cell's 3 float4, the x, y, z of its four vertex normals in vertex
 * order. Returns 1 and sets *color and *q on a crossing, else 0. */
int harc_iso_hit(const ClHarcParams* params, global const float4* normals, const float4 planes[4], const float3 e,
                 const float3 d, const float seg_f, const float seg_b, const float s_f, const float s_b,
                 float3* color, float* q)
{
    const float iso = params->iso.x;
    if (!((s_f <= iso && s_b > iso) || (s_f >= iso && s_b < iso)))
        return 0;
    *q = (iso - s_f) / (s_b - s_f);
    const int flags = (int)params->iso.w;
    if (!(flags & HARC_ISO_SHADED)) {
        *color = clamp(params->iso_color.xyz, 0.0f, 1.0f);
        return 1;
    }
    const float w = (flags & HARC_ISO_EQUAL_WEIGHTS) ? 0.5f : *q;
    const float3 pf = e + seg_f * d, pb = e + seg_b * d;
    const float4 bf = (float4)(harc_dot3(planes[0].xyz, pf) + planes[0].w, harc_dot3(planes[1].xyz, pf) + planes[1].w,
                               harc_dot3(planes[2].xyz, pf) + planes[2].w, harc_dot3(planes[3].xyz, pf) + planes[3].w);
    const float4 bb = (float4)(harc_dot3(planes[0].xyz, pb) + planes[0].w, harc_dot3(planes[1].xyz, pb) + planes[1].w,
                               harc_dot3(planes[2].xyz, pb) + planes[2].w, harc_dot3(planes[3].xyz, pb) + planes[3].w);
    const float4 b = (1.0f - w) * bf + w * bb;
    const float3 n = (float3)(harc_dot4(normals[0], b), harc_dot4(normals[1], b), harc_dot4(normals[2], b));
    *color = clamp(params->iso_color.xyz * (params->iso.y + params->iso.z * harc_dot3(params->iso_light.xyz, n)), 0.0f,
                   1.0f);
    return 1;
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
 * of pixel p's ray, sorted by ray parameter: (λ as float bits, tet * 4 + face), after (0, -1 - tet) when a
 * perspective eye lies inside tet. params.camera is
 * relative to the mesh's shifted origin. Ray e + λ d, |d| = 1 (kernels/ray.h's clvr_ray_unit, as
 * host/model/camera.cpp's Camera::ray). stats[p] = (steps, 1 if the step bound stopped the ray, pieces;
 * with HARC_INTEGRATION_SLICES the slices taken; with HARC_INTEGRATION_ISO the hit's λ as float bits,
 * +infinity without one). iso_normals: HARC_INTEGRATION_ISO's vertex normals, 3 float4 per cell (a one-element
 * dummy otherwise).
 * integration: HARC_INTEGRATION_*; full_table, full_ns, full_nl, full_params: harc_full_lookup's
 * table (a one-element dummy unless integration is full). With clip_box (a sort-last part, host/cluster/
 * partition.h) only the ray's part inside [box_lo, box_hi] is integrated: each segment is cut to it, the
 * scalar interpolated at the cut (the field is linear in the cell), and the walk stops past the box.
 * Out: (I + T background, 1 - T). */
kernel void harc_render(global float4* out, global uint* stats, global const float4* tets,
                        global const uint* offsets, global const int2* entries, global const float* tf,
                        global const float* psi, global const float4* full_table, global const float4* iso_normals,
                        const ClHarcParams params)
{
    CLVR_GUARD_2D(params.width, params.height);
    const int x = (int)get_global_id(0), y = (int)get_global_id(1);
    const int p = y * params.width + x;
    const int tf_count = params.tf_count, psi_n = params.psi_n, integration = params.integration;
    const uint max_steps = params.max_steps;
    const float ert_alpha = params.ert_alpha;
    const float2 size = (float2)((float)params.width, (float)params.height);
    float3 e, d;
    const float2 offset = clvr_ray_window_offset(clvr_ray_pixel_centre(x, y), size, params.camera);
    clvr_ray_unit(offset, params.camera, &e, &d);

    /* The ray's parameter range inside the part's box (slab test); everywhere without one. */
    float clip_lo = -INFINITY, clip_hi = INFINITY;
    if (params.clip_box) {
        const float3 inv_d = 1.0f / d;
        const float3 t0 = (params.box_lo.xyz - e) * inv_d, t1 = (params.box_hi.xyz - e) * inv_d;
        const float3 t_near = fmin(t0, t1), t_far = fmax(t0, t1);
        for (int a = 0; a < 3; ++a) {
            const float da = a == 0 ? d.x : (a == 1 ? d.y : d.z);
            const float ea = a == 0 ? e.x : (a == 1 ? e.y : e.z);
            const float lo = a == 0 ? params.box_lo.x : (a == 1 ? params.box_lo.y : params.box_lo.z);
            const float hi = a == 0 ? params.box_hi.x : (a == 1 ? params.box_hi.y : params.box_hi.z);
            if (da == 0.0f) {
                if (ea < lo || ea > hi)
                    clip_hi = -INFINITY;
                continue;
            }
            clip_lo = fmax(clip_lo, a == 0 ? t_near.x : (a == 1 ? t_near.y : t_near.z));
            clip_hi = fmin(clip_hi, a == 0 ? t_far.x : (a == 1 ? t_far.y : t_far.z));
        }
    }
    float3 color = (float3)(0.0f);
    float transmittance = 1.0f;
    uint steps = 0, bounded = 0, pieces = 0;
    float lambda_done = -INFINITY;  /* where the ray last left the mesh */
    float iso_lambda = INFINITY;    /* HARC_INTEGRATION_ISO: the hit */
    const uint end = clip_lo <= clip_hi ? offsets[p + 1] : offsets[p];  /* a ray that misses the box: nothing */
    for (uint k = offsets[p]; k < end && !bounded; ++k) {
        const int2 entry = entries[k];
        float lambda = as_float(entry.x);
        /* Crossings the walk has passed (and duplicates on shared edges) lie before lambda_done. */
        if (lambda < lambda_done - 1e-5f * (1.0f + fabs(lambda_done)))
            continue;
        lambda = fmax(lambda, lambda_done);
        /* tet * 4 + entry face; -1 - tet for a perspective eye inside tet (no entry face) */
        int t = entry.y >= 0 ? entry.y >> 2 : -1 - entry.y;
        int entry_face = entry.y >= 0 ? entry.y & 3 : -1;
        /* Partial integration: the last segment's back end, which is this cell's front when the walk goes
         * on through a face without a cut (the field is continuous across faces: one scalar per point),
         * so its transfer-function search is not repeated. */
        HarcTfPoint carried;
        int carry = 0;
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
            /* Exit: the nearest face ahead, not the one the ray came in through (Figure 6 lines 3–8). Face i
             * is num_i / den_i ahead; the fractions are compared by cross-multiplication (denominators > 0),
             * so a step takes one division, not one per face. */
            float best_num = 0.0f, best_den = 0.0f;
            int exit_face = -1;
            const float4 planes[4] = {p0, p1, p2, p3};
            for (int i = 0; i < 4; ++i) {
                const float den = -harc_dot3(planes[i].xyz, d);
                if (i != entry_face && den > 0.0f) {
                    const float num = fmax(harc_dot3(planes[i].xyz, pos) + planes[i].w, 0.0f);
                    if (exit_face < 0 || num * best_den < best_num * den) {
                        best_num = num;
                        best_den = den;
                        exit_face = i;
                    }
                }
            }
            if (exit_face < 0) {  /* grazing a degenerate cell: leave the mesh here */
                lambda_done = lambda;
                break;
            }
            const float step = best_num / best_den;
            const float lambda_exit = lambda + step;
            /* The segment [lambda, lambda_exit], cut to the part's box (unchanged without one). */
            const float seg_f = fmax(lambda, clip_lo), seg_b = fmin(lambda_exit, clip_hi);
            if (seg_f < seg_b || (seg_f == lambda && seg_b == lambda_exit)) {
                const float length = seg_f == lambda && seg_b == lambda_exit ? step : seg_b - seg_f;
                const float s_b = harc_dot3(grad.xyz, e + seg_b * d) + grad.w;                       /* Eq. 6 */
                if (integration == HARC_INTEGRATION_PARTIAL) {
                    const HarcTfPoint front = carry && seg_f == lambda
                                                  ? carried
                                                  : harc_tf_point(tf, tf_count,
                                                                  harc_dot3(grad.xyz, e + seg_f * d) + grad.w);
                    pieces += (uint)harc_segment_from(tf, tf_count, psi, psi_n, front, s_b, length, &color,
                                                      &transmittance, &carried);
                    carry = seg_b == lambda_exit;
                } else if (integration == HARC_INTEGRATION_ISO) {
                    const float s_f = harc_dot3(grad.xyz, e + seg_f * d) + grad.w;
                    float q;
                    if (harc_iso_hit(&params, iso_normals + (size_t)t * 3, planes, e, d, seg_f, seg_b, s_f, s_b,
                                     &color, &q)) {
                        iso_lambda = seg_f + q * (seg_b - seg_f);
                        transmittance = 0.0f;
                        k = end; /* the first crossing ends the ray */
                        break;
                    }
                } else if (integration == HARC_INTEGRATION_SLICES) {
                    const float df = harc_dot3(d, params.camera.forward.xyz);
                    if (df > 0.0f)
                        pieces += harc_slices(tf, tf_count, params.slices, df, e, d, grad, seg_f, seg_b, &color,
                                              &transmittance);
                } else {
                    const float s_f = harc_dot3(grad.xyz, e + seg_f * d) + grad.w;
                    if (integration == HARC_INTEGRATION_FULL) {
                        /* The whole segment at once: no split at control points (the table has them inside). */
                        const float4 c = harc_full_lookup(full_table, params.full_ns, params.full_nl,
                                                          params.full_params, s_f, s_b, length);
                        color += transmittance * c.xyz;
                        transmittance *= 1.0f - c.w;
                    } else {  /* HARC_INTEGRATION_AVERAGE */
                        harc_segment_average(tf, tf_count, s_f, s_b, length, &color, &transmittance);
                    }
                    ++pieces;
                }
            } else {
                carry = 0;
            }
            if (1.0f - transmittance >= ert_alpha || lambda_exit >= clip_hi) {  /* early ray termination (off:
                                                                                 * ert_alpha = 2), or past the box */
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
    out[p] = (float4)(color + transmittance * params.background.xyz, 1.0f - transmittance);
    stats[3 * p + 0] = steps;
    stats[3 * p + 1] = bounded;
    stats[3 * p + 2] = integration == HARC_INTEGRATION_ISO ? as_uint(iso_lambda) : pieces;
}

/* ---- harc_render_packet: 8 pixels of a row per work-item (partial pre-integration, no part box) ----------
 * Each lane walks its own ray through its own cells (its own entry list, cell, entry face, segment and pieces)
 * with harc_render's operations lane by lane (kernels/packet.h's rule), so the pixels are the same bits: a lane
 * that needs its next entry takes it in scalars; a cell step, its exit face and its segment run on all lanes at
 * once, masked; the packet ends when no lane is left. The helpers below are segment_integral.h's lane by lane. */

/* harc_slices lane by lane, for the lanes in m (df > 0): each lane's slices in [seg_f, seg_b) in order. Returns the
 * slices taken per lane. */
__attribute__((always_inline)) int8 harc_slices8(global const float* tf, const int tf_count, const float4 slices, const float8 df, const float8 e_x,
                  const float8 e_y, const float8 e_z, const float8 d_x, const float8 d_y, const float8 d_z,
                  const float8 gx, const float8 gy, const float8 gz, const float8 gw, const float8 seg_f,
                  const float8 seg_b, const int8 m, float8* c_r, float8* c_g, float8* c_b, float8* transmittance)
{
    const float z0 = slices.x, ds = slices.y;
    const int count = (int)slices.z;
    const float8 neg_log2e = -(ds / df) * M_LOG2E_F;
    int8 k = max(convert_int8(ceil((seg_f * df - z0) / ds)) - 1, 0); /* one before the first, for rounding */
    int8 taken = 0;
    for (;;) {
        const float8 lambda_k = (z0 + convert_float8(k) * ds) / df;
        const int8 in = m & (k < count) & isless(lambda_k, seg_b);
        if (!any(in))
            break;
        const int8 take = in & ~isless(lambda_k, seg_f);
        if (any(take)) {
            float8 r, g, b, tau;
            clvr_tf_eval8(tf, tf_count,
                          harc_dot8(gx, gy, gz, e_x + lambda_k * d_x, e_y + lambda_k * d_y, e_z + lambda_k * d_z) + gw,
                          &r, &g, &b, &tau);
            const float8 alpha = 1.0f - clvr_exp2_8(tau * neg_log2e);
            const float8 ta = *transmittance * alpha;
            *c_r = select(*c_r, *c_r + ta * r, take);
            *c_g = select(*c_g, *c_g + ta * g, take);
            *c_b = select(*c_b, *c_b + ta * b, take);
            *transmittance = select(*transmittance, *transmittance * (1.0f - alpha), take);
            taken -= take;
        }
        k -= in;
    }
    return taken;
}

/* harc_iso_hit lane by lane, for the lanes in m: the lanes whose cell holds a crossing (returned), their shade in
 * (c_r, c_g, c_b) and their q. */
int8 harc_iso_hit8(const ClHarcParams* params, global const float4* normals, const int8 cell, const float8 h[4][4],
                   const float8 e_x, const float8 e_y, const float8 e_z, const float8 d_x, const float8 d_y,
                   const float8 d_z, const float8 seg_f, const float8 seg_b, const float8 s_f, const float8 s_b,
                   const int8 m, float8* c_r, float8* c_g, float8* c_b, float8* q)
{
    const float iso = params->iso.x;
    const int8 hit = m & ((islessequal(s_f, iso) & isgreater(s_b, iso)) | (isgreaterequal(s_f, iso) & isless(s_b, iso)));
    if (!any(hit))
        return hit;
    *q = select(*q, (iso - s_f) / (s_b - s_f), hit);
    const int flags = (int)params->iso.w;
    const float3 base = params->iso_color.xyz;
    if (!(flags & HARC_ISO_SHADED)) {
        const float3 c = clamp(base, 0.0f, 1.0f);
        *c_r = select(*c_r, (float8)(c.x), hit), *c_g = select(*c_g, (float8)(c.y), hit);
        *c_b = select(*c_b, (float8)(c.z), hit);
        return hit;
    }
    const float8 w = (flags & HARC_ISO_EQUAL_WEIGHTS) ? (float8)(0.5f) : *q;
    const float8 pf_x = e_x + seg_f * d_x, pf_y = e_y + seg_f * d_y, pf_z = e_z + seg_f * d_z;
    const float8 pb_x = e_x + seg_b * d_x, pb_y = e_y + seg_b * d_y, pb_z = e_z + seg_b * d_z;
    float8 b[4];
    for (int i = 0; i < 4; ++i) {
        const float8 bf = harc_dot8(h[i][0], h[i][1], h[i][2], pf_x, pf_y, pf_z) + h[i][3];
        const float8 bb = harc_dot8(h[i][0], h[i][1], h[i][2], pb_x, pb_y, pb_z) + h[i][3];
        b[i] = (1.0f - w) * bf + w * bb;
    }
    float8 n[3];
    for (int axis = 0; axis < 3; ++axis) {
        float8 nx, ny, nz, nw;
        const int8 at = select((int8)(0), cell * 3 + axis, hit);
#define HARC_NORMAL(L)                                                                                               {                                                                                                                const float4 v = normals[at.s##L];                                                                           nx.s##L = v.x, ny.s##L = v.y, nz.s##L = v.z, nw.s##L = v.w;                                              }
        CLVR_EACH_LANE(HARC_NORMAL)
#undef HARC_NORMAL
        n[axis] = harc_dot8_4(nx, ny, nz, nw, b[0], b[1], b[2], b[3]);
    }
    const float3 light = params->iso_light.xyz;
    const float8 shade = params->iso.y + params->iso.z * harc_dot8((float8)(light.x), (float8)(light.y),
                                                                    (float8)(light.z), n[0], n[1], n[2]);
    *c_r = select(*c_r, clamp(base.x * shade, 0.0f, 1.0f), hit);
    *c_g = select(*c_g, clamp(base.y * shade, 0.0f, 1.0f), hit);
    *c_b = select(*c_b, clamp(base.z * shade, 0.0f, 1.0f), hit);
    return hit;
}

kernel void harc_render_packet(global float4* out, global uint* stats, global const float4* tets,
                               global const uint* offsets, global const int2* entries, global const float* tf,
                               global const float* psi, global const float4* full_table,
                               global const float4* iso_normals, const ClHarcParams params)
{
    const int x0 = (int)get_global_id(0) * CLVR_LANES, y = (int)get_global_id(1);
    if (x0 >= params.width || y >= params.height)
        return;
    const int tf_count = params.tf_count, psi_n = params.psi_n, integration = params.integration;
    const uint max_steps = params.max_steps;
    const float ert_alpha = params.ert_alpha;
    const float2 size = (float2)((float)params.width, (float)params.height);
    /* each lane's ray and entry list, as harc_render sets them up */
    float8 e_x, e_y, e_z, d_x, d_y, d_z;
    int8 kk = 0, kend = 0;
    int8 live = x0 + CLVR_LANE_INDEX < params.width;
#define HARC_SETUP(L)                                                                                        \
    {                                                                                                        \
        float3 e, d;                                                                                         \
        clvr_ray_unit(clvr_ray_window_offset(clvr_ray_pixel_centre(min(x0 + L, params.width - 1), y), size,   \
                                             params.camera),                                                 \
                      params.camera, &e, &d);                                                                \
        e_x.s##L = e.x, e_y.s##L = e.y, e_z.s##L = e.z, d_x.s##L = d.x, d_y.s##L = d.y, d_z.s##L = d.z;       \
        const int p = y * params.width + min(x0 + L, params.width - 1);                                       \
        kk.s##L = (int)offsets[p], kend.s##L = (int)offsets[p + 1];                                          \
    }
    CLVR_EACH_LANE(HARC_SETUP)
#undef HARC_SETUP
    /* HARC_INTEGRATION_SLICES: the eye depth per unit λ of each lane's ray */
    const float8 df = harc_dot8(d_x, d_y, d_z, (float8)(params.camera.forward.x), (float8)(params.camera.forward.y),
                                (float8)(params.camera.forward.z));
    float8 c_r = 0.0f, c_g = 0.0f, c_b = 0.0f, transmittance = 1.0f;
    uint8 steps = 0;
    int8 bounded = 0, pieces = 0;
    float8 lambda_done = -INFINITY, lambda = 0.0f;
    int8 cell = 0, entry_face = -1, carry = 0, need = live;
    float8 iso_lambda = INFINITY; /* HARC_INTEGRATION_ISO: the hit */
    HarcTfPoint8 carried = {0.0f, 0.0f, 0.0f, 0.0f, 0.0f, 0};
    while (any(live)) {
        /* Lanes that left the mesh (or start) take their next crossing ahead of where they left it; crossings the
         * walk has passed (and duplicates on shared edges) lie before lambda_done. None left: the lane is done. */
        if (any(need)) {
#define HARC_ENTRY(L)                                                                                        \
            if (need.s##L) {                                                                                 \
                const float done = lambda_done.s##L;                                                         \
                int k = kk.s##L, found = 0;                                                                  \
                for (; k < kend.s##L; ++k) {                                                                 \
                    const int2 entry = entries[k];                                                           \
                    const float at = as_float(entry.x);                                                      \
                    if (at < done - 1e-5f * (1.0f + fabs(done)))                                             \
                        continue;                                                                            \
                    lambda.s##L = fmax(at, done);                                                            \
                    cell.s##L = entry.y >= 0 ? entry.y >> 2 : -1 - entry.y;                                  \
                    entry_face.s##L = entry.y >= 0 ? entry.y & 3 : -1;                                       \
                    found = 1;                                                                               \
                    ++k;                                                                                     \
                    break;                                                                                   \
                }                                                                                            \
                kk.s##L = k;                                                                                 \
                need.s##L = 0;                                                                               \
                carry.s##L = 0;                                                                              \
                if (!found)                                                                                  \
                    live.s##L = 0;                                                                           \
            }
            CLVR_EACH_LANE(HARC_ENTRY)
#undef HARC_ENTRY
        }
        int8 act = live;
        const int8 over = act & as_int8(steps >= max_steps);
        bounded |= over & 1;
        live &= ~over;
        act &= ~over;
        if (!any(act))
            continue;
        steps += as_uint8(act & 1);
        /* the lanes' cells */
        float8 h0x, h0y, h0z, h0w, h1x, h1y, h1z, h1w, h2x, h2y, h2z, h2w, gx, gy, gz, gw;
        int8 a0, a1, a2, a3;
        const int8 t = select((int8)(0), cell, act);
#define HARC_CELL(L)                                                                                         \
        {                                                                                                    \
            global const float4* q = tets + (size_t)t.s##L * HARC_TET_FLOAT4S;                               \
            const float4 p0 = q[0], p1 = q[1], p2 = q[2], grad = q[3];                                       \
            const int4 adj = as_int4(q[4]);                                                                  \
            h0x.s##L = p0.x, h0y.s##L = p0.y, h0z.s##L = p0.z, h0w.s##L = p0.w;                              \
            h1x.s##L = p1.x, h1y.s##L = p1.y, h1z.s##L = p1.z, h1w.s##L = p1.w;                              \
            h2x.s##L = p2.x, h2y.s##L = p2.y, h2z.s##L = p2.z, h2w.s##L = p2.w;                              \
            gx.s##L = grad.x, gy.s##L = grad.y, gz.s##L = grad.z, gw.s##L = grad.w;                          \
            a0.s##L = adj.x, a1.s##L = adj.y, a2.s##L = adj.z, a3.s##L = adj.w;                              \
        }
        CLVR_EACH_LANE(HARC_CELL)
#undef HARC_CELL
        const float8 h3x = -(h0x + h1x + h2x), h3y = -(h0y + h1y + h2y), h3z = -(h0z + h1z + h2z);
        const float8 h3w = 1.0f - (h0w + h1w + h2w);
        const float8 pos_x = e_x + lambda * d_x, pos_y = e_y + lambda * d_y, pos_z = e_z + lambda * d_z;
        /* the exit face, as harc_render chooses it */
        float8 best_num = 0.0f, best_den = 0.0f;
        int8 exit_face = -1;
#define HARC_FACE(I, HX, HY, HZ, HW)                                                                         \
        {                                                                                                    \
            const float8 den = -harc_dot8(HX, HY, HZ, d_x, d_y, d_z);                                        \
            const int8 candidate = (entry_face != I) & isgreater(den, 0.0f);                                 \
            const float8 num = fmax(harc_dot8(HX, HY, HZ, pos_x, pos_y, pos_z) + HW, 0.0f);                  \
            const int8 better = candidate & ((exit_face < 0) | isless(num * best_den, best_num * den));      \
            best_num = select(best_num, num, better);                                                        \
            best_den = select(best_den, den, better);                                                        \
            exit_face = select(exit_face, (int8)(I), better);                                                \
        }
        HARC_FACE(0, h0x, h0y, h0z, h0w)
        HARC_FACE(1, h1x, h1y, h1z, h1w)
        HARC_FACE(2, h2x, h2y, h2z, h2w)
        HARC_FACE(3, h3x, h3y, h3z, h3w)
#undef HARC_FACE
        const int8 grazing = act & (exit_face < 0); /* a degenerate cell: leave the mesh here */
        lambda_done = select(lambda_done, lambda, grazing);
        need |= grazing;
        act &= ~grazing;
        const float8 step = best_num / best_den;
        const float8 lambda_exit = lambda + step;
        const float8 s_b = harc_dot8(gx, gy, gz, e_x + lambda_exit * d_x, e_y + lambda_exit * d_y,
                                     e_z + lambda_exit * d_z) + gw;
        if (integration == HARC_INTEGRATION_ISO) {
            const float8 h[4][4] = {{h0x, h0y, h0z, h0w}, {h1x, h1y, h1z, h1w}, {h2x, h2y, h2z, h2w}, {h3x, h3y, h3z, h3w}};
            const float8 s_f = harc_dot8(gx, gy, gz, pos_x, pos_y, pos_z) + gw;
            float8 q = 0.0f;
            const int8 hit = harc_iso_hit8(&params, iso_normals, t, h, e_x, e_y, e_z, d_x, d_y, d_z, lambda, lambda_exit,
                                           s_f, s_b, act, &c_r, &c_g, &c_b, &q);
            iso_lambda = select(iso_lambda, lambda + q * (lambda_exit - lambda), hit);
            transmittance = select(transmittance, (float8)(0.0f), hit);
            live &= ~hit; /* the first crossing ends the ray */
            act &= ~hit;
        } else if (integration == HARC_INTEGRATION_FULL || integration == HARC_INTEGRATION_AVERAGE) {
            /* one lookup or one average per segment, lane by lane with harc_render's own functions */
            const float8 s_f = harc_dot8(gx, gy, gz, pos_x, pos_y, pos_z) + gw;
#define HARC_WHOLE(L)                                                                                                \
            if (act.s##L) {                                                                                          \
                float3 color = (float3)(c_r.s##L, c_g.s##L, c_b.s##L);                                               \
                float transmittance_l = transmittance.s##L;                                                          \
                if (integration == HARC_INTEGRATION_FULL) {                                                          \
                    const float4 c = harc_full_lookup(full_table, params.full_ns, params.full_nl, params.full_params, \
                                                      s_f.s##L, s_b.s##L, step.s##L);                                \
                    color += transmittance_l * c.xyz;                                                                \
                    transmittance_l *= 1.0f - c.w;                                                                   \
                } else {                                                                                             \
                    harc_segment_average(tf, tf_count, s_f.s##L, s_b.s##L, step.s##L, &color, &transmittance_l);     \
                }                                                                                                    \
                c_r.s##L = color.x, c_g.s##L = color.y, c_b.s##L = color.z, transmittance.s##L = transmittance_l;    \
            }
            CLVR_EACH_LANE(HARC_WHOLE)
#undef HARC_WHOLE
            pieces -= act;
        } else if (integration == HARC_INTEGRATION_SLICES) {
            pieces += harc_slices8(tf, tf_count, params.slices, df, e_x, e_y, e_z, d_x, d_y, d_z, gx, gy, gz, gw,
                                   lambda, lambda_exit, act & isgreater(df, 0.0f), &c_r, &c_g, &c_b, &transmittance);
        } else {
            /* the segment's front: the last segment's back end where the walk came through a face, else looked up */
            HarcTfPoint8 front = carried;
            const int8 lookup = act & ~carry;
            if (any(lookup)) {
                const float8 s_f = harc_dot8(gx, gy, gz, pos_x, pos_y, pos_z) + gw;
#define HARC_FRONT(L)                                                                                                \
                if (lookup.s##L) {                                                                                   \
                    const HarcTfPoint q = harc_tf_point(tf, tf_count, s_f.s##L);                                     \
                    front.s.s##L = q.s, front.k.s##L = q.k;                                                          \
                    front.r.s##L = q.c.x, front.g.s##L = q.c.y, front.b.s##L = q.c.z, front.w.s##L = q.c.w;          \
                }
                CLVR_EACH_LANE(HARC_FRONT)
#undef HARC_FRONT
            }
            pieces += harc_segment_from8(tf, tf_count, psi, psi_n, &front, s_b, step, act, &c_r, &c_g, &c_b,
                                         &transmittance, &carried);
            carry |= act;
        }
        /* early ray termination (off: ert_alpha = 2) */
        const int8 finished = act & (isgreaterequal(1.0f - transmittance, ert_alpha) | isgreaterequal(lambda_exit, INFINITY));
        live &= ~finished;
        act &= ~finished;
        const int8 next = select(select(select(a3, a2, exit_face == 2), a1, exit_face == 1), a0, exit_face == 0);
        lambda = select(lambda, lambda_exit, act);
        const int8 left = act & (next < 0);
        lambda_done = select(lambda_done, lambda_exit, left);
        need |= left;
        const int8 on = act & ~left;
        cell = select(cell, next >> 2, on);
        entry_face = select(entry_face, next & 3, on);
    }
    const size_t row = (size_t)y * (size_t)params.width;
#define HARC_STORE(L)                                                                                        \
    if (x0 + L < params.width) {                                                                             \
        const size_t p = row + (size_t)(x0 + L);                                                             \
        out[p] = (float4)((float3)(c_r.s##L, c_g.s##L, c_b.s##L) + transmittance.s##L * params.background.xyz, \
                          1.0f - transmittance.s##L);                                                        \
        stats[3 * p + 0] = steps.s##L;                                                                       \
        stats[3 * p + 1] = (uint)bounded.s##L;                                                               \
        stats[3 * p + 2] = integration == HARC_INTEGRATION_ISO ? as_uint(iso_lambda.s##L) : (uint)pieces.s##L; \
    }
    CLVR_EACH_LANE(HARC_STORE)
#undef HARC_STORE
}
