// host/render/grid/spherical.h — pixel textures on spherical domains (seeds/000 §2.2): a scalar volume
// parameterized in normalized spherical coordinates, grid axes x = φ (longitude), y = θ (polar angle
// from +z), z = r, is rendered through concentric spheres ("shells") drawn with the normalized
// coordinates (u, v, w) = (φ / 2π, θ / π, (r - r_min) / (r_max - r_min)) as interpolated vertex
// colors. Per shell and hemisphere, back to front: raster::draw of the tessellated sphere into a
// coordinate frame buffer, raster::applyPixelTransfer (the paper's b + s·CM·p: the user's color
// matrix, scale and bias, composed with the map of normalized coordinates to texel centers), then
// kernels/spherical.cl: the pixel texture fetch of the volume, classification, opacity for the
// shell's slab and the "over" blend into the image ("path": "raster"). The fused path ("path": "fused",
// the default; kernels/spherical.cl spherical_fused) meets the exact spheres per pixel in one kernel and
// computes the coordinates at each hit. docs/spherical.md.
#pragma once

#include "host/model/camera.h"
#include "host/render/renderer.h"
#include "host/render/scaffold.h"
#include "host/render/transfer_function_upload.h"
#include "raster/pixel_transfer.h"
#include "raster/rasterizer.h"

#include <glm/glm.hpp>
#include <nlohmann/json.hpp>

#include <optional>
#include <vector>

namespace clvr {

// The world domain of the data: the points x with r_min <= |x - center| <= r_max.
// Grid point (i, j, k) of an (nx, ny, nz) grid sits at u = i / (nx - 1) (so φ = 2π u; i = 0 and
// i = nx - 1 are the same meridian, and φ interpolation wraps), v = j / (ny - 1), w = k / (nz - 1);
// the volume's origin and spacing are not used.
struct SphericalDomain {
    glm::dvec3 center{0.0};
    double rMin = 0.5, rMax = 1.0;  // world units, 0 <= rMin < rMax
};

struct SphericalOptions {
    SphericalDomain domain;
    int shells = 64;    // spheres drawn, at r_min + k (r_max - r_min) / (shells - 1)
    int segments = 64;  // tessellation: segments in φ, segments / 2 in θ
    // The paper's pixel transfer on (u, v, w, 1): q = bias + scale · (colorMatrix · p); q.x wraps
    // (φ is periodic), q.y, q.z are clamped to [0, 1] by the texture's clamp-to-edge; q.w is unused.
    raster::PixelTransfer transfer;
    // How a shell's opacity counts the shell's slab [r_lo, r_hi] (radii halfway to the neighbours):
    // Path: the length of the pixel's ray inside the slab on the drawn hemisphere's side (exact per
    // pixel; a ray that misses the next inner sphere gives this shell its path down to its closest
    // approach, so no path is lost at silhouettes); Radial: r_hi - r_lo for every pixel (the paper's
    // plain blending; too transparent wherever rays are oblique).
    enum class Opacity { Path, Radial } opacity = Opacity::Path;
    // Raster: the shells drawn pass by pass (the paper's technique, the specification). Fused: each pixel's
    // ray meets the exact spheres in one kernel, front to back (no tessellation: `segments` is unused).
    enum class Path { Fused, Raster } path = Path::Fused;
    double earlyTermination = 1.0;  // fused path: stop a ray once its opacity reaches this (1: off)
    // Fused path: 8 neighbouring pixels per work-item, one per float8 lane (kernels/spherical.cl's
    // spherical_fused_packet; the same bits). Unset: on CPU devices only (packetsOnDevice, options_util.h).
    std::optional<bool> packets;
};

// Its registry entry (host/render/renderer.h): name, data kind, one line, options with defaults.
TechniqueInfo sphericalTechnique();

// Reads the scene's "options" for spherical. Throws InputError naming the key ("options.shells: ...").
SphericalOptions parseSphericalOptions(const nlohmann::json& options);

// Normalized spherical coordinates (u, v, w) of world point x: u = φ / 2π in [0, 1), φ = atan2(y, x)
// of x - center; v = θ / π, θ the angle from +z; w = (r - r_min) / (r_max - r_min) (not clamped).
glm::dvec3 sphericalCoordinates(const SphericalDomain& domain, const glm::dvec3& x);

// One drawn sphere and the slab of radii it stands for: radii halfway to its neighbours, limited
// to [r_min, r_max] (so the slabs tile the domain exactly).
struct Shell {
    double radius = 0.0, rLo = 0.0, rHi = 0.0;
};
std::vector<Shell> planShells(const SphericalOptions& options);

// The sphere of `radius` about `center` as a triangle list, outward faces counter-clockwise: a
// segments x segments / 2 grid in (φ, θ) whose vertices carry attribute 0 = (u, v, w, 1). The φ = 2π
// meridian has its own vertices (u = 1), so no triangle interpolates across the seam; the pole
// triangles' pole vertex takes the mean u of their other two vertices. Positions are clip
// coordinates (viewProjection times world).
std::vector<raster::Vertex> sphereTriangles(const glm::dvec3& center, double radius, double w, int segments,
                                            const glm::dmat4& viewProjection);

// The texture coordinate map composed into the pixel transfer: texel centers of an n-point axis
// are at (i + 0.5) / n, so normalized u goes to u (n - 1) / n + 0.5 / n — a scale and a bias.
raster::PixelTransfer composeTextureMap(const raster::PixelTransfer& user, const glm::ivec3& dims);

class SphericalRenderer final : public Renderer {
public:
    SphericalRenderer(Device& device, const Scene& scene, const Volume& volume);
    Image4f render(FrameStats& stats) override;
    std::uint64_t residentBytes() const override { return residentBytes_; }
    void setTransferFunction(const TransferFunction& tf) override;
    bool setCamera(const Scene& scene) override;  // the camera and the shells' view-projection

    // One pass (for tests): shell `shell` of planShells, its far (back = true) or near hemisphere,
    // drawn, transferred and blended into image() as render() does. render() clears image() first.
    void renderPass(std::size_t shell, bool back);
    raster::Framebuffer& coordinates() { return *coords_; }  // after the pixel transfer; stencil = coverage
    raster::Framebuffer& image() { return *image_; }          // premultiplied, no background yet
    const std::vector<Shell>& shells() const { return shells_; }
    const Camera& camera() const { return camera_; }
    const raster::PixelTransfer& texturedTransfer() const { return texturedTransfer_; }
    const raster::Texture& texture() const { return *texture_; }

private:
    Device& device_;
    SphericalOptions options_;
    Camera camera_;
    ImageSpec imageSpec_;
    glm::ivec3 dims_{0};
    std::vector<Shell> shells_;
    raster::PixelTransfer texturedTransfer_;
    std::unique_ptr<raster::Texture> texture_;
    TransferFunctionUpload tf_;
    std::uint64_t residentBytes_ = 0;
    std::unique_ptr<raster::Framebuffer> coords_, image_;
    glm::dmat4 viewProjection_{1.0};
    cl::Kernel shellKernel_;
    OverBackground overBackground_;
    raster::DrawStats drawStats_;
    // The fused path: its kernel, the shell table (radius, r_lo, r_hi, w) and the samples per pixel.
    cl::Kernel fused_;
    bool packet_ = false;  // fused_ is spherical_fused_packet
    cl::Buffer shellTable_, fusedSamples_;
    std::uint64_t renderFused();
    void frameView(const Scene& scene);
};

// Renderer for "spherical": uploads the volume as a one-channel float 3D texture and the packed
// transfer function; InputError for bad options, and for a scene with "lights" or "iso" (unshaded
// direct volume rendering only).
std::unique_ptr<Renderer> makeSphericalRenderer(Device& device, const Scene& scene, const Volume& volume);

}  // namespace clvr
