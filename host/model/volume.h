// host/model/volume.h — a regular grid as DESIGN.md defines it: values on grid points (VTK point data),
// x fastest; bounds origin .. origin + (n-1)*spacing; trilinear reconstruction; empty outside.
#pragma once

#include <glm/glm.hpp>

#include <cstddef>
#include <cstdint>
#include <memory>
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

// The bytes of a volume's voxels in their own type: one page-aligned block behind a shared pointer, so that a
// device whose memory is the host's can render from the block itself (Device::readOnlyOver) and keep it alive
// as long as its buffer lives — one copy of the voxels in the process, not two (issue 37 goal 4). Value
// semantics as std::vector<std::uint8_t>: a copy copies the bytes, a move moves the block.
class VoxelBytes {
public:
    VoxelBytes() = default;
    explicit VoxelBytes(std::size_t size);  // zero-filled
    VoxelBytes(const VoxelBytes& other);
    VoxelBytes(VoxelBytes&& other) noexcept;
    VoxelBytes& operator=(const VoxelBytes& other);
    VoxelBytes& operator=(VoxelBytes&& other) noexcept;

    std::size_t size() const { return size_; }
    bool empty() const { return size_ == 0; }
    std::uint8_t* data() { return block_.get(); }
    const std::uint8_t* data() const { return block_.get(); }
    std::uint8_t& operator[](std::size_t i) { return block_.get()[i]; }
    std::uint8_t operator[](std::size_t i) const { return block_.get()[i]; }
    // A new zero-filled block of `size` bytes that starts with the old one's first min(size, size()) bytes.
    void resize(std::size_t size);
    // Shares the block: what a device buffer over data() holds to keep it alive.
    std::shared_ptr<const void> owner() const { return block_; }

    friend bool operator==(const VoxelBytes& a, const VoxelBytes& b);

private:
    std::shared_ptr<std::uint8_t> block_;
    std::size_t size_ = 0;
};

// The types a Volume holds its values in: float32, or (where a file stores them so) integers of one and two
// bytes in their own type, which float represents exactly (issue 37 goal 2: no float copy of such a volume).
enum class VoxelType : std::uint32_t { Float32, UInt8, Int8, UInt16, Int16 };
std::size_t voxelTypeSize(VoxelType type);
const char* voxelTypeName(VoxelType type);  // "float32", "uint8", ...

struct Volume {
    glm::ivec3 dims{0};
    glm::dvec3 spacing{1.0};
    glm::dvec3 origin{0.0};
    std::vector<float> values;  // data units, as stored (int16 CT numbers stay CT numbers); empty when
                                // `voxels` holds them
    // The values in their own integer type (voxelType, host byte order), where a reader kept them so (raw,
    // NRRD in one raw stream, .npy, VTK's formats); `values` is then empty. Read either storage through
    // at(), value(), floats() or withVoxels().
    VoxelType voxelType = VoxelType::Float32;
    VoxelBytes voxels;
    std::string source;         // file or generator it came from, for messages
    std::optional<GridPart> part;  // set only on a part of a larger grid (sort-last); see GridPart
    // `part`, or for a whole volume the GridPart that makes it the only part of itself (offset 0).
    GridPart gridPart() const { return part ? *part : GridPart{glm::ivec3(0), dims, origin}; }

    std::size_t voxelCount() const { return static_cast<std::size_t>(dims.x) * dims.y * dims.z; }
    glm::dvec3 boundsMin() const { return origin; }
    glm::dvec3 boundsMax() const { return origin + glm::dvec3(dims - 1) * spacing; }
    bool native() const { return voxelType != VoxelType::Float32; }
    // The value of grid point `index` (x fastest), from either storage.
    float value(std::size_t index) const;
    float at(int i, int j, int k) const { return value((static_cast<std::size_t>(k) * dims.y + j) * dims.x + i); }
    // Every value as float: `values` itself, or the native voxels converted into `scratch` (for code that
    // needs float32 on the host; it costs 4 bytes per grid point while `scratch` lives).
    const std::vector<float>& floats(std::vector<float>& scratch) const;
    // Host bytes of the values: 4 per grid point as float32, 1 or 2 as native voxels.
    std::uint64_t valueBytes() const { return values.size() * sizeof(float) + voxels.size(); }
    // Sizes the storage voxelType names for voxelCount() values (the other one left empty), and the values'
    // bytes in it, x fastest, voxelTypeSize(voxelType) bytes each: for code that moves values whatever their
    // type (cutting parts, transposing, copying pieces in).
    void allocateValues();
    std::uint8_t* valueData();
    const std::uint8_t* valueData() const;
    // Trilinear reconstruction at a world position; nullopt outside the bounds.
    std::optional<double> sample(const glm::dvec3& p) const;
    // Smallest and largest value.
    glm::dvec2 range() const;
    // Throws InputError (naming `source`) for dims < 1 (or < 2 on any axis), spacing <= 0 or
    // non-finite, a values size that disagrees with dims, or NaN/infinite values.
    void validate() const;
};

// Calls f(const T* data, std::size_t count) with the volume's values in their storage type T (float,
// std::uint8_t, std::int8_t, std::uint16_t or std::int16_t) and returns what it returns.
template <typename F>
decltype(auto) withVoxels(const Volume& v, F&& f)
{
    const std::size_t n = v.voxelCount();
    switch (v.voxelType) {
    case VoxelType::UInt8: return f(reinterpret_cast<const std::uint8_t*>(v.voxels.data()), n);
    case VoxelType::Int8: return f(reinterpret_cast<const std::int8_t*>(v.voxels.data()), n);
    case VoxelType::UInt16: return f(reinterpret_cast<const std::uint16_t*>(v.voxels.data()), n);
    case VoxelType::Int16: return f(reinterpret_cast<const std::int16_t*>(v.voxels.data()), n);
    case VoxelType::Float32: break;
    }
    return f(v.values.data(), n);
}

}  // namespace clvr
