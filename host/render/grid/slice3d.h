// host/render/grid/slice3d.h — 3D-texture slicing (§2 of seeds/000_354856c7f65dc3f9.txt; the "Blend"
// method of seeds/004): slices parallel to the image plane through the volume box, classified after
// trilinear interpolation and blended "over", back to front. Two paths: a fused kernel (one
// work-item per pixel loops over all slices; the fast path) and the pass-by-pass path through
// raster::draw (slice polygons with a fragment program; the specification). docs/slice3d.md.
#pragma once

#include "host/optics/clip_mesh.h"
#include "host/optics/clip_texture.h"
#include "host/render/renderer.h"
#include "host/render/slice_plan.h"
#include "raster/rasterizer.h"

#include <glm/glm.hpp>
#include <nlohmann/json.hpp>

#include <optional>
#include <vector>

namespace clvr {

// Clipping with a closed triangle mesh through the stencil buffer (§2.1 of seeds/000; raster path only).
struct Slice3dClip {
    // TwoPass: the paper's method — back faces behind the slice set the stencil, front faces in
    // front of the nearest such back face clear it. Naive: back faces only (its Figure 2: wrong
    // wherever a part of the mesh lies behind the slice without the slice cutting it).
    enum class Method { TwoPass, Naive };
    ClipMeshSpec mesh;
    bool inverse = false;  // false: keep the volume inside the mesh; true: keep it outside
    Method method = Method::TwoPass;
};

struct Slice3dOptions {
    enum class Order { BackToFront, FrontToBack };
    enum class Path { Fused, Raster };
    int slices = 256;            // slices across the box's eye-depth range ...
    double sliceSpacing = 0.0;   // ... or, when > 0, this spacing in world units (then slices is derived)
    Order order = Order::BackToFront;
    double earlyTermination = 1.0;  // front-to-back only: stop once A >= this; 1.0 = off
    Path path = Path::Fused;
    bool emptySpaceSkipping = true;  // fused path: step over bricks where tau is 0 (bit-identical image)
    bool nativeVoxels = true;  // fused path: uint8/uint16 on the device when every value fits (same bits)
    // Fused path: 8 neighbouring pixels per work-item, one per float8 lane (kernels/slice3d.cl's
    // slice3d_fused_packet; same bits as one pixel per work-item). Not with preintegrated. Unset: on CPU
    // devices only (packetsOnDevice, host/render/options_util.h).
    std::optional<bool> packets;
    // Fused path: integrate each slab between consecutive samples with the scalar linear in between (partial
    // pre-integration, kernels/segment_integral.h) instead of one classified sample per slice.
    bool preintegrated = false;
    std::optional<Slice3dClip> clip;  // needs the raster path (chosen by default when clip is given)
    // Clipping with a second "stencil" texture (seeds/003; host/optics/clip_texture.h): both paths.
    std::optional<ClipTextureSpec> clipTexture;
};

// Its registry entry (host/render/renderer.h): name, data kind, one line, options with defaults.
TechniqueInfo slice3dTechnique();

// Reads the scene's "options" for slice3d. Throws InputError naming the key ("options.slices: ...")
// for unknown keys, wrong types and values out of range.
Slice3dOptions parseSlice3dOptions(const nlohmann::json& options);

// Slices over the eye-depth range of the box [lo, hi] as options.slices and options.sliceSpacing ask
// (planSlices of host/render/slice_plan.h).
SlicePlan planSlices(const Camera& camera, const glm::dvec3& lo, const glm::dvec3& hi, const Slice3dOptions& options);

// The fused path's clip-mesh peel draws (kernels/clip_layers.cl, docs/slice3d.md "Clipping with closed meshes"; also
// tools/ceiling.h's): the mesh's triangles as raster::draw takes them, projected as the raster path projects its
// slices for `camera` and `plan` (near plane at half the first slice's depth, far plane beyond the box and the
// mesh), attribute 0 the world position.
std::vector<raster::Vertex> clipPeelVertices(const ClipMesh& mesh, const Camera& camera, int width, int height,
                                             const SlicePlan& plan);

// Empty-space skipping (docs/slice3d.md): bricks of B^3 cells, B = kBrickCells (= 2^CLVR_BRICK_SHIFT
// in kernels/empty_space.h; 4 measured faster than 8 on the engine); brick b covers the grid points
// [Bb, Bb + B] on each axis (one point of overlap), so it holds every trilinear footprint whose lower
// corner lies in it. The min-max grid is built once per volume.
constexpr int kBrickCells = 4;

struct BrickGrid {
    glm::ivec3 dims{0};             // bricks per axis: ceil((n - 1) / B)
    std::vector<glm::vec2> minMax;  // (min, max) of the brick's grid points, x fastest
};
BrickGrid buildBrickGrid(const Volume& volume);

// One byte per brick, 1 = empty: tauZeroOn over the brick's [min, max], widened by a few ulp so that
// float rounding in the trilinear interpolation cannot leave the interval.
std::vector<cl_uchar> emptyBricks(const BrickGrid& grid, const TransferFunction& tf);

// The bricks that are not empty (`empty`: emptyBricks' flags) span [lo, hi] per axis; none: lo = brickDims,
// hi = -1. The fused kernel's sample loop runs inside their box.
void filledBricks(const glm::ivec3& brickDims, const std::vector<cl_uchar>& empty, glm::ivec3& lo, glm::ivec3& hi);

// What the fused kernel reads per brick (kernels/slice3d.cl): 0 for a brick that is not empty, else
// r + 1 where every brick within Chebyshev distance r is empty (bricks outside the grid count as
// empty), capped at 255; the kernel steps over that cube in one run.
std::vector<cl_uchar> emptySpaceRadii(const glm::ivec3& brickDims, const std::vector<cl_uchar>& empty);

// Renderer for "slice3d". Uploads the volume as float32 (4 bytes per grid point) and the packed
// transfer function; throws InputError for bad options and DeviceError when the volume does not fit.
std::unique_ptr<Renderer> makeSlice3dRenderer(Device& device, const Scene& scene, const Volume& volume);

// Moves the clip texture of a slice3d renderer made with options.clip_texture for the following
// frames, as the scene's "offset" and "matrix" would (seeds/003: "the clipping volume can be
// interactively moved by adapting texture coordinates"): only the texture coordinates change, the
// texture on the device stays. The next frame is bit-identical to a new renderer's with that
// placement. InputError for another renderer, one without a clip texture, or a singular matrix.
void setSlice3dClipPlacement(Renderer& renderer, const glm::dvec3& offset, const glm::dmat3& matrix = glm::dmat3(1.0));

}  // namespace clvr
