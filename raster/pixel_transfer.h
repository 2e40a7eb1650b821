// raster/pixel_transfer.h — GL 1.2 imaging pixel operations on the frame buffer (DESIGN.md, raster
// stage: Pixel transfer): color matrix with scale and bias, per-channel lookup tables, draw-pixels
// with an offset and blending, SGI pixel textures, accumulation-buffer ops. Kernels:
// kernels/pixel_transfer.cl; reference: raster/reference/pixel_transfer.h.
#pragma once

#include "host/runtime/device.h"
#include "host/model/image.h"
#include "raster/framebuffer.h"
#include "raster/texture.h"

#include <glm/glm.hpp>

#include <array>
#include <cstdint>
#include <optional>
#include <vector>

namespace clvr::raster {

// Identity by default, as in GL. Per pixel c (RGBA, float):
//   c' = bias + scale * (colorMatrix * c)   (seeds/000 §2.2: b + s·CM·p; GL's color matrix followed
//                                            by the post-color-matrix scale and bias)
// then, if `lookup` is set, each channel k with a non-empty table T = (*lookup)[k] of n entries:
//   x = clamp(c'_k, 0, 1) * (n - 1),  c''_k = T[floor x] + frac(x) * (T[floor x + 1] - T[floor x])
// i.e. GL's post-color-matrix color table, but interpolated linearly between entries (GL takes the
// nearest entry); a one-entry table is a constant, an empty one leaves the channel as it is.
// Nothing is clamped to [0,1] otherwise: the color buffer is float.
struct PixelTransfer {
    glm::mat4 colorMatrix{1.0f};
    glm::vec4 scale{1.0f};
    glm::vec4 bias{0.0f};
    std::optional<std::array<std::vector<float>, 4>> lookup;
};

// Throws InputError if a lookup table has more than 2^20 entries.
void validate(const PixelTransfer& xf);

// Applies the transfer to every pixel of fb's color in place (glCopyPixels of the color buffer onto
// itself with the transfer enabled). Launch "pixel transfer".
void applyPixelTransfer(Device& device, Framebuffer& fb, const PixelTransfer& xf);

// How drawn pixels s combine with the frame buffer's d: GL blend equations with factors ONE, ONE
// (Replace: blending disabled). Not clamped.
enum class DrawPixelsBlend : std::uint32_t {
    Replace,          // s
    Add,              // s + d      (GL_FUNC_ADD)
    Subtract,         // s - d      (GL_FUNC_SUBTRACT)
    ReverseSubtract,  // d - s      (GL_FUNC_REVERSE_SUBTRACT)
    Min,              // min(s, d)  (GL_MIN; factors ignored, as in GL)
    Max,              // max(s, d)  (GL_MAX)
};

// glDrawPixels of `src` with its top-left pixel at (offset.x, offset.y) of `dst` (row 0 at the top,
// so +y moves the image down): the raster position shifted by whole pixels, the pixel bias shift of
// gradientless shading (seeds/000 §3). Each source pixel goes through `xf`, then through
// `pixelTexture` if given (its RGB used as 3D coordinates, as pixelTexture() below), then blends
// into dst's color. Pixels landing outside dst are dropped. Depth, stencil and the fragment tests
// are not involved. InternalError for an empty or inconsistent src or an unknown blend. Launch "draw pixels".
void drawPixels(Device& device, Framebuffer& dst, const Image4f& src, glm::ivec2 offset, const PixelTransfer& xf,
                DrawPixelsBlend blend = DrawPixelsBlend::Replace, const Texture* pixelTexture = nullptr);

// SGI pixel texture (seeds/000 §2.2): each pixel's RGB is a texture coordinate (s, t, r) into
// `texture3d`, sampled with its own filter and wrap (a texture of depth 1 is one slice); the texel
// (RGBA; (v, v, v, v) for one channel) replaces the pixel's color. In place. Launch "pixel texture".
void pixelTexture(Device& device, Framebuffer& fb, const Texture& texture3d);

// glAccum(op, value) on fb.accum() (GL 1.2 §4.2.4), per pixel c (color) and a (accum), RGBA:
//   Accum: a += value c    Load: a = value c    Return: c = value a    Mult: a *= value    Add: a += value
// Not clamped (GL clamps Return for fixed-point color buffers only). InternalError if fb has no
// accumulation buffer or op is unknown. Launch "accum".
enum class AccumOp : std::uint32_t { Accum, Load, Return, Mult, Add };
void accumulate(Device& device, Framebuffer& fb, AccumOp op, float value);

}  // namespace clvr::raster
