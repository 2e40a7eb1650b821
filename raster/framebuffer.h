// raster/framebuffer.h — the emulated frame buffer (DESIGN.md, raster stage): planar device buffers,
// row 0 at the top. color: premultiplied RGBA float4; depth: float window depth in [0,1];
// stencil: uchar; accum: optional RGBA float4 accumulation buffer.
#pragma once

#include "host/runtime/device.h"
#include "host/model/image.h"

#include <cstdint>
#include <vector>

namespace clvr::raster {

class Framebuffer {
public:
    // InternalError unless both sizes are in 1..16384 (scenes check image sizes before); the size checks of
    // write*() and copyFrom() are InternalErrors too.
    Framebuffer(Device& device, int width, int height, bool withAccum = false);

    int width() const { return width_; }
    int height() const { return height_; }
    std::size_t pixelCount() const { return static_cast<std::size_t>(width_) * height_; }
    bool hasAccum() const { return hasAccum_; }

    cl::Buffer& color() { return color_; }      // float4 per pixel
    cl::Buffer& depth() { return depth_; }      // float per pixel
    cl::Buffer& stencil() { return stencil_; }  // uchar per pixel
    cl::Buffer& accum();                        // float4 per pixel; InternalError if created without

    // GL's clears (glClearColor/glClearDepth/glClearStencil + glClear), on the device.
    void clearColor(Device& device, glm::vec4 value);
    void clearDepth(Device& device, float value = 1.0f);
    void clearStencil(Device& device, std::uint8_t value = 0);
    void clearAccum(Device& device, glm::vec4 value = glm::vec4(0.0f));

    Image4f readColor(Device& device);
    void writeColor(Device& device, const Image4f& image);
    std::vector<float> readDepth(Device& device);
    void writeDepth(Device& device, const std::vector<float>& depth);
    std::vector<std::uint8_t> readStencil(Device& device);
    void writeStencil(Device& device, const std::vector<std::uint8_t>& stencil);
    Image4f readAccum(Device& device);

    // Copies every plane of `other` (same size) into this one (glCopyPixels of the whole buffer).
    void copyFrom(Device& device, Framebuffer& other);

private:
    int width_ = 0;
    int height_ = 0;
    bool hasAccum_ = false;
    cl::Buffer color_, depth_, stencil_, accum_;
};

}  // namespace clvr::raster
