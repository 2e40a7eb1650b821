// kernels/stack2d.cl — fragment program of the 2D texture stacks (seeds/003_e49ee09fcdafadac.txt;
// host/render/grid/stack2d.cpp, docs/stack2d.md). The host appends this file, with CLVR_STACK2D_FRAGMENT
// defined, after kernels/raster.cl; compiled on its own (the offline syntax test) it pulls in
// raster.cl itself, so that the fragment program is checked in the context it runs in.
// The host has validated everything; this file only does arithmetic.
#include "clip_texture.h"
#include "transfer_function.h"
#include "reflectance_map.h"
#ifndef CLVR_STACK2D_FRAGMENT
#include "raster.cl"
#endif

/* One fragment of a stack quad (direct volume rendering; iso-surfaces below). attr[0] = (u, v, lower, weight): the 2D texture coordinates on the
 * slice (texel i of n centered at (i + 0.5) / n, so grid point i is texel i), the stack slice to
 * sample and the weight of slice lower + 1 (0 on a stack slice itself); attr[1] = (the slab's
 * thickness along the stack axis in world units, first, count, 0): count 0 for one slice per quad,
 * else the quad stands for slices first .. first + count - 1 of the table in buffer[3] (several
 * slices per polygon, below). All but (u, v) are constant over a quad.
 * uniforms: 0..3 camera position, forward, right, up; 4 (tan(view_angle / 2) or parallel_scale,
 * aspect, 1 if parallel, 0); 5 (image width, height, tf_count, 0); 6 the stack axis as a unit vector;
 * 7 (texture width, height, channels, 0) of one slice; 8 (reflectance map n, 1 if shaded, 0, 0);
 * 9 the unit vector towards the eye (-forward); 10 (data minimum, 1 if iso-surface, ambient, diffuse);
 * 11 (surface color, 1 if gradient-shaded); 12 (unit vector towards the light, 1 / (data range)):
 * iso-surfaces only; several slices per polygon only: 13, 14 unit vectors along the slice's texture
 * axes b and c; 15 (box min b, min c, max b, max c), world; 16 (u, v at the box min, u, v at the
 * box max); 17 (the alpha test's reference, 0, 0, 0). buffer[0] the stack (slices one after another, x
 * fastest): 1 channel, the value, returned as (v, v, v, v); or, shaded, 4 channels (gradient, value)
 * from host/optics/gradient_volume.h. buffer[1] the transfer function (transfer_function.h); buffer[2] the
 * reflectance map (reflectance_map.h), shaded only; buffer[3] the slice table (float4 per slice:
 * world coordinate on the axis, lower, weight, thickness), several slices per polygon only, followed
 * by the clip texture's texels (clip textures, below: uniforms 18..22, attr[2]).
 * Sample: bilinear in each slice; an intermediate slice lerps two bilinear samples, the paper's
 * register-combiner step, which makes the sample (and the gradient) trilinear. Classified after
 * interpolation; shaded, the color is C times the map's shade of the interpolated gradient (the
 * model of host/optics/reflectance_map.h, as planes and blend; tau is not shaded);
 * alpha = 1 - exp(-tau Delta) with Delta the ray's length through the slab, thickness / |cos| of
 * the angle between the pixel's ray and the axis. Output premultiplied (C alpha, alpha). */

/* Clip texture (seeds/003, "Clipping with arbitrary clipping geometry"; host/optics/clip_texture.h, as
 * slice3d): with CLVR_STACK2D_CLIP_TEXTURE defined, a second, one-channel texture (negative inside,
 * linear filtering, clamp to edge) decides per sample whether it is drawn. uniforms 18 (width,
 * height, depth, 1 if inverse), 19..21 the rows of world -> clip-texture coordinates
 * (clipTextureCoordinates), 22 (offset of the texels in buffer[3], in floats, 0, 0, 0); buffer[3]
 * holds the slice table (several slices per polygon; empty otherwise) followed by the texels. One
 * slice per quad: attr[2] = the clip-texture coordinates of the fragment's point on the slice
 * (perspective-correct; affine in the point, so exact up to rounding), and a clipped fragment is
 * discarded. Several slices per polygon: the coordinates of the ray's hit point p on each slice,
 * a clipped sample skipped. Iso-surfaces: a clipped sample is no hit. */
#ifdef CLVR_STACK2D_CLIP_TEXTURE
/* clvr_clip_keep (clip_texture.h) on the clip texture behind the slice table in buffer[3]. */
static int stack2d_clip_keep(const ClFragmentResources* r, const float3 uc)
{
    constant float4* u = r->uniforms;
    return clvr_clip_keep(r->buffer[3] + (size_t)u[22].x, clvr_clip_texture(u[18]), uc, (int)u[18].w);
}

/* World point p -> clip-texture coordinates (uniforms 19..21, affine). */
static float3 stack2d_clip_coordinates(constant float4* u, const float3 p)
{
    return (float3)(dot(u[19].xyz, p) + u[19].w, dot(u[20].xyz, p) + u[20].w, dot(u[21].xyz, p) + u[21].w);
}
#endif

/* The stack's slices as one 2D texture each (uniform 7). */
static ClTexture stack2d_slice_texture(constant float4* u)
{
    ClTexture slice;
    slice.width = (cl_uint)u[7].x;
    slice.height = (cl_uint)u[7].y;
    slice.depth = 1u;
    slice.channels = (cl_uint)u[7].z;
    slice.filter = CLVR_FILTER_LINEAR;
    slice.wrap = CLVR_WRAP_CLAMP_TO_EDGE;
    slice.pad0 = slice.pad1 = 0u;
    slice.border = (float4)(0.0f);
    return slice;
}

/* The bilinear sample of stack slice `lower` at uv, lerped towards slice lower + 1 by weight > 0. */
static float4 stack2d_fetch(global const float* stack, const ClTexture slice, int lower, float weight, float2 uv)
{
    const size_t texels = (size_t)slice.width * slice.height * slice.channels;
    global const float* s0 = stack + (size_t)lower * texels;
    float4 sample = clvr_tex2d(s0, slice, uv);
    if (weight > 0.0f)
        sample = mix(sample, clvr_tex2d(s0 + texels, slice, uv), weight);
    return sample;
}

/* Iso-surface mode: (shaded color, value mapped to [0, 1] over the data range). */
static float4 stack2d_iso_shade(constant float4* u, float4 sample)
{
    float shade = 1.0f;
    if (u[11].w != 0.0f) {
        const float len = length(sample.xyz);
        float3 n = len > 0.0f ? sample.xyz / len : (float3)(0.0f);
        if (dot(n, u[9].xyz) < 0.0f)
            n = -n;
        shade = u[10].z + u[10].w * fmax(0.0f, dot(n, u[12].xyz));
    }
    return (float4)(u[11].xyz * shade, (sample.w - u[10].x) * u[12].w);
}

/* Direct volume rendering: the premultiplied color of a sample standing for a ray length delta. */
static float4 stack2d_classify(const ClFragmentResources* r, float4 sample, float delta)
{
    constant float4* u = r->uniforms;
    const float4 ct = clvr_tf_eval(r->buffer[1], (int)u[5].z, sample.w);
    const float alpha = 1.0f - exp(-ct.w * delta);
    float3 c = ct.xyz;
    if (u[8].y != 0.0f)
        c *= clvr_reflectance((global const float4*)r->buffer[2], (int)u[8].x, sample.xyz, u[9].xyz);
    return (float4)(c * alpha, alpha);
}

int clvr_fragment(const ClFragment* f, const ClFragmentResources* r, float4* color)
{
    /* Iso-surface mode (the paper's fast shaded iso-surfaces): output (shaded color, value mapped to
     * [0, 1] over the data range, as the paper's 8-bit alpha); the draw's alpha test (GEQUAL the
     * iso-value mapped alike) keeps the fragments inside the surface, and back-to-front drawing
     * without blending leaves the front-most one. Diffuse shading with the two-sided normal of the
     * interpolated gradient: ambient + diffuse max(0, N.L), N turned to face the viewer. */
    constant float4* u = r->uniforms;
    const ClTexture slice = stack2d_slice_texture(u);
    const bool iso = u[10].y != 0.0f;

    /* The pixel's ray (host/model/camera.cpp's PixelRays): from the camera through the pixel center, or for
     * a parallel camera from the pixel's point on the image plane along forward. */
    const float2 ndc = (float2)(f->window.x / u[5].x * 2.0f - 1.0f, 1.0f - f->window.y / u[5].y * 2.0f);
    const float3 offset = (ndc.x * u[4].x * u[4].y) * u[2].xyz + (ndc.y * u[4].x) * u[3].xyz;
    const bool parallel = u[4].z != 0.0f;
    const float3 d = parallel ? u[1].xyz : u[1].xyz + offset;
    /* a fragment's ray meets the quad's plane, so cos_theta > 0; the floor only keeps tau = 0 times
     * an infinite Delta (a plane seen exactly edge-on, rounded) from giving NaN */
    const float cos_theta = fmax(fabs(dot(d, u[6].xyz)) / length(d), 1e-20f);

    const int count = (int)round(f->attr[1].z);
    if (count == 0) {
        /* One slice per quad: lower and weight are interpolated constants: round lower, take weight as
         * it comes (its rounding error is a few ulp). */
#ifdef CLVR_STACK2D_CLIP_TEXTURE
        if (!stack2d_clip_keep(r, f->attr[2].xyz))
            return 0;
#endif
        const float4 sample =
            stack2d_fetch(r->buffer[0], slice, (int)round(f->attr[0].z), f->attr[0].w, f->attr[0].xy);
        *color = iso ? stack2d_iso_shade(u, sample) : stack2d_classify(r, sample, f->attr[1].x / cos_theta);
        return 1;
    }

    /* Several slices per polygon (seeds/003, "mapping the textures of multiple slice images onto a
     * single polygon"): this quad stands for `count` consecutive slices of the drawing order, table
     * entries first .. first + count - 1 of buffer[3] (world coordinate on the axis, lower, weight,
     * thickness), back to front; it lies in the front-most slice's plane, enlarged to cover where
     * every one of them is seen. Each slice is sampled where the pixel's ray meets its plane (texture
     * coordinates from uniforms 13..16), skipped where that point is outside the box, and the samples
     * are composited back to front inside the fragment — "over" is associative, so the blended
     * result is that of one quad per slice. Iso-surfaces keep the front-most sample at or above the
     * iso-value (alpha reference u[17].x), as the alpha test and the drawing order would. */
    const float3 origin = parallel ? u[0].xyz + offset : u[0].xyz;
    const float da = dot(d, u[6].xyz), oa = dot(origin, u[6].xyz);
    global const float4* table = (global const float4*)r->buffer[3];
    const int first = (int)round(f->attr[1].y);
    float4 out = (float4)(0.0f);
    float4 iso_fallback = (float4)(0.0f, 0.0f, 0.0f, -1.0f);
    bool iso_hit = false;
    for (int j = first; j < first + count; ++j) {
        const float4 e = table[j];
        const float t = (e.x - oa) / da;
        if (!(t > 0.0f))
            continue;
        const float3 p = origin + t * d;
        const float2 bc = (float2)(dot(p, u[13].xyz), dot(p, u[14].xyz));
        if (bc.x < u[15].x || bc.x > u[15].z || bc.y < u[15].y || bc.y > u[15].w)
            continue;
#ifdef CLVR_STACK2D_CLIP_TEXTURE
        if (!stack2d_clip_keep(r, stack2d_clip_coordinates(u, p)))
            continue;
#endif
        const float2 uv = u[16].xy + (bc - u[15].xy) / (u[15].zw - u[15].xy) * (u[16].zw - u[16].xy);
        const float4 sample = stack2d_fetch(r->buffer[0], slice, (int)e.y, e.z, uv);
        if (iso) {
            const float4 shaded = stack2d_iso_shade(u, sample);
            if (shaded.w >= u[17].x) {
                out = shaded;
                iso_hit = true;
            } else if (!iso_hit) {
                iso_fallback = shaded;
            }
        } else {
            const float4 s = stack2d_classify(r, sample, e.w / cos_theta);
            out = s + (1.0f - s.w) * out;
        }
    }
    *color = iso && !iso_hit ? iso_fallback : out;
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
