// kernels/blend.cl — the Blend method of seeds/004_35d3c76e603b55b1.txt (§3.2, Algorithm 2): slices
// parallel to the image plane, back to front; each slice's samples (value and Sobel gradient from the RGBA
// volume) are classified, those with opacity above the threshold shaded through the reflectance map (the
// rest written clear), and the shaded slice blended "over" into the frame. The paper's two buffers (slice
// of shaded samples, frame buffer) are fused here: one work-item per pixel walks all slices.
// The host has validated everything; this file only does arithmetic.
#include "clvr_common.h"
#include "reflectance_map.h"
#include "transfer_function.h"
#include "volume_sampling.h"

/* One work-item per pixel. The pixel's ray is o + z d with z the eye depth (dot(d, forward) = 1: d =
 * forward + sx right + sy up for perspective, forward for parallel with o on the image plane), so slice k
 * at eye depth depth0 + (k + 0.5) delta_s is met at o + z_k d and a slice stands for a ray length
 * delta = delta_s |d|. Slices from the farthest (slice_count - 1) to the nearest; only samples inside the
 * grid count (samples[]). alpha = 1 - exp(-tau delta); alpha <= threshold: clear (skipped[], not shaded);
 * else c = C shade alpha + (1 - alpha) c, A = alpha + (1 - alpha) A. Pixel c + (1 - A) background, A. */
kernel void blend_render(global float4* out, global uint* samples, global uint* skipped, const int width,
                         const int height, global const float4* volume, const int4 dims, const float4 grid_origin,
                         const float4 inv_spacing, global const float* tf, const int tf_count,
                         global const float4* map, const int map_n, const int shade_on, const float4 to_eye,
                         const float4 cam_position, const float4 cam_forward, const float4 cam_right,
                         const float4 cam_up, const float4 cam_params, const float depth0, const float delta_s,
                         const int slice_count, const float threshold, const float4 background)
{
    CLVR_GUARD_2D(width, height);
    const int x = (int)get_global_id(0), y = (int)get_global_id(1);
    const float ndc_x = ((float)x + 0.5f) / (float)width * 2.0f - 1.0f;
    const float ndc_y = 1.0f - ((float)y + 0.5f) / (float)height * 2.0f;
    const float sx = ndc_x * cam_params.x * cam_params.y, sy = ndc_y * cam_params.x;
    const int parallel = cam_params.z != 0.0f;
    const float3 o = parallel ? cam_position.xyz + sx * cam_right.xyz + sy * cam_up.xyz : cam_position.xyz;
    const float3 d = parallel ? cam_forward.xyz : cam_forward.xyz + sx * cam_right.xyz + sy * cam_up.xyz;
    const float delta = delta_s * (parallel ? 1.0f : sqrt(1.0f + sx * sx + sy * sy));
    const float neg_delta_log2e = -delta * M_LOG2E_F; /* exp(-tau delta) = exp2(tau * this) */
    const float3 go = (o - grid_origin.xyz) * inv_spacing.xyz; /* grid coordinates */
    const float3 gd = d * inv_spacing.xyz;

    float3 c = (float3)(0.0f);
    float alpha_acc = 0.0f;
    uint taken = 0, below = 0;
    for (int k = slice_count - 1; k >= 0; --k) {
        const float3 g = go + (depth0 + ((float)k + 0.5f) * delta_s) * gd;
        if (!clvr_grid_inside(g, dims))
            continue;
        ++taken;
        const float4 s = clvr_trilinear4(volume, dims, g);
        const float4 ct = clvr_tf_eval(tf, tf_count, s.w);
        const float alpha = 1.0f - exp2(ct.w * neg_delta_log2e);
        if (alpha <= threshold) { /* written clear: blending it changes nothing */
            ++below;
            continue;
        }
        const float3 shade = shade_on ? clvr_reflectance(map, map_n, s.xyz, to_eye.xyz) : (float3)(1.0f);
        c = (ct.xyz * shade) * alpha + (1.0f - alpha) * c;
        alpha_acc = alpha + (1.0f - alpha) * alpha_acc;
    }
    const int i = y * width + x;
    out[i] = (float4)(c + (1.0f - alpha_acc) * background.xyz, alpha_acc);
    samples[i] = taken;
    skipped[i] = below;
}
