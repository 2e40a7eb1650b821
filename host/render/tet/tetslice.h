// host/render/tet/tetslice.h — direct slicing of tetrahedral grids through cell faces (seeds/000 §4.2),
// with active cell lists (§4.3). No traversal and no topology: per slice (an eye-depth plane, as
// slice3d's), the raster stage draws the back faces of the cells the slice cuts, vertex colors (scalar,
// cell id, normalized eye depth in alpha), alpha test >= the slice's depth and depth test LESS keeping
// the nearest, the stencil set where both pass; the accumulation buffer keeps that image; then the front
// faces, alpha test <= the slice, depth test GREATER keeping the farthest, only where the stencil is
// set. kernels/tetslice.cl interpolates the scalar at the slice between the two faces of one cell
// (the paper's S = (R-d)/(R-B) G + (d-B)/(R-B) alpha), classifies it and blends the slab back to front.
// The fused path ("path": "fused", the default) walks each ray through the cells instead (harc's walk) and
// samples the same slices. docs/tetslice.md.
#pragma once

#include "host/model/camera.h"
#include "host/model/mesh.h"
#include "host/render/renderer.h"
#include "host/render/tet/harc.h"

#include <nlohmann/json.hpp>

#include <cstdint>
#include <memory>
#include <optional>
#include <vector>

namespace clvr {

struct TetsliceOptions {
    int slices = 256;           // slices across the mesh box's eye-depth range ...
    double sliceSpacing = 0.0;  // ... or, when > 0, this spacing in world units (then slices is derived)
    // Raster: the face draws per slice (the paper's method, the specification). Fused: each pixel's ray walks
    // the cells through their adjacency (harc's walk, kernels/harc.cl HARC_INTEGRATION_SLICES) and samples
    // each cell's linear field at the slices inside it — the scalar the face draws interpolate.
    enum class Path { Fused, Raster };
    Path path = Path::Fused;
    // Fused path: 8 neighbouring pixels' walks per work-item as vector lanes (harc's packets; the same bits).
    // Unset: on CPU devices only (packetsOnDevice, host/render/options_util.h).
    std::optional<bool> packets;
};

// Its registry entry (host/render/renderer.h).
TechniqueInfo tetsliceTechnique();

// Reads the scene's "options" for tetslice: "slices", "slice_spacing" (as slice3d's), "path", "packets". InputError naming
// the key for unknown keys, wrong types and values out of range.
TetsliceOptions parseTetsliceOptions(const nlohmann::json& options);

// Active cell lists (§4.3) for slices k = 0 .. count-1 at eye depths depthMin + (k + 0.5) deltaS, walked
// back to front: a cell with eye-depth range [zMin, zMax] is cut by the slices in [first, last] (none
// when a thin cell lies between two slices); it is stored twice, in the start list of its farthest
// slice and the end list of its nearest, and is active from the one to the other.
class ActiveCellLists {
public:
    // zMin[c] <= zMax[c], eye depths of cell c's vertices.
    ActiveCellLists(const std::vector<double>& zMin, const std::vector<double>& zMax, double depthMin,
                    double deltaS, int count);

    // Slices from the back (k = count-1) to the front (k = 0): call next() count times; each call
    // returns the cells the next slice cuts (in a fixed order: a cell keeps its place until it leaves).
    const std::vector<std::uint32_t>& next();
    int slice() const { return k_; }  // the slice next() last returned
    std::uint64_t cellsListed() const { return listed_; }  // cells cut by at least one slice

private:
    std::vector<std::uint32_t> startAt_, startBegin_;  // CSR by slice: cells whose farthest slice is k
    std::vector<std::uint32_t> endAt_, endBegin_;      // CSR by slice: cells whose nearest slice is k
    std::vector<std::uint32_t> active_;
    std::vector<std::uint32_t> place_;                  // place_[cell] = its index in active_
    int count_ = 0, k_ = 0;
    std::uint64_t listed_ = 0;
    bool pendingEnd_ = false;
};

// Renderer for "tetslice" on a mesh that checkMesh() has normalized. InputError for bad options, an
// empty mesh or more than 2^24 cells (cell ids travel as two 12-bit halves in float channels).
std::unique_ptr<Renderer> makeTetsliceRenderer(Device& device, const Scene& scene, const TetMesh& mesh);

// The fused path's walk (harc with HarcOptions::Integration::Slices, `options.packets` passed on): the slices the
// raster path plans for the scene's view of `mesh` (its camera frame and mesh box, so the same eye depths). What
// the fused renderer hands harc, and what tools/ceiling_harc.h walks for tetslice scenes.
HarcOptions tetsliceWalkOptions(const Scene& scene, const TetMesh& mesh, const TetsliceOptions& options);

}  // namespace clvr
