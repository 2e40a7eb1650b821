// host/reference/iso_reference.cpp — exact first ray/iso-surface hits in the trilinear field, and their shade
// (host/reference/iso_reference.h). Rows are spread over host threads.
#include "host/reference/iso_reference.h"

#include "host/optics/gradient_volume.h"
#include "host/runtime/parallel.h"

#include <algorithm>
#include <array>
#include <atomic>
#include <cmath>
#include <limits>

namespace clvr {
namespace {

// A cubic c[0] + c[1] s + c[2] s^2 + c[3] s^3.
using Cubic = std::array<double, 4>;

double evalCubic(const Cubic& c, double s) { return ((c[3] * s + c[2]) * s + c[1]) * s + c[0]; }

// Roots of c[1] + 2 c[2] s + 3 c[3] s^2 (the turning points) strictly inside (0, len), sorted.
std::vector<double> turningPoints(const Cubic& c, double len)
{
    const double a = 3.0 * c[3], b = 2.0 * c[2], k = c[1];
    std::vector<double> r;
    const double scale = std::abs(a) * len * len + std::abs(b) * len + std::abs(k);
    if (std::abs(a) * len * len <= 1e-14 * scale) {  // (nearly) a quadratic: one turning point at most
        if (b != 0.0)
            r.push_back(-k / b);
    } else {
        const double disc = b * b - 4.0 * a * k;
        if (disc >= 0.0) {
            // The numerically stable pair: q = -(b + sign(b) sqrt(disc)) / 2, roots q / a and k / q.
            const double q = -0.5 * (b + std::copysign(std::sqrt(disc), b));
            r.push_back(q / a);
            if (q != 0.0)
                r.push_back(k / q);
        }
    }
    std::vector<double> inside;
    for (double s : r)
        if (s > 0.0 && s < len)
            inside.push_back(s);
    std::sort(inside.begin(), inside.end());
    return inside;
}

// The trilinear function of cell (i, j, k) along g(s) = g0 + s gd, multiplied out: each corner's weight is
// a product of three linear factors (1 - f or f per axis, f = g - cell corner).
Cubic cellCubic(const Volume& v, const glm::ivec3& cell, const glm::dvec3& g0, const glm::dvec3& gd)
{
    Cubic c{0.0, 0.0, 0.0, 0.0};
    for (int corner = 0; corner < 8; ++corner) {
        const glm::ivec3 o((corner & 1) ? 1 : 0, (corner & 2) ? 1 : 0, (corner & 4) ? 1 : 0);
        // Polynomial of the weight, built one axis at a time.
        Cubic w{1.0, 0.0, 0.0, 0.0};
        for (int a = 0; a < 3; ++a) {
            const double f0 = g0[a] - cell[a], f1 = gd[a];
            const double p0 = o[a] ? f0 : 1.0 - f0, p1 = o[a] ? f1 : -f1;  // factor p0 + p1 s
            Cubic next{0.0, 0.0, 0.0, 0.0};
            for (int d = 0; d < 3; ++d) {
                next[d] += w[d] * p0;
                next[d + 1] += w[d] * p1;
            }
            w = next;
        }
        const double value = v.at(cell.x + o.x, cell.y + o.y, cell.z + o.z);
        for (int d = 0; d < 4; ++d)
            c[d] += value * w[d];
    }
    return c;
}

// Trilinear RGBA at grid coordinates g (inside the bounds), lower corner clamped to n - 2 as Volume::sample.
glm::dvec4 trilinear4(const std::vector<glm::vec4>& rgba, const glm::ivec3& n, const glm::dvec3& g)
{
    const glm::ivec3 c = glm::min(glm::ivec3(glm::floor(g)), n - 2);
    const glm::dvec3 f = g - glm::dvec3(c);
    glm::dvec4 sum(0.0);
    for (int corner = 0; corner < 8; ++corner) {
        const glm::ivec3 o((corner & 1) ? 1 : 0, (corner & 2) ? 1 : 0, (corner & 4) ? 1 : 0);
        const glm::ivec3 p = c + o;
        const double w = (o.x ? f.x : 1.0 - f.x) * (o.y ? f.y : 1.0 - f.y) * (o.z ? f.z : 1.0 - f.z);
        sum += w * glm::dvec4(rgba[(static_cast<std::size_t>(p.z) * n.y + p.y) * n.x + p.x]);
    }
    return sum;
}

}  // namespace

std::optional<double> firstIsoHit(const Volume& v, const Ray& ray, double iso)
{
    const glm::ivec3 n = v.dims;
    const glm::dvec3 go = (ray.origin - v.origin) / v.spacing, gd = ray.direction / v.spacing;
    const glm::dvec3 last(n - 1);
    // The chord inside the bounds [0, n - 1] (slab test), from t = 0 on.
    double tin = 0.0, tout = std::numeric_limits<double>::infinity();
    for (int a = 0; a < 3; ++a) {
        if (gd[a] == 0.0) {
            if (go[a] < 0.0 || go[a] > last[a])
                return std::nullopt;
            continue;
        }
        const double t0 = (0.0 - go[a]) / gd[a], t1 = (last[a] - go[a]) / gd[a];
        tin = std::max(tin, std::min(t0, t1));
        tout = std::min(tout, std::max(t0, t1));
    }
    if (!(tin <= tout))
        return std::nullopt;
    // Every grid-plane crossing on the chord: between two of them the ray stays in one cell.
    std::vector<double> cuts{tin, tout};
    for (int a = 0; a < 3; ++a) {
        if (gd[a] == 0.0)
            continue;
        const double ga = go[a] + tin * gd[a], gb = go[a] + tout * gd[a];
        for (int k = static_cast<int>(std::ceil(std::min(ga, gb))); k <= static_cast<int>(std::floor(std::max(ga, gb))); ++k)
            cuts.push_back((k - go[a]) / gd[a]);
    }
    std::sort(cuts.begin(), cuts.end());
    for (std::size_t i = 0; i + 1 < cuts.size(); ++i) {
        const double ta = std::clamp(cuts[i], tin, tout), tb = std::clamp(cuts[i + 1], tin, tout);
        if (i > 0 && !(tb > ta))
            continue;
        const glm::dvec3 mid = go + 0.5 * (ta + tb) * gd;
        const glm::ivec3 cell = glm::clamp(glm::ivec3(glm::floor(mid)), glm::ivec3(0), n - 2);
        const double len = tb - ta;
        const Cubic c = cellCubic(v, cell, go + ta * gd, gd);
        if (evalCubic(c, 0.0) >= iso)
            return ta;
        // Monotone pieces in order; the first whose end reaches iso holds the crossing (its start is below).
        std::vector<double> ends = turningPoints(c, len);
        ends.push_back(len);
        double s0 = 0.0;
        for (double s1 : ends) {
            if (evalCubic(c, s1) >= iso) {
                double lo = s0, hi = s1;  // f(lo) < iso <= f(hi)
                for (int it = 0; it < 200 && hi - lo > 1e-15 * (1.0 + std::abs(ta)); ++it) {
                    const double m = 0.5 * (lo + hi);
                    (evalCubic(c, m) >= iso ? hi : lo) = m;
                }
                return ta + hi;
            }
            s0 = s1;
        }
    }
    return std::nullopt;
}

IsoReference isoReference(const Volume& volume, const Camera& camera, const ImageSpec& spec, const IsoSurface& iso)
{
    IsoReference out;
    const std::size_t pixels = static_cast<std::size_t>(spec.width) * spec.height;
    out.eyeDepth.assign(pixels, std::numeric_limits<double>::infinity());
    out.image = Image4d(spec.width, spec.height);
    const std::vector<glm::vec4> gradients = sobelGradientVolume(volume);
    const PixelRays rays(camera, spec.width, spec.height);
    const glm::dvec3 forward = camera.forward();
    std::atomic<int> nextRow{0};
    auto worker = [&] {
        for (int y; (y = nextRow.fetch_add(1)) < spec.height;) {
            for (int x = 0; x < spec.width; ++x) {
                const Ray ray = rays.at(x, y);  // the center of pixel (x, y)
                const std::optional<double> t = firstIsoHit(volume, ray, iso.value);
                glm::dvec4& pixel = out.image.at(x, y);
                if (!t) {
                    pixel = glm::dvec4(spec.background, 0.0);
                    continue;
                }
                out.eyeDepth[static_cast<std::size_t>(y) * spec.width + x] = *t * glm::dot(ray.direction, forward);
                glm::dvec3 color = iso.color;
                if (iso.shading == IsoSurface::Shading::Gradient) {
                    const glm::dvec3 g = (ray.origin + *t * ray.direction - volume.origin) / volume.spacing;
                    const glm::dvec3 grad(trilinear4(gradients, volume.dims, glm::clamp(g, glm::dvec3(0.0), glm::dvec3(volume.dims - 1))));
                    const double length = glm::length(grad);
                    const glm::dvec3 normal = length > 0.0 ? -grad / length : glm::dvec3(0.0);
                    color = glm::clamp(iso.color * (iso.ambient + iso.diffuse * glm::dot(iso.light, normal)), 0.0, 1.0);
                }
                pixel = glm::dvec4(color, 1.0);
            }
        }
    };
    runOnThreads(2, spec.height, worker);
    return out;
}

}  // namespace clvr
