// host/render/grid/cube_octree.h — the data hierarchy of seeds/002 §6: one cube per voxel (a cube of one
// grid spacing centred on its grid point), merged bottom up into an octree whose cube values are the mean
// of their leaves and whose error is the largest |value - leaf| below them; selection depth first until a
// cube's error is within the tolerance, in back-to-front order for the eye, skipping cubes the transfer
// function makes transparent. host/render/grid/cubefan.h draws the cubes.
#pragma once

#include "host/model/transfer_function.h"
#include "host/model/volume.h"

#include <glm/glm.hpp>

#include <array>
#include <cstdint>
#include <limits>
#include <vector>

namespace clvr::cubefan {

// One selected cube: level (0: a voxel), its index on that level and its box in world coordinates.
struct Cube {
    int level = 0;
    glm::ivec3 index{0};
    glm::dvec3 lo{0.0}, hi{0.0};
    float value = 0.0f;
};

// The box the cube field fills: the grid's bounds grown by half a spacing on every side (the root's box).
void cubeFieldBounds(const Volume& volume, glm::dvec3& lo, glm::dvec3& hi);

struct SelectionStats {
    std::uint64_t visited = 0;      // nodes looked at
    std::uint64_t selected = 0;     // cubes returned
    std::uint64_t transparent = 0;  // cubes (or whole subtrees, counted once) skipped as transparent
    double largestDiagonal = 0.0;   // of the selected cubes, world units
};

// Voxel v's place in a selection grid over `dims` voxels: bricks of 4 x 4 x 4 (64 entries, the level bytes
// of one cache line), the bricks x fastest and the voxels inside each x fastest; the grid has
// ceil(dims / 4) bricks per axis (kernels/cubefan.cl's cubefan_at).
inline std::size_t selectionGridIndex(const glm::ivec3& v, const glm::ivec3& dims)
{
    const glm::ivec3 bricks = (dims + 3) / 4;
    const std::size_t brick =
        (static_cast<std::size_t>(v.z >> 2) * bricks.y + static_cast<std::size_t>(v.y >> 2)) * bricks.x + (v.x >> 2);
    return (brick << 6) | static_cast<std::size_t>(((v.z & 3) << 4) | ((v.y & 3) << 2) | (v.x & 3));
}

class CubeOctree {
public:
    // Level 0 has the volume's dims; level k+1 has ceil(dims_k / 2) per axis, up to a single cube.
    // A cube's value is the mean of the voxels below it (a cube at the volume's far faces has fewer
    // than 8^k), its error max |value - voxel| over them.
    explicit CubeOctree(const Volume& volume);

    int levels() const { return static_cast<int>(levels_.size()); }
    glm::ivec3 dims(int level) const { return levels_[level].dims; }
    float value(int level, const glm::ivec3& i) const { return levels_[level].mean[at(level, i)]; }
    float error(int level, const glm::ivec3& i) const;
    double dataRange() const { return range_; }

    // World box of cube i of `level`: voxels [i 2^k, min((i+1) 2^k, n)) each spanning its grid point
    // +- half a spacing.
    void box(int level, const glm::ivec3& i, glm::dvec3& lo, glm::dvec3& hi) const;

    // Depth first from the root: a cube is taken when it is a voxel or its error <= tolerance * data
    // range, and kept when tf's extinction at its value is > 0; a subtree whose value range the transfer
    // function makes transparent throughout (tauZeroOn, as slice3d's empty bricks) is skipped whole.
    // Children are visited farthest first from the eye (perspective) or along forward (parallel: eye
    // unused), so the result is back to front.
    std::vector<Cube> select(double tolerance, const TransferFunction& tf, const glm::dvec3& eye,
                             const glm::dvec3& forward, bool parallel, SelectionStats* stats = nullptr) const;

    // The same selection as a grid over the voxels, for the fused path's ray walk (no order: each ray
    // finds its own): per voxel the level of the selected cube that holds it, with kTransparent set where
    // that cube (or a transparent subtree skipped whole, its level given) adds nothing, and the cube's
    // value. The cube holding voxel v at level L is index v >> L on that level. Laid out in bricks of
    // 4 x 4 x 4 voxels (selectionGridIndex), the layout kernels/cubefan.cl reads.
    static constexpr std::uint8_t kTransparent = 0x80;
    struct SelectionGrid {
        std::vector<std::uint8_t> level;
        std::vector<float> value;
    };
    SelectionGrid selectGrid(double tolerance, const TransferFunction& tf, SelectionStats* stats = nullptr) const;

    // The same selection once more, for orders per view (the tile path, host/render/grid/cubefan.cpp): the cubes
    // that add color (`cubes`, their index is their id) and the octree's nodes that the selection descends
    // through, each with its split point and its children — a node (>= 0), a cube (~id) or none (kNone: outside
    // the grid, or transparent). frontToBack orders the cubes for an eye as select() does, nearest first.
    struct SelectionTree {
        static constexpr std::int32_t kNone = std::numeric_limits<std::int32_t>::min();
        struct Node {
            glm::dvec3 split;                 // the world coordinates of the planes between the children
            std::array<std::int32_t, 8> child; // child m at (m & 1, m >> 1 & 1, m >> 2 & 1) of the split
        };
        std::vector<Node> nodes;  // nodes[0] the root, when it is split
        std::vector<Cube> cubes;
        std::int32_t root = kNone;  // a node, a cube (~id) or none
        // The cubes' ids, nearest first: the reverse of select()'s back-to-front order for the same eye.
        void frontToBack(const glm::dvec3& eye, const glm::dvec3& forward, bool parallel,
                         std::vector<std::uint32_t>& order) const;
    };
    SelectionTree selectTree(double tolerance, const TransferFunction& tf, SelectionStats* stats = nullptr) const;

private:
    // The selection's verdict on one cube: drawn whole, transparent (skipped with its subtree), or split.
    enum class Verdict { Take, Transparent, Descend };
    Verdict verdict(int level, const glm::ivec3& i, double allowed, const TransferFunction& tf) const;
    // A cube taken whole by a selection (its largest diagonal noted in s).
    Cube take(int level, const glm::ivec3& i, SelectionStats& s) const;

    struct Level {
        glm::ivec3 dims{0};
        std::vector<float> mean, min, max;
    };
    std::size_t at(int level, const glm::ivec3& i) const
    {
        const glm::ivec3 n = levels_[level].dims;
        return (static_cast<std::size_t>(i.z) * n.y + i.y) * n.x + i.x;
    }
    std::vector<Level> levels_;
    glm::ivec3 voxels_{0};
    glm::dvec3 origin_{0.0}, spacing_{1.0};
    double range_ = 0.0;
};

}  // namespace clvr::cubefan
