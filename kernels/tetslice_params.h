/* kernels/tetslice_params.h — the parameters of kernels/tetslice.cl, shared by host
 * (host/render/tet/tetslice.cpp) and device; sizes and offsets probed by tests/layout_test.cpp. */
#ifndef CLVR_TETSLICE_PARAMS_H
#define CLVR_TETSLICE_PARAMS_H

#include "cl_types.h"
#include "ray.h"

/* One slice's resolve-and-composite pass (tetslice_composite). */
typedef struct {
    ClCamera camera;       /* relative to the renderer's shifted origin */
    cl_int width, height;  /* the image = the frame buffer */
    cl_int tf_count;       /* control points in the transfer-function buffer */
    cl_int pad0;
    cl_float depth;        /* the slice's eye depth d */
    cl_float delta_s;      /* slice spacing along forward; the ray's slab length is delta_s * |d| */
    cl_float pad1, pad2;
} ClTetsliceCompositeParams; /* 112 bytes */

#endif
