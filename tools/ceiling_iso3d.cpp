// tools/ceiling_iso3d.cpp — the plain C++ ceiling loop for iso3d's fused path (see ceiling_iso3d.h): kernels/iso3d.cl's
// iso3d_fused line for line in float, then the shading and finish passes, over rows on std::threads.
#include "tools/ceiling_iso3d.h"

#include "host/render/camera_args.h"
#include "raster/reference/pixel_transfer.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace clvr::tools {
namespace {

// kernels/volume_sampling.h's clvr_trilinear (and clvr_trilinear4's mix, the same form) at grid coordinates g
// inside [0, n-1].
template <typename T>
T trilinearAt(const T* v, const glm::ivec3& n, const glm::vec3& g)
{
    const int i = std::min(static_cast<int>(g.x), n.x - 2), j = std::min(static_cast<int>(g.y), n.y - 2),
              k = std::min(static_cast<int>(g.z), n.z - 2);
    const float fx = g.x - static_cast<float>(i), fy = g.y - static_cast<float>(j), fz = g.z - static_cast<float>(k);
    const std::size_t nx = static_cast<std::size_t>(n.x), nxy = nx * static_cast<std::size_t>(n.y);
    const T* p = v + (static_cast<std::size_t>(k) * nxy + static_cast<std::size_t>(j) * nx + static_cast<std::size_t>(i));
    const T c00 = p[0] + fx * (p[1] - p[0]), c10 = p[nx] + fx * (p[nx + 1] - p[nx]);
    const T c01 = p[nxy] + fx * (p[nxy + 1] - p[nxy]), c11 = p[nxy + nx] + fx * (p[nxy + nx + 1] - p[nxy + nx]);
    const T c0 = c00 + fy * (c10 - c00), c1 = c01 + fy * (c11 - c01);
    return c0 + fz * (c1 - c0);
}

}  // namespace

bool iso3dCeilingFits(const Iso3dOptions& options, const IsoSpec& iso)
{
    const bool unbricked = options.bricks.x <= 0 && options.brickBudget == 0;
    return (options.path == Iso3dOptions::Path::Raster || unbricked) && !options.interior &&
           iso.shading != IsoSpec::Shading::Gradientless;
}

Iso3dCeiling::Iso3dCeiling(const Volume& volume, const Scene& scene, const Camera& camera, const Iso3dOptions& options)
    : VolumeCeiling(scene.image.width, scene.image.height), volume_(volume), camera_(camera),
      background_(glm::vec3(scene.image.background))
{
    // As Iso3dRendererImpl: the slices, the surface, the alpha test's value map and reference, the empty space.
    plan_ = planSlices(camera_, volume.boundsMin(), volume.boundsMax(), options.slices, options.sliceSpacing);
    iso_ = isoSurface(scene, camera_);
    shading_ = isoShadingTransfer(iso_);
    rgba_ = encodedNormalVolume(volume);
    std::uint64_t emptyBricks = 0;
    space_ = iso3dEmptySpace(volume, iso_.value, brickDims_, emptyBricks);
    skip_ = options.emptySpaceSkipping && emptyBricks > 0;
    const glm::dvec2 range = volume.range();
    valueLo_ = static_cast<float>(std::min(range.x, iso_.value));
    const float valueHi = static_cast<float>(std::max(range.y, iso_.value));
    valueScale_ = valueHi > valueLo_ ? 1.0f / (valueHi - valueLo_) : 1.0f;
    alphaRef_ = (static_cast<float>(iso_.value) - valueLo_) * valueScale_;
    origin_ = glm::vec3(volume.origin);
    invSpacing_ = glm::vec3(1.0 / volume.spacing);
    raster_ = options.path == Iso3dOptions::Path::Raster;
    if (raster_) {  // as Iso3dRendererImpl's raster frame: its projection, its brick grid and draws
        const double nearZ = 0.5 * plan_.depth(0), farZ = 2.0 * plan_.depthMax + 1.0;
        const glm::dmat4 viewProjection =
            camera_.projectionMatrix(width_, height_, nearZ, farZ) * camera_.viewMatrix();
        bricks_ = iso3dBrickGrid(volume.dims, options, sizeof(glm::vec4));
        for (const BrickDraw& d : brickDraws(bricks_, camera_, volume.origin, volume.spacing, plan_, viewProjection,
                                             width_, height_)) {
            Draw draw;
            draw.draw = d;
            draw.texels = brickPoints(rgba_, volume.dims, bricks_, d.brick);
            draw.dims = bricks_.dims(d.brick);
            const glm::ivec3 lo = bricks_.lo(d.brick), hi = bricks_.hi(d.brick), n = volume.dims;
            draw.lo = glm::vec3(lo);
            draw.end = glm::vec3(hi.x == n.x - 1 ? n.x : hi.x, hi.y == n.y - 1 ? n.y : hi.y, hi.z == n.z - 1 ? n.z : hi.z);
            draws_.push_back(std::move(draw));
        }
    }
}

nlohmann::json Iso3dCeiling::describe() const
{
    nlohmann::json d = {{"slices", plan_.count}, {"iso_value", iso_.value}};
    if (raster_) {
        d["path"] = "raster";
        d["bricks"] = bricks_.count();
        d["samples_are"] = "fragments tested, up to each pixel's hit";
    }
    return d;
}

std::uint64_t Iso3dCeiling::renderRow(int y, Image4f& image) const
{
    const ClCamera cam = toClCamera(camera_, width_, height_);
    const glm::vec3 position(cam.position.s[0], cam.position.s[1], cam.position.s[2]);
    const glm::vec3 forward(cam.forward.s[0], cam.forward.s[1], cam.forward.s[2]);
    const glm::vec3 right(cam.right.s[0], cam.right.s[1], cam.right.s[2]), up(cam.up.s[0], cam.up.s[1], cam.up.s[2]);
    const float scale = cam.params.s[0], aspect = cam.params.s[1];
    const bool parallel = cam.params.s[2] != 0.0f;
    const glm::ivec3 n = volume_.dims;
    const glm::vec3 top = gridTop(n);
    const float depth0 = static_cast<float>(plan_.depth(0)), deltaS = static_cast<float>(plan_.deltaS);
    std::vector<float> scratch;
    const float* values = volume_.floats(scratch).data();
    auto onGrid = [&](const glm::vec3& g) {  // kernels/volume_sampling.h's clvr_grid_inside
        return g.x >= 0.0f && g.y >= 0.0f && g.z >= 0.0f && g.x <= static_cast<float>(n.x - 1) &&
               g.y <= static_cast<float>(n.y - 1) && g.z <= static_cast<float>(n.z - 1);
    };
    std::uint64_t taken = 0;
    for (int x = 0; x < width_; ++x) {
        // kernels/ray.h: the pixel's offset and its ray o + z d, z the eye depth
        const float sx = ((x + 0.5f) / width_ * 2.0f - 1.0f) * scale * aspect;
        const float sy = (1.0f - (y + 0.5f) / height_ * 2.0f) * scale;
        glm::vec3 o = position, d = forward;
        if (parallel)
            o = position + sx * right + sy * up;
        else
            d = forward + sx * right + sy * up;
        const glm::vec3 go = (o - origin_) * invSpacing_, gd = d * invSpacing_;
        glm::vec4 out(background_, 0.0f);
        // The hit's color: iso3d_color, then the shading color matrix and the finish pass's clamp.
        auto shade = [&](const glm::vec4& t) {
            if (iso_.shading == IsoSpec::Shading::None)
                return glm::vec4(glm::vec3(iso_.color), 1.0f);
            const glm::dvec4 c =
                raster::reference::pixelTransfer(glm::dvec4(t.x, t.y, t.z, (t.w - valueLo_) * valueScale_), shading_);
            return glm::vec4(glm::clamp(glm::vec3(c), 0.0f, 1.0f), 1.0f);
        };
        if (raster_) {  // the bricks' draws, front to back; the first fragment that passes locks the pixel
            bool hit = false;
            for (const Draw& b : draws_) {
                const BrickDraw& dr = b.draw;
                if (dr.scissor && (x < dr.x0 || x >= dr.x1 || y < dr.y0 || y >= dr.y1))
                    continue;
                for (int k = dr.kLo; k <= dr.kHi && !hit; ++k) {
                    const glm::vec3 g = go + (depth0 + static_cast<float>(k) * deltaS) * gd;
                    if (!onGrid(g))
                        continue;  // not on the slice polygon: no fragment
                    ++taken;
                    if (g.x < b.lo.x || g.y < b.lo.y || g.z < b.lo.z || g.x >= b.end.x || g.y >= b.end.y || g.z >= b.end.z)
                        continue;  // another brick's
                    const glm::vec4 t = trilinearAt(b.texels.data(), b.dims, g - b.lo);
                    if ((t.w - valueLo_) * valueScale_ >= alphaRef_) {
                        out = shade(t);
                        hit = true;
                    }
                }
                if (hit)
                    break;
            }
            image.at(x, y) = out;
            continue;
        }
        float z0, z1;
        boxChord(go, gd, top, z0, z1);
        int kLo, kHi;
        sliceRange(z0, z1, depth0, deltaS, plan_.count, kLo, kHi);
        for (int k = kLo; k <= kHi; ++k) {
            const glm::vec3 g = go + (depth0 + static_cast<float>(k) * deltaS) * gd;
            if (!onGrid(g))
                continue;
            if (skip_) {  // kernels/empty_space.h's clvr_brick and clvr_space: no sample in an empty brick
                const glm::ivec3 b(std::min(static_cast<int>(g.x), n.x - 2) >> 2, std::min(static_cast<int>(g.y), n.y - 2) >> 2,
                                   std::min(static_cast<int>(g.z), n.z - 2) >> 2);
                if (space_[(static_cast<std::size_t>(b.z) * brickDims_.y + b.y) * brickDims_.x + b.x] != 0)
                    continue;
            }
            ++taken;
            if ((trilinearAt(values, n, g) - valueLo_) * valueScale_ >= alphaRef_) {
                out = shade(iso_.shading == IsoSpec::Shading::None ? glm::vec4(0.0f) : trilinearAt(rgba_.data(), n, g));
                break;
            }
        }
        image.at(x, y) = out;
    }
    return taken;
}

}  // namespace clvr::tools
