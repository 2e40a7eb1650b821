// tools/ceiling_spherical.cpp — the plain C++ ceiling loop for spherical's fused path (see
// ceiling_spherical.h): kernels/spherical.cl's spherical_fused, line for line in float, over rows on
// std::threads.
#include "tools/ceiling_spherical.h"

#include <algorithm>
#include <cmath>
#include <thread>

namespace clvr::tools {
namespace {

// kernels/clvr_common.h's clvr_atan2: the same polynomial, the same operations.
float atan2Poly(float y, float x)
{
    const float ax = std::fabs(x), ay = std::fabs(y);
    const float hi = std::max(ax, ay), lo = std::min(ax, ay);
    const float a = hi > 0.0f ? lo / hi : 0.0f;
    const float s = a * a;
    float r = 2.8501858469098806e-3f;
    r = r * s - 1.6069890931248665e-2f;
    r = r * s + 4.269373044371605e-2f;
    r = r * s - 7.504499703645706e-2f;
    r = r * s + 1.064104288816452e-1f;
    r = r * s - 1.4203676581382751e-1f;
    r = r * s + 1.999262422323227e-1f;
    r = r * s - 3.3333075046539307e-1f;
    r = (r * s + 1.0f) * a;
    if (ay > ax)
        r = 1.5707963267948966f - r;
    if (x < 0.0f)
        r = 3.14159265358979323846f - r;
    return std::copysign(r, y);
}

}  // namespace

SphericalCeiling::SphericalCeiling(const Volume& volume, const TransferFunction& tf, const Camera& camera,
                                   const ImageSpec& image, const SphericalOptions& options)
    : VolumeCeiling(image.width, image.height), volume_(volume), camera_(camera),
      background_(glm::vec3(image.background)), center_(glm::vec3(options.domain.center)),
      phiS0_(0.5f / volume.dims.x), phiPeriod_((volume.dims.x - 1.0f) / volume.dims.x),
      ertAlpha_(options.earlyTermination < 1.0 ? static_cast<float>(options.earlyTermination) : 2.0f),
      radial_(options.opacity == SphericalOptions::Opacity::Radial), classify_(volume, tf)
{
    const SphericalDomain& d = options.domain;
    for (const Shell& shell : planShells(options))
        shells_.emplace_back(glm::dvec4(shell.radius, shell.rLo, shell.rHi, (shell.radius - d.rMin) / (d.rMax - d.rMin)));
    const raster::PixelTransfer t = composeTextureMap(options.transfer, volume.dims);
    matrix_ = t.colorMatrix;
    scale_ = t.scale;
    bias_ = t.bias;
}

std::uint64_t SphericalCeiling::renderRow(int y, Image4f& image) const
{
    const glm::vec3 position(camera_.position), forward(camera_.forward()), right(camera_.right()), up(camera_.up());
    const float scale = static_cast<float>(camera_.parallel ? camera_.parallelScale
                                                            : std::tan(glm::radians(camera_.viewAngle) * 0.5));
    const float aspect = static_cast<float>(width_) / static_cast<float>(height_);
    const glm::ivec3 n = volume_.dims;
    const glm::vec3 texels(n), top(n - 1);
    const int shellCount = static_cast<int>(shells_.size());
    const float invTwoPi = 0.15915494309189535f, invPi = 0.3183098861837907f;

    std::uint64_t taken = 0;
    for (int x = 0; x < width_; ++x) {
        // kernels/ray.h's clvr_ray_rounded_terms: unit direction.
        const float ndcX = (x + 0.5f) / width_ * 2.0f - 1.0f, ndcY = 1.0f - (y + 0.5f) / height_ * 2.0f;
        const glm::vec3 r = right * (ndcX * scale * aspect), u = up * (ndcY * scale);
        glm::vec3 origin = position, dir = forward;
        if (camera_.parallel)
            origin += r + u;
        else
            dir = glm::normalize(forward + r + u);
        const glm::vec3 oc = center_ - origin;
        const float tc = glm::dot(oc, dir);
        const glm::vec3 off = oc - tc * dir;
        const float p2 = glm::dot(off, off);

        glm::vec3 c(0.0f);
        float transmittance = 1.0f;
        bool opaque = false;
        int innermost = shellCount;
        for (int pass = 0; pass < 2 && !opaque; ++pass) {
            const float side = pass == 0 ? -1.0f : 1.0f;
            for (int m = pass == 0 ? 0 : innermost; m < shellCount; ++m) {
                const int k = pass == 0 ? shellCount - 1 - m : m;
                const glm::vec4 shell = shells_[k];
                const float radius = shell.x;
                if (!(p2 < radius * radius))
                    break;
                if (pass == 0)
                    innermost = k;
                const float t = tc + side * std::sqrt(radius * radius - p2);
                if (t < 0.0f)
                    continue;
                const glm::vec3 rel = t * dir - oc;
                float uu = atan2Poly(rel.y, rel.x) * invTwoPi;
                uu = uu < 0.0f ? uu + 1.0f : (uu >= 1.0f ? 0.0f : uu);
                const float vv = atan2Poly(std::sqrt(rel.x * rel.x + rel.y * rel.y), rel.z) * invPi;
                glm::vec4 q = bias_ + scale_ * (matrix_ * glm::vec4(uu, vv, shell.w, 1.0f));
                const float w = (q.x - phiS0_) / phiPeriod_;
                q.x = phiS0_ + (w - std::floor(w)) * phiPeriod_;
                ++taken;
                const glm::vec4 ct = classify_(glm::clamp(glm::vec3(q) * texels - 0.5f, glm::vec3(0.0f), top));
                float len = shell.z - shell.y;
                if (!radial_) {  // kernels/spherical.cl's clvr_spherical_slab
                    const float rInner = k > 0 ? shells_[k - 1].x : -1.0f;
                    const float hHi = std::sqrt(std::max(shell.z * shell.z - p2, 0.0f));
                    const float hLo = p2 >= rInner * rInner ? 0.0f : std::sqrt(std::max(shell.y * shell.y - p2, 0.0f));
                    const float t0 = side > 0.0f ? tc + hLo : tc - hHi, t1 = side > 0.0f ? tc + hHi : tc - hLo;
                    len = std::max(t1 - std::max(t0, 0.0f), 0.0f);
                }
                const float alpha = 1.0f - std::exp(-ct.w * len);
                c += (transmittance * alpha) * glm::vec3(ct);
                transmittance *= 1.0f - alpha;
                opaque = 1.0f - transmittance >= ertAlpha_;
                if (opaque)
                    break;
            }
        }
        image.at(x, y) = glm::vec4(c + transmittance * background_, 1.0f - transmittance);
    }
    return taken;
}

}  // namespace clvr::tools
