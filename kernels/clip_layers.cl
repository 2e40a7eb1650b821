// kernels/clip_layers.cl — the fragment program that peels a closed clip mesh into depth layers for
// slice3d's fused path (seeds/000 §2.1's stencil clipping without a stencil; host/render/grid/slice3d.cpp,
// docs/slice3d.md "Clipping with closed meshes"). The host appends this file, with CLVR_CLIP_LAYERS_FRAGMENT
// defined, after kernels/raster.cl and draws the whole mesh once per layer with the depth test LESS: a
// fragment survives only beyond the previous layer's window depth at its pixel, so layer l holds the
// (l+1)-th surface along each pixel's ray. Compiled on its own (the offline syntax test) it pulls in
// raster.cl itself. The host has validated everything; this file only does arithmetic.
#ifndef CLVR_CLIP_LAYERS_FRAGMENT
#include "raster.cl"
#endif

/* attr[0] = the world position (perspective-correct). uniforms[0] = (eye position, image width),
 * uniforms[1] = (forward, 0). buffer[0] = the previous layer's window depth per pixel (row 0 at the top;
 * -1 before the first layer). Output (eye depth of the surface point, 1 if front-facing else 0, 0, 0). */
int clvr_fragment(const ClFragment* f, const ClFragmentResources* r, float4* color)
{
    const float4 eye = r->uniforms[0], forward = r->uniforms[1];
    const size_t pixel = (size_t)f->window.y * (size_t)eye.w + (size_t)f->window.x;
    if (!(f->depth > r->buffer[0][pixel]))
        return 0;
    *color = (float4)(dot(f->attr[0].xyz - eye.xyz, forward.xyz), f->front_facing ? 1.0f : 0.0f, 0.0f, 0.0f);
    return 1;
}
