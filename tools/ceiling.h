// tools/ceiling.h — the interface of the regular-grid ceiling loops, and the speed ceiling for slice3d:
// the per-sample work of its fused kernel (kernels/slice3d.cl: ray–slice intersection, trilinear sample
// from a float array, exact piecewise-linear transfer-function lookup, alpha = 1 - exp(-tau Delta), "over"
// compositing; with a clip mesh, the test of each sample against the mesh's peeled layers; with pre-integrated
// slabs, each slab between consecutive samples integrated by kernels/segment_integral.h's pieces) as a plain C++
// loop, multithreaded with std::thread over rows. clvr bench reports clvr's samples/s as a fraction of this
// loop's (docs/benchmarks.md). Not part of the library; tests/bench_test.cpp checks its image against
// host/reference/reference_integral.h and, clipped or pre-integrated, against the kernel's.
#pragma once

#include "host/model/camera.h"
#include "host/model/image.h"
#include "host/render/grid/slice3d.h"
#include "host/model/transfer_function.h"
#include "host/model/volume.h"
#include "host/optics/clip_mesh.h"
#include "tools/ceiling_segment.h"

#include <glm/glm.hpp>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <limits>
#include <cmath>
#include <cstdint>
#include <optional>
#include <vector>

namespace clvr::tools {

struct CeilingScene {
    Camera camera;
    int width = 512, height = 512;
    glm::dvec3 background{0.0};
    Slice3dOptions options;  // slices / slice_spacing, order, early_termination, integration, clip as slice3d reads them
    std::optional<ClipMesh> clipMesh;  // options.clip's mesh, loaded (loadClipMesh)
};

struct CeilingResult {
    Image4f image;              // I + (1 - A) background, alpha = A
    std::uint64_t samples = 0;  // samples taken inside the grid bounds (slice3d's stats.samples)
};

// The fused kernels' per-sample classification in plain C++: kernels/volume_sampling.h's clvr_trilinear on the
// volume's floats at grid coordinates g (checked inside by the caller), then kernels/transfer_function.h's
// clvr_tf_eval (the exact piecewise-linear transfer function): (r, g, b, tau). Inline, as the loops need it.
class CeilingClassifier {
public:
    CeilingClassifier(const Volume& volume, const TransferFunction& tf)
        : volume_(volume), values_(volume.floats(scratch_).data())
    {
        for (const ControlPoint& p : tf.points()) {
            s_.push_back(static_cast<float>(p.s));
            value_.emplace_back(glm::vec3(p.color), static_cast<float>(p.tau));
        }
    }
    glm::vec4 operator()(const glm::vec3& g) const { return classify(value(g)); }

    // clvr_trilinear: the scalar at grid coordinates g.
    float value(const glm::vec3& g) const
    {
        const glm::ivec3 n = volume_.dims;
        const std::size_t nx = static_cast<std::size_t>(n.x), nxy = nx * n.y;
        const int i = std::min(static_cast<int>(g.x), n.x - 2);
        const int j = std::min(static_cast<int>(g.y), n.y - 2);
        const int k = std::min(static_cast<int>(g.z), n.z - 2);
        const float fx = g.x - i, fy = g.y - j, fz = g.z - k;
        const float* p = values_ + k * nxy + j * nx + i;
        const float c00 = p[0] + fx * (p[1] - p[0]);
        const float c10 = p[nx] + fx * (p[nx + 1] - p[nx]);
        const float c01 = p[nxy] + fx * (p[nxy + 1] - p[nxy]);
        const float c11 = p[nxy + nx] + fx * (p[nxy + nx + 1] - p[nxy + nx]);
        const float c0 = c00 + fy * (c10 - c00), c1 = c01 + fy * (c11 - c01);
        return c0 + fz * (c1 - c0);
    }

    // clvr_tf_eval: (r, g, b, tau) at the scalar s.
    glm::vec4 classify(float s) const
    {
        const int count = static_cast<int>(s_.size());
        if (!(s > s_[0]))
            return value_[0];
        if (s >= s_[count - 1])
            return value_[count - 1];
        int m = 1;
        while (s_[m] <= s)
            ++m;
        const float t = (s - s_[m - 1]) / (s_[m] - s_[m - 1]);
        return value_[m - 1] + t * (value_[m] - value_[m - 1]);
    }

private:
    const Volume& volume_;
    std::vector<float> scratch_;    // the values as float where the volume holds native voxels
    const float* values_;
    std::vector<float> s_;          // control points' s, increasing
    std::vector<glm::vec4> value_;  // their (r, g, b, tau)
};

// The kernels' half-open grid box [0, top) of a grid with n points per axis: top the next float above n - 1 (the
// fused kernels' grid_hi / own_hi for a whole grid).
inline glm::vec3 gridTop(const glm::ivec3& n)
{
    const float inf = std::numeric_limits<float>::infinity();
    return {std::nextafter(static_cast<float>(n.x - 1), inf), std::nextafter(static_cast<float>(n.y - 1), inf),
            std::nextafter(static_cast<float>(n.z - 1), inf)};
}

// kernels/volume_sampling.h's clvr_box_chord for the box [0, hi) (hi per axis the next float above the last grid
// point): the eye-depth interval [zin, zout] of the ray go + z gd inside it, zin > zout where it misses.
inline void boxChord(const glm::vec3& go, const glm::vec3& gd, const glm::vec3& hi, float& zin, float& zout)
{
    zin = -std::numeric_limits<float>::infinity();
    zout = std::numeric_limits<float>::infinity();
    for (int a = 0; a < 3; ++a) {
        if (gd[a] == 0.0f) {
            if (go[a] < 0.0f || go[a] >= hi[a])
                zout = -std::numeric_limits<float>::infinity();
            continue;
        }
        const float t0 = (0.0f - go[a]) / gd[a], t1 = (hi[a] - go[a]) / gd[a];
        zin = std::max(zin, std::min(t0, t1));
        zout = std::min(zout, std::max(t0, t1));
    }
}

// kernels/volume_sampling.h's clvr_slice_range: the slices kLo..kHi (of 0..count - 1, at depth0 + k deltaS) near
// the chord [zin, zout], one more each way; none (kLo > kHi) for an empty chord.
inline void sliceRange(float zin, float zout, float depth0, float deltaS, int count, int& kLo, int& kHi)
{
    kLo = 0;
    kHi = -1;
    if (zin <= zout) {
        const float n = static_cast<float>(count);
        kLo = static_cast<int>(std::clamp(std::ceil((zin - depth0) / deltaS) - 1.0f, 0.0f, n));
        kHi = static_cast<int>(std::clamp(std::floor((zout - depth0) / deltaS) + 1.0f, -1.0f, n - 1.0f));
    }
}

// A ceiling loop for a regular-grid technique's fused kernel (slice3d's below, spherical's in
// tools/ceiling_spherical.h): clvr bench times render() interleaved with clvr's frames.
class VolumeCeiling {
public:
    virtual ~VolumeCeiling() = default;
    // Renders with `threads` threads taking rows from a shared counter (<= 0: the thread budget,
    // host/runtime/parallel.h); the samples are renderRow's, summed.
    CeilingResult render(int threads = 0) const;
    // What the bench report says about the loop's work (slice3d: slices and spacing; spherical: shells).
    virtual nlohmann::json describe() const = 0;

protected:
    VolumeCeiling(int width, int height) : width_(width), height_(height) {}
    // Row y of the image (row 0 at the top); returns the samples taken.
    virtual std::uint64_t renderRow(int y, Image4f& image) const = 0;
    int width_, height_;
};

// slice3d's fused path: per-sample classification, clipped by a mesh or not, or pre-integrated slabs (the fused
// path's options; InputError for a clip mesh that scene.clipMesh does not hold).
class Ceiling final : public VolumeCeiling {
public:
    Ceiling(const Volume& volume, const TransferFunction& tf, const CeilingScene& scene);
    nlohmann::json describe() const override;
    // The slices, as slice3d plans them (planSlices).
    const SlicePlan& plan() const { return plan_; }

private:
    std::uint64_t renderRow(int y, Image4f& image) const override;
    // Pixel (x, y) with pre-integrated slabs; returns the samples taken.
    std::uint64_t preintegratedPixel(int x, int y, const glm::vec3& go, const glm::vec3& gd, float stretch,
                                     Image4f& image) const;
    // The clip mesh's surfaces along every pixel's ray, as the renderer peels them (kernels/clip_layers.cl's rule)
    // but drawn by the CPU reference rasterizer (raster/reference/rasterizer.h).
    void peel(const ClipMesh& mesh);

    const Volume& volume_;
    CeilingScene scene_;
    SlicePlan plan_;
    CeilingClassifier classify_;
    std::optional<CeilingSegments> segments_;  // integration "preintegrated"
    std::vector<glm::vec2> layers_;  // clip mesh: layer l of pixel p at l * pixels + p, (eye depth, 1 if front-facing)
    int layerCount_ = 0;
};

}  // namespace clvr::tools
