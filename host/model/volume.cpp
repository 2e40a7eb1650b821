// host/model/volume.cpp — trilinear reconstruction and validation of regular grids.
#include "host/model/volume.h"

#include "host/runtime/errors.h"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <new>
#include <unistd.h>

namespace clvr {

glm::vec3 GridPart::ownLo() const { return glm::vec3(offset + ghostLo); }

glm::vec3 GridPart::ownHi(const glm::ivec3& dims) const
{
    glm::vec3 hi;
    for (int a = 0; a < 3; ++a) {
        const int last = offset[a] + dims[a] - 1 - ghostHi[a];
        hi[a] = last == fullDims[a] - 1 ? std::nextafter(static_cast<float>(last), INFINITY) : static_cast<float>(last);
    }
    return hi;
}

namespace {

// This machine's physical memory in bytes; 0 when the system does not say.
std::uint64_t physicalMemory()
{
    const long pages = ::sysconf(_SC_PHYS_PAGES), pageSize = ::sysconf(_SC_PAGE_SIZE);
    return pages > 0 && pageSize > 0 ? static_cast<std::uint64_t>(pages) * static_cast<std::uint64_t>(pageSize) : 0;
}

}  // namespace

void checkHostMemoryForVoxels(const std::string& source, std::uint64_t voxels)
{
    const std::uint64_t physical = physicalMemory();  // 0: unknown, let the allocation decide
    const std::uint64_t needed = voxels * sizeof(float);
    if (physical > 0 && needed > physical / 2)
        throw InputError(source + ": " + std::to_string(voxels) + " grid points need " +
                         std::to_string(needed >> 20) + " MiB as float32, more than half of this machine's " +
                         std::to_string(physical >> 20) + " MiB of memory");
}

void checkHostMemory(const std::string& what, std::uint64_t bytes)
{
    const std::uint64_t physical = physicalMemory();
    if (physical > 0 && bytes > physical / 2)
        throw InputError(what + " needs " + std::to_string(bytes >> 20) + " MiB, more than half of this machine's " +
                         std::to_string(physical >> 20) + " MiB of memory");
}

namespace {

constexpr std::size_t kVoxelBlockAlignment = 4096;  // a page: more than any OpenCL device's base address alignment

std::shared_ptr<std::uint8_t> allocateVoxelBlock(std::size_t size)
{
    if (size == 0)
        return nullptr;
    const std::size_t rounded = (size + kVoxelBlockAlignment - 1) / kVoxelBlockAlignment * kVoxelBlockAlignment;
    void* p = std::aligned_alloc(kVoxelBlockAlignment, rounded);
    if (!p)
        throw std::bad_alloc();
    std::memset(p, 0, rounded);
    return std::shared_ptr<std::uint8_t>(static_cast<std::uint8_t*>(p), [](std::uint8_t* q) { std::free(q); });
}

}  // namespace

VoxelBytes::VoxelBytes(std::size_t size) : block_(allocateVoxelBlock(size)), size_(size) {}

VoxelBytes::VoxelBytes(const VoxelBytes& other) : VoxelBytes(other.size_)
{
    if (size_)
        std::memcpy(block_.get(), other.block_.get(), size_);
}

VoxelBytes::VoxelBytes(VoxelBytes&& other) noexcept : block_(std::move(other.block_)), size_(other.size_)
{
    other.size_ = 0;
}

VoxelBytes& VoxelBytes::operator=(const VoxelBytes& other)
{
    if (this != &other)
        *this = VoxelBytes(other);
    return *this;
}

VoxelBytes& VoxelBytes::operator=(VoxelBytes&& other) noexcept
{
    if (this != &other) {
        block_ = std::move(other.block_);
        size_ = other.size_;
        other.size_ = 0;
    }
    return *this;
}

void VoxelBytes::resize(std::size_t size)
{
    if (size == size_)
        return;
    VoxelBytes grown(size);
    if (const std::size_t kept = std::min(size, size_))
        std::memcpy(grown.data(), data(), kept);
    *this = std::move(grown);
}

bool operator==(const VoxelBytes& a, const VoxelBytes& b)
{
    return a.size_ == b.size_ && (a.size_ == 0 || std::memcmp(a.data(), b.data(), a.size_) == 0);
}

std::size_t voxelTypeSize(VoxelType type)
{
    switch (type) {
    case VoxelType::UInt8:
    case VoxelType::Int8: return 1;
    case VoxelType::UInt16:
    case VoxelType::Int16: return 2;
    case VoxelType::Float32: break;
    }
    return 4;
}

const char* voxelTypeName(VoxelType type)
{
    switch (type) {
    case VoxelType::UInt8: return "uint8";
    case VoxelType::Int8: return "int8";
    case VoxelType::UInt16: return "uint16";
    case VoxelType::Int16: return "int16";
    case VoxelType::Float32: break;
    }
    return "float32";
}

float Volume::value(std::size_t index) const
{
    switch (voxelType) {
    case VoxelType::UInt8: return static_cast<float>(voxels[index]);
    case VoxelType::Int8: return static_cast<float>(static_cast<std::int8_t>(voxels[index]));
    case VoxelType::UInt16: {
        std::uint16_t v;
        std::memcpy(&v, voxels.data() + 2 * index, 2);
        return static_cast<float>(v);
    }
    case VoxelType::Int16: {
        std::int16_t v;
        std::memcpy(&v, voxels.data() + 2 * index, 2);
        return static_cast<float>(v);
    }
    case VoxelType::Float32: break;
    }
    return values[index];
}

void Volume::allocateValues()
{
    if (native())
        voxels.resize(voxelCount() * voxelTypeSize(voxelType));
    else
        values.resize(voxelCount());
}

std::uint8_t* Volume::valueData()
{
    return native() ? voxels.data() : reinterpret_cast<std::uint8_t*>(values.data());
}

const std::uint8_t* Volume::valueData() const
{
    return native() ? voxels.data() : reinterpret_cast<const std::uint8_t*>(values.data());
}

const std::vector<float>& Volume::floats(std::vector<float>& scratch) const
{
    if (!native())
        return values;
    scratch.resize(voxelCount());
    withVoxels(*this, [&](const auto* data, std::size_t n) {
        for (std::size_t i = 0; i < n; ++i)
            scratch[i] = static_cast<float>(data[i]);
    });
    return scratch;
}

std::optional<double> Volume::sample(const glm::dvec3& p) const
{
    const glm::dvec3 g = (p - origin) / spacing;  // grid coordinates
    const glm::dvec3 last(dims - 1);
    for (int a = 0; a < 3; ++a)
        if (!(g[a] >= 0.0 && g[a] <= last[a]))
            return std::nullopt;
    glm::ivec3 i0 = glm::min(glm::ivec3(glm::floor(g)), dims - 2);
    i0 = glm::max(i0, glm::ivec3(0));
    const glm::dvec3 f = g - glm::dvec3(i0);
    auto v = [&](int dx, int dy, int dz) { return static_cast<double>(at(i0.x + dx, i0.y + dy, i0.z + dz)); };
    const double c00 = v(0, 0, 0) * (1 - f.x) + v(1, 0, 0) * f.x;
    const double c10 = v(0, 1, 0) * (1 - f.x) + v(1, 1, 0) * f.x;
    const double c01 = v(0, 0, 1) * (1 - f.x) + v(1, 0, 1) * f.x;
    const double c11 = v(0, 1, 1) * (1 - f.x) + v(1, 1, 1) * f.x;
    const double c0 = c00 * (1 - f.y) + c10 * f.y;
    const double c1 = c01 * (1 - f.y) + c11 * f.y;
    return c0 * (1 - f.z) + c1 * f.z;
}

glm::dvec2 Volume::range() const
{
    return withVoxels(*this, [](const auto* data, std::size_t n) {
        if (n == 0)
            return glm::dvec2(0.0);
        const auto [lo, hi] = std::minmax_element(data, data + n);
        return glm::dvec2(static_cast<double>(*lo), static_cast<double>(*hi));
    });
}

void Volume::validate() const
{
    for (int a = 0; a < 3; ++a) {
        if (dims[a] < 2)
            throw InputError(source + ": dimension " + std::to_string(a) + " is " + std::to_string(dims[a]) +
                             ", must be at least 2 grid points");
        if (!(spacing[a] > 0.0) || !std::isfinite(spacing[a]))
            throw InputError(source + ": spacing " + std::to_string(a) + " must be a positive finite number");
        if (!std::isfinite(origin[a]))
            throw InputError(source + ": origin must be finite");
    }
    const std::size_t held = native() ? voxels.size() / voxelTypeSize(voxelType) : values.size();
    if (held != voxelCount() || (native() && (!values.empty() || voxels.size() % voxelTypeSize(voxelType) != 0)))
        throw InputError(source + ": has " + std::to_string(held) + " values for " +
                         std::to_string(dims.x) + "x" + std::to_string(dims.y) + "x" + std::to_string(dims.z) +
                         " grid points");
    if (!native())  // integers are finite
        for (std::size_t i = 0; i < values.size(); ++i)
            if (!std::isfinite(values[i]))
                throw InputError(source + ": value " + std::to_string(i) + " is NaN or infinite");
    if (part)  // made by code (host/cluster/partition.h), never read from a file
        for (int a = 0; a < 3; ++a)
            if (part->offset[a] < 0 || part->offset[a] + dims[a] > part->fullDims[a])
                throw InternalError(source + ": part of a larger grid does not lie inside it on axis " +
                                    std::to_string(a));
}

}  // namespace clvr
