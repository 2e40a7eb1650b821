// raster/texture.cpp — validation, packing and upload of textures.
#include "raster/texture.h"

#include "host/runtime/errors.h"

#include <string>

namespace clvr::raster {

static_assert(sizeof(ClTexture) == 48, "also probed on the device by tests/texture_test.cpp");

void validate(const TextureDesc& d, std::size_t texelCount)
{
    const auto size = [](int n) { return n >= 1 && n <= 65536; };
    const std::string shape = std::to_string(d.width) + "x" + std::to_string(d.height) + "x" +
                              std::to_string(d.depth) + " x " + std::to_string(d.channels) + " channels";
    if (!size(d.width) || !size(d.height) || !size(d.depth))
        throw InputError("texture size " + shape + ": every size must be in 1..65536");
    if (d.channels != 1 && d.channels != 4)
        throw InternalError("texture " + shape + ": channels must be 1 or 4");
    if (d.filter != Filter::Nearest && d.filter != Filter::Linear)
        throw InternalError("texture filter " + std::to_string(static_cast<std::uint32_t>(d.filter)) + " is unknown");
    if (d.wrap != Wrap::ClampToEdge && d.wrap != Wrap::ClampToBorder)
        throw InternalError("texture wrap " + std::to_string(static_cast<std::uint32_t>(d.wrap)) + " is unknown");
    const std::uint64_t want = static_cast<std::uint64_t>(d.width) * d.height * d.depth * d.channels;
    if (want != texelCount)
        throw InternalError("texture " + shape + " needs " + std::to_string(want) + " floats, got " +
                         std::to_string(texelCount));
}

ClTexture toCl(const TextureDesc& d)
{
    ClTexture t{};
    t.width = static_cast<cl_uint>(d.width);
    t.height = static_cast<cl_uint>(d.height);
    t.depth = static_cast<cl_uint>(d.depth);
    t.channels = static_cast<cl_uint>(d.channels);
    t.filter = static_cast<cl_uint>(d.filter);
    t.wrap = static_cast<cl_uint>(d.wrap);
    t.border = cl_float4{{d.border.r, d.border.g, d.border.b, d.border.a}};
    return t;
}

Texture::Texture(Device& device, const TextureDesc& desc, const std::vector<float>& texels) : desc_(desc)
{
    validate(desc, texels.size());
    bytes_ = texels.size() * sizeof(float);
    buffer_ = device.upload("texture", texels, CL_MEM_READ_ONLY);
}

ClTexture Texture::toCl() const
{
    return raster::toCl(desc_);
}

}  // namespace clvr::raster
