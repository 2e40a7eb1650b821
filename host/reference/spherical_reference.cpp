// host/reference/spherical_reference.cpp — the spherical technique's reference integral (see the header).
#include "host/reference/spherical_reference.h"

#include "host/runtime/parallel.h"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <vector>

namespace clvr {

double sphericalSample(const Volume& volume, const SphericalDomain& domain, const raster::PixelTransfer& transfer,
                       const glm::dvec3& x)
{
    const glm::dvec3 uvw = sphericalCoordinates(domain, x);
    const glm::dvec4 p(uvw, 1.0);
    const glm::dmat4 m(transfer.colorMatrix);
    const glm::dvec4 q = glm::dvec4(transfer.bias) + glm::dvec4(transfer.scale) * (m * p);
    const glm::dvec3 c(q.x - std::floor(q.x), std::clamp(q.y, 0.0, 1.0), std::clamp(q.z, 0.0, 1.0));
    const glm::ivec3 n = volume.dims;
    const glm::dvec3 g = c * glm::dvec3(n - 1);
    glm::ivec3 i0;
    glm::dvec3 f;
    for (int a = 0; a < 3; ++a) {
        i0[a] = std::clamp(static_cast<int>(std::floor(g[a])), 0, n[a] - 2);
        f[a] = g[a] - i0[a];
    }
    double v = 0.0;
    for (int corner = 0; corner < 8; ++corner) {
        const int dx = corner & 1, dy = (corner >> 1) & 1, dz = (corner >> 2) & 1;
        const double weight = (dx ? f.x : 1.0 - f.x) * (dy ? f.y : 1.0 - f.y) * (dz ? f.z : 1.0 - f.z);
        v += weight * volume.at(i0.x + dx, i0.y + dy, i0.z + dz);
    }
    return v;
}

namespace {

// (I, A) of the ray over its chords, n midpoint segments per chord, front to back.
glm::dvec4 integrate(const Volume& volume, const TransferFunction& tf, const SphericalDomain& domain,
                     const raster::PixelTransfer& transfer, const Ray& ray, const std::vector<glm::dvec2>& chords, int n)
{
    glm::dvec3 color(0.0);
    double transmittance = 1.0;
    for (const glm::dvec2& chord : chords) {
        const double h = (chord.y - chord.x) / n;
        for (int i = 0; i < n; ++i) {
            const glm::dvec3 x = ray.origin + (chord.x + (i + 0.5) * h) * ray.direction;
            const glm::dvec4 c = tf(sphericalSample(volume, domain, transfer, x));
            const double alpha = 1.0 - std::exp(-c.w * h);
            color += transmittance * alpha * glm::dvec3(c);
            transmittance *= 1.0 - alpha;
        }
    }
    return {color, 1.0 - transmittance};
}

}  // namespace

Image4d sphericalReferenceIntegral(const Volume& volume, const TransferFunction& tf, const Camera& camera,
                                   const ImageSpec& image, const SphericalDomain& domain,
                                   const raster::PixelTransfer& transfer, const SphericalReferenceOptions& options)
{
    Image4d out(image.width, image.height);
    const PixelRays rays(camera, image.width, image.height);
    std::atomic<int> nextRow{0};
    std::vector<double> residuals(static_cast<std::size_t>(image.height), 0.0);
    runOnThreads(options.threads, image.height, [&] {
        for (int y = nextRow++; y < image.height; y = nextRow++)
            for (int x = 0; x < image.width; ++x) {
                const Ray ray = rays.at(x, y);
                // Chords: the outer ball minus the inner one, t >= 0.
                const glm::dvec3 oc = domain.center - ray.origin;
                const double tc = glm::dot(oc, ray.direction);
                const glm::dvec3 off = oc - tc * ray.direction;
                const double p2 = glm::dot(off, off);
                std::vector<glm::dvec2> chords;
                if (p2 < domain.rMax * domain.rMax) {
                    const double h1 = std::sqrt(domain.rMax * domain.rMax - p2);
                    if (p2 < domain.rMin * domain.rMin) {
                        const double h0 = std::sqrt(domain.rMin * domain.rMin - p2);
                        chords = {{tc - h1, tc - h0}, {tc + h0, tc + h1}};
                    } else {
                        chords = {{tc - h1, tc + h1}};
                    }
                }
                std::vector<glm::dvec2> kept;
                for (glm::dvec2 c : chords) {
                    c.x = std::max(c.x, 0.0);
                    if (c.y > c.x)
                        kept.push_back(c);
                }
                glm::dvec4 result(0.0);
                if (!kept.empty()) {
                    int n = options.initialSegments;
                    glm::dvec4 previous = integrate(volume, tf, domain, transfer, ray, kept, n);
                    double change = 0.0;
                    do {
                        n *= 2;
                        result = integrate(volume, tf, domain, transfer, ray, kept, n);
                        change = glm::length(result - previous) > 0.0
                                     ? std::max({std::abs(result.x - previous.x), std::abs(result.y - previous.y),
                                                 std::abs(result.z - previous.z), std::abs(result.w - previous.w)})
                                     : 0.0;
                        previous = result;
                    } while (change > options.tolerance && n < options.maxSegments);
                    residuals[static_cast<std::size_t>(y)] = std::max(residuals[static_cast<std::size_t>(y)], change);
                }
                out.at(x, y) = glm::dvec4(glm::dvec3(result) + (1.0 - result.w) * image.background, result.w);
            }
    });
    if (options.maxResidual)
        *options.maxResidual = *std::max_element(residuals.begin(), residuals.end());
    return out;
}

}  // namespace clvr
