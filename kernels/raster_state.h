/* kernels/raster_state.h — the raster stage's host/device layouts (DESIGN.md, raster stage).
 * Compiled as OpenCL C and as C++ (raster/fragment_state.h, raster/rasterizer.cpp). Layout only.
 * No bool, size_t or float3: their size differs between host and device (float3 is 16 bytes in
 * OpenCL, 12 in glm::vec3). Sizes and offsets are probed on the device by tests/layout_test.cpp. */
#ifndef CLVR_RASTER_STATE_H
#define CLVR_RASTER_STATE_H

#include "cl_types.h"  /* cl_uint, cl_float4, ... on both sides */

#define CLVR_MAX_ATTRIBUTES 4
#define CLVR_MAX_UNIFORMS 64
/* Window coordinates are snapped to 1/CLVR_SUBPIXEL_SCALE pixel (8 fractional bits), so that
 * coverage is decided by exact integer edge functions on the host, the device and the reference. */
#define CLVR_SUBPIXEL_BITS 8
#define CLVR_SUBPIXEL_SCALE 256
/* Triangles are binned to screen tiles of at most CLVR_TILE_SIZE x CLVR_TILE_SIZE pixels, and a
 * work-item (an "item") shades at most a tile's pixels; the host picks both shapes per device
 * (raster/rasterizer.h, RasterShape). */
#define CLVR_TILE_SIZE 16

/* CompareFunc, StencilOp, BlendEquation and BlendFactor values: the host's enum classes. */
#define CLVR_FUNC_NEVER 0u
#define CLVR_FUNC_LESS 1u
#define CLVR_FUNC_EQUAL 2u
#define CLVR_FUNC_LEQUAL 3u
#define CLVR_FUNC_GREATER 4u
#define CLVR_FUNC_NOTEQUAL 5u
#define CLVR_FUNC_GEQUAL 6u
#define CLVR_FUNC_ALWAYS 7u

#define CLVR_STENCIL_KEEP 0u
#define CLVR_STENCIL_ZERO 1u
#define CLVR_STENCIL_REPLACE 2u
#define CLVR_STENCIL_INCR 3u
#define CLVR_STENCIL_INCR_WRAP 4u
#define CLVR_STENCIL_DECR 5u
#define CLVR_STENCIL_DECR_WRAP 6u
#define CLVR_STENCIL_INVERT 7u

#define CLVR_BLEND_ADD 0u
#define CLVR_BLEND_SUBTRACT 1u
#define CLVR_BLEND_REVERSE_SUBTRACT 2u
#define CLVR_BLEND_MIN 3u
#define CLVR_BLEND_MAX 4u

#define CLVR_FACTOR_ZERO 0u
#define CLVR_FACTOR_ONE 1u
#define CLVR_FACTOR_SRC_COLOR 2u
#define CLVR_FACTOR_ONE_MINUS_SRC_COLOR 3u
#define CLVR_FACTOR_DST_COLOR 4u
#define CLVR_FACTOR_ONE_MINUS_DST_COLOR 5u
#define CLVR_FACTOR_SRC_ALPHA 6u
#define CLVR_FACTOR_ONE_MINUS_SRC_ALPHA 7u
#define CLVR_FACTOR_DST_ALPHA 8u
#define CLVR_FACTOR_ONE_MINUS_DST_ALPHA 9u
#define CLVR_FACTOR_CONSTANT_COLOR 10u
#define CLVR_FACTOR_ONE_MINUS_CONSTANT_COLOR 11u
#define CLVR_FACTOR_CONSTANT_ALPHA 12u
#define CLVR_FACTOR_ONE_MINUS_CONSTANT_ALPHA 13u
#define CLVR_FACTOR_SRC_ALPHA_SATURATE 14u

/* color_mask bits */
#define CLVR_MASK_R 1u
#define CLVR_MASK_G 2u
#define CLVR_MASK_B 4u
#define CLVR_MASK_A 8u

typedef struct {
    cl_uint depth_test, depth_func, depth_write; /* CompareFunc as cl_uint */
    cl_uint stencil_test, stencil_func, stencil_ref, stencil_read_mask, stencil_write_mask;
    cl_uint stencil_sfail, stencil_dpfail, stencil_dppass; /* StencilOp as cl_uint */
    cl_uint alpha_test, alpha_func;
    cl_float alpha_ref;
    cl_uint color_mask; /* CLVR_MASK_* bits */
    cl_uint pad0;       /* blend state travels in its own ClBlendState */
} ClFragmentState;      /* 64 bytes */

typedef struct {
    cl_float4 color; /* GL_BLEND_COLOR */
    cl_uint enabled, rgb_equation, alpha_equation;
    cl_uint src_rgb, dst_rgb, src_alpha, dst_alpha; /* BlendFactor as cl_uint */
    cl_uint pad0;
} ClBlendState; /* 48 bytes */

/* One set-up triangle after clipping, projection, viewport transform and snapping. Vertices are
 * ordered so that the edge functions are positive inside (clockwise on the row-down screen). In the
 * triangle buffer each one is followed by its pass's attributes: for attribute k = 0 .. n-1 (n: the
 * fragment program's attribute count), attribute / clip w at vertices 0, 1, 2 as three float4, so a
 * record is CLVR_TRIANGLE_FLOAT4S(n) float4s long. */
typedef struct {
    cl_int x[3], y[3];  /* window position in 1/CLVR_SUBPIXEL_SCALE pixels, row-down */
    cl_int bias[3];     /* fill rule: 0 for a top or left edge (i -> i+1), -1 otherwise */
    cl_uint front_facing;
    cl_float inv_area;  /* 1 / twice the area, in subpixel units squared */
    /* Pixels whose centers can be covered, clipped to the draw's viewport and scissor rectangle (ends
     * inclusive): a work-item skips the triangle outside them, and no pixel outside is ever visited. */
    cl_int col_min, col_max, row_min, row_max;
    cl_uint pad0;
    cl_float4 depth;    /* window depth of vertices 0..2 in .x .y .z */
    cl_float4 inv_w;    /* 1 / clip w of vertices 0..2 in .x .y .z */
} ClTriangle; /* 96 bytes = 6 float4 */

#define CLVR_TRIANGLE_FLOAT4S(n) (6 + 3 * (n))

/* One fragment launch (a pass: consecutive draws sharing program and state) over the viewport
 * rectangle rect_* (clipped to the frame buffer). Tiles of 2^tile_w_log2 x 2^tile_h_log2 pixels and
 * items of 2^item_w_log2 x 2^item_h_log2 pixels (one work-item each, inside one tile) start at the
 * rectangle's corner; tile t of the pass lists its triangles in tile_start[tile_base + t] ..
 * tile_start[tile_base + t + 1] of the submission's tile lists, and this launch walks the entries
 * list_first .. list_first + list_count - 1 of each list (the whole list unless the device caps loop
 * iterations: RasterShape::listChunk). */
typedef struct {
    cl_int fb_width;
    cl_int rect_x, rect_y, rect_w, rect_h;
    cl_int tile_w_log2, tile_h_log2, tiles_x;
    cl_int item_w_log2, item_h_log2;
    cl_uint tile_base;      /* the pass's first tile in tile_start */
    cl_uint uniform_base;   /* the pass's first uniform in the submission's uniforms */
    cl_ulong triangle_base; /* float4 offset of the pass's triangle 0 in the triangle buffer */
    cl_uint list_first, list_count;
    ClFragmentState fragment;
    ClBlendState blend;
} ClRasterPass; /* 176 bytes */

#endif
