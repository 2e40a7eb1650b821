/* kernels/spherical_params.h — the scalar arguments of kernels/spherical.cl's spherical_shell as one
 * struct, shared by host (host/render/grid/spherical.cpp) and device, passed by value; buffers stay
 * separate arguments. Sizes and offsets are probed on the device by tests/layout_test.cpp. */
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

#endif
