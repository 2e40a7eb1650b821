// raster/texture.h — 1D/2D/3D float textures on the device (DESIGN.md, raster stage: Textures).
// Typed GL-like state on the host; ClTexture (kernels/texture.h) is its flat device form, sampled by
// clvr_tex1d/2d/3d with GL's nearest/linear filtering and clamp-to-edge/clamp-to-border wrapping.
#pragma once

#include "host/runtime/device.h"
#include "kernels/texture.h"

#include <glm/glm.hpp>

#include <cstdint>
#include <vector>

namespace clvr::raster {

enum class Filter : std::uint32_t { Nearest = CLVR_FILTER_NEAREST, Linear = CLVR_FILTER_LINEAR };
enum class Wrap : std::uint32_t { ClampToEdge = CLVR_WRAP_CLAMP_TO_EDGE, ClampToBorder = CLVR_WRAP_CLAMP_TO_BORDER };

// A texture's shape and sampling state. 1D: height = depth = 1; 2D: depth = 1. channels is 1 (sampled
// as (v, v, v, v), GL's INTENSITY) or 4 (RGBA). The same filter is used for magnification and
// minification (no mipmaps). border: the CLAMP_TO_BORDER color.
struct TextureDesc {
    int width = 1, height = 1, depth = 1, channels = 1;
    Filter filter = Filter::Linear;
    Wrap wrap = Wrap::ClampToEdge;
    glm::vec4 border{0.0f};
};

// Throws InputError unless every size is in 1..65536 (sizes can come from a data file), and
// InternalError unless channels is 1 or 4, filter and wrap are known values and texelCount ==
// width * height * depth * channels (the caller's own description).
void validate(const TextureDesc& desc, std::size_t texelCount);

// The texels live in one read-only device buffer: float, x fastest, then y, then z, channels interleaved.
class Texture {
public:
    // Validates (InputError, InternalError), then uploads (DeviceError if the device cannot hold it).
    Texture(Device& device, const TextureDesc& desc, const std::vector<float>& texels);

    const TextureDesc& desc() const { return desc_; }
    cl::Buffer& buffer() { return buffer_; }
    const cl::Buffer& buffer() const { return buffer_; }
    ClTexture toCl() const;
    std::uint64_t bytes() const { return bytes_; }  // device memory held by the texels

private:
    TextureDesc desc_;
    cl::Buffer buffer_;
    std::uint64_t bytes_ = 0;
};

ClTexture toCl(const TextureDesc& desc);

}  // namespace clvr::raster
