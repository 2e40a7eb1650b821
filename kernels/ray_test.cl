// kernels/ray_test.cl — the rays of kernels/ray.h for every pixel of an image, in each of its forms;
// used only by tests/ray_test.cpp.
#include "clvr_common.h"
#include "ray.h"

/* form 0: clvr_ray_depth, 1: clvr_ray_unit, 2: clvr_ray_offset_first, 3: clvr_ray_rounded_terms.
 * out[2 i] = (origin, stretch), out[2 i + 1] = (direction, 0) of pixel i = y width + x. */
kernel void ray_pixels(global float4* out, const ClCamera cam, const int width, const int height, const int form)
{
    CLVR_GUARD_2D(width, height);
    const int x = (int)get_global_id(0), y = (int)get_global_id(1);
    const float2 size = (float2)((float)width, (float)height);
    const float2 s = clvr_ray_window_offset(clvr_ray_pixel_centre(x, y), size, cam);
    float3 o, d;
    if (form == 0)
        clvr_ray_depth(s, cam, &o, &d);
    else if (form == 1)
        clvr_ray_unit(s, cam, &o, &d);
    else if (form == 2)
        clvr_ray_offset_first(s, cam, &o, &d);
    else
        clvr_ray_rounded_terms(s, cam, &o, &d);
    const size_t i = (size_t)y * width + x;
    out[2 * i] = (float4)(o, clvr_ray_stretch(s, cam));
    out[2 * i + 1] = (float4)(d, 0.0f);
}
