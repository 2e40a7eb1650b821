/* kernels/tetiso_params.h — the parameters of kernels/tetiso.cl, shared by host
 * (host/render/tet/tetiso.cpp) and device; sizes and offsets probed by tests/layout_test.cpp. */
#ifndef CLVR_TETISO_PARAMS_H
#define CLVR_TETISO_PARAMS_H

#include "cl_types.h"

/* The fragment program's uniforms (uniforms[0]). */
typedef struct {
    cl_float4 size;  /* (width, height, 0, 0) of the frame buffer */
} ClTetisoUniforms;  /* 16 bytes */

/* tetiso_weights, tetiso_nearer, tetiso_add and tetiso_finish. */
typedef struct {
    cl_float4 background;  /* w = 0 */
    cl_int count;          /* pixels */
    cl_int equal;          /* 1: q = 1/2 wherever both faces were found (equal blending) */
    cl_float iso;          /* the iso-value, normalized as the vertex scalars are */
    cl_int pass;           /* tetiso_add: 0 the crossings upwards, 1 downwards, + 2 for the back faces' shade */
} ClTetisoParams;          /* 32 bytes */

#endif
