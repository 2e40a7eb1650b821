// tools/ceiling_stack2d.cpp — the plain C++ ceiling loop for stack2d's fused path (see ceiling_stack2d.h):
// kernels/stack2d.cl's stack2d_fused for direct volume rendering, line for line in float, over rows on
// std::threads.
#include "tools/ceiling_stack2d.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <thread>

namespace clvr::tools {
namespace {

// The stack along `axis` as a volume: axes (b, c, axis) with b < c the other two (stack2d.cpp's
// stackShape), b fastest — the layout of the stack's texels.
Volume stackVolume(const Volume& volume, int axis)
{
    const int p = (axis + 1) % 3, q = (axis + 2) % 3, b = std::min(p, q), c = std::max(p, q);
    const glm::ivec3 n = volume.dims;
    Volume stack;
    stack.dims = glm::ivec3(n[b], n[c], n[axis]);
    stack.values.reserve(volume.voxelCount());
    glm::ivec3 g;
    for (g[axis] = 0; g[axis] < n[axis]; ++g[axis])
        for (g[c] = 0; g[c] < n[c]; ++g[c])
            for (g[b] = 0; g[b] < n[b]; ++g[b])
                stack.values.push_back(volume.at(g.x, g.y, g.z));
    return stack;
}

}  // namespace

bool stack2dCeilingFits(const Scene& scene, const Stack2dOptions& options)
{
    return options.path == Stack2dOptions::Path::Fused && !scene.lighting.shaded() && !scene.iso && !options.clipTexture;
}

Stack2dCeiling::Stack2dCeiling(const Volume& volume, const TransferFunction& tf, const Camera& camera,
                               const ImageSpec& image, const Stack2dOptions& options)
    : VolumeCeiling(image.width, image.height), stack_(stackVolume(volume, stackAxis(camera))), camera_(camera),
      background_(glm::vec3(image.background)), axis_(stackAxis(camera)),
      planes_((volume.dims[axis_] - 1) * (options.intermediate + 1) + 1),
      step_(static_cast<float>(1.0 / (options.intermediate + 1))),
      ertAlpha_(options.earlyTermination < 1.0 ? static_cast<float>(options.earlyTermination) : 2.0f),
      classify_(stack_, tf)
{
    const int p = (axis_ + 1) % 3, q = (axis_ + 2) % 3;
    const int axes[3] = {std::min(p, q), std::max(p, q), axis_};
    for (int r = 0; r < 3; ++r) {  // as stack2d.cpp's renderFused: q_r = (p[a] - origin[a]) / spacing[a]
        toStack_[r] = glm::vec4(0.0f);
        toStack_[r][axes[r]] = static_cast<float>(1.0 / volume.spacing[axes[r]]);
        toStack_[r].w = static_cast<float>(-volume.origin[axes[r]] / volume.spacing[axes[r]]);
    }
}

std::uint64_t Stack2dCeiling::renderRow(int y, Image4f& image) const
{
    const glm::vec3 position(camera_.position), forward(camera_.forward()), right(camera_.right()), up(camera_.up());
    const float scale = static_cast<float>(camera_.parallel ? camera_.parallelScale
                                                            : std::tan(glm::radians(camera_.viewAngle) * 0.5));
    const float aspect = static_cast<float>(width_) / static_cast<float>(height_);
    const glm::ivec3 n = stack_.dims;
    const float bMax = static_cast<float>(n.x - 1), cMax = static_cast<float>(n.y - 1), aMax = static_cast<float>(n.z - 1);
    const float inf = std::numeric_limits<float>::infinity();
    std::uint64_t taken = 0;
    for (int x = 0; x < width_; ++x) {
        // kernels/ray.h's clvr_ray_depth: o + z d, z the eye depth.
        const float ndcX = (x + 0.5f) / width_ * 2.0f - 1.0f, ndcY = 1.0f - (y + 0.5f) / height_ * 2.0f;
        const float sx = ndcX * scale * aspect, sy = ndcY * scale;
        glm::vec3 o = position, d = forward + sx * right + sy * up;
        if (camera_.parallel) {
            o = position + sx * right + sy * up;
            d = forward;
        }
        glm::vec3 qo, qd;
        for (int r = 0; r < 3; ++r) {
            qo[r] = glm::dot(glm::vec3(toStack_[r]), o) + toStack_[r].w;
            qd[r] = glm::dot(glm::vec3(toStack_[r]), d);
        }
        glm::vec3 c(0.0f);
        float transmittance = 1.0f;
        if (qd.z != 0.0f) {
            // The ray by the plane coordinate u = q.z: q = q1o + u q1d.
            const glm::vec3 q1d(qd.x / qd.z, qd.y / qd.z, 1.0f);
            const glm::vec3 q1o(qo.x - qo.z * q1d.x, qo.y - qo.z * q1d.y, 0.0f);
            // The chord through the box in u (kernels/volume_sampling.h's clvr_box_chord on [0, n - 1]).
            float uin, uout;
            boxChord(q1o, q1d, glm::vec3(std::nextafter(bMax, inf), std::nextafter(cMax, inf), aMax), uin, uout);
            int jLo, jHi;
            sliceRange(uin, uout, 0.0f, step_, planes_, jLo, jHi);
            const int dir = qd.z > 0.0f ? 1 : -1, jEnd = dir > 0 ? jHi : jLo;
            const float negFull = -step_ * glm::length(d) / std::fabs(qd.z);
            for (int j = dir > 0 ? jLo : jHi; dir * (jEnd - j) >= 0; j += dir) {
                const glm::vec3 q = q1o + (static_cast<float>(j) * step_) * q1d;
                if (!(q.x >= 0.0f && q.y >= 0.0f && q.x <= bMax && q.y <= cMax))
                    continue;
                if (!((q.z - qo.z) * static_cast<float>(dir) > 0.0f))
                    continue;  // behind the eye
                ++taken;
                const glm::vec4 ct = classify_(q);
                const float slab = j == 0 || j == planes_ - 1 ? 0.5f : 1.0f;
                const float alpha = 1.0f - std::exp(ct.w * (slab * negFull));
                c += (transmittance * alpha) * glm::vec3(ct);
                transmittance *= 1.0f - alpha;
                if (1.0f - transmittance >= ertAlpha_)
                    break;
            }
        }
        image.at(x, y) = glm::vec4(c + transmittance * background_, 1.0f - transmittance);
    }
    return taken;
}

}  // namespace clvr::tools
