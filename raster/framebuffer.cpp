// raster/framebuffer.cpp — allocation, clears, read-back and copies of the frame buffer planes.
#include "raster/framebuffer.h"

#include "host/runtime/errors.h"

#include <string>

namespace clvr::raster {
namespace {

void fill(Device& device, const char* kernelName, const char* pass, cl::Buffer& buffer, auto value, std::size_t n)
{
    cl::Kernel k = device.kernel("util.cl", kernelName);
    k.setArg(0, buffer);
    k.setArg(1, value);
    k.setArg(2, static_cast<cl_uint>(n));
    device.launch(pass, k, n);
}

}  // namespace

Framebuffer::Framebuffer(Device& device, int width, int height, bool withAccum)
    : width_(width), height_(height), hasAccum_(withAccum)
{
    if (width < 1 || height < 1 || width > 16384 || height > 16384)
        throw InternalError("frame buffer size " + std::to_string(width) + "x" + std::to_string(height) +
                         " is outside 1..16384");
    const std::size_t n = pixelCount();
    color_ = device.buffer("frame buffer color", n * sizeof(cl_float4));
    depth_ = device.buffer("frame buffer depth", n * sizeof(cl_float));
    stencil_ = device.buffer("frame buffer stencil", n * sizeof(cl_uchar));
    if (withAccum)
        accum_ = device.buffer("accumulation buffer", n * sizeof(cl_float4));
}

cl::Buffer& Framebuffer::accum()
{
    if (!hasAccum_)
        throw InternalError("the frame buffer was created without an accumulation buffer");
    return accum_;
}

void Framebuffer::clearColor(Device& device, glm::vec4 value)
{
    fill(device, "fill_float4", "clear color", color_, cl_float4{{value.r, value.g, value.b, value.a}}, pixelCount());
}

void Framebuffer::clearDepth(Device& device, float value)
{
    fill(device, "fill_float", "clear depth", depth_, value, pixelCount());
}

void Framebuffer::clearStencil(Device& device, std::uint8_t value)
{
    fill(device, "fill_uchar", "clear stencil", stencil_, static_cast<cl_uchar>(value), pixelCount());
}

void Framebuffer::clearAccum(Device& device, glm::vec4 value)
{
    fill(device, "fill_float4", "clear accum", accum(), cl_float4{{value.r, value.g, value.b, value.a}},
         pixelCount());
}

Image4f Framebuffer::readColor(Device& device)
{
    Image4f image(width_, height_);
    device.queue().enqueueReadBuffer(color_, CL_TRUE, 0, pixelCount() * sizeof(cl_float4), image.pixels().data());
    return image;
}

void Framebuffer::writeColor(Device& device, const Image4f& image)
{
    if (image.width() != width_ || image.height() != height_)
        throw InternalError("writeColor: image size differs from the frame buffer");
    device.queue().enqueueWriteBuffer(color_, CL_TRUE, 0, pixelCount() * sizeof(cl_float4), image.pixels().data());
}

std::vector<float> Framebuffer::readDepth(Device& device)
{
    return device.download<float>(depth_, pixelCount());
}

void Framebuffer::writeDepth(Device& device, const std::vector<float>& depth)
{
    if (depth.size() != pixelCount())
        throw InternalError("writeDepth: size differs from the frame buffer");
    device.queue().enqueueWriteBuffer(depth_, CL_TRUE, 0, pixelCount() * sizeof(float), depth.data());
}

std::vector<std::uint8_t> Framebuffer::readStencil(Device& device)
{
    return device.download<std::uint8_t>(stencil_, pixelCount());
}

void Framebuffer::writeStencil(Device& device, const std::vector<std::uint8_t>& stencil)
{
    if (stencil.size() != pixelCount())
        throw InternalError("writeStencil: size differs from the frame buffer");
    device.queue().enqueueWriteBuffer(stencil_, CL_TRUE, 0, pixelCount(), stencil.data());
}

Image4f Framebuffer::readAccum(Device& device)
{
    Image4f image(width_, height_);
    device.queue().enqueueReadBuffer(accum(), CL_TRUE, 0, pixelCount() * sizeof(cl_float4), image.pixels().data());
    return image;
}

void Framebuffer::copyFrom(Device& device, Framebuffer& other)
{
    if (other.width_ != width_ || other.height_ != height_)
        throw InternalError("copyFrom: frame buffers differ in size");
    const std::size_t n = pixelCount();
    device.queue().enqueueCopyBuffer(other.color_, color_, 0, 0, n * sizeof(cl_float4));
    device.queue().enqueueCopyBuffer(other.depth_, depth_, 0, 0, n * sizeof(float));
    device.queue().enqueueCopyBuffer(other.stencil_, stencil_, 0, 0, n);
    if (hasAccum_ && other.hasAccum_)
        device.queue().enqueueCopyBuffer(other.accum_, accum_, 0, 0, n * sizeof(cl_float4));
}

}  // namespace clvr::raster
