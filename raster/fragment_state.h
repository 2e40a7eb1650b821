// raster/fragment_state.h — GL's per-fragment state, typed, with GL's defaults (DESIGN.md, raster
// stage). toCl() flattens it into the layouts of kernels/raster_state.h.
#pragma once

#include "kernels/raster_state.h"

#include <glm/glm.hpp>

#include <cstdint>

namespace clvr::raster {

enum class CompareFunc : std::uint32_t { Never, Less, Equal, LEqual, Greater, NotEqual, GEqual, Always };
enum class StencilOp : std::uint32_t { Keep, Zero, Replace, Incr, IncrWrap, Decr, DecrWrap, Invert };
enum class BlendEquation : std::uint32_t { Add, Subtract, ReverseSubtract, Min, Max };
enum class BlendFactor : std::uint32_t {
    Zero, One, SrcColor, OneMinusSrcColor, DstColor, OneMinusDstColor, SrcAlpha, OneMinusSrcAlpha,
    DstAlpha, OneMinusDstAlpha, ConstantColor, OneMinusConstantColor, ConstantAlpha, OneMinusConstantAlpha,
    SrcAlphaSaturate
};
enum class CullFace : std::uint32_t { None, Front, Back, FrontAndBack };

struct AlphaState {                  // glAlphaFunc; the fragment passes if alpha <func> ref
    bool test = false;
    CompareFunc func = CompareFunc::Always;
    float ref = 0.0f;                // clamped to [0,1] as GL does
};

struct StencilState {                // glStencilFunc + glStencilMask + glStencilOp
    bool test = false;
    CompareFunc func = CompareFunc::Always;  // passes if (ref & readMask) <func> (stencil & readMask)
    std::uint8_t ref = 0, readMask = 0xff, writeMask = 0xff;
    StencilOp sfail = StencilOp::Keep, dpfail = StencilOp::Keep, dppass = StencilOp::Keep;
};

struct DepthState {                  // passes if fragment depth <func> stored depth
    bool test = false;
    CompareFunc func = CompareFunc::Less;
    bool write = true;               // glDepthMask; only with the test enabled, as GL
};

struct BlendState {                  // glBlendEquationSeparate + glBlendFuncSeparate + glBlendColor
    bool enabled = false;
    BlendEquation rgbEquation = BlendEquation::Add, alphaEquation = BlendEquation::Add;
    BlendFactor srcRgb = BlendFactor::One, dstRgb = BlendFactor::Zero;
    BlendFactor srcAlpha = BlendFactor::One, dstAlpha = BlendFactor::Zero;
    glm::vec4 constant{0.0f};
};

// Back-to-front compositing of premultiplied colors, "over": dst = src + (1 - src.a) dst on every channel
// (GL_ONE, GL_ONE_MINUS_SRC_ALPHA, enabled).
inline BlendState premultipliedOver()
{
    BlendState b;
    b.enabled = true;
    b.srcRgb = b.srcAlpha = BlendFactor::One;
    b.dstRgb = b.dstAlpha = BlendFactor::OneMinusSrcAlpha;
    return b;
}

struct ColorMask {                   // glColorMask
    bool r = true, g = true, b = true, a = true;
};

struct FragmentState {
    AlphaState alpha;
    StencilState stencil;
    DepthState depth;
    BlendState blend;
    ColorMask colorMask;
    CullFace cull = CullFace::None;  // glCullFace, None = GL_CULL_FACE disabled
    bool frontFaceCCW = true;        // glFrontFace(GL_CCW): counter-clockwise on screen, y up
};

ClFragmentState toCl(const FragmentState& s);
ClBlendState toCl(const BlendState& s);

}  // namespace clvr::raster
