// kernels/tetslice.cl — direct slicing of tetrahedral grids through cell faces (seeds/000 §4.2),
// the passes after the raster stage's two face draws of a slice (host/render/tet/tetslice.cpp):
// the back-face draw left, in the accumulation buffer, per pixel the nearest back face at or beyond the
// slice; the front-face draw left, in the color buffer, the farthest front face at or before it. Both
// are (scalar, cell id low 12 bits, cell id high bits, eye depth); id low < 0 where no face passed.
// The last pass, I + (1 - A) background, is slice3d's (slice3d_over_background).
#include "clvr_common.h"
#include "ray.h"
#include "transfer_function.h"

#include "tetslice_params.h"

/* Per pixel: if both faces belong to one cell, the slice point d lies in that cell (a tetrahedron is
 * convex: its entry is at or before d and its exit at or beyond); its scalar is the paper's
 *     S = (R - d) / (R - B) * G + (d - B) / (R - B) * alpha
 * with R = the back face's eye depth, B = the front face's, G = the front face's scalar and alpha = the
 * back face's (the linear field along the ray between the cell's two faces). Faces of different cells
 * mean d is outside the mesh (a gap of a non-convex mesh): no sample. S goes through the transfer
 * function and the slab's opacity alpha = 1 - exp(-tau * delta_s * |d|) is blended "over" the slices
 * behind it (back to front, premultiplied). */
kernel void tetslice_composite(global float4* image, global const float4* front, global const float4* back,
                               global const float* tf, const ClTetsliceCompositeParams p)
{
    CLVR_GUARD_2D(p.width, p.height);
    const int x = (int)get_global_id(0), y = (int)get_global_id(1);
    const int i = y * p.width + x;
    const float4 b = back[i];
    const float4 f = front[i];
    if (!(b.y >= 0.0f) || !(f.y >= 0.0f))
        return;  /* no back face beyond the slice, or no front face before it */
    /* The ids are interpolated constants: within a few ulps of integers below 2^12 each. */
    if (rint(b.y) != rint(f.y) || rint(b.z) != rint(f.z))
        return;
    const float d = p.depth;
    const float R = b.w, B = f.w, G = f.x, alpha_s = b.x;
    const float span = R - B;
    const float s = span > 0.0f ? (R - d) / span * G + (d - B) / span * alpha_s : G;
    const float4 ct = clvr_tf_eval(tf, p.tf_count, s);
    const float2 size = (float2)((float)p.width, (float)p.height);
    const float2 so = clvr_ray_window_offset(clvr_ray_pixel_centre(x, y), size, p.camera);
    const float delta = p.delta_s * clvr_ray_stretch(so, p.camera);
    const float a = 1.0f - exp(-ct.w * delta);
    const float4 c = image[i];
    image[i] = (float4)(ct.xyz * a, a) + (1.0f - a) * c;
}
