/* kernels/slice3d_params.h — the scalar arguments of kernels/slice3d.cl's fused kernel and of its
 * last pass slice3d_over_background as one struct each (passed by value; buffers stay separate
 * arguments), and the uniforms of its fragment program as another (float4 fields only, read through
 * r->uniforms), shared by host (host/render/grid/slice3d.cpp; stack2d.cpp and spherical.cpp also run
 * slice3d_over_background) and device. Sizes and offsets are probed on the device by
 * tests/layout_test.cpp. */
#ifndef CLVR_SLICE3D_PARAMS_H
#define CLVR_SLICE3D_PARAMS_H

#include "cl_types.h"
#include "ray.h"
#include "texture.h"

typedef struct {
    ClCamera camera;
    cl_int4 dims;            /* grid points per axis, w = 0 */
    cl_float4 grid_origin;   /* world position of grid point (0, 0, 0), w = 0 */
    cl_float4 inv_spacing;   /* 1 / spacing per axis, w = 0 */
    cl_int4 brick_dims;      /* bricks per axis (empty-space skipping), w = 0 */
    cl_float4 background;    /* image background, w = 0 */
    cl_int width, height;    /* image size in pixels */
    cl_int tf_count;         /* control points of the transfer function */
    cl_int skip;             /* 1: step over empty bricks */
    cl_float depth0;         /* eye depth of slice 0 */
    cl_float delta_s;        /* slice spacing along forward, world units */
    cl_int slice_count;
    cl_int front_to_back;    /* 1: front to back with early termination, 0: back to front */
    cl_float ert_alpha;      /* front to back: stop once the opacity reaches this (2: off) */
    cl_int clip_inverse;     /* clip texture: 1 keeps the outside */
    cl_int psi_n;            /* SLICE3D_PREINTEGRATED builds: the psi table is psi_n x psi_n */
    cl_int pad1;
    ClTexture clip_tex;      /* clip texture (SLICE3D_CLIP_TEXTURE builds only) */
    cl_float4 clip_row[3];   /* rows of the affine world -> clip-texture coordinates map */
    /* The part of the grid this volume is (sort-last, host/model/volume.h's GridPart; the whole grid
     * otherwise): grid_origin and the sample positions are the full grid's; a sample at full-grid
     * coordinates g is this volume's when own_lo <= g < own_hi per axis (own_hi is the next float above
     * the last point where the part ends with the grid), and is read at g - part_offset, dims being
     * the part's own. */
    cl_int4 part_offset;     /* w = 0 */
    cl_float4 own_lo;        /* w = 0 */
    cl_float4 own_hi;        /* w = 0 */
    cl_float4 grid_hi;       /* the next float above the full grid's last point, n - 1 per axis in full-grid
                              * coordinates: the box whose chord the slabs at its faces are clipped to
                              * (kernels/slice3d.cl), w = 0 */
    cl_int4 clip_mesh;       /* SLICE3D_CLIP_MESH builds: (layers, 1 if inverse, 1 if naive, 0) */
    cl_float4 tight_lo;      /* with skip: the box of the bricks that are not empty, in full-grid coordinates,
                              * inside [own_lo, own_hi) (tight_lo >= tight_hi on an axis: none); samples the
                              * sample loop visits (kernels/slice3d.cl), w = 0 */
    cl_float4 tight_hi;
} ClSlice3dParams;           /* 416 bytes */

typedef struct {
    cl_float4 background;    /* image background, w = 0 */
    cl_int count;            /* pixels */
    cl_int pad0, pad1, pad2;
} ClSlice3dOverBackgroundParams; /* 32 bytes */

typedef struct {
    ClCamera camera;
    cl_float4 frame;         /* (width, height, delta_s, tf_count) */
    cl_float4 grid_origin;   /* w = 0 */
    cl_float4 inv_spacing;   /* w = 0 */
    cl_float4 dims;          /* grid points per axis, w = 0 */
    cl_float4 clip_tex;      /* CLVR_SLICE3D_CLIP_TEXTURE: (width, height, depth, 1 if inverse) */
    cl_float4 slab;          /* (depth0, 0, 0, 0): slice k at eye depth depth0 + k delta_s (frame.z) */
} ClSlice3dUniforms;         /* 176 bytes */

#endif
