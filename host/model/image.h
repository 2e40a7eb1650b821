// host/model/image.h — a planar-free RGBA image in host memory, row 0 at the top.
// Image4f holds what a device renders (float), Image4d what a CPU reference computes (double).
#pragma once

#include <glm/glm.hpp>

#include <cstddef>
#include <vector>

namespace clvr {

template <typename Vec4>
class BasicImage {
public:
    BasicImage() = default;
    BasicImage(int width, int height, Vec4 fill = Vec4(0))
        : width_(width), height_(height), pixels_(static_cast<std::size_t>(width) * height, fill)
    {
    }
    int width() const { return width_; }
    int height() const { return height_; }
    std::size_t pixelCount() const { return pixels_.size(); }
    Vec4& at(int x, int y) { return pixels_[static_cast<std::size_t>(y) * width_ + x]; }
    const Vec4& at(int x, int y) const { return pixels_[static_cast<std::size_t>(y) * width_ + x]; }
    std::vector<Vec4>& pixels() { return pixels_; }
    const std::vector<Vec4>& pixels() const { return pixels_; }

private:
    int width_ = 0;
    int height_ = 0;
    std::vector<Vec4> pixels_;
};

using Image4f = BasicImage<glm::vec4>;
using Image4d = BasicImage<glm::dvec4>;

}  // namespace clvr
