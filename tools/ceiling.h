// tools/ceiling.h — the interface of the regular-grid ceiling loops, and the speed ceiling for slice3d:
// the per-sample work of its fused kernel (kernels/slice3d.cl: ray–slice intersection, trilinear sample
// from a float array, exact piecewise-linear transfer-function lookup, alpha = 1 - exp(-tau Delta), "over"
// compositing) as a plain C++ loop, multithreaded with std::thread over rows. clvr bench reports clvr's samples/s as
// a fraction of this loop's (docs/benchmarks.md). Not part of the library; tests/bench_test.cpp
// checks its image against host/reference/reference_integral.h.
#pragma once

#include "host/model/camera.h"
#include "host/model/image.h"
#include "host/render/grid/slice3d.h"
#include "host/model/transfer_function.h"
#include "host/model/volume.h"

#include <glm/glm.hpp>
#include <nlohmann/json.hpp>

#include <cstdint>
#include <vector>

namespace clvr::tools {

struct CeilingScene {
    Camera camera;
    int width = 512, height = 512;
    glm::dvec3 background{0.0};
    Slice3dOptions options;  // slices / slice_spacing, order, early_termination as slice3d reads them
};

struct CeilingResult {
    Image4f image;              // I + (1 - A) background, alpha = A
    std::uint64_t samples = 0;  // samples taken inside the grid bounds (slice3d's stats.samples)
};

// A ceiling loop for a regular-grid technique's fused kernel (slice3d's below, spherical's in
// tools/ceiling_spherical.h): clvr bench times render() interleaved with clvr's frames.
class VolumeCeiling {
public:
    virtual ~VolumeCeiling() = default;
    // Renders with `threads` threads taking rows from a shared counter (<= 0: the thread budget, host/runtime/parallel.h).
    virtual CeilingResult render(int threads = 0) const = 0;
    // What the bench report says about the loop's work (slice3d: slices and spacing; spherical: shells).
    virtual nlohmann::json describe() const = 0;
};

class Ceiling final : public VolumeCeiling {
public:
    Ceiling(const Volume& volume, const TransferFunction& tf, const CeilingScene& scene);
    CeilingResult render(int threads = 0) const override;
    nlohmann::json describe() const override { return {{"slices", plan_.count}, {"slice_spacing", plan_.deltaS}}; }
    // The slices, as slice3d plans them (planSlices).
    const SlicePlan& plan() const { return plan_; }

private:
    std::uint64_t renderRow(int y, Image4f& image) const;

    const Volume& volume_;
    CeilingScene scene_;
    SlicePlan plan_;
    std::vector<float> tfS_;          // control points' s, increasing
    std::vector<glm::vec4> tfValue_;  // their (r, g, b, tau)
};

}  // namespace clvr::tools
