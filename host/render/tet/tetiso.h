// host/render/tet/tetiso.h — shaded iso-surfaces of tetrahedral grids from cell faces (seeds/000 §4.1,
// Figure 8), with interval bit-streams (§4.3). No traversal, no polygons: the raster stage draws the
// faces of the cells the iso-value can cut, with the vertex scalar as color.
//  a. weights: back faces, alpha test GREATER iso and depth test LESS keep the nearest face past the
//     surface, the stencil set there; that image is kept (glCopyPixels); front faces, alpha test LEQUAL
//     iso, where the stencil is set and only the face of the same cell (the paper's stencil lock, here a
//     cell-id test against the kept image) — then q = (iso - S_f) / (S_b - S_f) per pixel. The same with
//     the alpha tests inverted finds the first crossing downwards; the nearer of the two is the surface;
//  b. shading: the same draws with Gouraud-shaded colors (vertex normals = averaged cell gradients, one
//     directional light, the headlight by default) instead of scalars;
//  c. the pixel is (1 - q) I_f + q I_b, summed in the accumulation buffer (or (I_f + I_b) / 2: the
//     paper's equal blending, Figure 9 left).
// docs/tetiso.md.
#pragma once

#include "host/model/mesh.h"
#include "host/render/renderer.h"
#include "host/render/tet/harc.h"

#include <glm/glm.hpp>
#include <nlohmann/json.hpp>

#include <cstdint>
#include <memory>
#include <optional>
#include <vector>

namespace clvr {

struct TetisoOptions {
    enum class Weights { Interpolated, Equal };
    Weights weights = Weights::Interpolated;  // "weights": "interpolated" (Figure 8) or "equal" (Figure 9, left)
    int intervals = 64;                       // "intervals": bit-streams over the normalized value range (raster path)
    // "path": "fused" (default): harc's cell walk stops each ray at its first crossing of the iso-value and
    // shades it as the face draws would (host/render/tet/harc.h, Integration::Iso); "raster": the paper's
    // face draws and per-pixel passes through the raster stage.
    enum class Path { Fused, Raster };
    Path path = Path::Fused;
    // Fused path: 8 neighbouring pixels' walks per work-item as vector lanes (harc's packets; the same bits).
    // Unset: on CPU devices only (packetsOnDevice, host/render/options_util.h).
    std::optional<bool> packets;
};

// Its registry entry (host/render/renderer.h).
TechniqueInfo tetisoTechnique();

// Reads the scene's "options" for tetiso. InputError naming the key for unknown keys, wrong types and
// values out of range.
TetisoOptions parseTetisoOptions(const nlohmann::json& options);

// Interval bit-streams (§4.3): the value range [lo, hi] split into `intervals` equal intervals; for each,
// a stream of ceil(N/8) bytes with bit c set when cell c's vertex values are neither all below nor all
// above the interval, stored run-length encoded (runs of zero bytes, then literal bytes); an interval
// with no cell stores nothing.
class IntervalBitStreams {
public:
    // cellMin[c] <= cellMax[c]: cell c's smallest and largest vertex value. intervals >= 1.
    IntervalBitStreams(const std::vector<double>& cellMin, const std::vector<double>& cellMax, double lo, double hi,
                       int intervals);

    int intervals() const { return static_cast<int>(streams_.size()); }
    std::size_t cellCount() const { return cells_; }
    // The interval holding `value` (values outside [lo, hi] clamp to the first or last).
    int intervalOf(double value) const;
    // The cells whose bit is set in interval i, ascending.
    std::vector<std::uint32_t> cells(int interval) const;
    // Bytes of the encoded streams (runs and literal bytes), all intervals; the unencoded streams would
    // take intervals * ceil(N/8).
    std::uint64_t encodedBytes() const;
    int emptyIntervals() const;

private:
    struct Run {
        std::uint32_t zeroBytes;  // bytes with no bit set, skipped
        std::uint32_t literals;   // then this many bytes from `bytes`
    };
    struct Stream {
        std::vector<Run> runs;
        std::vector<std::uint8_t> bytes;
    };
    std::vector<Stream> streams_;
    std::size_t cells_ = 0;
    double lo_ = 0.0, hi_ = 1.0;
};

// Per point of `mesh`, the average of the gradients of the cells that share it (the paper's vertex
// gradients; a cell's gradient is exact for its linear field). Zero-volume cells add nothing.
std::vector<glm::dvec3> averagedVertexGradients(const TetMesh& mesh);

// Renderer for "tetiso" on a mesh that checkMesh() has normalized; the scene needs an "iso". InputError
// for bad options, a missing "iso", "shading": "gradientless", an empty mesh or more than 2^24 cells.
class TetisoRenderer : public Renderer {
public:
    // Eye depth (distance to the image plane along the view direction) of the surface per pixel, row 0 at
    // the top, +infinity where no surface was found: (1 - q) z_f + q z_b of the last frame. Reads the
    // device's weights back (a frame does not), as iso3d's hitDepth() reads its depth buffer.
    virtual std::vector<double> hitDepth() = 0;
};
std::unique_ptr<TetisoRenderer> makeTetisoRenderer(Device& device, const Scene& scene, const TetMesh& mesh);

// The fused path's walk (harc with HarcOptions::Integration::Iso): the scene's iso-value, the mesh's vertex normals,
// the light for the scene's view of the mesh box, the shading and weights, `packets` as the options say. What the
// fused renderer hands harc, and what tools/ceiling_harc.h walks for tetiso scenes.
HarcOptions tetisoWalkOptions(const Scene& scene, const TetMesh& mesh);

}  // namespace clvr
