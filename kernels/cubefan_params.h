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

#endif
