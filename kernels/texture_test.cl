// kernels/texture_test.cl — samples a texture at given coordinates, and probes ClTexture's layout;
// used only by tests/texture_test.cpp.
#include "clvr_common.h"
#include "texture.h"

// out[i] = the texture sampled at coords[i] (.x for 1D, .xy for 2D, .xyz for 3D).
kernel void texture_sample(global const float* texels, const ClTexture t, const uint dimensions,
                           global const float4* coords, global float4* out, const uint n)
{
    CLVR_GUARD_1D(n);
    const size_t i = get_global_id(0);
    const float4 c = coords[i];
    if (dimensions == 1u)
        out[i] = clvr_tex1d(texels, t, c.x);
    else if (dimensions == 2u)
        out[i] = clvr_tex2d(texels, t, c.xy);
    else
        out[i] = clvr_tex3d(texels, t, c);
}

// sizeof(ClTexture) and the byte offsets of channels, filter and border, as the device sees them.
kernel void texture_layout(global uint* out)
{
    ClTexture t;
    private char* base = (private char*)&t;
    out[0] = (uint)sizeof(ClTexture);
    out[1] = (uint)((private char*)&t.channels - base);
    out[2] = (uint)((private char*)&t.filter - base);
    out[3] = (uint)((private char*)&t.border - base);
}
