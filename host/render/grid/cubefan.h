// host/render/grid/cubefan.h — hierarchical perspective volume rendering with triangle fans (seeds/002,
// Schussman & Max 2001). A regular grid becomes an octree of cubes (cube_octree.h: one cube per voxel,
// merged where the error tolerance allows); per frame the cubes within the tolerance are selected back
// to front, each is classified and projected as its class's fans and strips with the thickness l at
// every vertex (cube_fans.h), and all are drawn in that order through the raster stage
// (raster/rasterizer.h) with kernels/cubefan.cl's fragment program: alpha from the exp-opacity texture
// 1 - exp(-u v) at (l, tau) (§7), color C alpha, blended ONE, ONE_MINUS_SRC_ALPHA. docs/cubefan.md.
#pragma once

#include "host/model/transfer_function.h"
#include "host/render/grid/cube_octree.h"
#include "host/render/renderer.h"

#include <nlohmann/json.hpp>

#include <memory>
#include <optional>
#include <vector>

namespace clvr {

struct CubefanOptions {
    // Error tolerance as a fraction of the data range: a cube of the octree is drawn whole when every
    // voxel below it is within error * (max - min) of its mean (0: every voxel its own cube).
    double error = 0.0;
    // How a fragment gets its opacity: "texture" (§7: the exp-opacity texture looked up with the
    // interpolated thickness), "exp" (1 - exp(-tau l) of the interpolated thickness per fragment: the
    // texture without its table error) or "linear" (each vertex's opacity interpolated, Shirley-Tuchman).
    enum class Opacity { Texture, Exp, Linear };
    Opacity opacity = Opacity::Texture;
    int textureSize = 512;  // texels per axis of the exp-opacity texture
    // "interpolated" (§7): the thickness at the fans' vertices, interpolated across each triangle (exact
    // for parallel projection); "exact": every cube drawn as its back faces, each fragment intersecting
    // its own ray with the cube (the chord exact in perspective too; opacity 1 - exp(-tau l) per fragment,
    // so `opacity` does not apply). Cubes at the near plane are drawn that way in either mode.
    bool exactThickness = false;
    // "fused" (default): each pixel's ray walks the selected cubes in one kernel, every chord exact (the
    // image of exact thickness, without fans or the raster stage); "raster": the paper's fans through
    // the raster stage. opacity, texture_size and thickness describe the fans: one of them away from its
    // default, without a path, takes "raster".
    // "tiles": the selected cubes in the octree's visibility order for the eye (as the fans), binned to tiles of
    // kCubefanTileW x kCubefanTileH pixels by their boxes of pixel centres, each tile's rays meeting its cubes front
    // to back in one kernel (the chord exact, as the fused path's); early_termination and packets as fused. Without
    // "path" in the scene: "tiles" where error > 0, else "fused".
    enum class Path { Fused, Raster, Tiles };
    Path path = Path::Fused;
    double earlyTermination = 1.0;  // fused path: stop a ray once its opacity reaches this (1 = off)
    // Fused path: 8 neighbouring pixels per work-item, one per float8 lane (kernels/cubefan.cl's
    // cubefan_fused_packet; the same bits). Unset: on CPU devices only (packetsOnDevice, options_util.h).
    std::optional<bool> packets;
};

const char* opacityName(CubefanOptions::Opacity opacity);

// The option's value for `path` ("fused", "raster", "tiles").
const char* pathName(CubefanOptions::Path path);

// The tile path's tiles (kernels/cubefan.cl CUBEFAN_TILE_W_LOG2, _H_LOG2): 8 wide, a packet's row.
inline constexpr int kCubefanTileW = 8, kCubefanTileH = 4;


// Its registry entry (host/render/renderer.h).
TechniqueInfo cubefanTechnique();

// Reads the scene's "options" for cubefan: "error" (a number in [0, 1]), "opacity" ("texture" | "exp" |
// "linear"), "texture_size" (an integer in [2, 4096]), "thickness" ("interpolated" | "exact"), "path"
// ("fused" | "raster" | "tiles"), "early_termination" (in (0, 1], fused and tile paths), "packets" (true | false |
// null, fused and tile paths). InputError naming the key otherwise.
CubefanOptions parseCubefanOptions(const nlohmann::json& options);

// The exp-opacity texture of §7, N x N floats, x fastest: texel (i, j) = 1 - exp(-k u v) with
// u = i / (N - 1), v = j / (N - 1). With k = l_max tau_max, texel (u, v) is the opacity of a chord of
// length u l_max through extinction v tau_max.
std::vector<float> expOpacityTexels(int size, double k);

// The largest extinction the transfer function reaches (at a control point: it is piecewise linear).
double maxExtinction(const TransferFunction& tf);

// What the fused path's walk reads for one selection (kernels/cubefan.cl; tools/ceiling_cubefan.h reads the
// same): the selection grid (CubeOctree::selectGrid), per brick of 4^3 voxels (the grid's 64 entries) its
// empty-space radius — 0 where a voxel adds color, else r + 1 where every brick within Chebyshev distance r is
// transparent throughout (kernels/empty_space.h) — and the box of voxels [filledLo, filledHi) that holds every
// cube adding color (outside it the rays have nothing to walk).
struct CubefanWalkGrid {
    cubefan::CubeOctree::SelectionGrid grid;
    std::vector<std::uint8_t> space;
    glm::ivec3 filledLo{0}, filledHi{0};
    std::uint64_t emptyBricks = 0;  // bricks with nothing to add
};
CubefanWalkGrid buildCubefanWalkGrid(const cubefan::CubeOctree& octree, const glm::ivec3& dims, double tolerance,
                                     const TransferFunction& tf, cubefan::SelectionStats* stats = nullptr);

// Renderer for "cubefan". Builds the octree at set-up (its time is stats' hierarchy_ms); the volume
// itself never goes to the device. InputError for bad options.
std::unique_ptr<Renderer> makeCubefanRenderer(Device& device, const Scene& scene, const Volume& volume);

}  // namespace clvr
