// kernels/stack2d.cl — fragment program of the 2D texture stacks (seeds/003_e49ee09fcdafadac.txt;
// host/render/stack2d.cpp, docs/stack2d.md). The host appends this file, with CLVR_STACK2D_FRAGMENT
// defined, after kernels/raster.cl; compiled on its own (the offline syntax test) it pulls in
// raster.cl itself, so that the fragment program is checked in the context it runs in.
// The host has validated everything; this file only does arithmetic.
#include "transfer_function.h"
#include "reflectance_map.h"
#ifndef CLVR_STACK2D_FRAGMENT
#include "raster.cl"
#endif

/* One fragment of a stack quad (direct volume rendering; iso-surfaces below). attr[0] = (u, v, lower, weight): the 2D texture coordinates on the
 * slice (texel i of n centered at (i + 0.5) / n, so grid point i is texel i), the stack slice to
 * sample and the weight of slice lower + 1 (0 on a stack slice itself); attr[1].x = the slab's
 * thickness along the stack axis, world units. All but (u, v) are constant over a quad.
 * uniforms: 0..3 camera position, forward, right, up; 4 (tan(view_angle / 2) or parallel_scale,
 * aspect, 1 if parallel, 0); 5 (image width, height, tf_count, 0); 6 the stack axis as a unit vector;
 * 7 (texture width, height, channels, 0) of one slice; 8 (reflectance map n, 1 if shaded, 0, 0);
 * 9 the unit vector towards the eye (-forward); 10 (data minimum, 1 if iso-surface, ambient, diffuse);
 * 11 (surface color, 1 if gradient-shaded); 12 (unit vector towards the light, 1 / (data range)):
 * iso-surfaces only. buffer[0] the stack (slices one after another, x
 * fastest): 1 channel, the value, returned as (v, v, v, v); or, shaded, 4 channels (gradient, value)
 * from host/gradient_volume.h. buffer[1] the transfer function (transfer_function.h); buffer[2] the
 * reflectance map (reflectance_map.h), shaded only.
 * Sample: bilinear in each slice; an intermediate slice lerps two bilinear samples, the paper's
 * register-combiner step, which makes the sample (and the gradient) trilinear. Classified after
 * interpolation; shaded, the color is C times the map's shade of the interpolated gradient (the
 * model of host/reflectance_map.h, as planes and blend; tau is not shaded);
 * alpha = 1 - exp(-tau Delta) with Delta the ray's length through the slab, thickness / |cos| of
 * the angle between the pixel's ray and the axis. Output premultiplied (C alpha, alpha). */
int clvr_fragment(const ClFragment* f, const ClFragmentResources* r, float4* color)
{
    /* Iso-surface mode (the paper's fast shaded iso-surfaces): output (shaded color, value mapped to
     * [0, 1] over the data range, as the paper's 8-bit alpha); the draw's alpha test (GEQUAL the
     * iso-value mapped alike) keeps the fragments inside the surface, and back-to-front drawing
     * without blending leaves the front-most one. Diffuse shading with the two-sided normal of the
     * interpolated gradient: ambient + diffuse max(0, N.L), N turned to face the viewer. */
    constant float4* u = r->uniforms;
    ClTexture slice;
    slice.width = (cl_uint)u[7].x;
    slice.height = (cl_uint)u[7].y;
    slice.depth = 1u;
    slice.channels = (cl_uint)u[7].z;
    slice.filter = CLVR_FILTER_LINEAR;
    slice.wrap = CLVR_WRAP_CLAMP_TO_EDGE;
    slice.pad0 = slice.pad1 = 0u;
    slice.border = (float4)(0.0f);
    const size_t texels = (size_t)slice.width * slice.height * slice.channels;
    /* lower and weight are interpolated constants: round lower, take weight as it comes (its
     * rounding error is a few ulp) */
    const int lower = (int)round(f->attr[0].z);
    const float weight = f->attr[0].w;
    global const float* s0 = r->buffer[0] + (size_t)lower * texels;
    float4 sample = clvr_tex2d(s0, slice, f->attr[0].xy);
    if (weight > 0.0f)
        sample = mix(sample, clvr_tex2d(s0 + texels, slice, f->attr[0].xy), weight);

    if (u[10].y != 0.0f) {
        float shade = 1.0f;
        if (u[11].w != 0.0f) {
            const float len = length(sample.xyz);
            float3 n = len > 0.0f ? sample.xyz / len : (float3)(0.0f);
            if (dot(n, u[9].xyz) < 0.0f)
                n = -n;
            shade = u[10].z + u[10].w * fmax(0.0f, dot(n, u[12].xyz));
        }
        *color = (float4)(u[11].xyz * shade, (sample.w - u[10].x) * u[12].w);
        return 1;
    }

    /* The pixel's ray direction (host/camera.cpp's Camera::ray): forward for a parallel camera, else
     * forward + x right + y up through the pixel center. */
    const float2 ndc = (float2)(f->window.x / u[5].x * 2.0f - 1.0f, 1.0f - f->window.y / u[5].y * 2.0f);
    float3 d = u[1].xyz;
    if (u[4].z == 0.0f)
        d += (ndc.x * u[4].x * u[4].y) * u[2].xyz + (ndc.y * u[4].x) * u[3].xyz;
    /* a fragment's ray meets the quad's plane, so cos_theta > 0; the floor only keeps tau = 0 times
     * an infinite Delta (a plane seen exactly edge-on, rounded) from giving NaN */
    const float cos_theta = fmax(fabs(dot(d, u[6].xyz)) / length(d), 1e-20f);
    const float delta = f->attr[1].x / cos_theta;

    const float4 ct = clvr_tf_eval(r->buffer[1], (int)u[5].z, sample.w);
    const float alpha = 1.0f - exp(-ct.w * delta);
    float3 c = ct.xyz;
    if (u[8].y != 0.0f)
        c *= clvr_reflectance((global const float4*)r->buffer[2], (int)u[8].x, sample.xyz, u[9].xyz);
    *color = (float4)(c * alpha, alpha);
    return 1;
}

/* Iso-surface mode's last pass: where a fragment passed the alpha test (stencil 1) the pixel is the
 * surface, opaque; elsewhere the background, A = 0. */
kernel void stack2d_iso_finish(global float4* color, global const uchar* stencil, const int count,
                               const float4 background)
{
    CLVR_GUARD_1D(count);
    const size_t i = get_global_id(0);
    color[i] = stencil[i] != 0 ? (float4)(color[i].xyz, 1.0f) : (float4)(background.xyz, 0.0f);
}
