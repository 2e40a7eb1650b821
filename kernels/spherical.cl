// kernels/spherical.cl — the per-shell pixel pass of the spherical technique (seeds/000 §2.2,
// host/render/grid/spherical.h, docs/spherical.md). The frame buffer `coords` holds, per pixel, the
// sphere's interpolated normalized spherical coordinates after the pixel transfer b + s·CM·p, which
// also mapped them to texture coordinates; `stencil` marks the pixels the shell covered. Per covered
// pixel: the φ coordinate wraps (GL_REPEAT of the periodic axis), the pixel texture fetch of the
// scalar volume (clvr_tex3d, as raster::pixelTexture), classification by the transfer function,
// opacity alpha = 1 - exp(-tau L) for the length L of the ray inside this shell's slab, and the
// "over" blend into `image` (back to front, premultiplied): dst = (C alpha, alpha) + (1 - alpha) dst.
#include "clvr_common.h"
#include "texture.h"
#include "transfer_function.h"

/* The length of the camera ray through pixel (px, py) inside the slab r_lo <= |x - center| <= r_hi
 * on one side of the ray's closest approach to the center (side +1: beyond it, where the sphere's
 * back faces are; -1: before it, the front faces), counting only t >= 0. A ray that does not reach
 * the next inner sphere, radius center.w (its closest distance p >= center.w), never meets that
 * sphere, so this one takes its whole path below r_hi: the slab then starts at p (r_lo ignored). cam: 0..3 position,
 * forward, right, up; cam[4] = (scale, aspect, parallel, 0) with scale tan(view_angle / 2) or the
 * parallel scale; size = (width, height). The ray is host/model/camera.cpp's PixelRays::at. */
float clvr_spherical_slab_length(const float px, const float py, const float4 cam0, const float4 cam1,
                                 const float4 cam2, const float4 cam3, const float4 cam4, const float2 size,
                                 const float4 center, const float r_lo, const float r_hi, const float side)
{
    const float ndc_x = (px + 0.5f) / size.x * 2.0f - 1.0f;
    const float ndc_y = 1.0f - (py + 0.5f) / size.y * 2.0f;
    const float3 right = cam2.xyz * (ndc_x * cam4.x * cam4.y), up = cam3.xyz * (ndc_y * cam4.x);
    float3 origin = cam0.xyz, dir;
    if (cam4.z != 0.0f) {
        origin += right + up;
        dir = cam1.xyz;
    } else {
        dir = normalize(cam1.xyz + right + up);
    }
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

/* phi_wrap = (s0, period): the φ texture coordinate s.x wraps to [s0, s0 + period) (period 0: no
 * wrap). slab = (r_lo, r_hi, side, radial): radial != 0 uses L = r_hi - r_lo for every pixel. */
kernel void spherical_shell(global const float4* coords, global const uchar* stencil, global float4* image,
                            const int width, const int height, global const float* texels, const ClTexture tex,
                            const float2 phi_wrap, global const float* tf, const int tf_count, const float4 cam0,
                            const float4 cam1, const float4 cam2, const float4 cam3, const float4 cam4,
                            const float4 center, const float4 slab)
{
    CLVR_GUARD_2D(width, height);
    const int x = (int)get_global_id(0), y = (int)get_global_id(1);
    const size_t i = (size_t)y * width + x;
    if (stencil[i] == 0)
        return;
    float4 s = coords[i];
    if (phi_wrap.y > 0.0f) {
        const float u = (s.x - phi_wrap.x) / phi_wrap.y;
        s.x = phi_wrap.x + (u - floor(u)) * phi_wrap.y;
    }
    const float value = clvr_tex3d(texels, tex, s).x;
    const float4 c = clvr_tf_eval(tf, tf_count, value); /* (r, g, b, tau) */
    const float len = slab.w != 0.0f ? slab.y - slab.x
                                     : clvr_spherical_slab_length((float)x, (float)y, cam0, cam1, cam2, cam3, cam4,
                                                                  (float2)((float)width, (float)height), center, slab.x,
                                                                  slab.y, slab.z);
    const float alpha = 1.0f - exp(-c.w * len);
    const float4 src = (float4)(c.xyz * alpha, alpha);
    image[i] = src + (1.0f - alpha) * image[i];
}
