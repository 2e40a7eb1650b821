/* kernels/segment_integral8.h — kernels/segment_integral.h for 8 rays at once, one per float8 lane (the ray packets of
 * kernels/harc.cl's harc_render_packet and kernels/projtet.cl's projtet_fused_packet): each function does its scalar
 * twin's operations lane by lane (kernels/packet.h's rule), so a lane's result is the scalar one bit for bit; and
 * the dot products both write out (harc_dot3, harc_dot4 and their lane-by-lane forms). OpenCL C 1.2. */
#ifndef CLVR_SEGMENT_INTEGRAL8_H
#define CLVR_SEGMENT_INTEGRAL8_H

#include "packet.h"
#include "segment_integral.h"

/* dot() written out: the products, then their sum pairwise ((x + y) + z; (x + y) + (z + w) for float4s), nothing
 * fused — how PoCL's builtin rounds it (measured: bit for bit), and what harc_render_packet repeats lane by lane, so
 * that the two kernels round alike on any OpenCL whose builtin rounds otherwise (Mesa's rusticl does). */
float harc_dot3(const float3 a, const float3 b)
{
    const float x = a.x * b.x, y = a.y * b.y, z = a.z * b.z;
    return x + y + z;
}

float harc_dot4(const float4 a, const float4 b)
{
    const float x = a.x * b.x, y = a.y * b.y, z = a.z * b.z, w = a.w * b.w;
    return (x + y) + (z + w);
}

/* harc_dot3 lane by lane (a fused form would move the last bits). */
float8 harc_dot8(const float8 ax, const float8 ay, const float8 az, const float8 bx, const float8 by, const float8 bz)
{
    const float8 x = ax * bx, y = ay * by, z = az * bz;
    return x + y + z;
}

/* harc_dot4 lane by lane. */
float8 harc_dot8_4(const float8 ax, const float8 ay, const float8 az, const float8 aw, const float8 bx, const float8 by,
                   const float8 bz, const float8 bw)
{
    const float8 x = ax * bx, y = ay * by, z = az * bz, w = aw * bw;
    return (x + y) + (z + w);
}

/* harc_psi lane by lane (lanes outside m read the table's first texels). */
float8 harc_psi8(global const float* psi, const int n, const float8 tau_l_front, const float8 tau_l_back, const int8 m)
{
    const float8 f = fmin(tau_l_front, 1e30f), b = fmin(tau_l_back, 1e30f);
    const float n1 = (float)(n - 1);
    const float8 x = f / (1.0f + f) * n1, y = b / (1.0f + b) * n1;
    const int8 i = select((int8)(0), min(convert_int8(x), n - 2), m), j = select((int8)(0), min(convert_int8(y), n - 2), m);
    const float8 fx = x - convert_float8(i), fy = y - convert_float8(j);
    const int8 at = j * n + i;
    float8 r00, r01, r10, r11;
#define HARC_PSI(L)                                                  \
    {                                                                \
        const float2 u = vload2(0, psi + at.s##L);                   \
        const float2 v = vload2(0, psi + at.s##L + n);               \
        r00.s##L = u.x, r01.s##L = u.y, r10.s##L = v.x, r11.s##L = v.y; \
    }
    CLVR_EACH_LANE(HARC_PSI)
#undef HARC_PSI
    const float8 a = r00 + fx * (r01 - r00);
    const float8 c = r10 + fx * (r11 - r10);
    return a + fy * (c - a);
}

/* harc_piece lane by lane, for the lanes in m. */
void harc_piece8(global const float* psi, const int psi_n, const float8 cf_r, const float8 cf_g, const float8 cf_b,
                 const float8 cf_w, const float8 cb_r, const float8 cb_g, const float8 cb_b, const float8 cb_w,
                 const float8 l, int8 m, float8* c_r, float8* c_g, float8* c_b, float8* transmittance)
{
    const float8 tf = cf_w * l, tb = cb_w * l;
    m &= ~(isequal(tf, 0.0f) & isequal(tb, 0.0f)); /* tau 0 all along the piece: nothing to add */
    if (!any(m))
        return;
    const float8 zeta = clvr_exp2_8(-0.5f * M_LOG2E_F * (tf + tb));
    const float8 p = harc_psi8(psi, psi_n, tf, tb, m);
    const float8 r = cb_r * (p - zeta) + cf_r * (1.0f - p);
    const float8 g = cb_g * (p - zeta) + cf_g * (1.0f - p);
    const float8 b = cb_b * (p - zeta) + cf_b * (1.0f - p);
    *c_r = select(*c_r, *c_r + *transmittance * r, m);
    *c_g = select(*c_g, *c_g + *transmittance * g, m);
    *c_b = select(*c_b, *c_b + *transmittance * b, m);
    *transmittance = select(*transmittance, *transmittance * zeta, m);
}

/* vload4(i, v) of each lane's i into four vectors. */
void harc_gather4(global const float* v, const int8 i, float8* x, float8* y, float8* z, float8* w)
{
#define HARC_GATHER4(L)                                              \
    {                                                                \
        const float4 q = vload4(i.s##L, v);                          \
        (*x).s##L = q.x, (*y).s##L = q.y, (*z).s##L = q.z, (*w).s##L = q.w; \
    }
    CLVR_EACH_LANE(HARC_GATHER4)
#undef HARC_GATHER4
}

/* harc_tf_at lane by lane. */
void harc_tf_at8(global const float* tf, const int n, const int8 k, const float8 x, float8* r, float8* g, float8* b,
                 float8* w)
{
    global const float* value = tf + ((n + 3) & ~3);
    global const float* slope = value + 4 * n;
    const int8 i = clamp(k - 1, 0, n - 1);
    float8 vr, vg, vb, vw, sr, sg, sb, sw, s;
    harc_gather4(value, i, &vr, &vg, &vb, &vw);
    harc_gather4(slope, i, &sr, &sg, &sb, &sw);
    CLVR_GATHER8(s, tf, i);
    const float8 dx = x - s;
    const int8 first = k == 0, last = k == n;
    *r = select(select(vr + dx * sr, (float8)(value[0]), first), (float8)(value[4 * (n - 1)]), last);
    *g = select(select(vg + dx * sg, (float8)(value[1]), first), (float8)(value[4 * (n - 1) + 1]), last);
    *b = select(select(vb + dx * sb, (float8)(value[2]), first), (float8)(value[4 * (n - 1) + 2]), last);
    *w = select(select(vw + dx * sw, (float8)(value[3]), first), (float8)(value[4 * (n - 1) + 3]), last);
}

/* One end of each lane's segment (HarcTfPoint lane by lane). */
typedef struct {
    float8 s, r, g, b, w;
    int8 k;
} HarcTfPoint8;

/* harc_segment_from lane by lane for the lanes in m: each lane's pieces in its own order; *back (lanes in m) the
 * segment's back end. Returns the pieces per lane. */
int8 harc_segment_from8(global const float* tf, const int n, global const float* psi, const int psi_n,
                        const HarcTfPoint8* front, const float8 s_b, const float8 l, const int8 m, float8* c_r,
                        float8* c_g, float8* c_b, float8* transmittance, HarcTfPoint8* back)
{
    const float8 s_f = front->s;
    const int8 flat = m & ~isnotequal(s_b, s_f); /* s constant along the ray: one piece with constant C and tau */
    const int8 up = m & ~flat & isgreater(s_b, s_f), down = m & ~flat & ~up;
    harc_piece8(psi, psi_n, front->r, front->g, front->b, front->w, front->r, front->g, front->b, front->w, l, flat,
                c_r, c_g, c_b, transmittance);
    const float8 inv_ds = 1.0f / (s_b - s_f);
    float8 f_r = front->r, f_g = front->g, f_b = front->b, f_w = front->w, lambda_front = 0.0f;
    int8 pieces = flat & 1;
    /* up: from the first control point above s_f; down: below the points equal to s_f */
    int8 k = select(front->k, front->k - 1, down);
    for (;;) {
        float8 tk;
        CLVR_GATHER8(tk, tf, clamp(k, 0, n - 1));
        const int8 more = down & (k >= 0) & isgreaterequal(tk, s_f);
        if (!any(more))
            break;
        k -= more & 1;
    }
    global const float* value = tf + ((n + 3) & ~3);
    for (;;) {
        float8 tk;
        CLVR_GATHER8(tk, tf, clamp(k, 0, n - 1));
        const int8 next = (up & (k < n) & isless(tk, s_b)) | (down & (k >= 0) & isgreater(tk, s_b));
        if (!any(next))
            break;
        const float8 lambda = l * ((tk - s_f) * inv_ds);
        float8 i_r, i_g, i_b, i_w;
        harc_gather4(value, clamp(k, 0, n - 1), &i_r, &i_g, &i_b, &i_w);
        harc_piece8(psi, psi_n, f_r, f_g, f_b, f_w, i_r, i_g, i_b, i_w, lambda - lambda_front, next, c_r, c_g, c_b,
                    transmittance);
        f_r = select(f_r, i_r, next), f_g = select(f_g, i_g, next), f_b = select(f_b, i_b, next);
        f_w = select(f_w, i_w, next), lambda_front = select(lambda_front, lambda, next);
        pieces -= next;
        k += select((int8)(0), select((int8)(-1), (int8)(1), up), next);
    }
    float8 tk;
    CLVR_GATHER8(tk, tf, clamp(k, 0, n - 1));
    const int8 k_b = select(k + 1, select(k, k + 1, (k < n) & islessequal(tk, s_b)), up);
    const int8 walked = up | down;
    float8 b_r, b_g, b_b, b_w;
    harc_tf_at8(tf, n, k_b, s_b, &b_r, &b_g, &b_b, &b_w);
    harc_piece8(psi, psi_n, f_r, f_g, f_b, f_w, b_r, b_g, b_b, b_w, l - lambda_front, walked, c_r, c_g, c_b,
                transmittance);
    pieces -= walked;
    back->s = select(back->s, select(front->s, s_b, walked), m);
    back->k = select(back->k, select(front->k, k_b, walked), m);
    back->r = select(back->r, select(front->r, b_r, walked), m);
    back->g = select(back->g, select(front->g, b_g, walked), m);
    back->b = select(back->b, select(front->b, b_b, walked), m);
    back->w = select(back->w, select(front->w, b_w, walked), m);
    return pieces;
}

#endif
