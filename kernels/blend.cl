// kernels/blend.cl — the Blend method of seeds/004_35d3c76e603b55b1.txt (§3.2, Algorithm 2): slices
// parallel to the image plane, back to front; each slice's samples (value and Sobel gradient from the RGBA
// volume) are classified, those with opacity above the threshold shaded through the reflectance map (the
// rest written clear), and the shaded slice blended "over" into the frame. The paper's two buffers (slice
// of shaded samples, frame buffer) are fused here: one work-item per pixel walks all slices.
// The host has validated everything; this file only does arithmetic.
#include "blend_params.h"
#include "clvr_common.h"
#include "ray.h"
#include "reflectance_map.h"
#include "transfer_function.h"
#include "volume_sampling.h"

/* One work-item per pixel. The pixel's ray is o + z d with z the eye depth (dot(d, forward) = 1: d =
 * forward + sx right + sy up for perspective, forward for parallel with o on the image plane), so slice k
 * at eye depth depth0 + (k + 0.5) delta_s is met at o + z_k d and a slice stands for a ray length
 * delta = delta_s |d|. Slices from the farthest (slice_count - 1) to the nearest; only samples inside the
 * grid (and, for a sort-last part, its own: clvr_grid_owned) count (samples[]). alpha = 1 - exp(-tau
 * delta); alpha <= threshold: clear (skipped[], not shaded);
 * else c = C shade alpha + (1 - alpha) c, A = alpha + (1 - alpha) A. Pixel c + (1 - A) background, A. */
kernel void blend_render(global float4* out, global uint* samples, global uint* skipped,
                         global const float4* volume, global const float* tf, global const float4* map,
                         const ClBlendParams p)
{
    CLVR_GUARD_2D(p.width, p.height);
    const int x = (int)get_global_id(0), y = (int)get_global_id(1);
    const int4 dims = p.dims, offset = p.part_offset;
    const float3 own_lo = p.own_lo.xyz, own_hi = p.own_hi.xyz;
    const float depth0 = p.depth0, delta_s = p.delta_s, threshold = p.threshold;
    const int tf_count = p.tf_count, map_n = p.map_n, shade_on = p.shade_on;
    const float3 to_eye = p.to_eye.xyz;
    const float2 size = (float2)((float)p.width, (float)p.height);
    const float2 s = clvr_ray_window_offset(clvr_ray_pixel_centre(x, y), size, p.camera);
    float3 o, d;
    clvr_ray_depth(s, p.camera, &o, &d);
    const float delta = delta_s * clvr_ray_stretch(s, p.camera);
    const float neg_delta_log2e = -delta * M_LOG2E_F; /* exp(-tau delta) = exp2(tau * this) */
    const float3 go = (o - p.grid_origin.xyz) * p.inv_spacing.xyz; /* grid coordinates */
    const float3 gd = d * p.inv_spacing.xyz;

    float3 c = (float3)(0.0f);
    float alpha_acc = 0.0f;
    uint taken = 0, below = 0;
    for (int k = p.slice_count - 1; k >= 0; --k) {
        const float3 g = go + (depth0 + ((float)k + 0.5f) * delta_s) * gd;
        if (!clvr_grid_owned(g, own_lo, own_hi)) /* outside the grid, or another part's (sort-last) */
            continue;
        ++taken;
        const float4 v = clvr_trilinear4(volume, dims, clvr_grid_local(g, offset));
        const float4 ct = clvr_tf_eval(tf, tf_count, v.w);
        const float alpha = 1.0f - exp2(ct.w * neg_delta_log2e);
        if (alpha <= threshold) { /* written clear: blending it changes nothing */
            ++below;
            continue;
        }
        const float3 shade = shade_on ? clvr_reflectance(map, map_n, v.xyz, to_eye) : (float3)(1.0f);
        c = (ct.xyz * shade) * alpha + (1.0f - alpha) * c;
        alpha_acc = alpha + (1.0f - alpha) * alpha_acc;
    }
    const int i = y * p.width + x;
    out[i] = (float4)(c + (1.0f - alpha_acc) * p.background.xyz, alpha_acc);
    samples[i] = taken;
    skipped[i] = below;
}
