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
#include "clvr_common.h"
#include "cubefan_params.h"
#include "transfer_function.h"

#if defined(CLVR_CUBEFAN_FAN) || defined(CLVR_CUBEFAN_BOX)

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

#if !defined(CLVR_CUBEFAN_FAN) && !defined(CLVR_CUBEFAN_BOX)
/* The fused path (host/render/grid/cubefan.cpp, docs/cubefan.md "Fused path"): the same selected cubes,
 * each pixel's ray walking them front to back in one kernel instead of projecting them as fans.
 * level[v], value[v] (CubeOctree::selectGrid, laid out by cubefan_at): per voxel v the level L of the selected cube
 * that holds it, bit 7 set where that cube is transparent, and the cube's value. In the coordinates
 * q = (p - field_lo) inv_spacing, voxel v's cube is [v, v + 1) and the selected cube holding it
 * [(v >> L) << L, min(((v >> L) + 1) << L, dims)). From the voxel where the ray enters the box of the bricks
 * that add color (p.filled_lo, p.filled_hi: outside it every cube is transparent) (t >= 0: in front of the
 * eye, or of the image plane) to where it leaves it, each step reads the cube holding the current voxel, adds
 * its chord of length l (world units: the ray's direction is a unit vector) as (C alpha, alpha) with
 * alpha = 1 - exp(-tau l), exactly as the reference integral and the raster path's exact thickness, and
 * moves to the voxel across the face the ray leaves by. The voxel index moves monotonically along the
 * ray's direction on every axis and strictly on the exit axis, so a ray takes at most
 * dims.x + dims.y + dims.z steps. out[pixel] = (rgb + (1 - A) background, A); steps[pixel]: cubes
 * crossed that add color, skipped[pixel]: transparent ones stepped over. */
/* Voxel v's place in the selection grid: bricks of 4 x 4 x 4 voxels (64 level bytes, one cache line), bricks
 * and the voxels inside them x fastest; bricks = the grid's brick counts (dims rounded up to 4, / 4). A ray
 * stepping from voxel to voxel mostly stays in the brick it is in. */
static size_t cubefan_at(const int x, const int y, const int z, const int4 bricks)
{
    const size_t brick = ((size_t)(z >> 2) * (size_t)bricks.y + (size_t)(y >> 2)) * (size_t)bricks.x + (size_t)(x >> 2);
    return (brick << 6) | (size_t)(((z & 3) << 4) | ((y & 3) << 2) | (x & 3));
}

/* Where the ray q(t) = e + d t is at t along one axis, as the voxel of the next step: across the exit face on
 * the exit axis; on the others floor(q) kept inside the cube [lo, hi) and never behind the current voxel v
 * (rounding), so that every coordinate moves monotonically along the ray. */
static int cubefan_next(const int exit_axis, const int v, const int lo, const int hi, const int positive,
                        const float e, const float d, const float t)
{
    if (exit_axis)
        return positive ? hi : lo - 1;
    const int along = clamp((int)floor(e + d * t), lo, hi - 1);
    return positive ? max(v, along) : min(v, along);
}

kernel void cubefan_fused(global float4* out, global uint* steps, global uint* skipped, global const uchar* level,
                          global const float* value, global const uchar* space, global const float* tf,
                          const ClCubefanFusedParams p)
{
    CLVR_GUARD_2D(p.width, p.height);
    const int x = (int)get_global_id(0), y = (int)get_global_id(1);
    const size_t pixel = (size_t)y * (size_t)p.width + (size_t)x;
    float3 e, d;
    clvr_ray_unit(clvr_ray_window_offset(clvr_ray_pixel_centre(x, y), (float2)((float)p.width, (float)p.height), p.camera),
                  p.camera, &e, &d);
    const float3 qe3 = (e - p.field_lo.xyz) * p.inv_spacing.xyz;
    float3 qd3 = d * p.inv_spacing.xyz;
    /* A ray parallel to an axis gets a direction of 1e-30 along it: its exits there lie beyond any other. */
    qd3 = select(qd3, copysign((float3)(1e-30f), qd3), isless(fabs(qd3), (float3)(1e-30f)));
    const float3 inv3 = 1.0f / qd3;
    /* The ray's part inside the box of the bricks that add color: outside it every cube is transparent. */
    const int3 box_lo = p.filled_lo.xyz, box_hi = p.filled_hi.xyz;
    const float3 t0 = (convert_float3(box_lo) - qe3) * inv3, t1 = (convert_float3(box_hi) - qe3) * inv3;
    const float3 tn = fmin(t0, t1), tx = fmax(t0, t1);
    float t = fmax(fmax(fmax(tn.x, tn.y), tn.z), 0.0f);
    const float t_out = fmin(fmin(tx.x, tx.y), tx.z);
    /* The walk in scalars: PoCL runs it one work-item at a time (the rays diverge), and three-component
     * vectors cost shuffles there. */
    const float qex = qe3.x, qey = qe3.y, qez = qe3.z, qdx = qd3.x, qdy = qd3.y, qdz = qd3.z;
    const float ix = inv3.x, iy = inv3.y, iz = inv3.z;
    const int nx = p.dims.x, ny = p.dims.y, nz = p.dims.z;
    const int px = qdx > 0.0f, py = qdy > 0.0f, pz = qdz > 0.0f;
    const int4 bricks = (int4)((nx + 3) >> 2, (ny + 3) >> 2, (nz + 3) >> 2, 0);
    float3 c = (float3)(0.0f);
    float transmittance = 1.0f;
    uint crossed = 0, stepped_over = 0;
    if (t_out > t) {
        int vx = clamp((int)floor(qex + qdx * t), box_lo.x, box_hi.x - 1);
        int vy = clamp((int)floor(qey + qdy * t), box_lo.y, box_hi.y - 1);
        int vz = clamp((int)floor(qez + qdz * t), box_lo.z, box_hi.z - 1);
        for (;;) {
            const size_t at = cubefan_at(vx, vy, vz, bricks);
            const int code = level[at];
            const int l = code & 0x7f;
            int lox = (vx >> l) << l, loy = (vy >> l) << l, loz = (vz >> l) << l;
            int hix = min(lox + (1 << l), nx), hiy = min(loy + (1 << l), ny), hiz = min(loz + (1 << l), nz);
            if (code & 0x80) {
                /* Transparent: the cube of empty bricks around this one, when it is wider than the cube */
                const int r = (int)space[at >> 6] - 1;
                if (r >= 0 && 8 * r + 4 > (1 << l)) {
                    lox = max(((vx >> 2) - r) << 2, 0);
                    loy = max(((vy >> 2) - r) << 2, 0);
                    loz = max(((vz >> 2) - r) << 2, 0);
                    hix = min(((vx >> 2) + r + 1) << 2, nx);
                    hiy = min(((vy >> 2) + r + 1) << 2, ny);
                    hiz = min(((vz >> 2) + r + 1) << 2, nz);
                }
            }
            const float tbx = ((float)(px ? hix : lox) - qex) * ix;
            const float tby = ((float)(py ? hiy : loy) - qey) * iy;
            const float tbz = ((float)(pz ? hiz : loz) - qez) * iz;
            const int axis = tbx <= tby ? (tbx <= tbz ? 0 : 2) : (tby <= tbz ? 1 : 2);
            const float t_exit = fmax(axis == 0 ? tbx : (axis == 1 ? tby : tbz), t);
            if (code & 0x80) {
                ++stepped_over;
            } else {
                ++crossed;
                const float4 ct = clvr_tf_eval(tf, p.tf_count, value[at]);
                const float alpha = 1.0f - clvr_exp2(ct.w * ((t - t_exit) * M_LOG2E_F));
                c += (transmittance * alpha) * ct.xyz;
                transmittance *= 1.0f - alpha;
                if (1.0f - transmittance >= p.ert_alpha)
                    break;
            }
            t = t_exit;
            vx = cubefan_next(axis == 0, vx, lox, hix, px, qex, qdx, t);
            vy = cubefan_next(axis == 1, vy, loy, hiy, py, qey, qdy, t);
            vz = cubefan_next(axis == 2, vz, loz, hiz, pz, qez, qdz, t);
            if (vx < box_lo.x || vy < box_lo.y || vz < box_lo.z || vx >= box_hi.x || vy >= box_hi.y || vz >= box_hi.z)
                break; /* out of the box (a line leaves a box once) */
        }
    }
    out[pixel] = (float4)(c + transmittance * p.background.xyz, 1.0f - transmittance);
    steps[pixel] = crossed;
    skipped[pixel] = stepped_over;
}
#endif
