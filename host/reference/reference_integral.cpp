// host/reference/reference_integral.cpp — converged midpoint quadrature of the emission-absorption integral
// (Eq. 1 of seeds/001_cd12fd6b76f9cf96.txt) in double, per pixel, rows spread over host threads.
#include "host/reference/reference_integral.h"

#include "host/runtime/parallel.h"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <limits>
#include <mutex>
#include <vector>

namespace clvr {
namespace {

// Trilinear reconstruction at grid coordinates g of per-point data p (T = float or glm::vec4), clamped
// into the grid (the caller only asks for points inside the box; the clamp absorbs rounding at its
// faces). Same formula as Volume::sample.
template <typename T, typename R>
R trilinearOf(const T* data, const glm::ivec3& dims, glm::dvec3 g)
{
    const glm::dvec3 last(dims - 1);
    g = glm::clamp(g, glm::dvec3(0.0), last);
    glm::ivec3 i0 = glm::clamp(glm::ivec3(glm::floor(g)), glm::ivec3(0), dims - 2);
    const glm::dvec3 f = g - glm::dvec3(i0);
    const std::size_t nx = static_cast<std::size_t>(dims.x);
    const std::size_t nxy = nx * static_cast<std::size_t>(dims.y);
    const T* p = data + static_cast<std::size_t>(i0.z) * nxy + static_cast<std::size_t>(i0.y) * nx + i0.x;
    auto at = [p](std::size_t k) { return R(p[k]); };
    const R c00 = at(0) * (1 - f.x) + at(1) * f.x;
    const R c10 = at(nx) * (1 - f.x) + at(nx + 1) * f.x;
    const R c01 = at(nxy) * (1 - f.x) + at(nxy + 1) * f.x;
    const R c11 = at(nxy + nx) * (1 - f.x) + at(nxy + nx + 1) * f.x;
    const R c0 = c00 * (1 - f.y) + c10 * f.y;
    const R c1 = c01 * (1 - f.y) + c11 * f.y;
    return c0 * (1 - f.z) + c1 * f.z;
}

double trilinear(const Volume& v, const glm::dvec3& g)
{
    if (!v.native())
        return trilinearOf<float, double>(v.values.data(), v.dims, g);
    // Native integer voxels: the same arithmetic on the same values (integers convert exactly).
    return withVoxels(v, [&](const auto* data, std::size_t) {
        using T = std::remove_cv_t<std::remove_pointer_t<decltype(data)>>;
        return trilinearOf<T, double>(data, v.dims, g);
    });
}

// (r, g, b, tau) of the sample at grid coordinates g: classification after interpolation, and with
// shading the color times the shade of the interpolated gradient.
glm::dvec4 classify(const Volume& v, const TransferFunction& tf, const ReferenceShading* shading, const glm::dvec3& g)
{
    if (!shading)
        return tf(trilinear(v, g));
    const glm::dvec4 s = trilinearOf<glm::vec4, glm::dvec4>(shading->gradients->data(), v.dims, g);
    const glm::dvec4 c = tf(s.w);
    return glm::dvec4(glm::dvec3(c) * phongShade(shading->lighting, glm::dvec3(s), shading->toEye), c.a);
}

struct RayResult {
    glm::dvec4 value{0.0};  // (I.r, I.g, I.b, A)
    std::uint64_t samples = 0;
    int segments = 0;
    double residual = 0.0;
    bool converged = true;
};

// Midpoint composite with n segments over [t0, t1]. Stops once the transmittance is so small that
// the rest cannot change the result by more than `negligible`.
glm::dvec4 composite(const Volume& v, const TransferFunction& tf, const ReferenceShading* shading, const Ray& ray,
                     double t0, double t1, int n, double negligible, std::uint64_t& samples)
{
    const double h = (t1 - t0) / n;
    glm::dvec3 intensity(0.0);
    double transmittance = 1.0;
    const glm::dvec3 g0 = (ray.origin + t0 * ray.direction - v.origin) / v.spacing;
    const glm::dvec3 dg = ray.direction * h / v.spacing;
    for (int i = 0; i < n; ++i) {
        const glm::dvec3 g = g0 + (i + 0.5) * dg;
        const glm::dvec4 c = classify(v, tf, shading, g);
        ++samples;
        const double alpha = 1.0 - std::exp(-c.a * h);
        intensity += transmittance * alpha * glm::dvec3(c);
        transmittance *= 1.0 - alpha;
        if (transmittance < negligible)
            break;
    }
    return glm::dvec4(intensity, 1.0 - transmittance);
}

RayResult integrateRay(const Volume& v, const TransferFunction& tf, const Ray& ray, double t0, double t1,
                       const ReferenceOptions& o)
{
    RayResult r;
    const double minSpacing = std::min({v.spacing.x, v.spacing.y, v.spacing.z});
    const double h0 = minSpacing / std::max(1, o.initialStepsPerVoxel);
    int n = static_cast<int>(std::min<double>(std::ceil((t1 - t0) / h0), o.maxSegmentsPerRay));
    n = std::max(n, 1);
    const double negligible = o.tolerance * 1e-3;
    glm::dvec4 coarse = composite(v, tf, o.shading, ray, t0, t1, n, negligible, r.samples);
    for (;;) {
        if (2 * static_cast<long long>(n) > o.maxSegmentsPerRay) {
            r.converged = false;
            break;
        }
        n *= 2;
        const glm::dvec4 fine = composite(v, tf, o.shading, ray, t0, t1, n, negligible, r.samples);
        const glm::dvec4 d = glm::abs(fine - coarse);
        r.residual = std::max({d.r, d.g, d.b, d.a});
        coarse = fine;
        if (r.residual < o.tolerance)
            break;
    }
    r.value = coarse;
    r.segments = n;
    return r;
}

}  // namespace

bool clipRayToBox(const Ray& ray, const glm::dvec3& lo, const glm::dvec3& hi, double tMin, double& t0, double& t1)
{
    t0 = tMin;
    t1 = std::numeric_limits<double>::infinity();
    for (int a = 0; a < 3; ++a) {
        if (ray.direction[a] == 0.0) {
            if (ray.origin[a] < lo[a] || ray.origin[a] > hi[a])
                return false;
            continue;
        }
        const double inv = 1.0 / ray.direction[a];
        double ta = (lo[a] - ray.origin[a]) * inv, tb = (hi[a] - ray.origin[a]) * inv;
        if (ta > tb)
            std::swap(ta, tb);
        t0 = std::max(t0, ta);
        t1 = std::min(t1, tb);
    }
    return t1 > t0;
}

Image4d referenceIntegral(const Volume& volume, const TransferFunction& tf, const Camera& camera,
                          const ImageSpec& image, const ReferenceOptions& options)
{
    Image4d out(image.width, image.height);
    const glm::dvec3 lo = volume.boundsMin(), hi = volume.boundsMax();
    std::atomic<int> nextRow{0};
    std::mutex statsMutex;
    ReferenceStats total;

    auto worker = [&] {
        ReferenceStats local;
        for (int y; (y = nextRow.fetch_add(1)) < image.height;) {
            for (int x = 0; x < image.width; ++x) {
                const Ray ray = camera.ray(x, y, image.width, image.height);
                glm::dvec4 v(0.0);
                double t0, t1;
                if (clipRayToBox(ray, lo, hi, 0.0, t0, t1)) {
                    const std::vector<glm::dvec2> pieces =
                        options.intervals ? options.intervals(ray, t0, t1) : std::vector<glm::dvec2>{{t0, t1}};
                    bool converged = true;
                    for (const glm::dvec2& piece : pieces) {
                        const RayResult r = integrateRay(volume, tf, ray, piece.x, piece.y, options);
                        // Front to back: the piece is seen through the transmittance 1 - A of those before it.
                        v = glm::dvec4(glm::dvec3(v) + (1.0 - v.a) * glm::dvec3(r.value), v.a + (1.0 - v.a) * r.value.a);
                        local.samples += r.samples;
                        local.maxSegments = std::max(local.maxSegments, r.segments);
                        converged = converged && r.converged;
                        local.maxResidual = std::max(local.maxResidual, r.residual);
                    }
                    ++local.rays;
                    local.raysNotConverged += converged ? 0 : 1;
                }
                // Final pixel of DESIGN.md: I + (1 - A) * background, alpha = A.
                out.at(x, y) = glm::dvec4(glm::dvec3(v) + (1.0 - v.a) * image.background, v.a);
            }
        }
        std::lock_guard lock(statsMutex);
        total.rays += local.rays;
        total.samples += local.samples;
        total.maxSegments = std::max(total.maxSegments, local.maxSegments);
        total.raysNotConverged += local.raysNotConverged;
        total.maxResidual = std::max(total.maxResidual, local.maxResidual);
    };

    runOnThreads(options.threads, image.height, worker);
    if (options.stats)
        *options.stats = total;
    return out;
}

}  // namespace clvr
