// host/render/slice_plan.cpp — slice planning over a box and slice polygons (host/render/slice_plan.h).
#include "host/render/slice_plan.h"

#include "host/render/options_util.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>

namespace clvr {

SlicePlan planSlices(const Camera& camera, const glm::dvec3& lo, const glm::dvec3& hi, int slices, double sliceSpacing)
{
    const glm::dvec3 forward = camera.forward();
    double dMin = std::numeric_limits<double>::infinity(), dMax = -dMin;
    for (int c = 0; c < 8; ++c) {
        const glm::dvec3 corner((c & 1) ? hi.x : lo.x, (c & 2) ? hi.y : lo.y, (c & 4) ? hi.z : lo.z);
        const double d = glm::dot(forward, corner - camera.position);
        dMin = std::min(dMin, d);
        dMax = std::max(dMax, d);
    }
    SlicePlan plan;
    plan.depthMin = std::max(dMin, 0.0);
    plan.depthMax = dMax;
    const double range = dMax - plan.depthMin;
    if (!(range > 0.0))
        return plan;  // behind the camera: no slices
    if (sliceSpacing > 0.0) {
        const double n = std::ceil(range / sliceSpacing);
        if (n > kMaxPlannedSlices)
            badOption("slice_spacing", std::to_string(sliceSpacing) + " gives " + std::to_string(n) +
                                           " slices for this view, more than " + std::to_string(kMaxPlannedSlices));
        plan.count = std::max(1, static_cast<int>(n));
        plan.deltaS = sliceSpacing;
    } else {
        plan.count = slices;
        plan.deltaS = range / slices;
    }
    return plan;
}

std::vector<glm::dvec3> slicePolygon(const glm::dvec3& lo, const glm::dvec3& hi, const glm::dvec3& normal,
                                     double offset)
{
    std::vector<glm::dvec3> points;
    auto corner = [&](int c) {
        return glm::dvec3((c & 1) ? hi.x : lo.x, (c & 2) ? hi.y : lo.y, (c & 4) ? hi.z : lo.z);
    };
    const double scale = glm::length(hi - lo);
    const double eps = 1e-12 * (scale + std::abs(offset));
    // The 12 edges: corner pairs differing in one bit.
    for (int c = 0; c < 8; ++c)
        for (int bit = 1; bit < 8; bit <<= 1) {
            if (c & bit)
                continue;
            const glm::dvec3 a = corner(c), b = corner(c | bit);
            const double da = glm::dot(normal, a) - offset, db = glm::dot(normal, b) - offset;
            if ((da > eps && db > eps) || (da < -eps && db < -eps))
                continue;
            glm::dvec3 p;
            if (std::abs(da - db) <= eps)  // edge in the plane: both ends
                continue;                  // (its ends are found by the adjacent edges)
            p = a + (b - a) * glm::clamp(da / (da - db), 0.0, 1.0);
            bool duplicate = false;
            for (const glm::dvec3& q : points)
                duplicate = duplicate || glm::length(p - q) <= 1e-9 * scale;
            if (!duplicate)
                points.push_back(p);
        }
    if (points.size() < 3)
        return {};
    glm::dvec3 centroid(0.0);
    for (const glm::dvec3& p : points)
        centroid += p;
    centroid /= static_cast<double>(points.size());
    // Plane basis (u, v) with u x v = normal.
    const glm::dvec3 helper = std::abs(normal.x) < 0.9 ? glm::dvec3(1, 0, 0) : glm::dvec3(0, 1, 0);
    const glm::dvec3 u = glm::normalize(glm::cross(helper, normal));
    const glm::dvec3 v = glm::cross(normal, u);
    std::sort(points.begin(), points.end(), [&](const glm::dvec3& a, const glm::dvec3& b) {
        return std::atan2(glm::dot(a - centroid, v), glm::dot(a - centroid, u)) <
               std::atan2(glm::dot(b - centroid, v), glm::dot(b - centroid, u));
    });
    return points;
}

}  // namespace clvr
