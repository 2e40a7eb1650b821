// tools/ceiling_projtet.cpp — the plain C++ ceiling loop for projtet (see ceiling_projtet.h): the renderer's
// projection, then kernels/projtet.cl's fragment statement for statement in float over each cell's pixel box, the
// raster stage's premultiplied blending, and the over-background pass.
#include "tools/ceiling_projtet.h"

#include "host/render/camera_args.h"
#include "host/render/tet/harc.h"
#include "host/runtime/parallel.h"
#include "kernels/projtet_params.h"

#include <algorithm>
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
    // The cells' boxes of pixel centres, as the renderer's fused path takes them (projtetCellBoxes: the raster
    // path's projection, a cell at the near plane covering the whole image).
    const std::vector<ProjtetBox> boxes = projtetCellBoxes(points_, tets_, camera_, width_, height_);
    auto parallel = [&](const auto& work) {
        std::vector<std::thread> pool;
        for (int t = 0; t < threads; ++t)
            pool.emplace_back(work, t);
        for (std::thread& th : pool)
            th.join();
    };

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
            const ProjtetBox& box = boxes[order_[i]];
            if (box.x0 > box.x1 || box.y0 > box.y1)
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
                        const glm::vec4 h = planes[f];
                        // projtet_in_plane: a ray in the face's plane counts in one cell of the face only
                        if (std::fabs(hd) <= PROJTET_IN_PLANE * (std::fabs(h.x) + std::fabs(h.y) + std::fabs(h.z)) &&
                            std::fabs(b) <= PROJTET_IN_PLANE * (std::fabs(h.x * e.x) + std::fabs(h.y * e.y) +
                                                                std::fabs(h.z * e.z) + std::fabs(h.w))) {
                            miss = miss || !(glm::dot(glm::vec3(h), glm::vec3(PROJTET_TIE_X, PROJTET_TIE_Y, PROJTET_TIE_Z)) > 0.0f);
                            continue;
                        }
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
