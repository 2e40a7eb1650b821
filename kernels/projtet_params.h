/* kernels/projtet_params.h — the uniforms of kernels/projtet.cl's fragment program, shared by host
 * (host/render/tet/projtet.cpp) and device. float4s only: they travel as raster::FragmentProgram::uniforms
 * (host/render/fragment_uniforms.h), so host and device agree by construction; the host static_asserts
 * the size (not in tests/layout_test.cpp's probe, which covers by-value kernel arguments: the fused path's
 * ClProjtetFusedParams below). */
#ifndef CLVR_PROJTET_PARAMS_H
#define CLVR_PROJTET_PARAMS_H

#include "cl_types.h"
#include "ray.h"

typedef struct {
    ClCamera camera;   /* relative to the renderer's shifted origin (the mesh box's centre) */
    cl_float4 counts;  /* (width, height, transfer-function control points, ψ table size) */
} ClProjtetUniforms;   /* 96 bytes */

/* A ray in a face's plane (kernels/projtet.cl projtet_in_plane; tools/ceiling_projtet.cpp repeats it): within
 * PROJTET_IN_PLANE of its terms' sizes, and kept by the cell of the face whose h points to the side of
 * (PROJTET_TIE_X, _Y, _Z), a direction no face of a structured grid lies along. */
#define PROJTET_IN_PLANE 1e-5f
#define PROJTET_TIE_X 0.5227f
#define PROJTET_TIE_Y 0.6381f
#define PROJTET_TIE_Z 0.5653f

/* The fused path's kernel argument (kernels/projtet.cl projtet_fused), by value. */
typedef struct {
    ClCamera camera;       /* as ClProjtetUniforms' */
    cl_float4 background;  /* the scene's, w unused */
    cl_int4 size;          /* (width, height, tiles per row, tile rows) */
    cl_int4 counts;        /* (transfer-function control points, ψ table size, 0, 0) */
} ClProjtetFusedParams;    /* 128 bytes */

#endif
