// raster/reference/pixel_transfer.cpp — GL 1.2 imaging pixel transfer, draw-pixels, pixel texture
// and accumulation buffer in double precision.
#include "raster/reference/pixel_transfer.h"

#include "host/runtime/errors.h"
#include "raster/reference/texture.h"

#include <algorithm>
#include <cmath>

namespace clvr::raster::reference {
namespace {

double lookup(double c, const std::vector<float>& table)
{
    const std::size_t n = table.size();
    if (n == 1)
        return table[0];
    const double x = (std::isnan(c) ? 0.0 : std::clamp(c, 0.0, 1.0)) * double(n - 1);
    const double i0 = std::min(std::floor(x), double(n - 2));
    const std::size_t i = static_cast<std::size_t>(i0);
    return table[i] + (x - i0) * (double(table[i + 1]) - table[i]);
}

glm::dvec4 blendPixel(glm::dvec4 s, glm::dvec4 d, DrawPixelsBlend blend)
{
    switch (blend) {
    case DrawPixelsBlend::Add: return s + d;
    case DrawPixelsBlend::Subtract: return s - d;
    case DrawPixelsBlend::ReverseSubtract: return d - s;
    case DrawPixelsBlend::Min: return glm::min(s, d);
    case DrawPixelsBlend::Max: return glm::max(s, d);
    case DrawPixelsBlend::Replace: break;
    }
    return s;
}

glm::dvec4 sample3d(const TextureData& t, glm::dvec4 c)
{
    return sampleTexture(t.desc, t.texels, glm::dvec3(c), 3);
}

}  // namespace

Image4d toDouble(const Image4f& image)
{
    Image4d out(image.width(), image.height());
    for (std::size_t i = 0; i < image.pixelCount(); ++i)
        out.pixels()[i] = glm::dvec4(image.pixels()[i]);
    return out;
}

glm::dvec4 pixelTransfer(glm::dvec4 c, const PixelTransfer& xf)
{
    validate(xf);
    const glm::dmat4 m(xf.colorMatrix);
    glm::dvec4 r = glm::dvec4(xf.bias) + glm::dvec4(xf.scale) * (m * c);
    if (xf.lookup)
        for (int k = 0; k < 4; ++k)
            if (!(*xf.lookup)[k].empty())
                r[k] = lookup(r[k], (*xf.lookup)[k]);
    return r;
}

Image4d pixelTransfer(const Image4d& image, const PixelTransfer& xf)
{
    Image4d out(image.width(), image.height());
    for (std::size_t i = 0; i < image.pixelCount(); ++i)
        out.pixels()[i] = pixelTransfer(image.pixels()[i], xf);
    return out;
}

Image4d pixelTransfer(const Image4f& image, const PixelTransfer& xf)
{
    return pixelTransfer(toDouble(image), xf);
}

Image4d drawPixels(const Image4d& dst, const Image4f& src, glm::ivec2 offset, const PixelTransfer& xf,
                   DrawPixelsBlend blend, const TextureData* pixelTexture)
{
    Image4d out = dst;
    for (int y = 0; y < src.height(); ++y)
        for (int x = 0; x < src.width(); ++x) {
            const long dx = long(x) + offset.x, dy = long(y) + offset.y;
            if (dx < 0 || dy < 0 || dx >= dst.width() || dy >= dst.height())
                continue;
            glm::dvec4 s = pixelTransfer(glm::dvec4(src.at(x, y)), xf);
            if (pixelTexture)
                s = sample3d(*pixelTexture, s);
            glm::dvec4& d = out.at(int(dx), int(dy));
            d = blendPixel(s, d, blend);
        }
    return out;
}

Image4d pixelTexture(const Image4d& color, const TextureData& texture3d)
{
    Image4d out(color.width(), color.height());
    for (std::size_t i = 0; i < color.pixelCount(); ++i)
        out.pixels()[i] = sample3d(texture3d, color.pixels()[i]);
    return out;
}

Image4d pixelTexture(const Image4f& color, const TextureData& texture3d)
{
    return pixelTexture(toDouble(color), texture3d);
}

void accumulate(Image4d& color, Image4d& accum, AccumOp op, double value)
{
    if (color.pixelCount() != accum.pixelCount())
        throw InternalError("accumulate: color and accumulation planes differ in size");
    for (std::size_t i = 0; i < color.pixelCount(); ++i) {
        glm::dvec4& c = color.pixels()[i];
        glm::dvec4& a = accum.pixels()[i];
        switch (op) {
        case AccumOp::Accum: a += value * c; break;
        case AccumOp::Load: a = value * c; break;
        case AccumOp::Return: c = value * a; break;
        case AccumOp::Mult: a *= value; break;
        case AccumOp::Add: a += glm::dvec4(value); break;
        }
    }
}

}  // namespace clvr::raster::reference
