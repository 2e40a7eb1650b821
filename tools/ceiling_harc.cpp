// tools/ceiling_harc.cpp — the plain C++ ceiling loop for harc (see ceiling_harc.h): kernels/harc.cl's
// harc_render with partial integration and kernels/segment_integral.h's pieces, statement for statement
// in float, over rows on std::threads.
#include "tools/ceiling_harc.h"

#include "host/render/camera_args.h"
#include "host/render/scaffold.h"
#include "host/render/transfer_function_upload.h"
#include "host/runtime/parallel.h"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstring>
#include <limits>
#include <thread>

namespace clvr::tools {
namespace {

glm::vec4 toVec4(const cl_float4& v)
{
    return {v.s[0], v.s[1], v.s[2], v.s[3]};
}

glm::vec3 xyz(const cl_float4& v)
{
    return {v.s[0], v.s[1], v.s[2]};
}

}  // namespace

bool harcCeilingFits(const TetMesh& mesh)
{
    return !mesh.part;
}

HarcCeiling::HarcCeiling(const TetMesh& mesh, const TetTopology& topology, const TransferFunction& tf,
                         const Camera& camera, const ImageSpec& image, const HarcOptions& options)
    : width_(image.width), height_(image.height), background_(image.background), segments_(tf)
{
    // The renderer's frame: coordinates relative to the centre of harc's box.
    glm::dvec3 lo, hi;
    harcBounds(mesh, lo, hi);
    const glm::dvec3 shift = 0.5 * (lo + hi);
    camera_ = toClCamera(camera, width_, height_, shift);
    maxSteps_ = static_cast<std::uint32_t>(std::min<std::uint64_t>(harcMaxSteps(options, MeshCounts::of(mesh).rendered),
                                                                   0xffffffffu));
    ertAlpha_ = options.earlyTermination < 1.0 ? static_cast<float>(options.earlyTermination) : 2.0f;

    // The cells in harc's order on the device (harcCellOrder), the entry lists' codes mapped to it, as the renderer.
    const std::vector<std::uint32_t> slot = harcCellOrder(mesh, topology);
    for (const cl_float4& v : packHarcTets(mesh, topology, shift, slot))
        tets_.push_back(toVec4(v));
    lists_ = buildHarcEntryLists(mesh, topology, camera, width_, height_);
    if (!slot.empty())
        for (cl_int2& entry : lists_.entries)
            entry.s[1] = harcDeviceCode(entry.s[1], slot);
    const std::int64_t eyeTet = camera.parallel ? -1 : locatePoint(mesh, camera.position);
    if (eyeTet >= 0)
        prependEyeEntry(lists_, harcCellPlace(static_cast<std::size_t>(eyeTet), slot));
    integration_ = options.integration;
    if (options.integration == HarcOptions::Integration::Full) {  // as HarcRenderer::buildFullTable
        const glm::dvec2 range = mesh.scalarRange();
        double lMax = longestTetEdge(mesh);
        if (!(lMax > 0.0))
            lMax = 1.0;
        full_ = buildPreintegrationTable(tf, std::min(tf.sMin(), range.x), std::max(tf.sMax(), range.y), lMax,
                                         options.fullScalarSamples, options.fullLengthSamples);
    }
    if (options.integration == HarcOptions::Integration::Iso) {
        const HarcOptions::HarcIso& iso = options.iso;
        iso_ = true;
        isoValue_ = static_cast<float>(iso.value);
        isoAmbient_ = static_cast<float>(iso.ambient);
        isoDiffuse_ = static_cast<float>(iso.diffuse);
        isoShaded_ = iso.shaded;
        isoEqualWeights_ = iso.equalWeights;
        isoLight_ = glm::vec3(iso.light);
        isoColor_ = tf.points().empty() ? glm::vec3(1.0f) : glm::vec3(glm::dvec3(tf(iso.value)));  // harc's isoColorOf
        isoNormals_.resize(mesh.tets.size() * 3);
        for (std::size_t t = 0; t < mesh.tets.size(); ++t)
            for (int axis = 0; axis < 3; ++axis)
                for (int v = 0; v < 4; ++v)
                    isoNormals_[3 * harcCellPlace(t, slot) + axis][v] = static_cast<float>(iso.normals[mesh.tets[t][v]][axis]);
    }
    if (options.integration == HarcOptions::Integration::Slices) {
        slices_ = true;
        sliceDepth0_ = static_cast<float>(options.sliceDepth0);
        sliceSpacing_ = static_cast<float>(options.sliceSpacing);
        sliceCount_ = options.sliceCount;
    }

}

HarcCeilingResult HarcCeiling::render(int threads) const
{
    if (threads <= 0)
        threads = threadBudget();
    HarcCeilingResult result;
    result.image = Image4f(width_, height_);
    std::atomic<int> nextRow{0};
    std::vector<Counts> counts(threads);
    std::vector<std::thread> pool;
    for (int t = 0; t < threads; ++t)
        pool.emplace_back([&, t] {
            for (int y; (y = nextRow.fetch_add(1)) < height_;)
                renderRow(y, result.image, counts[t]);
        });
    for (std::thread& th : pool)
        th.join();
    for (const Counts& c : counts) {
        result.steps += c.steps;
        result.pieces += c.pieces;
    }
    return result;
}

void HarcCeiling::renderRow(int y, Image4f& image, Counts& counts) const
{
    const glm::vec4* tets = tets_.data();
    const cl_uint* offsets = lists_.offsets.data();
    const cl_int2* entries = lists_.entries.data();
    const CeilingSegments& seg = segments_;  // kernels/segment_integral.h
    using TfPoint = CeilingSegments::Point;

    // kernels/harc.cl's harc_slices (tetslice's fused path): the slices of constant eye depth in [segF, segB), in
    // order; df, the eye depth per unit λ.
    auto slices = [&](float df, const glm::vec3& e, const glm::vec3& d, const glm::vec4& grad, float segF, float segB,
                      glm::vec3& color, float& transmittance) {
        const float negLog2e = -(sliceSpacing_ / df) * 1.44269504f;
        int k = std::max(static_cast<int>(std::ceil((segF * df - sliceDepth0_) / sliceSpacing_)) - 1, 0);
        std::uint32_t taken = 0;
        for (; k < sliceCount_; ++k) {
            const float lambdaK = (sliceDepth0_ + static_cast<float>(k) * sliceSpacing_) / df;
            if (!(lambdaK < segB))
                break;
            if (lambdaK < segF)
                continue;
            const float s = glm::dot(glm::vec3(grad), e + lambdaK * d) + grad.w;  // kernels/transfer_function.h
            const glm::vec4 ct = seg.tfAt(seg.upper(s), s);
            const float alpha = 1.0f - std::exp2(ct.w * negLog2e);
            color += (transmittance * alpha) * glm::vec3(ct);
            transmittance *= 1.0f - alpha;
            ++taken;
        }
        return taken;
    };

    // kernels/ray.h's clvr_ray_unit for the whole image (no band).
    const glm::vec3 position = xyz(camera_.position), forward = xyz(camera_.forward), right = xyz(camera_.right),
                    up = xyz(camera_.up);
    const float scale = camera_.params.s[0], aspect = camera_.params.s[1];
    const bool parallel = camera_.params.s[2] != 0.0f;
    const float ndcY = 1.0f - (static_cast<float>(y) + 0.5f) / static_cast<float>(height_) * 2.0f;

    std::uint64_t rowSteps = 0, rowPieces = 0;  // added to `counts` once per row (no shared cache line per piece)
    for (int x = 0; x < width_; ++x) {
        const float ndcX = (static_cast<float>(x) + 0.5f) / static_cast<float>(width_) * 2.0f - 1.0f;
        const float sx = ndcX * scale * aspect, sy = ndcY * scale;
        glm::vec3 e = position, d = forward;
        if (parallel)
            e = position + sx * right + sy * up;
        else
            d = glm::normalize(forward + sx * right + sy * up);

        const std::size_t p = static_cast<std::size_t>(y) * width_ + x;
        glm::vec3 color(0.0f);
        float transmittance = 1.0f;
        std::uint32_t steps = 0;
        bool bounded = false;
        float lambdaDone = -std::numeric_limits<float>::infinity();
        const cl_uint end = offsets[p + 1];
        for (cl_uint k = offsets[p]; k < end && !bounded; ++k) {
            float lambda;
            std::memcpy(&lambda, &entries[k].s[0], sizeof lambda);
            const int code = entries[k].s[1];
            if (lambda < lambdaDone - 1e-5f * (1.0f + std::fabs(lambdaDone)))
                continue;
            lambda = std::max(lambda, lambdaDone);
            int t = code >= 0 ? code >> 2 : -1 - code;
            int entryFace = code >= 0 ? code & 3 : -1;
            TfPoint carried{};
            bool carry = false, stop = false;
            for (;;) {
                if (steps >= maxSteps_) {
                    bounded = true;
                    break;
                }
                ++steps;
                const glm::vec4* tet = tets + static_cast<std::size_t>(t) * 5;
                const glm::vec4 planes[4] = {tet[0], tet[1], tet[2],
                                             glm::vec4(-(glm::vec3(tet[0]) + glm::vec3(tet[1]) + glm::vec3(tet[2])),
                                                       1.0f - (tet[0].w + tet[1].w + tet[2].w))};
                const glm::vec4 grad = tet[3];
                std::int32_t adj[4];
                std::memcpy(adj, &tet[4], sizeof adj);
                const glm::vec3 pos = e + lambda * d;
                float bestNum = 0.0f, bestDen = 0.0f;
                int exitFace = -1;
                for (int i = 0; i < 4; ++i) {
                    const float den = -glm::dot(glm::vec3(planes[i]), d);
                    if (i != entryFace && den > 0.0f) {
                        const float num = std::max(glm::dot(glm::vec3(planes[i]), pos) + planes[i].w, 0.0f);
                        if (exitFace < 0 || num * bestDen < bestNum * den) {
                            bestNum = num;
                            bestDen = den;
                            exitFace = i;
                        }
                    }
                }
                if (exitFace < 0) {
                    lambdaDone = lambda;
                    break;
                }
                const float step = bestNum / bestDen;
                const float lambdaExit = lambda + step;
                if (iso_) {  // tetiso's fused path: kernels/harc.cl's harc_iso_hit
                    const float sF = glm::dot(glm::vec3(grad), pos) + grad.w;
                    const float sB = glm::dot(glm::vec3(grad), e + lambdaExit * d) + grad.w;
                    if ((sF <= isoValue_ && sB > isoValue_) || (sF >= isoValue_ && sB < isoValue_)) {
                        const float q = (isoValue_ - sF) / (sB - sF);
                        glm::vec3 c = glm::clamp(isoColor_, 0.0f, 1.0f);
                        if (isoShaded_) {
                            const float w = isoEqualWeights_ ? 0.5f : q;
                            const glm::vec3 pf = e + lambda * d, pb = e + lambdaExit * d;
                            glm::vec4 b;
                            for (int i = 0; i < 4; ++i)
                                b[i] = (1.0f - w) * (glm::dot(glm::vec3(planes[i]), pf) + planes[i].w) +
                                       w * (glm::dot(glm::vec3(planes[i]), pb) + planes[i].w);
                            const glm::vec4* normals = &isoNormals_[static_cast<std::size_t>(t) * 3];
                            const glm::vec3 n(glm::dot(normals[0], b), glm::dot(normals[1], b), glm::dot(normals[2], b));
                            c = glm::clamp(isoColor_ * (isoAmbient_ + isoDiffuse_ * glm::dot(isoLight_, n)), 0.0f, 1.0f);
                        }
                        color = c;
                        transmittance = 0.0f;
                        ++rowPieces;  // the hits
                        stop = true;
                        break;
                    }
                } else if (slices_) {  // tetslice's fused path
                    const float df = glm::dot(d, forward);
                    if (df > 0.0f)
                        rowPieces += slices(df, e, d, grad, lambda, lambdaExit, color, transmittance);
                } else if (integration_ == HarcOptions::Integration::Full ||
                           integration_ == HarcOptions::Integration::Average) {  // one lookup or average a segment
                    const float sF = glm::dot(glm::vec3(grad), pos) + grad.w;
                    const float sB = glm::dot(glm::vec3(grad), e + lambdaExit * d) + grad.w;
                    if (full_) {  // harc_full_lookup
                        const glm::vec4 c = full_->lookup(sF, sB, step);
                        color += transmittance * glm::vec3(c);
                        transmittance *= 1.0f - c.w;
                    } else {  // harc_segment_average
                        const glm::vec4 c = 0.5f * (seg.tfAt(seg.upper(sF), sF) + seg.tfAt(seg.upper(sB), sB));
                        const float zeta = std::exp(-c.w * step);
                        color += transmittance * (1.0f - zeta) * glm::vec3(c);
                        transmittance *= zeta;
                    }
                    ++rowPieces;
                } else {
                    const float sB = glm::dot(glm::vec3(grad), e + lambdaExit * d) + grad.w;
                    TfPoint front = carried;
                    if (!carry) {
                        const float sF = glm::dot(glm::vec3(grad), pos) + grad.w;
                        front = seg.point(sF);
                    }
                    rowPieces += static_cast<std::uint64_t>(seg.segment(front, sB, step, color, transmittance, carried));
                    carry = true;
                }
                if (1.0f - transmittance >= ertAlpha_) {
                    stop = true;
                    break;
                }
                const int next = adj[exitFace];
                lambda = lambdaExit;
                if (next < 0) {
                    lambdaDone = lambdaExit;
                    break;
                }
                t = next >> 2;
                entryFace = next & 3;
            }
            if (stop)
                break;
        }
        rowSteps += steps;
        image.at(x, static_cast<int>(y)) = glm::vec4(color + transmittance * background_, 1.0f - transmittance);
    }
    counts.steps += rowSteps;
    counts.pieces += rowPieces;
}

}  // namespace clvr::tools
