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

/* A ray that runs in a face's plane (the eye in that plane, the pixel centre on its image line) is inside both cells
 * of the face as far as rounding can tell, and each would add the stretch along the face. So a plane decides nothing
 * for such a ray, and only the cell whose h_i points to the side of PROJTET_TIE_* keeps it (the two cells' h_i for
 * their face point opposite ways): the stretch counts once. "In the plane": dot(h, d) and b = dot(h, e) + w within
 * PROJTET_IN_PLANE (kernels/projtet_params.h) of their terms' sizes — the same rays for both cells (h_i of one is
 * the other's times a negative factor), and far more than float rounding. */

/* The bound on |dot(h, d)| for |d| = 1, and on |b| at e. */
float projtet_flat_hd(const float4 h)
{
    return PROJTET_IN_PLANE * (fabs(h.x) + fabs(h.y) + fabs(h.z));
}

float projtet_flat_b(const float4 h, const float3 e)
{
    return PROJTET_IN_PLANE * (fabs(h.x * e.x) + fabs(h.y * e.y) + fabs(h.z * e.z) + fabs(h.w));
}

/* Whether this cell keeps a ray that lies in plane h. */
int projtet_keeps_in_plane(const float4 h)
{
    return harc_dot3(h.xyz, (float3)(PROJTET_TIE_X, PROJTET_TIE_Y, PROJTET_TIE_Z)) > 0.0f;
}

int projtet_in_plane(const float4 h, const float3 e, const float hd, const float b)
{
    return fabs(hd) <= projtet_flat_hd(h) && fabs(b) <= projtet_flat_b(h, e);
}

/* Cell t's four barycentric planes (h_i, w_i), the fourth 1 minus the sum of the others, and its gradient. */
void projtet_cell_planes(global const float* cells, const uint t, float4 planes[4], float4* grad)
{
    global const float* tet = cells + (size_t)t * (4 * PROJTET_TET_FLOAT4S);
    planes[0] = vload4(0, tet), planes[1] = vload4(1, tet), planes[2] = vload4(2, tet);
    planes[3] = (float4)(-(planes[0].xyz + planes[1].xyz + planes[2].xyz), 1.0f - (planes[0].w + planes[1].w + planes[2].w));
    *grad = vload4(3, tet);
}

/* Cell t's segment along the ray e + λ d, λ >= 0: inside, b_i(e + λ d) = b_i(e) + λ dot(h_i, d) >= 0 for all four
 * planes. Returns whether the ray meets the cell (not where it grazes it, or runs parallel to a face outside it, or
 * runs in a face's plane that the other cell of the face keeps), and then in *l its length and in *s_f, *s_b the
 * scalar at its front and back (Eq. 6). The dot products are written out (harc_dot3), as projtet_fused_packet's
 * lanes repeat them. */
__attribute__((always_inline)) int projtet_cell_segment(global const float* cells, const uint t, const float3 e,
                                                          const float3 d, float* l, float* s_f, float* s_b)
{
    float4 planes[4], grad;
    projtet_cell_planes(cells, t, planes, &grad);
    float lambda_in = 0.0f, lambda_out = INFINITY;
    int miss = 0;
    for (int i = 0; i < 4; ++i) {
        const float hd = harc_dot3(planes[i].xyz, d);
        const float b = harc_dot3(planes[i].xyz, e) + planes[i].w;
        if (projtet_in_plane(planes[i], e, hd, b)) {
            miss |= !projtet_keeps_in_plane(planes[i]);
            continue;
        }
        if (hd > 0.0f)
            lambda_in = fmax(lambda_in, -(b / hd));
        else if (hd < 0.0f)
            lambda_out = fmin(lambda_out, -(b / hd));  /* b / -hd: IEEE division rounds |b| / |hd| either way */
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
#define PROJTET_TILE_H (1 << PROJTET_TILE_H_LOG2)
#define PROJTET_TILE_PIXELS (CLVR_LANES * PROJTET_TILE_H) /* projtet_fused_packet: a tile row is a packet's 8 lanes */
#if (1 << PROJTET_TILE_W_LOG2) != CLVR_LANES
#error "projtet_fused_packet takes a tile row as one packet"
#endif

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
        if (!clvr_box_holds(b, x, y))
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

/* projtet_fused for one tile (8 x 4 pixels, a work-item each), its segments integrated 8 at a time, one per float8
 * lane (kernels/segment_integral8.h). Each cell's planes are loaded once and met by the rays of each of the tile's rows
 * that its box reaches, 8 as vectors; the segments those rays have (l > 0) join a queue in the tile list's order, and
 * each time 8 are queued they are integrated together — whichever pixels they belong to — and blended into their
 * pixels in queue order, which keeps each pixel's cells back to front. So the integration, most of the work, runs
 * with every lane busy where the cells are a few pixels wide (a row's 8 lanes would hold one or two segments).
 * Every lane does projtet_fused's operations (the dot products written out in both), so its pixel is the same bits. */
typedef struct {
    float s_f[2 * CLVR_LANES], s_b[2 * CLVR_LANES], l[2 * CLVR_LANES];  /* a row's ≤ 8 segments join ≤ 7 waiting */
    int pixel[2 * CLVR_LANES];                                          /* in the tile: row * 8 + column */
    int count;
} ProjtetQueue;

typedef struct {
    float r[PROJTET_TILE_PIXELS], g[PROJTET_TILE_PIXELS], b[PROJTET_TILE_PIXELS], alpha[PROJTET_TILE_PIXELS];
    uint n[PROJTET_TILE_PIXELS];  /* the raster stage's blend per pixel of the tile, and the segments blended */
} ProjtetTile;

/* Integrates the first min(count, 8) queued segments as lanes, blends each into its pixel in queue order, and moves
 * the rest to the queue's front. */
void projtet_drain8(ProjtetQueue* q, ProjtetTile* acc, global const float* tf, const int n, global const float* psi,
                    const int psi_n)
{
    const int lanes = min(q->count, 8);
    const int8 m = CLVR_LANE_INDEX < lanes;
    const float8 s_f = vload8(0, q->s_f), s_b = vload8(0, q->s_b), l = vload8(0, q->l);
    HarcTfPoint8 front, back;
    front.s = s_f, front.k = 0, front.r = front.g = front.b = front.w = 0.0f;
#define PROJTET_FRONT(L)                                                                                               \
    if (m.s##L) {                                                                                                      \
        const HarcTfPoint f = harc_tf_point(tf, n, s_f.s##L);                                                          \
        front.k.s##L = f.k, front.r.s##L = f.c.x, front.g.s##L = f.c.y, front.b.s##L = f.c.z, front.w.s##L = f.c.w;     \
    }
    CLVR_EACH_LANE(PROJTET_FRONT)
#undef PROJTET_FRONT
    back = front;
    float8 c_r = 0.0f, c_g = 0.0f, c_b = 0.0f, transmittance = 1.0f;
    harc_segment_from8(tf, n, psi, psi_n, &front, s_b, l, m, &c_r, &c_g, &c_b, &transmittance, &back);
    const float8 src_alpha = 1.0f - transmittance;
    float cr[8], cg[8], cb[8], ca[8];
    vstore8(c_r, 0, cr), vstore8(c_g, 0, cg), vstore8(c_b, 0, cb), vstore8(src_alpha, 0, ca);
    for (int i = 0; i < lanes; ++i) {
        const int at = q->pixel[i];
        acc->r[at] = cr[i] + (1.0f - ca[i]) * acc->r[at];
        acc->g[at] = cg[i] + (1.0f - ca[i]) * acc->g[at];
        acc->b[at] = cb[i] + (1.0f - ca[i]) * acc->b[at];
        acc->alpha[at] = ca[i] + (1.0f - ca[i]) * acc->alpha[at];
        ++acc->n[at];
    }
    for (int i = lanes; i < q->count; ++i) {
        q->s_f[i - lanes] = q->s_f[i], q->s_b[i - lanes] = q->s_b[i], q->l[i - lanes] = q->l[i];
        q->pixel[i - lanes] = q->pixel[i];
    }
    q->count -= lanes;
}

/* How many tile entries ahead the cells are prefetched (measured on bluntfin: 2, 4 and 8; BENCHMARKS.md run PF3). */
#define PROJTET_AHEAD 4

kernel void projtet_fused_packet(global float4* out, global uint* segments, global const uint* tile_start,
                                 global const uint* tile_cells, global const short4* boxes, global const float* cells,
                                 global const float* tf, global const float* psi, const ClProjtetFusedParams p)
{
    const int tx = (int)get_global_id(0), ty = (int)get_global_id(1);
    if (tx >= p.size.z || ty >= p.size.w)
        return;
    const int x0 = tx << PROJTET_TILE_W_LOG2, y0 = ty << PROJTET_TILE_H_LOG2;
    const int rows = min(PROJTET_TILE_H, p.size.y - y0);
    const int8 xs = x0 + CLVR_LANE_INDEX;
    const int8 valid = xs < p.size.x;
    const float2 size = (float2)((float)p.size.x, (float)p.size.y);
    float8 e_x[PROJTET_TILE_H], e_y[PROJTET_TILE_H], e_z[PROJTET_TILE_H], d_x[PROJTET_TILE_H], d_y[PROJTET_TILE_H],
        d_z[PROJTET_TILE_H];
    for (int row = 0; row < rows; ++row) {
#define PROJTET_RAY(L)                                                                                                 \
        {                                                                                                              \
            float3 e, d;                                                                                               \
            clvr_ray_unit(clvr_ray_window_offset(clvr_ray_pixel_centre(min(x0 + L, p.size.x - 1), y0 + row), size,     \
                                                 p.camera),                                                           \
                          p.camera, &e, &d);                                                                           \
            e_x[row].s##L = e.x, e_y[row].s##L = e.y, e_z[row].s##L = e.z;                                             \
            d_x[row].s##L = d.x, d_y[row].s##L = d.y, d_z[row].s##L = d.z;                                             \
        }
        CLVR_EACH_LANE(PROJTET_RAY)
#undef PROJTET_RAY
    }
    const int eye = !clvr_ray_parallel(p.camera);  /* every ray from the eye, else every ray along forward */
    const float3 e0 = (float3)(e_x[0].s0, e_y[0].s0, e_z[0].s0), d0 = (float3)(d_x[0].s0, d_y[0].s0, d_z[0].s0);
    ProjtetTile acc;
    for (int i = 0; i < PROJTET_TILE_PIXELS; ++i)
        acc.r[i] = acc.g[i] = acc.b[i] = acc.alpha[i] = 0.0f, acc.n[i] = 0;
    ProjtetQueue q;
    for (int i = 0; i < 2 * CLVR_LANES; ++i)
        q.s_f[i] = q.s_b[i] = q.l[i] = 0.0f, q.pixel[i] = 0;
    q.count = 0;
    const int tile = ty * p.size.z + tx;
    const uint end = tile_start[tile + 1];
    for (uint k = tile_start[tile]; k < end; ++k) {
        const uint t = tile_cells[k];
        if (k + PROJTET_AHEAD < end) {  /* the cells are in visibility order, scattered in memory */
            const uint ahead = tile_cells[k + PROJTET_AHEAD];
            CLVR_PREFETCH(boxes + ahead, 1);
            CLVR_PREFETCH(cells + (size_t)ahead * (4 * PROJTET_TET_FLOAT4S), 4 * PROJTET_TET_FLOAT4S);
        }
        const short4 b = boxes[t];
        const int row_lo = max((int)b.y - y0, 0), row_hi = min((int)b.w - y0, rows - 1);
        const int8 columns = valid & (xs >= (int)b.x) & (xs <= (int)b.z);
        if (row_lo > row_hi || !any(columns))
            continue;
        float4 planes[4], grad;
        projtet_cell_planes(cells, t, planes, &grad);
        const float8 gx = (float8)(grad.x), gy = (float8)(grad.y), gz = (float8)(grad.z);
        /* What the tile's rays share, once per cell: from one eye, b_i(e); along one direction (parallel), dot(h_i, d);
         * and whether that shared value lets a ray lie in plane i at all (projtet_in_plane's test of it): almost never,
         * so the lanes' test below mostly does not run */
        float shared[4];
        int flat_maybe = 0;
        for (int i = 0; i < 4; ++i) {
            const float4 h = planes[i];
            shared[i] = eye ? harc_dot3(h.xyz, e0) + h.w : harc_dot3(h.xyz, d0);
            flat_maybe |= (fabs(shared[i]) <= (eye ? projtet_flat_b(h, e0) : projtet_flat_hd(h))) << i;
        }
        for (int row = row_lo; row <= row_hi; ++row) {
            float8 lambda_in = 0.0f, lambda_out = INFINITY;
            int8 miss = 0;
            for (int i = 0; i < 4; ++i) {
                const float4 h = planes[i];
                const float8 hd = eye ? harc_dot8((float8)(h.x), (float8)(h.y), (float8)(h.z), d_x[row], d_y[row], d_z[row])
                                      : (float8)(shared[i]);
                const float8 bi = eye ? (float8)(shared[i])
                                      : harc_dot8((float8)(h.x), (float8)(h.y), (float8)(h.z), e_x[row], e_y[row], e_z[row]) + h.w;
                /* projtet_in_plane lane by lane, where the shared value allows it */
                int8 flat = 0;
                if (flat_maybe >> i & 1) {
                    flat = islessequal(fabs(hd), projtet_flat_hd(h)) &
                           islessequal(fabs(bi), PROJTET_IN_PLANE * (fabs(h.x * e_x[row]) + fabs(h.y * e_y[row]) +
                                                                     fabs(h.z * e_z[row]) + fabs(h.w)));
                    miss |= flat & (projtet_keeps_in_plane(h) ? 0 : -1);
                }
                const int8 enter = isgreater(hd, 0.0f) & ~flat, leave = isless(hd, 0.0f) & ~flat;
                const float8 at = -(bi / hd);  /* -b/h and b/-h alike: IEEE division rounds |b|/|h| either way */
                lambda_in = select(lambda_in, fmax(lambda_in, at), enter);
                lambda_out = select(lambda_out, fmin(lambda_out, at), leave);
                miss |= ~flat & ~enter & ~leave & isless(bi, 0.0f);
            }
            const float8 l = lambda_out - lambda_in;
            const int8 m = columns & ~miss & isgreater(l, 0.0f);
            if (!any(m))
                continue;
            const float8 s_f = harc_dot8(gx, gy, gz, e_x[row] + lambda_in * d_x[row], e_y[row] + lambda_in * d_y[row],
                                         e_z[row] + lambda_in * d_z[row]) + grad.w;
            const float8 s_b = harc_dot8(gx, gy, gz, e_x[row] + lambda_out * d_x[row], e_y[row] + lambda_out * d_y[row],
                                         e_z[row] + lambda_out * d_z[row]) + grad.w;
#define PROJTET_QUEUE(L)                                                                                               \
            if (m.s##L) {                                                                                              \
                q.s_f[q.count] = s_f.s##L, q.s_b[q.count] = s_b.s##L, q.l[q.count] = l.s##L;                           \
                q.pixel[q.count++] = row * CLVR_LANES + L;                                                             \
            }
            CLVR_EACH_LANE(PROJTET_QUEUE)
#undef PROJTET_QUEUE
            if (q.count >= 8)
                projtet_drain8(&q, &acc, tf, p.counts.x, psi, p.counts.y);
        }
    }
    if (q.count > 0)
        projtet_drain8(&q, &acc, tf, p.counts.x, psi, p.counts.y);
    for (int row = 0; row < rows; ++row)
        for (int c = 0; c < CLVR_LANES && x0 + c < p.size.x; ++c) {
            const int at = row * CLVR_LANES + c;
            const float a = acc.alpha[at];
            const size_t i = (size_t)(y0 + row) * (size_t)p.size.x + (size_t)(x0 + c);
            out[i] = (float4)(acc.r[at] + (1.0f - a) * p.background.x, acc.g[at] + (1.0f - a) * p.background.y,
                              acc.b[at] + (1.0f - a) * p.background.z, a);
            segments[i] = acc.n[at];
        }
}

#endif
