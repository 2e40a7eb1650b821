// kernels/cubefan.cl — the fragment programs of cubefan (seeds/002, Schussman & Max 2001), appended after
// kernels/raster.cl (host/render/grid/cubefan.h). Every cube of the octree has one value, so its color C
// and extinction tau are constant inside it and the exact contribution of a ray's chord of length l is
// (C alpha, alpha) with alpha = 1 - exp(-tau l); blending ONE, ONE_MINUS_SRC_ALPHA back to front
// composites the cubes.
//  - CLVR_CUBEFAN_FAN: the triangles of a projected cube (fans and strips of Figs. 4-6 as triangle lists).
//    attr[0] = (l / l_max, value, 0, 0) interpolated across each triangle (l = 0 on the silhouette), or
//    for CUBEFAN_OPACITY_LINEAR (alpha, value, 0, 0) with each vertex's own alpha.
//  - CLVR_CUBEFAN_BOX: a cube that reaches the near plane (one holding the eye, say), drawn as its back
//    faces in clip space; the fragment intersects its own ray with the box (attr[1] = lo, attr[2] = hi,
//    relative to the shifted origin), chord from max(entry, 0).
// buffer[1]: the transfer function (transfer_function.h layout); buffer[2]: the N x N exp-opacity texture,
// texel (i, j) = 1 - exp(-K i/(N-1) j/(N-1)), K = l_max tau_max, so that texel centres sit on u, v = k/(N-1).
#include "cubefan_params.h"

#if defined(CLVR_CUBEFAN_FAN) || defined(CLVR_CUBEFAN_BOX)
#include "transfer_function.h"

int clvr_fragment(const ClFragment* f, const ClFragmentResources* r, float4* color)
{
    constant ClCubefanUniforms* u = (constant ClCubefanUniforms*)r->uniforms;
    const float4 a = f->attr[0];
    const float4 tf = clvr_tf_eval(r->buffer[1], (int)u->counts.z, a.y);
    float alpha;
#ifdef CLVR_CUBEFAN_BOX
    const ClCamera cam = u->camera;
    float3 e, d;
    clvr_ray_unit(clvr_ray_window_offset(f->window, u->counts.xy, cam), cam, &e, &d);
    const float3 lo = f->attr[1].xyz, hi = f->attr[2].xyz;
    const float3 inv = 1.0f / d;  /* +-inf along an axis the ray is parallel to: the slabs below still hold */
    const float3 t0 = (lo - e) * inv, t1 = (hi - e) * inv;
    const float3 tn = fmin(t0, t1), tf3 = fmax(t0, t1);
    const float tIn = fmax(fmax(fmax(tn.x, tn.y), tn.z), 0.0f);
    const float tOut = fmin(fmin(tf3.x, tf3.y), tf3.z);
    if (!(tOut > tIn))
        return 0;
    alpha = -expm1(-tf.w * (tOut - tIn));
#else
    const int mode = (int)u->counts.w;
    if (mode == CUBEFAN_OPACITY_LINEAR) {
        alpha = a.x;
    } else if (mode == CUBEFAN_OPACITY_EXP) {
        alpha = -expm1(-tf.w * fmax(a.x, 0.0f) * u->scale.x);
    } else {
        /* §7: the texture at (l / l_max, tau / tau_max); texel k's centre is at k / (N - 1) of each axis. */
        ClTexture table;
        table.width = table.height = (cl_uint)u->scale.z;
        table.depth = 1u;
        table.channels = 1u;
        table.filter = CLVR_FILTER_LINEAR;
        table.wrap = CLVR_WRAP_CLAMP_TO_EDGE;
        table.pad0 = table.pad1 = 0u;
        table.border = (float4)(0.0f);
        const float n = u->scale.z;
        const float2 uv = (float2)(a.x, tf.w / u->scale.y) * ((n - 1.0f) / n) + 0.5f / n;
        alpha = clvr_tex2d(r->buffer[2], table, uv).x;
    }
#endif
    if (!(alpha > 0.0f))
        return 0;
    *color = (float4)(tf.xyz * alpha, alpha);
    return 1;
}

#endif
