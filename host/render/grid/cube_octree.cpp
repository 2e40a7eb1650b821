// host/render/grid/cube_octree.cpp — the octree of seeds/002 §6: built bottom up, selected depth first,
// back to front.
#include "host/render/grid/cube_octree.h"

#include "host/render/transfer_function_upload.h"  // tauZeroOn: also slice3d's empty-brick test
#include "host/runtime/errors.h"
#include "host/runtime/parallel.h"

#include <algorithm>
#include <atomic>
#include <cmath>

namespace clvr::cubefan {

namespace {

// The octant of a node's children nearest the eye: bit a set when the eye is on the high side of the split plane of
// axis a (parallel: when the view runs down axis a). Child nearSide ^ m for m = 0 .. 7 is nearest first.
int nearSide(const glm::dvec3& split, const glm::dvec3& eye, const glm::dvec3& forward, bool parallel)
{
    int side = 0;
    for (int a = 0; a < 3; ++a)
        side |= (parallel ? forward[a] < 0.0 : eye[a] > split[a]) ? (1 << a) : 0;
    return side;
}

// Voxels of level-k cube i along an axis of n voxels.
int leavesAlong(int i, int k, int n)
{
    const long long first = static_cast<long long>(i) << k;
    return static_cast<int>(std::min<long long>((static_cast<long long>(i) + 1) << k, n) - first);
}

}  // namespace

void cubeFieldBounds(const Volume& volume, glm::dvec3& lo, glm::dvec3& hi)
{
    lo = volume.origin - 0.5 * volume.spacing;
    hi = volume.origin + (glm::dvec3(volume.dims) - 0.5) * volume.spacing;
}

CubeOctree::CubeOctree(const Volume& volume)
    : voxels_(volume.dims), origin_(volume.origin), spacing_(volume.spacing)
{
    Level leaves;
    leaves.dims = volume.dims;
    std::vector<float> scratch;
    leaves.mean = volume.floats(scratch);
    leaves.min = leaves.mean;
    leaves.max = leaves.mean;
    const glm::dvec2 r = volume.range();
    range_ = r.y - r.x;
    levels_.push_back(std::move(leaves));
    while (glm::any(glm::greaterThan(levels_.back().dims, glm::ivec3(1)))) {
        const int k = static_cast<int>(levels_.size()) - 1;  // the finer level
        const Level& fine = levels_.back();
        Level coarse;
        coarse.dims = (fine.dims + 1) / 2;
        const std::size_t count = static_cast<std::size_t>(coarse.dims.x) * coarse.dims.y * coarse.dims.z;
        coarse.mean.resize(count);
        coarse.min.resize(count);
        coarse.max.resize(count);
        glm::ivec3 c;
        for (c.z = 0; c.z < coarse.dims.z; ++c.z)
            for (c.y = 0; c.y < coarse.dims.y; ++c.y)
                for (c.x = 0; c.x < coarse.dims.x; ++c.x) {
                    double sum = 0.0, leavesBelow = 0.0;
                    float lo = INFINITY, hi = -INFINITY;
                    for (int m = 0; m < 8; ++m) {
                        const glm::ivec3 f = 2 * c + glm::ivec3(m & 1, (m >> 1) & 1, (m >> 2) & 1);
                        if (glm::any(glm::greaterThanEqual(f, fine.dims)))
                            continue;
                        const std::size_t j = (static_cast<std::size_t>(f.z) * fine.dims.y + f.y) * fine.dims.x + f.x;
                        const double n = static_cast<double>(leavesAlong(f.x, k, voxels_.x)) *
                                         leavesAlong(f.y, k, voxels_.y) * leavesAlong(f.z, k, voxels_.z);
                        sum += n * fine.mean[j];
                        leavesBelow += n;
                        lo = std::min(lo, fine.min[j]);
                        hi = std::max(hi, fine.max[j]);
                    }
                    const std::size_t i = (static_cast<std::size_t>(c.z) * coarse.dims.y + c.y) * coarse.dims.x + c.x;
                    coarse.mean[i] = static_cast<float>(sum / leavesBelow);
                    coarse.min[i] = lo;
                    coarse.max[i] = hi;
                }
        levels_.push_back(std::move(coarse));
    }
}

float CubeOctree::error(int level, const glm::ivec3& i) const
{
    const Level& l = levels_[level];
    const std::size_t j = at(level, i);
    return std::max(l.max[j] - l.mean[j], l.mean[j] - l.min[j]);
}

void CubeOctree::box(int level, const glm::ivec3& i, glm::dvec3& lo, glm::dvec3& hi) const
{
    for (int a = 0; a < 3; ++a) {
        const double first = static_cast<double>(static_cast<long long>(i[a]) << level);
        lo[a] = origin_[a] + (first - 0.5) * spacing_[a];
        hi[a] = origin_[a] + (first + leavesAlong(i[a], level, voxels_[a]) - 0.5) * spacing_[a];
    }
}

CubeOctree::Verdict CubeOctree::verdict(int level, const glm::ivec3& i, double allowed, const TransferFunction& tf) const
{
    const Level& l = levels_[level];
    const std::size_t j = at(level, i);
    if (tauZeroOn(tf, l.min[j], l.max[j]))
        return Verdict::Transparent;  // the whole subtree
    if (level == 0 || error(level, i) <= allowed)
        return tf(l.mean[j]).a <= 0.0 ? Verdict::Transparent : Verdict::Take;
    return Verdict::Descend;
}

Cube CubeOctree::take(int level, const glm::ivec3& i, SelectionStats& s) const
{
    Cube c;
    c.level = level;
    c.index = i;
    c.value = value(level, i);
    box(level, i, c.lo, c.hi);
    s.largestDiagonal = std::max(s.largestDiagonal, glm::length(c.hi - c.lo));
    return c;
}

std::vector<Cube> CubeOctree::select(double tolerance, const TransferFunction& tf, const glm::dvec3& eye,
                                     const glm::dvec3& forward, bool parallel, SelectionStats* stats) const
{
    std::vector<Cube> out;
    SelectionStats s;
    const double allowed = tolerance * range_;
    // Recursion depth is the level count (at most 32 for any int dims), so plain recursion is bounded.
    auto visit = [&](auto&& self, int level, const glm::ivec3& i) -> void {
        ++s.visited;
        const Verdict v = verdict(level, i, allowed, tf);
        if (v == Verdict::Transparent) {
            ++s.transparent;
            return;
        }
        if (v == Verdict::Take) {
            out.push_back(take(level, i, s));
            return;
        }
        // The children's split planes: the high corner of the low child's box.
        glm::dvec3 lo, hi;
        box(level - 1, 2 * i, lo, hi);
        const int side = nearSide(hi, eye, forward, parallel);
        const glm::ivec3 childDims = levels_[level - 1].dims;
        for (int m = 7; m >= 0; --m) {  // farthest first: the child on the far side of every plane
            const int child = side ^ m;
            const glm::ivec3 ci = 2 * i + glm::ivec3(child & 1, (child >> 1) & 1, (child >> 2) & 1);
            if (glm::all(glm::lessThan(ci, childDims)))
                self(self, level - 1, ci);
        }
    };
    visit(visit, levels() - 1, glm::ivec3(0));
    s.selected = out.size();
    if (stats)
        *stats = s;
    return out;
}

CubeOctree::SelectionGrid CubeOctree::selectGrid(double tolerance, const TransferFunction& tf, SelectionStats* stats) const
{
    SelectionGrid grid;
    const glm::ivec3 bricks = (voxels_ + 3) / 4;
    const std::size_t count = static_cast<std::size_t>(bricks.x) * bricks.y * bricks.z * 64;
    grid.level.assign(count, kTransparent);  // the bricks' padding beyond the grid adds nothing
    grid.value.assign(count, 0.0f);
    SelectionStats s;
    const double allowed = tolerance * range_;
    // Writes the cube's level (and flag) and value into every voxel below it.
    auto fill = [&](int level, const glm::ivec3& i, std::uint8_t code, float v) {
        const glm::ivec3 first = i * (1 << level);
        const glm::ivec3 end = glm::min(first + (1 << level), voxels_);
        glm::ivec3 p;
        for (p.z = first.z; p.z < end.z; ++p.z)
            for (p.y = first.y; p.y < end.y; ++p.y)
                for (p.x = first.x; p.x < end.x; ++p.x) {
                    const std::size_t at = selectionGridIndex(p, voxels_);
                    grid.level[at] = code;
                    grid.value[at] = v;
                }
    };
    auto visit = [&](auto&& self, int level, const glm::ivec3& i) -> void {
        ++s.visited;
        const Verdict v = verdict(level, i, allowed, tf);
        if (v == Verdict::Descend) {
            const glm::ivec3 childDims = levels_[level - 1].dims;
            for (int m = 0; m < 8; ++m) {
                const glm::ivec3 ci = 2 * i + glm::ivec3(m & 1, (m >> 1) & 1, (m >> 2) & 1);
                if (glm::all(glm::lessThan(ci, childDims)))
                    self(self, level - 1, ci);
            }
            return;
        }
        const bool transparent = v == Verdict::Transparent;
        s.transparent += transparent ? 1 : 0;
        if (!transparent) {
            ++s.selected;
            glm::dvec3 lo, hi;
            box(level, i, lo, hi);
            s.largestDiagonal = std::max(s.largestDiagonal, glm::length(hi - lo));
        }
        fill(level, i, static_cast<std::uint8_t>(level | (transparent ? kTransparent : 0)), value(level, i));
    };
    visit(visit, levels() - 1, glm::ivec3(0));
    if (stats)
        *stats = s;
    return grid;
}

CubeOctree::SelectionTree CubeOctree::selectTree(double tolerance, const TransferFunction& tf, SelectionStats* stats) const
{
    SelectionTree tree;
    SelectionStats s;
    const double allowed = tolerance * range_;
    // Returns what goes into the parent's child slot.
    auto visit = [&](auto&& self, int level, const glm::ivec3& i) -> std::int32_t {
        ++s.visited;
        const Verdict v = verdict(level, i, allowed, tf);
        if (v == Verdict::Transparent) {
            ++s.transparent;
            return SelectionTree::kNone;
        }
        if (v == Verdict::Take) {
            tree.cubes.push_back(take(level, i, s));
            return ~static_cast<std::int32_t>(tree.cubes.size() - 1);
        }
        const std::size_t at = tree.nodes.size();
        tree.nodes.emplace_back();
        glm::dvec3 lo, hi;
        box(level - 1, 2 * i, lo, hi);
        tree.nodes[at].split = hi;
        const glm::ivec3 childDims = levels_[level - 1].dims;
        for (int m = 0; m < 8; ++m) {
            const glm::ivec3 ci = 2 * i + glm::ivec3(m & 1, (m >> 1) & 1, (m >> 2) & 1);
            const std::int32_t child = glm::all(glm::lessThan(ci, childDims)) ? self(self, level - 1, ci)
                                                                                : SelectionTree::kNone;
            tree.nodes[at].child[static_cast<std::size_t>(m)] = child;
        }
        return static_cast<std::int32_t>(at);
    };
    tree.root = visit(visit, levels() - 1, glm::ivec3(0));
    if (tree.cubes.size() >= static_cast<std::size_t>(std::numeric_limits<std::int32_t>::max()))
        throw InputError("cubefan: more than 2^31 cubes selected");
    s.selected = tree.cubes.size();
    if (stats)
        *stats = s;
    return tree;
}

void CubeOctree::SelectionTree::frontToBack(const glm::dvec3& eye, const glm::dvec3& forward, bool parallel,
                                            std::vector<std::uint32_t>& order) const
{
    // Depth first, a node's children nearest first (select()'s order reversed): visit(child) for each child there is.
    auto forChildren = [&](const Node& n, const auto& visit) {
        const int side = nearSide(n.split, eye, forward, parallel);
        for (int m = 0; m < 8; ++m)
            if (const std::int32_t child = n.child[static_cast<std::size_t>(side ^ m)]; child != kNone)
                visit(child);
    };
    // The top levels expanded in that order into at least kItems subtrees and cubes, then the subtrees walked on the
    // host's threads, each into its own list (recursion depth: the level count), and the lists joined in order.
    constexpr std::size_t kItems = 64;
    std::vector<std::int32_t> items, next;
    if (root != kNone)
        items.push_back(root);
    for (bool expanded = true; expanded && items.size() < kItems;) {
        expanded = false;
        next.clear();
        for (const std::int32_t item : items) {
            if (item < 0) {
                next.push_back(item);
                continue;
            }
            expanded = true;
            forChildren(nodes[static_cast<std::size_t>(item)], [&](std::int32_t child) { next.push_back(child); });
        }
        items.swap(next);
    }
    std::vector<std::vector<std::uint32_t>> lists(items.size());
    auto visit = [&](auto&& self, std::int32_t item, std::vector<std::uint32_t>& out) -> void {
        if (item < 0) {
            out.push_back(static_cast<std::uint32_t>(~item));
            return;
        }
        forChildren(nodes[static_cast<std::size_t>(item)], [&](std::int32_t child) { self(self, child, out); });
    };
    std::atomic<std::size_t> taken{0};
    runOnThreads(0, static_cast<int>(std::min<std::size_t>(items.size(), cubes.size() / 16384 + 1)), [&] {
        for (std::size_t k; (k = taken.fetch_add(1)) < items.size();)
            visit(visit, items[k], lists[k]);
    });
    order.clear();
    order.reserve(cubes.size());
    for (const std::vector<std::uint32_t>& list : lists)
        order.insert(order.end(), list.begin(), list.end());
}

}  // namespace clvr::cubefan
