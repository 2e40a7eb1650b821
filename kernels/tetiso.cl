// kernels/tetiso.cl — shaded iso-surfaces from cell faces (seeds/000 §4.1, Figure 8; host/render/tet/tetiso.h).
// Two uses: with CLVR_TETISO_FRAGMENT defined, the fragment program of the front-face draws, appended
// after kernels/raster.cl; otherwise the per-pixel passes between and after the draws.
#include "tetiso_params.h"

#ifdef CLVR_TETISO_FRAGMENT

/* attr[0] = the color to write; attr[1] = (0, cell id low 12 bits, id high 12 bits, 0), the same at the
 * three corners. buffer[0] = the kept back-face image (float4 per pixel: (t, id low, id high, s)), with
 * id low < 0 where no back face passed. uniforms: ClTetisoUniforms.
 * A front face survives only where the kept back face belongs to its own cell: what the paper's stencil
 * lock achieves by drawing each element's back faces again after its front faces. */
int clvr_fragment(const ClFragment* f, const ClFragmentResources* r, float4* color)
{
    constant ClTetisoUniforms* u = (constant ClTetisoUniforms*)r->uniforms;
    const int i = (int)f->window.y * (int)u->size.x + (int)f->window.x;
    const float4 kept = vload4(i, r->buffer[0]);
    if (!(kept.y >= 0.0f) || rint(kept.y) != rint(f->attr[1].y) || rint(kept.z) != rint(f->attr[1].z))
        return 0;
    *color = f->attr[0];
    return 1;
}

#else
#include "clvr_common.h"

/* Per pixel, from the kept back face b = (t_b, ids, s_b) and the front face f = (t_f, ids, s_f) of the
 * same cell (the front draw kept only those): the weight of the back face q = (iso - s_f) / (s_b - s_f)
 * (Figure 8; 1/2 for equal blending) and the surface's normalized eye depth t_f + q (t_b - t_f).
 * weights[i] = (q, t, 1, 0), or (0, 0, 0, 0) where no surface was found. */
kernel void tetiso_weights(global float4* weights, global const float4* front, global const float4* back,
                           const ClTetisoParams p)
{
    CLVR_GUARD_1D(p.count);
    const size_t i = get_global_id(0);
    const float4 b = back[i], f = front[i];
    if (!(b.y >= 0.0f) || !(f.y >= 0.0f)) {
        weights[i] = (float4)(0.0f);
        return;
    }
    const float span = b.w - f.w; /* > 0 for a crossing upwards, < 0 downwards */
    const float exact = span != 0.0f ? clamp((p.iso - f.w) / span, 0.0f, 1.0f) : 0.0f;
    const float depth = f.x + exact * (b.x - f.x);
    weights[i] = (float4)(p.equal ? 0.5f : exact, depth, 1.0f, 0.0f);
}

/* The first crossing is the nearer of the first one upwards and the first one downwards:
 * chosen[i] = (q, t, 1, 0 up or 1 down), or (0, 0, 0, 0) where neither was found. */
kernel void tetiso_nearer(global float4* chosen, global const float4* up, global const float4* down,
                          const ClTetisoParams p)
{
    CLVR_GUARD_1D(p.count);
    const size_t i = get_global_id(0);
    const float4 u = up[i], d = down[i];
    if (d.z != 0.0f && (u.z == 0.0f || d.y < u.y))
        chosen[i] = (float4)(d.x, d.y, 1.0f, 1.0f);
    else
        chosen[i] = u;
}

/* accum += q * shade (the back faces' draw) or (1 - q) * shade (the front faces'), where the chosen
 * crossing is of this pass's direction: the paper's shaded faces modulated by the weight images and
 * summed in the accumulation buffer. Alpha sums to the coverage. */
kernel void tetiso_add(global float4* accum, global const float4* shade, global const float4* chosen,
                       const ClTetisoParams p)
{
    CLVR_GUARD_1D(p.count);
    const size_t i = get_global_id(0);
    const float4 w = chosen[i];
    if (w.z == 0.0f || (int)w.w != (p.pass & 1))
        return;
    const float k = (p.pass & 2) ? w.x : 1.0f - w.x;
    accum[i] += (float4)(k * shade[i].xyz, k);
}

/* The accumulation buffer drawn back: clamp(I, 0, 1) + (1 - A) background, A. */
kernel void tetiso_finish(global float4* image, global const float4* accum, const ClTetisoParams p)
{
    CLVR_GUARD_1D(p.count);
    const size_t i = get_global_id(0);
    const float4 c = accum[i];
    image[i] = (float4)(clamp(c.xyz, 0.0f, 1.0f) + (1.0f - c.w) * p.background.xyz, c.w);
}
#endif
