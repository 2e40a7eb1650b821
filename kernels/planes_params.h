/* kernels/planes_params.h — the scalar arguments of kernels/planes.cl's planes_render as one struct,
 * shared by host (host/render/grid/planes.cpp) and device, passed by value; buffers stay separate
 * arguments. Sizes and offsets are probed on the device by tests/layout_test.cpp. */
#ifndef CLVR_PLANES_PARAMS_H
#define CLVR_PLANES_PARAMS_H

#include "cl_types.h"
#include "ray.h"

typedef struct {
    ClCamera camera;
    cl_int4 dims;           /* grid points per axis (of this volume, a part's own), w = 0 */
    cl_int4 part_offset;    /* this volume's point 0 in the full grid (sort-last part; else 0), w = 0 */
    cl_int4 full_dims;      /* the full grid's points per axis (= dims for a whole volume), w = 0 */
    cl_float4 grid_origin;  /* world position of the full grid's point (0, 0, 0), w = 0 */
    cl_float4 inv_spacing;  /* 1 / spacing per axis, w = 0 */
    cl_float4 box_lo, box_hi; /* the full grid's bounds, world, w = 0 */
    cl_float4 own_lo, own_hi; /* the full grid coordinates this volume samples (volume_sampling.h), w = 0 */
    cl_float4 to_eye;       /* unit vector towards the eye (-forward), for the reflectance map */
    cl_float4 background;   /* image background, w = 0 */
    cl_int width, height;   /* image size in pixels */
    cl_int tf_count;        /* control points of the transfer function */
    cl_int map_n;           /* reflectance map size */
    cl_int shade_on;        /* 1: shade through the reflectance map */
    cl_float step;          /* sample spacing along the ray, world units */
    cl_float ert_alpha;     /* stop once the opacity reaches this (1 or more: off) */
    cl_float threshold;     /* samples with alpha <= this are skipped */
} ClPlanesParams;           /* 288 bytes */

#endif
