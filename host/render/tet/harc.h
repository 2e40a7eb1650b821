// host/render/tet/harc.h — hardware-assisted ray casting of tetrahedral meshes with partial
// pre-integration (seeds/001_cd12fd6b76f9cf96.txt §3–4, Figure 6), kernels/harc.cl. One work-item
// per pixel walks the mesh through the cell adjacency from the first boundary front face its ray
// crosses; each cell's segment is split at the transfer function's control points and each piece is
// integrated by Eq. 2–4 (ψ from host/optics/psi_table.h); or, with "integration": "full" (HARC-Full), each
// whole segment is looked up in a 3D pre-integration table (host/optics/preintegration_table.h). Non-convex
// meshes: a per-pixel list of boundary front-face crossings sorted by depth, so a ray that leaves the
// mesh re-enters at the next one.
// docs/harc.md.
#pragma once

#include "host/model/camera.h"
#include "host/model/mesh.h"
#include "host/render/renderer.h"

#include <CL/opencl.hpp>
#include <nlohmann/json.hpp>

#include <cstdint>
#include <optional>
#include <vector>

namespace clvr {

struct HarcOptions {
    // Slices: not a harc option but tetslice's fused path (host/render/tet/tetslice.h): the walk samples the
    // cells' linear field at slices of constant eye depth sliceDepth0 + k sliceSpacing, k < sliceCount.
    // Iso: tetiso's fused path (host/render/tet/tetiso.h): the walk stops at the ray's first crossing of
    // iso.value and shades it (HarcIso).
    enum class Integration { Partial, Average, Full, Slices, Iso };
    Integration integration = Integration::Partial;
    double sliceDepth0 = 0.0, sliceSpacing = 0.0;
    int sliceCount = 0;
    struct HarcIso {
        double value = 0.0;                  // data units
        std::vector<glm::dvec3> normals;     // per mesh point, unit (or 0): interpolated barycentrically in each cell
        glm::dvec3 light{0.0, 0.0, 1.0};     // towards the light, unit; the color is the transfer function's
                                             // at the value (white without one)
        double ambient = 0.1, diffuse = 0.9;
        bool shaded = true;                  // false: the color unshaded
        bool equalWeights = false;           // the entry and exit points' shades averaged instead of weighted by q
    } iso;
    int fullScalarSamples = 64;     // "full_table": [NS, NL], the (s_f, s_b, l) table is NS x NS x NL
    int fullLengthSamples = 64;
    std::uint64_t maxSteps = 0;     // per ray; 0 = the default, 4 * cbrt(tets) + 10000
    double earlyTermination = 1.0;  // stop once A >= this; 1.0 = off (the paper's benchmarks)
    // Where the per-pixel entry lists come from: the raster stage (depth peeling of the boundary front
    // faces, host/render/tet/harc_entry.h, as seeds/001 §3-4) or exact ray/face intersection on the host.
    enum class Entry { Raster, Host };
    Entry entry = Entry::Host;
    int maxLayers = 64;  // raster entry: peeling layers per frame (1..255); rays past them are counted
    // A whole mesh (not a sort-last part), every integration: 8 neighbouring pixels per work-item, one per float8
    // lane (kernels/harc.cl's harc_render_packet; the same bits). Unset: on CPU devices only (packetsOnDevice,
    // host/render/options_util.h).
    std::optional<bool> packets;
    // The cells on the device in the mesh's own order instead of harcCellOrder's (not a scene option: the
    // tests' check that the order changes no bit, and A/B timing).
    bool meshCellOrder = false;
};

// Its registry entry (host/render/renderer.h): name, data kind, one line, options with defaults.
TechniqueInfo harcTechnique();

// Reads the scene's "options" for harc: "integration" ("partial" | "average" | "full"), "full_table"
// ([NS, NL], integers in [2, 512], at most kMaxFullTableBytes, only with "full"), "max_steps" (integer
// >= 1), "early_termination" (opacity in (0, 1]), "entry" ("raster" | "host"), "max_layers" (integer
// in [1, 255]). InputError naming the key for unknown keys, wrong
// types and values out of range.
HarcOptions parseHarcOptions(const nlohmann::json& options);

// The largest full pre-integration table "full_table" may ask for (16 bytes per entry): 256 MiB, e.g.
// 256 x 256 x 256 or 512 x 512 x 64. It is built on the host at every transfer-function change.
inline constexpr std::uint64_t kMaxFullTableBytes = std::uint64_t(256) << 20;

// The longest segment a ray can have inside one cell of the mesh: its longest tetrahedron edge (a
// tetrahedron's diameter is the distance between two of its vertices). World units; the l range of
// the full pre-integration table.
double longestTetEdge(const TetMesh& mesh);

// The box harc computes in: the bounding box of the mesh's tetrahedra, or for a part of a larger mesh
// (sort-last, host/model/mesh.h MeshPart) the full mesh's, so that the parts' images composite to the full
// one. Its centre is the origin the packed cells are relative to (packHarcTets' `shift`), for float precision.
void harcBounds(const TetMesh& mesh, glm::dvec3& lo, glm::dvec3& hi);

// Traversal steps per ray: options.maxSteps, or by default 4 cbrt(tets) + 10000 for `tets` tetrahedra.
std::uint64_t harcMaxSteps(const HarcOptions& options, std::uint64_t tets);

// The name of the walk kernel's launch in a frame's passes (FrameStats::passes; clvr bench's ceiling).
inline constexpr const char* kHarcWalkPass = "harc: walk";

// The device layout, 5 float4 = 80 bytes per tetrahedron (kernels/harc.cl describes it): three
// barycentric planes (the fourth is 1 minus their sum), the gradient and scalar term of Eq. 6, and the
// adjacency. Coordinates are relative to `shift` (the mesh's bounding-box center, for float precision).
// `slot` places tetrahedron t at cell harcCellPlace(t, slot) (its adjacency mapped alike).
inline constexpr std::size_t kHarcBytesPerTet = 5 * sizeof(cl_float4);
std::vector<cl_float4> packHarcTets(const TetMesh& mesh, const TetTopology& topology, const glm::dvec3& shift,
                                    const std::vector<std::uint32_t>& slot = {});

// The cells' order on the device: slot[t] is tetrahedron t's place in packHarcTets' layout, so that the next
// cell of a ray's walk is near in memory; empty where the mesh's own order is kept. TetGen numbers its cells in the order it made them (face neighbours
// lie a median 40,000 cells apart on a 205 k-cell mesh): those are sorted along a Morton (Z-order) curve
// through their centroids (ties in the mesh's order). A mesh whose own numbering keeps neighbours nearer
// (a structured grid split into cells, as bluntfin) keeps it (an empty slot): the order with the smaller
// harcNeighbourDistance wins. The walk's results do not depend on it: the entry lists are sorted in the
// mesh's numbering and only then mapped (harcDeviceCode).
std::vector<std::uint32_t> harcCellOrder(const TetMesh& mesh, const TetTopology& topology);

// How far apart face neighbours are with the cells at `slot` (empty: the mesh's order): the mean over face-
// neighbour pairs of log2(1 + |slot[t] - slot[n]|), about the number of cache levels a step jumps.
double harcNeighbourDistance(const TetTopology& topology, const std::vector<std::uint32_t>& slot = {});

// Tetrahedron t's place on the device: slot[t], or t where `slot` is empty (the mesh's own order).
inline std::uint32_t harcCellPlace(std::size_t t, const std::vector<std::uint32_t>& slot)
{
    return slot.empty() ? static_cast<std::uint32_t>(t) : slot[t];
}

// An entry code of HarcEntryLists (tet * 4 + face, or -1 - tet for the eye's cell) with the tetrahedron at its
// place in `slot` (harcCellPlace).
inline std::int32_t harcDeviceCode(std::int32_t code, const std::vector<std::uint32_t>& slot)
{
    return code >= 0 ? static_cast<std::int32_t>(harcCellPlace(static_cast<std::uint32_t>(code) >> 2, slot) * 4 + (code & 3))
                     : -1 - static_cast<std::int32_t>(harcCellPlace(static_cast<std::uint32_t>(-1 - code), slot));
}

// Per pixel of a width x height image, the crossings of its ray (Camera::ray, λ >= 0) with boundary
// faces that face the ray (outward normal . d < 0), sorted by λ: entries[offsets[p] .. offsets[p+1])
// = (λ as float bits, tet * 4 + face), ties in λ by code. Built over the host's threads in bands of rows (docs/harc.md).
struct HarcEntryLists {
    std::vector<cl_uint> offsets;  // width * height + 1
    std::vector<cl_int2> entries;
};
HarcEntryLists buildHarcEntryLists(const TetMesh& mesh, const TetTopology& topology, const Camera& camera,
                                   int width, int height);

// The first tetrahedron that holds `p` (on its faces included), or -1: where a perspective eye inside the
// mesh starts its rays. Linear in the cells, once per frame.
std::int64_t locatePoint(const TetMesh& mesh, const glm::dvec3& p);

// Puts (λ = 0, tet `tet`, no entry face; code -1 - tet) first in every pixel's list: the rays of an eye
// inside `tet` start there, and the walk skips the crossings it passes (kernels/harc.cl).
void prependEyeEntry(HarcEntryLists& lists, std::uint32_t tet);

// Renderer for "harc" on a mesh that checkMesh() has normalized, with its topology. Throws InputError
// for bad options or an empty mesh, DeviceError when the mesh does not fit on the device.
std::unique_ptr<Renderer> makeHarcRenderer(Device& device, const Scene& scene, const TetMesh& mesh,
                                           const TetTopology& topology);
// The same with the options given instead of read from scene.options (tetslice's and tetiso's fused paths).
std::unique_ptr<Renderer> makeHarcRenderer(Device& device, const Scene& scene, const TetMesh& mesh,
                                           const TetTopology& topology, const HarcOptions& options);

// Renderer::setCamera for tetslice's and tetiso's fused paths: points a harc renderer at the scene's camera
// with the view's slices (sliceDepth0, sliceSpacing, sliceCount) and iso light taken from `view`; false where
// setCamera refuses (another image size). InternalError for any other renderer.
bool harcSetView(Renderer& renderer, const Scene& scene, const HarcOptions& view);

// For a harc renderer made with Integration::Iso, after a frame: the eye depth of each pixel's iso-surface
// hit (row 0 at the top), +infinity where its ray found none. InternalError for any other renderer.
std::vector<double> harcIsoHitDepth(const Renderer& renderer);

}  // namespace clvr
