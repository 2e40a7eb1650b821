// kernels/raster.cl — the ordered fragment stage (DESIGN.md, raster stage; rules in docs/raster.md).
// The host has clipped, set up and binned the triangles; here one work-item owns one pixel, walks
// its tile's triangle list in submission order and applies GL's per-fragment operations.
#include "clvr_common.h"
#include "raster_state.h"
#include "texture.h"

typedef struct {
    float2 window;     /* pixel center (x + 0.5, row + 0.5), row 0 at the top */
    float depth;       /* window depth */
    int front_facing;  /* 1 front, 0 back */
    float4 attr[CLVR_MAX_ATTRIBUTES];
} ClFragment;

typedef struct {
    global const float* buffer[4];
    constant float4* uniforms;
} ClFragmentResources;

/* Defined by the fragment program appended after this file. Returns 0 to discard. */
int clvr_fragment(const ClFragment* f, const ClFragmentResources* r, float4* color);

int clvr_compare_float(uint func, float a, float b)
{
    switch (func) {
    case CLVR_FUNC_NEVER: return 0;
    case CLVR_FUNC_LESS: return a < b;
    case CLVR_FUNC_EQUAL: return a == b;
    case CLVR_FUNC_LEQUAL: return a <= b;
    case CLVR_FUNC_GREATER: return a > b;
    case CLVR_FUNC_NOTEQUAL: return a != b;
    case CLVR_FUNC_GEQUAL: return a >= b;
    default: return 1;
    }
}

int clvr_compare_uint(uint func, uint a, uint b)
{
    switch (func) {
    case CLVR_FUNC_NEVER: return 0;
    case CLVR_FUNC_LESS: return a < b;
    case CLVR_FUNC_EQUAL: return a == b;
    case CLVR_FUNC_LEQUAL: return a <= b;
    case CLVR_FUNC_GREATER: return a > b;
    case CLVR_FUNC_NOTEQUAL: return a != b;
    case CLVR_FUNC_GEQUAL: return a >= b;
    default: return 1;
    }
}

/* glStencilOp on an 8-bit value s, then glStencilMask: only write_mask bits change. */
uint clvr_stencil_op(uint op, uint s, uint ref, uint write_mask)
{
    uint v;
    switch (op) {
    case CLVR_STENCIL_ZERO: v = 0u; break;
    case CLVR_STENCIL_REPLACE: v = ref; break;
    case CLVR_STENCIL_INCR: v = min(s + 1u, 255u); break;
    case CLVR_STENCIL_INCR_WRAP: v = (s + 1u) & 255u; break;
    case CLVR_STENCIL_DECR: v = s > 0u ? s - 1u : 0u; break;
    case CLVR_STENCIL_DECR_WRAP: v = (s - 1u) & 255u; break;
    case CLVR_STENCIL_INVERT: v = ~s & 255u; break;
    default: v = s; break;
    }
    return ((s & ~write_mask) | (v & write_mask)) & 255u;
}

/* GL blend factor (GL 2.1 table 4.2) for all four channels; rgb uses .xyz, alpha uses .w. */
float4 clvr_blend_factor(uint f, float4 src, float4 dst, float4 k)
{
    switch (f) {
    case CLVR_FACTOR_ZERO: return (float4)(0.0f);
    case CLVR_FACTOR_ONE: return (float4)(1.0f);
    case CLVR_FACTOR_SRC_COLOR: return src;
    case CLVR_FACTOR_ONE_MINUS_SRC_COLOR: return 1.0f - src;
    case CLVR_FACTOR_DST_COLOR: return dst;
    case CLVR_FACTOR_ONE_MINUS_DST_COLOR: return 1.0f - dst;
    case CLVR_FACTOR_SRC_ALPHA: return (float4)(src.w);
    case CLVR_FACTOR_ONE_MINUS_SRC_ALPHA: return (float4)(1.0f - src.w);
    case CLVR_FACTOR_DST_ALPHA: return (float4)(dst.w);
    case CLVR_FACTOR_ONE_MINUS_DST_ALPHA: return (float4)(1.0f - dst.w);
    case CLVR_FACTOR_CONSTANT_COLOR: return k;
    case CLVR_FACTOR_ONE_MINUS_CONSTANT_COLOR: return 1.0f - k;
    case CLVR_FACTOR_CONSTANT_ALPHA: return (float4)(k.w);
    case CLVR_FACTOR_ONE_MINUS_CONSTANT_ALPHA: return (float4)(1.0f - k.w);
    default: { /* SRC_ALPHA_SATURATE */
        const float f_sat = min(src.w, 1.0f - dst.w);
        return (float4)(f_sat, f_sat, f_sat, 1.0f);
    }
    }
}

/* GL blend equation per channel; MIN and MAX ignore the factors. No clamp: the buffer is float. */
float4 clvr_blend_equation(uint eq, float4 s, float4 sf, float4 d, float4 df)
{
    switch (eq) {
    case CLVR_BLEND_SUBTRACT: return s * sf - d * df;
    case CLVR_BLEND_REVERSE_SUBTRACT: return d * df - s * sf;
    case CLVR_BLEND_MIN: return fmin(s, d);
    case CLVR_BLEND_MAX: return fmax(s, d);
    default: return s * sf + d * df;
    }
}

float4 clvr_blend(const ClBlendState* b, float4 src, float4 dst)
{
    const float4 rgb = clvr_blend_equation(b->rgb_equation, src, clvr_blend_factor(b->src_rgb, src, dst, b->color),
                                           dst, clvr_blend_factor(b->dst_rgb, src, dst, b->color));
    const float4 a = clvr_blend_equation(b->alpha_equation, src, clvr_blend_factor(b->src_alpha, src, dst, b->color),
                                         dst, clvr_blend_factor(b->dst_alpha, src, dst, b->color));
    return (float4)(rgb.xyz, a.w);
}

/* Edge function of edge a -> b at p, all in subpixel units: positive inside a set-up triangle.
 * Exact: coordinates stay below 2^24 in magnitude (guard band), products below 2^50. */
long clvr_edge(int xa, int ya, int xb, int yb, int px, int py)
{
    return (long)(xb - xa) * (long)(py - ya) - (long)(yb - ya) * (long)(px - xa);
}

/* One work-item per pixel of the viewport rectangle (rect_*, clipped to the frame buffer). Tiles of
 * CLVR_TILE_SIZE pixels start at the rectangle's corner; tile t lists triangle indices
 * tile_tris[tile_start[t] .. tile_start[t+1]) in submission order. fragment_counts[row] receives
 * the covered-pixel count of that rectangle row. */
kernel void raster_fragments(global float4* color, global float* depth, global uchar* stencil, const int fb_width,
                             const int rect_x, const int rect_y, const int rect_w, const int rect_h,
                             const int tiles_x, global const ClTriangle* tris, global const uint* tile_start,
                             global const uint* tile_tris, const ClFragmentState fs, const ClBlendState bs,
                             constant float4* uniforms, global const float* buffer0, global const float* buffer1,
                             global const float* buffer2, global const float* buffer3,
                             global uint* fragment_counts)
{
    CLVR_GUARD_2D(rect_w, rect_h);
    const int gx = (int)get_global_id(0);
    const int gy = (int)get_global_id(1);
    const int tile = (gy / CLVR_TILE_SIZE) * tiles_x + gx / CLVR_TILE_SIZE;
    const uint begin = tile_start[tile];
    const uint end = tile_start[tile + 1];
    if (begin == end)
        return;

    const int px = rect_x + gx;
    const int py = rect_y + gy;
    const size_t pixel = (size_t)py * (size_t)fb_width + (size_t)px;
    const int sx = px * CLVR_SUBPIXEL_SCALE + CLVR_SUBPIXEL_SCALE / 2;  /* pixel center */
    const int sy = py * CLVR_SUBPIXEL_SCALE + CLVR_SUBPIXEL_SCALE / 2;

    ClFragmentResources resources;
    resources.buffer[0] = buffer0;
    resources.buffer[1] = buffer1;
    resources.buffer[2] = buffer2;
    resources.buffer[3] = buffer3;
    resources.uniforms = uniforms;

    float4 c = color[pixel];
    float d = depth[pixel];
    uint s = stencil[pixel];
    uint covered = 0;

    for (uint i = begin; i < end; ++i) {
        global const ClTriangle* t = tris + tile_tris[i];
        /* e0: edge 0->1 (opposite vertex 2), e1: edge 1->2 (opposite 0), e2: edge 2->0 (opposite 1). */
        const long e0 = clvr_edge(t->x[0], t->y[0], t->x[1], t->y[1], sx, sy);
        const long e1 = clvr_edge(t->x[1], t->y[1], t->x[2], t->y[2], sx, sy);
        const long e2 = clvr_edge(t->x[2], t->y[2], t->x[0], t->y[0], sx, sy);
        /* Top-left rule: a pixel center on an edge belongs to the triangle only for a top or left edge. */
        if (e0 + t->bias[0] < 0 || e1 + t->bias[1] < 0 || e2 + t->bias[2] < 0)
            continue;
        ++covered;

        /* Barycentrics in window space; depth is linear there, attributes perspective-correct. */
        const float l0 = (float)e1 * t->inv_area;
        const float l1 = (float)e2 * t->inv_area;
        const float l2 = (float)e0 * t->inv_area;
        ClFragment f;
        f.window = (float2)((float)px + 0.5f, (float)py + 0.5f);
        f.depth = l0 * t->depth.x + l1 * t->depth.y + l2 * t->depth.z;
        f.front_facing = (int)t->front_facing;
        /* attr = sum(l_i attr_i / w_i) / sum(l_i / w_i) */
        const float q = 1.0f / (l0 * t->inv_w.x + l1 * t->inv_w.y + l2 * t->inv_w.z);
        for (int k = 0; k < CLVR_MAX_ATTRIBUTES; ++k)
            f.attr[k] = (l0 * t->attr_over_w[0][k] + l1 * t->attr_over_w[1][k] + l2 * t->attr_over_w[2][k]) * q;

        float4 src;
        if (!clvr_fragment(&f, &resources, &src))
            continue;
        if (fs.alpha_test && !clvr_compare_float(fs.alpha_func, src.w, fs.alpha_ref))
            continue;
        if (fs.stencil_test) {
            const uint m = fs.stencil_read_mask;
            if (!clvr_compare_uint(fs.stencil_func, fs.stencil_ref & m, s & m)) {
                s = clvr_stencil_op(fs.stencil_sfail, s, fs.stencil_ref, fs.stencil_write_mask);
                continue;
            }
        }
        if (fs.depth_test) {
            if (!clvr_compare_float(fs.depth_func, f.depth, d)) {
                if (fs.stencil_test)
                    s = clvr_stencil_op(fs.stencil_dpfail, s, fs.stencil_ref, fs.stencil_write_mask);
                continue;
            }
            if (fs.depth_write)
                d = f.depth;
        }
        if (fs.stencil_test)
            s = clvr_stencil_op(fs.stencil_dppass, s, fs.stencil_ref, fs.stencil_write_mask);
        const float4 blended = bs.enabled ? clvr_blend(&bs, src, c) : src;
        c = (float4)((fs.color_mask & CLVR_MASK_R) ? blended.x : c.x, (fs.color_mask & CLVR_MASK_G) ? blended.y : c.y,
                     (fs.color_mask & CLVR_MASK_B) ? blended.z : c.z, (fs.color_mask & CLVR_MASK_A) ? blended.w : c.w);
    }

    if (covered) {
        color[pixel] = c;
        depth[pixel] = d;
        stencil[pixel] = (uchar)s;
        atomic_add(fragment_counts + gy, covered);
    }
}

#define CLVR_PROBE_SIZE(i, T) out[i] = (uint)sizeof(T)
#define CLVR_PROBE_OFFSET(i, T, m) out[i] = (uint)__builtin_offsetof(T, m)

/* Sizes and offsets of the shared layouts as this device compiles them (tests/layout_test.cpp). */
kernel void raster_layout_probe(global uint* out)
{
    if (get_global_id(0) != 0)
        return;
    CLVR_PROBE_SIZE(0, ClFragmentState);
    CLVR_PROBE_OFFSET(1, ClFragmentState, stencil_test);
    CLVR_PROBE_OFFSET(2, ClFragmentState, stencil_dppass);
    CLVR_PROBE_OFFSET(3, ClFragmentState, alpha_ref);
    CLVR_PROBE_OFFSET(4, ClFragmentState, color_mask);
    CLVR_PROBE_SIZE(5, ClBlendState);
    CLVR_PROBE_OFFSET(6, ClBlendState, color);
    CLVR_PROBE_OFFSET(7, ClBlendState, enabled);
    CLVR_PROBE_OFFSET(8, ClBlendState, dst_alpha);
    CLVR_PROBE_SIZE(9, ClTriangle);
    CLVR_PROBE_OFFSET(10, ClTriangle, y);
    CLVR_PROBE_OFFSET(11, ClTriangle, bias);
    CLVR_PROBE_OFFSET(12, ClTriangle, front_facing);
    CLVR_PROBE_OFFSET(13, ClTriangle, inv_area);
    CLVR_PROBE_OFFSET(14, ClTriangle, depth);
    CLVR_PROBE_OFFSET(15, ClTriangle, inv_w);
    CLVR_PROBE_OFFSET(16, ClTriangle, attr_over_w);
    CLVR_PROBE_SIZE(17, ClTexture);
    CLVR_PROBE_OFFSET(18, ClTexture, border);
}
