// raster/fragment_state.cpp — the one place where the typed fragment state meets its device layout.
#include "raster/fragment_state.h"

#include <algorithm>
#include <cstddef>

namespace clvr::raster {

static_assert(sizeof(ClFragmentState) == 64, "also probed on the device by tests/layout_test.cpp");
static_assert(sizeof(ClBlendState) == 48, "also probed on the device by tests/layout_test.cpp");
static_assert(offsetof(ClBlendState, enabled) == 16);
static_assert(static_cast<cl_uint>(CompareFunc::Always) == CLVR_FUNC_ALWAYS);
static_assert(static_cast<cl_uint>(StencilOp::Invert) == CLVR_STENCIL_INVERT);
static_assert(static_cast<cl_uint>(BlendEquation::Max) == CLVR_BLEND_MAX);
static_assert(static_cast<cl_uint>(BlendFactor::SrcAlphaSaturate) == CLVR_FACTOR_SRC_ALPHA_SATURATE);

namespace {
cl_uint u(auto e) { return static_cast<cl_uint>(e); }
}  // namespace

ClFragmentState toCl(const FragmentState& s)
{
    ClFragmentState c{};
    c.depth_test = s.depth.test;
    c.depth_func = u(s.depth.func);
    c.depth_write = s.depth.write;
    c.stencil_test = s.stencil.test;
    c.stencil_func = u(s.stencil.func);
    c.stencil_ref = s.stencil.ref;
    c.stencil_read_mask = s.stencil.readMask;
    c.stencil_write_mask = s.stencil.writeMask;
    c.stencil_sfail = u(s.stencil.sfail);
    c.stencil_dpfail = u(s.stencil.dpfail);
    c.stencil_dppass = u(s.stencil.dppass);
    c.alpha_test = s.alpha.test;
    c.alpha_func = u(s.alpha.func);
    c.alpha_ref = std::clamp(s.alpha.ref, 0.0f, 1.0f);
    c.color_mask = (s.colorMask.r ? CLVR_MASK_R : 0u) | (s.colorMask.g ? CLVR_MASK_G : 0u) |
                   (s.colorMask.b ? CLVR_MASK_B : 0u) | (s.colorMask.a ? CLVR_MASK_A : 0u);
    return c;
}

ClBlendState toCl(const BlendState& s)
{
    ClBlendState c{};
    c.color = cl_float4{{s.constant.r, s.constant.g, s.constant.b, s.constant.a}};
    c.enabled = s.enabled;
    c.rgb_equation = u(s.rgbEquation);
    c.alpha_equation = u(s.alphaEquation);
    c.src_rgb = u(s.srcRgb);
    c.dst_rgb = u(s.dstRgb);
    c.src_alpha = u(s.srcAlpha);
    c.dst_alpha = u(s.dstAlpha);
    return c;
}

}  // namespace clvr::raster
