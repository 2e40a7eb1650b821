// kernels/harc_entry.cl — the fragment program of HARC's entry pass (host/render/tet/harc_entry.h):
// raster::draw appends it, with CLVR_HARC_ENTRY_FRAGMENT defined, after kernels/raster.cl. One draw
// of the mesh's boundary faces per depth-peeling layer, no culling, depth test LESS: at each pixel the
// nearest face that the ray enters through (decided here from the face's plane) whose ray parameter λ
// lies beyond the previous layer's survives.
#ifdef CLVR_HARC_ENTRY_FRAGMENT
#include "harc_entry_params.h"

/* attr[0] = (position relative to the mesh origin, 0), perspective-correct; attr[1] = (code & 0xffff,
 * code >> 16, 0, 0), the same at the three corners (code = tet * 4 + face).
 * uniforms: ClHarcEntryUniforms (kernels/harc_entry_params.h).
 * buffer[0] = the previous layer's λ per pixel (-1e30 before the first); buffer[1] = the tetrahedra in
 * kernels/harc.cl's 80-byte layout.
 * λ is the parameter of harc_render's ray e + λ d through this pixel's center where it crosses the
 * face's plane, computed from the plane (b_face(e + λ d) = 0), so that it does not carry the raster
 * stage's subpixel snapping.
 * Output: (λ, code & 0xffff, code >> 16, 1), exact integers in float. */
int clvr_fragment(const ClFragment* f, const ClFragmentResources* r, float4* color)
{
    constant ClHarcEntryUniforms* u = (constant ClHarcEntryUniforms*)r->uniforms;
    const int width = (int)u->size.x;
    const ClCamera cam = u->camera;
    float3 e, d;
    clvr_ray_unit(clvr_ray_window_offset(f->window, u->size.xy, cam), cam, &e, &d);
    const int code = (int)rint(f->attr[1].x) | ((int)rint(f->attr[1].y) << 16);
    global const float4* tet = (global const float4*)r->buffer[1] + (size_t)(code >> 2) * 5;
    const int face = code & 3;
    float4 plane;
    if (face < 3)
        plane = tet[face];
    else
        plane = (float4)(-(tet[0].xyz + tet[1].xyz + tet[2].xyz), 1.0f - (tet[0].w + tet[1].w + tet[2].w));
    const float hd = dot(plane.xyz, d);
    /* Facing from the plane, not from the snapped screen-space winding: a boundary face seen nearly
     * edge-on can change winding when its corners snap to the subpixel grid, and culling it would
     * lose the ray's entry there (a grazing entry into the far tube of a torus, say). */
    if (!(hd > 0.0f))  /* b_face does not grow along d: the ray leaves (or grazes) this cell here */
        return 0;
    const float lambda = -(dot(plane.xyz, e) + plane.w) / hd;
    const int p = (int)f->window.y * width + (int)f->window.x;
    const float previous = r->buffer[0][p];
    /* Peel: strictly beyond the last layer, by a relative margin far above float rounding of λ. */
    if (!(lambda > previous + 1e-5f * (1.0f + fabs(previous))))
        return 0;
    *color = (float4)(lambda, (float)(code & 0xffff), (float)(code >> 16), 1.0f);
    return 1;
}

#else

/* Compiled on its own (the offline syntax check) this file holds only the marker below: the program
 * exists only inside raster::draw's kernel. */
typedef int clvr_harc_entry_is_a_fragment_program;

#endif
