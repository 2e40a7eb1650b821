// kernels/stack2d.cl — fragment program of the 2D texture stacks (seeds/003_e49ee09fcdafadac.txt;
// host/render/grid/stack2d.cpp, docs/stack2d.md). The host appends this file, with CLVR_STACK2D_FRAGMENT
// defined, after kernels/raster.cl; compiled on its own (the offline syntax test) it pulls in
// raster.cl itself, so that the fragment program is checked in the context it runs in.
// The host has validated everything; this file only does arithmetic.
#include "clip_texture.h"
#include "stack2d_params.h"
#include "transfer_function.h"
#include "reflectance_map.h"
#ifndef CLVR_STACK2D_FRAGMENT
#include "raster.cl"
#include "clvr_common.h"
#include "empty_space.h"
#include "packet.h"
#endif

/* One fragment of a stack quad (direct volume rendering; iso-surfaces below). attr[0] = (u, v, lower, weight): the 2D texture coordinates on the
 * slice (texel i of n centered at (i + 0.5) / n, so grid point i is texel i), the stack slice to
 * sample and the weight of slice lower + 1 (0 on a stack slice itself); attr[1] = (the slab's
 * thickness along the stack axis in world units, first, count, 0): count 0 for one slice per quad,
 * else the quad stands for slices first .. first + count - 1 of the table in buffer[3] (several
 * slices per polygon, below). All but (u, v) are constant over a quad.
 * uniforms: ClStack2dUniforms (kernels/stack2d_params.h: camera, image size and tf_count, stack axis,
 * slice texture size, shading, towards the eye; iso-surfaces: iso, surface, light; several slices per
 * polygon: axis_b, axis_c, box, uv_box, alpha_ref; clip textures: clip_tex, clip_row, clip_offset).
 * buffer[0] the stack (slices one after another, x
 * fastest): 1 channel, the value, returned as (v, v, v, v); or, shaded, 4 channels (gradient, value)
 * from host/optics/gradient_volume.h. buffer[1] the transfer function (transfer_function.h); buffer[2] the
 * reflectance map (reflectance_map.h), shaded only; buffer[3] the slice table (float4 per slice:
 * world coordinate on the axis, lower, weight, thickness), several slices per polygon only, followed
 * by the clip texture's texels (clip textures, below: u->clip_*, attr[2]).
 * Sample: bilinear in each slice; an intermediate slice lerps two bilinear samples, the paper's
 * register-combiner step, which makes the sample (and the gradient) trilinear. Classified after
 * interpolation; shaded, the color is C times the map's shade of the interpolated gradient (the
 * model of host/optics/reflectance_map.h, as planes and blend; tau is not shaded);
 * alpha = 1 - exp(-tau Delta) with Delta the ray's length through the slab, thickness / |cos| of
 * the angle between the pixel's ray and the axis. Output premultiplied (C alpha, alpha). */

/* Clip texture (seeds/003, "Clipping with arbitrary clipping geometry"; host/optics/clip_texture.h, as
 * slice3d): with CLVR_STACK2D_CLIP_TEXTURE defined, a second, one-channel texture (negative inside,
 * linear filtering, clamp to edge) decides per sample whether it is drawn. u->clip_tex (width,
 * height, depth, 1 if inverse), u->clip_row the rows of world -> clip-texture coordinates
 * (clipTextureCoordinates), u->clip_offset (offset of the texels in buffer[3], in floats); buffer[3]
 * holds the slice table (several slices per polygon; empty otherwise) followed by the texels. One
 * slice per quad: attr[2] = the clip-texture coordinates of the fragment's point on the slice
 * (perspective-correct; affine in the point, so exact up to rounding), and a clipped fragment is
 * discarded. Several slices per polygon: the coordinates of the ray's hit point p on each slice,
 * a clipped sample skipped. Iso-surfaces: a clipped sample is no hit. */
#ifdef CLVR_STACK2D_CLIP_TEXTURE
/* clvr_clip_keep (clip_texture.h) on the clip texture behind the slice table in buffer[3]. */
static int stack2d_clip_keep(const ClFragmentResources* r, const float3 uc)
{
    constant ClStack2dUniforms* u = (constant ClStack2dUniforms*)r->uniforms;
    return clvr_clip_keep(r->buffer[3] + (size_t)u->clip_offset.x, clvr_clip_texture(u->clip_tex), uc, (int)u->clip_tex.w);
}

/* World point p -> clip-texture coordinates (u->clip_row, affine). */
static float3 stack2d_clip_coordinates(constant ClStack2dUniforms* u, const float3 p)
{
    return (float3)(dot(u->clip_row[0].xyz, p) + u->clip_row[0].w, dot(u->clip_row[1].xyz, p) + u->clip_row[1].w,
                    dot(u->clip_row[2].xyz, p) + u->clip_row[2].w);
}
#endif

/* The stack's slices as one 2D texture each (u->slice_tex). */
static ClTexture stack2d_slice_texture(constant ClStack2dUniforms* u)
{
    ClTexture slice;
    slice.width = (cl_uint)u->slice_tex.x;
    slice.height = (cl_uint)u->slice_tex.y;
    slice.depth = 1u;
    slice.channels = (cl_uint)u->slice_tex.z;
    slice.filter = CLVR_FILTER_LINEAR;
    slice.wrap = CLVR_WRAP_CLAMP_TO_EDGE;
    slice.pad0 = slice.pad1 = 0u;
    slice.border = (float4)(0.0f);
    return slice;
}

/* The bilinear sample of stack slice `lower` at uv, lerped towards slice lower + 1 by weight > 0. */
static float4 stack2d_fetch(global const float* stack, const ClTexture slice, int lower, float weight, float2 uv)
{
    const size_t texels = (size_t)slice.width * slice.height * slice.channels;
    global const float* s0 = stack + (size_t)lower * texels;
    float4 sample = clvr_tex2d(s0, slice, uv);
    if (weight > 0.0f)
        sample = mix(sample, clvr_tex2d(s0 + texels, slice, uv), weight);
    return sample;
}

/* Iso-surface mode: (shaded color, value mapped to [0, 1] over the data range) of an RGBA sample (gradient,
 * value); iso, surface, light as ClStack2dUniforms' fields of those names, to_eye towards the eye. */
static float4 stack2d_surface(const float4 sample, const float4 iso, const float4 surface, const float4 light,
                              const float3 to_eye)
{
    float shade = 1.0f;
    if (surface.w != 0.0f) {
        const float len = length(sample.xyz);
        float3 n = len > 0.0f ? sample.xyz / len : (float3)(0.0f);
        if (dot(n, to_eye) < 0.0f)
            n = -n;
        shade = iso.z + iso.w * fmax(0.0f, dot(n, light.xyz));
    }
    return (float4)(surface.xyz * shade, (sample.w - iso.x) * light.w);
}

/* Direct volume rendering: (color, tau) of a sample, the color shaded by the reflectance map's shade of the
 * sample's gradient (sample.xyz) when shaded != 0 (tau is not shaded). */
static float4 stack2d_color_tau(global const float* tf, const int tf_count, global const float4* map, const int map_n,
                                const int shaded, const float4 sample, const float3 to_eye)
{
    float4 ct = clvr_tf_eval(tf, tf_count, sample.w);
    if (shaded)
        ct.xyz *= clvr_reflectance(map, map_n, sample.xyz, to_eye);
    return ct;
}

static float4 stack2d_iso_shade(constant ClStack2dUniforms* u, float4 sample)
{
    return stack2d_surface(sample, u->iso, u->surface, u->light, u->to_eye.xyz);
}

/* Direct volume rendering: the premultiplied color of a sample standing for a ray length delta. */
static float4 stack2d_classify(const ClFragmentResources* r, float4 sample, float delta)
{
    constant ClStack2dUniforms* u = (constant ClStack2dUniforms*)r->uniforms;
    const float4 ct = stack2d_color_tau(r->buffer[1], (int)u->frame.z, (global const float4*)r->buffer[2],
                                        (int)u->shading.x, u->shading.y != 0.0f, sample, u->to_eye.xyz);
    const float alpha = 1.0f - exp(-ct.w * delta);
    return (float4)(ct.xyz * alpha, alpha);
}

int clvr_fragment(const ClFragment* f, const ClFragmentResources* r, float4* color)
{
    /* Iso-surface mode (the paper's fast shaded iso-surfaces): output (shaded color, value mapped to
     * [0, 1] over the data range, as the paper's 8-bit alpha); the draw's alpha test (GEQUAL the
     * iso-value mapped alike) keeps the fragments inside the surface, and back-to-front drawing
     * without blending leaves the front-most one. Diffuse shading with the two-sided normal of the
     * interpolated gradient: ambient + diffuse max(0, N.L), N turned to face the viewer. */
    constant ClStack2dUniforms* u = (constant ClStack2dUniforms*)r->uniforms;
    const ClTexture slice = stack2d_slice_texture(u);
    const bool iso = u->iso.y != 0.0f;

    /* The pixel's ray (host/model/camera.cpp's PixelRays): from the camera through the pixel center, or for
     * a parallel camera from the pixel's point on the image plane along forward. */
    const ClCamera cam = u->camera;
    float3 origin, d;
    clvr_ray_offset_first(clvr_ray_window_offset(f->window, u->frame.xy, cam), cam, &origin, &d);
    /* a fragment's ray meets the quad's plane, so cos_theta > 0; the floor only keeps tau = 0 times
     * an infinite Delta (a plane seen exactly edge-on, rounded) from giving NaN */
    const float cos_theta = fmax(fabs(dot(d, u->axis.xyz)) / length(d), 1e-20f);

    const int count = (int)round(f->attr[1].z);
    if (count == 0) {
        /* One slice per quad: lower and weight are interpolated constants: round lower, take weight as
         * it comes (its rounding error is a few ulp). */
#ifdef CLVR_STACK2D_CLIP_TEXTURE
        if (!stack2d_clip_keep(r, f->attr[2].xyz))
            return 0;
#endif
        const float4 sample =
            stack2d_fetch(r->buffer[0], slice, (int)round(f->attr[0].z), f->attr[0].w, f->attr[0].xy);
        *color = iso ? stack2d_iso_shade(u, sample) : stack2d_classify(r, sample, f->attr[1].x / cos_theta);
        return 1;
    }

    /* Several slices per polygon (seeds/003, "mapping the textures of multiple slice images onto a
     * single polygon"): this quad stands for `count` consecutive slices of the drawing order, table
     * entries first .. first + count - 1 of buffer[3] (world coordinate on the axis, lower, weight,
     * thickness), back to front; it lies in the front-most slice's plane, enlarged to cover where
     * every one of them is seen. Each slice is sampled where the pixel's ray meets its plane (texture
     * coordinates from u->axis_b, axis_c, box, uv_box), skipped where that point is outside the box, and the samples
     * are composited back to front inside the fragment — "over" is associative, so the blended
     * result is that of one quad per slice. Iso-surfaces keep the front-most sample at or above the
     * iso-value (alpha reference u->alpha_ref.x), as the alpha test and the drawing order would. */
    const float da = dot(d, u->axis.xyz), oa = dot(origin, u->axis.xyz);
    global const float4* table = (global const float4*)r->buffer[3];
    const int first = (int)round(f->attr[1].y);
    float4 out = (float4)(0.0f);
    float4 iso_fallback = (float4)(0.0f, 0.0f, 0.0f, -1.0f);
    bool iso_hit = false;
    for (int j = first; j < first + count; ++j) {
        const float4 e = table[j];
        const float t = (e.x - oa) / da;
        if (!(t > 0.0f))
            continue;
        const float3 p = origin + t * d;
        const float2 bc = (float2)(dot(p, u->axis_b.xyz), dot(p, u->axis_c.xyz));
        if (bc.x < u->box.x || bc.x > u->box.z || bc.y < u->box.y || bc.y > u->box.w)
            continue;
#ifdef CLVR_STACK2D_CLIP_TEXTURE
        if (!stack2d_clip_keep(r, stack2d_clip_coordinates(u, p)))
            continue;
#endif
        const float2 uv = u->uv_box.xy + (bc - u->box.xy) / (u->box.zw - u->box.xy) * (u->uv_box.zw - u->uv_box.xy);
        const float4 sample = stack2d_fetch(r->buffer[0], slice, (int)e.y, e.z, uv);
        if (iso) {
            const float4 shaded = stack2d_iso_shade(u, sample);
            if (shaded.w >= u->alpha_ref.x) {
                out = shaded;
                iso_hit = true;
            } else if (!iso_hit) {
                iso_fallback = shaded;
            }
        } else {
            const float4 s = stack2d_classify(r, sample, e.w / cos_theta);
            out = s + (1.0f - s.w) * out;
        }
    }
    *color = iso && !iso_hit ? iso_fallback : out;
    return 1;
}

/* Iso-surface mode's last pass: where a fragment passed the alpha test (stencil 1) the pixel is the
 * surface, opaque; elsewhere the background, A = 0. */
kernel void stack2d_iso_finish(global float4* color, global const uchar* stencil, const ClStack2dIsoFinishParams p)
{
    CLVR_GUARD_1D(p.count);
    const size_t i = get_global_id(0);
    color[i] = stencil[i] != 0 ? (float4)(color[i].xyz, 1.0f) : (float4)(p.background.xyz, 0.0f);
}

#ifndef CLVR_STACK2D_FRAGMENT

/* The fused path (host/render/grid/stack2d.cpp, "path": "fused"): one work-item per pixel does what the
 * quads of the drawn stack do at that pixel. In stack grid coordinates q = (b, c, axis) (to_stack), plane
 * j of (n_axis - 1)(intermediate + 1) + 1 lies at q.z = j plane_step, and its sample is the trilinear value
 * of the stack at the ray's point on it — exactly what a quad's fragment computes (bilinear in slice
 * floor(q.z), lerped towards the next by the fraction), at the ray's point instead of the rasterizer's
 * interpolated texture coordinates. A plane counts where that point lies in the box (the quad's
 * coverage) and in front of the eye (eye depth > 0; the draws clip at their near plane). Its slab
 * stands for Delta = thickness / cos = plane_step |d| / |q_d.z| of ray (half at the first and last plane,
 * whose slabs end at the box faces). Front to back — the same sum as the draws' back-to-front blending up
 * to rounding: c += T alpha C, T *= 1 - alpha, stopping once 1 - T >= ert_alpha; the pixel is
 * c + T background, 1 - T. mode 1 (shaded): the stack holds (gradient, value) and C is shaded by the
 * reflectance map; mode 2 (iso-surface): the first sample whose mapped value passes alpha_ref is the
 * pixel, (its shade, 1), else (background, 0) — what the alpha test, the drawing order and
 * stack2d_iso_finish leave. With clip textures, a clipped sample is skipped. With p.bricks.w != 0, runs of
 * planes in bricks of the stack grid where nothing can show (kernels/empty_space.h; tau is 0, or all values
 * lie below the iso-value) are stepped over: the pixel is the same bit for bit. samples[pixel]: planes
 * met inside the box (taken or stepped over), skipped[pixel]: those stepped over. */
/* The stack grid of dims points as the fused path samples it: the box in (b, c) as the quads cover it; along
 * the axis every plane is inside by construction (the last one's j plane_step may round a hair above n - 1,
 * which the trilinear clamp absorbs). */
ClvrOwnedGrid stack2d_grid(const int4 dims)
{
    const ClvrOwnedGrid grid = {dims, (int4)(0), (float3)(0.0f, 0.0f, -INFINITY),
                                (float3)(nextafter((float)(dims.x - 1), INFINITY), nextafter((float)(dims.y - 1), INFINITY),
                                         INFINITY)};
    return grid;
}

void stack2d_fused_pixel(const int x, const int y, global float4* out, global uint* samples, global uint* skipped,
                         global const float* stack, global const float* tf, global const float4* map,
                         global const uchar* space,
#ifdef CLVR_STACK2D_CLIP_TEXTURE
                         global const float* clip_texels,
#endif
                         const ClStack2dFusedParams p)
{
    const size_t pixel = (size_t)y * (size_t)p.width + (size_t)x;
    const float2 s = clvr_ray_window_offset(clvr_ray_pixel_centre(x, y), (float2)((float)p.width, (float)p.height),
                                            p.camera);
    float3 o, d;
    clvr_ray_depth(s, p.camera, &o, &d); /* o + z d, z the eye depth (> 0: in front of the eye or image plane) */
    const float4 r0 = p.to_stack[0], r1 = p.to_stack[1], r2 = p.to_stack[2];
    const float3 qo = (float3)(dot(r0.xyz, o) + r0.w, dot(r1.xyz, o) + r1.w, dot(r2.xyz, o) + r2.w);
    const float3 qd = (float3)(dot(r0.xyz, d), dot(r1.xyz, d), dot(r2.xyz, d));
    const int mode = p.mode;
    float3 c = (float3)(0.0f);
    float transmittance = 1.0f;
    float4 iso_hit = (float4)(p.background.xyz, 0.0f);
    uint taken = 0, stepped_over = 0;
    if (qd.z != 0.0f) { /* else the ray runs parallel to the planes: the quads are seen edge-on */
        /* The ray parameterized by the plane coordinate u = q.z: q = q1o + u q1d (q1d.z = 1, q1o.z = 0), so
         * that plane j's point is clvr_slice_point(q1o, q1d, 0, plane_step, j), the one expression the
         * empty-space runs check. */
        const float3 q1d = (float3)(qd.x / qd.z, qd.y / qd.z, 1.0f);
        const float3 q1o = (float3)(qo.x - qo.z * q1d.x, qo.y - qo.z * q1d.y, 0.0f);
        const float step = p.plane_step;
        const int4 dims = p.dims;
        const ClvrOwnedGrid grid = stack2d_grid(dims);
        const float3 own_lo = grid.own_lo, own_hi = grid.own_hi;
        float uin, uout;
        clvr_box_chord(q1o, q1d, (float3)(0.0f), (float3)(own_hi.xy, (float)(dims.z - 1)), &uin, &uout);
        int j_lo, j_hi;
        clvr_slice_range(uin, uout, 0.0f, step, p.planes, &j_lo, &j_hi);
        /* Front to back: along the ray u grows with the eye depth where qd.z > 0. */
        const int dir = qd.z > 0.0f ? 1 : -1;
        const int j_end = dir > 0 ? j_hi : j_lo;
        const float neg_full_log2e = -step * length(d) / fabs(qd.z) * M_LOG2E_F;
        const float3 inv_q1d = 1.0f / q1d; /* for empty-space runs only */
#ifdef CLVR_STACK2D_CLIP_TEXTURE
        const float4 k0 = p.clip_row[0], k1 = p.clip_row[1], k2 = p.clip_row[2];
#endif
        for (int j = dir > 0 ? j_lo : j_hi; dir * (j_end - j) >= 0; j += dir) {
            const float3 q = clvr_slice_point(q1o, q1d, 0.0f, step, j);
            if (!clvr_grid_owned(q, own_lo, own_hi))
                continue;
            /* behind the eye (or the image plane): eye depth (u - qo.z) / qd.z <= 0; front to back, these
             * come first and no run of empty bricks starts there */
            if (!((q.z - qo.z) * (float)dir > 0.0f))
                continue;
            if (p.bricks.w) {
                const int4 b = clvr_brick(q, dims);
                const int space_b = clvr_space(space, p.bricks, b);
                if (space_b != 0) {
                    const int run_end = clvr_empty_run(q1o, q1d, inv_q1d, 0.0f, step, j, dir, j_end, &grid, b,
                                                       space_b - 1);
                    stepped_over += (uint)(dir * (run_end - j) + 1);
                    j = run_end;
                    continue;
                }
            }
            ++taken;
#ifdef CLVR_STACK2D_CLIP_TEXTURE
            {
                const float3 w = o + ((q.z - qo.z) / qd.z) * d; /* the world point */
                const float3 uc = (float3)(dot(k0.xyz, w) + k0.w, dot(k1.xyz, w) + k1.w, dot(k2.xyz, w) + k2.w);
                if (!clvr_clip_keep(clip_texels, p.clip_tex, uc, p.clip_inverse))
                    continue;
            }
#endif
            const float4 sample = mode == 0 ? (float4)(clvr_trilinear(stack, dims, q)) : clvr_trilinear4((global const float4*)stack, dims, q);
            if (mode == 2) {
                const float4 shaded = stack2d_surface(sample, p.iso, p.surface, p.light, p.to_eye.xyz);
                if (shaded.w >= p.alpha_ref) {
                    iso_hit = (float4)(shaded.xyz, 1.0f);
                    break;
                }
                continue;
            }
            const float4 ct = stack2d_color_tau(tf, p.tf_count, map, p.map_n, mode == 1, sample, p.to_eye.xyz);
            const float slab = j == 0 || j == p.planes - 1 ? 0.5f : 1.0f; /* the end planes' slabs are half */
            const float alpha = 1.0f - clvr_exp2(ct.w * (slab * neg_full_log2e));
            c += (transmittance * alpha) * ct.xyz;
            transmittance *= 1.0f - alpha;
            if (1.0f - transmittance >= p.ert_alpha)
                break;
        }
    }
    out[pixel] = mode == 2 ? iso_hit : (float4)(c + transmittance * p.background.xyz, 1.0f - transmittance);
    samples[pixel] = taken + stepped_over;
    skipped[pixel] = stepped_over;
}

kernel void stack2d_fused(global float4* out, global uint* samples, global uint* skipped, global const float* stack,
                          global const float* tf, global const float4* map, global const uchar* space,
#ifdef CLVR_STACK2D_CLIP_TEXTURE
                          global const float* clip_texels,
#endif
                          const ClStack2dFusedParams p)
{
    CLVR_GUARD_2D(p.width, p.height);
    stack2d_fused_pixel((int)get_global_id(0), (int)get_global_id(1), out, samples, skipped, stack, tf, map, space,
#ifdef CLVR_STACK2D_CLIP_TEXTURE
                        clip_texels,
#endif
                        p);
}

#ifndef CLVR_STACK2D_CLIP_TEXTURE
/* The fused path's ray packets (host/render/grid/stack2d.cpp, plain mode 0 only; docs/stack2d.md): pixels
 * 8x .. 8x + 7 of a row per work-item, one per lane of float8 vectors (kernels/packet.h), stepping through the
 * same planes j together, each lane with stack2d_fused_pixel's expressions, so the image is its bits. Each
 * lane's ray is set up as stack2d_fused_pixel sets it up; the lanes must walk the planes in one direction
 * (the stack's axis seen from the same side): where they do not — a wide-angle camera whose rays straddle a
 * plane through the eye parallel to the axis — the work-item renders its 8 pixels one by one instead. As
 * slice3d's packets: a lane whose plane point is outside the box or behind the eye, or whose ray has stopped,
 * is masked; planes are stepped over only when every sampling lane is in an empty brick, to the nearest end of
 * their runs and never past another lane's next plane; a lane in an empty brick beside sampling ones takes its
 * sample (tau 0: nothing changes). samples[] counts what stack2d_fused_pixel counts (the planes met in the box
 * in front of the eye up to where the ray stopped), skipped[] those the lane did not sample. */
kernel void stack2d_fused_packet(global float4* out, global uint* samples, global uint* skipped,
                                 global const float* stack, global const float* tf, global const float4* map,
                                 global const uchar* space, const ClStack2dFusedParams p)
{
    const int x0 = (int)get_global_id(0) * CLVR_LANES, y = (int)get_global_id(1);
    if (x0 >= p.width || y >= p.height)
        return;
    const float step = p.plane_step;
    const int4 dims = p.dims;
    const ClvrOwnedGrid grid = stack2d_grid(dims);
    const float3 own_hi = grid.own_hi;
    const float4 r0 = p.to_stack[0], r1 = p.to_stack[1], r2 = p.to_stack[2];
    float q1ox[8], q1oy[8], q1dx[8], q1dy[8], qoz[8], nfl[8];
    int jlo[8], jhi[8];
    int dir = 0, one_way = 1;
    for (int l = 0; l < CLVR_LANES; ++l) {
        q1ox[l] = q1oy[l] = q1dx[l] = q1dy[l] = qoz[l] = nfl[l] = 0.0f;
        jlo[l] = 0, jhi[l] = -1;
        if (x0 + l >= p.width)
            continue;
        const float2 s = clvr_ray_window_offset(clvr_ray_pixel_centre(x0 + l, y), (float2)((float)p.width, (float)p.height),
                                                p.camera);
        float3 o, d;
        clvr_ray_depth(s, p.camera, &o, &d);
        const float3 qo = (float3)(dot(r0.xyz, o) + r0.w, dot(r1.xyz, o) + r1.w, dot(r2.xyz, o) + r2.w);
        const float3 qd = (float3)(dot(r0.xyz, d), dot(r1.xyz, d), dot(r2.xyz, d));
        if (qd.z == 0.0f)  /* parallel to the planes: none met */
            continue;
        const float3 q1d = (float3)(qd.x / qd.z, qd.y / qd.z, 1.0f);
        const float3 q1o = (float3)(qo.x - qo.z * q1d.x, qo.y - qo.z * q1d.y, 0.0f);
        float uin, uout;
        clvr_box_chord(q1o, q1d, (float3)(0.0f), (float3)(own_hi.xy, (float)(dims.z - 1)), &uin, &uout);
        clvr_slice_range(uin, uout, 0.0f, step, p.planes, &jlo[l], &jhi[l]);
        const int lane_dir = qd.z > 0.0f ? 1 : -1;
        if (dir != 0 && lane_dir != dir)
            one_way = 0;
        dir = lane_dir;
        q1ox[l] = q1o.x, q1oy[l] = q1o.y, q1dx[l] = q1d.x, q1dy[l] = q1d.y, qoz[l] = qo.z;
        nfl[l] = -step * length(d) / fabs(qd.z) * M_LOG2E_F;
    }
    if (!one_way) {
        for (int l = 0; l < CLVR_LANES && x0 + l < p.width; ++l)
            stack2d_fused_pixel(x0 + l, y, out, samples, skipped, stack, tf, map, space, p);
        return;
    }
    dir = dir != 0 ? dir : 1;
    const float8 q1o_x = vload8(0, q1ox), q1o_y = vload8(0, q1oy), q1d_x = vload8(0, q1dx), q1d_y = vload8(0, q1dy);
    const float8 q1o_z = 0.0f, q1d_z = 1.0f, qo_z = vload8(0, qoz), neg_full_log2e = vload8(0, nfl);
    const int8 lo8 = vload8(0, jlo), hi8 = vload8(0, jhi);
    const int8 ranged = lo8 <= hi8;
    const int j_begin = clvr_min8(select((int8)(p.planes), lo8, ranged)), j_end = clvr_max8(select((int8)(-1), hi8, ranged));
    const int skip = p.bricks.w;
    float8 cr = 0.0f, cg = 0.0f, cb = 0.0f, transmittance = 1.0f;
    int8 live = ranged, taken = 0, stepped = 0;
    for (int j = dir > 0 ? j_begin : j_end; dir > 0 ? j <= j_end : j >= j_begin; j += dir) {
        const float z = 0.0f + (float)j * step;  /* clvr_slice_point's depth of plane j */
        const float8 qx = q1o_x + z * q1d_x, qy = q1o_y + z * q1d_y, qz = q1o_z + z * q1d_z;
        int8 act = live & (j >= lo8) & (j <= hi8) & clvr_in_box8(qx, qy, qz, grid.own_lo, grid.own_hi) &
                   isgreater((qz - qo_z) * (float)dir, 0.0f);
        if (!any(act))
            continue;
        /* the stack's own coordinates, 0 in the lanes that do not sample */
        const float8 gx = select((float8)(0.0f), qx, act), gy = select((float8)(0.0f), qy, act);
        const float8 gz = select((float8)(0.0f), qz, act);
        if (skip) {
            const int8 bx = min(convert_int8(gx), dims.x - 2) >> CLVR_BRICK_SHIFT;
            const int8 by = min(convert_int8(gy), dims.y - 2) >> CLVR_BRICK_SHIFT;
            const int8 bz = min(convert_int8(gz), dims.z - 2) >> CLVR_BRICK_SHIFT;
            const int8 sp = clvr_space8(space, p.bricks, bx, by, bz);
            if (!any(act & (sp == 0))) {
                const int8 run_end = clvr_empty_run8(q1o_x, q1o_y, q1o_z, q1d_x, q1d_y, q1d_z, 0.0f, step, j, dir,
                                                     dir > 0 ? hi8 : lo8, &grid, bx, by, bz, sp - 1);
                const int jump = clvr_packet_jump(run_end, act, live, j, dir, lo8, hi8, j_begin, j_end);
                stepped += select((int8)(0), (int8)(dir * (jump - j) + 1), act);
                j = jump;
                continue;
            }
        }
        taken -= act;
        const float8 value = clvr_trilinear8(stack, dims, gx, gy, gz);
        float8 r, g, b, tau;
        clvr_tf_eval8(tf, p.tf_count, value, &r, &g, &b, &tau);
        const float slab = j == 0 || j == p.planes - 1 ? 0.5f : 1.0f; /* the end planes' slabs are half */
        const float8 alpha = 1.0f - clvr_exp2_8(tau * (slab * neg_full_log2e));
        cr = select(cr, cr + (transmittance * alpha) * r, act);
        cg = select(cg, cg + (transmittance * alpha) * g, act);
        cb = select(cb, cb + (transmittance * alpha) * b, act);
        transmittance = select(transmittance, transmittance * (1.0f - alpha), act);
        live &= ~(act & isgreaterequal(1.0f - transmittance, p.ert_alpha));
        if (!any(live))
            break;
    }
    const float8 orr = cr + transmittance * p.background.x, org = cg + transmittance * p.background.y;
    const float8 orb = cb + transmittance * p.background.z, oa = 1.0f - transmittance;
    float ro[8], go[8], bo[8], ao[8];
    int tk[8], st[8];
    vstore8(orr, 0, ro), vstore8(org, 0, go), vstore8(orb, 0, bo), vstore8(oa, 0, ao);
    vstore8(taken, 0, tk), vstore8(stepped, 0, st);
    for (int l = 0; l < CLVR_LANES && x0 + l < p.width; ++l) {
        const size_t i = (size_t)y * (size_t)p.width + (size_t)(x0 + l);
        out[i] = (float4)(ro[l], go[l], bo[l], ao[l]);
        samples[i] = (uint)(tk[l] + st[l]);
        skipped[i] = (uint)st[l];
    }
}
#endif

#endif
