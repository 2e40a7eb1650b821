// raster/pixel_transfer.cpp — validate, pack, launch, name the launch (kernels/pixel_transfer.cl).
#include "raster/pixel_transfer.h"

#include "host/runtime/errors.h"
#include "kernels/pixel_transfer_params.h"

#include <cstddef>
#include <cstdint>
#include <string>

namespace clvr::raster {

static_assert(sizeof(ClPixelTransfer) == 128, "also probed on the device by tests/layout_test.cpp");
static_assert(sizeof(ClPixelTransferParams) == 144, "also probed on the device by tests/layout_test.cpp");
static_assert(sizeof(ClDrawPixelsParams) == 208, "also probed on the device by tests/layout_test.cpp");
static_assert(sizeof(ClPixelTextureParams) == 64, "also probed on the device by tests/layout_test.cpp");
static_assert(sizeof(ClAccumParams) == 12, "also probed on the device by tests/layout_test.cpp");
static_assert(offsetof(ClDrawPixelsParams, tex) == 128);
static_assert(static_cast<cl_uint>(DrawPixelsBlend::ReverseSubtract) == CLVR_DRAW_REVERSE_SUBTRACT);
static_assert(static_cast<cl_uint>(DrawPixelsBlend::Max) == CLVR_DRAW_MAX);
static_assert(static_cast<cl_uint>(AccumOp::Return) == CLVR_ACCUM_RETURN);
static_assert(static_cast<cl_uint>(AccumOp::Add) == CLVR_ACCUM_ADD);

namespace {

constexpr std::size_t kMaxLookup = std::size_t(1) << 20;

cl_float4 toCl(glm::vec4 v)
{
    return cl_float4{{v.x, v.y, v.z, v.w}};
}

// The transfer as kernels/pixel_transfer_params.h lays it out, and its lookup tables concatenated in one
// buffer, which must outlive the launch (the caller holds it).
struct TransferUpload {
    ClPixelTransfer xf{};
    cl::Buffer lut;
};

TransferUpload uploadTransfer(Device& device, const PixelTransfer& xf)
{
    validate(xf);
    TransferUpload up;
    const glm::mat4& m = xf.colorMatrix;  // glm is column-major: row r is (m[0][r], m[1][r], m[2][r], m[3][r])
    for (int r = 0; r < 4; ++r)
        up.xf.matrix_row[r] = toCl(glm::vec4(m[0][r], m[1][r], m[2][r], m[3][r]));
    up.xf.scale = toCl(xf.scale);
    up.xf.bias = toCl(xf.bias);
    std::vector<float> tables;
    if (xf.lookup)
        for (int k = 0; k < 4; ++k) {
            const std::vector<float>& t = (*xf.lookup)[k];
            up.xf.lut_first.s[k] = static_cast<cl_uint>(tables.size());
            up.xf.lut_n.s[k] = static_cast<cl_uint>(t.size());
            tables.insert(tables.end(), t.begin(), t.end());
        }
    if (tables.empty())
        tables.push_back(0.0f);  // a kernel argument needs a buffer, even an unread one
    up.lut = device.upload("pixel transfer lookup tables", tables);
    return up;
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
    const TransferUpload transfer = uploadTransfer(device, xf);
    ClPixelTransferParams params{};
    params.xf = transfer.xf;
    params.n = static_cast<cl_uint>(fb.pixelCount());
    kernel.setArg(0, fb.color());
    kernel.setArg(1, transfer.lut);
    kernel.setArg(2, params);
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
    const TransferUpload transfer = uploadTransfer(device, xf);
    ClDrawPixelsParams params{};
    params.xf = transfer.xf;
    params.tex = pixelTexture ? pixelTexture->toCl() : raster::toCl(TextureDesc{});
    params.dst_width = dst.width();
    params.dst_height = dst.height();
    params.src_width = src.width();
    params.src_height = src.height();
    params.offset_x = offset.x;
    params.offset_y = offset.y;
    params.blend = static_cast<cl_uint>(blend);
    params.use_texture = pixelTexture ? 1 : 0;
    kernel.setArg(0, dst.color());
    kernel.setArg(1, source);
    kernel.setArg(2, pixelTexture ? pixelTexture->buffer() : unusedTexels);
    kernel.setArg(3, transfer.lut);
    kernel.setArg(4, params);
    device.launch("draw pixels", kernel, static_cast<std::size_t>(src.width()), static_cast<std::size_t>(src.height()));
}

void pixelTexture(Device& device, Framebuffer& fb, const Texture& texture3d)
{
    cl::Kernel kernel = device.kernel("pixel_transfer.cl", "pixel_texture");
    ClPixelTextureParams params{};
    params.tex = texture3d.toCl();
    params.n = static_cast<cl_uint>(fb.pixelCount());
    kernel.setArg(0, fb.color());
    kernel.setArg(1, texture3d.buffer());
    kernel.setArg(2, params);
    device.launch("pixel texture", kernel, fb.pixelCount());
}

void accumulate(Device& device, Framebuffer& fb, AccumOp op, float value)
{
    if (static_cast<std::uint32_t>(op) > static_cast<std::uint32_t>(AccumOp::Add))
        throw InternalError("accum op " + std::to_string(static_cast<std::uint32_t>(op)) + " is unknown");
    cl::Kernel kernel = device.kernel("pixel_transfer.cl", "accum");
    ClAccumParams params{};
    params.n = static_cast<cl_uint>(fb.pixelCount());
    params.op = static_cast<cl_uint>(op);
    params.value = value;
    kernel.setArg(0, fb.color());
    kernel.setArg(1, fb.accum());
    kernel.setArg(2, params);
    device.launch("accum", kernel, fb.pixelCount());
}

}  // namespace clvr::raster
