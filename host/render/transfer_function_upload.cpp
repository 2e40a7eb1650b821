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

}  // namespace clvr
