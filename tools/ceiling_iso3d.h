// tools/ceiling_iso3d.h — the speed ceiling for iso3d's fused path: kernels/iso3d.cl's iso3d_fused (each pixel's ray
// meets the view-aligned slices nearest first; the first sample inside the grid whose value passes the alpha test
// is the surface, its (normal, value) sample the fragment color) and the passes after it (the shading color
// matrix, the finish pass) as a plain C++ loop in float on std::threads over rows. Samples in bricks the empty-space
// grid marks empty are not taken, one by one (the kernel steps over runs of them): the same samples taken and the
// same hits. `clvr bench` times it interleaved with clvr on iso3d scenes with the fused path, unbricked, shaded by
// gradient or unshaded, without the interior pass (iso3dCeilingFits), and reports clvr's samples taken per second as
// a fraction of its. Not part of the library; tests/bench_test.cpp checks its image and samples against clvr's.
#pragma once

#include "host/model/camera.h"
#include "host/model/image.h"
#include "host/model/scene.h"
#include "host/model/volume.h"
#include "host/render/grid/iso3d.h"
#include "host/render/slice_plan.h"
#include "raster/pixel_transfer.h"
#include "tools/ceiling.h"

#include <glm/glm.hpp>

#include <cstdint>
#include <vector>

namespace clvr::tools {

// Whether the loop does what iso3d renders for these options and this surface.
bool iso3dCeilingFits(const Iso3dOptions& options, const IsoSpec& iso);

class Iso3dCeiling final : public VolumeCeiling {
public:
    // The volume and scene as iso3d renders them and the camera it uses (Session::camera).
    Iso3dCeiling(const Volume& volume, const Scene& scene, const Camera& camera, const Iso3dOptions& options);
    nlohmann::json describe() const override { return {{"slices", plan_.count}, {"iso_value", iso_.value}}; }

private:
    // Row y; returns the samples taken.
    std::uint64_t renderRow(int y, Image4f& image) const override;

    const Volume& volume_;
    Camera camera_;
    SlicePlan plan_;
    IsoSurface iso_;
    raster::PixelTransfer shading_;  // isoShadingTransfer (gradient shading)
    std::vector<glm::vec4> rgba_;    // encodedNormalVolume
    std::vector<std::uint8_t> space_;
    glm::ivec3 brickDims_{0};
    bool skip_ = false;              // empty_space_skipping and an empty brick
    glm::vec3 origin_, invSpacing_, background_;
    float valueLo_ = 0.0f, valueScale_ = 1.0f, alphaRef_ = 0.0f;
};

}  // namespace clvr::tools
