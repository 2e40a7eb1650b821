// kernels/projtet.cl — cell projection in visibility order (Shirley & Tuchman 1990; Williams 1992),
// the fragment program of its one draw, appended after kernels/raster.cl (host/render/tet/projtet.h), and
// (without CLVR_PROJTET_FRAGMENT) the fused path's kernel, projtet_fused, which does that draw's work per pixel.
// The projected triangles of a tetrahedron only give coverage (its silhouette, once); each fragment then
// intersects its own ray with the tetrahedron's four planes, so (s_f, s_b, l) are exact for perspective
// and parallel cameras alike, and integrates the segment with harc's partial pre-integration
// (kernels/segment_integral.h: ψ table, split at the transfer function's control points). Blending
// ONE, ONE_MINUS_SRC_ALPHA back to front composites the segments.
#include "projtet_params.h"
#include "segment_integral8.h"  /* once, for both parts: the embedded source holds each header once */

/* Per tetrahedron, kernels/harc.cl's 5 float4 (host/render/tet/harc.h packHarcTets): three barycentric
 * planes (h_i, k_i), the fourth 1 minus their sum, the gradient and scalar term; the adjacency is unused. */
#define PROJTET_TET_FLOAT4S 5

/* Cell t's segment along the ray e + λ d, λ >= 0: inside, b_i(e + λ d) = b_i(e) + λ dot(h_i, d) >= 0 for all four
 * planes. Returns whether the ray meets the cell (not where it grazes it, or runs parallel to a face outside it),
 * and then in *l its length and in *s_f, *s_b the scalar at its front and back (Eq. 6). The dot products are
 * written out (harc_dot3), as projtet_fused_packet's lanes repeat them. */
__attribute__((always_inline)) int projtet_cell_segment(global const float* cells, const uint t, const float3 e,
                                                          const float3 d, float* l, float* s_f, float* s_b)
{
    global const float* tet = cells + (size_t)t * (4 * PROJTET_TET_FLOAT4S);
    const float4 p0 = vload4(0, tet), p1 = vload4(1, tet), p2 = vload4(2, tet), grad = vload4(3, tet);
    const float4 p3 = (float4)(-(p0.xyz + p1.xyz + p2.xyz), 1.0f - (p0.w + p1.w + p2.w));
    float lambda_in = 0.0f, lambda_out = INFINITY;
    const float4 planes[4] = {p0, p1, p2, p3};
    int miss = 0;
    for (int i = 0; i < 4; ++i) {
        const float hd = harc_dot3(planes[i].xyz, d);
        const float b = harc_dot3(planes[i].xyz, e) + planes[i].w;
        if (hd > 0.0f)
            lambda_in = fmax(lambda_in, -b / hd);
        else if (hd < 0.0f)
            lambda_out = fmin(lambda_out, b / -hd);
        else if (b < 0.0f)
            miss = 1;  /* parallel to face i, outside it */
    }
    *l = lambda_out - lambda_in;
    if (miss || !(*l > 0.0f))
        return 0;
    *s_f = harc_dot3(grad.xyz, e + lambda_in * d) + grad.w;
    *s_b = harc_dot3(grad.xyz, e + lambda_out * d) + grad.w;
    return 1;
}

#ifdef CLVR_PROJTET_FRAGMENT
/* attr[0] = (tet id low 12 bits, tet id high 12 bits, 0, 0), the same at every corner: interpolated
 * constants within a few ulps of integers below 2^12. buffer[0] the tetrahedra, buffer[1] the transfer
 * function (transfer_function.h layout), buffer[2] the ψ table. uniforms: ClProjtetUniforms.
 * color = the segment's premultiplied (I, 1 - T), composited under nothing (I_0 = 0, T_0 = 1). */
int clvr_fragment(const ClFragment* f, const ClFragmentResources* r, float4* color)
{
    constant ClProjtetUniforms* u = (constant ClProjtetUniforms*)r->uniforms;
    const ClCamera cam = u->camera;
    const float4 counts = u->counts;
    const uint t = (uint)rint(f->attr[0].x) + ((uint)rint(f->attr[0].y) << 12);

    /* The ray through the pixel centre, |d| = 1, as harc's (kernels/ray.h). */
    float3 e, d;
    clvr_ray_unit(clvr_ray_window_offset(f->window, counts.xy, cam), cam, &e, &d);
    float l, s_f, s_b;
    if (!projtet_cell_segment(r->buffer[0], t, e, d, &l, &s_f, &s_b))
        return 0;  /* the pixel centre's ray misses (grazes) the cell: no light, no opacity */
    float3 c = (float3)(0.0f);
    float transmittance = 1.0f;
    harc_segment(r->buffer[1], (int)counts.z, r->buffer[2], (int)counts.w, s_f, s_b, l, &c, &transmittance);
    *color = (float4)(c, 1.0f - transmittance);
    return 1;
}

#endif

#ifndef CLVR_PROJTET_FRAGMENT

/* The fused path's tiles: 8 pixels wide (a packet's row), 4 high (host/render/tet/projtet.h kProjtetTileW, H). */
#define PROJTET_TILE_W_LOG2 3
#define PROJTET_TILE_H_LOG2 2

/* The fused path ("path": "fused", host/render/tet/projtet.cpp): the cells, back to front, binned to tiles by
 * their boxes of pixel centres (tile_start: each tile's first entry, CSR; tile_cells: cell ids, in visibility
 * order within a tile; boxes[cell] = (x0, y0, x1, y1), inclusive, empty when x0 > x1). One work-item per pixel
 * walks its tile's cells and, for each whose box holds the pixel, does the fragment program's work above — its
 * own ray against the cell's four planes, the segment by partial pre-integration — and blends it ONE,
 * ONE_MINUS_SRC_ALPHA as the raster stage would, in private memory. out = I + (1 - A) background, A;
 * segments[pixel] = the segments integrated (the rays that meet a cell with l > 0). */
kernel void projtet_fused(global float4* out, global uint* segments, global const uint* tile_start,
                          global const uint* tile_cells, global const short4* boxes, global const float* cells,
                          global const float* tf, global const float* psi, const ClProjtetFusedParams p)
{
    CLVR_GUARD_2D(p.size.x, p.size.y);
    const int x = (int)get_global_id(0), y = (int)get_global_id(1);
    const int tile = (y >> PROJTET_TILE_H_LOG2) * p.size.z + (x >> PROJTET_TILE_W_LOG2);
    float3 e, d;
    clvr_ray_unit(clvr_ray_window_offset(clvr_ray_pixel_centre(x, y), (float2)((float)p.size.x, (float)p.size.y),
                                         p.camera),
                  p.camera, &e, &d);
    float3 dst = (float3)(0.0f);
    float dst_alpha = 0.0f;
    uint n = 0;
    const uint end = tile_start[tile + 1];
    for (uint k = tile_start[tile]; k < end; ++k) {
        const uint t = tile_cells[k];
        const short4 b = boxes[t];
        if (x < b.x || y < b.y || x > b.z || y > b.w)
            continue;
        float l, s_f, s_b;
        if (!projtet_cell_segment(cells, t, e, d, &l, &s_f, &s_b))
            continue;
        float3 c = (float3)(0.0f);
        float transmittance = 1.0f;
        harc_segment(tf, p.counts.x, psi, p.counts.y, s_f, s_b, l, &c, &transmittance);
        const float src_alpha = 1.0f - transmittance;
        dst = c + (1.0f - src_alpha) * dst;
        dst_alpha = src_alpha + (1.0f - src_alpha) * dst_alpha;
        ++n;
    }
    const size_t i = (size_t)y * (size_t)p.size.x + (size_t)x;
    out[i] = (float4)(dst + (1.0f - dst_alpha) * p.background.xyz, dst_alpha);
    segments[i] = n;
}

/* projtet_fused for the 8 pixels x0 .. x0 + 7 of a row, one per float8 lane (kernels/segment_integral8.h): a tile is
 * 8 pixels wide, so the 8 lanes walk the same cells; each cell's planes are loaded once and met by the 8 rays as
 * vectors, and its segment is integrated for the lanes whose ray meets it. Every lane does projtet_fused's
 * operations (the dot products written out in both), so its pixel is the same bits. */
kernel void projtet_fused_packet(global float4* out, global uint* segments, global const uint* tile_start,
                                 global const uint* tile_cells, global const short4* boxes, global const float* cells,
                                 global const float* tf, global const float* psi, const ClProjtetFusedParams p)
{
    const int x0 = (int)get_global_id(0) * 8, y = (int)get_global_id(1);
    if (x0 >= p.size.x || y >= p.size.y)
        return;
    const int8 xs = x0 + (int8)(0, 1, 2, 3, 4, 5, 6, 7);
    const int8 valid = xs < p.size.x;
    const int tile = (y >> PROJTET_TILE_H_LOG2) * p.size.z + (x0 >> PROJTET_TILE_W_LOG2);
    const float2 size = (float2)((float)p.size.x, (float)p.size.y);
    float8 e_x, e_y, e_z, d_x, d_y, d_z;
#define PROJTET_RAY(L)                                                                                                 \
    {                                                                                                                  \
        float3 e, d;                                                                                                   \
        clvr_ray_unit(clvr_ray_window_offset(clvr_ray_pixel_centre(min(x0 + L, p.size.x - 1), y), size, p.camera),   \
                      p.camera, &e, &d);                                                                               \
        e_x.s##L = e.x, e_y.s##L = e.y, e_z.s##L = e.z, d_x.s##L = d.x, d_y.s##L = d.y, d_z.s##L = d.z;                \
    }
    CLVR_EACH_LANE(PROJTET_RAY)
#undef PROJTET_RAY
    float8 dst_r = 0.0f, dst_g = 0.0f, dst_b = 0.0f, dst_alpha = 0.0f;
    int8 n = 0;
    const uint end = tile_start[tile + 1];
    for (uint k = tile_start[tile]; k < end; ++k) {
        const uint t = tile_cells[k];
        const short4 b = boxes[t];
        if (y < b.y || y > b.w)
            continue;
        int8 m = valid & (xs >= (int)b.x) & (xs <= (int)b.z);
        if (!any(m))
            continue;
        global const float* tet = cells + (size_t)t * (4 * PROJTET_TET_FLOAT4S);
        const float4 p0 = vload4(0, tet), p1 = vload4(1, tet), p2 = vload4(2, tet), grad = vload4(3, tet);
        const float4 p3 = (float4)(-(p0.xyz + p1.xyz + p2.xyz), 1.0f - (p0.w + p1.w + p2.w));
        const float4 planes[4] = {p0, p1, p2, p3};
        float8 lambda_in = 0.0f, lambda_out = INFINITY;
        int8 miss = 0;
        for (int i = 0; i < 4; ++i) {
            const float4 h = planes[i];
            const float8 hd = harc_dot8((float8)(h.x), (float8)(h.y), (float8)(h.z), d_x, d_y, d_z);
            const float8 bi = harc_dot8((float8)(h.x), (float8)(h.y), (float8)(h.z), e_x, e_y, e_z) + h.w;
            const int8 enter = isgreater(hd, 0.0f), leave = isless(hd, 0.0f);
            lambda_in = select(lambda_in, fmax(lambda_in, -bi / hd), enter);
            lambda_out = select(lambda_out, fmin(lambda_out, bi / -hd), leave);
            miss |= ~enter & ~leave & isless(bi, 0.0f);
        }
        const float8 l = lambda_out - lambda_in;
        m &= ~miss & isgreater(l, 0.0f);
        if (!any(m))
            continue;
        const float8 gx = (float8)(grad.x), gy = (float8)(grad.y), gz = (float8)(grad.z);
        const float8 s_f = harc_dot8(gx, gy, gz, e_x + lambda_in * d_x, e_y + lambda_in * d_y, e_z + lambda_in * d_z) + grad.w;
        const float8 s_b = harc_dot8(gx, gy, gz, e_x + lambda_out * d_x, e_y + lambda_out * d_y, e_z + lambda_out * d_z) + grad.w;
        HarcTfPoint8 front, back;
        front.s = s_f, front.k = 0, front.r = front.g = front.b = front.w = 0.0f;
#define PROJTET_FRONT(L)                                                                                               \
        if (m.s##L) {                                                                                                  \
            const HarcTfPoint q = harc_tf_point(tf, p.counts.x, s_f.s##L);                                             \
            front.k.s##L = q.k, front.r.s##L = q.c.x, front.g.s##L = q.c.y, front.b.s##L = q.c.z, front.w.s##L = q.c.w; \
        }
        CLVR_EACH_LANE(PROJTET_FRONT)
#undef PROJTET_FRONT
        back = front;
        float8 c_r = 0.0f, c_g = 0.0f, c_b = 0.0f, transmittance = 1.0f;
        harc_segment_from8(tf, p.counts.x, psi, p.counts.y, &front, s_b, l, m, &c_r, &c_g, &c_b, &transmittance, &back);
        const float8 src_alpha = 1.0f - transmittance;
        dst_r = select(dst_r, c_r + (1.0f - src_alpha) * dst_r, m);
        dst_g = select(dst_g, c_g + (1.0f - src_alpha) * dst_g, m);
        dst_b = select(dst_b, c_b + (1.0f - src_alpha) * dst_b, m);
        dst_alpha = select(dst_alpha, src_alpha + (1.0f - src_alpha) * dst_alpha, m);
        n -= m;
    }
    const float8 r = dst_r + (1.0f - dst_alpha) * p.background.x, g = dst_g + (1.0f - dst_alpha) * p.background.y,
                 bl = dst_b + (1.0f - dst_alpha) * p.background.z;
    const size_t row = (size_t)y * (size_t)p.size.x;
#define PROJTET_STORE(L)                                                                                               \
    if (valid.s##L) {                                                                                                  \
        out[row + x0 + L] = (float4)(r.s##L, g.s##L, bl.s##L, dst_alpha.s##L);                                         \
        segments[row + x0 + L] = (uint)n.s##L;                                                                         \
    }
    CLVR_EACH_LANE(PROJTET_STORE)
#undef PROJTET_STORE
}

#endif
