/* kernels/clvr_common.h — what every kernel file shares: guards and small math. OpenCL C 1.2. */
#ifndef CLVR_COMMON_H
#define CLVR_COMMON_H

/* Global sizes are padded to the work-group multiple (host/runtime/device.h); kernels return past n. */
#define CLVR_GUARD_1D(n) \
    if (get_global_id(0) >= (size_t)(n)) return
#define CLVR_GUARD_2D(w, h) \
    if (get_global_id(0) >= (size_t)(w) || get_global_id(1) >= (size_t)(h)) return

/* 2^x for x <= 0, the attenuation of every sample and segment (alpha = 1 - 2^(-tau l log2 e)): Cephes'
 * exp2f — x = n + f with n = rint(x), f in [-1/2, 1/2], 2^f by its degree-6 polynomial, 2^n put into
 * the exponent bits (CLVR_EXP2_POLYNOMIAL, also kernels/packet.h's clvr_exp2_8). Relative error 7.9e-8 measured on [-126, 0] (Cephes states 1.7e-7;
 * tests/device_test.cpp asserts < 3e-7 against the host's exp2). Below -126 it returns 0 (2^x < 1.2e-38
 * there; NaN also gives 0). PoCL's exp2 and exp took 13-40 % of slice3d's per-sample and harc's
 * per-piece time on this CPU; with this, slice3d frames are about 11 % and harc's 18 % shorter. */
#define CLVR_EXP2_POLYNOMIAL(f)                                                                             \
    (1.0f + (f) * (6.931472028550421e-1f +                                                                  \
                   (f) * (2.402264791363012e-1f +                                                           \
                          (f) * (5.550332471162809e-2f +                                                    \
                                 (f) * (9.618437357674640e-3f +                                             \
                                        (f) * (1.339887440266574e-3f + (f) * 1.535336188319500e-4f))))))
float clvr_exp2(const float x)
{
    if (!(x >= -126.0f))
        return 0.0f;
    const float n = rint(x);
    const float f = x - n;
    return CLVR_EXP2_POLYNOMIAL(f) * as_float(((int)n + 127) << 23);
}

/* CLVR_PREFETCH(p, n): fetch the n elements at p into the cache ahead of their use, where a walk jumps through memory
 * (the raster stage's triangle records, projtet's cells). PoCL's prefetch() does nothing (measured), so on x86-64
 * (clang compiling for the CPU) the first two cache lines at p; elsewhere OpenCL's prefetch(). */
#if defined(__clang__) && defined(__x86_64__)
#define CLVR_PREFETCH(p, n) __asm__ volatile("prefetcht0 (%0)\n\tprefetcht0 64(%0)" : : "r"(p))
#else
#define CLVR_PREFETCH(p, n) prefetch((p), (n))
#endif

/* Whether the box of pixel centres b = (x0, y0, x1, y1), inclusive, holds pixel (x, y): the tile kernels' test of a
 * listed cell or cube (host/render/tile_lists.h). */
int clvr_box_holds(const short4 b, const int x, const int y)
{
    return x >= b.x && y >= b.y && x <= b.z && y <= b.w;
}

/* atan2(y, x) in (-pi, pi], the angle of (x, y): a = min(|x|, |y|) / max(|x|, |y|) in [0, 1], atan(a) =
 * a P(a^2) with P of degree 8 (fitted here: relative error 1.5e-8 in exact arithmetic, 1.3e-7 evaluated in
 * float on [0, 1]), then pi/2 - r where |y| > |x|, pi - r where x < 0, the sign of y. Absolute error below
 * 5e-7 (tests/device_test.cpp against the host's atan2); atan2(±0, 0) = ±0. PoCL's atan2 and acos took 57 %
 * of spherical's fused per-sample time on this CPU. */
/* P(s), declared as r of type T, one Horner step per statement (each contracted alike for scalars and
 * vectors); also kernels/packet.h's clvr_atan2_8. */
#define CLVR_ATAN_POLYNOMIAL(T, r, s)  \
    T r = 2.8501858469098806e-3f;      \
    r = r * (s) - 1.6069890931248665e-2f; \
    r = r * (s) + 4.269373044371605e-2f;  \
    r = r * (s) - 7.504499703645706e-2f;  \
    r = r * (s) + 1.064104288816452e-1f;  \
    r = r * (s) - 1.4203676581382751e-1f; \
    r = r * (s) + 1.999262422323227e-1f;  \
    r = r * (s) - 3.3333075046539307e-1f;

float clvr_atan2(const float y, const float x)
{
    const float ax = fabs(x), ay = fabs(y);
    const float hi = fmax(ax, ay), lo = fmin(ax, ay);
    const float a = hi > 0.0f ? lo / hi : 0.0f;
    const float s = a * a;
    CLVR_ATAN_POLYNOMIAL(float, r, s)
    r = (r * s + 1.0f) * a;
    if (ay > ax)
        r = 1.5707963267948966f - r;
    if (x < 0.0f)
        r = 3.14159265358979323846f - r;
    return copysign(r, y);
}

#endif
