// host/reference/cube_reference.cpp — the cube field's exact ray integral: a DDA over the cube grid.
#include "host/reference/cube_reference.h"

#include "host/reference/reference_integral.h"  // clipRayToBox
#include "host/render/grid/cube_octree.h"        // cubeFieldBounds: the box the renderer draws
#include "host/runtime/parallel.h"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <limits>

namespace clvr {

namespace {

// Front-to-back composite of the cubes along `ray` between t0 and t1 (inside the field's box).
glm::dvec4 walkCubes(const Volume& v, const TransferFunction& tf, const Ray& ray, double t0, double t1)
{
    glm::dvec3 lo, hi;
    cubefan::cubeFieldBounds(v, lo, hi);
    // The cube holding the ray's point a little past t0 (the entry point can sit on a boundary).
    const glm::dvec3 p = ray.origin + (t0 + 1e-9 * (t1 - t0)) * ray.direction;
    glm::ivec3 cell, step;
    glm::dvec3 tNext, tDelta;
    for (int a = 0; a < 3; ++a) {
        const double x = (p[a] - lo[a]) / v.spacing[a];
        cell[a] = std::clamp(static_cast<int>(std::floor(x)), 0, v.dims[a] - 1);
        const double d = ray.direction[a];
        if (d > 0.0) {
            step[a] = 1;
            tNext[a] = (lo[a] + (cell[a] + 1) * v.spacing[a] - ray.origin[a]) / d;
            tDelta[a] = v.spacing[a] / d;
        } else if (d < 0.0) {
            step[a] = -1;
            tNext[a] = (lo[a] + cell[a] * v.spacing[a] - ray.origin[a]) / d;
            tDelta[a] = -v.spacing[a] / d;
        } else {
            step[a] = 0;
            tNext[a] = std::numeric_limits<double>::infinity();
            tDelta[a] = 0.0;
        }
    }
    glm::dvec3 color(0.0);
    double transmittance = 1.0;
    double t = t0;
    // Each step leaves one cube: a ray crosses at most dims.x + dims.y + dims.z of them.
    const long long maxSteps = static_cast<long long>(v.dims.x) + v.dims.y + v.dims.z + 3;
    for (long long s = 0; s < maxSteps && t < t1; ++s) {
        const int a = tNext.x <= tNext.y ? (tNext.x <= tNext.z ? 0 : 2) : (tNext.y <= tNext.z ? 1 : 2);
        const double tExit = std::min(tNext[a], t1);
        const double l = tExit - t;
        if (l > 0.0) {
            const glm::dvec4 c = tf(v.at(cell.x, cell.y, cell.z));
            const double alpha = -std::expm1(-c.a * l);
            color += transmittance * alpha * glm::dvec3(c);
            transmittance *= 1.0 - alpha;
        }
        t = tExit;
        cell[a] += step[a];
        if (cell[a] < 0 || cell[a] >= v.dims[a])
            break;
        tNext[a] += tDelta[a];
    }
    return glm::dvec4(color, 1.0 - transmittance);
}

}  // namespace

Image4d cubeFieldIntegral(const Volume& volume, const TransferFunction& tf, const Camera& camera,
                          const ImageSpec& image, int threads)
{
    Image4d out(image.width, image.height);
    glm::dvec3 lo, hi;
    cubefan::cubeFieldBounds(volume, lo, hi);
    const PixelRays rays(camera, image.width, image.height);
    std::atomic<int> nextRow{0};
    auto worker = [&] {
        for (int y; (y = nextRow.fetch_add(1)) < image.height;)
            for (int x = 0; x < image.width; ++x) {
                const Ray ray = rays.at(x, y);
                glm::dvec4 v(0.0);
                double t0, t1;
                if (clipRayToBox(ray, lo, hi, 0.0, t0, t1))
                    v = walkCubes(volume, tf, ray, t0, t1);
                out.at(x, y) = glm::dvec4(glm::dvec3(v) + (1.0 - v.a) * image.background, v.a);
            }
    };
    runOnThreads(threads, image.height, worker);
    return out;
}

}  // namespace clvr
