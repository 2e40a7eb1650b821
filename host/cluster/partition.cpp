// host/cluster/partition.cpp — k-d partitions of grids and meshes, their visibility order, and the
// "over" composite of the parts' images (host/cluster/partition.h).
#include "host/cluster/partition.h"

#include "host/runtime/errors.h"

#include <algorithm>
#include <cstring>
#include <cmath>
#include <cstdint>
#include <string>
#include <unordered_map>

namespace clvr {
namespace {

// The axis of the longest extent (the first of equals).
int longestAxis(const glm::dvec3& extent)
{
    int axis = 0;
    for (int a = 1; a < 3; ++a)
        if (extent[a] > extent[axis])
            axis = a;
    return axis;
}

// Up to `most` sample coordinates spread evenly over cells [c0, c1) of one axis (cell units, centers of
// equal stretches).
std::vector<double> spreadSamples(int c0, int c1, int most)
{
    const int n = std::min(c1 - c0, most);
    std::vector<double> out;
    for (int i = 0; i < n; ++i)
        out.push_back(c0 + (i + 0.5) * (c1 - c0) / n);
    return out;
}

// The mean of `cost` over the sample points (cell units, per axis) times the box's world volume.
double boxCost(const std::vector<double> (&samples)[3], const glm::dvec3& origin, const glm::dvec3& spacing,
               double volume, const CostDensity& cost)
{
    double sum = 0.0;
    for (double z : samples[2])
        for (double y : samples[1])
            for (double x : samples[0])
                sum += cost(origin + glm::dvec3(x, y, z) * spacing);
    const double count = static_cast<double>(samples[0].size() * samples[1].size() * samples[2].size());
    return sum / count * volume;
}

// The cell layer on `axis` in (c0, c1) where cells [c0, cut) hold `share` of the cost of cells [c0, c1):
// the layers' costs summed in order, the cut at the layer boundary nearest the target. -1 when the cost
// is not positive (nothing to balance by).
int costCut(const glm::ivec3& c0, const glm::ivec3& c1, int axis, double share, const glm::dvec3& origin,
            const glm::dvec3& spacing, const CostDensity& cost)
{
    std::vector<double> samples[3];
    glm::dvec3 layerSize = glm::dvec3(c1 - c0) * spacing;
    layerSize[axis] = spacing[axis];
    const double layerVolume = layerSize.x * layerSize.y * layerSize.z;
    for (int a = 0; a < 3; ++a)
        samples[a] = spreadSamples(c0[a], c1[a], 16);
    std::vector<double> cumulative{0.0};  // cost of cells [c0, c0 + i) on the axis
    for (int layer = c0[axis]; layer < c1[axis]; ++layer) {
        samples[axis] = {layer + 0.5};
        cumulative.push_back(cumulative.back() + boxCost(samples, origin, spacing, layerVolume, cost));
    }
    const double total = cumulative.back();
    if (!(total > 0.0) || !std::isfinite(total))
        return -1;
    const double target = share * total;
    std::size_t best = 1;
    for (std::size_t i = 1; i + 1 < cumulative.size(); ++i)
        if (std::abs(cumulative[i] - target) < std::abs(cumulative[best] - target))
            best = i;
    return c0[axis] + static_cast<int>(best);
}

// Builds the grid tree over cells [c0, c1) per axis for `ranks` parts numbered from `firstPart`.
int splitGrid(GridPartition& out, const glm::ivec3& c0, const glm::ivec3& c1, const glm::dvec3& origin,
              const glm::dvec3& spacing, const CostDensity& cost, int ranks, int firstPart)
{
    const int node = static_cast<int>(out.tree.nodes.size());
    out.tree.nodes.emplace_back();
    if (ranks == 1) {
        out.tree.nodes[node].part = firstPart;
        out.lo[firstPart] = c0;
        out.hi[firstPart] = c1;  // points [c0, c1]: the cells' upper layer is shared with the neighbour
        return node;
    }
    const glm::ivec3 cells = c1 - c0;
    // The longest axis that still has a cell for each side.
    glm::dvec3 extent = glm::dvec3(cells) * spacing;
    for (int a = 0; a < 3; ++a)
        if (cells[a] < 2)
            extent[a] = -1.0;
    const int axis = longestAxis(extent);
    if (extent[axis] < 0.0)
        throw InputError("the volume has too few cells to split into parts for every rank (a part needs at least one "
                         "cell per axis); use fewer ranks, or --distribution sort-first or frames");
    const int below = ranks / 2;
    const double share = static_cast<double>(below) / ranks;
    int cut = cost ? costCut(c0, c1, axis, share, origin, spacing, cost) : -1;
    if (cut < 0)
        cut = c0[axis] + static_cast<int>(std::lround(cells[axis] * share));
    cut = std::clamp(cut, c0[axis] + 1, c1[axis] - 1);
    glm::ivec3 mid1 = c1, mid0 = c0;
    mid1[axis] = cut;
    mid0[axis] = cut;
    const int b = splitGrid(out, c0, mid1, origin, spacing, cost, below, firstPart);
    const int a = splitGrid(out, mid0, c1, origin, spacing, cost, ranks - below, firstPart + below);
    KdTree::Node& n = out.tree.nodes[node];
    n.axis = axis;
    n.split = origin[axis] + cut * spacing[axis];
    n.below = b;
    n.above = a;
    return node;
}

// A tetrahedron's centroid with its cost.
struct WeightedPoint {
    glm::dvec3 at;
    double cost;
};

// Builds the mesh tree over the points [first, last) (reordered in place) inside the box [lo, hi].
int splitMesh(MeshPartition& out, std::vector<WeightedPoint>& points, std::size_t first, std::size_t last,
              const glm::dvec3& lo, const glm::dvec3& hi, int ranks, int firstPart)
{
    const int node = static_cast<int>(out.tree.nodes.size());
    out.tree.nodes.emplace_back();
    if (ranks == 1) {
        out.tree.nodes[node].part = firstPart;
        out.lo[firstPart] = lo;
        out.hi[firstPart] = hi;
        return node;
    }
    const int axis = longestAxis(hi - lo);
    const int below = ranks / 2;
    const auto begin = points.begin() + static_cast<std::ptrdiff_t>(first);
    const auto end = points.begin() + static_cast<std::ptrdiff_t>(last);
    // The cost quantile of the ranks' share, inside the box (never on its faces, so both sides keep a
    // volume): the first point whose cost, with those before it, passes the share. With equal costs,
    // the centroid of rank count * below / ranks.
    double split = 0.5 * (lo[axis] + hi[axis]);
    if (first < last) {
        std::sort(begin, end, [axis](const WeightedPoint& p, const WeightedPoint& q) { return p.at[axis] < q.at[axis]; });
        double total = 0.0;
        for (auto it = begin; it != end; ++it)
            total += it->cost;
        const double target = total * below / ranks;
        double sum = 0.0;
        auto it = begin;
        for (; it + 1 != end; ++it) {
            sum += it->cost;
            if (sum > target)
                break;
        }
        split = it->at[axis];
    }
    const double margin = 1e-6 * (hi[axis] - lo[axis]);
    if (!(split > lo[axis] + margin && split < hi[axis] - margin))
        split = 0.5 * (lo[axis] + hi[axis]);
    glm::dvec3 mid1 = hi, mid0 = lo;
    mid1[axis] = split;
    mid0[axis] = split;
    // The points on each side, for the next levels.
    const auto middle = std::partition(begin, end, [&](const WeightedPoint& p) { return p.at[axis] < split; });
    const std::size_t m = static_cast<std::size_t>(middle - points.begin());
    const int b = splitMesh(out, points, first, m, lo, mid1, below, firstPart);
    const int a = splitMesh(out, points, m, last, mid0, hi, ranks - below, firstPart + below);
    KdTree::Node& n = out.tree.nodes[node];
    n.axis = axis;
    n.split = split;
    n.below = b;
    n.above = a;
    return node;
}

void checkRanks(int n)
{
    if (n < 1)
        throw InputError("a partition needs at least one part, got " + std::to_string(n));
}

}  // namespace

std::vector<int> KdTree::frontToBack(const Camera& camera) const
{
    std::vector<int> order;
    if (nodes.empty())
        return order;
    const glm::dvec3 forward = camera.forward();
    std::vector<int> stack{0};
    while (!stack.empty()) {
        const Node& n = nodes[static_cast<std::size_t>(stack.back())];
        stack.pop_back();
        if (n.axis < 0) {
            order.push_back(n.part);
            continue;
        }
        // Which side a ray starts on: the eye's side (perspective), or the side the direction leaves
        // (parallel: every ray has direction `forward`). A ray never crosses the plane back.
        const bool belowFirst = camera.parallel ? forward[n.axis] >= 0.0 : camera.position[n.axis] < n.split;
        stack.push_back(belowFirst ? n.above : n.below);  // popped second
        stack.push_back(belowFirst ? n.below : n.above);
    }
    return order;
}

int KdTree::partAt(const glm::dvec3& p) const
{
    if (nodes.empty())
        throw InternalError("KdTree::partAt: an empty tree");
    const Node* n = &nodes[0];
    while (n->axis >= 0)
        n = &nodes[static_cast<std::size_t>(p[n->axis] < n->split ? n->below : n->above)];
    return n->part;
}

GridPartition partitionGrid(const glm::ivec3& dims, const glm::dvec3& origin, const glm::dvec3& spacing, int n,
                            const CostDensity& cost)
{
    checkRanks(n);
    GridPartition out;
    out.lo.resize(static_cast<std::size_t>(n));
    out.hi.resize(static_cast<std::size_t>(n));
    splitGrid(out, glm::ivec3(0), dims - 1, origin, spacing, cost, n, 0);
    return out;
}

std::vector<double> gridPartCosts(const GridPartition& partition, const glm::dvec3& origin, const glm::dvec3& spacing,
                                  const CostDensity& cost)
{
    std::vector<double> out;
    for (std::size_t p = 0; p < partition.lo.size(); ++p) {
        std::vector<double> samples[3];
        for (int a = 0; a < 3; ++a)
            samples[a] = spreadSamples(partition.lo[p][a], partition.hi[p][a], 16);
        const glm::dvec3 size = glm::dvec3(partition.hi[p] - partition.lo[p]) * spacing;
        out.push_back(boxCost(samples, origin, spacing, size.x * size.y * size.z, cost));
    }
    return out;
}

GridRegion gridPartRegion(const GridPartition& partition, const glm::ivec3& dims, int p, int ghost)
{
    if (ghost < 0 || ghost > 1)
        throw InternalError("gridPartRegion: a ghost layer of 0 or 1 points");
    const glm::ivec3 own0 = partition.lo.at(static_cast<std::size_t>(p)), own1 = partition.hi.at(static_cast<std::size_t>(p));
    return {glm::max(own0 - ghost, glm::ivec3(0)), glm::min(own1 + ghost, dims - 1)};
}

GridPart gridPartPlacement(const GridPartition& partition, const glm::ivec3& dims, const glm::dvec3& origin, int p,
                           int ghost)
{
    const GridRegion r = gridPartRegion(partition, dims, p, ghost);
    const glm::ivec3 own0 = partition.lo.at(static_cast<std::size_t>(p)), own1 = partition.hi.at(static_cast<std::size_t>(p));
    return GridPart{r.lo, dims, origin, own0 - r.lo, r.hi - own1};
}

Volume cutGridPart(const Volume& volume, const GridPartition& partition, int p, int ghost)
{
    const GridRegion r = gridPartRegion(partition, volume.dims, p, ghost);
    const glm::ivec3 lo = r.lo, hi = r.hi;
    Volume part;
    part.dims = hi - lo + 1;
    part.spacing = volume.spacing;
    part.origin = volume.origin + glm::dvec3(lo) * volume.spacing;
    part.source = volume.source;
    part.part = gridPartPlacement(partition, volume.dims, volume.origin, p, ghost);
    // The rows of the part, in the volume's own storage (float32 or native voxels).
    part.voxelType = volume.voxelType;
    part.allocateValues();
    const std::size_t size = voxelTypeSize(volume.voxelType);
    const std::uint8_t* from = volume.valueData();
    std::uint8_t* to = part.valueData();
    std::size_t i = 0;
    for (int k = lo.z; k <= hi.z; ++k)
        for (int j = lo.y; j <= hi.y; ++j) {
            const std::size_t row = (static_cast<std::size_t>(k) * volume.dims.y + j) * volume.dims.x + lo.x;
            std::memcpy(to + i * size, from + row * size, static_cast<std::size_t>(part.dims.x) * size);
            i += static_cast<std::size_t>(part.dims.x);
        }
    return part;
}

std::vector<glm::dvec3> tetCentroids(const TetMesh& mesh)
{
    std::vector<glm::dvec3> out;
    out.reserve(mesh.tets.size());
    for (const glm::uvec4& t : mesh.tets)
        out.push_back(0.25 * (mesh.points[t.x] + mesh.points[t.y] + mesh.points[t.z] + mesh.points[t.w]));
    return out;
}

MeshPartition partitionMesh(const TetMesh& mesh, int n, const std::vector<double>& tetCost)
{
    checkRanks(n);
    if (mesh.tets.empty())
        throw InputError(mesh.source + ": the mesh has no tetrahedra to split into parts");
    if (!tetCost.empty() && tetCost.size() != mesh.tets.size())
        throw InternalError("partitionMesh: one cost per tetrahedron");
    double total = 0.0;
    for (double c : tetCost) {
        if (!(c >= 0.0) || !std::isfinite(c))
            throw InternalError("partitionMesh: a tetrahedron's cost is negative or not finite");
        total += c;
    }
    const bool byCost = total > 0.0;  // all zero: nothing to balance by, so by count
    const std::vector<glm::dvec3> centroids = tetCentroids(mesh);
    std::vector<WeightedPoint> points;
    points.reserve(centroids.size());
    for (std::size_t i = 0; i < centroids.size(); ++i)
        points.push_back({centroids[i], byCost ? tetCost[i] : 1.0});
    MeshPartition out;
    out.lo.resize(static_cast<std::size_t>(n));
    out.hi.resize(static_cast<std::size_t>(n));
    splitMesh(out, points, 0, points.size(), mesh.boundsMin(), mesh.boundsMax(), n, 0);
    return out;
}

TetMesh cutMeshPart(const TetMesh& mesh, const MeshPartition& partition, int p)
{
    const glm::dvec3 lo = partition.lo.at(static_cast<std::size_t>(p)), hi = partition.hi.at(static_cast<std::size_t>(p));
    TetMesh part;
    part.source = mesh.source;
    part.part = MeshPart{lo, hi, mesh.boundsMin(), mesh.boundsMax()};
    std::unordered_map<std::uint32_t, std::uint32_t> renumber;
    const auto point = [&](std::uint32_t v) {
        const auto [it, added] = renumber.try_emplace(v, static_cast<std::uint32_t>(part.points.size()));
        if (added) {
            part.points.push_back(mesh.points[v]);
            part.scalars.push_back(mesh.scalars[v]);
        }
        return it->second;
    };
    for (const glm::uvec4& t : mesh.tets) {
        const glm::dvec3 a = mesh.points[t.x], b = mesh.points[t.y], c = mesh.points[t.z], d = mesh.points[t.w];
        const glm::dvec3 tlo = glm::min(glm::min(a, b), glm::min(c, d)), thi = glm::max(glm::max(a, b), glm::max(c, d));
        if (glm::any(glm::lessThan(thi, lo)) || glm::any(glm::greaterThan(tlo, hi)))
            continue;
        part.tets.push_back(glm::uvec4(point(t.x), point(t.y), point(t.z), point(t.w)));
    }
    part.tetsRead = part.tets.size();
    return part;
}

Image4f compositeOver(const std::vector<const Image4f*>& frontToBack)
{
    if (frontToBack.empty())
        throw InternalError("compositeOver: no images");
    Image4f out(frontToBack[0]->width(), frontToBack[0]->height());
    for (const Image4f* image : frontToBack) {
        if (image->width() != out.width() || image->height() != out.height())
            throw InternalError("compositeOver: images of different sizes");
        for (std::size_t i = 0; i < out.pixelCount(); ++i) {
            glm::vec4& o = out.pixels()[i];
            o += (1.0f - o.a) * image->pixels()[i];
        }
    }
    return out;
}

void addBackground(Image4f& image, const glm::dvec3& background)
{
    const glm::vec3 bg(background);
    for (glm::vec4& p : image.pixels())
        p = glm::vec4(glm::vec3(p) + (1.0f - p.a) * bg, p.a);
}

std::vector<int> balanceRows(int height, const std::vector<int>& rows, const std::vector<double>& ms)
{
    if (rows.empty() || rows.size() != ms.size() || height < static_cast<int>(rows.size()))
        throw InternalError("balanceRows: one row count and one time per rank, and a row for each");
    const int n = static_cast<int>(rows.size());
    std::vector<int> out(static_cast<std::size_t>(n), height / n);
    for (int r = 0; r < height % n; ++r)
        ++out[static_cast<std::size_t>(r)];
    double total = 0.0;
    for (double t : ms)
        total += t;
    if (!(total > 0.0))
        return out;
    int given = 0;
    for (int r : rows)
        given += r;
    if (given != height || *std::min_element(rows.begin(), rows.end()) < 1)
        throw InternalError("balanceRows: the previous bands do not tile the image");
    std::vector<double> rowCost;  // per image row, top to bottom
    for (int r = 0; r < n; ++r)
        for (int i = 0; i < rows[static_cast<std::size_t>(r)]; ++i)
            rowCost.push_back(ms[static_cast<std::size_t>(r)] / rows[static_cast<std::size_t>(r)]);
    double acc = 0.0;
    int rank = 0, start = 0;
    for (int y = 0; y < height && rank < n - 1; ++y) {
        acc += rowCost[static_cast<std::size_t>(y)];
        const int left = height - (y + 1);  // rows still to hand out after this one
        if (acc >= total * (rank + 1) / n || left == n - 1 - rank) {
            out[static_cast<std::size_t>(rank)] = y + 1 - start;
            start = y + 1;
            ++rank;
        }
    }
    out[static_cast<std::size_t>(n - 1)] = height - start;
    return out;
}

}  // namespace clvr
