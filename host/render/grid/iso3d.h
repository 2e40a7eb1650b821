// host/render/grid/iso3d.h — shaded iso-surfaces by the alpha test (§3 of seeds/000_354856c7f65dc3f9.txt):
// view-aligned slices through an RGBA volume (encoded normal, value) drawn front to back through the
// raster stage; the alpha test (GEQUAL iso) keeps samples at or above the iso-value and the depth test
// (LESS) the nearest, so each pixel ends up holding the first slice sample on the surface. Gradient
// shading then copies the frame buffer onto itself through the paper's color matrix, with the diffuse
// reflectivity as scale and the ambient term as bias. docs/iso3d.md.
#pragma once

#include "host/render/renderer.h"
#include "host/render/slice_plan.h"
#include "raster/pixel_transfer.h"

#include <glm/glm.hpp>
#include <nlohmann/json.hpp>

#include <array>
#include <cstdint>
#include <memory>
#include <vector>

namespace clvr {

struct Iso3dOptions {
    int slices = 256;           // slices across the box's eye-depth range ...
    double sliceSpacing = 0.0;  // ... or, when > 0, this spacing in world units
    double gradientlessStep = 0.0;  // Delta of gradientless shading, world units; 0: the smallest grid spacing
    double gradientlessScale = 0.0;  // k: shade I_a + k_d k (X(p0) - X(p0 + Delta L)); 0: 1 / (Delta |grad|~)
    // Figure 7's multi-pass: where the values right behind the box entry are already at or above the
    // iso-value (stencil set), show the first sample below it (the interior surface) instead of the entry.
    bool interior = false;
    // Bricking (§3.1, docs/iso3d.md): at most this many bytes of brick textures resident on the device
    // (0: the whole volume, unbricked) ...
    std::uint64_t brickBudget = 0;
    // ... or exactly this brick grid (0: not given).
    glm::ivec3 bricks{0};
    // The slices drawn through the raster stage pass by pass (Raster: the paper's alpha and depth tests) or
    // the same slices stepped through per pixel in one kernel that stops at the first passing sample
    // (Fused, kernels/iso3d.cl iso3d_fused; the same frame buffer contents up to rounding). Bricking and
    // interior need the raster path (chosen when they are given without a path).
    enum class Path { Fused, Raster };
    Path path = Path::Fused;
    bool emptySpaceSkipping = true;  // fused path: step over bricks whose values all lie below the iso-value

};

// Its registry entry (host/render/renderer.h): name, data kind, one line, options with defaults.
TechniqueInfo iso3dTechnique();

// Reads the scene's "options" for iso3d (slices, slice_spacing, gradientless_step, gradientless_scale,
// interior, brick_budget, bricks, path, empty_space_skipping). Throws InputError naming the key.
Iso3dOptions parseIso3dOptions(const nlohmann::json& options);

// The scene's "iso" as iso3d and its reference use it: the light resolved for the camera, the color
// taken from the transfer function.
struct IsoSurface {
    using Shading = IsoSpec::Shading;
    double value = 0.0;                   // data units
    Shading shading = Shading::Gradient;  // Gradientless: forward differences (docs/iso3d.md); None: flat color
    glm::dvec3 light{0.0, 0.0, 1.0};      // towards the light, world space, unit length
    double ambient = 0.1, diffuse = 0.9;  // I_a and k_d of the paper
    glm::dvec3 color{1.0};                // the transfer function's color at the value, or white
};

// The scene's "iso" seen from `camera` (IsoSpec::lightFor: "light", else the headlight). Throws
// InputError ("iso: ...") when the scene has no "iso".
IsoSurface isoSurface(const Scene& scene, const Camera& camera);

// Per grid point (0.5 N + 0.5, value), N = -grad/|grad| from the Sobel gradient (host/optics/gradient_volume.h),
// the unit normal pointing out of the region at or above any iso-value (towards lower values); (0.5, 0.5,
// 0.5) where the gradient is 0. The paper's "gradient components scaled and translated by 0.5", in float32.
std::vector<glm::vec4> encodedNormalVolume(const Volume& volume);

// The fused path's empty space (kernels/empty_space.h): slice3d's bricks of 4^3 cells, empty where every value lies
// below `iso` by more than float rounding in the trilinear interpolation could make up; per brick 0, or r + 1 where
// every brick within Chebyshev distance r is empty. Sets the brick grid's dims and the empty bricks' count.
std::vector<std::uint8_t> iso3dEmptySpace(const Volume& volume, double iso, glm::ivec3& brickDims,
                                          std::uint64_t& emptyBricks);

// The median Sobel gradient length (data units per world unit) over the grid points next to a crossing of
// `iso` (the point or its +x, +y or +z neighbour on the other side): gradientless shading's default
// normalization, |grad|~ in 1 / (Delta |grad|~). 1 when no edge crosses.
double medianGradientAtIso(const Volume& volume, double iso);

// The paper's color matrix for gradient shading, as printed in §3:
//   CM = (rows L^T, L^T, L^T, e_4^T) * M_rot * (2 I_3 | -1; 0 | 1),
// `rotation` (M_rot) taking the volume's frame to the light's (identity when both are world space, as in
// clvr's scenes). The decode's -1 sits in the alpha column, so CM (R, G, B, alpha) = <L, M_rot (2 rgb -
// alpha)>: <L, N> only for alpha = 1, and alpha holds the material value (at least the iso-value).
glm::dmat4 isoColorMatrix(const glm::dvec3& light, const glm::dmat3& rotation = glm::dmat3(1.0));

// What iso3d loads into the pixel transfer instead: the same matrix with the -1 moved out of the alpha
// column into the bias (GL's post-color-matrix bias, an equivalent state for any alpha):
//   matrix = (rows L^T, L^T, L^T, e_4^T) * M_rot * diag(2, 2, 2, 1),
//   scale = (k_d c, 1),  bias = (c (I_a - k_d <L, M_rot 1>), 0),
// so that bias + scale * (matrix (0.5 N + 0.5, alpha)) = (c (k_d <L, M_rot N> + I_a), alpha), c the surface color.
raster::PixelTransfer isoShadingTransfer(const IsoSurface& iso, const glm::dmat3& rotation = glm::dmat3(1.0));

// Bricking (§3.1 of seeds/000): the grid points split into counts.x x counts.y x counts.z bricks. Along
// each axis the n - 1 cells are cut into `counts` slabs of floor or ceil((n - 1) / counts) cells; slab s
// holds the grid points starts[s] .. starts[s + 1], so neighbouring bricks share the grid points of their
// common face (the one-voxel overlap): every cell lies whole in one brick, and trilinear samples and the
// (globally computed) gradients are the unbricked ones.
struct MemoryBricks {
    glm::ivec3 counts{1};
    std::array<std::vector<int>, 3> starts;  // per axis counts[a] + 1 grid-point indices, 0 .. n - 1
    std::uint64_t bytesPerPoint = 0;         // device bytes of every texture per grid point
    int count() const { return counts.x * counts.y * counts.z; }
    glm::ivec3 lo(const glm::ivec3& b) const { return {starts[0][b.x], starts[1][b.y], starts[2][b.z]}; }
    glm::ivec3 hi(const glm::ivec3& b) const  // last grid point, inclusive
    {
        return {starts[0][b.x + 1], starts[1][b.y + 1], starts[2][b.z + 1]};
    }
    glm::ivec3 dims(const glm::ivec3& b) const { return hi(b) - lo(b) + 1; }
    std::uint64_t bytes(const glm::ivec3& b) const;
    std::uint64_t maxBytes() const;  // the largest brick's
};

// The grid of exactly `counts` bricks. Throws InputError ("options.bricks: ...") when a count is < 1 or
// more than the axis' cells.
MemoryBricks splitBricks(const glm::ivec3& dims, const glm::ivec3& counts, std::uint64_t bytesPerPoint);

// The grid whose largest brick fits `budget` bytes: from one brick, the axis with the most grid points per
// brick is cut into one more slab until it fits (bricks stay near cubes). Throws InputError
// ("options.brick_budget: ...") when the budget is below the smallest brick, 2x2x2 grid points.
MemoryBricks planBricks(const glm::ivec3& dims, std::uint64_t bytesPerPoint, std::uint64_t budget);

// The brick grid iso3d renders with for these options: exactly options.bricks, else planBricks for
// options.brickBudget, else one brick (unbricked).
MemoryBricks iso3dBrickGrid(const glm::ivec3& dims, const Iso3dOptions& options, std::uint64_t bytesPerPoint);

// Brick b's grid points cut out of a whole grid's `points` (x fastest, `dims` per axis), x fastest.
std::vector<glm::vec4> brickPoints(const std::vector<glm::vec4>& points, const glm::ivec3& dims, const MemoryBricks& grid,
                                   const glm::ivec3& b);

// The bricks front to back for `camera`: a visibility order of the axis-aligned grid (a ray from the eye
// crosses the slabs of each axis monotonically away from the eye's slab, so its bricks have increasing
// sum over the axes of |slab - eye slab|; parallel projection: slabs counted along the view direction).
// Sorted by that sum, ties by index. `origin`, `spacing`: the volume's.
std::vector<glm::ivec3> brickOrder(const MemoryBricks& grid, const Camera& camera, const glm::dvec3& origin,
                                   const glm::dvec3& spacing);

// One brick's draw in the raster path's bricked frame (§3.1; also tools/ceiling_iso3d.h's loop): the slices that can
// reach the brick (its corners' eye-depth range, one slice more each side, of plan's slices) and the scissor
// box of pixels they are drawn in (the hull of its projected corners one pixel wider, [x0, x1) x [y0, y1); the
// whole image when a corner is not in front of the eye: scissor false).
struct BrickDraw {
    glm::ivec3 brick{0};
    int kLo = 0, kHi = -1;
    bool scissor = false;
    int x0 = 0, y0 = 0, x1 = 0, y1 = 0;
};
// The bricks' draws in brickOrder, those with no slice or off screen left out; viewProjection: the draws'.
std::vector<BrickDraw> brickDraws(const MemoryBricks& grid, const Camera& camera, const glm::dvec3& origin,
                                  const glm::dvec3& spacing, const SlicePlan& plan, const glm::dmat4& viewProjection,
                                  int width, int height);

// Renderer for "iso3d". hitDepth() gives the last frame's eye depth (along the camera's forward axis,
// world units) of the surface per pixel, row 0 at the top, +infinity where no sample passed.
class Iso3dRenderer : public Renderer {
public:
    virtual std::vector<double> hitDepth() = 0;
    virtual double sliceSpacing() const = 0;  // deltaS, world units along forward
};

// Throws InputError for bad options or "iso", DeviceError when the volume (or a brick) does not fit.
std::unique_ptr<Iso3dRenderer> makeIso3dRenderer(Device& device, const Scene& scene, const Volume& volume);

}  // namespace clvr
