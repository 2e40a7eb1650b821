// tools/ceiling_projtet.cpp — the plain C++ ceiling loop for projtet (see ceiling_projtet.h): the renderer's
// projection, then kernels/projtet.cl's fragment statement for statement in float over each cell's pixel box, the
// raster stage's premultiplied blending, and the over-background pass.
#include "tools/ceiling_projtet.h"

#include "host/render/camera_args.h"
#include "host/render/tet/harc.h"
#include "host/runtime/parallel.h"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <limits>
#include <thread>

namespace clvr::tools {
namespace {

constexpr int kRowBlock = 8;  // rows per block; thread t owns the blocks t, t + threads, ...

glm::vec3 projtetVec3(const cl_float4& v)
{
    return {v.s[0], v.s[1], v.s[2]};
}

// A cell's pixels: x0..x1, y0..y1 inclusive (empty when x0 > x1 or y0 > y1).
struct PixelBox {
    int x0, x1, y0, y1;
};

}  // namespace

ProjtetCeiling::ProjtetCeiling(const TetMesh& mesh, const TetTopology& topology, const TransferFunction& tf,
                               const Camera& camera, const ImageSpec& image, const ProjtetOptions& options)
    : width_(image.width), height_(image.height), background_(image.background), camera_(camera),
      points_(mesh.points), tets_(mesh.tets.begin(), mesh.tets.end()), segments_(tf)
{
    // As ProjtetRenderer: the cells relative to the centre of the mesh's box, sorted back to front.
    const glm::dvec3 shift = 0.5 * (mesh.boundsMin() + mesh.boundsMax());
    rayCamera_ = toClCamera(camera, width_, height_, shift);
    for (const cl_float4& v : packHarcTets(mesh, topology, shift))
        cells_.emplace_back(v.s[0], v.s[1], v.s[2], v.s[3]);
    order_ = VisibilitySorter(mesh, topology).sort(camera, options.order, width_, height_).order;
}

ProjtetCeilingResult ProjtetCeiling::render(int threads) const
{
    if (threads <= 0)
        threads = threadBudget();
    // The renderer's projection (ProjtetRenderer::render): each point in float NDC, a cell with a point at or
    // behind the near plane covering the whole image; then each cell's box of pixel centres, by cell in order.
    const glm::dvec3 forward = camera_.forward();
    double depthMax = 0.0;
    for (const glm::dvec3& p : points_)
        depthMax = std::max(depthMax, glm::dot(p - camera_.position, forward));
    const double nearZ = 1e-4 * depthMax + 1e-9, farZ = 2.0 * depthMax + 1.0;
    const glm::dmat4 viewProjection = camera_.projectionMatrix(width_, height_, nearZ, farZ) * camera_.viewMatrix();
    std::vector<glm::vec2> window(points_.size());  // pixel coordinates, row 0 at the top
    std::vector<std::uint8_t> inFront(points_.size());
    std::vector<PixelBox> boxes(order_.size());
    auto parallel = [&](const auto& work) {
        std::vector<std::thread> pool;
        for (int t = 0; t < threads; ++t)
            pool.emplace_back(work, t);
        for (std::thread& th : pool)
            th.join();
    };
    parallel([&](int t) {
        const std::size_t n = points_.size(), begin = n * t / threads, end = n * (t + 1) / threads;
        for (std::size_t p = begin; p < end; ++p) {
            const glm::dvec4 c = viewProjection * glm::dvec4(points_[p], 1.0);
            inFront[p] = camera_.parallel || c.w > nearZ;
            const glm::vec2 ndc(static_cast<float>(c.x / c.w), static_cast<float>(c.y / c.w));
            window[p] = glm::vec2((ndc.x + 1.0f) * 0.5f * static_cast<float>(width_),
                                  (1.0f - ndc.y) * 0.5f * static_cast<float>(height_));
        }
    });
    parallel([&](int t) {
        constexpr float kMargin = 1.0f / 16.0f;  // the renderer grows each silhouette by this much
        const std::size_t n = order_.size(), begin = n * t / threads, end = n * (t + 1) / threads;
        for (std::size_t i = begin; i < end; ++i) {
            const glm::uvec4 tet = tets_[order_[i]];
            if (!(inFront[tet[0]] && inFront[tet[1]] && inFront[tet[2]] && inFront[tet[3]])) {
                boxes[i] = {0, width_ - 1, 0, height_ - 1};
                continue;
            }
            glm::vec2 lo = window[tet[0]], hi = lo;
            for (int v = 1; v < 4; ++v) {
                lo = glm::min(lo, window[tet[v]]);
                hi = glm::max(hi, window[tet[v]]);
            }
            // the pixel centres x + 0.5 in [lo - margin, hi + margin]
            boxes[i] = {std::max(static_cast<int>(std::ceil(lo.x - kMargin - 0.5f)), 0),
                        std::min(static_cast<int>(std::floor(hi.x + kMargin - 0.5f)), width_ - 1),
                        std::max(static_cast<int>(std::ceil(lo.y - kMargin - 0.5f)), 0),
                        std::min(static_cast<int>(std::floor(hi.y + kMargin - 0.5f)), height_ - 1)};
        }
    });

    // The draw: every thread walks every cell in order over the rows it owns.
    std::vector<glm::vec4> fb(static_cast<std::size_t>(width_) * height_, glm::vec4(0.0f));
    std::vector<std::uint64_t> tested(threads, 0), integrated(threads, 0);
    const glm::vec3 position = projtetVec3(rayCamera_.position), camForward = projtetVec3(rayCamera_.forward),
                    right = projtetVec3(rayCamera_.right), up = projtetVec3(rayCamera_.up);
    const float scale = rayCamera_.params.s[0], aspect = rayCamera_.params.s[1];
    const bool parallelRays = rayCamera_.params.s[2] != 0.0f;
    const CeilingSegments& seg = segments_;
    parallel([&](int thread) {
        std::uint64_t pixelsTested = 0, segmentCount = 0;
        for (std::size_t i = 0; i < order_.size(); ++i) {
            const PixelBox& box = boxes[i];
            if (box.x0 > box.x1)
                continue;
            const glm::vec4* cell = cells_.data() + static_cast<std::size_t>(order_[i]) * 5;
            const glm::vec4 planes[4] = {cell[0], cell[1], cell[2],
                                         glm::vec4(-(glm::vec3(cell[0]) + glm::vec3(cell[1]) + glm::vec3(cell[2])),
                                                   1.0f - (cell[0].w + cell[1].w + cell[2].w))};
            const glm::vec4 grad = cell[3];
            for (int y = box.y0; y <= box.y1; ++y) {
                if ((y / kRowBlock) % threads != thread)
                    continue;
                const float sy = (1.0f - (static_cast<float>(y) + 0.5f) / static_cast<float>(height_) * 2.0f) * scale;
                for (int x = box.x0; x <= box.x1; ++x) {
                    ++pixelsTested;
                    // kernels/ray.h's clvr_ray_unit through the pixel centre
                    const float sx = ((static_cast<float>(x) + 0.5f) / static_cast<float>(width_) * 2.0f - 1.0f) * scale * aspect;
                    glm::vec3 e = position, d = camForward;
                    if (parallelRays)
                        e = position + sx * right + sy * up;
                    else
                        d = glm::normalize(camForward + sx * right + sy * up);
                    // kernels/projtet.cl's clvr_fragment: the ray inside all four planes
                    float lambdaIn = 0.0f, lambdaOut = std::numeric_limits<float>::infinity();
                    bool miss = false;
                    for (int f = 0; f < 4; ++f) {
                        const float hd = glm::dot(glm::vec3(planes[f]), d);
                        const float b = glm::dot(glm::vec3(planes[f]), e) + planes[f].w;
                        if (hd > 0.0f)
                            lambdaIn = std::max(lambdaIn, -b / hd);
                        else if (hd < 0.0f)
                            lambdaOut = std::min(lambdaOut, b / -hd);
                        else if (b < 0.0f)
                            miss = true;
                    }
                    const float l = lambdaOut - lambdaIn;
                    if (miss || !(l > 0.0f))
                        continue;
                    ++segmentCount;
                    const float sF = glm::dot(glm::vec3(grad), e + lambdaIn * d) + grad.w;
                    const float sB = glm::dot(glm::vec3(grad), e + lambdaOut * d) + grad.w;
                    glm::vec3 c(0.0f);
                    float transmittance = 1.0f;
                    CeilingSegments::Point back;
                    seg.segment(seg.point(sF), sB, l, c, transmittance, back);
                    glm::vec4& dst = fb[static_cast<std::size_t>(y) * width_ + x];
                    const glm::vec4 src(c, 1.0f - transmittance);
                    dst = src + (1.0f - src.a) * dst;  // ONE, ONE_MINUS_SRC_ALPHA
                }
            }
        }
        tested[thread] = pixelsTested;
        integrated[thread] = segmentCount;
    });

    ProjtetCeilingResult result;
    result.image = Image4f(width_, height_);
    for (int y = 0; y < height_; ++y)
        for (int x = 0; x < width_; ++x) {  // slice3d_over_background
            const glm::vec4 c = fb[static_cast<std::size_t>(y) * width_ + x];
            result.image.at(x, y) = glm::vec4(glm::vec3(c) + (1.0f - c.w) * background_, c.w);
        }
    for (int t = 0; t < threads; ++t) {
        result.pixelsTested += tested[t];
        result.segments += integrated[t];
    }
    return result;
}

}  // namespace clvr::tools
