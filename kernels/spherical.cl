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

/* The length of the camera ray through pixel (px, py) inside the slab r_lo <= |x - center| <= r_hi
 * on one side of the ray's closest approach to the center (side +1: beyond it, where the sphere's
 * back faces are; -1: before it, the front faces), counting only t >= 0. A ray that does not reach
 * the next inner sphere, radius center.w (its closest distance p >= center.w), never meets that
 * sphere, so this one takes its whole path below r_hi: the slab then starts at p (r_lo ignored).
 * size = (width, height). The ray is kernels/ray.h's clvr_ray_rounded_terms (unit direction). */
float clvr_spherical_slab_length(const float px, const float py, const ClCamera cam, const float2 size,
                                 const float4 center, const float r_lo, const float r_hi, const float side)
{
    float3 origin, dir;
    clvr_ray_rounded_terms(clvr_ray_window_offset((float2)(px + 0.5f, py + 0.5f), size, cam), cam, &origin,
                           &dir);
    const float3 oc = center.xyz - origin;
    const float tc = dot(oc, dir);
    const float3 off = oc - tc * dir; /* center minus its closest ray point: p = |off|, no cancellation */
    const float p2 = dot(off, off);
    const float h_hi = sqrt(fmax(r_hi * r_hi - p2, 0.0f));
    const float h_lo = p2 >= center.w * center.w ? 0.0f : sqrt(fmax(r_lo * r_lo - p2, 0.0f));
    const float t0 = side > 0.0f ? tc + h_lo : tc - h_hi;
    const float t1 = side > 0.0f ? tc + h_hi : tc - h_lo;
    return fmax(t1 - fmax(t0, 0.0f), 0.0f);
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
    if (p.phi_period > 0.0f) {
        const float u = (s.x - p.phi_s0) / p.phi_period;
        s.x = p.phi_s0 + (u - floor(u)) * p.phi_period;
    }
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
