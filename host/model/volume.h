// host/model/volume.h — a regular grid as DESIGN.md defines it: values on grid points (VTK point data),
// x fastest; bounds origin .. origin + (n-1)*spacing; trilinear reconstruction; empty outside.
#pragma once

#include <glm/glm.hpp>

#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

namespace clvr {

// Throws InputError (naming `source`) when `voxels` float values would not fit in half of this
// machine's physical memory: a volume that large would be killed by the OOM killer, not reported.
void checkHostMemoryForVoxels(const std::string& source, std::uint64_t voxels);

// The same for `bytes` of host memory that `what` ("engine.nrrd: cubefan's octree") needs:
// InputError "WHAT needs N MiB, more than half of this machine's M MiB of memory".
void checkHostMemory(const std::string& what, std::uint64_t bytes);

// Where a volume sits in the larger grid it was cut from (sort-last cluster rendering, host/cluster/):
// its grid point (0, 0, 0) is point `offset` of that grid, whose dims and origin these are (same
// spacing). It may hold `ghostLo`/`ghostHi` extra layers of points beyond its own on each axis (0 or 1;
// planes and blend need one for their Sobel gradients). Such a volume "owns" the full grid coordinates
// [offset + ghostLo, offset + dims - 1 - ghostHi) per axis, closed at the full grid's last point, so that
// parts cut with one shared layer of points own every sample once.
struct GridPart {
    glm::ivec3 offset{0};
    glm::ivec3 fullDims{0};
    glm::dvec3 fullOrigin{0.0};
    glm::ivec3 ghostLo{0}, ghostHi{0};

    glm::dvec3 fullBoundsMin() const { return fullOrigin; }
    glm::dvec3 fullBoundsMax(const glm::dvec3& spacing) const { return fullOrigin + glm::dvec3(fullDims - 1) * spacing; }
    // The owned range as the kernels test it, own_lo <= g < own_hi in full grid coordinates (own_hi is
    // the next float above the full grid's last point where the part reaches it). `dims`: the part's.
    glm::vec3 ownLo() const;
    glm::vec3 ownHi(const glm::ivec3& dims) const;
};

// A box of a grid's points, [lo, hi] inclusive per axis (a sort-last rank's part, with its ghost layers).
struct GridRegion {
    glm::ivec3 lo{0}, hi{0};
    glm::ivec3 dims() const { return hi - lo + 1; }
};

// What a volume file's header says of its grid, before any value is read.
struct GridHeader {
    glm::ivec3 dims{0};
    glm::dvec3 spacing{1.0};
    glm::dvec3 origin{0.0};
};

struct Volume {
    glm::ivec3 dims{0};
    glm::dvec3 spacing{1.0};
    glm::dvec3 origin{0.0};
    std::vector<float> values;  // data units, as stored (int16 CT numbers stay CT numbers)
    std::string source;         // file or generator it came from, for messages
    std::optional<GridPart> part;  // set only on a part of a larger grid (sort-last); see GridPart
    // `part`, or for a whole volume the GridPart that makes it the only part of itself (offset 0).
    GridPart gridPart() const { return part ? *part : GridPart{glm::ivec3(0), dims, origin}; }

    std::size_t voxelCount() const { return static_cast<std::size_t>(dims.x) * dims.y * dims.z; }
    glm::dvec3 boundsMin() const { return origin; }
    glm::dvec3 boundsMax() const { return origin + glm::dvec3(dims - 1) * spacing; }
    float at(int i, int j, int k) const
    {
        return values[(static_cast<std::size_t>(k) * dims.y + j) * dims.x + i];
    }
    // Trilinear reconstruction at a world position; nullopt outside the bounds.
    std::optional<double> sample(const glm::dvec3& p) const;
    // Smallest and largest value.
    glm::dvec2 range() const;
    // Throws InputError (naming `source`) for dims < 1 (or < 2 on any axis), spacing <= 0 or
    // non-finite, a values size that disagrees with dims, or NaN/infinite values.
    void validate() const;
};

}  // namespace clvr
