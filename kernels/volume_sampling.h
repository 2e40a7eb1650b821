/* kernels/volume_sampling.h — trilinear reconstruction of a regular grid (DESIGN.md, Conventions:
 * values on grid points, x fastest) from a global float buffer, written by hand: faster than
 * image3d_t on PoCL and available everywhere (OPENCL-NOTES.md). OpenCL C 1.2. */
#ifndef CLVR_VOLUME_SAMPLING_H
#define CLVR_VOLUME_SAMPLING_H

/* 1 if grid coordinates g (world position minus origin, over spacing) lie in the bounds [0, n-1]. */
int clvr_grid_inside(const float3 g, const int4 dims)
{
    return g.x >= 0.0f && g.y >= 0.0f && g.z >= 0.0f && g.x <= (float)(dims.x - 1) &&
           g.y <= (float)(dims.y - 1) && g.z <= (float)(dims.z - 1);
}

/* The eye-depth interval [*zin, *zout] of the ray go + z gd (grid coordinates) inside the box [lo, hi)
 * (slab test; a ray parallel to an axis is inside for lo <= g < hi, so hi is the next float above the last
 * grid point); empty (*zin > *zout) when it misses, and when the box is empty (lo >= hi on an axis: the
 * slab test alone would give the chord between the two planes). */
void clvr_box_chord(const float3 go, const float3 gd, const float3 lo, const float3 hi, float* zin, float* zout)
{
    float z0 = -INFINITY, z1 = INFINITY;
    for (int a = 0; a < 3; ++a) {
        const float g0 = a == 0 ? go.x : (a == 1 ? go.y : go.z);
        const float gs = a == 0 ? gd.x : (a == 1 ? gd.y : gd.z);
        const float l = a == 0 ? lo.x : (a == 1 ? lo.y : lo.z);
        const float h = a == 0 ? hi.x : (a == 1 ? hi.y : hi.z);
        if (gs == 0.0f || !(l < h)) {
            if (g0 < l || g0 >= h)  /* always, when l >= h */
                z1 = -INFINITY;
            continue;
        }
        const float t0 = (l - g0) / gs, t1 = (h - g0) / gs;
        z0 = fmax(z0, fmin(t0, t1));
        z1 = fmin(z1, fmax(t0, t1));
    }
    *zin = z0;
    *zout = z1;
}

/* The slices k_lo..k_hi (of 0..count - 1, at eye depths depth0 + k delta_s) near the chord [zin, zout], one
 * more each way; none (k_lo > k_hi) for an empty chord. Only bounds a loop: every sample is still checked. */
void clvr_slice_range(const float zin, const float zout, const float depth0, const float delta_s, const int count,
                      int* k_lo, int* k_hi)
{
    *k_lo = 0;
    *k_hi = -1;
    if (zin <= zout) {
        const float n = (float)count;
        *k_lo = (int)clamp(ceil((zin - depth0) / delta_s) - 1.0f, 0.0f, n);
        *k_hi = (int)clamp(floor((zout - depth0) / delta_s) + 1.0f, -1.0f, n - 1.0f);
    }
}

/* Sort-last parts (host/model/volume.h GridPart): 1 when full-grid coordinates g are this volume's to
 * sample (own_lo <= g < own_hi per axis; for the whole grid own_hi is the next float above n - 1, so
 * this is clvr_grid_inside's g <= n - 1). */
int clvr_grid_owned(const float3 g, const float3 own_lo, const float3 own_hi)
{
    return g.x >= own_lo.x && g.y >= own_lo.y && g.z >= own_lo.z && g.x < own_hi.x && g.y < own_hi.y &&
           g.z < own_hi.z;
}

/* The volume's own grid coordinates of owned full-grid coordinates g: g - offset, exact in float (g >=
 * offset >= 0 and g < 2^24, so the difference is a multiple of g's ulp no larger than g). */
float3 clvr_grid_local(const float3 g, const int4 offset)
{
    return g - convert_float3(offset.xyz);
}

/* Trilinear value at grid coordinates g, which the caller has checked with clvr_grid_inside. The
 * lower corner is clamped to n-2 so that g = n-1 takes the last cell with weight 1. At most
 * 2^32 - 1 grid points. */
float clvr_trilinear(global const float* v, const int4 dims, const float3 g)
{
    const int i = min((int)g.x, dims.x - 2);
    const int j = min((int)g.y, dims.y - 2);
    const int k = min((int)g.z, dims.z - 2);
    const float fx = g.x - (float)i, fy = g.y - (float)j, fz = g.z - (float)k;
    /* 32-bit index arithmetic (cheaper than size_t per sample); the host allows at most 2^32 - 1
     * grid points. */
    const uint nx = (uint)dims.x;
    const uint nxy = nx * (uint)dims.y;
    global const float* p = v + ((uint)k * nxy + (uint)j * nx + (uint)i);
    const float2 a00 = vload2(0, p), a10 = vload2(0, p + nx);  /* (i, i+1) pairs, x fastest */
    const float2 a01 = vload2(0, p + nxy), a11 = vload2(0, p + nxy + nx);
    const float c00 = a00.x + fx * (a00.y - a00.x);
    const float c10 = a10.x + fx * (a10.y - a10.x);
    const float c01 = a01.x + fx * (a01.y - a01.x);
    const float c11 = a11.x + fx * (a11.y - a11.x);
    const float c0 = c00 + fy * (c10 - c00);
    const float c1 = c01 + fy * (c11 - c01);
    return c0 + fz * (c1 - c0);
}

/* Trilinear RGBA at grid coordinates g inside [0, n-1] (checked or clamped by the caller), the four channels
 * of a grid point together and filtered as one texture: the (gradient, value) volumes of planes and blend
 * (seeds/004), iso3d's (normal, value) volume (seeds/000 §3), stack2d's RGBA stacks (seeds/003). Lower
 * corner clamped to n-2 as clvr_trilinear does. At most 2^32 - 1 grid points. */
float4 clvr_trilinear4(global const float4* v, const int4 dims, const float3 g)
{
    const int i = min((int)g.x, dims.x - 2);
    const int j = min((int)g.y, dims.y - 2);
    const int k = min((int)g.z, dims.z - 2);
    const float fx = g.x - (float)i, fy = g.y - (float)j, fz = g.z - (float)k;
    const uint nx = (uint)dims.x;
    const uint nxy = nx * (uint)dims.y;
    global const float4* p = v + ((uint)k * nxy + (uint)j * nx + (uint)i);
    const float4 c00 = mix(p[0], p[1], fx), c10 = mix(p[nx], p[nx + 1], fx);
    const float4 c01 = mix(p[nxy], p[nxy + 1], fx), c11 = mix(p[nxy + nx], p[nxy + nx + 1], fx);
    return mix(mix(c00, c10, fy), mix(c01, c11, fy), fz);
}

/* The same for volumes stored in their native integer type (1 or 2 bytes per grid point): the
 * conversion of each grid value to float is exact, so the result equals clvr_trilinear on the same
 * values stored as float, bit for bit. */
#define CLVR_TRILINEAR_INT(name, T)                                                                 \
    float name(global const T* v, const int4 dims, const float3 g)                                 \
    {                                                                                               \
        const int i = min((int)g.x, dims.x - 2);                                                    \
        const int j = min((int)g.y, dims.y - 2);                                                    \
        const int k = min((int)g.z, dims.z - 2);                                                    \
        const float fx = g.x - (float)i, fy = g.y - (float)j, fz = g.z - (float)k;                  \
        const uint nx = (uint)dims.x;                                                               \
        const uint nxy = nx * (uint)dims.y;                                                         \
        global const T* p = v + ((uint)k * nxy + (uint)j * nx + (uint)i);                          \
        const float2 a00 = convert_float2(vload2(0, p)), a10 = convert_float2(vload2(0, p + nx));   \
        const float2 a01 = convert_float2(vload2(0, p + nxy));                                      \
        const float2 a11 = convert_float2(vload2(0, p + nxy + nx));                                 \
        const float c00 = a00.x + fx * (a00.y - a00.x);                                             \
        const float c10 = a10.x + fx * (a10.y - a10.x);                                             \
        const float c01 = a01.x + fx * (a01.y - a01.x);                                             \
        const float c11 = a11.x + fx * (a11.y - a11.x);                                             \
        const float c0 = c00 + fy * (c10 - c00);                                                    \
        const float c1 = c01 + fy * (c11 - c01);                                                    \
        return c0 + fz * (c1 - c0);                                                                 \
    }
CLVR_TRILINEAR_INT(clvr_trilinear_uchar, uchar)
CLVR_TRILINEAR_INT(clvr_trilinear_ushort, ushort)
#undef CLVR_TRILINEAR_INT

#endif
