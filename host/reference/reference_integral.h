// host/reference/reference_integral.h — the CPU reference of DESIGN.md's optical model: per pixel, the
// emission-absorption integral I = ∫ C(s) τ(s) exp(-∫τ) dλ (Eq. 1 of seeds/001_cd12fd6b76f9cf96.txt)
// along the camera ray through the pixel center, in double, with trilinear reconstruction and
// classification after interpolation (the transfer function of the interpolated value); optionally
// shaded (ReferenceShading: the color times the Phong shade of the interpolated gradient, seeds/004).
// Used by tests to judge every regular-grid technique; not a renderer.
#pragma once

#include "host/model/camera.h"
#include "host/model/image.h"
#include "host/optics/reflectance_map.h"
#include "host/model/scene.h"
#include "host/model/transfer_function.h"
#include "host/model/volume.h"

#include <cstdint>
#include <functional>
#include <vector>

namespace clvr {

// What the integration did, for tests and docs.
struct ReferenceStats {
    std::uint64_t rays = 0;             // rays that cross the volume box
    std::uint64_t samples = 0;          // trilinear samples taken, all refinement levels
    int maxSegments = 0;                // most segments any ray needed
    std::uint64_t raysNotConverged = 0;  // rays that hit maxSegmentsPerRay before meeting tolerance
    double maxResidual = 0.0;           // largest last |I_h - I_2h| (per channel, rgb and A) over rays
};

// Shaded emission (seeds/004 §2, the model of host/optics/reflectance_map.h's phongShade): a sample's color is
// the transfer function's color times phongShade of the gradient interpolated trilinearly (in double)
// from `gradients` (host/optics/gradient_volume.h's RGBA volume of the same grid); tau is not shaded.
struct ReferenceShading {
    const std::vector<glm::vec4>* gradients = nullptr;  // sobelGradientVolume(volume), not owned
    Lighting lighting;
    glm::dvec3 toEye{0.0, 0.0, 1.0};  // unit, towards the viewer: the camera's -forward
};

struct ReferenceOptions {
    // A ray's integral is refined (segment count doubled) until the change of every channel of
    // (I, A) is below this. The midpoint rule used is second order, so the remaining error is
    // about a third of the last change.
    double tolerance = 1e-6;
    // First level: segments of at most min(spacing) / initialStepsPerVoxel along the chord.
    int initialStepsPerVoxel = 2;
    int maxSegmentsPerRay = 1 << 20;
    int threads = 2;                     // std::thread workers over rows (<= 0: hardware_concurrency)
    ReferenceStats* stats = nullptr;     // filled when not null
    // When set, only these sub-intervals of a ray's chord [t0, t1] count (in increasing order, within
    // [t0, t1]): each is integrated (and converged) on its own and the pieces are composited front to
    // back; the medium elsewhere is taken as empty. Clipping uses it (host/optics/clip_mesh.h: clipIntervals).
    std::function<std::vector<glm::dvec2>(const Ray& ray, double t0, double t1)> intervals;
    const ReferenceShading* shading = nullptr;  // null: unshaded (the color is the transfer function's)
};

// Integrates every pixel of an image.width x image.height image; the result pixel is
// rgb = I + (1 - A) * background, a = A. Only the ray part in front of the camera (t >= 0, from
// the camera position, or for a parallel camera from its image plane through the position) counts.
// Quadrature: the chord through the volume box [boundsMin, boundsMax] is cut into n equal
// segments; segment i gets the transfer function (rgb_i, tau_i) at its midpoint, opacity
// alpha_i = 1 - exp(-tau_i h) and color rgb_i alpha_i, composited front to back (exact for
// piecewise-constant data, second order otherwise); n doubles until the ray meets the tolerance.
Image4d referenceIntegral(const Volume& volume, const TransferFunction& tf, const Camera& camera,
                          const ImageSpec& image, const ReferenceOptions& options = {});

// The parameter interval [t0, t1] (t0 >= tMin) of `ray` inside the box [lo, hi]; false if it misses.
bool clipRayToBox(const Ray& ray, const glm::dvec3& lo, const glm::dvec3& hi, double tMin, double& t0, double& t1);

}  // namespace clvr
