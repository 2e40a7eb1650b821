/* kernels/iso3d_params.h — the uniforms of kernels/iso3d.cl's fragment program as one struct (float4
 * fields only, read through r->uniforms; the host copies it through host/render/fragment_uniforms.h),
 * and the scalar arguments of its last pass iso3d_finish and of its fused path iso3d_fused as two more
 * (passed by value; buffers stay separate arguments), shared by host (host/render/grid/iso3d.cpp) and
 * device. Sizes and offsets are probed on the device by tests/layout_test.cpp. */
#ifndef CLVR_ISO3D_PARAMS_H
#define CLVR_ISO3D_PARAMS_H

#include "cl_types.h"
#include "ray.h"

typedef struct {
    cl_float4 grid_origin;  /* world position of grid point (0, 0, 0), w = 0 */
    cl_float4 inv_spacing;  /* 1 / spacing per axis, w = 0 */
    cl_float4 dims;         /* grid points per axis, w = 0 */
    cl_float4 value_map;    /* (value_lo, 1 / (value_hi - value_lo), positions, flip), see clvr_fragment */
    cl_float4 brick_lo;     /* the brick's first grid point (0 unbricked), w = 0 */
    cl_float4 brick_end;    /* its box's exclusive upper end in grid units (dims unbricked), w = 0 */
    cl_float4 brick_dims;   /* its grid points per axis (dims unbricked), w = 0 */
} ClIso3dUniforms;          /* 112 bytes */

typedef struct {
    cl_float4 surface;      /* flat surface color (shaded 0), w = 1 */
    cl_float4 background;   /* image background, w = 0 */
    cl_uint n;              /* pixels */
    cl_int shaded;          /* 1: the frame buffer holds the shaded color, 0: flat `surface` */
    cl_int pad0, pad1;
} ClIso3dFinishParams;      /* 48 bytes */

/* The fused path's arguments (kernels/iso3d.cl's iso3d_fused): the rays, the fragment program's uniforms
 * (unbricked), and the slices of the slice draws. */
typedef struct {
    ClCamera camera;        /* 80 bytes */
    ClIso3dUniforms grid;   /* as the fragment program's (brick = the whole grid); value_map.w (flip) is 0 */
    cl_float4 slices;       /* (eye depth of slice 0, slice spacing, near, far): near and far are the slice draws'
                             * projection, for the window depth of a hit */
    cl_int4 bricks;         /* empty-space skipping (kernels/empty_space.h): bricks per axis; w = 1 to skip */
    cl_int width, height;   /* image size in pixels */
    cl_int slice_count;
    cl_float alpha_ref;     /* the alpha test's reference: a sample is on the surface if its alpha >= this */
} ClIso3dFusedParams;       /* 240 bytes */

#endif
