// tools/ceiling_cubefan.cpp — the plain C++ ceiling loop for cubefan's fused path (see ceiling_cubefan.h):
// kernels/cubefan.cl's cubefan_fused, line for line in float, over rows on std::threads.
#include "tools/ceiling_cubefan.h"

#include "host/render/grid/cube_octree.h"

#include <algorithm>
#include <cmath>

namespace clvr::tools {

CubefanCeiling::CubefanCeiling(const Volume& volume, const TransferFunction& tf, const Camera& camera,
                               const ImageSpec& image, const CubefanOptions& options)
    : VolumeCeiling(image.width, image.height), background_(glm::vec3(image.background)), dims_(volume.dims),
      ertAlpha_(options.earlyTermination < 1.0 ? static_cast<float>(options.earlyTermination) : 2.0f),
      error_(options.error)
{
    // The renderer's frame: the cube field's box centred on the origin (float precision), the camera moved with it.
    glm::dvec3 lo, hi;
    cubefan::cubeFieldBounds(volume, lo, hi);
    const glm::dvec3 shift = 0.5 * (lo + hi);
    camera_ = camera.relativeTo(shift);
    fieldLo_ = glm::vec3(lo - shift);
    invSpacing_ = glm::vec3(1.0 / volume.spacing);
    const cubefan::CubeOctree octree(volume);
    cubefan::SelectionStats stats;
    walk_ = buildCubefanWalkGrid(octree, volume.dims, options.error, tf, &stats);
    cubes_ = stats.selected;
    filledLo_ = walk_.filledLo;
    filledHi_ = walk_.filledHi;
    for (const ControlPoint& p : tf.points()) {
        tfS_.push_back(static_cast<float>(p.s));
        tfValue_.emplace_back(glm::vec3(p.color), static_cast<float>(p.tau));
    }
}

std::uint64_t CubefanCeiling::renderRow(int y, Image4f& image) const
{
    const glm::vec3 position(camera_.position), forward(camera_.forward()), right(camera_.right()), up(camera_.up());
    const float scale = static_cast<float>(camera_.parallel ? camera_.parallelScale
                                                            : std::tan(glm::radians(camera_.viewAngle) * 0.5));
    const float aspect = static_cast<float>(width_) / static_cast<float>(height_);
    const int nx = dims_.x, ny = dims_.y, nz = dims_.z;
    const std::size_t bricksX = static_cast<std::size_t>((nx + 3) >> 2), bricksY = static_cast<std::size_t>((ny + 3) >> 2);
    const std::uint8_t* level = walk_.grid.level.data();
    const float* value = walk_.grid.value.data();
    const std::uint8_t* space = walk_.space.data();
    const int tfCount = static_cast<int>(tfS_.size());
    std::uint64_t crossed = 0;
    for (int x = 0; x < width_; ++x) {
        // kernels/cubefan.cl's cubefan_ray: the ray, its direction normalized, in the grid's coordinates.
        const float sx = ((x + 0.5f) / width_ * 2.0f - 1.0f) * scale * aspect, sy = (1.0f - (y + 0.5f) / height_ * 2.0f) * scale;
        glm::vec3 e = position, d = forward;
        if (camera_.parallel) {
            e += sx * right + sy * up;
        } else {
            d += sx * right + sy * up;
            d *= 1.0f / std::sqrt(d.x * d.x + d.y * d.y + d.z * d.z);
        }
        const glm::vec3 qe = (e - fieldLo_) * invSpacing_;
        glm::vec3 qd = d * invSpacing_;
        for (int a = 0; a < 3; ++a)
            if (std::fabs(qd[a]) < 1e-30f)
                qd[a] = std::copysign(1e-30f, qd[a]);
        const glm::vec3 inv = 1.0f / qd;
        const glm::vec3 t0 = (glm::vec3(filledLo_) - qe) * inv, t1 = (glm::vec3(filledHi_) - qe) * inv;
        const glm::vec3 tn = glm::min(t0, t1), tx = glm::max(t0, t1);
        float t = std::max(std::max(std::max(tn.x, tn.y), tn.z), 0.0f);
        const float tOut = std::min(std::min(tx.x, tx.y), tx.z);
        const bool px = qd.x > 0.0f, py = qd.y > 0.0f, pz = qd.z > 0.0f;
        glm::vec3 c(0.0f);
        float transmittance = 1.0f;
        if (tOut > t) {
            int v[3] = {std::clamp(static_cast<int>(std::floor(qe.x + qd.x * t)), filledLo_.x, filledHi_.x - 1),
                        std::clamp(static_cast<int>(std::floor(qe.y + qd.y * t)), filledLo_.y, filledHi_.y - 1),
                        std::clamp(static_cast<int>(std::floor(qe.z + qd.z * t)), filledLo_.z, filledHi_.z - 1)};
            for (;;) {
                const std::size_t at = ((static_cast<std::size_t>(v[2] >> 2) * bricksY + static_cast<std::size_t>(v[1] >> 2)) * bricksX +
                                        static_cast<std::size_t>(v[0] >> 2)) << 6 |
                                       static_cast<std::size_t>(((v[2] & 3) << 4) | ((v[1] & 3) << 2) | (v[0] & 3));
                const int code = level[at], l = code & 0x7f;
                int lo[3], hi[3];
                const int n[3] = {nx, ny, nz};
                for (int a = 0; a < 3; ++a) {
                    lo[a] = (v[a] >> l) << l;
                    hi[a] = std::min(lo[a] + (1 << l), n[a]);
                }
                if (code & cubefan::CubeOctree::kTransparent) {
                    const int r = static_cast<int>(space[at >> 6]) - 1;  // the cube of empty bricks around it
                    if (r >= 0 && 8 * r + 4 > (1 << l))
                        for (int a = 0; a < 3; ++a) {
                            lo[a] = std::max(((v[a] >> 2) - r) << 2, 0);
                            hi[a] = std::min(((v[a] >> 2) + r + 1) << 2, n[a]);
                        }
                }
                const float tbx = (static_cast<float>(px ? hi[0] : lo[0]) - qe.x) * inv.x;
                const float tby = (static_cast<float>(py ? hi[1] : lo[1]) - qe.y) * inv.y;
                const float tbz = (static_cast<float>(pz ? hi[2] : lo[2]) - qe.z) * inv.z;
                const int axis = tbx <= tby ? (tbx <= tbz ? 0 : 2) : (tby <= tbz ? 1 : 2);
                const float tExit = std::max(axis == 0 ? tbx : (axis == 1 ? tby : tbz), t);
                if (!(code & cubefan::CubeOctree::kTransparent)) {
                    ++crossed;
                    // kernels/transfer_function.h's clvr_tf_eval at the cube's value
                    const float s = value[at];
                    glm::vec4 ct = tfValue_[0];
                    if (s >= tfS_[tfCount - 1]) {
                        ct = tfValue_[tfCount - 1];
                    } else if (s > tfS_[0]) {
                        int m = 1;
                        while (tfS_[m] <= s)
                            ++m;
                        ct = tfValue_[m - 1] + (s - tfS_[m - 1]) / (tfS_[m] - tfS_[m - 1]) * (tfValue_[m] - tfValue_[m - 1]);
                    }
                    const float alpha = 1.0f - std::exp(ct.w * (t - tExit));
                    c += (transmittance * alpha) * glm::vec3(ct);
                    transmittance *= 1.0f - alpha;
                    if (1.0f - transmittance >= ertAlpha_)
                        break;
                }
                t = tExit;
                const bool positive[3] = {px, py, pz};
                const float qeA[3] = {qe.x, qe.y, qe.z}, qdA[3] = {qd.x, qd.y, qd.z};
                for (int a = 0; a < 3; ++a) {  // kernels/cubefan.cl's cubefan_next
                    if (a == axis) {
                        v[a] = positive[a] ? hi[a] : lo[a] - 1;
                    } else {
                        const int along = std::clamp(static_cast<int>(std::floor(qeA[a] + qdA[a] * t)), lo[a], hi[a] - 1);
                        v[a] = positive[a] ? std::max(v[a], along) : std::min(v[a], along);
                    }
                }
                if (v[0] < filledLo_.x || v[1] < filledLo_.y || v[2] < filledLo_.z || v[0] >= filledHi_.x ||
                    v[1] >= filledHi_.y || v[2] >= filledHi_.z)
                    break;
            }
        }
        image.at(x, y) = glm::vec4(c + transmittance * background_, 1.0f - transmittance);
    }
    return crossed;
}

}  // namespace clvr::tools
