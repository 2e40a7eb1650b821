/* kernels/stack2d_params.h — the uniforms of kernels/stack2d.cl's fragment program as one struct (float4
 * fields only, read through r->uniforms; the host copies it through host/render/fragment_uniforms.h;
 * fields of a mode that is off stay 0), and the scalar arguments of the iso-surface mode's last pass
 * stack2d_iso_finish and of the fused path stack2d_fused as two more (passed by value; buffers stay
 * separate arguments), shared by host
 * (host/render/grid/stack2d.cpp) and device. Sizes and offsets are probed on the device by
 * tests/layout_test.cpp. */
#ifndef CLVR_STACK2D_PARAMS_H
#define CLVR_STACK2D_PARAMS_H

#include "cl_types.h"
#include "ray.h"
#include "texture.h"

typedef struct {
    ClCamera camera;
    cl_float4 frame;       /* (image width, height, tf_count, 0) */
    cl_float4 axis;        /* the stack axis as a unit vector */
    cl_float4 slice_tex;   /* (texture width, height, channels, 0) of one slice */
    cl_float4 shading;     /* (reflectance map n, 1 if shaded, 0, 0) */
    cl_float4 to_eye;      /* unit vector towards the eye (-forward) */
    /* iso-surfaces only */
    cl_float4 iso;         /* (data minimum, 1 if iso-surface, ambient, diffuse) */
    cl_float4 surface;     /* (surface color, 1 if gradient-shaded) */
    cl_float4 light;       /* (unit vector towards the light, 1 / data range) */
    /* several slices per polygon only */
    cl_float4 axis_b, axis_c; /* unit vectors along the slice's texture axes b and c */
    cl_float4 box;         /* (min b, min c, max b, max c), world */
    cl_float4 uv_box;      /* (u, v at the box min, u, v at the box max) */
    cl_float4 alpha_ref;   /* (the alpha test's reference, 0, 0, 0) */
    /* clip textures only */
    cl_float4 clip_tex;    /* (width, height, depth, 1 if inverse) */
    cl_float4 clip_row[3]; /* rows of world -> clip-texture coordinates */
    cl_float4 clip_offset; /* (offset of the texels in buffer[3], in floats, 0, 0, 0) */
} ClStack2dUniforms;       /* 368 bytes */

typedef struct {
    cl_float4 background;  /* image background, w = 0 */
    cl_int count;          /* pixels */
    cl_int pad0, pad1, pad2;
} ClStack2dIsoFinishParams; /* 32 bytes */

/* The fused path (kernels/stack2d.cl's stack2d_fused): each pixel's ray steps through the drawn stack's
 * planes in its own work-item. Stack grid coordinates q = (b, c, axis) index the stack as a volume of
 * dims (n_b, n_c, n_axis) (slices one after another, b fastest); plane j lies at q.z = j * plane_step. */
typedef struct {
    ClCamera camera;       /* 80 bytes */
    cl_float4 to_stack[3]; /* rows of world -> stack grid coordinates: q_i = dot(to_stack[i].xyz, p) + to_stack[i].w */
    cl_float4 to_eye;      /* unit vector towards the eye (-forward): shading and iso-surfaces */
    cl_float4 background;  /* image background, w = 0 */
    cl_float4 iso;         /* iso-surfaces: as ClStack2dUniforms (data minimum, 1, ambient, diffuse) */
    cl_float4 surface;     /* iso-surfaces: (surface color, 1 if gradient-shaded) */
    cl_float4 light;       /* iso-surfaces: (unit vector towards the light, 1 / data range) */
    cl_float4 clip_row[3]; /* clip textures: rows of world -> clip-texture coordinates */
    ClTexture clip_tex;    /* clip textures: the second texture (CLVR_STACK2D_CLIP_TEXTURE builds) */
    cl_int4 dims;          /* stack grid points (n_b, n_c, n_axis), w = 0 */
    cl_int4 bricks;        /* empty-space skipping (kernels/empty_space.h) over the stack grid: bricks per
                            * axis, w = 1 to skip */
    cl_int width, height;  /* image size in pixels */
    cl_int tf_count;       /* control points of the transfer function */
    cl_int planes;         /* (n_axis - 1)(intermediate + 1) + 1 */
    cl_float plane_step;   /* 1 / (intermediate + 1): grid units between planes */
    cl_float ert_alpha;    /* stop once the opacity reaches this (2: off) */
    cl_float alpha_ref;    /* iso-surfaces: a sample is inside when its mapped value is >= this (inf: never) */
    cl_int mode;           /* 0 plain, 1 shaded (4-channel stack, reflectance map), 2 iso-surface */
    cl_int map_n;          /* shaded: n of the reflectance map */
    cl_int clip_inverse;   /* clip textures: 1 keeps the outside */
    cl_int pad0, pad1;
} ClStack2dFusedParams;    /* 384 bytes */

#endif
