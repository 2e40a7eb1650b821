// tools/ceiling.h — the speed ceiling for slice3d: the per-sample work of its fused kernel
// (kernels/slice3d.cl: ray–slice intersection, trilinear sample from a float array, exact
// piecewise-linear transfer-function lookup, alpha = 1 - exp(-tau Delta), "over" compositing) as a
// plain C++ loop, multithreaded with std::thread over rows. clvr bench reports clvr's samples/s as
// a fraction of this loop's (docs/benchmarks.md). Not part of the library; tests/bench_test.cpp
// checks its image against host/reference/reference_integral.h.
#pragma once

#include "host/model/camera.h"
#include "host/model/image.h"
#include "host/render/grid/slice3d.h"
#include "host/model/transfer_function.h"
#include "host/model/volume.h"

#include <glm/glm.hpp>

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

class Ceiling {
public:
    Ceiling(const Volume& volume, const TransferFunction& tf, const CeilingScene& scene);
    // Renders with `threads` threads taking rows from a shared counter (<= 0: hardware_concurrency()).
    CeilingResult render(int threads = 0) const;
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
