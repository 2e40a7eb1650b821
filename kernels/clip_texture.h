/* kernels/clip_texture.h — the clip texture's test per sample (seeds/003, "Clipping with arbitrary
 * clipping geometry"; host/optics/clip_texture.h), shared by slice3d (fused kernel and fragment program) and
 * stack2d's fragment program: a second, one-channel texture, negative inside (a signed distance, or
 * 0.5 - mask value), sampled with linear filtering at the sample's clip-texture coordinates u
 * (normalized, GL's: texel i centered at (i + 0.5) / n). */
#ifndef CLVR_CLIP_TEXTURE_H
#define CLVR_CLIP_TEXTURE_H

#include "texture.h"

#ifdef __OPENCL_C_VERSION__

/* The clip texture of (width, height, depth) = dims.xyz texels: one channel, linear, clamp to edge
 * (as host/optics/clip_texture.cpp uploads it). */
ClTexture clvr_clip_texture(const float4 dims)
{
    ClTexture t;
    t.width = (uint)dims.x;
    t.height = (uint)dims.y;
    t.depth = (uint)dims.z;
    t.channels = 1u;
    t.filter = CLVR_FILTER_LINEAR;
    t.wrap = CLVR_WRAP_CLAMP_TO_EDGE;
    t.pad0 = t.pad1 = 0u;
    t.border = (float4)(0.0f);
    return t;
}

/* 1 when the sample at clip-texture coordinates u is drawn. Inside: u within the box of texel centers
 * and the filtered value < 0; drawn: inside, or outside when inverse is 1 (the alpha test on the mask). */
int clvr_clip_keep(global const float* texels, const ClTexture t, const float3 u, const int inverse)
{
    const float3 n = (float3)((float)t.width, (float)t.height, (float)t.depth);
    const float3 x = u * n;
    const int in_box = all(x >= 0.5f) && all(x <= n - 0.5f);
    const int inside = in_box && clvr_tex3d(texels, t, (float4)(u, 0.0f)).x < 0.0f;
    return inside != inverse;
}

#endif /* __OPENCL_C_VERSION__ */

#endif /* CLVR_CLIP_TEXTURE_H */
