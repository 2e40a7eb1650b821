// host/reference/spherical_reference.h — the CPU reference of the spherical technique (host/render/grid/spherical.h):
// per pixel, the emission-absorption integral of DESIGN.md's optical model along the camera ray
// through the spherical domain r_min <= |x - center| <= r_max, in double, with each sample's exact
// normalized spherical coordinates (u, v, w), the same pixel transfer q = b + s·CM·(u, v, w, 1) (q.x
// wrapped to [0, 1), q.y and q.z clamped to [0, 1]), trilinear reconstruction in the (φ, θ, r) grid
// (grid point (i, j, k) at (q.x, q.y, q.z) = (i / (nx-1), j / (ny-1), k / (nz-1))) and classification
// after interpolation. Used by tests; not a renderer.
#pragma once

#include "host/model/camera.h"
#include "host/model/image.h"
#include "host/render/grid/spherical.h"
#include "host/model/scene.h"
#include "host/model/transfer_function.h"
#include "host/model/volume.h"
#include "raster/pixel_transfer.h"

namespace clvr {

struct SphericalReferenceOptions {
    // Each of a ray's (at most two) chords through the domain is cut into n equal segments
    // (midpoint rule, alpha = 1 - exp(-tau h) per segment, composited front to back); n starts at
    // initialSegments and doubles until no channel of (I, A) changes by more than `tolerance`.
    double tolerance = 1e-6;
    int initialSegments = 64;
    int maxSegments = 1 << 16;
    int threads = 2;
    double* maxResidual = nullptr;  // when set: the largest last change over all rays
};

// The value the spherical technique reconstructs at world point x (0 outside the domain is not
// special-cased: callers only sample inside).
double sphericalSample(const Volume& volume, const SphericalDomain& domain, const raster::PixelTransfer& transfer,
                       const glm::dvec3& x);

// rgb = I + (1 - A) background, a = A, per pixel; only t >= 0 counts (as referenceIntegral).
Image4d sphericalReferenceIntegral(const Volume& volume, const TransferFunction& tf, const Camera& camera,
                                   const ImageSpec& image, const SphericalDomain& domain,
                                   const raster::PixelTransfer& transfer, const SphericalReferenceOptions& options = {});

}  // namespace clvr
