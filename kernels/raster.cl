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

/* Defined by the fragment program appended after this file. Returns 0 to discard. Always inlined,
 * so that the fragment never goes through memory and unused attributes are never interpolated. */
__attribute__((always_inline)) int clvr_fragment(const ClFragment* f, const ClFragmentResources* r, float4* color);

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

/* GL blend factors (GL 2.1 table 4.2) as linear forms, set up once per work-item so that the
 * per-fragment work has no branches (PoCL if-converts branches when it vectorizes work-items):
 * factor = base + c_src * src + c_dst * dst + c_src_a * src.w + c_dst_a * dst.w + c_sat * sat,
 * sat = min(src.w, 1 - dst.w). Exactly one term besides base is nonzero and the coefficients are
 * 0 or +-1, so the result has the rounding of the direct formula (1 - src is 1 + (-1) * src). */
typedef struct {
    float4 base, c_src, c_dst, c_src_a, c_dst_a, c_sat;
} ClvrBlendFactor;

void clvr_factor_channel(uint f, float4 k, int ch, ClvrBlendFactor* out)
{
    float base = 0.0f, cs = 0.0f, cd = 0.0f, csa = 0.0f, cda = 0.0f, csat = 0.0f;
    const float kc = ch == 0 ? k.x : ch == 1 ? k.y : ch == 2 ? k.z : k.w;
    switch (f) {
    case CLVR_FACTOR_ZERO: break;
    case CLVR_FACTOR_ONE: base = 1.0f; break;
    case CLVR_FACTOR_SRC_COLOR: cs = 1.0f; break;
    case CLVR_FACTOR_ONE_MINUS_SRC_COLOR: base = 1.0f; cs = -1.0f; break;
    case CLVR_FACTOR_DST_COLOR: cd = 1.0f; break;
    case CLVR_FACTOR_ONE_MINUS_DST_COLOR: base = 1.0f; cd = -1.0f; break;
    case CLVR_FACTOR_SRC_ALPHA: csa = 1.0f; break;
    case CLVR_FACTOR_ONE_MINUS_SRC_ALPHA: base = 1.0f; csa = -1.0f; break;
    case CLVR_FACTOR_DST_ALPHA: cda = 1.0f; break;
    case CLVR_FACTOR_ONE_MINUS_DST_ALPHA: base = 1.0f; cda = -1.0f; break;
    case CLVR_FACTOR_CONSTANT_COLOR: base = kc; break;
    case CLVR_FACTOR_ONE_MINUS_CONSTANT_COLOR: base = 1.0f - kc; break;
    case CLVR_FACTOR_CONSTANT_ALPHA: base = k.w; break;
    case CLVR_FACTOR_ONE_MINUS_CONSTANT_ALPHA: base = 1.0f - k.w; break;
    default: /* SRC_ALPHA_SATURATE: (sat, sat, sat, 1) */
        if (ch == 3)
            base = 1.0f;
        else
            csat = 1.0f;
        break;
    }
    switch (ch) {
    case 0: out->base.x = base; out->c_src.x = cs; out->c_dst.x = cd; out->c_src_a.x = csa; out->c_dst_a.x = cda; out->c_sat.x = csat; break;
    case 1: out->base.y = base; out->c_src.y = cs; out->c_dst.y = cd; out->c_src_a.y = csa; out->c_dst_a.y = cda; out->c_sat.y = csat; break;
    case 2: out->base.z = base; out->c_src.z = cs; out->c_dst.z = cd; out->c_src_a.z = csa; out->c_dst_a.z = cda; out->c_sat.z = csat; break;
    default: out->base.w = base; out->c_src.w = cs; out->c_dst.w = cd; out->c_src_a.w = csa; out->c_dst_a.w = cda; out->c_sat.w = csat; break;
    }
}

/* The source or destination factor: rgb from rgb_factor, alpha from alpha_factor. */
ClvrBlendFactor clvr_blend_factor_setup(uint rgb_factor, uint alpha_factor, float4 k)
{
    ClvrBlendFactor f;
    for (int ch = 0; ch < 3; ++ch)
        clvr_factor_channel(rgb_factor, k, ch, &f);
    clvr_factor_channel(alpha_factor, k, 3, &f);
    return f;
}

float4 clvr_blend_factor(const ClvrBlendFactor* f, float4 src, float4 dst)
{
    const float sat = min(src.w, 1.0f - dst.w);
    return f->base + f->c_src * src + f->c_dst * dst + f->c_src_a * src.w + f->c_dst_a * dst.w + f->c_sat * sat;
}

/* GL blend equations as signs per channel: ADD (+1, +1), SUBTRACT (+1, -1), REVERSE_SUBTRACT (-1, +1);
 * MIN and MAX ignore the factors. No clamp: the buffer is float. */
typedef struct {
    ClvrBlendFactor src, dst;
    float4 sign_src, sign_dst;
    int4 use_min, use_max;
} ClvrBlend;

void clvr_equation_channel(uint eq, float* ss, float* sd, int* mn, int* mx)
{
    *ss = eq == CLVR_BLEND_REVERSE_SUBTRACT ? -1.0f : 1.0f;
    *sd = eq == CLVR_BLEND_SUBTRACT ? -1.0f : 1.0f;
    *mn = eq == CLVR_BLEND_MIN ? -1 : 0;
    *mx = eq == CLVR_BLEND_MAX ? -1 : 0;
}

ClvrBlend clvr_blend_setup(const ClBlendState* b)
{
    ClvrBlend r;
    r.src = clvr_blend_factor_setup(b->src_rgb, b->src_alpha, b->color);
    r.dst = clvr_blend_factor_setup(b->dst_rgb, b->dst_alpha, b->color);
    float ss, sd, as, ad;
    int mn, mx, amn, amx;
    clvr_equation_channel(b->rgb_equation, &ss, &sd, &mn, &mx);
    clvr_equation_channel(b->alpha_equation, &as, &ad, &amn, &amx);
    r.sign_src = (float4)(ss, ss, ss, as);
    r.sign_dst = (float4)(sd, sd, sd, ad);
    r.use_min = (int4)(mn, mn, mn, amn);
    r.use_max = (int4)(mx, mx, mx, amx);
    return r;
}

float4 clvr_blend(const ClvrBlend* b, float4 src, float4 dst)
{
    const float4 linear = b->sign_src * (src * clvr_blend_factor(&b->src, src, dst)) +
                          b->sign_dst * (dst * clvr_blend_factor(&b->dst, src, dst));
    return select(select(linear, fmin(src, dst), b->use_min), fmax(src, dst), b->use_max);
}

/* Edge function of edge a -> b at p, all in subpixel units: positive inside a set-up triangle.
 * Exact: coordinates stay below 2^24 in magnitude (guard band), products below 2^50. */
long clvr_edge(int xa, int ya, int xb, int yb, int px, int py)
{
    return (long)(xb - xa) * (long)(py - ya) - (long)(yb - ya) * (long)(px - xa);
}

/* One fragment of triangle t at pixel (px, py) with exact edge values e0..e2, through GL's
 * per-fragment operations against the pixel's color c, depth d and stencil s (kept in registers). */
__attribute__((always_inline)) void clvr_shade(global const ClTriangle* t, long e0, long e1, long e2, int px, int py,
                                               const ClFragmentState* fs, const ClBlendState* bs,
                                               const ClvrBlend* blend, int4 write_mask,
                                               const ClFragmentResources* resources, float4* c, float* d, uint* s)
{
    /* Barycentrics in window space; depth is linear there, attributes perspective-correct:
     * attr = sum(l_i attr_i / w_i) / sum(l_i / w_i). */
    const float l0 = (float)e1 * t->inv_area;
    const float l1 = (float)e2 * t->inv_area;
    const float l2 = (float)e0 * t->inv_area;
    ClFragment f;
    f.window = (float2)((float)px + 0.5f, (float)py + 0.5f);
    f.depth = l0 * t->depth.x + l1 * t->depth.y + l2 * t->depth.z;
    f.front_facing = (int)t->front_facing;
    const float q = 1.0f / (l0 * t->inv_w.x + l1 * t->inv_w.y + l2 * t->inv_w.z);
    for (int k = 0; k < CLVR_MAX_ATTRIBUTES; ++k)
        f.attr[k] = (l0 * t->attr_over_w[0][k] + l1 * t->attr_over_w[1][k] + l2 * t->attr_over_w[2][k]) * q;

    float4 src;
    if (!clvr_fragment(&f, resources, &src))
        return;
    if (fs->alpha_test && !clvr_compare_float(fs->alpha_func, src.w, fs->alpha_ref))
        return;
    if (fs->stencil_test) {
        const uint m = fs->stencil_read_mask;
        if (!clvr_compare_uint(fs->stencil_func, fs->stencil_ref & m, *s & m)) {
            *s = clvr_stencil_op(fs->stencil_sfail, *s, fs->stencil_ref, fs->stencil_write_mask);
            return;
        }
    }
    if (fs->depth_test) {
        if (!clvr_compare_float(fs->depth_func, f.depth, *d)) {
            if (fs->stencil_test)
                *s = clvr_stencil_op(fs->stencil_dpfail, *s, fs->stencil_ref, fs->stencil_write_mask);
            return;
        }
        if (fs->depth_write)
            *d = f.depth;
    }
    if (fs->stencil_test)
        *s = clvr_stencil_op(fs->stencil_dppass, *s, fs->stencil_ref, fs->stencil_write_mask);
    const float4 blended = bs->enabled ? clvr_blend(blend, src, *c) : src;
    *c = select(*c, blended, write_mask);
}

/* One work-item per CLVR_PIXELS_PER_ITEM horizontally adjacent pixels of the viewport rectangle
 * (rect_*, clipped to the frame buffer): independent pixels give the CPU instruction-level
 * parallelism and share each triangle's loads. Tiles of 2^tile_w_log2 x 2^tile_h_log2 pixels (the
 * width a multiple of CLVR_PIXELS_PER_ITEM; the host picks the shape) start at the rectangle's corner,
 * so a work-item's pixels share a tile; tile t lists triangle indices
 * tile_tris[tile_start[tile_base + t] .. tile_start[tile_base + t + 1]) in submission order (one
 * buffer holds the tile lists of every pass of a batch, and one uniforms buffer their uniforms,
 * this pass's from uniform_base). fragment_counts[row] accumulates the
 * covered-pixel count of that rectangle row over launches until the host reads and clears it. Pixels
 * outside a triangle's col/row bounds (which include GL's scissor rectangle) are never its fragments. */
kernel void raster_fragments(global float4* color, global float* depth, global uchar* stencil, const int fb_width,
                             const int rect_x, const int rect_y, const int rect_w, const int rect_h,
                             const int tile_w_log2, const int tile_h_log2, const int tiles_x, const uint tile_base, global const ClTriangle* tris,
                             global const uint* tile_start, global const uint* tile_tris, const ClFragmentState fs,
                             const ClBlendState bs, constant float4* uniforms, const uint uniform_base,
                             global const float* buffer0,
                             global const float* buffer1, global const float* buffer2, global const float* buffer3,
                             global uint* fragment_counts)
{
    CLVR_GUARD_2D((rect_w + CLVR_PIXELS_PER_ITEM - 1) / CLVR_PIXELS_PER_ITEM, rect_h);
    const int gx0 = (int)get_global_id(0) * CLVR_PIXELS_PER_ITEM;
    const int gy = (int)get_global_id(1);
    /* Shifts, not divisions: an integer division per work-item was the launch's largest cost. */
    const uint tile = tile_base + (uint)((gy >> tile_h_log2) * tiles_x + (gx0 >> tile_w_log2));
    const uint begin = tile_start[tile];
    const uint end = tile_start[tile + 1];
    if (begin == end)
        return;

    const int px0 = rect_x + gx0;
    const int py = rect_y + gy;
    const int count = min(CLVR_PIXELS_PER_ITEM, rect_w - gx0);
    const int px1 = px0 + count - 1;  /* last pixel of this work-item */
    const size_t pixel0 = (size_t)py * (size_t)fb_width + (size_t)px0;
    const int sx0 = px0 * CLVR_SUBPIXEL_SCALE + CLVR_SUBPIXEL_SCALE / 2;  /* first pixel center */
    const int sy = py * CLVR_SUBPIXEL_SCALE + CLVR_SUBPIXEL_SCALE / 2;

    ClFragmentResources resources;
    resources.buffer[0] = buffer0;
    resources.buffer[1] = buffer1;
    resources.buffer[2] = buffer2;
    resources.buffer[3] = buffer3;
    resources.uniforms = uniforms + uniform_base;
    const ClvrBlend blend = clvr_blend_setup(&bs);
    const int4 write_mask = (int4)((fs.color_mask & CLVR_MASK_R) ? -1 : 0, (fs.color_mask & CLVR_MASK_G) ? -1 : 0,
                                   (fs.color_mask & CLVR_MASK_B) ? -1 : 0, (fs.color_mask & CLVR_MASK_A) ? -1 : 0);

    float4 c[CLVR_PIXELS_PER_ITEM];
    float d[CLVR_PIXELS_PER_ITEM];
    uint s[CLVR_PIXELS_PER_ITEM];
    uint covered = 0;
#pragma unroll
    for (int p = 0; p < CLVR_PIXELS_PER_ITEM; ++p) {
        const size_t i = pixel0 + (size_t)min(p, count - 1);  /* past the rectangle: a harmless duplicate */
        c[p] = color[i];
        d[p] = depth[i];
        s[p] = stencil[i];
    }

    for (uint i = begin; i < end; ++i) {
        global const ClTriangle* t = tris + tile_tris[i];
        const int col_min = t->col_min, col_max = t->col_max;
        if (py < t->row_min || py > t->row_max || px1 < col_min || px0 > col_max)
            continue;
        /* e0: edge 0->1 (opposite vertex 2), e1: edge 1->2 (opposite 0), e2: edge 2->0 (opposite 1);
         * one pixel to the right adds -(y_b - y_a) * CLVR_SUBPIXEL_SCALE. */
        long e0 = clvr_edge(t->x[0], t->y[0], t->x[1], t->y[1], sx0, sy);
        long e1 = clvr_edge(t->x[1], t->y[1], t->x[2], t->y[2], sx0, sy);
        long e2 = clvr_edge(t->x[2], t->y[2], t->x[0], t->y[0], sx0, sy);
        const long step0 = -(long)(t->y[1] - t->y[0]) * CLVR_SUBPIXEL_SCALE;
        const long step1 = -(long)(t->y[2] - t->y[1]) * CLVR_SUBPIXEL_SCALE;
        const long step2 = -(long)(t->y[0] - t->y[2]) * CLVR_SUBPIXEL_SCALE;
#pragma unroll
        for (int p = 0; p < CLVR_PIXELS_PER_ITEM; ++p) {
            /* Top-left rule: a pixel center on an edge belongs to the triangle only for a top or left
             * edge. col_max is inside the rectangle, so p < count holds for every pixel that passes. */
            if (px0 + p >= col_min && px0 + p <= col_max && e0 + t->bias[0] >= 0 && e1 + t->bias[1] >= 0 &&
                e2 + t->bias[2] >= 0) {
                ++covered;
                clvr_shade(t, e0, e1, e2, px0 + p, py, &fs, &bs, &blend, write_mask, &resources, &c[p], &d[p], &s[p]);
            }
            e0 += step0;
            e1 += step1;
            e2 += step2;
        }
    }

    if (covered) {
#pragma unroll
        for (int p = 0; p < CLVR_PIXELS_PER_ITEM; ++p) {
            if (p < count) {
                color[pixel0 + p] = c[p];
                depth[pixel0 + p] = d[p];
                stencil[pixel0 + p] = (uchar)s[p];
            }
        }
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
    CLVR_PROBE_OFFSET(19, ClTriangle, col_min);
    CLVR_PROBE_OFFSET(20, ClTriangle, row_max);
}
