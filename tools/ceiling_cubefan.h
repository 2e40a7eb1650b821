// tools/ceiling_cubefan.h — the speed ceiling for cubefan's fused path: kernels/cubefan.cl's cubefan_fused (each
// pixel's ray walks the selected cubes voxel to voxel through the selection grid: a transparent cube, or the cube
// of empty bricks around it, stepped over; a cube that adds color, its chord's alpha = 1 - exp(-tau l) at the
// cube's value, "over" front to back) as a plain C++ loop over the same grid (host/render/grid/cubefan.h's
// buildCubefanWalkGrid), in float, on std::threads over rows. `clvr bench` times it interleaved with clvr on
// cubefan scenes with the fused path and reports clvr's cubes crossed per second as a fraction of its
// (docs/benchmarks.md). Not part of the library; tests/bench_test.cpp checks its image and cubes against the kernel's.
#pragma once

#include "host/model/camera.h"
#include "host/model/image.h"
#include "host/model/scene.h"
#include "host/model/transfer_function.h"
#include "host/model/volume.h"
#include "host/render/grid/cubefan.h"
#include "tools/ceiling.h"

#include <glm/glm.hpp>

#include <cstdint>
#include <vector>

namespace clvr::tools {

class CubefanCeiling final : public VolumeCeiling {
public:
    // The volume and options as cubefan renders them, the camera it uses (Session::camera), the image. The octree
    // and the selection are built here (not timed).
    CubefanCeiling(const Volume& volume, const TransferFunction& tf, const Camera& camera, const ImageSpec& image,
                   const CubefanOptions& options);
    nlohmann::json describe() const override { return {{"error", error_}, {"cubes", cubes_}}; }

private:
    // The cubes that add color crossed in row y (cubefan's stats.samples).
    std::uint64_t renderRow(int y, Image4f& image) const override;

    Camera camera_;       // relative to shift_
    glm::vec3 fieldLo_, invSpacing_, background_;
    glm::ivec3 dims_, filledLo_, filledHi_;
    CubefanWalkGrid walk_;
    std::vector<float> tfS_;         // the control points' s, increasing
    std::vector<glm::vec4> tfValue_; // their (r, g, b, tau)
    float ertAlpha_;
    double error_;
    std::uint64_t cubes_ = 0;
};

}  // namespace clvr::tools
