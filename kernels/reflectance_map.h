/* kernels/reflectance_map.h — shading of volume samples on the device (§2.2-2.3 of
 * seeds/004_35d3c76e603b55b1.txt): trilinear reconstruction of the RGBA volume (gradient, value) and
 * the reflectance-map lookup. The map's layout and cube-face convention are host/optics/reflectance_map.h's:
 * 6 n^2 float4 entries (rgb = shade), entry 6 n^2 = the shade of a zero gradient. OpenCL C 1.2. */
#ifndef CLVR_REFLECTANCE_MAP_H
#define CLVR_REFLECTANCE_MAP_H

/* Trilinear (gx, gy, gz, value) at grid coordinates g inside [0, n-1] (checked or clamped by the caller);
 * lower corner clamped to n-2 as clvr_trilinear does. At most 2^32 - 1 grid points. */
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

/* The map's shade of gradient grad seen along to_eye (unit): the normal turned to face the viewer
 * (two-sided), normalized by its largest component |N_a| (no square root needed: the patch depends only on
 * the ratios), face 2a + (N_a < 0), patch (i, j) of the other two axes (a+1)%3, (a+2)%3. */
float3 clvr_reflectance(global const float4* map, const int n, const float3 grad, const float3 to_eye)
{
    const float3 N = dot(grad, to_eye) < 0.0f ? -grad : grad;
    const float3 a = fabs(N);
    uint index;
    if (a.x == 0.0f && a.y == 0.0f && a.z == 0.0f) {
        index = 6u * (uint)n * (uint)n;
    } else {
        int face;
        float u, v, m;
        if (a.x >= a.y && a.x >= a.z) {
            face = N.x < 0.0f ? 1 : 0; m = a.x; u = N.y; v = N.z;
        } else if (a.y >= a.z) {
            face = N.y < 0.0f ? 3 : 2; m = a.y; u = N.z; v = N.x;
        } else {
            face = N.z < 0.0f ? 5 : 4; m = a.z; u = N.x; v = N.y;
        }
        const float half_n = 0.5f * (float)n;
        const int i = min((int)((u / m + 1.0f) * half_n), n - 1);
        const int j = min((int)((v / m + 1.0f) * half_n), n - 1);
        index = ((uint)face * (uint)n + (uint)j) * (uint)n + (uint)i;
    }
    return map[index].xyz;
}

#endif
