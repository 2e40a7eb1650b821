// tools/ceiling_iso3d.h — the speed ceiling for iso3d: its fused path, kernels/iso3d.cl's iso3d_fused (each pixel's
// ray meets the view-aligned slices nearest first; the first sample inside the grid whose value passes the alpha
// test is the surface, its (normal, value) sample the fragment color), and its raster path, bricked or not (§3.1:
// per brick front to back, the slices that reach it within its scissor box, each fragment sampling the brick's own
// RGBA texture and kept only inside the brick's half-open box, the first one that passes the alpha test locking
// the pixel), then the passes after it (the shading color matrix, the finish pass) as a plain C++ loop in float
// on std::threads over rows. The fused loop skips samples in bricks the empty-space grid marks empty, one by one
// (the kernel steps over runs of them): the same samples taken and the same hits. The raster loop goes ray by ray
// through the bricks' draws and stops at the pixel's first hit, where the raster stage draws every slice fragment
// and the stencil rejects those behind a hit: its count is the fragments it tested, fewer than clvr's, so `clvr
// bench` sets the two frame times side by side. Not part of the library; tests/bench_test.cpp checks its image
// against clvr's and its samples against the fused kernel's.
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

// Whether the loop does what iso3d renders for these options and this surface: the fused path unbricked, or the
// raster path bricked or not; without the interior pass; shaded by gradient or unshaded.
bool iso3dCeilingFits(const Iso3dOptions& options, const IsoSpec& iso);

class Iso3dCeiling final : public VolumeCeiling {
public:
    // The volume and scene as iso3d renders them and the camera it uses (Session::camera).
    Iso3dCeiling(const Volume& volume, const Scene& scene, const Camera& camera, const Iso3dOptions& options);
    nlohmann::json describe() const override;

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
    // The raster path: the bricks' draws front to back, each with its brick's texture and half-open box.
    struct Draw {
        BrickDraw draw;
        std::vector<glm::vec4> texels;  // brickPoints of the RGBA volume
        glm::ivec3 dims{0};             // the brick's grid points per axis
        glm::vec3 lo{0.0f}, end{0.0f};  // its box [lo, end) in grid coordinates (end = n on the grid's last slab)
    };
    bool raster_ = false;
    MemoryBricks bricks_;
    std::vector<Draw> draws_;
};

}  // namespace clvr::tools
