// kernels/iso3d.cl — shaded iso-surfaces by the alpha test (§3 of seeds/000_354856c7f65dc3f9.txt).
// Two uses of this file (host/render/grid/iso3d.cpp):
//  - with CLVR_ISO3D_FRAGMENT defined, it is appended after kernels/raster.cl as the fragment program
//    of the slices: it samples the RGBA volume (encoded normal, value) trilinearly and puts the value,
//    normalized to [0,1], in alpha, where the alpha test (GEQUAL iso) keeps the samples at or above
//    the iso-value and the depth test (LESS) the nearest of them;
//  - without it: iso3d_fused, the fused path (the slice draws' work in one kernel: each pixel's ray steps
//    through the same slices, nearest first, and stops at the first sample that passes the alpha test),
//    and iso3d_finish, the last pass, which puts the background where no slice passed.
// The host has validated everything; this file only does arithmetic.
#include "clvr_common.h"
#include "empty_space.h"
#include "iso3d_params.h"
#include "ray.h"
#include "volume_sampling.h"

/* The slices' fragment color for RGBA sample t at grid coordinates g of a grid with `dims` points and
 * value_map m (ClIso3dUniforms): (0.5 N + 0.5 interpolated, turned round with m.w != 0; or with m.z != 0
 * the point's 3D texture coordinates (g + 0.5) / n), and in alpha the value normalized to [0,1]. */
float4 iso3d_color(const float4 t, const float3 g, const int4 dims, const float4 m)
{
    const float3 n = m.w != 0.0f ? 1.0f - t.xyz : t.xyz;
    const float3 rgb = m.z != 0.0f ? (g + 0.5f) / convert_float3(dims.xyz) : n;
    return (float4)(rgb, (t.w - m.x) * m.y);
}

#ifndef CLVR_ISO3D_FRAGMENT

/* Last pass, per pixel: a pixel is on the surface iff some fragment passed both tests there, i.e.
 * its depth is below the cleared 1.0. On the surface: (color, 1), the color clamped to [0,1] as a
 * fixed-point frame buffer would after the color-matrix copy (shaded != 0), or the flat surface
 * color (shaded == 0). Elsewhere: (background, 0), so the image is I + (1 - A) background. */
kernel void iso3d_finish(global float4* color, global const float* depth, const ClIso3dFinishParams p)
{
    CLVR_GUARD_1D(p.n);
    const size_t i = get_global_id(0);
    if (depth[i] < 1.0f)
        color[i] = (float4)(p.shaded ? clamp(color[i].xyz, 0.0f, 1.0f) : p.surface.xyz, 1.0f);
    else
        color[i] = (float4)(p.background.xyz, 0.0f);
}

/* The fused path (host/render/grid/iso3d.cpp, "path": "fused"): one work-item per pixel does what the slice
 * draws do at that pixel. Its ray o + z d (z the eye depth, kernels/ray.h) meets slice k at the eye depth
 * slices.x + k slices.y; front to back, the first sample inside the grid whose fragment color passes the
 * alpha test (alpha >= alpha_ref) is kept, as the depth test LESS keeps the nearest passing fragment. Out:
 * what the draws leave in the frame buffer — that color and the hit's window depth of the draws'
 * projection (near slices.z, far slices.w), or (0, 0, 0, 0) and the cleared depth 1 where no sample passes
 * — and samples[pixel] = the samples taken. The sample points are the slice polygons' fragments up to
 * rounding: the draws interpolate world positions across the polygons, this adds z d to o. values is
 * the scalar volume (float, the RGBA volume's fourth channel). With p.bricks.w != 0 runs of slices in
 * bricks whose values all lie below the iso-value (space[], kernels/empty_space.h) are stepped over: no
 * sample there could pass, so the frame buffer is the same bit for bit; they are not counted in samples. */
kernel void iso3d_fused(global float4* color, global float* depth, global uint* samples, global const float* volume,
                        global const float* values, global const uchar* space, const ClIso3dFusedParams p)
{
    CLVR_GUARD_2D(p.width, p.height);
    const int x = (int)get_global_id(0), y = (int)get_global_id(1);
    const size_t pixel = (size_t)y * (size_t)p.width + (size_t)x;
    const float2 s = clvr_ray_window_offset(clvr_ray_pixel_centre(x, y), (float2)((float)p.width, (float)p.height),
                                            p.camera);
    float3 o, d;
    clvr_ray_depth(s, p.camera, &o, &d);
    const int4 dims = convert_int4(p.grid.dims);
    const float3 go = (o - p.grid.grid_origin.xyz) * p.grid.inv_spacing.xyz, gd = d * p.grid.inv_spacing.xyz;
    const float depth0 = p.slices.x, delta_s = p.slices.y;

    /* The whole grid (no parts): own_hi the next float above n - 1, the box of clvr_grid_inside. */
    const float3 top = nextafter(convert_float3(dims.xyz - 1), (float3)(INFINITY));
    const ClvrOwnedGrid grid = {dims, (int4)(0), (float3)(0.0f), top};
    /* The slices near the ray's chord through the grid (one more each way; every sample is still checked). */
    float zin, zout;
    clvr_box_chord(go, gd, grid.own_lo, grid.own_hi, &zin, &zout);
    int k_lo, k_hi;
    clvr_slice_range(zin, zout, depth0, delta_s, p.slice_count, &k_lo, &k_hi);
    const float3 inv_gd = 1.0f / gd;  /* for empty-space runs only (inf where gd is 0, not used there) */
    float4 hit = (float4)(0.0f);
    float window = 1.0f;
    uint taken = 0;
    for (int k = k_lo; k <= k_hi; ++k) {
        const float3 g = clvr_slice_point(go, gd, depth0, delta_s, k);
        if (!clvr_grid_inside(g, dims))
            continue;
        if (p.bricks.w) {
            const int4 b = clvr_brick(g, dims);
            const int space_b = clvr_space(space, p.bricks, b);
            if (space_b != 0) {
                k = clvr_empty_run(go, gd, inv_gd, depth0, delta_s, k, 1, k_hi, &grid, b, space_b - 1);
                continue;
            }
        }
        ++taken;
        const float z = depth0 + (float)k * delta_s;
        /* The alpha test on the value alone (values: the scalar volume, the RGBA volume's fourth channel: the
         * same trilinear arithmetic on a quarter of the bytes); the whole RGBA sample only for the hit. */
        if ((clvr_trilinear(values, dims, g) - p.grid.value_map.x) * p.grid.value_map.y >= p.alpha_ref) {
            const float4 c = iso3d_color(clvr_trilinear4((global const float4*)volume, dims, g), g, dims, p.grid.value_map);
            /* glm's projection: NDC z in [-1, 1], window depth (ndc + 1) / 2. */
            const float n = p.slices.z, f = p.slices.w;
            const float ndc = clvr_ray_parallel(p.camera) ? (2.0f * z - f - n) / (f - n)
                                                          : (f + n) / (f - n) - 2.0f * f * n / ((f - n) * z);
            hit = c;
            window = 0.5f * ndc + 0.5f;
            break;
        }
    }
    color[pixel] = hit;
    depth[pixel] = window;
    samples[pixel] = taken;
}

#else

/* attr[0] = world position on the slice (perspective-correct). uniforms: ClIso3dUniforms
 * (kernels/iso3d_params.h): grid origin, 1 / spacing, dims; the brick's first grid point, its box's
 * exclusive upper end (grid units), its dims; value_map = (value_lo, 1 / (value_hi - value_lo),
 * positions, flip): the value range mapped onto alpha's [0,1],
 * positions != 0 for gradientless shading, and flip != 0 for Figure 7's interior pass (the normal turned
 * round: encoded 1 - rgb). buffer[0]: RGBA volume (or the brick's part of it), per grid point (0.5 N + 0.5, value)
 * with N the unit normal (iso3d.h). Output: (0.5 N + 0.5 interpolated, normalized value), or with
 * positions the point's 3D texture coordinates (g + 0.5) / n in RGB (the paper: "the computed texture
 * coordinate (u, v, w) is assigned as RGB color value"); discarded outside the grid (empty there). */
int clvr_fragment(const ClFragment* f, const ClFragmentResources* r, float4* color)
{
    constant ClIso3dUniforms* u = (constant ClIso3dUniforms*)r->uniforms;
    const int4 dims = convert_int4(u->dims);
    const float3 g = (f->attr[0].xyz - u->grid_origin.xyz) * u->inv_spacing.xyz;
    if (!clvr_grid_inside(g, dims))
        return 0;
    /* Bricking (§3.1): the fragment belongs to the brick whose half-open box [lo, hi) holds g (hi = n for
     * the last slab of an axis, so its far face is kept), which cuts every slice exactly between bricks.
     * The brick's texture is sampled at g - lo: exact in float (0 <= lo <= g, lo an integer), so the
     * cell and its weights are the unbricked ones, bit for bit. Unbricked: lo = 0, hi = n. */
    const float3 lo = u->brick_lo.xyz;
    const float4 hi = u->brick_end;
    if (g.x < lo.x || g.y < lo.y || g.z < lo.z || g.x >= hi.x || g.y >= hi.y || g.z >= hi.z)
        return 0;
    *color = iso3d_color(clvr_trilinear4((global const float4*)r->buffer[0], convert_int4(u->brick_dims), g - lo), g, dims, u->value_map);
    return 1;
}

#endif
