// host/render/grid/stack2d.h — 2D texture stacks (seeds/003_e49ee09fcdafadac.txt): the volume held as three
// stacks of 2D textures, one per axis; per view the stack whose axis is most parallel to the view
// direction is drawn as object-aligned quads, back to front, each sampled bilinearly, classified after
// interpolation and blended "over"; with "lights", the color is shaded by the interpolated gradient
// (the paper's shading of semi-transparent volumes, with planes/blend's Phong model and reflectance
// map); with "iso", a shaded iso-surface through the alpha test. Intermediate slices between two stack
// slices lerp the bilinear samples of both (the paper's multi-texture combiner), so their sampling is
// trilinear. With options.clip_texture (slice3d's, host/optics/clip_texture.h), a second "stencil" texture
// drops the samples it calls clipped (seeds/003's clipping with arbitrary clipping geometry). Pass by
// pass through raster::draw with kernels/stack2d.cl as fragment program ("path": "raster"), or by the
// fused kernel stack2d_fused of the same file, which steps each pixel's ray through the same planes
// ("path": "fused", the default).
// docs/stack2d.md.
#pragma once

#include "host/model/camera.h"
#include "host/optics/clip_texture.h"
#include "host/render/renderer.h"

#include <glm/glm.hpp>
#include <nlohmann/json.hpp>

#include <optional>
#include <vector>

namespace clvr {

struct Stack2dOptions {
    // Raster: the quads through raster::draw (the paper's passes, the specification). Fused: each pixel's
    // ray steps through the same planes in one kernel (kernels/stack2d.cl stack2d_fused; the same image up
    // to rounding and the draws' vertex snapping). Several slices per polygon are raster-path work (chosen
    // when given without a path).
    enum class Path { Fused, Raster };
    Path path = Path::Fused;
    bool emptySpaceSkipping = true;  // fused path: step over bricks where nothing can show (same image)
    double earlyTermination = 1.0;   // fused path: stop a ray once its opacity reaches this (1: off)
    // Fused path, plain rendering without a clip texture: 8 neighbouring pixels per work-item, one per float8
    // lane (kernels/stack2d.cl stack2d_fused_packet; the same bits as one pixel per work-item). Unset: on CPU
    // devices only (packetsOnDevice, host/render/options_util.h).
    std::optional<bool> packets;
    int intermediate = 0;  // slices interpolated between two neighbouring stack slices (0: the stack itself)
    int reflectanceMapSize = 128;  // shaded ("lights" in the scene): n, 6 n^2 shades (host/optics/reflectance_map.h)
    int slicesPerPolygon = 1;      // slices one quad stands for (seeds/003's multi-texture speed-up)
    // options.clip_texture (as slice3d's, host/optics/clip_texture.h): samples the second texture calls
    // clipped are not drawn (iso-surfaces: are no hit). docs/stack2d.md, "Clip textures".
    std::optional<ClipTextureSpec> clipTexture;
};

// Its registry entry (host/render/renderer.h): name, data kind, one line, options with defaults.
TechniqueInfo stack2dTechnique();

// Reads the scene's "options" for stack2d. Throws InputError naming the key ("options.intermediate: ...").
Stack2dOptions parseStack2dOptions(const nlohmann::json& options);

// The stack for this view: the axis (0 x, 1 y, 2 z) with the largest |forward[axis]|, the lowest
// axis on a tie. The paper switches stacks by the view direction; for a perspective camera this is
// the direction through the image center (off-center rays may be more oblique to the slices).
int stackAxis(const Camera& camera);

// One quad of the drawn stack: its plane is at grid coordinate `position` along the stack axis
// (world origin[axis] + position * spacing[axis]); it samples stack slice `lower` and, when
// weight > 0, lerps towards slice lower + 1 by `weight`. `thickness` is the slab it stands for,
// measured along the axis in world units: spacing / (intermediate + 1), half that for the first
// and last slice (whose slabs end at the box faces), so the slabs tile the box exactly.
struct StackSlice {
    double position = 0.0;
    int lower = 0;
    float weight = 0.0f;
    double thickness = 0.0;
};

// The (n - 1)(intermediate + 1) + 1 slices of the stack along `axis` (n grid points on it), in
// drawing order: back to front as seen from the camera (perspective: decreasing distance of the
// plane from the camera position along the axis; parallel: decreasing depth along forward).
std::vector<StackSlice> planStack(const Camera& camera, const glm::dvec3& origin, const glm::dvec3& spacing,
                                  const glm::ivec3& dims, int axis, int intermediate);

// Several slices per polygon: the slices of `drawOrder` (planStack's order) grouped into runs of at
// most `perPolygon` consecutive slices, each drawn as one quad whose fragment program samples all of
// them. A ray meets the planes on one side of a perspective camera only (along the axis), so the
// slices are first split by side — each side keeps its back-to-front order, and groups never mix
// sides; a plane through the camera (seen edge-on, no fragments) is dropped. `slices` is the new
// order, `groups` (first, count) index into it, farthest slice of a group first.
struct SliceGroups {
    std::vector<StackSlice> slices;
    std::vector<std::pair<int, int>> groups;
};
SliceGroups groupStackSlices(const std::vector<StackSlice>& drawOrder, const Camera& camera, const glm::dvec3& origin,
                             const glm::dvec3& spacing, int axis, int perPolygon);

// Renderer for "stack2d". Uploads three float32 stacks (3 x 4 bytes per grid point; shaded, with the
// Sobel gradient: 3 x 16 bytes) and the packed transfer function (and the reflectance map); throws InputError for bad options, DeviceError when the stacks do not fit.
std::unique_ptr<Renderer> makeStack2dRenderer(Device& device, const Scene& scene, const Volume& volume);

// Moves the clip texture of a stack2d renderer made with options.clip_texture for the following frames,
// as slice3d's setSlice3dClipPlacement does: only texture coordinates change; the next frame is
// bit-identical to a new renderer's with that placement. InputError for another renderer, one without
// a clip texture, or a singular matrix.
void setStack2dClipPlacement(Renderer& renderer, const glm::dvec3& offset, const glm::dmat3& matrix = glm::dmat3(1.0));

}  // namespace clvr
