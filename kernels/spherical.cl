// kernels/spherical.cl — the per-shell pixel pass of the spherical technique (seeds/000 §2.2,
// host/render/grid/spherical.h, docs/spherical.md). The frame buffer `coords` holds, per pixel, the
// sphere's interpolated normalized spherical coordinates after the pixel transfer b + s·CM·p, which
// also mapped them to texture coordinates; `stencil` marks the pixels the shell covered. Per covered
// pixel: the φ coordinate wraps (GL_REPEAT of the periodic axis), the pixel texture fetch of the
// scalar volume (clvr_tex3d, as raster::pixelTexture), classification by the transfer function,
// opacity alpha = 1 - exp(-tau L) for the length L of the ray inside this shell's slab, and the
// "over" blend into `image` (back to front, premultiplied): dst = (C alpha, alpha) + (1 - alpha) dst.
#include "clvr_common.h"
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
            const float4 uvw = (float4)(u, v, shell.w, 1.0f);
            float4 q = p.bias + p.scale * (float4)(dot(p.matrix_row[0], uvw), dot(p.matrix_row[1], uvw),
                                                   dot(p.matrix_row[2], uvw), dot(p.matrix_row[3], uvw));
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
