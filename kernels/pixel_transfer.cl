// kernels/pixel_transfer.cl — GL 1.2 imaging pixel transfer and frame-buffer pixel operations
// (DESIGN.md, raster stage: Pixel transfer). The host has validated the state; this file only does
// arithmetic. Nothing is clamped to [0,1] except the lookup-table index: the color buffer is float.
// Each kernel takes its buffers as arguments and its scalars as one struct of
// kernels/pixel_transfer_params.h (raster/pixel_transfer.cpp fills them); `lut` holds the lookup
// tables of the 4 channels concatenated, as xf.lut_n and xf.lut_first index them.
#include "clvr_common.h"
#include "pixel_transfer_params.h"
#include "texture.h"

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
float4 clvr_pixel_transfer(float4 c, const ClPixelTransfer xf, global const float* lut)
{
    const float4 mc = (float4)(dot(xf.matrix_row[0], c), dot(xf.matrix_row[1], c), dot(xf.matrix_row[2], c),
                               dot(xf.matrix_row[3], c));
    float4 r = xf.bias + xf.scale * mc;
    if (xf.lut_n.x)
        r.x = clvr_lookup(r.x, lut + xf.lut_first.x, xf.lut_n.x);
    if (xf.lut_n.y)
        r.y = clvr_lookup(r.y, lut + xf.lut_first.y, xf.lut_n.y);
    if (xf.lut_n.z)
        r.z = clvr_lookup(r.z, lut + xf.lut_first.z, xf.lut_n.z);
    if (xf.lut_n.w)
        r.w = clvr_lookup(r.w, lut + xf.lut_first.w, xf.lut_n.w);
    return r;
}

/* DrawPixelsBlend (CLVR_DRAW_*): result from source s and destination d, factors ONE/ONE (GL blend
 * equations). */
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
kernel void pixel_transfer(global float4* color, global const float* lut, const ClPixelTransferParams p)
{
    CLVR_GUARD_1D(p.n);
    const size_t i = get_global_id(0);
    color[i] = clvr_pixel_transfer(color[i], p.xf, lut);
}

// glDrawPixels of src (src_width x src_height, row 0 at the top) with its top-left pixel at
// (offset_x, offset_y) in dst: pixel transfer, then the pixel texture if use_texture (the transferred
// RGB as str), then blending. One work-item per source pixel; pixels landing outside dst are dropped.
kernel void draw_pixels(global float4* dst, global const float4* src, global const float* texels,
                        global const float* lut, const ClDrawPixelsParams p)
{
    CLVR_GUARD_2D(p.src_width, p.src_height);
    const int x = (int)get_global_id(0), y = (int)get_global_id(1);
    const int dx = x + p.offset_x, dy = y + p.offset_y;
    if (dx < 0 || dy < 0 || dx >= p.dst_width || dy >= p.dst_height)
        return;
    float4 s = clvr_pixel_transfer(src[(size_t)y * p.src_width + x], p.xf, lut);
    if (p.use_texture)
        s = clvr_tex3d(texels, p.tex, s);
    const size_t d = (size_t)dy * p.dst_width + dx;
    dst[d] = clvr_draw_blend(s, dst[d], p.blend);
}

// SGI pixel texture: each pixel's RGB is a 3D texture coordinate (s, t, r); the filtered texel
// replaces the pixel's color, alpha included (seeds/000 §2.2).
kernel void pixel_texture(global float4* color, global const float* texels, const ClPixelTextureParams p)
{
    CLVR_GUARD_1D(p.n);
    const size_t i = get_global_id(0);
    color[i] = clvr_tex3d(texels, p.tex, color[i]);
}

// glAccum(op, value) (GL 1.2 §4.2.4), op one of CLVR_ACCUM_*: ACCUM acc += value c; LOAD acc = value c;
// RETURN c = value acc; MULT acc *= value; ADD acc += value.
kernel void accum(global float4* color, global float4* acc, const ClAccumParams p)
{
    CLVR_GUARD_1D(p.n);
    const size_t i = get_global_id(0);
    const float value = p.value;
    switch (p.op) {
    case CLVR_ACCUM_ACCUM: acc[i] += value * color[i]; break;
    case CLVR_ACCUM_LOAD: acc[i] = value * color[i]; break;
    case CLVR_ACCUM_RETURN: color[i] = value * acc[i]; break;
    case CLVR_ACCUM_MULT: acc[i] *= value; break;
    default: acc[i] += (float4)(value); break;
    }
}
