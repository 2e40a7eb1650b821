// host/io/image_io.h — image files through OpenImageIO. PNG: 8-bit RGB, round(clamp(x,0,1)*255), no gamma
// (DESIGN.md), opaque because the background is already composited; EXR: float RGBA. Writes go to a temporary file renamed into place, so a failure
// never leaves a partial output file.
#pragma once

#include "host/model/image.h"

#include <string>

namespace clvr {

// Writes `image` to `path`; the format follows the extension (.png, .exr). Throws InputError for an
// unsupported extension or an unwritable path.
void writeImage(const std::string& path, const Image4f& image);

// Reads any image OpenImageIO reads, as float RGBA (missing alpha = 1). Throws InputError.
Image4f readImage(const std::string& path);

// The 8-bit value DESIGN.md prescribes for a channel value x.
inline unsigned char toByte(float x)
{
    const float c = x < 0.0f ? 0.0f : (x > 1.0f ? 1.0f : x);
    return static_cast<unsigned char>(c * 255.0f + 0.5f);
}

}  // namespace clvr
