// host/render/transfer_function_upload.cpp — packing (kernels/transfer_function.h's layout) and upload
// of the transfer function, with its resident-byte count.
#include "host/render/transfer_function_upload.h"

#include <glm/glm.hpp>

namespace clvr {

std::vector<float> packTransferFunction(const TransferFunction& tf)
{
    const auto& points = tf.points();
    const std::size_t n = points.size(), m = (n + 3) / 4 * 4;
    std::vector<float> out(m + 8 * n, 0.0f);
    auto value = [&](std::size_t i) { return glm::dvec4(points[i].color, points[i].tau); };
    for (std::size_t i = 0; i < n; ++i) {
        out[i] = static_cast<float>(points[i].s);
        const glm::dvec4 slope =
            i + 1 < n ? (value(i + 1) - value(i)) / (points[i + 1].s - points[i].s) : glm::dvec4(0.0);
        for (int c = 0; c < 4; ++c) {
            out[m + 4 * i + c] = static_cast<float>(value(i)[c]);
            out[m + 4 * n + 4 * i + c] = static_cast<float>(slope[c]);
        }
    }
    return out;
}

void TransferFunctionUpload::upload(Device& device, const std::string& what, const TransferFunction& tf)
{
    std::vector<float> packed = packTransferFunction(tf);
    if (packed.empty())
        packed.push_back(0.0f);  // an iso-surface scene without a transfer function: never read
    buffer_ = device.upload(what, packed);
    count_ = static_cast<int>(tf.points().size());
    bytes_ = packed.size() * sizeof(float);
}

void TransferFunctionUpload::replace(Device& device, const std::string& what, const TransferFunction& tf,
                                     std::uint64_t& residentBytes)
{
    residentBytes -= bytes_;
    upload(device, what, tf);
    residentBytes += bytes_;
}

bool tauZeroOn(const TransferFunction& tf, float lo, float hi)
{
    // The device compares x with the float control points: find the control points whose values
    // clvr_tf_eval can use for some x in [lo, hi]: from the segment holding lo (point 0 when
    // lo <= s_0) to the first point at or above hi (the last point when hi >= s_{n-1}).
    const auto& p = tf.points();
    const int n = static_cast<int>(p.size());
    auto s = [&](int i) { return static_cast<float>(p[i].s); };
    int first = 0;
    while (first + 1 < n && s(first + 1) <= lo)
        ++first;
    int last = 0;
    while (last + 1 < n && s(last) < hi)
        ++last;
    for (int i = first; i <= last; ++i)
        if (p[i].tau != 0.0)  // exactly 0 in double: then the packed slopes are exactly 0 too
            return false;
    return true;
}

}  // namespace clvr
