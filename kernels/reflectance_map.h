/* kernels/reflectance_map.h — shading of volume samples on the device (§2.2-2.3 of
 * seeds/004_35d3c76e603b55b1.txt): the reflectance-map lookup of a sample's gradient (the RGBA volume
 * (gradient, value) is reconstructed by volume_sampling.h's clvr_trilinear4). The map's layout and
 * cube-face convention are host/optics/reflectance_map.h's: 6 n^2 float4 entries (rgb = shade), entry
 * 6 n^2 = the shade of a zero gradient. OpenCL C 1.2. */
#ifndef CLVR_REFLECTANCE_MAP_H
#define CLVR_REFLECTANCE_MAP_H

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
