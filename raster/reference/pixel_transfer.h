// raster/reference/pixel_transfer.h — the pixel operations of raster/pixel_transfer.h in double
// precision, on host images (DESIGN.md, raster stage: CPU reference). Used only by tests.
#pragma once

#include "host/model/image.h"
#include "raster/pixel_transfer.h"
#include "raster/texture.h"

#include <glm/glm.hpp>

#include <vector>

namespace clvr::raster::reference {

// A texture as the reference sees it: its state and its texels.
struct TextureData {
    TextureDesc desc;
    std::vector<float> texels;
};

// bias + scale * (colorMatrix * c), then the lookup tables (raster/pixel_transfer.h).
glm::dvec4 pixelTransfer(glm::dvec4 c, const PixelTransfer& xf);
Image4d pixelTransfer(const Image4d& image, const PixelTransfer& xf);
Image4d pixelTransfer(const Image4f& image, const PixelTransfer& xf);

// dst with src drawn at offset through xf, the optional pixel texture and `blend`.
Image4d drawPixels(const Image4d& dst, const Image4f& src, glm::ivec2 offset, const PixelTransfer& xf,
                   DrawPixelsBlend blend = DrawPixelsBlend::Replace, const TextureData* pixelTexture = nullptr);

// Every pixel's color replaced by the texture sampled in 3D at its RGB.
Image4d pixelTexture(const Image4d& color, const TextureData& texture3d);
Image4d pixelTexture(const Image4f& color, const TextureData& texture3d);

// glAccum(op, value) on the two planes, in place.
void accumulate(Image4d& color, Image4d& accum, AccumOp op, double value);

// Image4f -> Image4d, exactly.
Image4d toDouble(const Image4f& image);

}  // namespace clvr::raster::reference
