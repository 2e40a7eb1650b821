// host/reference/image_error.h — how far an image is from a reference: per channel (r, g, b, a) the largest
// and the mean absolute difference over the pixels. The tests judge every renderer by it
// (tests/support/test_util.h: imagesNear), and `clvr bench --reference` reports it.
#pragma once

#include "host/model/image.h"

#include <glm/glm.hpp>

#include <cstddef>

namespace clvr {

struct ImageError {
    glm::dvec4 maxAbs{0.0};
    glm::dvec4 meanAbs{0.0};
    std::size_t nanCount = 0;  // channel values that were NaN (left out of max and mean)
};

// Over the pixels both images have (the caller checks the sizes).
ImageError imageError(const Image4f& actual, const Image4d& expected);

}  // namespace clvr
