// raster/pixel_transfer.cpp — validate, pack, launch, name the launch (kernels/pixel_transfer.cl).
#include "raster/pixel_transfer.h"

#include "host/runtime/errors.h"

#include <cstdint>
#include <string>

namespace clvr::raster {
namespace {

constexpr std::size_t kMaxLookup = std::size_t(1) << 20;

cl_float4 toCl(glm::vec4 v)
{
    return cl_float4{{v.x, v.y, v.z, v.w}};
}

// Sets CLVR_TRANSFER_PARAMS (kernels/pixel_transfer.cl) from argument `first` on; the lookup tables
// are uploaded into one buffer, which must outlive the launch (the caller holds it).
cl::Buffer setTransferArgs(Device& device, cl::Kernel& kernel, cl_uint first, const PixelTransfer& xf)
{
    validate(xf);
    const glm::mat4& m = xf.colorMatrix;  // glm is column-major: row r is (m[0][r], m[1][r], m[2][r], m[3][r])
    for (int r = 0; r < 4; ++r)
        kernel.setArg(first + r, toCl(glm::vec4(m[0][r], m[1][r], m[2][r], m[3][r])));
    kernel.setArg(first + 4, toCl(xf.scale));
    kernel.setArg(first + 5, toCl(xf.bias));
    std::vector<float> tables;
    cl_uint4 n{{0, 0, 0, 0}}, start{{0, 0, 0, 0}};
    if (xf.lookup)
        for (int k = 0; k < 4; ++k) {
            const std::vector<float>& t = (*xf.lookup)[k];
            start.s[k] = static_cast<cl_uint>(tables.size());
            n.s[k] = static_cast<cl_uint>(t.size());
            tables.insert(tables.end(), t.begin(), t.end());
        }
    if (tables.empty())
        tables.push_back(0.0f);  // a kernel argument needs a buffer, even an unread one
    cl::Buffer lut = device.upload("pixel transfer lookup tables", tables);
    kernel.setArg(first + 6, lut);
    kernel.setArg(first + 7, n);
    kernel.setArg(first + 8, start);
    return lut;
}

}  // namespace

void validate(const PixelTransfer& xf)
{
    if (!xf.lookup)
        return;
    for (int k = 0; k < 4; ++k)
        if ((*xf.lookup)[k].size() > kMaxLookup)
            throw InputError("pixel transfer lookup table " + std::to_string(k) + " has " +
                             std::to_string((*xf.lookup)[k].size()) + " entries, more than 2^20");
}

void applyPixelTransfer(Device& device, Framebuffer& fb, const PixelTransfer& xf)
{
    cl::Kernel kernel = device.kernel("pixel_transfer.cl", "pixel_transfer");
    kernel.setArg(0, fb.color());
    kernel.setArg(1, static_cast<cl_uint>(fb.pixelCount()));
    const cl::Buffer lut = setTransferArgs(device, kernel, 2, xf);
    device.launch("pixel transfer", kernel, fb.pixelCount());
}

void drawPixels(Device& device, Framebuffer& dst, const Image4f& src, glm::ivec2 offset, const PixelTransfer& xf,
                DrawPixelsBlend blend, const Texture* pixelTexture)
{
    if (src.width() < 1 || src.height() < 1 ||
        src.pixelCount() != static_cast<std::size_t>(src.width()) * static_cast<std::size_t>(src.height()))
        throw InternalError("draw pixels: source image " + std::to_string(src.width()) + "x" +
                         std::to_string(src.height()) + " is empty or inconsistent");
    if (static_cast<std::uint32_t>(blend) > static_cast<std::uint32_t>(DrawPixelsBlend::Max))
        throw InternalError("draw pixels: blend " + std::to_string(static_cast<std::uint32_t>(blend)) + " is unknown");
    validate(xf);
    // Entirely outside: nothing to draw (and no int overflow of x + offset.x in the kernel).
    const std::int64_t x0 = offset.x, y0 = offset.y;
    if (x0 >= dst.width() || y0 >= dst.height() || x0 + src.width() <= 0 || y0 + src.height() <= 0)
        return;
    cl::Buffer source = device.upload("draw pixels source", src.pixels());
    cl::Buffer unusedTexels;
    if (!pixelTexture)
        unusedTexels = device.buffer("draw pixels no texture", sizeof(float));
    cl::Kernel kernel = device.kernel("pixel_transfer.cl", "draw_pixels");
    kernel.setArg(0, dst.color());
    kernel.setArg(1, static_cast<cl_int>(dst.width()));
    kernel.setArg(2, static_cast<cl_int>(dst.height()));
    kernel.setArg(3, source);
    kernel.setArg(4, static_cast<cl_int>(src.width()));
    kernel.setArg(5, static_cast<cl_int>(src.height()));
    kernel.setArg(6, cl_int2{{offset.x, offset.y}});
    kernel.setArg(7, static_cast<cl_uint>(blend));
    kernel.setArg(8, static_cast<cl_uint>(pixelTexture ? 1 : 0));
    kernel.setArg(9, pixelTexture ? pixelTexture->buffer() : unusedTexels);
    kernel.setArg(10, pixelTexture ? pixelTexture->toCl() : raster::toCl(TextureDesc{}));
    const cl::Buffer lut = setTransferArgs(device, kernel, 11, xf);
    device.launch("draw pixels", kernel, static_cast<std::size_t>(src.width()), static_cast<std::size_t>(src.height()));
}

void pixelTexture(Device& device, Framebuffer& fb, const Texture& texture3d)
{
    cl::Kernel kernel = device.kernel("pixel_transfer.cl", "pixel_texture");
    kernel.setArg(0, fb.color());
    kernel.setArg(1, static_cast<cl_uint>(fb.pixelCount()));
    kernel.setArg(2, texture3d.buffer());
    kernel.setArg(3, texture3d.toCl());
    device.launch("pixel texture", kernel, fb.pixelCount());
}

void accumulate(Device& device, Framebuffer& fb, AccumOp op, float value)
{
    if (static_cast<std::uint32_t>(op) > static_cast<std::uint32_t>(AccumOp::Add))
        throw InternalError("accum op " + std::to_string(static_cast<std::uint32_t>(op)) + " is unknown");
    cl::Kernel kernel = device.kernel("pixel_transfer.cl", "accum");
    kernel.setArg(0, fb.color());
    kernel.setArg(1, fb.accum());
    kernel.setArg(2, static_cast<cl_uint>(fb.pixelCount()));
    kernel.setArg(3, static_cast<cl_uint>(op));
    kernel.setArg(4, value);
    device.launch("accum", kernel, fb.pixelCount());
}

}  // namespace clvr::raster
