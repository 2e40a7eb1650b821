// host/cluster/balance.cpp — the work a view asks of a region, and sort-last cuts by it
// (host/cluster/balance.h).
#include "host/cluster/balance.h"

#include "host/runtime/errors.h"

#include <algorithm>
#include <cmath>

namespace clvr {
namespace {

constexpr double kOutsideShare = 1e-3;  // density out of view, relative to the focal plane's
constexpr double kTetFloor = 1e-3;      // pixels: a tetrahedron no ray crosses still costs a little

// The area of the triangle (a, b, c) of 2D points (x, y of each).
double triangleArea(const glm::dvec3& a, const glm::dvec3& b, const glm::dvec3& c)
{
    return 0.5 * std::abs((b.x - a.x) * (c.y - a.y) - (b.y - a.y) * (c.x - a.x));
}

}  // namespace

ViewCost::ViewCost(const Camera& camera, int width, int height)
    : position_(camera.position), forward_(camera.forward()), right_(camera.right()), up_(camera.up()),
      width_(width), height_(height), parallel_(camera.parallel)
{
    if (width < 1 || height < 1)
        throw InternalError("ViewCost: an image of at least one pixel");
    // Half the view's height is tan(angle / 2) at depth 1 (perspective) or the parallel scale.
    const double halfHeight = parallel_ ? camera.parallelScale : std::tan(glm::radians(camera.viewAngle) * 0.5);
    pixelsPerUnit_ = 0.5 * height_ / halfHeight;
    const double focalDistance = glm::length(camera.focalPoint - camera.position);
    minDepth_ = 0.05 * focalDistance;
    const double focalPerUnit = parallel_ ? pixelsPerUnit_ : pixelsPerUnit_ / focalDistance;
    outsideDensity_ = kOutsideShare * focalPerUnit * focalPerUnit;
}

glm::dvec3 ViewCost::project(const glm::dvec3& p) const
{
    const glm::dvec3 d = p - position_;
    const double depth = glm::dot(d, forward_);
    const double scale = parallel_ ? pixelsPerUnit_ : pixelsPerUnit_ / std::max(depth, minDepth_);
    return {0.5 * width_ + glm::dot(d, right_) * scale, 0.5 * height_ - glm::dot(d, up_) * scale, depth};
}

double ViewCost::density(const glm::dvec3& p) const
{
    const glm::dvec3 s = project(p);
    if (!parallel_ && s.z <= 0.0)
        return outsideDensity_;  // behind the eye
    if (s.x < 0.0 || s.x > width_ || s.y < 0.0 || s.y > height_)
        return outsideDensity_;
    const double perUnit = parallel_ ? pixelsPerUnit_ : pixelsPerUnit_ / std::max(s.z, minDepth_);
    return perUnit * perUnit;
}

double ViewCost::tetWork(const glm::dvec3& a, const glm::dvec3& b, const glm::dvec3& c, const glm::dvec3& d) const
{
    const glm::dvec3 p[4] = {project(a), project(b), project(c), project(d)};
    if (!parallel_ && p[0].z <= 0.0 && p[1].z <= 0.0 && p[2].z <= 0.0 && p[3].z <= 0.0)
        return kTetFloor;  // wholly behind the eye
    const double area =
        0.5 * (triangleArea(p[0], p[1], p[2]) + triangleArea(p[0], p[1], p[3]) + triangleArea(p[0], p[2], p[3]) +
               triangleArea(p[1], p[2], p[3]));
    glm::dvec2 lo(p[0]), hi(p[0]);
    for (const glm::dvec3& q : p) {
        lo = glm::min(lo, glm::dvec2(q));
        hi = glm::max(hi, glm::dvec2(q));
    }
    const glm::dvec2 inLo = glm::max(lo, glm::dvec2(0.0)), inHi = glm::min(hi, glm::dvec2(width_, height_));
    if (inHi.x <= inLo.x || inHi.y <= inLo.y)
        return kTetFloor;  // out of the image
    const double box = (hi.x - lo.x) * (hi.y - lo.y);
    const double share = box > 0.0 ? (inHi.x - inLo.x) * (inHi.y - inLo.y) / box : 1.0;
    return area * share + kTetFloor;
}

std::vector<double> ViewCost::tetWork(const TetMesh& mesh) const
{
    std::vector<double> out;
    out.reserve(mesh.tets.size());
    for (const glm::uvec4& t : mesh.tets)
        out.push_back(tetWork(mesh.points[t.x], mesh.points[t.y], mesh.points[t.z], mesh.points[t.w]));
    return out;
}

double imbalance(const std::vector<double>& ms)
{
    if (ms.empty())
        return 1.0;
    double sum = 0.0;
    for (double t : ms)
        sum += t;
    return sum > 0.0 ? *std::max_element(ms.begin(), ms.end()) * static_cast<double>(ms.size()) / sum : 1.0;
}

std::vector<double> partRates(const std::vector<double>& estimate, const std::vector<double>& ms)
{
    if (estimate.size() != ms.size())
        throw InternalError("partRates: one estimate and one time per part");
    double work = 0.0, time = 0.0;
    for (std::size_t p = 0; p < ms.size(); ++p) {
        work += estimate[p];
        time += ms[p];
    }
    if (!(work > 0.0) || !(time > 0.0))
        return std::vector<double>(ms.size(), 1.0);  // nothing measured: the estimate alone
    const double whole = time / work;
    std::vector<double> out;
    for (std::size_t p = 0; p < ms.size(); ++p) {
        const double rate = estimate[p] > 0.0 ? ms[p] / estimate[p] : 8.0 * whole;
        out.push_back(std::clamp(rate, whole / 8.0, 8.0 * whole));
    }
    return out;
}

double predictedImbalance(const std::vector<double>& estimateBefore, const std::vector<double>& estimateNext,
                          const std::vector<double>& ms)
{
    const std::vector<double> rates = partRates(estimateBefore, ms);
    if (estimateNext.size() != rates.size())
        throw InternalError("predictedImbalance: one estimate per part");
    std::vector<double> predicted;
    for (std::size_t p = 0; p < rates.size(); ++p)
        predicted.push_back(rates[p] * estimateNext[p]);
    return imbalance(predicted);
}

double meshPartWork(const TetMesh& part, const KdTree& tree, int p, const ViewCost& view)
{
    double sum = 0.0;
    for (const glm::uvec4& t : part.tets) {
        const glm::dvec3 a = part.points[t.x], b = part.points[t.y], c = part.points[t.z], d = part.points[t.w];
        if (tree.partAt(0.25 * (a + b + c + d)) == p)
            sum += view.tetWork(a, b, c, d);
    }
    return sum;
}

GridPartition balanceGrid(const glm::ivec3& dims, const glm::dvec3& origin, const glm::dvec3& spacing, int n,
                          const ViewCost& next, const GridPartition* previous, const MeasuredFrame* measured)
{
    const CostDensity estimate = [&](const glm::dvec3& p) { return next.density(p); };
    if (!previous || !measured)
        return partitionGrid(dims, origin, spacing, n, estimate);
    const CostDensity before = [&](const glm::dvec3& p) { return measured->view.density(p); };
    const std::vector<double> rates = partRates(gridPartCosts(*previous, origin, spacing, before), measured->ms);
    return partitionGrid(dims, origin, spacing, n, [&](const glm::dvec3& p) {
        return next.density(p) * rates[static_cast<std::size_t>(previous->tree.partAt(p))];
    });
}

MeshPartition balanceMesh(const TetMesh& mesh, int n, const ViewCost& next, const MeshPartition* previous,
                          const MeasuredFrame* measured)
{
    std::vector<double> work = next.tetWork(mesh);
    if (previous && measured) {
        const std::vector<glm::dvec3> centroids = tetCentroids(mesh);
        std::vector<int> part(centroids.size());
        for (std::size_t t = 0; t < centroids.size(); ++t)
            part[t] = previous->tree.partAt(centroids[t]);
        const std::vector<double> before = measured->view.tetWork(mesh);
        std::vector<double> estimate(measured->ms.size(), 0.0);
        for (std::size_t t = 0; t < before.size(); ++t)
            estimate.at(static_cast<std::size_t>(part[t])) += before[t];
        const std::vector<double> rates = partRates(estimate, measured->ms);
        for (std::size_t t = 0; t < work.size(); ++t)
            work[t] *= rates[static_cast<std::size_t>(part[t])];
    }
    return partitionMesh(mesh, n, work);
}

}  // namespace clvr
