// tools/ceiling_spherical.h — the speed ceiling for spherical's fused path: kernels/spherical.cl's
// spherical_fused (each pixel's ray meets the exact spheres front to back; per hit the (u, v) of the hit
// point by the same polynomial arctangent, the pixel transfer, the φ wrap, the trilinear fetch, the
// transfer function, the slab length, alpha = 1 - exp(-tau L), "over" front to back) as a plain C++ loop
// on std::threads over rows. `clvr bench` times it interleaved with clvr on spherical scenes and reports
// clvr's samples/s as a fraction of its (docs/benchmarks.md). Not part of the library;
// tests/bench_test.cpp checks its image and samples against the kernel's.
#pragma once

#include "host/model/camera.h"
#include "host/model/image.h"
#include "host/model/scene.h"
#include "host/model/transfer_function.h"
#include "host/model/volume.h"
#include "host/render/grid/spherical.h"
#include "tools/ceiling.h"

#include <glm/glm.hpp>

#include <cstdint>
#include <vector>

namespace clvr::tools {

class SphericalCeiling final : public VolumeCeiling {
public:
    // The volume and options as spherical renders them, the camera it uses (Session::camera), the image.
    SphericalCeiling(const Volume& volume, const TransferFunction& tf, const Camera& camera, const ImageSpec& image,
                     const SphericalOptions& options);
    nlohmann::json describe() const override { return {{"shells", shells_.size()}}; }

private:
    std::uint64_t renderRow(int y, Image4f& image) const override;

    const Volume& volume_;
    Camera camera_;
    glm::vec3 background_;
    std::vector<glm::vec4> shells_;  // (radius, r_lo, r_hi, w), as the kernel's shell table
    glm::vec3 center_;
    glm::mat4 matrix_;               // the pixel transfer with the texel-center map composed in
    glm::vec4 scale_, bias_;
    float phiS0_, phiPeriod_, ertAlpha_;
    bool radial_;
    CeilingClassifier classify_;
};

}  // namespace clvr::tools
