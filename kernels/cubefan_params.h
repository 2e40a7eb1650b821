/* kernels/cubefan_params.h — the uniforms of kernels/cubefan.cl's fragment programs, shared by host
 * (host/render/grid/cubefan.cpp) and device. float4s only: they travel as raster::FragmentProgram::uniforms
 * (host/render/fragment_uniforms.h); the host static_asserts the size. */
#ifndef CLVR_CUBEFAN_PARAMS_H
#define CLVR_CUBEFAN_PARAMS_H

#include "cl_types.h"
#include "ray.h"

/* How a fragment of a projected cube gets its opacity (CubefanOptions::Opacity). */
#define CUBEFAN_OPACITY_TEXTURE 0 /* the exp-opacity texture of seeds/002 §7 at (l / l_max, tau / tau_max) */
#define CUBEFAN_OPACITY_EXP 1     /* 1 - exp(-tau l) of the interpolated l, per fragment (no table) */
#define CUBEFAN_OPACITY_LINEAR 2  /* the per-vertex opacity interpolated (Shirley & Tuchman) */

typedef struct {
    ClCamera camera;   /* relative to the renderer's shifted origin (the volume box's centre) */
    cl_float4 counts;  /* (width, height, transfer-function control points, CUBEFAN_OPACITY_*) */
    cl_float4 scale;   /* (l_max, tau_max, texture size N, 0): the texture's axes u = l / l_max, v = tau / tau_max */
} ClCubefanUniforms;   /* 112 bytes */

/* cubefan_fused's parameters (the fused path: each pixel's ray walks the selected cubes). */
typedef struct {
    ClCamera camera;        /* relative to the renderer's shifted origin (the cube field's centre) */
    cl_float4 field_lo;     /* xyz: the cube field's low corner, relative to the same origin */
    cl_float4 inv_spacing;  /* xyz: 1 / grid spacing: q = (p - field_lo) inv_spacing puts voxel i's cube at [i, i + 1) */
    cl_float4 background;   /* rgb */
    cl_int4 dims;           /* xyz: voxels per axis (the selection grid's) */
    cl_int width, height, tf_count;
    cl_float ert_alpha;     /* stop once the opacity reaches this; > 1: never */
    cl_int4 filled_lo;      /* xyz: the box of the bricks with a voxel that adds color, in voxels [lo, hi): */
    cl_int4 filled_hi;      /* the rays walk only inside it (none: lo >= hi) */
} ClCubefanFusedParams;     /* 192 bytes */

#endif
