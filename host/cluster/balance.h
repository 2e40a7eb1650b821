// host/cluster/balance.h — sort-last parts cut by the work a view asks of them, not by data size
// (docs/cluster.md "Balance"). A ray caster's or slicer's work in a region is the number of samples it
// takes there: the pixels the region covers times its depth. ViewCost estimates that for one view; the
// first frame's parts are cut by it. After a frame, each part's measured time over its estimate is a rate
// (ms per unit of work: empty space skipped, early termination, the transfer function's cost), and the
// next frame's parts are cut by the next view's estimate times the rate measured where each point was —
// the previous frame's cost, as sort-first rebalances its rows (balanceRows).
#pragma once

#include "host/cluster/partition.h"
#include "host/model/camera.h"
#include "host/model/mesh.h"

#include <vector>

namespace clvr {

// The work of one view, estimated from geometry alone.
class ViewCost {
public:
    ViewCost(const Camera& camera, int width, int height);

    // Samples per unit volume near p, up to a constant: the pixels per unit area of the image plane at p's
    // depth (perspective: falls as 1/depth², the depth no less than 5% of the focal distance; parallel:
    // constant) inside the view; outside it, and behind the eye, 1/1000 of the focal plane's (a part out
    // of view still clears and composites its image).
    double density(const glm::dvec3& p) const;

    // The rays that cross a tetrahedron: the pixels its projection covers (half the summed projected
    // areas of its four faces, each point of the projection lying under two faces), scaled by the share
    // of its projection's bounding box inside the image, plus 1/1000 of a pixel.
    double tetWork(const glm::dvec3& a, const glm::dvec3& b, const glm::dvec3& c, const glm::dvec3& d) const;
    std::vector<double> tetWork(const TetMesh& mesh) const;

private:
    // p on the image: pixel coordinates (x right, y down) and the depth along the view direction.
    glm::dvec3 project(const glm::dvec3& p) const;

    glm::dvec3 position_, forward_, right_, up_;
    double width_, height_;
    double pixelsPerUnit_;  // parallel: pixels per world unit; perspective: the same at depth 1
    double minDepth_;
    double outsideDensity_;  // density() out of view: 1/1000 of the focal plane's
    bool parallel_;
};

// Slowest over mean of per-rank times (1 when balanced, or when every time is 0).
double imbalance(const std::vector<double>& ms);

// Per part: its measured time over its estimated work, each within 1/8..8 of the whole job's rate (a part
// with almost no estimated work would otherwise get an unbounded rate from a fixed per-frame cost).
std::vector<double> partRates(const std::vector<double>& estimate, const std::vector<double>& ms);

// The imbalance the current parts would have under the next view: each part's measured time times its
// estimate for the next view over its estimate for the measured one (rates as partRates). A cut balanced
// for one view can drift out of balance as an orbit turns: this says when to re-cut before it does.
double predictedImbalance(const std::vector<double>& estimateBefore, const std::vector<double>& estimateNext,
                          const std::vector<double>& ms);

// The estimated work of part p's own tetrahedra (those whose centroid `tree` places in part p) for `view`:
// what the rank holding part p adds up, where the whole mesh is not at hand, for predictedImbalance.
double meshPartWork(const TetMesh& part, const KdTree& tree, int p, const ViewCost& view);

// What a frame measured: the view it rendered and each part's render time.
struct MeasuredFrame {
    ViewCost view;
    std::vector<double> ms;
};

// The grid's parts for the view `next`: cut by its estimated work (ViewCost::density), and where
// `previous` and `measured` are given, that estimate times the rate measured for the previous part that
// held each point.
GridPartition balanceGrid(const glm::ivec3& dims, const glm::dvec3& origin, const glm::dvec3& spacing, int n,
                          const ViewCost& next, const GridPartition* previous = nullptr,
                          const MeasuredFrame* measured = nullptr);

// The same for a mesh: each tetrahedron costs its ViewCost::tetWork for `next`, times the rate measured for
// the previous part that held its centroid.
MeshPartition balanceMesh(const TetMesh& mesh, int n, const ViewCost& next, const MeshPartition* previous = nullptr,
                          const MeasuredFrame* measured = nullptr);

}  // namespace clvr
