// raster/reference/texture.cpp — GL 1.2 texture sampling (§3.8.5-3.8.7) in double precision.
#include "raster/reference/texture.h"

#include "host/runtime/errors.h"

#include <algorithm>
#include <cmath>
#include <string>

namespace clvr::raster::reference {
namespace {

struct Sampler {
    const TextureDesc& d;
    const std::vector<float>& texels;

    glm::dvec4 texel(int i, int j, int k) const
    {
        if (d.wrap == Wrap::ClampToBorder) {
            if (i < 0 || j < 0 || k < 0 || i >= d.width || j >= d.height || k >= d.depth)
                return glm::dvec4(d.border);
        } else {
            i = std::clamp(i, 0, d.width - 1);
            j = std::clamp(j, 0, d.height - 1);
            k = std::clamp(k, 0, d.depth - 1);
        }
        const std::size_t index = (static_cast<std::size_t>(k) * d.height + j) * d.width + i;
        if (d.channels == 1)
            return glm::dvec4(texels[index]);
        const float* p = &texels[4 * index];
        return {p[0], p[1], p[2], p[3]};
    }
};

// u n limited to [-1/2, n + 1/2] (GL's CLAMP_TO_BORDER coordinate clamp; kernels/texture.h).
double position(double u, int n)
{
    if (std::isnan(u))
        return -0.5;  // the device's fmax(NaN, -0.5)
    return std::clamp(u * n, -0.5, n + 0.5);
}

int nearest(double u, int n)
{
    return static_cast<int>(std::floor(position(u, n)));
}

int lower(double u, int n, double& f)
{
    const double x = position(u, n) - 0.5;
    const double i0 = std::floor(x);
    f = x - i0;
    return static_cast<int>(i0);
}

glm::dvec4 lerp(const glm::dvec4& a, const glm::dvec4& b, double f)
{
    return a + (b - a) * f;
}

}  // namespace

glm::dvec4 sampleTexture(const TextureDesc& desc, const std::vector<float>& texels, glm::dvec3 c, int dimensions)
{
    validate(desc, texels.size());
    if (dimensions < 1 || dimensions > 3)
        throw InternalError("texture dimensions " + std::to_string(dimensions) + " is not 1, 2 or 3");
    const Sampler s{desc, texels};
    const int ny = dimensions >= 2 ? desc.height : 1;  // an unused axis samples row/slice 0
    const int nz = dimensions >= 3 ? desc.depth : 1;
    if (desc.filter == Filter::Nearest)
        return s.texel(nearest(c.x, desc.width), dimensions >= 2 ? nearest(c.y, ny) : 0,
                       dimensions >= 3 ? nearest(c.z, nz) : 0);
    double fx = 0, fy = 0, fz = 0;
    const int i = lower(c.x, desc.width, fx);
    const int j = dimensions >= 2 ? lower(c.y, ny, fy) : 0;
    const int k = dimensions >= 3 ? lower(c.z, nz, fz) : 0;
    const auto row = [&](int jj, int kk) { return lerp(s.texel(i, jj, kk), s.texel(i + 1, jj, kk), fx); };
    if (dimensions == 1)
        return row(0, 0);
    const auto slice = [&](int kk) { return lerp(row(j, kk), row(j + 1, kk), fy); };
    if (dimensions == 2)
        return slice(0);
    return lerp(slice(k), slice(k + 1), fz);
}

glm::dvec4 sampleTexture(const TextureDesc& desc, const std::vector<float>& texels, glm::dvec3 coord)
{
    return sampleTexture(desc, texels, coord, desc.depth > 1 ? 3 : desc.height > 1 ? 2 : 1);
}

}  // namespace clvr::raster::reference
