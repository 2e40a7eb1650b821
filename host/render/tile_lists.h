// host/render/tile_lists.h — items (cells, cubes) binned to tiles of pixels by their boxes of pixel centres, in a
// given order: the lists the tile kernels walk (kernels/projtet.cl projtet_fused, kernels/cubefan.cl cubefan_tiles).
#pragma once

#include <CL/opencl.hpp>

#include <cstddef>
#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

namespace clvr {

// An item's box of pixel centres (x0, y0)-(x1, y1), inclusive; empty when x0 > x1 or y0 > y1. Uploaded as short4.
struct PixelBox {
    std::int16_t x0, y0, x1, y1;
};

// Images the tile kernels take: at most this many pixels a side (PixelBox holds them).
inline constexpr int kTileImageMax = 16384;

// Per tile (row-major, tilesX per row) the items whose box reaches it: tile t's items are items[start[t] ..
// start[t + 1]).
struct TileLists {
    int tilesX = 0, tilesY = 0;
    std::vector<cl_uint> start, items;
};

// The items of `order` binned to tiles of tileW x tileH pixels (powers of two) by boxes[item], each tile's in
// `order`'s order: a stable counting sort by chunks of the order on the host's threads (each chunk counts its items'
// tiles, the counts become each chunk's offsets within each tile, each chunk writes its items). InputError
// "<what>: the tile lists have more than 2^32 entries; <remedy>" where they would.
TileLists binToTiles(const std::vector<PixelBox>& boxes, const std::vector<std::uint32_t>& order, int width, int height,
                     int tileW, int tileH, const std::string& what, const std::string& remedy);

class Device;

// A read-only device buffer for per-frame uploads (boxes, tile lists), grown as needed (to at least twice its size,
// so that a frame rarely reallocates); `resident` keeps the renderer's count of device bytes.
class StagingBuffer {
public:
    void write(Device& device, std::string_view what, const void* data, std::size_t bytes, std::uint64_t& resident);
    const cl::Buffer& buffer() const { return buffer_; }

private:
    cl::Buffer buffer_;
    std::size_t bytes_ = 0;
};

}  // namespace clvr
