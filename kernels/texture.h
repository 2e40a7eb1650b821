/* kernels/texture.h — 1D/2D/3D textures on global float buffers (DESIGN.md, raster stage: Textures).
 * Compiled as OpenCL C 1.2 (layout and sampling functions) and as C++ (layout only, see
 * raster/texture.h). GL semantics (OpenGL 1.2 spec §3.8.5-3.8.7): normalized coordinates, texel i
 * centered at (i + 0.5) / n; NEAREST takes texel floor(u n); LINEAR weights the two texels around
 * u n - 0.5; CLAMP_TO_EDGE clamps the texel index to [0, n-1]; CLAMP_TO_BORDER uses the border color
 * for texels outside [0, n-1], so linear filtering blends towards the border in the outer half texel.
 * Texels are float, x fastest, then y, then z; 4 channels are interleaved RGBA; a 1-channel texture
 * returns (v, v, v, v), as GL's INTENSITY format does.
 * Hand-written filtering on buffers, not image3d_t: faster on PoCL and available everywhere
 * (OPENCL-NOTES.md). */
#ifndef CLVR_TEXTURE_H
#define CLVR_TEXTURE_H

#include "cl_types.h"  /* cl_uint, cl_float4, ... on both sides */

#define CLVR_FILTER_NEAREST 0u
#define CLVR_FILTER_LINEAR 1u
#define CLVR_WRAP_CLAMP_TO_EDGE 0u
#define CLVR_WRAP_CLAMP_TO_BORDER 1u

typedef struct {
    cl_uint width, height, depth, channels; /* channels 1 or 4; a 1D texture has height = depth = 1 */
    cl_uint filter, wrap, pad0, pad1;       /* CLVR_FILTER_*, CLVR_WRAP_* */
    cl_float4 border;                       /* CLAMP_TO_BORDER color, RGBA */
} ClTexture;                                /* 48 bytes */

#ifdef __OPENCL_C_VERSION__

/* The texel at integer index (i, j, k), after the wrap rule. */
float4 clvr_tex_texel(global const float* texels, const ClTexture t, int i, int j, int k)
{
    if (t.wrap == CLVR_WRAP_CLAMP_TO_BORDER) {
        if (i < 0 || j < 0 || k < 0 || i >= (int)t.width || j >= (int)t.height || k >= (int)t.depth)
            return t.border;
    } else {
        i = clamp(i, 0, (int)t.width - 1);
        j = clamp(j, 0, (int)t.height - 1);
        k = clamp(k, 0, (int)t.depth - 1);
    }
    const size_t index = ((size_t)k * t.height + (size_t)j) * t.width + (size_t)i;
    if (t.channels == 1u) {
        const float v = texels[index];
        return (float4)(v, v, v, v);
    }
    return vload4(index, texels);
}

/* Texel-space position u n of normalized coordinate u along an axis of n texels, limited to
 * [-0.5, n + 0.5] before the integer conversion. That is GL's coordinate clamp for CLAMP_TO_BORDER
 * (u in [-1/2n, 1 + 1/2n]): nearest then yields indices -1..n, linear lower indices -1..n with
 * weight 0 at the limits, so far outside gives exactly the border (or the edge texel for
 * CLAMP_TO_EDGE, where the index clamp decides anyway). It also keeps huge or infinite coordinates
 * from overflowing int; fmin/fmax map NaN to a limit, so a NaN coordinate samples a defined texel. */
float clvr_tex_position(float u, cl_uint n)
{
    return fmin(fmax(u * (float)n, -0.5f), (float)n + 0.5f);
}

/* NEAREST: texel floor(u n). Returns the index, which may be -1 or n (then the wrap rule applies). */
int clvr_tex_nearest_index(float u, cl_uint n)
{
    return (int)floor(clvr_tex_position(u, n));
}

/* LINEAR: the lower texel i0 = floor(u n - 0.5) and the weight f of texel i0 + 1. */
int clvr_tex_linear_index(float u, cl_uint n, float* f)
{
    const float x = clvr_tex_position(u, n) - 0.5f;
    const float i0 = floor(x);
    *f = x - i0;
    return (int)i0;
}

float4 clvr_tex1d(global const float* texels, const ClTexture t, float s)
{
    if (t.filter == CLVR_FILTER_NEAREST)
        return clvr_tex_texel(texels, t, clvr_tex_nearest_index(s, t.width), 0, 0);
    float fx;
    const int i = clvr_tex_linear_index(s, t.width, &fx);
    return mix(clvr_tex_texel(texels, t, i, 0, 0), clvr_tex_texel(texels, t, i + 1, 0, 0), fx);
}

float4 clvr_tex2d(global const float* texels, const ClTexture t, float2 st)
{
    if (t.filter == CLVR_FILTER_NEAREST)
        return clvr_tex_texel(texels, t, clvr_tex_nearest_index(st.x, t.width),
                              clvr_tex_nearest_index(st.y, t.height), 0);
    float fx, fy;
    const int i = clvr_tex_linear_index(st.x, t.width, &fx);
    const int j = clvr_tex_linear_index(st.y, t.height, &fy);
    const float4 c0 = mix(clvr_tex_texel(texels, t, i, j, 0), clvr_tex_texel(texels, t, i + 1, j, 0), fx);
    const float4 c1 = mix(clvr_tex_texel(texels, t, i, j + 1, 0), clvr_tex_texel(texels, t, i + 1, j + 1, 0), fx);
    return mix(c0, c1, fy);
}

float4 clvr_tex3d(global const float* texels, const ClTexture t, float4 str)
{
    if (t.filter == CLVR_FILTER_NEAREST)
        return clvr_tex_texel(texels, t, clvr_tex_nearest_index(str.x, t.width),
                              clvr_tex_nearest_index(str.y, t.height), clvr_tex_nearest_index(str.z, t.depth));
    float fx, fy, fz;
    const int i = clvr_tex_linear_index(str.x, t.width, &fx);
    const int j = clvr_tex_linear_index(str.y, t.height, &fy);
    const int k = clvr_tex_linear_index(str.z, t.depth, &fz);
    const float4 c00 = mix(clvr_tex_texel(texels, t, i, j, k), clvr_tex_texel(texels, t, i + 1, j, k), fx);
    const float4 c10 = mix(clvr_tex_texel(texels, t, i, j + 1, k), clvr_tex_texel(texels, t, i + 1, j + 1, k), fx);
    const float4 c01 = mix(clvr_tex_texel(texels, t, i, j, k + 1), clvr_tex_texel(texels, t, i + 1, j, k + 1), fx);
    const float4 c11 =
        mix(clvr_tex_texel(texels, t, i, j + 1, k + 1), clvr_tex_texel(texels, t, i + 1, j + 1, k + 1), fx);
    return mix(mix(c00, c10, fy), mix(c01, c11, fy), fz);
}

#endif /* __OPENCL_C_VERSION__ */

#endif /* CLVR_TEXTURE_H */
