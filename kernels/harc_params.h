/* kernels/harc_params.h — the scalar arguments of kernels/harc.cl's harc_render as one struct, shared
 * by host (host/render/tet/harc.cpp) and device, passed by value; buffers stay separate arguments. Sizes
 * and offsets are probed on the device by tests/layout_test.cpp. */
#ifndef CLVR_HARC_PARAMS_H
#define CLVR_HARC_PARAMS_H

#include "cl_types.h"
#include "ray.h"

typedef struct {
    ClCamera camera;        /* relative to the mesh's shifted origin */
    cl_float4 background;   /* image background, w = 0 */
    cl_float4 full_params;  /* full pre-integration table: (s of sample 0, samples per unit s,
                             * samples per unit l, 0) */
    cl_int width, height;   /* image size in pixels */
    cl_int tf_count;        /* control points of the transfer function */
    cl_int psi_n;           /* the psi table is psi_n x psi_n */
    cl_uint max_steps;      /* traversal steps per ray at most */
    cl_int integration;     /* HARC_INTEGRATION_* */
    cl_float ert_alpha;     /* stop once the opacity reaches this (2: off) */
    cl_int full_ns, full_nl; /* full pre-integration table: samples per s axis and along l */
    cl_int clip_box;        /* 1: integrate only inside [box_lo, box_hi] (a sort-last part), 0: everywhere */
    cl_int pad1, pad2;
    cl_float4 box_lo;       /* the part's box, relative to the shifted origin, w = 0 */
    cl_float4 box_hi;
    cl_float4 slices;       /* HARC_INTEGRATION_SLICES (tetslice's fused path): (eye depth of slice 0, slice
                             * spacing, slice count, 0) */
    cl_float4 iso;          /* HARC_INTEGRATION_ISO (tetiso's fused path): (iso-value, ambient, diffuse, flags:
                             * HARC_ISO_SHADED | HARC_ISO_EQUAL_WEIGHTS) */
    cl_float4 iso_light;    /* towards the light, unit, w = 0 */
    cl_float4 iso_color;    /* the surface color, w = 0 */
} ClHarcParams;             /* 256 bytes */

#define HARC_ISO_SHADED 1        /* color (ambient + diffuse <light, N>); else the color */
#define HARC_ISO_EQUAL_WEIGHTS 2 /* the entry and exit shades averaged (seeds/000 Figure 9, left); else q-weighted */

#endif
