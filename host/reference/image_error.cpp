// host/reference/image_error.cpp — see image_error.h.
#include "host/reference/image_error.h"

#include <algorithm>
#include <cmath>

namespace clvr {

ImageError imageError(const Image4f& actual, const Image4d& expected)
{
    ImageError e;
    const std::size_t n = std::min(actual.pixelCount(), expected.pixelCount());
    for (std::size_t i = 0; i < n; ++i) {
        for (int c = 0; c < 4; ++c) {
            const double a = actual.pixels()[i][c];
            const double d = std::abs(a - expected.pixels()[i][c]);
            if (std::isnan(a) || std::isnan(d)) {
                ++e.nanCount;
                continue;
            }
            e.maxAbs[c] = std::max(e.maxAbs[c], d);
            e.meanAbs[c] += d;
        }
    }
    if (n)
        e.meanAbs /= static_cast<double>(n);
    return e;
}

}  // namespace clvr
