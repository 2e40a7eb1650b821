// kernels/planes.cl — the Planes method of seeds/004_35d3c76e603b55b1.txt (§3.1, Algorithm 1):
// resample-then-shade ray casting. Per pixel ray, samples at a fixed spacing, value and Sobel gradient
// interpolated together from the RGBA volume, classification after interpolation, the shade from the
// reflectance map, composited front to back with early ray termination and skipping of samples whose
// opacity is at most a threshold. The paper's planes (one per image row, resampled by the texture
// hardware and composited by the CPU) are the rows of this 2D launch: every ray of row y lies in the
// plane through the eye (or, parallel, along forward) and that row, and resampling and compositing are
// fused in one work-item per pixel instead of pipelined row by row.
// The host has validated everything; this file only does arithmetic.
#include "clvr_common.h"
#include "planes_params.h"
#include "ray.h"
#include "reflectance_map.h"
#include "transfer_function.h"
#include "volume_sampling.h"

/* One work-item per pixel. The chord [t0, t1] of the ray inside the box [lo, hi] (t0 >= 0) is cut into
 * count = ceil((t1 - t0) / step) equal segments of length h <= step; sample k sits at the middle of
 * segment k (the midpoint rule of host/reference/reference_integral.h's first level). Per sample:
 * alpha = 1 - exp(-tau h); if alpha <= threshold the sample is skipped before shading (counted in
 * skipped[]); else c += T alpha C shade, T *= 1 - alpha, and the ray stops once 1 - T >= ert_alpha
 * (counted in terminated[]). shade_on = 0: shade 1 (unshaded, the integral slice3d approximates).
 * The pixel is c + T background, 1 - T. samples[] counts the samples classified. */
kernel void planes_render(global float4* out, global uint* samples, global uint* skipped, global uchar* terminated,
                          global const float4* volume, global const float* tf, global const float4* map,
                          const ClPlanesParams p)
{
    CLVR_GUARD_2D(p.width, p.height);
    const int x = (int)get_global_id(0), y = (int)get_global_id(1);
    /* the values the sample loop reads, as locals */
    const int4 dims = p.dims, offset = p.part_offset;
    const float3 own_lo = p.own_lo.xyz, own_hi = p.own_hi.xyz;
    const float3 grid_origin = p.grid_origin.xyz, inv_spacing = p.inv_spacing.xyz, to_eye = p.to_eye.xyz;
    const int tf_count = p.tf_count, map_n = p.map_n, shade_on = p.shade_on;
    const float ert_alpha = p.ert_alpha, threshold = p.threshold;
    /* The ray through the pixel center, origin o and unit direction d (kernels/ray.h). */
    const float2 size = (float2)((float)p.width, (float)p.height);
    float3 o, d;
    clvr_ray_unit(clvr_ray_window_offset(clvr_ray_pixel_centre(x, y), size, p.camera), p.camera, &o, &d);

    /* Slab test against the box: t0 >= 0 keeps only what lies in front of the camera. */
    float t0 = 0.0f, t1 = INFINITY;
    for (int a = 0; a < 3; ++a) {
        const float oa = a == 0 ? o.x : (a == 1 ? o.y : o.z);
        const float da = a == 0 ? d.x : (a == 1 ? d.y : d.z);
        const float lo = a == 0 ? p.box_lo.x : (a == 1 ? p.box_lo.y : p.box_lo.z);
        const float hi = a == 0 ? p.box_hi.x : (a == 1 ? p.box_hi.y : p.box_hi.z);
        if (da == 0.0f) {
            if (oa < lo || oa > hi)
                t1 = -INFINITY;
            continue;
        }
        const float ta = (lo - oa) / da, tb = (hi - oa) / da;
        t0 = fmax(t0, fmin(ta, tb));
        t1 = fmin(t1, fmax(ta, tb));
    }

    float3 c = (float3)(0.0f);
    float transmittance = 1.0f;
    uint taken = 0, below = 0;
    uchar stopped = 0;
    if (t1 > t0) {
        const int count = max(1, (int)ceil((t1 - t0) / p.step));
        const float h = (t1 - t0) / (float)count;
        const float neg_h_log2e = -h * M_LOG2E_F; /* exp(-tau h) = exp2(tau * this) */
        const float3 last = convert_float3(p.full_dims.xyz - 1);
        for (int k = 0; k < count; ++k) {
            const float3 q = o + (t0 + ((float)k + 0.5f) * h) * d;
            /* inside the box by construction; the clamp absorbs float rounding at its faces */
            const float3 g = clamp((q - grid_origin) * inv_spacing, (float3)(0.0f), last);
            if (!clvr_grid_owned(g, own_lo, own_hi)) /* another part's sample (sort-last) */
                continue;
            const float4 s = clvr_trilinear4(volume, dims, clvr_grid_local(g, offset));
            const float4 ct = clvr_tf_eval(tf, tf_count, s.w);
            ++taken;
            const float alpha = 1.0f - exp2(ct.w * neg_h_log2e);
            if (alpha <= threshold) { /* the paper's low-opacity skip: no shading, no compositing */
                ++below;
                continue;
            }
            const float3 shade = shade_on ? clvr_reflectance(map, map_n, s.xyz, to_eye) : (float3)(1.0f);
            c += (transmittance * alpha) * (ct.xyz * shade);
            transmittance *= 1.0f - alpha;
            if (1.0f - transmittance >= ert_alpha) {
                stopped = 1;
                break;
            }
        }
    }
    const int i = y * p.width + x;
    out[i] = (float4)(c + transmittance * p.background.xyz, 1.0f - transmittance);
    samples[i] = taken;
    skipped[i] = below;
    terminated[i] = stopped;
}
