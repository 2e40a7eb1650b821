/* kernels/spherical_params.h — the scalar arguments of kernels/spherical.cl's spherical_shell and of its
 * fused path spherical_fused as one struct each, shared by host (host/render/grid/spherical.cpp) and
 * device, passed by value; buffers stay separate arguments. Sizes and offsets are probed on the device by
 * tests/layout_test.cpp. */
#ifndef CLVR_SPHERICAL_PARAMS_H
#define CLVR_SPHERICAL_PARAMS_H

#include "cl_types.h"
#include "ray.h"
#include "texture.h"

typedef struct {
    ClCamera camera;
    ClTexture tex;          /* the scalar volume as a 3D texture in spherical coordinates */
    cl_float4 center;       /* sphere center (world), w = radius of the next inner shell (-1: none) */
    cl_float4 slab;         /* (r_lo, r_hi, side, radial), see spherical_shell */
    cl_int width, height;   /* image size in pixels */
    cl_int tf_count;        /* control points of the transfer function */
    cl_int pad0;
    cl_float phi_s0;        /* the phi texture coordinate wraps to [phi_s0, phi_s0 + phi_period) */
    cl_float phi_period;    /* 0: no wrap */
    cl_float pad1, pad2;
} ClSphericalParams;        /* 192 bytes */

/* The fused path's arguments (kernels/spherical.cl's spherical_fused); the shells are a buffer. */
typedef struct {
    ClCamera camera;
    ClTexture tex;            /* the scalar volume as a 3D texture in spherical coordinates */
    cl_float4 matrix_row[4];  /* the pixel transfer's color matrix, row by row (the texel-center map composed in) */
    cl_float4 scale;          /* its scale ... */
    cl_float4 bias;           /* ... and bias: q = bias + scale (M (u, v, w, 1)) */
    cl_float4 center;         /* sphere center (world), w = 0 */
    cl_float4 background;     /* image background, w = 0 */
    cl_int width, height;     /* image size in pixels */
    cl_int tf_count;          /* control points of the transfer function */
    cl_int shells;            /* entries of the shell table */
    cl_float phi_s0;          /* the phi texture coordinate wraps to [phi_s0, phi_s0 + phi_period) */
    cl_float phi_period;      /* 0: no wrap */
    cl_float ert_alpha;       /* stop once the opacity reaches this (2: off) */
    cl_int radial;            /* 1: a shell's opacity counts r_hi - r_lo ("opacity": "radial") */
} ClSphericalFusedParams;   /* 288 bytes */

#endif
