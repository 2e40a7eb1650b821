// kernels/spherical.cl — the per-shell pixel pass of the spherical technique (seeds/000 §2.2,
// host/render/grid/spherical.h, docs/spherical.md). The frame buffer `coords` holds, per pixel, the
// sphere's interpolated normalized spherical coordinates after the pixel transfer b + s·CM·p, which
// also mapped them to texture coordinates; `stencil` marks the pixels the shell covered. Per covered
// pixel: the φ coordinate wraps (GL_REPEAT of the periodic axis), the pixel texture fetch of the
// scalar volume (clvr_tex3d, as raster::pixelTexture), classification by the transfer function,
// opacity alpha = 1 - exp(-tau L) for the length L of the ray inside this shell's slab, and the
// "over" blend into `image` (back to front, premultiplied): dst = (C alpha, alpha) + (1 - alpha) dst.
#include "clvr_common.h"
#include "packet.h"
#include "ray.h"
#include "spherical_params.h"
#include "texture.h"
#include "transfer_function.h"
#include "volume_sampling.h"

/* The length of a ray inside the slab r_lo <= |x - center| <= r_hi on one side of its closest approach to
 * the center (side +1: beyond it, where the sphere's back faces are; -1: before it, the front faces),
 * counting only t >= 0. tc: the ray parameter of the closest approach (unit direction), p2: the squared
 * closest distance. A ray that does not reach the next inner sphere, radius r_inner (p >= r_inner), never
 * meets that sphere, so this one takes its whole path below r_hi: the slab then starts at p (r_lo
 * ignored). */
float clvr_spherical_slab(const float tc, const float p2, const float r_inner, const float r_lo, const float r_hi,
                          const float side)
{
    const float h_hi = sqrt(fmax(r_hi * r_hi - p2, 0.0f));
    const float h_lo = p2 >= r_inner * r_inner ? 0.0f : sqrt(fmax(r_lo * r_lo - p2, 0.0f));
    const float t0 = side > 0.0f ? tc + h_lo : tc - h_hi;
    const float t1 = side > 0.0f ? tc + h_hi : tc - h_lo;
    return fmax(t1 - fmax(t0, 0.0f), 0.0f);
}

/* The camera ray through pixel (px, py) as (tc, p2) about center.xyz: the parameter of its closest approach
 * and the squared closest distance; origin and unit direction from kernels/ray.h's clvr_ray_rounded_terms,
 * size = (width, height). */
void clvr_spherical_ray(const float px, const float py, const ClCamera cam, const float2 size, const float3 center,
                        float3* oc, float3* dir, float* tc, float* p2)
{
    float3 origin;
    clvr_ray_rounded_terms(clvr_ray_window_offset((float2)(px + 0.5f, py + 0.5f), size, cam), cam, &origin, dir);
    *oc = center - origin;
    *tc = dot(*oc, *dir);
    const float3 off = *oc - *tc * *dir; /* center minus its closest ray point: p = |off|, no cancellation */
    *p2 = dot(off, off);
}

/* clvr_spherical_slab for the camera ray through pixel (px, py); center.w = r_inner. */
float clvr_spherical_slab_length(const float px, const float py, const ClCamera cam, const float2 size,
                                 const float4 center, const float r_lo, const float r_hi, const float side)
{
    float3 oc, dir;
    float tc, p2;
    clvr_spherical_ray(px, py, cam, size, center.xyz, &oc, &dir, &tc, &p2);
    return clvr_spherical_slab(tc, p2, center.w, r_lo, r_hi, side);
}

/* The φ texture coordinate wrapped into [s0, s0 + period) (GL_REPEAT of the periodic axis; period 0: none). */
float clvr_spherical_wrap(const float s, const float s0, const float period)
{
    if (!(period > 0.0f))
        return s;
    const float u = (s - s0) / period;
    return s0 + (u - floor(u)) * period;
}

/* Row m of the color matrix applied to (u, v, w, 1), written out (not dot(), whose evaluation order is the
 * implementation's) so that the packet kernel repeats it lane by lane. */
float clvr_spherical_row(const float4 m, const float u, const float v, const float w)
{
    return m.x * u + m.y * v + m.z * w + m.w;
}

/* p.phi_s0, p.phi_period: the φ texture coordinate s.x wraps to [phi_s0, phi_s0 + phi_period)
 * (period 0: no wrap). p.slab = (r_lo, r_hi, side, radial): radial != 0 uses L = r_hi - r_lo for every
 * pixel. */
kernel void spherical_shell(global const float4* coords, global const uchar* stencil, global float4* image,
                            global const float* texels, global const float* tf, const ClSphericalParams p)
{
    const int width = p.width, height = p.height;
    const float4 slab = p.slab;
    CLVR_GUARD_2D(width, height);
    const int x = (int)get_global_id(0), y = (int)get_global_id(1);
    const size_t i = (size_t)y * width + x;
    if (stencil[i] == 0)
        return;
    float4 s = coords[i];
    s.x = clvr_spherical_wrap(s.x, p.phi_s0, p.phi_period);
    const float value = clvr_tex3d(texels, p.tex, s).x;
    const float4 c = clvr_tf_eval(tf, p.tf_count, value); /* (r, g, b, tau) */
    const float len = slab.w != 0.0f ? slab.y - slab.x
                                     : clvr_spherical_slab_length((float)x, (float)y, p.camera,
                                                                  (float2)((float)width, (float)height), p.center,
                                                                  slab.x, slab.y, slab.z);
    const float alpha = 1.0f - exp(-c.w * len);
    const float4 src = (float4)(c.xyz * alpha, alpha);
    image[i] = src + (1.0f - alpha) * image[i];
}

/* The fused path (host/render/grid/spherical.cpp, "path": "fused"): one work-item per pixel meets every
 * shell of shells[] (float4 (radius, r_lo, r_hi, w) per shell, increasing radius) where its ray crosses
 * the exact sphere, front to back — the near hemispheres from the outermost shell in, then the far ones
 * from the innermost out, t >= 0 only — and at each hit does what the shell passes do per covered pixel:
 * the hit's normalized spherical coordinates (u, v) = (φ / 2π, θ / π) and the shell's w, the pixel
 * transfer q = bias + scale (M (u, v, w, 1)) (the texel-center map composed in), the φ wrap, the
 * trilinear fetch, classification, alpha = 1 - exp(-tau L) with L the ray's length in the shell's slab
 * on that side (or r_hi - r_lo when p.radial), composited c += T alpha C, T *= 1 - alpha, stopping once
 * 1 - T >= p.ert_alpha. Where the passes interpolate (u, v) across the tessellation's flat triangles,
 * this computes them at the sphere's point: the tessellation's error is gone. The pixel is
 * c + T background, 1 - T; samples[pixel] the shell hits taken. */
kernel void spherical_fused(global float4* out, global uint* samples, global const float* texels,
                            global const float* tf, global const float4* shells, const ClSphericalFusedParams p)
{
    CLVR_GUARD_2D(p.width, p.height);
    const int x = (int)get_global_id(0), y = (int)get_global_id(1);
    float3 oc, dir;
    float tc, p2;
    clvr_spherical_ray((float)x, (float)y, p.camera, (float2)((float)p.width, (float)p.height), p.center.xyz, &oc,
                       &dir, &tc, &p2);
    const float inv_two_pi = 0.15915494309189535f, inv_pi = 0.3183098861837907f;
    const int4 dims = (int4)((int)p.tex.width, (int)p.tex.height, (int)p.tex.depth, 0);
    const float3 texels_n = convert_float3(dims.xyz);
    float3 c = (float3)(0.0f);
    float transmittance = 1.0f;
    uint taken = 0;
    bool opaque = false;
    int innermost = p.shells; /* the innermost shell the ray meets, found by pass 0 */
    /* pass 0: the near hemispheres, outermost first; pass 1: the far ones, innermost first */
    for (int pass = 0; pass < 2 && !opaque; ++pass) {
        const float side = pass == 0 ? -1.0f : 1.0f;
        for (int n = pass == 0 ? 0 : innermost; n < p.shells; ++n) {
            const int k = pass == 0 ? p.shells - 1 - n : n;
            const float4 shell = shells[k];
            const float r = shell.x;
            if (!(p2 < r * r)) /* the ray misses this sphere and, going inwards, every inner one */
                break;
            if (pass == 0)
                innermost = k;
            const float t = tc + side * sqrt(r * r - p2);
            if (t < 0.0f)
                continue; /* behind the eye */
            const float3 rel = t * dir - oc; /* the hit minus the center */
            /* φ = atan2(y, x) in [0, 2π), θ = atan2(ρ, z) in [0, π] with ρ the distance from the z axis (as
             * acos(z / r), well conditioned at the poles too); kernels/clvr_common.h's clvr_atan2 */
            float u = clvr_atan2(rel.y, rel.x) * inv_two_pi;
            u = u < 0.0f ? u + 1.0f : (u >= 1.0f ? 0.0f : u);
            const float v = clvr_atan2(sqrt(rel.x * rel.x + rel.y * rel.y), rel.z) * inv_pi;
            const float w = shell.w;
            float4 q = p.bias + p.scale * (float4)(clvr_spherical_row(p.matrix_row[0], u, v, w),
                                                   clvr_spherical_row(p.matrix_row[1], u, v, w),
                                                   clvr_spherical_row(p.matrix_row[2], u, v, w),
                                                   clvr_spherical_row(p.matrix_row[3], u, v, w));
            q.x = clvr_spherical_wrap(q.x, p.phi_s0, p.phi_period);
            ++taken;
            /* clvr_tex3d's linear filter with clamp to edge, as clvr_trilinear on the grid: texel i centered at
             * (i + 0.5) / n, coordinates outside the outermost centers clamped to them (the same value) */
            const float3 g = clamp(q.xyz * texels_n - 0.5f, (float3)(0.0f), texels_n - 1.0f);
            const float4 ct = clvr_tf_eval(tf, p.tf_count, clvr_trilinear(texels, dims, g));
            const float len = p.radial ? shell.z - shell.y
                                       : clvr_spherical_slab(tc, p2, k > 0 ? shells[k - 1].x : -1.0f, shell.y, shell.z,
                                                             side);
            const float alpha = 1.0f - clvr_exp2(-ct.w * len * M_LOG2E_F);
            c += (transmittance * alpha) * ct.xyz;
            transmittance *= 1.0f - alpha;
            opaque = 1.0f - transmittance >= p.ert_alpha;
            if (opaque)
                break;
        }
    }
    const size_t i = (size_t)y * p.width + x;
    out[i] = (float4)(c + transmittance * p.background.xyz, 1.0f - transmittance);
    samples[i] = taken;
}

/* ---- ray packets (host: "packets"; docs/spherical.md) -------------------------------------------------- */

/* clvr_spherical_wrap lane by lane. */
float8 clvr_spherical_wrap8(const float8 s, const float s0, const float period)
{
    if (!(period > 0.0f))
        return s;
    const float8 u = (s - s0) / period;
    return s0 + (u - floor(u)) * period;
}

/* clvr_spherical_row lane by lane; w is a vector so that m.z * w fuses into the sum as the scalar one does. */
float8 clvr_spherical_row8(const float4 m, const float8 u, const float8 v, const float8 w)
{
    return m.x * u + m.y * v + m.z * w + m.w;
}

/* clvr_spherical_slab lane by lane (r_inner, r_lo, r_hi as vectors for the same fused products). */
float8 clvr_spherical_slab8(const float8 tc, const float8 p2, const float8 r_inner, const float8 r_lo, const float8 r_hi,
                            const float side)
{
    const float8 h_hi = sqrt(fmax(r_hi * r_hi - p2, 0.0f));
    const float8 h_lo = select(sqrt(fmax(r_lo * r_lo - p2, 0.0f)), (float8)(0.0f), isgreaterequal(p2, r_inner * r_inner));
    const float8 t0 = side > 0.0f ? tc + h_lo : tc - h_hi;
    const float8 t1 = side > 0.0f ? tc + h_hi : tc - h_lo;
    return fmax(t1 - fmax(t0, 0.0f), 0.0f);
}

/* spherical_fused for the 8 pixels (8 x .. 8 x + 7, y) of one work-item, one per float8 lane (kernels/packet.h):
 * the shells are the same spheres for every ray, so the lanes step through them together, each lane doing
 * spherical_fused's arithmetic (the same operations, the same bits) where its own loop would: a lane stops
 * the near pass at the first sphere it misses, starts the far pass at its own innermost sphere, skips hits
 * behind the eye, and stops once opaque. The ray set-up is the scalar code's, lane by lane. */
kernel void spherical_fused_packet(global float4* out, global uint* samples, global const float* texels,
                                   global const float* tf, global const float4* shells, const ClSphericalFusedParams p)
{
    const int x0 = (int)get_global_id(0) * CLVR_LANES, y = (int)get_global_id(1);
    if (x0 >= p.width || y >= p.height)
        return;
    const float2 size = (float2)((float)p.width, (float)p.height);
    float8 oc_x, oc_y, oc_z, dir_x, dir_y, dir_z, tc, p2;
#define CLVR_SPHERICAL_SETUP(L)                                                                            \
    {                                                                                                      \
        float3 oc, dir;                                                                                    \
        float t, q;                                                                                        \
        clvr_spherical_ray((float)(x0 + L), (float)y, p.camera, size, p.center.xyz, &oc, &dir, &t, &q);    \
        oc_x.s##L = oc.x, oc_y.s##L = oc.y, oc_z.s##L = oc.z;                                              \
        dir_x.s##L = dir.x, dir_y.s##L = dir.y, dir_z.s##L = dir.z;                                        \
        tc.s##L = t, p2.s##L = q;                                                                          \
    }
    CLVR_EACH_LANE(CLVR_SPHERICAL_SETUP)
#undef CLVR_SPHERICAL_SETUP
    const float inv_two_pi = 0.15915494309189535f, inv_pi = 0.3183098861837907f;
    const int4 dims = (int4)((int)p.tex.width, (int)p.tex.height, (int)p.tex.depth, 0);
    const float3 texels_n = convert_float3(dims.xyz);
    float8 c_r = 0.0f, c_g = 0.0f, c_b = 0.0f, transmittance = 1.0f;
    int8 taken = 0;
    int8 go = x0 + CLVR_LANE_INDEX < p.width; /* lanes still walking: in the image, not opaque */
    int8 innermost = p.shells;                /* each lane's innermost shell, found by pass 0 */
    for (int pass = 0; pass < 2; ++pass) {
        const float side = pass == 0 ? -1.0f : 1.0f;
        int8 walk = go; /* pass 0: lanes that have not yet missed a sphere */
        int n = 0;
        if (pass == 1) {
            /* each lane starts at its own innermost shell; lanes that met none have innermost = shells */
            n = clvr_min8(select((int8)(p.shells), innermost, go));
        }
        for (; n < p.shells; ++n) {
            const int k = pass == 0 ? p.shells - 1 - n : n;
            const float4 shell = shells[k];
            const float8 r = shell.x;
            int8 act;
            if (pass == 0) {
                walk &= isless(p2, r * r); /* a lane that misses this sphere misses every inner one */
                innermost = select(innermost, (int8)(k), walk);
                act = walk;
            } else {
                act = walk & (k >= innermost); /* a lane whose innermost shell lies further out joins later */
            }
            if (!any(walk))
                break;
            if (!any(act))
                continue;
            const float8 t = tc + side * sqrt(r * r - p2);
            act &= !isless(t, 0.0f); /* behind the eye */
            if (!any(act))
                continue;
            const float8 rel_x = t * dir_x - oc_x, rel_y = t * dir_y - oc_y, rel_z = t * dir_z - oc_z;
            float8 u = clvr_atan2_8(rel_y, rel_x) * inv_two_pi;
            u = select(select(u, (float8)(0.0f), isgreaterequal(u, 1.0f)), u + 1.0f, isless(u, 0.0f));
            const float8 v = clvr_atan2_8(sqrt(rel_x * rel_x + rel_y * rel_y), rel_z) * inv_pi;
            const float8 w = shell.w;
            const float8 q_x = clvr_spherical_wrap8(p.bias.x + p.scale.x * clvr_spherical_row8(p.matrix_row[0], u, v, w),
                                                    p.phi_s0, p.phi_period);
            const float8 q_y = p.bias.y + p.scale.y * clvr_spherical_row8(p.matrix_row[1], u, v, w);
            const float8 q_z = p.bias.z + p.scale.z * clvr_spherical_row8(p.matrix_row[2], u, v, w);
            /* the lanes that do not sample read texel 0 (their coordinates may be anything, NaN included) */
            const float8 g_x = select((float8)(0.0f), clamp(q_x * texels_n.x - 0.5f, 0.0f, texels_n.x - 1.0f), act);
            const float8 g_y = select((float8)(0.0f), clamp(q_y * texels_n.y - 0.5f, 0.0f, texels_n.y - 1.0f), act);
            const float8 g_z = select((float8)(0.0f), clamp(q_z * texels_n.z - 0.5f, 0.0f, texels_n.z - 1.0f), act);
            float8 cr, cg, cb, tau;
            clvr_tf_eval8(tf, p.tf_count, clvr_trilinear8(texels, dims, g_x, g_y, g_z), &cr, &cg, &cb, &tau);
            const float8 len = p.radial ? (float8)(shell.z - shell.y)
                                        : clvr_spherical_slab8(tc, p2, (float8)(k > 0 ? shells[k - 1].x : -1.0f),
                                                               (float8)(shell.y), (float8)(shell.z), side);
            const float8 alpha = 1.0f - clvr_exp2_8(-tau * len * M_LOG2E_F);
            const float8 ta = transmittance * alpha;
            c_r = select(c_r, c_r + ta * cr, act);
            c_g = select(c_g, c_g + ta * cg, act);
            c_b = select(c_b, c_b + ta * cb, act);
            transmittance = select(transmittance, transmittance * (1.0f - alpha), act);
            taken -= act; /* act is -1 where true */
            const int8 opaque = act & isgreaterequal(1.0f - transmittance, p.ert_alpha);
            go &= !opaque;
            walk &= !opaque;
        }
    }
    const float8 a = 1.0f - transmittance;
    const float8 o_r = c_r + transmittance * p.background.x, o_g = c_g + transmittance * p.background.y;
    const float8 o_b = c_b + transmittance * p.background.z;
    const size_t row = (size_t)y * p.width;
#define CLVR_SPHERICAL_STORE(L)                                                                            \
    if (x0 + L < p.width) {                                                                                \
        out[row + x0 + L] = (float4)(o_r.s##L, o_g.s##L, o_b.s##L, a.s##L);                                \
        samples[row + x0 + L] = (uint)taken.s##L;                                                          \
    }
    CLVR_EACH_LANE(CLVR_SPHERICAL_STORE)
#undef CLVR_SPHERICAL_STORE
}
