// kernels/slice3d.cl — 3D-texture slicing (§2 of seeds/000_354856c7f65dc3f9.txt): planes parallel to
// the image plane, trilinear samples, classification after interpolation, alpha = 1 - exp(-tau Delta)
// with Delta the pixel ray's length between slices, premultiplied color, "over" blending.
// Two uses of this file (host/render/grid/slice3d.cpp):
//  - the fused kernel slice3d_fused: one work-item per pixel walks all slices (the fast path);
//  - with CLVR_SLICE3D_FRAGMENT defined, it is appended after kernels/raster.cl as the fragment
//    program of the pass-by-pass path (the specification): one fragment per slice and pixel.
// The host has validated everything; this file only does arithmetic.
#include "clvr_common.h"
#include "clip_texture.h"
#include "ray.h"
#include "texture.h"
#include "transfer_function.h"
#include "volume_sampling.h"
#include "empty_space.h"
#include "packet.h"
#ifdef SLICE3D_PREINTEGRATED
#include "segment_integral.h"
#endif

#include "slice3d_params.h"

/* Shared by both paths: the slabs at the box faces. Slice k stands for the slab [z - ds/2, z + ds/2] of
 * eye depth around it (z = depth0 + k ds), except where that slab reaches past the ray's chord through the
 * grid box [chord_in, chord_out]: the first slice inside the chord (the one before it lies outside)
 * reaches back to chord_in, the last forward to chord_out, so that the slabs cover the chord exactly once.
 * Without it a ray gains or loses up to one slab's opacity at each face: first order in ds (DESIGN's
 * midpoint rule is second order only inside). Returns -(its ray length) * log2(e), so that
 * alpha = 1 - clvr_exp2(tau * it); neg_delta_log2e is the full slab's, neg_stretch_log2e per unit of depth. */
float slice3d_slab_log2e(const float z, const float delta_s, const float chord_in, const float chord_out,
                         const float neg_delta_log2e, const float neg_stretch_log2e)
{
    const int first = z - delta_s < chord_in, last = z + delta_s > chord_out;
    if (!first && !last)
        return neg_delta_log2e;
    const float lo = first ? chord_in : z - 0.5f * delta_s;
    const float hi = last ? chord_out : z + 0.5f * delta_s;
    return fmax(hi - lo, 0.0f) * neg_stretch_log2e;
}

#ifndef CLVR_SLICE3D_FRAGMENT

#ifdef SLICE3D_CLIP_MESH
/* Clipping with a closed mesh on the fused path (docs/slice3d.md, "Clipping with closed meshes"): the
 * mesh's surfaces along this pixel's ray, peeled by kernels/clip_layers.cl, layers[l * stride] =
 * (eye depth, 1 if front-facing) for l < count in increasing depth ((+inf, 1) past the pixel's last
 * surface). The sample at eye depth z is inside iff the first surface beyond it is a back face (two-pass:
 * the stencil passes' rule), or iff any surface beyond it is a back face (naive: Figure 2's rule). *next is
 * the first layer beyond the previous sample, moved to this one's (z only grows or only shrinks along a
 * loop, so this is one or two steps at most per layer). Returns 1 when the sample is drawn. */
int slice3d_mesh_keep(global const float4* layers, const size_t stride, const int4 mesh, const int last_back,
                      int* next, const float z)
{
    int n = *next;
    while (n < mesh.x && layers[(size_t)n * stride].x <= z)
        ++n;
    while (n > 0 && layers[(size_t)(n - 1) * stride].x > z)
        --n;
    *next = n;
    const int inside = mesh.z ? n <= last_back : (n < mesh.x && layers[(size_t)n * stride].y == 0.0f);
    return inside != mesh.y;
}

/* The deepest back face among a pixel's mesh layers (-1: none), for the naive rule. */
int slice3d_mesh_last_back(global const float4* layers, const size_t stride, const int4 mesh)
{
    int last_back = -1;
    for (int l = 0; l < mesh.x; ++l)
        if (layers[(size_t)l * stride].y == 0.0f)
            last_back = l;
    return last_back;
}
#endif

#ifdef SLICE3D_CLIP_TEXTURE
/* Clip-texture coordinates are affine in the world position, so along the ray o + z d they are uo + z ud. */
void slice3d_clip_ray(const ClSlice3dParams* p, const float3 o, const float3 d, float3* uo, float3* ud)
{
    const float4 clip_row0 = p->clip_row[0], clip_row1 = p->clip_row[1], clip_row2 = p->clip_row[2];
    *uo = (float3)(dot(clip_row0.xyz, o) + clip_row0.w, dot(clip_row1.xyz, o) + clip_row1.w,
                   dot(clip_row2.xyz, o) + clip_row2.w);
    *ud = (float3)(dot(clip_row0.xyz, d), dot(clip_row1.xyz, d), dot(clip_row2.xyz, d));
}
#endif

/* The volume's type on the device for the fused kernel: float by default; the host builds with
 * -DSLICE3D_VOXEL=uchar -DSLICE3D_TRILINEAR=clvr_trilinear_uchar (or ushort) when every value is an
 * integer in that type's range (the same interpolated values, bit for bit). */
#ifndef SLICE3D_VOXEL
#define SLICE3D_VOXEL float
#define SLICE3D_TRILINEAR clvr_trilinear
#endif

#ifdef SLICE3D_PREINTEGRATED
/* The value at eye depth z where the ray enters or leaves the grid: the slab test's depth rounds, so the
 * point is clamped into [0, n - 1] first (the whole grid: pre-integration renders no parts). */
float slice3d_value_at_depth(global const SLICE3D_VOXEL* volume, const int4 dims, const float3 go, const float3 gd,
                             const float z)
{
    const float3 top = convert_float3(dims.xyz - 1);
    return SLICE3D_TRILINEAR(volume, dims, clamp(go + z * gd, (float3)(0.0f), top));
}
#endif

/* One work-item per pixel: slices k = 0 .. slice_count-1 at eye depth depth0 + k * delta_s. Only the
 * slices whose ray point lies in the grid bounds (the part's own box, for a part) are sampled (the rest are empty, DESIGN.md); their
 * number goes to samples[pixel]. With skip != 0, runs of slices in empty bricks are stepped over
 * (their number goes to skipped[pixel]; they are counted in samples[pixel] too). Back to front:
 * c = C alpha + (1 - alpha) c (the paper's blending); front to back: c += T alpha C, T *= 1 - alpha,
 * stopping once 1 - T >= ert_alpha. alpha = 1 - exp(-tau Delta), computed as
 * 1 - clvr_exp2(tau * (-Delta log2 e)) (kernels/clvr_common.h). The pixel is c + (1 - A) background, A. */
kernel void slice3d_fused(global float4* out, global uint* samples, global uint* skipped,
                          global const SLICE3D_VOXEL* volume, global const float* tf, global const uchar* space,
#ifdef SLICE3D_CLIP_TEXTURE
                          global const float* clip_texels,
#endif
#ifdef SLICE3D_CLIP_MESH
                          global const float4* clip_layers,
#endif
#ifdef SLICE3D_PREINTEGRATED
                          global const float* psi,
#endif
                          const ClSlice3dParams p)
{
    CLVR_GUARD_2D(p.width, p.height);
    const int x = (int)get_global_id(0), y = (int)get_global_id(1);
    const int4 dims = p.dims;
    const float depth0 = p.depth0, delta_s = p.delta_s, ert_alpha = p.ert_alpha;
    const int tf_count = p.tf_count, skip = p.skip;
    const int4 bdims = p.brick_dims;
    /* The pixel's ray as origin o + z * d, z the eye depth along forward (dot(d, forward) = 1), so the
     * ray's point on the slice at depth z is o + z d and a slice spacing deltaS is a ray length
     * deltaS * |d| (= deltaS / cos(theta)). */
    const float2 size = (float2)((float)p.width, (float)p.height);
    const float2 s = clvr_ray_window_offset(clvr_ray_pixel_centre(x, y), size, p.camera);
    float3 o, d;
    clvr_ray_depth(s, p.camera, &o, &d);
    const float delta = delta_s * clvr_ray_stretch(s, p.camera);  /* ray length per slice */
    const float neg_delta_log2e = -delta * M_LOG2E_F;                /* exp(-tau delta) = exp2(tau * this) */
    const float3 go = (o - p.grid_origin.xyz) * p.inv_spacing.xyz;     /* grid coordinates */
    const float3 gd = d * p.inv_spacing.xyz;
    const float3 inv_gd = 1.0f / gd;  /* for empty-space runs only (inf where gd is 0, not used there) */
#ifdef SLICE3D_CLIP_TEXTURE
    float3 uo, ud;
    slice3d_clip_ray(&p, o, d, &uo, &ud);
#endif
#ifdef SLICE3D_CLIP_MESH
    /* This pixel's mesh layers (one per image-sized layer), the deepest back face among them (naive), and the
     * first layer beyond the current sample (the loops below keep it). */
    const int4 mesh = p.clip_mesh;
    const size_t mesh_stride = (size_t)p.width * (size_t)p.height;
    global const float4* layers = clip_layers + ((size_t)y * p.width + x);
    const int last_back = slice3d_mesh_last_back(layers, mesh_stride, mesh);
    int mesh_next = 0;
#endif

    /* Depth interval of the ray inside the owned box (slab test), widened by one slice each way; each
     * sample is still checked, so this only limits the loop. */
    const float3 own_lo = p.own_lo.xyz, own_hi = p.own_hi.xyz;
    const int4 offset = p.part_offset;
    float zin, zout;
    clvr_box_chord(go, gd, own_lo, own_hi, &zin, &zout);
    int k_lo, k_hi;
    clvr_slice_range(zin, zout, depth0, delta_s, p.slice_count, &k_lo, &k_hi);
#ifndef SLICE3D_PREINTEGRATED
    /* With empty-space skipping the sample loop runs over the box of the bricks that are not empty
     * (p.tight_lo, p.tight_hi): every sample outside it lies in an empty brick, which the loop would step
     * over (tau 0: the same bits), and the runs through the margins between the data and the grid's faces
     * cost per ray whatever the slice count. The samples counted stay the owned box's, as without it: its
     * owned samples form one run of k (each coordinate is monotonic in k), from k_first to k_last. */
    int k_first = k_lo, k_last = k_hi;
    const float3 loop_lo = skip ? p.tight_lo.xyz : own_lo, loop_hi = skip ? p.tight_hi.xyz : own_hi;
    if (skip) {
        while (k_first <= k_last && !clvr_grid_owned(clvr_slice_point(go, gd, depth0, delta_s, k_first), own_lo, own_hi))
            ++k_first;
        while (k_last >= k_first && !clvr_grid_owned(clvr_slice_point(go, gd, depth0, delta_s, k_last), own_lo, own_hi))
            --k_last;
        float tin, tout;
        clvr_box_chord(go, gd, loop_lo, loop_hi, &tin, &tout);
        clvr_slice_range(tin, tout, depth0, delta_s, p.slice_count, &k_lo, &k_hi);
    }
    const ClvrOwnedGrid owned = {dims, offset, loop_lo, loop_hi};  /* for empty-space runs */
    int k_stop = k_last;  /* where early termination stopped the ray */
#else
    const ClvrOwnedGrid owned = {dims, offset, own_lo, own_hi};  /* for empty-space runs */
#endif

    float3 c = (float3)(0.0f);
    float alpha_acc = 0.0f;
    uint taken = 0, stepped_over = 0;
#ifdef SLICE3D_PREINTEGRATED
    /* Pre-integrated slabs (docs/slice3d.md, "integration"): the chain of ray points entry, the samples
     * inside the grid, exit; between two consecutive points the scalar is taken as linear and the slab is
     * integrated exactly for that (partial pre-integration, seeds/001 §3–4), front to back whatever the
     * order option says (the same integral). A run of samples in empty bricks is stepped over: the slab
     * into its first sample is integrated, the chain goes on from its last. The ray starts at depth 0
     * (the eye, or the image plane of a parallel camera). */
    float transmittance = 1.0f;
    const float z_begin = fmax(zin, 0.0f);
    if (z_begin < zout) {
        const float stretch = clvr_ray_stretch(s, p.camera);  /* ray length per unit of eye depth */
        HarcTfPoint front = harc_tf_point(tf, tf_count, slice3d_value_at_depth(volume, dims, go, gd, z_begin));
        float z_front = z_begin;
        for (int k = k_lo; k <= k_hi; ++k) {
            const float3 g = clvr_slice_point(go, gd, depth0, delta_s, k);
            if (!clvr_grid_owned(g, own_lo, own_hi))
                continue;
            const float z = depth0 + (float)k * delta_s;
            if (!(z > z_front))  /* a sample at or before the chain's last point (the entry's rounding) */
                continue;
            ++taken;
            /* front becomes this slab's back end, the next slab's front (kernels/segment_integral.h) */
            harc_segment_from(tf, tf_count, psi, p.psi_n, front, SLICE3D_TRILINEAR(volume, dims, g),
                              (z - z_front) * stretch, &c, &transmittance, &front);
            z_front = z;
            if (1.0f - transmittance >= ert_alpha)
                break;
            if (skip) {
                const int4 b = clvr_brick(g, dims);
                const int space_b = clvr_space(space, bdims, b);
                if (space_b != 0) {
                    const int run_end = clvr_empty_run(go, gd, inv_gd, depth0, delta_s, k, 1, k_hi, &owned, b,
                                                          space_b - 1);
                    if (run_end > k) {
                        stepped_over += (uint)(run_end - k);
                        k = run_end;
                        z_front = depth0 + (float)k * delta_s;
                        front = harc_tf_point(tf, tf_count,
                                              SLICE3D_TRILINEAR(volume, dims, clvr_slice_point(go, gd, depth0, delta_s, k)));
                    }
                }
            }
        }
        if (1.0f - transmittance < ert_alpha && zout > z_front)
            harc_segment_from(tf, tf_count, psi, p.psi_n, front, slice3d_value_at_depth(volume, dims, go, gd, zout),
                              (zout - z_front) * stretch, &c, &transmittance, &front);
    }
    alpha_acc = 1.0f - transmittance;
#else
    /* The chord through the whole grid (not only this part's box: a sort-last part's slices weigh as the
     * whole grid's, so the parts composite to one process's image), from depth 0 on. */
    float chord_in, chord_out;
    clvr_box_chord(go, gd, (float3)(0.0f), p.grid_hi.xyz, &chord_in, &chord_out);
    chord_in = fmax(chord_in, 0.0f);
    const float neg_stretch_log2e = -clvr_ray_stretch(s, p.camera) * M_LOG2E_F;
    if (p.front_to_back) {
        float transmittance = 1.0f;
        for (int k = k_lo; k <= k_hi; ++k) {
            const float3 g = clvr_slice_point(go, gd, depth0, delta_s, k);
            if (!clvr_grid_owned(g, loop_lo, loop_hi))
                continue;
            const float3 gl = clvr_grid_local(g, offset);
            if (skip) {
                const int4 b = clvr_brick(gl, dims);
                const int space_b = clvr_space(space, bdims, b);
                if (space_b != 0) {
                    const int run_end = clvr_empty_run(go, gd, inv_gd, depth0, delta_s, k, 1, k_hi, &owned, b,
                                                          space_b - 1);
                    stepped_over += (uint)(run_end - k + 1);
                    k = run_end;
                    continue;
                }
            }
            ++taken;
#ifdef SLICE3D_CLIP_TEXTURE
            if (!clvr_clip_keep(clip_texels, p.clip_tex, uo + (depth0 + (float)k * delta_s) * ud, p.clip_inverse))
                continue;
#endif
#ifdef SLICE3D_CLIP_MESH
            if (!slice3d_mesh_keep(layers, mesh_stride, mesh, last_back, &mesh_next, depth0 + (float)k * delta_s))
                continue;
#endif
            const float4 ct = clvr_tf_eval(tf, tf_count, SLICE3D_TRILINEAR(volume, dims, gl));
            const float slab = slice3d_slab_log2e(depth0 + (float)k * delta_s, delta_s, chord_in, chord_out,
                                                  neg_delta_log2e, neg_stretch_log2e);
            const float alpha = 1.0f - clvr_exp2(ct.w * slab);
            c += (transmittance * alpha) * ct.xyz;
            transmittance *= 1.0f - alpha;
            if (1.0f - transmittance >= ert_alpha) {
                k_stop = k;
                break;
            }
        }
        alpha_acc = 1.0f - transmittance;
    } else {
        for (int k = k_hi; k >= k_lo; --k) {
            const float3 g = clvr_slice_point(go, gd, depth0, delta_s, k);
            if (!clvr_grid_owned(g, loop_lo, loop_hi))
                continue;
            const float3 gl = clvr_grid_local(g, offset);
            if (skip) {
                const int4 b = clvr_brick(gl, dims);
                const int space_b = clvr_space(space, bdims, b);
                if (space_b != 0) {
                    const int run_end = clvr_empty_run(go, gd, inv_gd, depth0, delta_s, k, -1, k_lo, &owned, b,
                                                          space_b - 1);
                    stepped_over += (uint)(k - run_end + 1);
                    k = run_end;
                    continue;
                }
            }
            ++taken;
#ifdef SLICE3D_CLIP_TEXTURE
            if (!clvr_clip_keep(clip_texels, p.clip_tex, uo + (depth0 + (float)k * delta_s) * ud, p.clip_inverse))
                continue;
#endif
#ifdef SLICE3D_CLIP_MESH
            if (!slice3d_mesh_keep(layers, mesh_stride, mesh, last_back, &mesh_next, depth0 + (float)k * delta_s))
                continue;
#endif
            const float4 ct = clvr_tf_eval(tf, tf_count, SLICE3D_TRILINEAR(volume, dims, gl));
            const float slab = slice3d_slab_log2e(depth0 + (float)k * delta_s, delta_s, chord_in, chord_out,
                                                  neg_delta_log2e, neg_stretch_log2e);
            const float alpha = 1.0f - clvr_exp2(ct.w * slab);
            c = ct.xyz * alpha + (1.0f - alpha) * c;
            alpha_acc = alpha + (1.0f - alpha) * alpha_acc;
        }
    }
#endif
#ifndef SLICE3D_PREINTEGRATED
    if (skip) {  /* the owned box's samples up to where the ray stopped; all but those taken stepped over */
        const uint inside = k_stop >= k_first ? (uint)(k_stop - k_first + 1) : 0u;
        stepped_over = inside - taken;
    }
#endif
    const int i = y * p.width + x;
    out[i] = (float4)(c + (1.0f - alpha_acc) * p.background.xyz, alpha_acc);
    samples[i] = taken + stepped_over;
    skipped[i] = stepped_over;
}

#ifndef SLICE3D_PREINTEGRATED
/* ---- The packet kernel: slice3d_fused for 8 neighbouring pixels of a row at once, one per lane of float8
 * vectors (docs/slice3d.md, "Ray packets"). The slices are the same planes for every pixel, so the 8 rays
 * step through k together: positions, the transfer function, the exponential and the blending run as
 * vector instructions (PoCL does not vectorize slice3d_fused's divergent per-pixel loop); only the voxel
 * loads and the empty-space lookups are per lane. Every lane computes exactly slice3d_fused's expressions,
 * so its pixel is the same bits: a lane whose sample is not owned, or whose ray has stopped, is masked; a
 * lane in an empty brick while another lane samples takes its sample, whose tau is 0 (empty bricks are
 * decided with a margin for float rounding), which changes nothing; the packet steps over slices only
 * when every active lane is in an empty brick, as far as the nearest of their runs' ends. With a clip
 * texture or mesh each lane's clip test runs slice3d_fused's code for that lane. The vector functions are
 * kernels/packet.h's. */
kernel void slice3d_fused_packet(global float4* out, global uint* samples, global uint* skipped,
                                 global const SLICE3D_VOXEL* volume, global const float* tf,
                                 global const uchar* space,
#ifdef SLICE3D_CLIP_TEXTURE
                                 global const float* clip_texels,
#endif
#ifdef SLICE3D_CLIP_MESH
                                 global const float4* clip_layers,
#endif
                                 const ClSlice3dParams p)
{
    const int x0 = (int)get_global_id(0) * CLVR_LANES, y = (int)get_global_id(1);
    if (x0 >= p.width || y >= p.height)
        return;
    const int4 dims = p.dims, bdims = p.brick_dims, offset = p.part_offset;
    const float depth0 = p.depth0, delta_s = p.delta_s, ert_alpha = p.ert_alpha;
    const int tf_count = p.tf_count, skip = p.skip;
    const float3 own_lo = p.own_lo.xyz, own_hi = p.own_hi.xyz;
    const float3 loop_lo = skip ? p.tight_lo.xyz : own_lo, loop_hi = skip ? p.tight_hi.xyz : own_hi;
    const ClvrOwnedGrid owned = {dims, offset, loop_lo, loop_hi};  /* for empty-space runs */

    /* Each lane's ray, as slice3d_fused sets it up (clvr_ray_window_offset, clvr_ray_depth, clvr_ray_stretch:
     * the same expressions lane by lane; the row's offset s.y is one scalar). */
    const float2 size = (float2)((float)p.width, (float)p.height);
    const ClCamera cam = p.camera;
    const float sy = clvr_ray_window_offset(clvr_ray_pixel_centre(x0, y), size, cam).y;
    const float8 wx = convert_float8(x0 + CLVR_LANE_INDEX) + 0.5f;
    const float8 sx = (wx / size.x * 2.0f - 1.0f) * cam.params.x * cam.params.y;
    /* s.y as a vector too: a product of two scalars would be rounded before the sum it is added to, where the
     * one-pixel kernel's float3 expressions fuse it (a * b + c as one rounding) */
    const float8 sy8 = sy;
    float8 o_x, o_y, o_z, d_x, d_y, d_z, stretch;
    if (clvr_ray_parallel(cam)) {
        o_x = cam.position.x + sx * cam.right.x + sy8 * cam.up.x;
        o_y = cam.position.y + sx * cam.right.y + sy8 * cam.up.y;
        o_z = cam.position.z + sx * cam.right.z + sy8 * cam.up.z;
        d_x = cam.forward.x, d_y = cam.forward.y, d_z = cam.forward.z;
        stretch = 1.0f;
    } else {
        o_x = cam.position.x, o_y = cam.position.y, o_z = cam.position.z;
        d_x = cam.forward.x + sx * cam.right.x + sy8 * cam.up.x;
        d_y = cam.forward.y + sx * cam.right.y + sy8 * cam.up.y;
        d_z = cam.forward.z + sx * cam.right.z + sy8 * cam.up.z;
        stretch = sqrt(1.0f + sx * sx + sy8 * sy8);
    }
    const float8 delta = delta_s * stretch;
    const float8 neg_delta_log2e = -delta * M_LOG2E_F;
    const float8 neg_stretch_log2e = -stretch * M_LOG2E_F;
#if defined(SLICE3D_CLIP_TEXTURE) || defined(SLICE3D_CLIP_MESH)
    /* the clip tests run lane by lane, with slice3d_fused's own code: each lane's ray in arrays */
    float ox[8], oy[8], oz[8], dx[8], dy[8], dz[8];
    vstore8(o_x, 0, ox), vstore8(o_y, 0, oy), vstore8(o_z, 0, oz), vstore8(d_x, 0, dx), vstore8(d_y, 0, dy), vstore8(d_z, 0, dz);
#endif
#ifdef SLICE3D_CLIP_TEXTURE
    /* clip-texture coordinates along each lane's ray, u = uo + z ud (slice3d_fused's expressions per lane) */
    float uox[8], uoy[8], uoz[8], udx[8], udy[8], udz[8];
    for (int l = 0; l < CLVR_LANES; ++l) {
        float3 uo, ud;
        slice3d_clip_ray(&p, (float3)(ox[l], oy[l], oz[l]), (float3)(dx[l], dy[l], dz[l]), &uo, &ud);
        uox[l] = uo.x, uoy[l] = uo.y, uoz[l] = uo.z, udx[l] = ud.x, udy[l] = ud.y, udz[l] = ud.z;
    }
    const float8 uo_x = vload8(0, uox), uo_y = vload8(0, uoy), uo_z = vload8(0, uoz);
    const float8 ud_x = vload8(0, udx), ud_y = vload8(0, udy), ud_z = vload8(0, udz);
#endif
#ifdef SLICE3D_CLIP_MESH
    /* each lane's mesh layers, its deepest back face (naive) and its next layer, as slice3d_fused keeps them */
    const int4 mesh = p.clip_mesh;
    const size_t mesh_stride = (size_t)p.width * (size_t)p.height;
    int last_back[8], mesh_next[8];
    for (int l = 0; l < CLVR_LANES; ++l) {
        last_back[l] = slice3d_mesh_last_back(clip_layers + ((size_t)y * p.width + min(x0 + l, p.width - 1)),
                                              mesh_stride, mesh);
        mesh_next[l] = 0;
    }
#endif
    const float8 go_x = (o_x - p.grid_origin.x) * p.inv_spacing.x, go_y = (o_y - p.grid_origin.y) * p.inv_spacing.y;
    const float8 go_z = (o_z - p.grid_origin.z) * p.inv_spacing.z;
    const float8 gd_x = d_x * p.inv_spacing.x, gd_y = d_y * p.inv_spacing.y, gd_z = d_z * p.inv_spacing.z;
    /* the slices near the chord through the owned box; with skipping, the first and last owned ones (for the
     * samples counted) and the slices near the chord through the box of the bricks that are not empty */
    float8 zin, zout;
    clvr_box_chord8(go_x, go_y, go_z, gd_x, gd_y, gd_z, own_lo, own_hi, &zin, &zout);
    int8 lo8, hi8;
    clvr_slice_range8(zin, zout, depth0, delta_s, p.slice_count, &lo8, &hi8);
    int8 k_first = lo8, k_last = hi8;
    if (skip) {
        for (int8 move = (int8)(-1); any(move);) {
            move = (k_first <= k_last) & ~clvr_grid_owned8(go_x, go_y, go_z, gd_x, gd_y, gd_z, depth0, delta_s, k_first,
                                                         own_lo, own_hi);
            k_first -= move;
        }
        for (int8 move = (int8)(-1); any(move);) {
            move = (k_last >= k_first) & ~clvr_grid_owned8(go_x, go_y, go_z, gd_x, gd_y, gd_z, depth0, delta_s, k_last,
                                                        own_lo, own_hi);
            k_last += move;
        }
        clvr_box_chord8(go_x, go_y, go_z, gd_x, gd_y, gd_z, loop_lo, loop_hi, &zin, &zout);
        clvr_slice_range8(zin, zout, depth0, delta_s, p.slice_count, &lo8, &hi8);
    }
    /* lanes past the row's end: nothing to sample, nothing written */
    const int8 in_row = x0 + CLVR_LANE_INDEX < p.width;
    lo8 = select((int8)(0), lo8, in_row), hi8 = select((int8)(-1), hi8, in_row);
    k_first = select((int8)(0), k_first, in_row), k_last = select((int8)(-1), k_last, in_row);
    const int8 ranged = lo8 <= hi8;
    const int k_begin = clvr_min8(select((int8)(p.slice_count), lo8, ranged));
    const int k_end = clvr_max8(select((int8)(-1), hi8, ranged));
    float8 chord_in, chord_out;
    clvr_box_chord8(go_x, go_y, go_z, gd_x, gd_y, gd_z, (float3)(0.0f), p.grid_hi.xyz, &chord_in, &chord_out);
    chord_in = fmax(chord_in, 0.0f);
    const float3 off = convert_float3(offset.xyz);

    float8 cr = 0.0f, cg = 0.0f, cb = 0.0f;
    float8 transmittance = 1.0f, alpha_acc = 0.0f;
    int8 live = ranged;               /* lanes with slices to sample and not stopped */
    int8 k_stop = k_last;             /* where early termination stopped each ray */
    int8 taken = 0;
    const int ftb = p.front_to_back, step = ftb ? 1 : -1;
    for (int k = ftb ? k_begin : k_end; ftb ? k <= k_end : k >= k_begin; k += step) {
        const float z = depth0 + (float)k * delta_s;
        const float8 gx = go_x + z * gd_x, gy = go_y + z * gd_y, gz = go_z + z * gd_z;
        int8 act = live & (k >= lo8) & (k <= hi8) & clvr_in_box8(gx, gy, gz, loop_lo, loop_hi);
        if (!any(act))
            continue;
        /* the volume's own coordinates, 0 in the lanes that do not sample (their loads stay in the grid) */
        const float8 lx = select((float8)(0.0f), gx - off.x, act);
        const float8 ly = select((float8)(0.0f), gy - off.y, act);
        const float8 lz = select((float8)(0.0f), gz - off.z, act);
        const int8 ix = min(convert_int8(lx), dims.x - 2);
        const int8 iy = min(convert_int8(ly), dims.y - 2);
        const int8 iz = min(convert_int8(lz), dims.z - 2);
        if (skip) {
            const int8 bx = ix >> CLVR_BRICK_SHIFT, by = iy >> CLVR_BRICK_SHIFT, bz = iz >> CLVR_BRICK_SHIFT;
            const int8 sp = clvr_space8(space, bdims, bx, by, bz);
            if (!any(act & (sp == 0))) {
                /* every sampling lane is in an empty brick: on from the nearest end of their runs */
                const int8 run_end = clvr_empty_run8(go_x, go_y, go_z, gd_x, gd_y, gd_z, depth0, delta_s, k, step,
                                                     ftb ? hi8 : lo8, &owned, bx, by, bz, sp - 1);
                k = clvr_packet_jump(run_end, act, live, k, step, lo8, hi8, k_begin, k_end);
                continue;
            }
        }
        taken -= act;
#if defined(SLICE3D_CLIP_TEXTURE) || defined(SLICE3D_CLIP_MESH)
        /* the clip tests lane by lane: a sample they remove counts as taken and adds nothing */
        int acts[8];
        vstore8(act, 0, acts);
#ifdef SLICE3D_CLIP_TEXTURE
        {
            const float8 u_x = uo_x + z * ud_x, u_y = uo_y + z * ud_y, u_z = uo_z + z * ud_z;
            float ux[8], uy[8], uz[8];
            vstore8(u_x, 0, ux), vstore8(u_y, 0, uy), vstore8(u_z, 0, uz);
            for (int l = 0; l < CLVR_LANES; ++l)
                if (acts[l] && !clvr_clip_keep(clip_texels, p.clip_tex, (float3)(ux[l], uy[l], uz[l]), p.clip_inverse))
                    acts[l] = 0;
        }
#endif
#ifdef SLICE3D_CLIP_MESH
        for (int l = 0; l < CLVR_LANES; ++l)
            if (acts[l] && !slice3d_mesh_keep(clip_layers + ((size_t)y * p.width + x0 + l), mesh_stride, mesh, last_back[l],
                                              &mesh_next[l], z))
                acts[l] = 0;
#endif
        act = vload8(0, acts);
        if (!any(act))
            continue;
#endif
#if defined(SLICE3D_VOXEL_BITS) && (SLICE3D_VOXEL_BITS == 8 || SLICE3D_VOXEL_BITS == 16)
        /* Integer voxels: each (i, i + 1) pair is one 16- or 32-bit load, put into a lane of one vector and
         * split into its two values there (little-endian: value i in the low half), half the lane inserts;
         * then clvr_trilinear's interpolation as vectors. */
        const float8 fx = lx - convert_float8(ix), fy = ly - convert_float8(iy), fz = lz - convert_float8(iz);
        const uint nx = (uint)dims.x, nxy = nx * (uint)dims.y;
        const uint8 idx = convert_uint8(iz) * nxy + convert_uint8(iy) * nx + convert_uint8(ix);
        float8 a00x, a00y, a10x, a10y, a01x, a01y, a11x, a11y;
#if SLICE3D_VOXEL_BITS == 8
        typedef ushort8 Pair8;
#define SLICE3D_PAIR(q) as_ushort(vload2(0, q))
#define SLICE3D_SPLIT(v, lo, hi) lo = convert_float8(v & (ushort)0xff), hi = convert_float8(v >> (ushort)8)
#else
        typedef uint8 Pair8;
#define SLICE3D_PAIR(q) as_uint(vload2(0, q))
#define SLICE3D_SPLIT(v, lo, hi) lo = convert_float8(v & 0xffffu), hi = convert_float8(v >> 16u)
#endif
        Pair8 p00, p10, p01, p11;
#define SLICE3D_GATHER(L)                                                                                 \
        {                                                                                                 \
            global const SLICE3D_VOXEL* q = volume + idx.s##L;                                            \
            p00.s##L = SLICE3D_PAIR(q), p10.s##L = SLICE3D_PAIR(q + nx);                                  \
            p01.s##L = SLICE3D_PAIR(q + nxy), p11.s##L = SLICE3D_PAIR(q + nxy + nx);                      \
        }
        CLVR_EACH_LANE(SLICE3D_GATHER)
#undef SLICE3D_GATHER
        SLICE3D_SPLIT(p00, a00x, a00y);
        SLICE3D_SPLIT(p10, a10x, a10y);
        SLICE3D_SPLIT(p01, a01x, a01y);
        SLICE3D_SPLIT(p11, a11x, a11y);
#undef SLICE3D_PAIR
#undef SLICE3D_SPLIT
        const float8 value = clvr_trilinear8_mix(a00x, a00y, a10x, a10y, a01x, a01y, a11x, a11y, fx, fy, fz);
#else
        const float8 value = clvr_trilinear8(volume, dims, lx, ly, lz);
#endif
        float8 r, g, b, tau;
        clvr_tf_eval8(tf, tf_count, value, &r, &g, &b, &tau);
        /* slice3d_slab_log2e lane by lane */
        const int8 first = isless(z - delta_s, chord_in), last = isgreater(z + delta_s, chord_out);
        const float8 slo = select((float8)(z - 0.5f * delta_s), chord_in, first);
        const float8 shi = select((float8)(z + 0.5f * delta_s), chord_out, last);
        const float8 slab = select(neg_delta_log2e, fmax(shi - slo, 0.0f) * neg_stretch_log2e, first | last);
        const float8 alpha = 1.0f - clvr_exp2_8(tau * slab);
        if (ftb) {
            cr = select(cr, cr + (transmittance * alpha) * r, act);
            cg = select(cg, cg + (transmittance * alpha) * g, act);
            cb = select(cb, cb + (transmittance * alpha) * b, act);
            transmittance = select(transmittance, transmittance * (1.0f - alpha), act);
            const int8 done = act & isgreaterequal(1.0f - transmittance, ert_alpha);
            k_stop = select(k_stop, (int8)(k), done);
            live &= ~done;
            if (!any(live))
                break;
        } else {
            cr = select(cr, r * alpha + (1.0f - alpha) * cr, act);
            cg = select(cg, g * alpha + (1.0f - alpha) * cg, act);
            cb = select(cb, b * alpha + (1.0f - alpha) * cb, act);
            alpha_acc = select(alpha_acc, alpha + (1.0f - alpha) * alpha_acc, act);
        }
    }
    if (ftb)
        alpha_acc = 1.0f - transmittance;
    const float8 orr = cr + (1.0f - alpha_acc) * p.background.x;
    const float8 org = cg + (1.0f - alpha_acc) * p.background.y;
    const float8 orb = cb + (1.0f - alpha_acc) * p.background.z;
    float ro[8], go8[8], bo[8], ao[8];
    int ks[8], tk[8], kfirst[8];
    vstore8(orr, 0, ro), vstore8(org, 0, go8), vstore8(orb, 0, bo), vstore8(alpha_acc, 0, ao);
    vstore8(k_stop, 0, ks), vstore8(taken, 0, tk), vstore8(k_first, 0, kfirst);
    for (int l = 0; l < CLVR_LANES && x0 + l < p.width; ++l) {
        uint stepped_over = 0;
        if (skip) {  /* as slice3d_fused: the owned box's samples up to where the ray stopped */
            const uint inside = ks[l] >= kfirst[l] ? (uint)(ks[l] - kfirst[l] + 1) : 0u;
            stepped_over = inside - (uint)tk[l];
        }
        const int i = y * p.width + x0 + l;
        out[i] = (float4)(ro[l], go8[l], bo[l], ao[l]);
        samples[i] = (uint)tk[l] + stepped_over;
        skipped[i] = stepped_over;
    }
}
#endif

/* The pass-by-pass path's last pass: premultiplied (I, A) in place -> I + (1 - A) background, A. */
kernel void slice3d_over_background(global float4* color, const ClSlice3dOverBackgroundParams p)
{
    CLVR_GUARD_1D(p.count);
    const size_t i = get_global_id(0);
    const float4 c = color[i];
    color[i] = (float4)(c.xyz + (1.0f - c.w) * p.background.xyz, c.w);
}

#else

/* Fragment program of the pass-by-pass path (raster/rasterizer.h). attr[0] = world position on the
 * slice (perspective-correct). uniforms: ClSlice3dUniforms (kernels/slice3d_params.h). buffer[0]
 * volume values, buffer[1] transfer function (transfer_function.h layout).
 * With CLVR_SLICE3D_CLIP_TEXTURE: attr[1] clip-texture coordinates, u->clip_tex, buffer[2] its texels.
 * Output: premultiplied (C alpha, alpha), blended by the draw state. */
int clvr_fragment(const ClFragment* f, const ClFragmentResources* r, float4* color)
{
    constant ClSlice3dUniforms* u = (constant ClSlice3dUniforms*)r->uniforms;
    const int4 dims = convert_int4(u->dims);
    const float3 g = (f->attr[0].xyz - u->grid_origin.xyz) * u->inv_spacing.xyz;
    if (!clvr_grid_inside(g, dims))
        return 0;
#ifdef CLVR_SLICE3D_CLIP_TEXTURE
    /* The second texture (multitexturing): attr[1] = clip-texture coordinates of the slice point;
     * u->clip_tex = (width, height, depth, inverse) of buffer[2], one channel, linear, clamp to edge. */
    if (!clvr_clip_keep(r->buffer[2], clvr_clip_texture(u->clip_tex), f->attr[1].xyz, (int)u->clip_tex.w))
        return 0;
#endif
    const ClCamera cam = u->camera;
    const float2 s = clvr_ray_window_offset(f->window, u->frame.xy, cam);
    const float stretch = clvr_ray_stretch(s, cam), delta_s = u->frame.z;
    /* The slab at the box faces as the fused kernel weighs it: the pixel ray's chord through the grid, and
     * this fragment's slice (its eye depth rounded to the slice it lies on). */
    float3 o, d;
    clvr_ray_depth(s, cam, &o, &d);
    float chord_in, chord_out;
    clvr_box_chord((o - u->grid_origin.xyz) * u->inv_spacing.xyz, d * u->inv_spacing.xyz, (float3)(0.0f),
                  nextafter(u->dims.xyz - 1.0f, (float3)(INFINITY)), &chord_in, &chord_out);
    chord_in = fmax(chord_in, 0.0f);
    const float k = rint((dot(f->attr[0].xyz - o, cam.forward.xyz) - u->slab.x) / delta_s);
    const float slab = slice3d_slab_log2e(u->slab.x + k * delta_s, delta_s, chord_in, chord_out,
                                          -(delta_s * stretch) * M_LOG2E_F, -stretch * M_LOG2E_F);
    const float4 ct = clvr_tf_eval(r->buffer[1], (int)u->frame.w, clvr_trilinear(r->buffer[0], dims, g));
    const float alpha = 1.0f - clvr_exp2(ct.w * slab);
    *color = (float4)(ct.xyz * alpha, alpha);
    return 1;
}

#endif
