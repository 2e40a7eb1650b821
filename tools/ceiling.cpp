// tools/ceiling.cpp — the plain C++ ceiling loop for slice3d (see ceiling.h): kernels/slice3d.cl's
// slice3d_fused, line for line in float, over rows on std::threads.
#include "tools/ceiling.h"

#include "host/runtime/errors.h"
#include "host/runtime/parallel.h"
#include "raster/reference/rasterizer.h"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <limits>
#include <thread>

namespace clvr::tools {

Ceiling::Ceiling(const Volume& volume, const TransferFunction& tf, const CeilingScene& scene)
    : VolumeCeiling(scene.width, scene.height), volume_(volume), scene_(scene),
      plan_(planSlices(scene.camera, volume.boundsMin(), volume.boundsMax(), scene.options)), classify_(volume, tf)
{
    if (scene.options.preintegrated)
        segments_.emplace(tf);
    if (scene.options.clip) {
        if (!scene.clipMesh)
            throw InputError("ceiling: options.clip needs its mesh loaded (CeilingScene::clipMesh)");
        peel(*scene.clipMesh);
    }
}

nlohmann::json Ceiling::describe() const
{
    nlohmann::json d = {{"slices", plan_.count}, {"slice_spacing", plan_.deltaS}};
    if (segments_)
        d["integration"] = "preintegrated";
    if (scene_.options.clip)
        d["clip_layers"] = layerCount_;
    return d;
}

// Slice3dRenderer::peelClipMesh's loop: the whole mesh drawn once per layer with the depth test LESS, a fragment
// kept only beyond the previous layer's window depth at its pixel, until a draw leaves no fragment.
void Ceiling::peel(const ClipMesh& mesh)
{
    constexpr int kMaxLayers = 64;  // as the renderer
    const int width = scene_.width, height = scene_.height;
    const std::size_t pixels = static_cast<std::size_t>(width) * static_cast<std::size_t>(height);
    const std::vector<raster::Vertex> vertices = clipPeelVertices(mesh, scene_.camera, width, height, plan_);
    const glm::dvec3 eye = scene_.camera.position, forward = scene_.camera.forward();
    raster::DrawState state;
    state.fragment.depth.test = true;
    state.fragment.depth.func = raster::CompareFunc::Less;
    state.fragment.depth.write = true;
    std::vector<double> previous(pixels, -1.0);
    for (;;) {
        raster::reference::Planes fb(width, height, glm::dvec4(std::numeric_limits<double>::infinity(), 1.0, 0.0, 0.0));
        raster::reference::draw(fb, state, raster::Topology::Triangles, vertices,
                                [&](const raster::reference::Fragment& f, glm::dvec4& color) {  // clip_layers.cl
                                    const std::size_t p = static_cast<std::size_t>(f.window.y) * width +
                                                          static_cast<std::size_t>(f.window.x);
                                    if (!(f.depth > previous[p]))
                                        return false;
                                    color = glm::dvec4(glm::dot(glm::dvec3(f.attributes[0]) - eye, forward),
                                                       f.frontFacing ? 1.0 : 0.0, 0.0, 0.0);
                                    return true;
                                });
        if (std::none_of(fb.depth.begin(), fb.depth.end(), [](double d) { return d < 1.0; }))
            break;
        if (layerCount_ == kMaxLayers)
            throw InputError("ceiling: some pixel's ray crosses the clip mesh more than " + std::to_string(kMaxLayers) +
                             " times");
        for (const glm::dvec4& c : fb.color)
            layers_.emplace_back(static_cast<float>(c.x), static_cast<float>(c.y));
        previous = fb.depth;
        ++layerCount_;
    }
}

CeilingResult VolumeCeiling::render(int threads) const
{
    if (threads <= 0)
        threads = threadBudget();
    CeilingResult result;
    result.image = Image4f(width_, height_);
    std::atomic<int> nextRow{0};
    std::vector<std::uint64_t> samples(threads, 0);
    std::vector<std::thread> pool;
    for (int t = 0; t < threads; ++t)
        pool.emplace_back([&, t] {
            std::uint64_t count = 0;
            for (int y; (y = nextRow.fetch_add(1)) < height_;)
                count += renderRow(y, result.image);
            samples[t] = count;
        });
    for (std::thread& th : pool)
        th.join();
    for (std::uint64_t s : samples)
        result.samples += s;
    return result;
}

std::uint64_t Ceiling::renderRow(int y, Image4f& image) const
{
    const Camera& cam = scene_.camera;
    const int width = scene_.width, height = scene_.height;
    const glm::vec3 position(cam.position), forward(cam.forward()), right(cam.right()), up(cam.up());
    const float scale = static_cast<float>(cam.parallel ? cam.parallelScale : std::tan(glm::radians(cam.viewAngle) * 0.5));
    const float aspect = static_cast<float>(width) / static_cast<float>(height);
    const glm::vec3 origin(volume_.origin), invSpacing(1.0 / volume_.spacing);
    const glm::ivec3 n = volume_.dims;
    const glm::vec3 last(n - 1);
    const glm::vec3 top = gridTop(n);
    const float depth0 = static_cast<float>(plan_.depth(0)), deltaS = static_cast<float>(plan_.deltaS);
    const int sliceCount = plan_.count;
    const bool frontToBack = scene_.options.order == Slice3dOptions::Order::FrontToBack;
    const float ertAlpha = scene_.options.earlyTermination < 1.0 ? static_cast<float>(scene_.options.earlyTermination) : 2.0f;
    const glm::vec3 background(scene_.background);
    const CeilingClassifier& sample = classify_;  // clvr_trilinear, then clvr_tf_eval
    const std::size_t pixels = static_cast<std::size_t>(width) * static_cast<std::size_t>(height);
    const bool clip = scene_.options.clip.has_value();
    const bool naive = clip && scene_.options.clip->method == Slice3dClip::Method::Naive;
    const bool inverse = clip && scene_.options.clip->inverse;
    auto inside = [&](const glm::vec3& g) {
        return g.x >= 0.0f && g.y >= 0.0f && g.z >= 0.0f && g.x <= last.x && g.y <= last.y && g.z <= last.z;
    };

    std::uint64_t taken = 0;
    for (int x = 0; x < width; ++x) {
        // The ray o + z d, z the eye depth (dot(d, forward) = 1): slice3d_ray and slice3d_stretch.
        const float ndcX = (x + 0.5f) / width * 2.0f - 1.0f, ndcY = 1.0f - (y + 0.5f) / height * 2.0f;
        const float sx = ndcX * scale * aspect, sy = ndcY * scale;
        glm::vec3 o = position, d = forward + sx * right + sy * up;
        float stretch = std::sqrt(1.0f + sx * sx + sy * sy);
        if (cam.parallel) {
            o = position + sx * right + sy * up;
            d = forward;
            stretch = 1.0f;
        }
        const float delta = deltaS * stretch;  // ray length per slice
        const glm::vec3 go = (o - origin) * invSpacing, gd = d * invSpacing;
        if (segments_) {
            taken += preintegratedPixel(x, y, go, gd, stretch, image);
            continue;
        }

        // Depth interval inside the grid bounds (the kernel's half-open box), widened by one slice each way.
        float zin, zout;
        boxChord(go, gd, top, zin, zout);
        int kLo, kHi;
        sliceRange(zin, zout, depth0, deltaS, sliceCount, kLo, kHi);

        // The slabs at the box faces (kernels/slice3d.cl's slice3d_slab_log2e): the first slice inside the
        // chord reaches back to its entry (from depth 0 on), the last forward to its exit.
        const float chordIn = std::max(zin, 0.0f), chordOut = zout;
        auto slabLength = [&](int k) {
            const float z = depth0 + k * deltaS;
            const bool first = z - deltaS < chordIn, last = z + deltaS > chordOut;
            if (!first && !last)
                return delta;
            const float lo = first ? chordIn : z - 0.5f * deltaS, hi = last ? chordOut : z + 0.5f * deltaS;
            return std::max(hi - lo, 0.0f) * stretch;
        };

        // kernels/slice3d.cl's slice3d_mesh_keep: whether the sample at eye depth z is drawn, the first layer
        // beyond the previous sample kept in `next` (the layers of this pixel at stride `pixels`).
        const glm::vec2* layers = layers_.data() + (static_cast<std::size_t>(y) * width + x);
        int lastBack = -1, next = 0;  // the deepest back face (naive rule)
        for (int l = 0; l < layerCount_; ++l)
            if (layers[l * pixels].y == 0.0f)
                lastBack = l;
        auto keep = [&](float z) {
            if (!clip)
                return true;
            int n = next;
            while (n < layerCount_ && layers[n * pixels].x <= z)
                ++n;
            while (n > 0 && layers[(n - 1) * pixels].x > z)
                --n;
            next = n;
            const bool inside = naive ? n <= lastBack : (n < layerCount_ && layers[n * pixels].y == 0.0f);
            return inside != inverse;
        };

        glm::vec3 c(0.0f);
        float alphaAcc = 0.0f;
        if (frontToBack) {
            float transmittance = 1.0f;
            for (int k = kLo; k <= kHi; ++k) {
                const glm::vec3 g = go + (depth0 + k * deltaS) * gd;
                if (!inside(g))
                    continue;
                ++taken;
                if (!keep(depth0 + k * deltaS))
                    continue;
                const glm::vec4 ct = sample(g);
                const float alpha = 1.0f - std::exp(-ct.w * slabLength(k));  // Eq. 1 of seeds/001 per slab
                c += (transmittance * alpha) * glm::vec3(ct);
                transmittance *= 1.0f - alpha;
                if (1.0f - transmittance >= ertAlpha)
                    break;
            }
            alphaAcc = 1.0f - transmittance;
        } else {
            for (int k = kHi; k >= kLo; --k) {
                const glm::vec3 g = go + (depth0 + k * deltaS) * gd;
                if (!inside(g))
                    continue;
                ++taken;
                if (!keep(depth0 + k * deltaS))
                    continue;
                const glm::vec4 ct = sample(g);
                const float alpha = 1.0f - std::exp(-ct.w * slabLength(k));
                c = glm::vec3(ct) * alpha + (1.0f - alpha) * c;
                alphaAcc = alpha + (1.0f - alpha) * alphaAcc;
            }
        }
        image.at(x, y) = glm::vec4(c + (1.0f - alphaAcc) * background, alphaAcc);
    }
    return taken;
}

// slice3d_fused with SLICE3D_PREINTEGRATED: the chain entry, the samples inside the grid, exit; each slab between
// two consecutive points integrated with the scalar linear in between (harc_segment_from), front to back.
std::uint64_t Ceiling::preintegratedPixel(int x, int y, const glm::vec3& go, const glm::vec3& gd, float stretch,
                                          Image4f& image) const
{
    const CeilingSegments& seg = *segments_;
    const glm::ivec3 n = volume_.dims;
    const glm::vec3 last(n - 1);
    const glm::vec3 top = gridTop(n);  // own_hi: the whole grid, half open above
    const float depth0 = static_cast<float>(plan_.depth(0)), deltaS = static_cast<float>(plan_.deltaS);
    const float ertAlpha = scene_.options.earlyTermination < 1.0 ? static_cast<float>(scene_.options.earlyTermination) : 2.0f;
    auto valueAtDepth = [&](float z) {  // slice3d_value_at_depth: the point clamped into the grid
        return classify_.value(glm::clamp(go + z * gd, glm::vec3(0.0f), last));
    };
    float zin, zout;
    boxChord(go, gd, top, zin, zout);
    int kLo, kHi;
    sliceRange(zin, zout, depth0, deltaS, plan_.count, kLo, kHi);

    std::uint64_t taken = 0;
    glm::vec3 c(0.0f);
    float transmittance = 1.0f;
    const float zBegin = std::max(zin, 0.0f);
    if (zBegin < zout) {
        CeilingSegments::Point front = seg.point(valueAtDepth(zBegin));
        float zFront = zBegin;
        for (int k = kLo; k <= kHi; ++k) {
            const float z = depth0 + static_cast<float>(k) * deltaS;
            const glm::vec3 g = go + z * gd;
            if (!(g.x >= 0.0f && g.y >= 0.0f && g.z >= 0.0f && g.x < top.x && g.y < top.y && g.z < top.z))
                continue;
            if (!(z > zFront))
                continue;
            ++taken;
            seg.segment(front, classify_.value(g), (z - zFront) * stretch, c, transmittance, front);
            zFront = z;
            if (1.0f - transmittance >= ertAlpha)
                break;
        }
        if (1.0f - transmittance < ertAlpha && zout > zFront)
            seg.segment(front, valueAtDepth(zout), (zout - zFront) * stretch, c, transmittance, front);
    }
    const float alpha = 1.0f - transmittance;
    image.at(x, y) = glm::vec4(c + (1.0f - alpha) * glm::vec3(scene_.background), alpha);
    return taken;
}

}  // namespace clvr::tools
