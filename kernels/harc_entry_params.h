/* kernels/harc_entry_params.h — the uniforms of kernels/harc_entry.cl's fragment program as one struct,
 * shared by host (host/render/tet/harc_entry.cpp, through host/render/fragment_uniforms.h) and device
 * (read through r->uniforms). float4 fields only. Probed by tests/layout_test.cpp. */
#ifndef CLVR_HARC_ENTRY_PARAMS_H
#define CLVR_HARC_ENTRY_PARAMS_H

#include "ray.h"

typedef struct {
    ClCamera camera;  /* relative to the mesh origin, as harc_render takes it */
    cl_float4 size;   /* (width, height, 0, 0) */
} ClHarcEntryUniforms; /* 96 bytes */

#endif
