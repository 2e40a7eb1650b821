/* kernels/empty_space.h — empty-space skipping over a grid of bricks, for the fused kernels that step a
 * ray through view-aligned slices (kernels/slice3d.cl: bricks where the transfer function's tau is 0;
 * kernels/iso3d.cl: bricks whose values all lie below the iso-value). docs/slice3d.md.
 *
 * The grid's cells are grouped in bricks of B = 2^CLVR_BRICK_SHIFT = 4 cells per axis (host: kBrickCells,
 * host/render/grid/slice3d.h); brick b covers the cells [Bb, Bb + B), i.e. the grid points [Bb, Bb + B] (one
 * point of overlap with its neighbour), so every trilinear footprint lies in the brick of its lower corner.
 * The host decides which bricks are empty from the min-max of their points, widened against float rounding,
 * so that a sample in an empty brick would leave the pixel unchanged bit for bit.
 * space[brick] = 0 for a brick that is not empty, else r + 1 where every brick within Chebyshev
 * distance r (bricks outside the grid count as empty) is empty: one run steps over that cube. OpenCL C 1.2. */
#ifndef CLVR_EMPTY_SPACE_H
#define CLVR_EMPTY_SPACE_H

#include "volume_sampling.h"

#define CLVR_BRICK_SHIFT 2

/* The grid a kernel samples: its points per axis, and for a sort-last part (host/model/volume.h GridPart)
 * its offset in the full grid and the full-grid box it owns (clvr_grid_owned); for a whole grid offset 0
 * and own_hi the next float above n - 1. */
typedef struct {
    int4 dims;
    int4 offset;
    float3 own_lo, own_hi;
} ClvrOwnedGrid;

/* Grid coordinates of slice k's sample: the one expression used for every sample position, so that
 * the run ends found by clvr_empty_run are the positions the main loop would compute. Each
 * coordinate is a monotonic function of k (every rounded operation is), hence so are the inside
 * test and the brick index per axis: two samples in the same box of bricks enclose only samples in it. */
float3 clvr_slice_point(const float3 go, const float3 gd, const float depth0, const float delta_s, const int k)
{
    return go + (depth0 + (float)k * delta_s) * gd;
}

/* Brick (x, y, z) of the cell clvr_trilinear uses at the volume's own coordinates gl (its lower corner,
 * clamped to n - 2). */
int4 clvr_brick(const float3 gl, const int4 dims)
{
    return (int4)(min((int)gl.x, dims.x - 2), min((int)gl.y, dims.y - 2), min((int)gl.z, dims.z - 2), 0) >>
           CLVR_BRICK_SHIFT;
}

/* 1 if slice k's sample is the grid's (owned) and its brick within Chebyshev distance r of brick b. */
int clvr_in_cube(const float3 go, const float3 gd, const float depth0, const float delta_s, const int k,
                 const ClvrOwnedGrid* grid, const int4 b, const int r)
{
    const float3 g = clvr_slice_point(go, gd, depth0, delta_s, k);
    if (!clvr_grid_owned(g, grid->own_lo, grid->own_hi))
        return 0;
    const uint4 c = abs_diff(clvr_brick(clvr_grid_local(g, grid->offset), grid->dims), b);
    return max(c.x, max(c.y, c.z)) <= (uint)r;
}

/* Slice k's sample lies in brick b, and every brick within Chebyshev distance r of b is empty;
 * walking in direction step (+1 or -1) towards k_end, the last slice whose sample is still inside
 * the grid and in that cube of bricks. The ray's exit from the cube's box (clipped to the grid; inv_gd
 * = 1 / gd) gives a candidate, checked with the main loop's own arithmetic (and one slice back if it
 * fails); by monotonicity every slice between k and it is then in the cube too. Falls back to k. */
int clvr_empty_run(const float3 go, const float3 gd, const float3 inv_gd, const float depth0, const float delta_s,
                   const int k, const int step, const int k_end, const ClvrOwnedGrid* grid, const int4 b, const int r)
{
    /* the cube's box in full-grid coordinates */
    const int4 dims = grid->dims;
    const float3 offset = convert_float3(grid->offset.xyz);
    const float3 lo = offset + convert_float3(max(b.xyz - r, 0) << CLVR_BRICK_SHIFT);
    const float3 hi = offset + fmin(convert_float3((b.xyz + r + 1) << CLVR_BRICK_SHIFT), convert_float3(dims.xyz - 1));
    /* eye depth where the ray crosses each face it walks towards */
    const float3 face = (float)step * gd > 0.0f ? hi : lo;
    const float3 t = (face - go) * inv_gd;
    float zexit;
    if (step > 0)
        zexit = fmin(gd.x != 0.0f ? t.x : INFINITY, fmin(gd.y != 0.0f ? t.y : INFINITY, gd.z != 0.0f ? t.z : INFINITY));
    else
        zexit = fmax(gd.x != 0.0f ? t.x : -INFINITY, fmax(gd.y != 0.0f ? t.y : -INFINITY, gd.z != 0.0f ? t.z : -INFINITY));
    const float kf = (zexit - depth0) / delta_s;
    int cand;
    if (step > 0)
        cand = (int)clamp(floor(kf), (float)k, (float)k_end);
    else
        cand = (int)clamp(ceil(kf), (float)k_end, (float)k);
    for (int tries = 0; tries < 2 && cand != k; ++tries, cand -= step)
        if (clvr_in_cube(go, gd, depth0, delta_s, cand, grid, b, r))
            return cand;
    return k;
}

/* space[] of brick b: 0 if not empty, else r + 1 (see above). */
int clvr_space(global const uchar* space, const int4 bdims, const int4 b)
{
    return space[((uint)b.z * (uint)bdims.y + (uint)b.y) * (uint)bdims.x + (uint)b.x];
}

#endif
