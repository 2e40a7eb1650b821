// host/render/grid/cube_octree.h — the data hierarchy of seeds/002 §6: one cube per voxel (a cube of one
// grid spacing centred on its grid point), merged bottom up into an octree whose cube values are the mean
// of their leaves and whose error is the largest |value - leaf| below them; selection depth first until a
// cube's error is within the tolerance, in back-to-front order for the eye, skipping cubes the transfer
// function makes transparent. host/render/grid/cubefan.h draws the cubes.
#pragma once

#include "host/model/transfer_function.h"
#include "host/model/volume.h"

#include <glm/glm.hpp>

#include <cstdint>
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

private:
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
