// kernels/pixel_transfer.cl — GL 1.2 imaging pixel transfer and frame-buffer pixel operations
// (DESIGN.md, raster stage: Pixel transfer). The host has validated the state; this file only does
// arithmetic. Nothing is clamped to [0,1] except the lookup-table index: the color buffer is float.
#include "clvr_common.h"
#include "texture.h"

/* The transfer state as kernel arguments, in this order (raster/pixel_transfer.cpp sets them):
 * the color matrix as 4 rows, scale, bias, the lookup tables of the 4 channels concatenated, each
 * channel's table length (0: no table for that channel) and its first entry in `lut`. */
/* One line each: tools/embed_kernels.cmake splits lines as a CMake list, where a trailing
 * backslash would escape the separator. */
#define CLVR_TRANSFER_PARAMS const float4 m0, const float4 m1, const float4 m2, const float4 m3, const float4 scale, const float4 bias, global const float* lut, const uint4 lut_n, const uint4 lut_first
#define CLVR_TRANSFER_ARGS m0, m1, m2, m3, scale, bias, lut, lut_n, lut_first

/* One channel through its table: index x = clamp(c, 0, 1) (n - 1), linear between entries
 * floor(x) and floor(x) + 1. n = 1 is a constant. fmin/fmax send NaN to an end of the table. */
float clvr_lookup(float c, global const float* table, uint n)
{
    if (n == 1u)
        return table[0];
    const float x = fmin(fmax(c, 0.0f), 1.0f) * (float)(n - 1u);
    const float i0 = fmin(floor(x), (float)(n - 2u));
    const int i = (int)i0;
    return mix(table[i], table[i + 1], x - i0);
}

/* c' = bias + scale * (CM c) (seeds/000 §2.2, GL's post-color-matrix scale and bias), then the
 * post-color-matrix color table of each channel that has one. */
float4 clvr_pixel_transfer(float4 c, CLVR_TRANSFER_PARAMS)
{
    const float4 mc = (float4)(dot(m0, c), dot(m1, c), dot(m2, c), dot(m3, c));
    float4 r = bias + scale * mc;
    if (lut_n.x)
        r.x = clvr_lookup(r.x, lut + lut_first.x, lut_n.x);
    if (lut_n.y)
        r.y = clvr_lookup(r.y, lut + lut_first.y, lut_n.y);
    if (lut_n.z)
        r.z = clvr_lookup(r.z, lut + lut_first.z, lut_n.z);
    if (lut_n.w)
        r.w = clvr_lookup(r.w, lut + lut_first.w, lut_n.w);
    return r;
}

/* DrawPixelsBlend: result from source s and destination d, factors ONE/ONE (GL blend equations). */
#define CLVR_DRAW_REPLACE 0u
#define CLVR_DRAW_ADD 1u
#define CLVR_DRAW_SUBTRACT 2u
#define CLVR_DRAW_REVERSE_SUBTRACT 3u
#define CLVR_DRAW_MIN 4u
#define CLVR_DRAW_MAX 5u

float4 clvr_draw_blend(float4 s, float4 d, uint blend)
{
    switch (blend) {
    case CLVR_DRAW_ADD: return s + d;
    case CLVR_DRAW_SUBTRACT: return s - d;
    case CLVR_DRAW_REVERSE_SUBTRACT: return d - s;
    case CLVR_DRAW_MIN: return fmin(s, d);
    case CLVR_DRAW_MAX: return fmax(s, d);
    default: return s;
    }
}

// The frame buffer's color copied onto itself through the pixel transfer (glCopyPixels), in place.
kernel void pixel_transfer(global float4* color, const uint n, CLVR_TRANSFER_PARAMS)
{
    CLVR_GUARD_1D(n);
    const size_t i = get_global_id(0);
    color[i] = clvr_pixel_transfer(color[i], CLVR_TRANSFER_ARGS);
}

// glDrawPixels of src (src_w x src_h, row 0 at the top) with its top-left pixel at `offset` in dst:
// pixel transfer, then the pixel texture if use_texture (the transferred RGB as str), then blending.
// One work-item per source pixel; pixels landing outside dst are dropped.
kernel void draw_pixels(global float4* dst, const int dst_w, const int dst_h, global const float4* src,
                        const int src_w, const int src_h, const int2 offset, const uint blend,
                        const uint use_texture, global const float* texels, const ClTexture tex,
                        CLVR_TRANSFER_PARAMS)
{
    CLVR_GUARD_2D(src_w, src_h);
    const int x = (int)get_global_id(0), y = (int)get_global_id(1);
    const int dx = x + offset.x, dy = y + offset.y;
    if (dx < 0 || dy < 0 || dx >= dst_w || dy >= dst_h)
        return;
    float4 s = clvr_pixel_transfer(src[(size_t)y * src_w + x], CLVR_TRANSFER_ARGS);
    if (use_texture)
        s = clvr_tex3d(texels, tex, s);
    const size_t d = (size_t)dy * dst_w + dx;
    dst[d] = clvr_draw_blend(s, dst[d], blend);
}

// SGI pixel texture: each pixel's RGB is a 3D texture coordinate (s, t, r); the filtered texel
// replaces the pixel's color, alpha included (seeds/000 §2.2).
kernel void pixel_texture(global float4* color, const uint n, global const float* texels, const ClTexture tex)
{
    CLVR_GUARD_1D(n);
    const size_t i = get_global_id(0);
    color[i] = clvr_tex3d(texels, tex, color[i]);
}

// glAccum(op, value) (GL 1.2 §4.2.4): ACCUM acc += value c; LOAD acc = value c; RETURN c = value acc;
// MULT acc *= value; ADD acc += value.
#define CLVR_ACCUM_ACCUM 0u
#define CLVR_ACCUM_LOAD 1u
#define CLVR_ACCUM_RETURN 2u
#define CLVR_ACCUM_MULT 3u
#define CLVR_ACCUM_ADD 4u

kernel void accum(global float4* color, global float4* acc, const uint n, const uint op, const float value)
{
    CLVR_GUARD_1D(n);
    const size_t i = get_global_id(0);
    switch (op) {
    case CLVR_ACCUM_ACCUM: acc[i] += value * color[i]; break;
    case CLVR_ACCUM_LOAD: acc[i] = value * color[i]; break;
    case CLVR_ACCUM_RETURN: color[i] = value * acc[i]; break;
    case CLVR_ACCUM_MULT: acc[i] *= value; break;
    default: acc[i] += (float4)(value); break;
    }
}
