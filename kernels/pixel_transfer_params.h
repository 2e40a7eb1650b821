/* kernels/pixel_transfer_params.h — the scalar arguments of kernels/pixel_transfer.cl's kernels
 * (pixel_transfer, draw_pixels, pixel_texture, accum) as one struct each, shared by host
 * (raster/pixel_transfer.cpp) and device, passed by value; buffers (the frame buffer's planes, the
 * lookup tables, the source image, the texels) stay separate arguments. Sizes and offsets are probed on
 * the device by tests/layout_test.cpp. */
#ifndef CLVR_PIXEL_TRANSFER_PARAMS_H
#define CLVR_PIXEL_TRANSFER_PARAMS_H

#include "cl_types.h"
#include "texture.h"

/* DrawPixelsBlend (raster/pixel_transfer.h): result from source s and destination d, factors ONE/ONE. */
#define CLVR_DRAW_REPLACE 0u
#define CLVR_DRAW_ADD 1u
#define CLVR_DRAW_SUBTRACT 2u
#define CLVR_DRAW_REVERSE_SUBTRACT 3u
#define CLVR_DRAW_MIN 4u
#define CLVR_DRAW_MAX 5u

/* AccumOp (raster/pixel_transfer.h), glAccum's ops. */
#define CLVR_ACCUM_ACCUM 0u
#define CLVR_ACCUM_LOAD 1u
#define CLVR_ACCUM_RETURN 2u
#define CLVR_ACCUM_MULT 3u
#define CLVR_ACCUM_ADD 4u

/* The transfer state (raster::PixelTransfer), validated by the host. */
typedef struct {
    cl_float4 matrix_row[4]; /* the color matrix, row by row */
    cl_float4 scale;         /* post-color-matrix scale */
    cl_float4 bias;          /* post-color-matrix bias */
    cl_uint4 lut_n;          /* each channel's lookup-table length (0: no table for that channel) */
    cl_uint4 lut_first;      /* each channel's first entry in the concatenated tables `lut` */
} ClPixelTransfer;           /* 128 bytes */

typedef struct {
    ClPixelTransfer xf;
    cl_uint n;               /* pixels of the frame buffer */
    cl_uint pad0, pad1, pad2;
} ClPixelTransferParams;     /* 144 bytes */

typedef struct {
    ClPixelTransfer xf;
    ClTexture tex;           /* the pixel texture (use_texture; else unread) */
    cl_int dst_width, dst_height; /* destination frame buffer size in pixels */
    cl_int src_width, src_height; /* source image size in pixels */
    cl_int offset_x, offset_y;    /* where the source's top-left pixel lands in dst */
    cl_uint blend;           /* CLVR_DRAW_* */
    cl_uint use_texture;     /* 1: the transferred RGB through the pixel texture */
} ClDrawPixelsParams;        /* 208 bytes */

typedef struct {
    ClTexture tex;           /* the 3D texture the pixels' RGB index */
    cl_uint n;               /* pixels of the frame buffer */
    cl_uint pad0, pad1, pad2;
} ClPixelTextureParams;      /* 64 bytes */

typedef struct {
    cl_uint n;               /* pixels of the frame buffer */
    cl_uint op;              /* CLVR_ACCUM_* */
    cl_float value;
} ClAccumParams;             /* 12 bytes */

#endif
