// host/render/tile_lists.cpp — binning items to tiles in order (tile_lists.h).
#include "host/render/tile_lists.h"

#include <algorithm>

#include "host/runtime/device.h"
#include "host/runtime/errors.h"
#include "host/runtime/parallel.h"

namespace clvr {

TileLists binToTiles(const std::vector<PixelBox>& boxes, const std::vector<std::uint32_t>& order, int width, int height,
                     int tileW, int tileH, const std::string& what, const std::string& remedy)
{
    // the tile sizes as shifts (a division per box and pass cost more than the rest of the loop)
    int tileWLog2 = 0, tileHLog2 = 0;
    while ((1 << tileWLog2) < tileW)
        ++tileWLog2;
    while ((1 << tileHLog2) < tileH)
        ++tileHLog2;
    if ((1 << tileWLog2) != tileW || (1 << tileHLog2) != tileH)
        throw InternalError("binToTiles: tile sizes must be powers of two, got " + std::to_string(tileW) + "x" +
                            std::to_string(tileH));
    TileLists lists;
    lists.tilesX = (width + tileW - 1) / tileW;
    lists.tilesY = (height + tileH - 1) / tileH;
    const std::size_t tiles = static_cast<std::size_t>(lists.tilesX) * lists.tilesY;
    // One chunk per thread (at least 16,384 items each): the per-chunk counts and their prefix stay small.
    const int threads = threadsToUse(0, static_cast<int>(order.size() / 16384 + 1));
    const std::size_t chunk = std::max<std::size_t>(16384, (order.size() + threads - 1) / threads);
    const std::size_t chunks = (order.size() + chunk - 1) / chunk;
    // chunk c's count, then its first entry, in tile t: offset[c * tiles + t]
    std::vector<cl_uint> offset(chunks * tiles, 0);
    const std::size_t tilesX = static_cast<std::size_t>(lists.tilesX);
    // visit(i, tile) for each tile of each item of order[begin, end)
    auto overItems = [&](std::size_t begin, std::size_t end, const auto& visit) {
        for (std::size_t i = begin; i < end; ++i) {
            const PixelBox b = boxes[order[i]];
            if (b.x0 > b.x1 || b.y0 > b.y1)
                continue;
            for (int ty = b.y0 >> tileHLog2; ty <= b.y1 >> tileHLog2; ++ty)
                for (int tx = b.x0 >> tileWLog2; tx <= b.x1 >> tileWLog2; ++tx)
                    visit(i, static_cast<std::size_t>(ty) * tilesX + static_cast<std::size_t>(tx));
        }
    };
    auto overChunks = [&](const auto& work) { forHostChunks(threads, order.size(), work, chunk); };
    overChunks([&](std::size_t begin, std::size_t end) {
        cl_uint* count = offset.data() + begin / chunk * tiles;
        overItems(begin, end, [&](std::size_t, std::size_t tile) { ++count[tile]; });
    });
    lists.start.resize(tiles + 1);
    std::uint64_t entries = 0;
    for (std::size_t t = 0; t < tiles; ++t) {
        lists.start[t] = static_cast<cl_uint>(entries);
        for (std::size_t c = 0; c < chunks; ++c) {
            const cl_uint n = offset[c * tiles + t];
            offset[c * tiles + t] = static_cast<cl_uint>(entries);
            entries += n;
        }
    }
    if (entries > 0xffffffffu)
        throw InputError(what + ": the tile lists have more than 2^32 entries; " + remedy);
    lists.start[tiles] = static_cast<cl_uint>(entries);
    lists.items.resize(entries);
    cl_uint* items = lists.items.data();
    overChunks([&](std::size_t begin, std::size_t end) {
        cl_uint* next = offset.data() + begin / chunk * tiles;
        overItems(begin, end, [&](std::size_t i, std::size_t tile) { items[next[tile]++] = order[i]; });
    });
    return lists;
}

void StagingBuffer::write(Device& device, std::string_view what, const void* data, std::size_t bytes,
                          std::uint64_t& resident)
{
    const std::size_t need = std::max<std::size_t>(bytes, 16);
    if (!buffer_() || bytes_ < need) {
        resident -= bytes_;
        bytes_ = std::max(need, 2 * bytes_);
        buffer_ = device.buffer(what, bytes_, CL_MEM_READ_ONLY);
        resident += bytes_;
    }
    if (bytes > 0)
        device.queue().enqueueWriteBuffer(buffer_, CL_TRUE, 0, bytes, data);
}

}  // namespace clvr
