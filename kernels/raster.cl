// kernels/raster.cl — the ordered fragment stage (DESIGN.md, raster stage; rules in docs/raster.md).
// The host has clipped, set up and binned the triangles; here one work-item owns a rectangle of pixels,
// walks its tile's triangle list in submission order and applies GL's per-fragment operations.
#include "clvr_common.h"
#include "raster_state.h"
#include "texture.h"

/* Attributes the fragment program reads (FragmentProgram::attributes; the rest are zero) and the most
 * pixels of an item (RasterShape): build options of each compiled fragment program. */
#ifndef CLVR_ATTRIBUTES
#define CLVR_ATTRIBUTES CLVR_MAX_ATTRIBUTES
#endif
#ifndef CLVR_ITEM_PIXELS
#define CLVR_ITEM_PIXELS (CLVR_TILE_SIZE * CLVR_TILE_SIZE)
#endif

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
 * per-fragment operations against the pixel's color c, depth d and stencil s (the item's private copy). */
__attribute__((always_inline)) void clvr_shade(global const ClTriangle* t, global const float4* attr_over_w,
                                               long e0, long e1, long e2, int px, int py,
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
#pragma unroll
    for (int k = 0; k < CLVR_MAX_ATTRIBUTES; ++k)
        f.attr[k] = k < CLVR_ATTRIBUTES ? (l0 * attr_over_w[3 * k] + l1 * attr_over_w[3 * k + 1] + l2 * attr_over_w[3 * k + 2]) * q
                                        : (float4)(0.0f);

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

/* Triangle records are fetched this many tile-list entries ahead: tile lists jump through the
 * triangle buffer, so without it every entry waits for memory. */
#define CLVR_PREFETCH_AHEAD 8
/* (CLVR_PREFETCH, kernels/clvr_common.h: on x86 the record's first two cache lines, header and attribute 0) */

/* One work-item per item of the pass (ClRasterPass). The item walks its tile's list once, in
 * submission order, and for each triangle the pixels of the triangle's col/row bounds (which include
 * GL's scissor rectangle) inside the item, row by row; so every pixel sees its fragments in submission
 * order and no other work-item touches it. The item's pixels stay in private memory meanwhile (on a
 * CPU an item is a whole tile: a tile list is walked once and its pixels read and written once; on a
 * GPU an item is a pixel). fragment_counts[item row] accumulates the covered-pixel count of that row
 * of items over launches until the host reads and clears it. */
kernel void raster_fragments(global float4* color, global float* depth, global uchar* stencil, const ClRasterPass pass,
                             global const float4* triangles, global const uint* tile_start,
                             global const uint* tile_tris, constant float4* uniforms, global const float* buffer0,
                             global const float* buffer1, global const float* buffer2, global const float* buffer3,
                             global uint* fragment_counts)
{
    const int item_w = 1 << pass.item_w_log2, item_h = 1 << pass.item_h_log2;
    CLVR_GUARD_2D((pass.rect_w + item_w - 1) >> pass.item_w_log2, (pass.rect_h + item_h - 1) >> pass.item_h_log2);
    const int gx0 = (int)get_global_id(0) << pass.item_w_log2;  /* the item's corner in the rectangle */
    const int gy0 = (int)get_global_id(1) << pass.item_h_log2;
    /* Shifts, not divisions: an integer division per work-item was once the launch's largest cost. */
    const uint tile = pass.tile_base + (uint)((gy0 >> pass.tile_h_log2) * pass.tiles_x + (gx0 >> pass.tile_w_log2));
    const uint list_start = tile_start[tile], list_length = tile_start[tile + 1] - list_start;
    const uint skipped = min(pass.list_first, list_length);
    const uint begin = list_start + skipped;
    const uint end = begin + min(pass.list_count, list_length - skipped);
    if (begin == end)
        return;

    /* The item's pixels, ends inclusive, and its private copy of them (row-major, w per row): a row is
     * read when a triangle first reaches it (bit py - y0 of `loaded`) and written back at the end, so
     * a sparse draw moves only the rows it touches. */
    const int x0 = pass.rect_x + gx0, x1 = min(x0 + item_w, pass.rect_x + pass.rect_w) - 1;
    const int y0 = pass.rect_y + gy0, y1 = min(y0 + item_h, pass.rect_y + pass.rect_h) - 1;
    const int w = x1 - x0 + 1;
    float4 c[CLVR_ITEM_PIXELS];
    float d[CLVR_ITEM_PIXELS];
    uint s[CLVR_ITEM_PIXELS];
    uint loaded = 0u;

    ClFragmentResources resources;
    resources.buffer[0] = buffer0;
    resources.buffer[1] = buffer1;
    resources.buffer[2] = buffer2;
    resources.buffer[3] = buffer3;
    resources.uniforms = uniforms + pass.uniform_base;
    const ClFragmentState fs = pass.fragment;
    const ClBlendState bs = pass.blend;
    const ClvrBlend blend = clvr_blend_setup(&bs);
    const int4 write_mask = (int4)((fs.color_mask & CLVR_MASK_R) ? -1 : 0, (fs.color_mask & CLVR_MASK_G) ? -1 : 0,
                                   (fs.color_mask & CLVR_MASK_B) ? -1 : 0, (fs.color_mask & CLVR_MASK_A) ? -1 : 0);
    global const float4* pass_triangles = triangles + pass.triangle_base;
    const size_t stride = CLVR_TRIANGLE_FLOAT4S(CLVR_ATTRIBUTES);

    uint covered = 0;
    for (uint i = begin; i < end; ++i) {
        if (i + CLVR_PREFETCH_AHEAD < end)
            CLVR_PREFETCH(pass_triangles + tile_tris[i + CLVR_PREFETCH_AHEAD] * stride, stride);
        global const float4* record = pass_triangles + tile_tris[i] * stride;
        global const ClTriangle* t = (global const ClTriangle*)record;
        const int cx0 = max(t->col_min, x0), cx1 = min(t->col_max, x1);
        const int cy0 = max(t->row_min, y0), cy1 = min(t->row_max, y1);
        if (cx0 > cx1 || cy0 > cy1)
            continue;
        /* Edge values with the fill-rule bias at the first pixel center (e0: edge 0->1, opposite vertex 2;
         * e1: edge 1->2, opposite 0; e2: edge 2->0, opposite 1); one pixel right adds -(y_b - y_a) *
         * CLVR_SUBPIXEL_SCALE, one row down (x_b - x_a) * CLVR_SUBPIXEL_SCALE. Exact, so every pixel gets
         * the values it would get on its own. Top-left rule: a center on an edge is inside (>= 0 with
         * the bias) only for a top or left edge. */
        const int sx = cx0 * CLVR_SUBPIXEL_SCALE + CLVR_SUBPIXEL_SCALE / 2;
        const int sy = cy0 * CLVR_SUBPIXEL_SCALE + CLVR_SUBPIXEL_SCALE / 2;
        const long b0 = t->bias[0], b1 = t->bias[1], b2 = t->bias[2];
        long r0 = clvr_edge(t->x[0], t->y[0], t->x[1], t->y[1], sx, sy) + b0;
        long r1 = clvr_edge(t->x[1], t->y[1], t->x[2], t->y[2], sx, sy) + b1;
        long r2 = clvr_edge(t->x[2], t->y[2], t->x[0], t->y[0], sx, sy) + b2;
        const long dx0 = -(long)(t->y[1] - t->y[0]) * CLVR_SUBPIXEL_SCALE;
        const long dx1 = -(long)(t->y[2] - t->y[1]) * CLVR_SUBPIXEL_SCALE;
        const long dx2 = -(long)(t->y[0] - t->y[2]) * CLVR_SUBPIXEL_SCALE;
        const long dy0 = (long)(t->x[1] - t->x[0]) * CLVR_SUBPIXEL_SCALE;
        const long dy1 = (long)(t->x[2] - t->x[1]) * CLVR_SUBPIXEL_SCALE;
        const long dy2 = (long)(t->x[0] - t->x[2]) * CLVR_SUBPIXEL_SCALE;
        for (int py = cy0; py <= cy1; ++py) {
            const uint row = 1u << (py - y0);
            if (!(loaded & row)) {
                loaded |= row;
                const size_t i0 = (size_t)py * (size_t)pass.fb_width + (size_t)x0;
                for (int k = 0, l = (py - y0) * w; k < w; ++k, ++l) {
                    c[l] = color[i0 + k];
                    d[l] = depth[i0 + k];
                    s[l] = stencil[i0 + k];
                }
            }
            long e0 = r0, e1 = r1, e2 = r2;
            for (int px = cx0, l = (py - y0) * w + (cx0 - x0); px <= cx1; ++px, ++l) {
                if (e0 >= 0 && e1 >= 0 && e2 >= 0) {
                    ++covered;
                    clvr_shade(t, record + 6, e0 - b0, e1 - b1, e2 - b2, px, py, &fs, &bs, &blend, write_mask,
                               &resources, &c[l], &d[l], &s[l]);
                }
                e0 += dx0;
                e1 += dx1;
                e2 += dx2;
            }
            r0 += dy0;
            r1 += dy1;
            r2 += dy2;
        }
    }

    for (int py = y0; py <= y1; ++py)
        if (loaded & (1u << (py - y0))) {
            const size_t i0 = (size_t)py * (size_t)pass.fb_width + (size_t)x0;
            for (int k = 0, l = (py - y0) * w; k < w; ++k, ++l) {
                color[i0 + k] = c[l];
                depth[i0 + k] = d[l];
                stencil[i0 + k] = (uchar)s[l];
            }
        }
    if (covered)
        atomic_add(fragment_counts + get_global_id(1), covered);
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
    CLVR_PROBE_SIZE(16, ClRasterPass);
    CLVR_PROBE_SIZE(17, ClTexture);
    CLVR_PROBE_OFFSET(18, ClTexture, border);
    CLVR_PROBE_OFFSET(19, ClTriangle, col_min);
    CLVR_PROBE_OFFSET(20, ClTriangle, row_max);
    CLVR_PROBE_OFFSET(21, ClRasterPass, triangle_base);
    CLVR_PROBE_OFFSET(22, ClRasterPass, fragment);
    CLVR_PROBE_OFFSET(23, ClRasterPass, blend);
    CLVR_PROBE_OFFSET(24, ClRasterPass, item_h_log2);
}
