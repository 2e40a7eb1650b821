/* kernels/packet.h — ray packets: 8 pixels' rays stepping through the same planes together, one per lane of
 * float8 vectors (kernels/slice3d.cl's slice3d_fused_packet, kernels/stack2d.cl's stack2d_fused_packet;
 * docs/slice3d.md, "Ray packets"). Each function here is a scalar function of kernels/ lane by lane, with
 * the same operations in the same order, so that a packet's pixels are the scalar kernel's bits (OpenCL
 * contracts a * b + c within one expression, for vectors as for scalars; a product of two scalars broadcast
 * into a vector sum is rounded on its own, so such operands are made vectors first). OpenCL C 1.2. */
#ifndef CLVR_PACKET_H
#define CLVR_PACKET_H

#include "empty_space.h"

#include "clvr_common.h"

#define CLVR_LANES 8  /* host: kPacketLanes (host/render/options_util.h) */
#define CLVR_EACH_LANE(M) M(0) M(1) M(2) M(3) M(4) M(5) M(6) M(7)
#define CLVR_LANE_INDEX ((int8)(0, 1, 2, 3, 4, 5, 6, 7))

/* out.sL = array[index.sL] in every lane L: a gather, one load per lane (OpenCL C has none); out's element type
 * converts each loaded element (a uchar into an int lane, say). */
#define CLVR_GATHER8(out, array, index)                                                                   \
    ((out).s0 = (array)[(index).s0], (out).s1 = (array)[(index).s1], (out).s2 = (array)[(index).s2],      \
     (out).s3 = (array)[(index).s3], (out).s4 = (array)[(index).s4], (out).s5 = (array)[(index).s5],      \
     (out).s6 = (array)[(index).s6], (out).s7 = (array)[(index).s7])

/* The smallest (largest) of 8 lanes. */
int clvr_min8(const int8 v)
{
    const int4 a = min(v.lo, v.hi);
    const int2 b = min(a.lo, a.hi);
    return min(b.x, b.y);
}

int clvr_max8(const int8 v)
{
    const int4 a = max(v.lo, v.hi);
    const int2 b = max(a.lo, a.hi);
    return max(b.x, b.y);
}

/* clvr_grid_owned lane by lane: 1 where (gx, gy, gz) lies in the half-open box [lo, hi). */
int8 clvr_in_box8(const float8 gx, const float8 gy, const float8 gz, const float3 lo, const float3 hi)
{
    return isgreaterequal(gx, lo.x) & isgreaterequal(gy, lo.y) & isgreaterequal(gz, lo.z) & isless(gx, hi.x) &
           isless(gy, hi.y) & isless(gz, hi.z);
}

/* clvr_space lane by lane: the empty-space byte of brick (bx, by, bz) of each lane. */
int8 clvr_space8(global const uchar* space, const int4 bdims, const int8 bx, const int8 by, const int8 bz)
{
    const uint8 i = (convert_uint8(bz) * (uint)bdims.y + convert_uint8(by)) * (uint)bdims.x + convert_uint8(bx);
    int8 s;
    CLVR_GATHER8(s, space, i);
    return s;
}

/* Where a packet goes on from slice k (walking by step = +1 or -1 over k_begin .. k_end, the union of its lanes'
 * ranges [lo, hi]) when every lane that samples at k (act) is in an empty brick, run_end being each such lane's
 * last slice in its empty cube (clvr_empty_run8): the nearest of those ends, but no further than any other live
 * lane's next slice — before its range the slice before its first, inside its range (outside its box there) k
 * itself. The caller goes on at the result + step. */
int clvr_packet_jump(const int8 run_end, const int8 act, const int8 live, const int k, const int step, const int8 lo,
                     const int8 hi, const int k_begin, const int k_end)
{
    int8 bound;
    if (step > 0)
        bound = select(select(select((int8)(k_end), (int8)(k), k <= hi), lo - 1, k < lo), run_end, act);
    else
        bound = select(select(select((int8)(k_begin), (int8)(k), k >= lo), hi + 1, k > hi), run_end, act);
    bound = select((int8)(step > 0 ? k_end : k_begin), bound, live);
    return step > 0 ? clvr_min8(bound) : clvr_max8(bound);
}

/* clvr_atan2 (kernels/clvr_common.h) lane by lane, the same operations. */
float8 clvr_atan2_8(const float8 y, const float8 x)
{
    const float8 ax = fabs(x), ay = fabs(y);
    const float8 hi = fmax(ax, ay), lo = fmin(ax, ay);
    const float8 a = select((float8)(0.0f), lo / hi, isgreater(hi, 0.0f));
    const float8 s = a * a;
    CLVR_ATAN_POLYNOMIAL(float8, r, s)
    r = (r * s + 1.0f) * a;
    r = select(r, 1.5707963267948966f - r, isgreater(ay, ax));
    r = select(r, 3.14159265358979323846f - r, isless(x, 0.0f));
    return copysign(r, y);
}

/* clvr_exp2 (kernels/clvr_common.h) lane by lane, the same operations: clvr_exp2_8 and clvr_exp2_16 (two rows of a
 * packet in one vector, kernels/cubefan.cl's tiles). */
#define CLVR_EXP2_LANES(N)                                                                            \
    float##N clvr_exp2_##N(const float##N x)                                                          \
    {                                                                                                 \
        const float##N n = rint(x);                                                                   \
        const float##N f = x - n;                                                                     \
        const float##N r = CLVR_EXP2_POLYNOMIAL(f) * as_float##N((convert_int##N(n) + 127) << 23);     \
        return select((float##N)(0.0f), r, isgreaterequal(x, -126.0f));                              \
    }
CLVR_EXP2_LANES(8)
CLVR_EXP2_LANES(16)
#undef CLVR_EXP2_LANES

/* clvr_tf_eval (kernels/transfer_function.h) lane by lane: the same segment and expression per lane, found
 * by selects over the segments instead of a search. */
void clvr_tf_eval8(global const float* tf, const int n, const float8 x, float8* r, float8* g, float8* b, float8* tau)
{
    global const float* value = tf + ((n + 3) & ~3);
    global const float* slope = value + 4 * n;
    float8 vr = value[0], vg = value[1], vb = value[2], vt = value[3];
    for (int j = 0; j + 1 < n; ++j) {
        const float s = tf[j];
        const int8 in = j == 0 ? isgreater(x, s) : isgreaterequal(x, s);
        const float8 dx = x - s;
        global const float* v = value + 4 * j;
        global const float* m = slope + 4 * j;
        vr = select(vr, v[0] + dx * m[0], in);
        vg = select(vg, v[1] + dx * m[1], in);
        vb = select(vb, v[2] + dx * m[2], in);
        vt = select(vt, v[3] + dx * m[3], in);
    }
    const int8 top = isgreaterequal(x, tf[n - 1]);
    global const float* v = value + 4 * (n - 1);
    *r = select(vr, (float8)(v[0]), top);
    *g = select(vg, (float8)(v[1]), top);
    *b = select(vb, (float8)(v[2]), top);
    *tau = select(vt, (float8)(v[3]), top);
}

/* clvr_empty_run (kernels/empty_space.h) lane by lane, the same arithmetic: lane l's sample k lies in brick
 * (bx, by, bz) and every brick within Chebyshev distance r of it is empty; the last slice towards k_end still
 * in that cube of bricks (k where no candidate checks out; only the lanes that sample are meaningful). */
int8 clvr_in_cube8(const float8 go_x, const float8 go_y, const float8 go_z, const float8 gd_x, const float8 gd_y,
                   const float8 gd_z, const float depth0, const float delta_s, const int8 k, const ClvrOwnedGrid* grid,
                   const int8 bx, const int8 by, const int8 bz, const int8 r)
{
    const float8 z = depth0 + convert_float8(k) * delta_s;
    const float8 gx = go_x + z * gd_x, gy = go_y + z * gd_y, gz = go_z + z * gd_z;
    const int8 in = clvr_in_box8(gx, gy, gz, grid->own_lo, grid->own_hi);
    const float3 off = convert_float3(grid->offset.xyz);
    /* outside lanes read as 0: their answer is 0 anyway */
    const int8 cx = min(convert_int8(select((float8)(0.0f), gx - off.x, in)), grid->dims.x - 2) >> CLVR_BRICK_SHIFT;
    const int8 cy = min(convert_int8(select((float8)(0.0f), gy - off.y, in)), grid->dims.y - 2) >> CLVR_BRICK_SHIFT;
    const int8 cz = min(convert_int8(select((float8)(0.0f), gz - off.z, in)), grid->dims.z - 2) >> CLVR_BRICK_SHIFT;
    const uint8 c = max(abs_diff(cx, bx), max(abs_diff(cy, by), abs_diff(cz, bz)));
    return in & (c <= convert_uint8(r));
}

int8 clvr_empty_run8(const float8 go_x, const float8 go_y, const float8 go_z, const float8 gd_x, const float8 gd_y,
                     const float8 gd_z, const float depth0, const float delta_s, const int k, const int step,
                     const int8 k_end, const ClvrOwnedGrid* grid, const int8 bx, const int8 by, const int8 bz,
                     const int8 r)
{
    const float3 off = convert_float3(grid->offset.xyz);
    const int4 dims = grid->dims;
    /* the face each lane walks towards, per axis: the cube's high side where step * gd > 0, else its low one */
    const float8 lo_x = off.x + convert_float8(max(bx - r, 0) << CLVR_BRICK_SHIFT);
    const float8 lo_y = off.y + convert_float8(max(by - r, 0) << CLVR_BRICK_SHIFT);
    const float8 lo_z = off.z + convert_float8(max(bz - r, 0) << CLVR_BRICK_SHIFT);
    const float8 hi_x = off.x + fmin(convert_float8((bx + r + 1) << CLVR_BRICK_SHIFT), (float)(dims.x - 1));
    const float8 hi_y = off.y + fmin(convert_float8((by + r + 1) << CLVR_BRICK_SHIFT), (float)(dims.y - 1));
    const float8 hi_z = off.z + fmin(convert_float8((bz + r + 1) << CLVR_BRICK_SHIFT), (float)(dims.z - 1));
    const float fs = (float)step;
    const float8 tx = (select(lo_x, hi_x, isgreater(fs * gd_x, 0.0f)) - go_x) * (1.0f / gd_x);
    const float8 ty = (select(lo_y, hi_y, isgreater(fs * gd_y, 0.0f)) - go_y) * (1.0f / gd_y);
    const float8 tz = (select(lo_z, hi_z, isgreater(fs * gd_z, 0.0f)) - go_z) * (1.0f / gd_z);
    const float none = step > 0 ? INFINITY : -INFINITY;
    const float8 ex = select(tx, (float8)(none), gd_x == 0.0f), ey = select(ty, (float8)(none), gd_y == 0.0f);
    const float8 ez = select(tz, (float8)(none), gd_z == 0.0f);
    const float8 zexit = step > 0 ? fmin(ex, fmin(ey, ez)) : fmax(ex, fmax(ey, ez));
    const float8 kf = (zexit - depth0) / delta_s;
    const float8 fk = (float8)((float)k), fe = convert_float8(k_end);
    const int8 c1 = step > 0 ? convert_int8(clamp(floor(kf), fk, fe)) : convert_int8(clamp(ceil(kf), fe, fk));
    const int8 c2 = c1 - step;
    const int8 ok1 = (c1 != k) & clvr_in_cube8(go_x, go_y, go_z, gd_x, gd_y, gd_z, depth0, delta_s, c1, grid, bx, by, bz, r);
    const int8 ok2 = (c1 != k) & (c2 != k) &
                     clvr_in_cube8(go_x, go_y, go_z, gd_x, gd_y, gd_z, depth0, delta_s, c2, grid, bx, by, bz, r);
    return select(select((int8)(k), c2, ok2), c1, ok1);
}

/* clvr_box_chord lane by lane (the same divisions and min/max per axis; an axis the ray runs parallel to
 * empties the chord where the ray lies outside [lo, hi) on it, an empty box, l >= h, every chord). */
void clvr_chord_axis8(const float8 g0, const float8 gs, const float l, const float h, float8* z0, float8* z1)
{
    if (!(l < h)) {
        *z1 = -INFINITY;
        return;
    }
    const float8 t0 = (l - g0) / gs, t1 = (h - g0) / gs;
    const int8 flat = gs == 0.0f;
    *z0 = select(fmax(*z0, fmin(t0, t1)), *z0, flat);
    *z1 = select(fmin(*z1, fmax(t0, t1)), select(*z1, (float8)(-INFINITY), isless(g0, l) | isgreaterequal(g0, h)), flat);
}

void clvr_box_chord8(const float8 go_x, const float8 go_y, const float8 go_z, const float8 gd_x, const float8 gd_y,
                     const float8 gd_z, const float3 lo, const float3 hi, float8* zin, float8* zout)
{
    float8 z0 = -INFINITY, z1 = INFINITY;
    clvr_chord_axis8(go_x, gd_x, lo.x, hi.x, &z0, &z1);
    clvr_chord_axis8(go_y, gd_y, lo.y, hi.y, &z0, &z1);
    clvr_chord_axis8(go_z, gd_z, lo.z, hi.z, &z0, &z1);
    *zin = z0;
    *zout = z1;
}

/* clvr_slice_range lane by lane. */
void clvr_slice_range8(const float8 zin, const float8 zout, const float depth0, const float delta_s, const int count,
                       int8* k_lo, int8* k_hi)
{
    const float n = (float)count;
    const int8 chord = islessequal(zin, zout);
    *k_lo = select((int8)(0), convert_int8(clamp(ceil((zin - depth0) / delta_s) - 1.0f, 0.0f, n)), chord);
    *k_hi = select((int8)(-1), convert_int8(clamp(floor((zout - depth0) / delta_s) + 1.0f, -1.0f, n - 1.0f)), chord);
}

/* clvr_grid_owned of each lane's slice-k point (clvr_slice_point's expression). */
int8 clvr_grid_owned8(const float8 go_x, const float8 go_y, const float8 go_z, const float8 gd_x, const float8 gd_y,
                      const float8 gd_z, const float depth0, const float delta_s, const int8 k, const float3 lo,
                      const float3 hi)
{
    const float8 z = depth0 + convert_float8(k) * delta_s;
    return clvr_in_box8(go_x + z * gd_x, go_y + z * gd_y, go_z + z * gd_z, lo, hi);
}

/* clvr_trilinear's interpolation lane by lane: the four (i, i + 1) pairs of the cell's corners along x (rows j,
 * j + 1 of slices k, k + 1) and the fractions. */
float8 clvr_trilinear8_mix(const float8 a00x, const float8 a00y, const float8 a10x, const float8 a10y, const float8 a01x,
                           const float8 a01y, const float8 a11x, const float8 a11y, const float8 fx, const float8 fy,
                           const float8 fz)
{
    const float8 c00 = a00x + fx * (a00y - a00x);
    const float8 c10 = a10x + fx * (a10y - a10x);
    const float8 c01 = a01x + fx * (a01y - a01x);
    const float8 c11 = a11x + fx * (a11y - a11x);
    const float8 c0 = c00 + fy * (c10 - c00);
    const float8 c1 = c01 + fy * (c11 - c01);
    return c0 + fz * (c1 - c0);
}

/* clvr_trilinear (kernels/volume_sampling.h) lane by lane at grid coordinates (gx, gy, gz), which the caller
 * has checked in every lane (or set to 0 where the lane does not sample): the 4 pairs of loads per lane, the
 * interpolation as vectors. */
float8 clvr_trilinear8(global const float* v, const int4 dims, const float8 gx, const float8 gy, const float8 gz)
{
    const int8 i = min(convert_int8(gx), dims.x - 2), j = min(convert_int8(gy), dims.y - 2);
    const int8 k = min(convert_int8(gz), dims.z - 2);
    const float8 fx = gx - convert_float8(i), fy = gy - convert_float8(j), fz = gz - convert_float8(k);
    const uint nx = (uint)dims.x, nxy = nx * (uint)dims.y;
    const uint8 idx = convert_uint8(k) * nxy + convert_uint8(j) * nx + convert_uint8(i);
    float8 a00x, a00y, a10x, a10y, a01x, a01y, a11x, a11y;
#define CLVR_GATHER(L)                                                                                    \
    {                                                                                                     \
        global const float* q = v + idx.s##L;                                                             \
        const float2 v00 = vload2(0, q), v10 = vload2(0, q + nx), v01 = vload2(0, q + nxy);               \
        const float2 v11 = vload2(0, q + nxy + nx);                                                       \
        a00x.s##L = v00.x, a00y.s##L = v00.y, a10x.s##L = v10.x, a10y.s##L = v10.y;                       \
        a01x.s##L = v01.x, a01y.s##L = v01.y, a11x.s##L = v11.x, a11y.s##L = v11.y;                       \
    }
    CLVR_EACH_LANE(CLVR_GATHER)
#undef CLVR_GATHER
    return clvr_trilinear8_mix(a00x, a00y, a10x, a10y, a01x, a01y, a11x, a11y, fx, fy, fz);
}

#endif
