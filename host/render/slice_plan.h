// host/render/slice_plan.h — slices parallel to the image plane through a box (§2 of
// seeds/000_354856c7f65dc3f9.txt): their eye depths and spacing, and each slice's polygon. Shared by
// the slicing techniques (slice3d, iso3d, blend).
#pragma once

#include "host/model/camera.h"

#include <glm/glm.hpp>

#include <vector>

namespace clvr {

// The most slices a slice_spacing may give (InputError beyond).
constexpr int kMaxPlannedSlices = 65536;

// Slice k (0 = nearest) lies on the plane dot(forward, p - position) = depthMin + (k + 0.5) * deltaS.
struct SlicePlan {
    double depthMin = 0.0;  // eye depth where the slab of slices begins (>= 0: nothing behind the camera)
    double depthMax = 0.0;  // eye depth of the box's farthest corner
    double deltaS = 0.0;    // slice spacing along forward, world units
    int count = 0;          // 0 when the box is entirely behind the camera
    double depth(int k) const { return depthMin + (k + 0.5) * deltaS; }
};

// Slices over the eye-depth range of the box [lo, hi] (its 8 corners, clipped at depth 0): `slices`
// equal slabs, or, when sliceSpacing > 0, slabs of `sliceSpacing` (count = ceil(range / spacing);
// InputError naming options.slice_spacing if > kMaxPlannedSlices).
SlicePlan planSlices(const Camera& camera, const glm::dvec3& lo, const glm::dvec3& hi, int slices, double sliceSpacing);

// The cross-section of the box [lo, hi] with the plane dot(normal, p) = offset (normal unit length):
// the plane cut with the 12 box edges, duplicates (plane through a corner) merged, 3 to 6 vertices
// ordered by angle about their centroid in a plane basis (u, v) with u x v = normal. Empty when the
// plane misses the box or only touches it in fewer than 3 distinct points.
std::vector<glm::dvec3> slicePolygon(const glm::dvec3& lo, const glm::dvec3& hi, const glm::dvec3& normal,
                                     double offset);

}  // namespace clvr
