// host/render/transfer_function_upload.h — the transfer function on the device: packed as
// kernels/transfer_function.h lays it out, uploaded, and counted in a renderer's resident bytes.
// Every technique that classifies on the device keeps one TransferFunctionUpload.
#pragma once

#include "host/runtime/device.h"
#include "host/model/transfer_function.h"

#include <CL/opencl.hpp>

#include <cstdint>
#include <string>
#include <vector>

namespace clvr {

// The transfer function as kernels/transfer_function.h lays it out: n control points s_i, their
// (r, g, b, tau) and the slopes of the segments, n + pad + 8n floats.
std::vector<float> packTransferFunction(const TransferFunction& tf);

// True when the device's evaluation of the packed transfer function (clvr_tf_eval, float control
// points) gives tau exactly 0 for every x in [lo, hi]: all control points whose segments the interval
// touches have tau 0 (then the slopes are 0 too), including the clamped ends.
bool tauZeroOn(const TransferFunction& tf, float lo, float hi);

// One packed transfer function resident on the device; upload() replaces it (a renderer's
// setTransferFunction), keeping its buffer, control-point count and byte count together.
class TransferFunctionUpload {
public:
    // Packs and uploads tf into a buffer named `what` (Device::upload). An empty transfer function
    // (iso-surface scenes may have none) becomes one float that no kernel reads (4 bytes).
    void upload(Device& device, const std::string& what, const TransferFunction& tf);

    const cl::Buffer& buffer() const { return buffer_; }
    int count() const { return count_; }                // control points: the kernels' tf_count
    std::uint64_t bytes() const { return bytes_; }      // resident on the device
    // Replaces the upload and adds the change in bytes to `residentBytes`.
    void replace(Device& device, const std::string& what, const TransferFunction& tf, std::uint64_t& residentBytes);

private:
    cl::Buffer buffer_;
    int count_ = 0;
    std::uint64_t bytes_ = 0;
};

}  // namespace clvr
