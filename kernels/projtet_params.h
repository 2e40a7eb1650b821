/* kernels/projtet_params.h — the uniforms of kernels/projtet.cl's fragment program, shared by host
 * (host/render/tet/projtet.cpp) and device. float4s only: they travel as raster::FragmentProgram::uniforms
 * (host/render/fragment_uniforms.h), so host and device agree by construction; the host static_asserts
 * the size (not in tests/layout_test.cpp's probe, which covers by-value kernel arguments). */
#ifndef CLVR_PROJTET_PARAMS_H
#define CLVR_PROJTET_PARAMS_H

#include "cl_types.h"
#include "ray.h"

typedef struct {
    ClCamera camera;   /* relative to the renderer's shifted origin (the mesh box's centre) */
    cl_float4 counts;  /* (width, height, transfer-function control points, ψ table size) */
} ClProjtetUniforms;   /* 96 bytes */

#endif
