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
#include "packet.h"

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

/* A pixel's ray in the selection grid's coordinates q = e + d t (t: world length, d a unit vector): e, its
 * direction d (1e-30 along an axis the ray is parallel to: its exits there lie beyond any other), 1 / d, and
 * [t, t_out), its part inside the box of the bricks that add color (outside it every cube is transparent) in
 * front of the eye; t_out <= t: none. s: the pixel's image-plane offset (clvr_ray_window_offset). The
 * perspective direction is normalized here, component by component, so that cubefan_fused_packet can repeat
 * it lane by lane (normalize() has no 8-lane twin). */
static void cubefan_ray(const float2 s, const ClCubefanFusedParams* p, float3* qe, float3* qd, float3* inv,
                        float* t, float* t_out)
{
    const ClCamera cam = p->camera;
    float3 e, d;
    clvr_ray_depth(s, cam, &e, &d);
    if (!clvr_ray_parallel(cam)) {
        const float n2 = d.x * d.x + d.y * d.y + d.z * d.z;
        d *= 1.0f / sqrt(n2);
    }
    *qe = (e - p->field_lo.xyz) * p->inv_spacing.xyz;
    float3 q = d * p->inv_spacing.xyz;
    q = select(q, copysign((float3)(1e-30f), q), isless(fabs(q), (float3)(1e-30f)));
    *qd = q;
    *inv = 1.0f / q;
    const float3 t0 = (convert_float3(p->filled_lo.xyz) - *qe) * *inv, t1 = (convert_float3(p->filled_hi.xyz) - *qe) * *inv;
    const float3 tn = fmin(t0, t1), tx = fmax(t0, t1);
    *t = fmax(fmax(fmax(tn.x, tn.y), tn.z), 0.0f);
    *t_out = fmin(fmin(tx.x, tx.y), tx.z);
}

kernel void cubefan_fused(global float4* out, global uint* steps, global uint* skipped, global const uchar* level,
                          global const float* value, global const uchar* space, global const float* tf,
                          const ClCubefanFusedParams p)
{
    CLVR_GUARD_2D(p.width, p.height);
    const int x = (int)get_global_id(0), y = (int)get_global_id(1);
    const size_t pixel = (size_t)y * (size_t)p.width + (size_t)x;
    float3 qe3, qd3, inv3;
    float t, t_out;
    cubefan_ray(clvr_ray_window_offset(clvr_ray_pixel_centre(x, y), (float2)((float)p.width, (float)p.height), p.camera),
                &p, &qe3, &qd3, &inv3, &t, &t_out);
    const int3 box_lo = p.filled_lo.xyz, box_hi = p.filled_hi.xyz;
    /* The walk in scalars (three-component vectors cost shuffles on CPUs; cubefan_fused_packet below walks 8
     * rays as vector lanes, the same operations). */
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

/* cubefan_fused for 8 pixels of a row at once, one per lane of 8-wide vectors (kernels/packet.h; docs/cubefan.md,
 * "Ray packets"): every lane walks its own ray through its own cubes, the same operations as cubefan_fused lane
 * by lane, so the pixels are the same bits. A lane that has left the box or become opaque keeps its state
 * while the others go on; the packet ends when none is left. The grid's entries are indexed in 32 bits (the
 * host runs cubefan_fused where they do not fit). */
/* cubefan_next lane by lane (exit: the lanes leaving by this axis' face; positive: the lanes whose ray goes up it). */
static int8 cubefan_next8(const int8 exit, const int8 v, const int8 lo, const int8 hi, const int8 positive,
                          const float8 e, const float8 d, const float8 t)
{
    const int8 along = clamp(convert_int8(floor(e + d * t)), lo, hi - 1);
    return select(select(min(v, along), max(v, along), positive), select(lo - 1, hi, positive), exit);
}

/* cubefan_ray lane by lane for the 8 pixels (x0 .. x0 + 7, y) (lanes past the image's width take rays beyond it,
 * which the kernels do not store): e and d in the selection grid's coordinates, and 1 / d. */
static void cubefan_ray8(const int x0, const int y, const ClCubefanFusedParams* p, float8* qex, float8* qey, float8* qez,
                         float8* qdx, float8* qdy, float8* qdz, float8* ix, float8* iy, float8* iz)
{
    /* each lane's ray, cubefan_ray's expressions lane by lane (as slice3d_fused_packet: the row's offset s.y
     * is one scalar, made a vector so that its products fuse into the sums as the float3 expressions' do) */
    const ClCamera cam = p->camera;
    const float2 size = (float2)((float)p->width, (float)p->height);
    const float8 sy = clvr_ray_window_offset(clvr_ray_pixel_centre(x0, y), size, cam).y;
    const float8 sx = (convert_float8(x0 + CLVR_LANE_INDEX) + 0.5f) / size.x * 2.0f - 1.0f;
    const float8 s_x = sx * cam.params.x * cam.params.y;
    float8 e_x, e_y, e_z, d_x, d_y, d_z;
    if (clvr_ray_parallel(cam)) {
        e_x = cam.position.x + s_x * cam.right.x + sy * cam.up.x;
        e_y = cam.position.y + s_x * cam.right.y + sy * cam.up.y;
        e_z = cam.position.z + s_x * cam.right.z + sy * cam.up.z;
        d_x = cam.forward.x, d_y = cam.forward.y, d_z = cam.forward.z;
    } else {
        e_x = cam.position.x, e_y = cam.position.y, e_z = cam.position.z;
        d_x = cam.forward.x + s_x * cam.right.x + sy * cam.up.x;
        d_y = cam.forward.y + s_x * cam.right.y + sy * cam.up.y;
        d_z = cam.forward.z + s_x * cam.right.z + sy * cam.up.z;
        const float8 n2 = d_x * d_x + d_y * d_y + d_z * d_z;
        const float8 inv_len = 1.0f / sqrt(n2);
        d_x *= inv_len, d_y *= inv_len, d_z *= inv_len;
    }
    *qex = (e_x - p->field_lo.x) * p->inv_spacing.x, *qey = (e_y - p->field_lo.y) * p->inv_spacing.y,
    *qez = (e_z - p->field_lo.z) * p->inv_spacing.z;
    const float8 q_x = d_x * p->inv_spacing.x, q_y = d_y * p->inv_spacing.y, q_z = d_z * p->inv_spacing.z;
    *qdx = select(q_x, copysign((float8)(1e-30f), q_x), isless(fabs(q_x), (float8)(1e-30f)));
    *qdy = select(q_y, copysign((float8)(1e-30f), q_y), isless(fabs(q_y), (float8)(1e-30f)));
    *qdz = select(q_z, copysign((float8)(1e-30f), q_z), isless(fabs(q_z), (float8)(1e-30f)));
    *ix = 1.0f / *qdx, *iy = 1.0f / *qdy, *iz = 1.0f / *qdz;
}

kernel void cubefan_fused_packet(global float4* out, global uint* steps, global uint* skipped,
                                 global const uchar* level, global const float* value, global const uchar* space,
                                 global const float* tf, const ClCubefanFusedParams p)
{
    const int x0 = (int)get_global_id(0) * CLVR_LANES, y = (int)get_global_id(1);
    if (x0 >= p.width || y >= p.height)
        return;
    const int3 box_lo = p.filled_lo.xyz, box_hi = p.filled_hi.xyz;
    float8 qex, qey, qez, qdx, qdy, qdz, ix, iy, iz;
    cubefan_ray8(x0, y, &p, &qex, &qey, &qez, &qdx, &qdy, &qdz, &ix, &iy, &iz);
    const float8 t0x = ((float)box_lo.x - qex) * ix, t1x = ((float)box_hi.x - qex) * ix;
    const float8 t0y = ((float)box_lo.y - qey) * iy, t1y = ((float)box_hi.y - qey) * iy;
    const float8 t0z = ((float)box_lo.z - qez) * iz, t1z = ((float)box_hi.z - qez) * iz;
    float8 t = fmax(fmax(fmax(fmin(t0x, t1x), fmin(t0y, t1y)), fmin(t0z, t1z)), 0.0f);
    const float8 t_out = fmin(fmin(fmax(t0x, t1x), fmax(t0y, t1y)), fmax(t0z, t1z));
    int8 vx = 0, vy = 0, vz = 0;
    const int nx = p.dims.x, ny = p.dims.y, nz = p.dims.z;
    const int8 px = isgreater(qdx, 0.0f), py = isgreater(qdy, 0.0f), pz = isgreater(qdz, 0.0f);
    const uint bricks_x = (uint)((nx + 3) >> 2), bricks_y = (uint)((ny + 3) >> 2);
    float8 c_r = 0.0f, c_g = 0.0f, c_b = 0.0f, transmittance = 1.0f;
    int8 crossed = 0, stepped_over = 0;
    /* lanes still walking: in the image, in the box, not opaque */
    int8 live = (x0 + CLVR_LANE_INDEX < p.width) & isgreater(t_out, t);
    vx = select(vx, clamp(convert_int8(floor(qex + qdx * t)), box_lo.x, box_hi.x - 1), live);
    vy = select(vy, clamp(convert_int8(floor(qey + qdy * t)), box_lo.y, box_hi.y - 1), live);
    vz = select(vz, clamp(convert_int8(floor(qez + qdz * t)), box_lo.z, box_hi.z - 1), live);
    while (any(live)) {
        /* cubefan_at lane by lane; the lanes that have stopped read entry 0 */
        const uint8 brick = (convert_uint8(vz >> 2) * bricks_y + convert_uint8(vy >> 2)) * bricks_x + convert_uint8(vx >> 2);
        const uint8 at = select((uint8)(0u), (brick << 6) | convert_uint8(((vz & 3) << 4) | ((vy & 3) << 2) | (vx & 3)), live);
        int8 code;
        CLVR_GATHER8(code, level, at);
        const int8 l = code & 0x7f;
        const int8 side = (int8)(1) << l;
        int8 lox = (vx >> l) << l, loy = (vy >> l) << l, loz = (vz >> l) << l;
        int8 hix = min(lox + side, nx), hiy = min(loy + side, ny), hiz = min(loz + side, nz);
        const int8 transparent = (code & 0x80) != 0;
        if (any(transparent & live)) {
            /* the cube of empty bricks around a transparent cube, where it is wider than the cube (the radius less
             * one in each lane's own load: CLVR_GATHER8 and a vector subtraction made the frame 25 % slower on
             * PoCL 3.1, BENCHMARKS.md "cubefan's empty-space read") */
            int8 r;
#define CUBEFAN_SPACE(L) r.s##L = (int)space[at.s##L >> 6] - 1;
            CLVR_EACH_LANE(CUBEFAN_SPACE)
#undef CUBEFAN_SPACE
            const int8 wide = transparent & (r >= 0) & (8 * r + 4 > side);
            lox = select(lox, max(((vx >> 2) - r) << 2, 0), wide);
            loy = select(loy, max(((vy >> 2) - r) << 2, 0), wide);
            loz = select(loz, max(((vz >> 2) - r) << 2, 0), wide);
            hix = select(hix, min(((vx >> 2) + r + 1) << 2, nx), wide);
            hiy = select(hiy, min(((vy >> 2) + r + 1) << 2, ny), wide);
            hiz = select(hiz, min(((vz >> 2) + r + 1) << 2, nz), wide);
        }
        const float8 tbx = (convert_float8(select(lox, hix, px)) - qex) * ix;
        const float8 tby = (convert_float8(select(loy, hiy, py)) - qey) * iy;
        const float8 tbz = (convert_float8(select(loz, hiz, pz)) - qez) * iz;
        const int8 xy = islessequal(tbx, tby);
        const int8 exit_x = xy & islessequal(tbx, tbz);
        const int8 exit_y = ~xy & islessequal(tby, tbz);
        const int8 exit_z = ~(exit_x | exit_y);
        const float8 t_exit = fmax(select(select(tbz, tby, exit_y), tbx, exit_x), t);
        const int8 opaque = live & ~transparent;
        stepped_over -= live & transparent;
        crossed -= opaque;
        if (any(opaque)) {
            float8 cr, cg, cb, tau;
            float8 v;
            CLVR_GATHER8(v, value, at);
            clvr_tf_eval8(tf, p.tf_count, v, &cr, &cg, &cb, &tau);
            const float8 alpha = 1.0f - clvr_exp2_8(tau * ((t - t_exit) * M_LOG2E_F));
            const float8 ta = transmittance * alpha;
            c_r = select(c_r, c_r + ta * cr, opaque);
            c_g = select(c_g, c_g + ta * cg, opaque);
            c_b = select(c_b, c_b + ta * cb, opaque);
            transmittance = select(transmittance, transmittance * (1.0f - alpha), opaque);
            live &= ~(opaque & isgreaterequal(1.0f - transmittance, p.ert_alpha));
        }
        t = t_exit;
        const int8 nvx = cubefan_next8(exit_x, vx, lox, hix, px, qex, qdx, t);
        const int8 nvy = cubefan_next8(exit_y, vy, loy, hiy, py, qey, qdy, t);
        const int8 nvz = cubefan_next8(exit_z, vz, loz, hiz, pz, qez, qdz, t);
        /* out of the box (a line leaves a box once) */
        live &= (nvx >= box_lo.x) & (nvy >= box_lo.y) & (nvz >= box_lo.z) & (nvx < box_hi.x) & (nvy < box_hi.y) &
                (nvz < box_hi.z);
        vx = select(vx, nvx, live);
        vy = select(vy, nvy, live);
        vz = select(vz, nvz, live);
    }
    const size_t row = (size_t)y * (size_t)p.width;
#define CUBEFAN_STORE(L)                                                                                             \
    if (x0 + L < p.width) {                                                                                          \
        const size_t pixel = row + (size_t)(x0 + L);                                                                 \
        out[pixel] = (float4)((float3)(c_r.s##L, c_g.s##L, c_b.s##L) + transmittance.s##L * p.background.xyz,        \
                              1.0f - transmittance.s##L);                                                            \
        steps[pixel] = (uint)crossed.s##L;                                                                           \
        skipped[pixel] = (uint)stepped_over.s##L;                                                                    \
    }
    CLVR_EACH_LANE(CUBEFAN_STORE)
#undef CUBEFAN_STORE
}

/* The tile path ("path": "tiles", host/render/grid/cubefan.cpp; docs/cubefan.md): §6's selected cubes projected in
 * the octree's visibility order, as the fans are, but each cube's pixels found by a tile's rays instead of the raster
 * stage. The cubes that add color, front to back, binned to tiles of 8 x 4 pixels by their boxes of pixel centres
 * (tile_start: each tile's first entry, CSR; tile_cubes: cube ids in that order; boxes[cube] = (x0, y0, x1, y1),
 * inclusive); cubes[3 i] = (low corner, value), cubes[3 i + 1] = (high corner, 0) of cube i in the selection grid's
 * coordinates (cubefan_ray's q), cubes[3 i + 2] its color and extinction (cubefan_cube_colors). A pixel's ray meets a cube of its tile whose box holds the pixel by the slab test;
 * its chord [t_in, t_out), t_in >= 0, adds (C alpha, alpha), alpha = 1 - exp(-tau (t_out - t_in)), front to back
 * under what is in front, as the walk adds its chords (the same expressions), until the opacity reaches
 * p.ert_alpha. out[pixel] = (rgb + (1 - A) background, A); steps[pixel]: the chords added. tiles_x: tiles per row. */
#define CUBEFAN_TILE_W_LOG2 3 /* host/render/grid/cubefan.h kCubefanTileW, H */
#define CUBEFAN_TILE_H_LOG2 2
#define CUBEFAN_TILE_H (1 << CUBEFAN_TILE_H_LOG2)
#define CUBEFAN_AHEAD 12 /* how many tile entries ahead cubefan_tiles_packet prefetches its cubes (BENCHMARKS.md run CT3) */
#if (1 << CUBEFAN_TILE_W_LOG2) != CLVR_LANES || CUBEFAN_TILE_H != 4
#error "cubefan_tiles_packet takes a tile as two pairs of rows of 8"
#endif

/* Once per selection: each cube's color and extinction, cubes[3 i + 2] = the transfer function at its value (as the
 * walk evaluates it per chord). n: the cubes. */
kernel void cubefan_cube_colors(global float4* cubes, global const float* tf, const int tf_count, const uint n)
{
    const uint i = (uint)get_global_id(0);
    if (i >= n)
        return;
    cubes[3 * i + 2] = clvr_tf_eval(tf, tf_count, cubes[3 * i].w);
}

/* The extent in image-plane offsets (right and up over the depth along forward) of the part of the box [lo, hi] (relative
 * to the eye) at depth >= z_near: its corners beyond z_near and the crossings of that plane by its 12 edges.
 * (min x, min y, max x, max y). */
static float4 cubefan_clipped_extent(const float3 lo, const float3 hi, const ClCamera* cam, const float z_near)
{
    float x[8], y[8], z[8];
    for (int k = 0; k < 8; ++k) {
        const float3 q = (float3)(k & 1 ? hi.x : lo.x, k & 2 ? hi.y : lo.y, k & 4 ? hi.z : lo.z);
        x[k] = dot(q, cam->right.xyz), y[k] = dot(q, cam->up.xyz), z[k] = dot(q, cam->forward.xyz);
    }
    float4 e = (float4)(INFINITY, INFINITY, -INFINITY, -INFINITY);
    for (int k = 0; k < 8; ++k) {
        if (z[k] >= z_near)
            e = (float4)(fmin(e.xy, (float2)(x[k], y[k]) / z[k]), fmax(e.zw, (float2)(x[k], y[k]) / z[k]));
        for (int bit = 1; bit < 8; bit <<= 1) {
            const int j = k | bit;
            if ((k & bit) || (z[k] >= z_near) == (z[j] >= z_near))
                continue;
            const float f = (z_near - z[k]) / (z[j] - z[k]);
            const float2 q = (float2)(x[k] + f * (x[j] - x[k]), y[k] + f * (y[j] - y[k])) / z_near;
            e = (float4)(fmin(e.xy, q), fmax(e.zw, q));
        }
    }
    return e;
}

/* Per frame: each cube's box of pixel centres, grown by 0.01 pixel and 1e-5 of its size (far more than the rays'
 * float rounding reaches past the projection) and clipped to the image; (1, 1, 0, 0) when empty. Parallel: its eight
 * corners projected. Perspective (the inverse of kernels/ray.h's rays): a point the rays reach at depth z along
 * forward is within z c of the eye, c = |d| / (d . forward) of the image's corner ray; so a cube at distance r from
 * the eye is seen only in its part at depth >= z_near = r / (2 c), which is projected — its corners there, or where it
 * crosses that plane its clipped part (cubefan_clipped_extent); a cube holding the eye covers the whole image, one
 * wholly nearer than z_near none. 8 cubes per work-item, one per lane (PoCL does not vectorize the work-items of
 * this kernel itself): cubes 8 i .. 8 i + 7 of n. */
kernel void cubefan_cube_boxes(global const float4* cubes, global short4* boxes, const ClCubefanFusedParams p,
                               const uint n)
{
    const uint first = (uint)get_global_id(0) * CLVR_LANES;
    if (first >= n)
        return;
    const ClCamera cam = p.camera;
    float8 lo_x, lo_y, lo_z, hi_x, hi_y, hi_z;
#define CUBEFAN_LOAD(L)                                                                                              \
    {                                                                                                                \
        const uint i = min(first + L, n - 1);                                                                        \
        const float4 a = cubes[3 * i], b = cubes[3 * i + 1];                                                         \
        lo_x.s##L = a.x, lo_y.s##L = a.y, lo_z.s##L = a.z, hi_x.s##L = b.x, hi_y.s##L = b.y, hi_z.s##L = b.z;         \
    }
    CLVR_EACH_LANE(CUBEFAN_LOAD)
#undef CUBEFAN_LOAD
    /* relative to the eye, in world units */
    lo_x = p.field_lo.x + lo_x / p.inv_spacing.x - cam.position.x, hi_x = p.field_lo.x + hi_x / p.inv_spacing.x - cam.position.x;
    lo_y = p.field_lo.y + lo_y / p.inv_spacing.y - cam.position.y, hi_y = p.field_lo.y + hi_y / p.inv_spacing.y - cam.position.y;
    lo_z = p.field_lo.z + lo_z / p.inv_spacing.z - cam.position.z, hi_z = p.field_lo.z + hi_z / p.inv_spacing.z - cam.position.z;
    const int parallel = clvr_ray_parallel(cam);
    /* each corner's extent (over its depth: perspective) */
    float8 min_x = INFINITY, max_x = -INFINITY, min_y = INFINITY, max_y = -INFINITY, min_z = INFINITY, max_z = -INFINITY;
#define CUBEFAN_CORNER(K)                                                                                            \
    {                                                                                                                \
        const float8 x = (K) & 1 ? hi_x : lo_x, y = (K) & 2 ? hi_y : lo_y, z = (K) & 4 ? hi_z : lo_z;                 \
        const float8 depth = x * cam.forward.x + y * cam.forward.y + z * cam.forward.z;                              \
        const float8 w = parallel ? (float8)(1.0f) : 1.0f / depth;                                                   \
        const float8 sx = (x * cam.right.x + y * cam.right.y + z * cam.right.z) * w;                                 \
        const float8 sy = (x * cam.up.x + y * cam.up.y + z * cam.up.z) * w;                                          \
        min_x = fmin(min_x, sx), max_x = fmax(max_x, sx), min_y = fmin(min_y, sy), max_y = fmax(max_y, sy);          \
        min_z = fmin(min_z, depth), max_z = fmax(max_z, depth);                                                      \
    }
    CLVR_EACH_LANE(CUBEFAN_CORNER)
#undef CUBEFAN_CORNER
    int8 whole = 0, empty = 0;
    if (!parallel) {
        const float8 gap_x = fmax(fmax(lo_x, -hi_x), 0.0f), gap_y = fmax(fmax(lo_y, -hi_y), 0.0f),
                     gap_z = fmax(fmax(lo_z, -hi_z), 0.0f);
        const float8 distance = sqrt(gap_x * gap_x + gap_y * gap_y + gap_z * gap_z);
        const float c = sqrt(1.0f + cam.params.x * cam.params.x * (1.0f + cam.params.y * cam.params.y));
        const float8 z_near = distance * (0.5f / c);
        whole = isequal(distance, 0.0f);
        empty = ~whole & islessequal(max_z, z_near);
        const int8 crosses = ~whole & ~empty & isless(min_z, z_near);
        if (any(crosses)) {
#define CUBEFAN_CLIP(L)                                                                                              \
            if (crosses.s##L) {                                                                                      \
                const float4 e = cubefan_clipped_extent((float3)(lo_x.s##L, lo_y.s##L, lo_z.s##L),                   \
                                                        (float3)(hi_x.s##L, hi_y.s##L, hi_z.s##L), &cam, z_near.s##L);  \
                min_x.s##L = e.x, min_y.s##L = e.y, max_x.s##L = e.z, max_y.s##L = e.w;                              \
            }
            CLVR_EACH_LANE(CUBEFAN_CLIP)
#undef CUBEFAN_CLIP
        }
    }
    /* window = (ndc + 1) / 2 size; pixel centre x at window x + 0.5; a band's rows start at cam.position.w */
    const float full_h = cam.forward.w > 0.0f ? cam.forward.w : (float)p.height;
    const float kx = 0.5f * (float)p.width / (cam.params.x * cam.params.y), ky = 0.5f * full_h / cam.params.x;
    const float cx0 = 0.5f * (float)p.width - 0.5f, cy0 = 0.5f * full_h - 0.5f - cam.position.w;
    const float8 px0 = min_x * kx + cx0, px1 = max_x * kx + cx0, py0 = cy0 - max_y * ky, py1 = cy0 - min_y * ky;
    const float8 pad = 0.01f + 1e-5f * fmin(fmax(px1 - px0, py1 - py0), 1e30f);
    const float w1 = (float)(p.width - 1), h1 = (float)(p.height - 1);
    const float8 x0 = select(fmax(ceil(px0 - pad), 0.0f), 0.0f, whole), x1 = select(fmin(floor(px1 + pad), w1), w1, whole);
    const float8 y0 = select(fmax(ceil(py0 - pad), 0.0f), 0.0f, whole), y1 = select(fmin(floor(py1 + pad), h1), h1, whole);
    empty |= isgreater(x0, x1) | isgreater(y0, y1) | isnan(x0) | isnan(x1) | isnan(y0) | isnan(y1);
#define CUBEFAN_STORE_BOX(L)                                                                                         \
    if (first + L < n)                                                                                               \
        boxes[first + L] = empty.s##L ? (short4)(1, 1, 0, 0)                                                         \
                                      : (short4)((short)x0.s##L, (short)y0.s##L, (short)x1.s##L, (short)y1.s##L);
    CLVR_EACH_LANE(CUBEFAN_STORE_BOX)
#undef CUBEFAN_STORE_BOX
}

kernel void cubefan_tiles(global float4* out, global uint* steps, global const uint* tile_start,
                          global const uint* tile_cubes, global const short4* boxes, global const float4* cubes,
                          const ClCubefanFusedParams p, const int tiles_x)
{
    CLVR_GUARD_2D(p.width, p.height);
    const int x = (int)get_global_id(0), y = (int)get_global_id(1);
    float3 qe, qd, inv;
    float t_box, t_box_out;
    cubefan_ray(clvr_ray_window_offset(clvr_ray_pixel_centre(x, y), (float2)((float)p.width, (float)p.height), p.camera),
                &p, &qe, &qd, &inv, &t_box, &t_box_out);
    const int tile = (y >> CUBEFAN_TILE_H_LOG2) * tiles_x + (x >> CUBEFAN_TILE_W_LOG2);
    float3 c = (float3)(0.0f);
    float transmittance = 1.0f;
    uint crossed = 0;
    const uint end = tile_start[tile + 1];
    for (uint k = tile_start[tile]; k < end; ++k) {
        const uint i = tile_cubes[k];
        const short4 b = boxes[i];
        if (!clvr_box_holds(b, x, y))
            continue;
        const float4 lo = cubes[3 * i], hi = cubes[3 * i + 1], ct = cubes[3 * i + 2];
        const float t0x = (lo.x - qe.x) * inv.x, t1x = (hi.x - qe.x) * inv.x;
        const float t0y = (lo.y - qe.y) * inv.y, t1y = (hi.y - qe.y) * inv.y;
        const float t0z = (lo.z - qe.z) * inv.z, t1z = (hi.z - qe.z) * inv.z;
        const float t_in = fmax(fmax(fmax(fmin(t0x, t1x), fmin(t0y, t1y)), fmin(t0z, t1z)), 0.0f);
        const float t_out = fmin(fmin(fmax(t0x, t1x), fmax(t0y, t1y)), fmax(t0z, t1z));
        if (!(t_out > t_in))
            continue;
        ++crossed;
        const float alpha = 1.0f - clvr_exp2(ct.w * ((t_in - t_out) * M_LOG2E_F));
        c += (transmittance * alpha) * ct.xyz;
        transmittance *= 1.0f - alpha;
        if (1.0f - transmittance >= p.ert_alpha)
            break;
    }
    const size_t pixel = (size_t)y * (size_t)p.width + (size_t)x;
    out[pixel] = (float4)(c + transmittance * p.background.xyz, 1.0f - transmittance);
    steps[pixel] = crossed;
}

/* cubefan_tiles for a whole tile per work-item: two rows of 8 pixels as the 16 lanes of one vector (16 floats, one
 * AVX-512 register), the tile's 4 rows as two such pairs. Each cube of the list is loaded once for the tile and met by
 * the pairs its box reaches, the lanes outside its box (or past the image) masked, without asking whether any lane
 * hits (that branch cost more than the work it skipped; BENCHMARKS.md run CT1). Lane by lane the operations of
 * cubefan_tiles (kernels/packet.h's rule): the same bits. */
kernel void cubefan_tiles_packet(global float4* out, global uint* steps, global const uint* tile_start,
                                 global const uint* tile_cubes, global const short4* boxes, global const float4* cubes,
                                 const ClCubefanFusedParams p, const int tiles_x)
{
    const int tx = (int)get_global_id(0), ty = (int)get_global_id(1);
    if (tx >= tiles_x || ty >= ((p.height + CUBEFAN_TILE_H - 1) >> CUBEFAN_TILE_H_LOG2))
        return;
    const int x0 = tx << CUBEFAN_TILE_W_LOG2, y0 = ty << CUBEFAN_TILE_H_LOG2;
    const int rows = min(CUBEFAN_TILE_H, p.height - y0);
    const int8 xs8 = x0 + CLVR_LANE_INDEX;
    const int16 xs = (int16)(xs8, xs8);
    const int16 lane_row = (int16)((int8)(0), (int8)(1));  /* the lane's row within its pair */
    float16 qex[2], qey[2], qez[2], ix[2], iy[2], iz[2], c_r[2], c_g[2], c_b[2], transmittance[2];
    int16 crossed[2], live[2];
    for (int pair = 0; pair < 2; ++pair) {
        float8 ex[2], ey[2], ez[2], dx, dy, dz, inx[2], iny[2], inz[2];
        for (int r = 0; r < 2; ++r)
            cubefan_ray8(x0, y0 + 2 * pair + r, &p, &ex[r], &ey[r], &ez[r], &dx, &dy, &dz, &inx[r], &iny[r], &inz[r]);
        qex[pair] = (float16)(ex[0], ex[1]), qey[pair] = (float16)(ey[0], ey[1]), qez[pair] = (float16)(ez[0], ez[1]);
        ix[pair] = (float16)(inx[0], inx[1]), iy[pair] = (float16)(iny[0], iny[1]), iz[pair] = (float16)(inz[0], inz[1]);
        c_r[pair] = c_g[pair] = c_b[pair] = 0.0f, transmittance[pair] = 1.0f;
        crossed[pair] = 0;
        live[pair] = (xs < p.width) & (2 * pair + lane_row < rows);
    }
    /* from one eye (perspective) every ray's e is the same: a cube's corners less e once per cube */
    const int eye = !clvr_ray_parallel(p.camera);
    const float e_x = qex[0].s0, e_y = qey[0].s0, e_z = qez[0].s0;
    const int tile = ty * tiles_x + tx;
    const uint end = tile_start[tile + 1];
    for (uint k = tile_start[tile]; k < end; ++k) {
        const uint i = tile_cubes[k];
        if (k + CUBEFAN_AHEAD < end) {  /* the cubes come in visibility order, scattered in memory */
            const uint ahead = tile_cubes[k + CUBEFAN_AHEAD];
            CLVR_PREFETCH(boxes + ahead, 1);
            CLVR_PREFETCH(cubes + 3 * (size_t)ahead, 3);
        }
        const short4 b = boxes[i];
        const int16 columns = (xs >= (int)b.x) & (xs <= (int)b.z);
        const float4 lo = cubes[3 * i], hi = cubes[3 * i + 1], ct = cubes[3 * i + 2];
        const float a_x = lo.x - e_x, a_y = lo.y - e_y, a_z = lo.z - e_z, b_x = hi.x - e_x, b_y = hi.y - e_y,
                    b_z = hi.z - e_z;
        const int pair_lo = max((int)b.y - y0, 0) >> 1, pair_hi = min((int)b.w - y0, CUBEFAN_TILE_H - 1) >> 1;
        for (int pair = pair_lo; pair <= pair_hi; ++pair) {
            const int16 row = y0 + 2 * pair + lane_row;
            const float16 t0x = (eye ? (float16)(a_x) : lo.x - qex[pair]) * ix[pair];
            const float16 t1x = (eye ? (float16)(b_x) : hi.x - qex[pair]) * ix[pair];
            const float16 t0y = (eye ? (float16)(a_y) : lo.y - qey[pair]) * iy[pair];
            const float16 t1y = (eye ? (float16)(b_y) : hi.y - qey[pair]) * iy[pair];
            const float16 t0z = (eye ? (float16)(a_z) : lo.z - qez[pair]) * iz[pair];
            const float16 t1z = (eye ? (float16)(b_z) : hi.z - qez[pair]) * iz[pair];
            const float16 t_in = fmax(fmax(fmax(fmin(t0x, t1x), fmin(t0y, t1y)), fmin(t0z, t1z)), 0.0f);
            const float16 t_out = fmin(fmin(fmax(t0x, t1x), fmax(t0y, t1y)), fmax(t0z, t1z));
            const int16 m = live[pair] & columns & (row >= (int)b.y) & (row <= (int)b.w) & isgreater(t_out, t_in);
            crossed[pair] -= m;
            const float16 alpha = 1.0f - clvr_exp2_16(ct.w * ((t_in - t_out) * M_LOG2E_F));
            const float16 ta = transmittance[pair] * alpha;
            c_r[pair] = select(c_r[pair], c_r[pair] + ta * ct.x, m);
            c_g[pair] = select(c_g[pair], c_g[pair] + ta * ct.y, m);
            c_b[pair] = select(c_b[pair], c_b[pair] + ta * ct.z, m);
            transmittance[pair] = select(transmittance[pair], transmittance[pair] * (1.0f - alpha), m);
            live[pair] &= ~(m & isgreaterequal(1.0f - transmittance[pair], p.ert_alpha));
        }
        if (p.ert_alpha <= 1.0f && !any(live[0]) && !any(live[1]))
            break;  /* early termination: every pixel of the tile is opaque */
    }
    for (int row = 0; row < rows; ++row) {
        float r[16], g[16], bl[16], t[16];
        int n[16];
        const int pair = row >> 1, h = (row & 1) * CLVR_LANES;
        vstore16(c_r[pair], 0, r), vstore16(c_g[pair], 0, g), vstore16(c_b[pair], 0, bl);
        vstore16(transmittance[pair], 0, t), vstore16(crossed[pair], 0, n);
        const size_t at = (size_t)(y0 + row) * (size_t)p.width + (size_t)x0;
        for (int c = 0; c < CLVR_LANES && x0 + c < p.width; ++c) {
            out[at + c] = (float4)((float3)(r[h + c], g[h + c], bl[h + c]) + t[h + c] * p.background.xyz, 1.0f - t[h + c]);
            steps[at + c] = (uint)n[h + c];
        }
    }
}
#endif
