// host/io/image_io.cpp — PNG and EXR through OpenImageIO, written atomically.
#include "host/io/image_io.h"

#include "host/runtime/errors.h"

#include <OpenImageIO/imageio.h>

#include <algorithm>
#include <cctype>
#include <cstdio>
#include <filesystem>
#include <unistd.h>

namespace clvr {
namespace {

std::string extensionOf(const std::string& path)
{
    std::string ext = std::filesystem::path(path).extension().string();
    std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return std::tolower(c); });
    return ext;
}

}  // namespace

void writeImage(const std::string& path, const Image4f& image)
{
    const std::string ext = extensionOf(path);
    if (ext != ".png" && ext != ".exr")
        throw InputError(path + ": unsupported image format \"" + ext + "\" (use .png or .exr)");
    // The temporary keeps the extension so OpenImageIO picks the right writer.
    const std::filesystem::path target(path);
    const std::filesystem::path tmp =
        target.parent_path() / (".clvr-tmp-" + std::to_string(::getpid()) + "-" + target.filename().string());

    auto out = OIIO::ImageOutput::create(tmp.string());
    if (!out)
        throw InputError(path + ": cannot create an image writer: " + OIIO::geterror());
    const int w = image.width(), h = image.height();
    bool ok = false;
    if (ext == ".png") {
        // The background is already composited (I + (1 - A) * background), so a PNG is the
        // opaque RGB picture a person looks at; EXR keeps A for tools that composite again.
        OIIO::ImageSpec spec(w, h, 3, OIIO::TypeDesc::UINT8);
        std::vector<unsigned char> bytes(static_cast<std::size_t>(w) * h * 3);
        for (std::size_t i = 0; i < image.pixelCount(); ++i)
            for (int c = 0; c < 3; ++c)
                bytes[i * 3 + c] = toByte(image.pixels()[i][c]);
        ok = out->open(tmp.string(), spec) && out->write_image(OIIO::TypeDesc::UINT8, bytes.data());
    } else {
        OIIO::ImageSpec spec(w, h, 4, OIIO::TypeDesc::FLOAT);
        ok = out->open(tmp.string(), spec) && out->write_image(OIIO::TypeDesc::FLOAT, image.pixels().data());
    }
    const std::string error = ok ? std::string() : out->geterror();
    ok = out->close() && ok;
    out.reset();
    std::error_code ec;
    if (!ok) {
        std::filesystem::remove(tmp, ec);
        // The writer names the temporary file; the user named `path`.
        std::string said = error.empty() ? "write failed" : error;
        for (std::size_t at; (at = said.find(tmp.string())) != std::string::npos;)
            said.replace(at, tmp.string().size(), path);
        throw InputError(path + ": cannot write image: " + said);
    }
    std::filesystem::rename(tmp, target, ec);
    if (ec) {
        std::filesystem::remove(tmp, ec);
        throw InputError(path + ": cannot write image: " + ec.message());
    }
}

Image4f readImage(const std::string& path)
{
    auto in = OIIO::ImageInput::open(path);
    if (!in)
        throw InputError(path + ": cannot read image: " + OIIO::geterror());
    const OIIO::ImageSpec& spec = in->spec();
    Image4f image(spec.width, spec.height, glm::vec4(0, 0, 0, 1));
    std::vector<float> data(static_cast<std::size_t>(spec.width) * spec.height * spec.nchannels);
    if (!in->read_image(0, 0, 0, spec.nchannels, OIIO::TypeDesc::FLOAT, data.data()))
        throw InputError(path + ": cannot read image: " + in->geterror());
    for (std::size_t i = 0; i < image.pixelCount(); ++i)
        for (int c = 0; c < std::min(4, spec.nchannels); ++c)
            image.pixels()[i][c] = data[i * spec.nchannels + c];
    return image;
}

}  // namespace clvr
