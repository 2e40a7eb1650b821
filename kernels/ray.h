/* kernels/ray.h — pixel -> ray for the cameras of DESIGN.md (perspective and parallel; rays through
 * pixel centres; image row 0 at the top), as host/model/camera.cpp's PixelRays::at computes them in double.
 * Compiled as OpenCL C (the ray functions) and as C++ (the ClCamera layout only; the host packs it in
 * host/render/camera_args.h). Sizes and offsets are probed on the device by tests/layout_test.cpp.
 *
 * Every kernel that casts rays takes them from here. The float expressions are the ones the kernels
 * had, statement for statement: OpenCL C contracts a * b + c into one fused multiply-add only inside
 * one expression (FP_CONTRACT is on by default; PoCL fuses them on this machine), so where a value is
 * split into statements, and the order of the sums, decide the rounding. Three forms exist, each kept
 * because changing it changes images:
 *  - clvr_ray_depth / clvr_ray_unit: position + s.x right + s.y up, or forward + s.x right + s.y up,
 *    in one expression (slice3d, blend, planes, harc, harc_entry);
 *  - clvr_ray_offset_first: the image-plane offset s.x right + s.y up as one expression first, then
 *    added to position or forward (stack2d's fragment program);
 *  - clvr_ray_rounded_terms: s.x right and s.y up rounded apart, then summed: position + (R + U),
 *    (forward + R) + U (spherical_shell). */
#ifndef CLVR_RAY_H
#define CLVR_RAY_H

#include "cl_types.h"  /* cl_uint, cl_float4, ... on both sides */

/* The camera as rays need it: an orthonormal frame and the image plane's extent. */
typedef struct {
    cl_float4 position; /* world (or relative to a renderer's shifted origin); w: the band's first row y0 */
    cl_float4 forward;  /* unit vector; w: the full image's height H for a band, 0 for the whole image */
    cl_float4 right, up; /* unit vectors, w = 0 */
    cl_float4 params;   /* (scale, aspect = width / height of the full image, 1 if parallel else 0, 0), scale =
                         * tan(view_angle / 2) for perspective, parallel_scale for parallel */
} ClCamera;             /* 80 bytes */

#ifdef __OPENCL_C_VERSION__

/* Normalized device coordinates of window position w (pixel (x, row) has its centre at
 * (x + 0.5, row + 0.5)), y up: row 0 is the top of the image. size = (width, height). */
float2 clvr_ray_ndc(const float2 w, const float2 size)
{
    return (float2)(w.x / size.x * 2.0f - 1.0f, 1.0f - w.y / size.y * 2.0f);
}

/* The centre of pixel (x, y) in window coordinates. */
float2 clvr_ray_pixel_centre(const int x, const int y)
{
    return (float2)((float)x + 0.5f, (float)y + 0.5f);
}

/* The image-plane offset s of ndc in units of right and up: (ndc.x scale aspect, ndc.y scale). */
float2 clvr_ray_offset(const float2 ndc, const ClCamera cam)
{
    return (float2)(ndc.x * cam.params.x * cam.params.y, ndc.y * cam.params.x);
}

/* The offset s of window position w in an image of `size` pixels. For a band of rows (sort-first: the
 * image is rows [y0, y0 + size.y) of one H rows tall, cam.position.w = y0, cam.forward.w = H) w is
 * moved to the full image's window and ndc taken there: row y0 + y's ray, bit for bit as the full
 * image computes it (y0 + w.y is exact in float). */
float2 clvr_ray_window_offset(const float2 w, const float2 size, const ClCamera cam)
{
    if (cam.forward.w > 0.0f)
        return clvr_ray_offset(clvr_ray_ndc((float2)(w.x, w.y + cam.position.w), (float2)(size.x, cam.forward.w)), cam);
    return clvr_ray_offset(clvr_ray_ndc(w, size), cam);
}

int clvr_ray_parallel(const ClCamera cam)
{
    return cam.params.z != 0.0f;
}

/* The ray o + z d with z the eye depth along forward (dot(d, forward) = 1): perspective o = position,
 * d = forward + s.x right + s.y up; parallel o = position + s.x right + s.y up, d = forward. */
void clvr_ray_depth(const float2 s, const ClCamera cam, float3* o, float3* d)
{
    if (clvr_ray_parallel(cam)) {
        *o = cam.position.xyz + s.x * cam.right.xyz + s.y * cam.up.xyz;
        *d = cam.forward.xyz;
    } else {
        *o = cam.position.xyz;
        *d = cam.forward.xyz + s.x * cam.right.xyz + s.y * cam.up.xyz;
    }
}

/* |d| of clvr_ray_depth: 1 / cos(theta) for perspective (orthonormal frame), 1 for parallel. */
float clvr_ray_stretch(const float2 s, const ClCamera cam)
{
    if (clvr_ray_parallel(cam))
        return 1.0f;
    return sqrt(1.0f + s.x * s.x + s.y * s.y);
}

/* The ray o + t d with |d| = 1 (t the distance along the ray), host/model/camera.cpp's Camera::ray. */
void clvr_ray_unit(const float2 s, const ClCamera cam, float3* o, float3* d)
{
    clvr_ray_depth(s, cam, o, d);
    if (!clvr_ray_parallel(cam))
        *d = normalize(*d);
}

/* The offset-first form: offset = s.x right + s.y up (rounded on its own), then o = position + offset
 * (parallel) and d = forward + offset (perspective; not normalized, dot(d, forward) = 1). */
void clvr_ray_offset_first(const float2 s, const ClCamera cam, float3* o, float3* d)
{
    const float3 offset = s.x * cam.right.xyz + s.y * cam.up.xyz;
    if (clvr_ray_parallel(cam)) {
        *o = cam.position.xyz + offset;
        *d = cam.forward.xyz;
    } else {
        *o = cam.position.xyz;
        *d = cam.forward.xyz + offset;
    }
}

/* The rounded-terms form: R = s.x right and U = s.y up each rounded, then o = position + (R + U)
 * (parallel) and d = normalize((forward + R) + U) (perspective; unit length). */
void clvr_ray_rounded_terms(const float2 s, const ClCamera cam, float3* o, float3* d)
{
    const float3 r = cam.right.xyz * s.x;
    const float3 u = cam.up.xyz * s.y;
    *o = cam.position.xyz;
    if (clvr_ray_parallel(cam)) {
        *o += r + u;
        *d = cam.forward.xyz;
    } else {
        *d = normalize(cam.forward.xyz + r + u);
    }
}

#endif

#endif
