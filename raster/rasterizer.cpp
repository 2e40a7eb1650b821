// raster/rasterizer.cpp — primitive assembly, clipping, set-up and tile binning on the host (in
// double precision, then snapped to the subpixel grid), and the ordered fragment launches: one per pass
// (a run of draws with the same program and state), from buffers that persist in the Rasterizer.
// A triangle is binned as soon as it is set up, while its record is in cache; a submission then only
// sorts the (tile, triangle) pairs into tile lists.
#include "raster/rasterizer.h"

#include "host/runtime/errors.h"
#include "host/runtime/parallel.h"

#include <algorithm>
#include <atomic>
#include <bit>
#include <cmath>
#include <cstddef>
#include <cstring>
#include <limits>

namespace clvr::raster {

static_assert(sizeof(ClTriangle) == 96, "also probed on the device by tests/layout_test.cpp");
static_assert(sizeof(ClTriangle) == CLVR_TRIANGLE_FLOAT4S(0) * sizeof(cl_float4));
static_assert(offsetof(ClTriangle, depth) == 64);
static_assert(sizeof(ClRasterPass) == 176 && offsetof(ClRasterPass, fragment) == 64);

namespace {

struct ClipVertex {
    glm::dvec4 position;
    std::array<glm::dvec4, kMaxAttributes> attributes;
};

// Sutherland–Hodgman against one plane (keep dot(plane, position) >= 0). An intersection is always
// interpolated from the inside vertex towards the outside one, so that an edge shared by two
// triangles is cut at the same point whichever way each triangle runs along it.
void clipPolygon(std::vector<ClipVertex>& polygon, const glm::dvec4& plane, std::vector<ClipVertex>& scratch)
{
    scratch.clear();
    const std::size_t n = polygon.size();
    for (std::size_t i = 0; i < n; ++i) {
        const ClipVertex& a = polygon[i];
        const ClipVertex& b = polygon[(i + 1) % n];
        const double da = glm::dot(plane, a.position);
        const double db = glm::dot(plane, b.position);
        if (da >= 0.0)
            scratch.push_back(a);
        if ((da >= 0.0) != (db >= 0.0)) {
            const ClipVertex& in = da >= 0.0 ? a : b;
            const ClipVertex& out = da >= 0.0 ? b : a;
            const double dIn = da >= 0.0 ? da : db;
            const double dOut = da >= 0.0 ? db : da;
            const double t = dIn / (dIn - dOut);
            ClipVertex v;
            v.position = in.position + t * (out.position - in.position);
            for (int k = 0; k < kMaxAttributes; ++k)
                v.attributes[k] = in.attributes[k] + t * (out.attributes[k] - in.attributes[k]);
            scratch.push_back(v);
        }
    }
    polygon.swap(scratch);
}

struct Rect {
    int x = 0, y = 0, width = 0, height = 0;
};

struct ResolvedViewport {
    double x, y, width, height, nearZ, farZ;
    Rect scissor;  // viewport ∩ frame buffer
};

ResolvedViewport resolveViewport(const Viewport& v, int fbWidth, int fbHeight)
{
    const int w = v.width < 0 ? fbWidth : v.width;
    const int h = v.height < 0 ? fbHeight : v.height;
    if (w == 0 || h == 0)
        throw InternalError("viewport of size " + std::to_string(w) + "x" + std::to_string(h) + " is empty");
    ResolvedViewport r{double(v.x), double(v.y), double(w), double(h),
                       std::clamp(double(v.nearZ), 0.0, 1.0), std::clamp(double(v.farZ), 0.0, 1.0), {}};
    const int x0 = std::max(v.x, 0), y0 = std::max(v.y, 0);
    const int x1 = std::min(v.x + w, fbWidth), y1 = std::min(v.y + h, fbHeight);
    r.scissor = {x0, y0, std::max(0, x1 - x0), std::max(0, y1 - y0)};
    return r;
}

// The clip planes in the order they are applied: near, far, the user's, then the x/y guard band.
std::vector<glm::dvec4> clipPlanes(const DrawState& state, const ResolvedViewport& vp)
{
    std::vector<glm::dvec4> planes{{0.0, 0.0, 1.0, 1.0}, {0.0, 0.0, -1.0, 1.0}};
    for (const glm::vec4& p : state.clipPlanes)
        planes.emplace_back(p);
    const double gx = 1.0 + 2.0 * kGuardBandPixels / vp.width;
    const double gy = 1.0 + 2.0 * kGuardBandPixels / vp.height;
    planes.insert(planes.end(), {{-1.0, 0.0, 0.0, gx}, {1.0, 0.0, 0.0, gx}, {0.0, -1.0, 0.0, gy}, {0.0, 1.0, 0.0, gy}});
    return planes;
}

struct WindowVertex {
    std::int64_t x, y;  // subpixel units, row-down
    double depth, invW;
    std::array<glm::dvec4, kMaxAttributes> attrOverW;  // the first `attributes` are set
};

std::int64_t cross(const WindowVertex& a, const WindowVertex& b, const WindowVertex& c)
{
    return (b.x - a.x) * (c.y - a.y) - (b.y - a.y) * (c.x - a.x);
}

float f(double v) { return static_cast<float>(v); }

// floor(v) as an integer, for |v| < 2^62: the same value as static_cast<int64_t>(std::floor(v)) without
// the libm call (x86-64's baseline has no rounding instruction).
std::int64_t floorToInt(double v)
{
    const auto i = static_cast<std::int64_t>(v);  // truncates towards zero
    return static_cast<double>(i) > v ? i - 1 : i;
}

// Perspective divide, viewport transform (clip +y to the top row), snap to the subpixel grid.
// False for a vertex at w <= 0.
bool toWindow(const glm::dvec4& position, const std::array<glm::dvec4, kMaxAttributes>& attributes, int count,
              const ResolvedViewport& vp, WindowVertex& wv)
{
    const double w = position.w;
    if (!(w > 0.0))
        return false;
    const glm::dvec3 ndc = glm::dvec3(position) / w;
    wv.x = floorToInt((vp.x + (ndc.x + 1.0) * 0.5 * vp.width) * CLVR_SUBPIXEL_SCALE + 0.5);
    wv.y = floorToInt((vp.y + (1.0 - ndc.y) * 0.5 * vp.height) * CLVR_SUBPIXEL_SCALE + 0.5);
    wv.depth = vp.nearZ + (ndc.z + 1.0) * 0.5 * (vp.farZ - vp.nearZ);
    wv.invW = 1.0 / w;
    for (int k = 0; k < count; ++k)
        wv.attrOverW[k] = attributes[k] * wv.invW;
    return true;
}

// ceil(a / 256) and floor(a / 256) at the subpixel scale, exact for every int64 (arithmetic shifts).
static_assert(CLVR_SUBPIXEL_SCALE == 1 << CLVR_SUBPIXEL_BITS);
std::int64_t floorSubpixel(std::int64_t a) { return a >> CLVR_SUBPIXEL_BITS; }
std::int64_t ceilSubpixel(std::int64_t a) { return -((-a) >> CLVR_SUBPIXEL_BITS); }

bool powerOfTwoUpTo(int v, int max) { return v >= 1 && v <= max && (v & (v - 1)) == 0; }

int log2Of(int powerOfTwo) { return std::countr_zero(static_cast<unsigned>(powerOfTwo)); }

// The tiles of a pass: shape.tileW x shape.tileH pixels from the rectangle's corner.
struct TileGrid {
    Rect rect;
    int tileW = CLVR_TILE_SIZE, tileH = CLVR_TILE_SIZE;
    int tilesX() const { return (rect.width + tileW - 1) / tileW; }
    int tilesY() const { return (rect.height + tileH - 1) / tileH; }
};

// A tile is skipped when one edge function (with its fill-rule bias) is negative at all four corner
// pixel centers of the tile's part of the rectangle: exact, so no covered center is lost.
bool touches(const ClTriangle& t, const TileGrid& grid, int tx, int ty)
{
    const Rect& rect = grid.rect;
    const std::int64_t x0 = rect.x + tx * grid.tileW, y0 = rect.y + ty * grid.tileH;
    const std::int64_t x1 = std::min<std::int64_t>(x0 + grid.tileW, rect.x + rect.width) - 1;
    const std::int64_t y1 = std::min<std::int64_t>(y0 + grid.tileH, rect.y + rect.height) - 1;
    const std::int64_t half = CLVR_SUBPIXEL_SCALE / 2;
    const std::int64_t cx[2] = {x0 * CLVR_SUBPIXEL_SCALE + half, x1 * CLVR_SUBPIXEL_SCALE + half};
    const std::int64_t cy[2] = {y0 * CLVR_SUBPIXEL_SCALE + half, y1 * CLVR_SUBPIXEL_SCALE + half};
    for (int j = 0; j < 3; ++j) {
        const std::int64_t xa = t.x[j], ya = t.y[j], xb = t.x[(j + 1) % 3], yb = t.y[(j + 1) % 3];
        bool outside = true;
        for (std::int64_t px : cx)
            for (std::int64_t py : cy)
                outside = outside && (xb - xa) * (py - ya) - (yb - ya) * (px - xa) + t.bias[j] < 0;
        if (outside)
            return false;
    }
    return true;
}

bool sameBytes(const auto& a, const auto& b) { return std::memcmp(&a, &b, sizeof a) == 0; }

cl_float4 toCl4(const glm::vec4& v) { return cl_float4{{v.x, v.y, v.z, v.w}}; }
cl_float4 toCl4(const glm::dvec4& v) { return cl_float4{{f(v.x), f(v.y), f(v.z), f(v.w)}}; }

// Grows `buffer` to hold `bytes` (capacity at least doubles, so n draws cost O(log n) allocations).
void reserve(Device& device, std::string_view what, cl::Buffer& buffer, std::size_t& capacity, std::size_t bytes,
             cl_mem_flags flags)
{
    if (buffer() && bytes <= capacity)
        return;
    capacity = std::max({bytes, 2 * capacity, std::size_t{4096}});
    buffer = device.buffer(what, capacity, flags);
}

// Triangles of a list, strip or fan of vertexCount vertices; InternalError for an unknown topology.
std::uint32_t triangleCount(Topology topology, std::size_t vertexCount)
{
    const auto n = static_cast<std::uint32_t>(vertexCount);
    switch (topology) {
    case Topology::Triangles: return n / 3;
    case Topology::TriangleStrip:
    case Topology::TriangleFan: return n >= 3 ? n - 2 : 0;
    }
    throw InternalError("assembleTriangles: topology " + std::to_string(static_cast<int>(topology)) + " is unknown");
}

// Vertex indices of triangle i of a list, strip or fan (assembleTriangles, without the array); the
// topology is one that triangleCount accepted.
inline std::array<std::uint32_t, 3> triangleIndices(Topology topology, std::uint32_t i)
{
    if (topology == Topology::Triangles)
        return {3 * i, 3 * i + 1, 3 * i + 2};
    if (topology == Topology::TriangleFan)
        return {0, i + 1, i + 2};
    return i % 2 == 0 ? std::array<std::uint32_t, 3>{i, i + 1, i + 2} : std::array<std::uint32_t, 3>{i + 1, i, i + 2};
}

constexpr std::size_t kMaxRows = 16384;  // Framebuffer's largest height: one fragment counter per item row
// A draw of at least twice this many triangles is set up in chunks of it on the host's threads (setUpDraw).
constexpr std::size_t kSetUpChunk = 16384;

}  // namespace

// The raster kernel built for one fragment program source on one context.
struct CompiledFragmentProgram {
    cl_context context = nullptr;
    std::size_t sourceSize = 0;
    int attributes = 0;
    int itemPixels = 0;
    cl::Kernel kernel;  // set per launch; only one thread uses a Rasterizer (rasterizer.h)
};

// One fragment launch: consecutive draws that share everything but geometry and scissor.
struct Pass {
    cl::Kernel kernel;
    std::array<cl::Buffer, 4> buffers;
    ClFragmentState fragment;
    ClBlendState blend;
    TileGrid grid;                  // its rect is the viewport rectangle: the launch's extent and its tiles' origin
    std::size_t uniformBase = 0;    // first uniform in SetUpDraws::uniforms
    std::size_t uniformCount = 0;
    std::size_t triangleBase = 0;   // float4 offset of its first triangle in SetUpDraws::triangles
    std::size_t triangles = 0;
    std::size_t tileBase = 0;       // its first tile in SetUpDraws::tileCounts
};

struct SetUpDraws {
    int fbWidth = 0, fbHeight = 0;
    RasterShape shape;
    std::vector<cl_float4> triangles;                 // set-up records, in submission order
    std::vector<cl_uint> tileCounts;                  // entries per tile, the tiles of every pass in turn
    std::vector<std::array<cl_uint, 2>> pairs;        // (tile, triangle of its pass), in submission order
    std::vector<Pass> passes;
    std::vector<cl_float4> uniforms;
    std::uint64_t setUp = 0;            // DrawStats::triangles: also those whose pixel box is empty
    std::size_t draws = 0;
    std::vector<ClipVertex> polygon, scratch;
    // A large draw's triangles set up in chunks on the host's threads (setUpDraw), each into its own arrays,
    // kept with their capacity between draws.
    struct Chunk {
        std::vector<cl_float4> triangles;
        std::vector<std::array<cl_uint, 2>> pairs;  // (tile, triangle of the chunk)
        std::vector<cl_uint> tileCounts;            // the pass's tiles
        std::vector<ClipVertex> polygon, scratch;
        std::size_t count = 0;                      // triangles set up with a nonempty pixel box
        std::uint64_t setUp = 0;
    };
    std::vector<Chunk> chunks;

    void clear()
    {
        triangles.clear();
        tileCounts.clear();
        pairs.clear();
        passes.clear();
        uniforms.clear();
        setUp = 0;
        draws = 0;
    }
};

// Everything a Rasterizer keeps between draws. Host staging is uploaded without blocking, so it is
// only refilled after the uploads that read it have completed (uploadsDone).
struct RasterScratch {
    cl::Buffer triangles, tileStarts, tileTris, uniforms, fragmentCounts, dummy;
    std::size_t triangleBytes = 0, tileStartBytes = 0, tileTrisBytes = 0, uniformBytes = 0;
    std::vector<cl_float4> stagedTriangles;
    std::vector<cl_uint> stagedTileStarts, stagedTileTris;
    std::vector<cl_float4> stagedUniforms;
    std::vector<cl::Event> uploads;
    std::size_t maxUniforms = 0;  // the device's constant buffer size in float4s
    std::uint64_t setUp = 0;       // DrawStats::triangles since the last takeStats()
    std::size_t rowsCounted = 0;   // fragmentCounts rows launched over since the last takeStats()

    void uploadsDone()
    {
        if (!uploads.empty())
            cl::Event::waitForEvents(uploads);
        uploads.clear();
    }
};

namespace {

// Hands the (empty) host arrays of `from`, with their capacity, to `to`: a DrawBatch borrows the
// Rasterizer's, so that a batch per frame does not grow its arrays from nothing (and fault in fresh
// pages) every frame. Only capacity moves; pending draws are never lost.
void lendCapacity(SetUpDraws& from, SetUpDraws& to)
{
    const auto lend = [](auto& a, auto& b) {
        if (!a.empty())
            return;
        b.clear();
        if (b.capacity() < a.capacity())
            b.swap(a);
    };
    lend(from.triangles, to.triangles);
    lend(from.pairs, to.pairs);
}

// Where set-up triangles go: records appended to `triangles`, (tile, index) pairs to `pairs` (index counted
// from `index` on), the pass's tile counts, the triangles set up (DrawStats::triangles) in setUp.
struct TriangleSink {
    std::vector<cl_float4>& triangles;
    std::vector<std::array<cl_uint, 2>>& pairs;
    cl_uint* tileCounts;  // the pass's tiles, tile (tx, ty) at ty * tilesX + tx
    std::size_t index;
    std::uint64_t setUp;
    std::vector<ClipVertex>& polygon;  // clipping scratch
    std::vector<ClipVertex>& scratch;
};

// One draw's triangles [first, last) set up and binned into a sink (docs/raster.md, steps 1-6): clipped against
// the planes, snapped to the subpixel grid, culled, and binned to every tile of the pass they can cover.
struct TriangleSetUp {
    Topology topology;
    const std::vector<Vertex>& vertices;
    const std::vector<glm::dvec4>& planes;
    const ResolvedViewport& vp;
    const Rect& rect;  // the pass's (the viewport's) rectangle
    const Rect& clip;  // the scissored rectangle
    const FragmentState& fs;
    int attributes;
    const TileGrid& grid;
    std::size_t tileBase;  // the pass's first tile

    void run(std::uint32_t first, std::uint32_t last, TriangleSink& sink) const
    {
        const int tilesX = grid.tilesX();
        const int tileWLog2 = log2Of(grid.tileW), tileHLog2 = log2Of(grid.tileH);
        const std::size_t stride = CLVR_TRIANGLE_FLOAT4S(attributes);
        std::vector<ClipVertex>& polygon = sink.polygon;
        std::vector<ClipVertex>& scratch = sink.scratch;
        // The clipped polygon in window coordinates: each of the planes (near, far, the user's, four guard
        // band planes) adds at most one vertex to a convex polygon.
        std::array<WindowVertex, 3 + 2 + kMaxClipPlanes + 4> window;
        std::size_t windowSize = 0;
        for (std::uint32_t triangle = first; triangle < last; ++triangle) {
            const std::array<std::uint32_t, 3> indices = triangleIndices(topology, triangle);
            bool inside = true;
            glm::dvec4 position[3];
            for (int j = 0; j < 3; ++j) {
                position[j] = glm::dvec4(vertices[indices[j]].position);
                for (const glm::dvec4& p : planes)
                    inside = inside && glm::dot(p, position[j]) >= 0.0;
            }
            windowSize = 0;
            bool finite = true;
            const auto project = [&](const glm::dvec4& pos, const std::array<glm::dvec4, kMaxAttributes>& attrs) {
                finite = finite && toWindow(pos, attrs, attributes, vp, window[windowSize++]);
            };
            std::array<glm::dvec4, kMaxAttributes> attrs;
            if (inside) {  // the common case: no clipping, straight from the vertices
                for (int j = 0; j < 3 && finite; ++j) {
                    for (int k = 0; k < attributes; ++k)
                        attrs[k] = glm::dvec4(vertices[indices[j]].attributes[k]);
                    project(position[j], attrs);
                }
            } else {
                polygon.clear();
                for (int j = 0; j < 3; ++j) {
                    ClipVertex v{position[j], {}};
                    for (int k = 0; k < kMaxAttributes; ++k)
                        v.attributes[k] = glm::dvec4(vertices[indices[j]].attributes[k]);
                    polygon.push_back(v);
                }
                for (const glm::dvec4& p : planes) {
                    clipPolygon(polygon, p, scratch);
                    if (polygon.size() < 3)
                        break;
                }
                if (polygon.size() < 3)
                    continue;
                for (const ClipVertex& v : polygon) {
                    project(v.position, v.attributes);
                    if (!finite)
                        break;
                }
            }
            if (!finite)
                continue;

            // Facing from the polygon's signed area. cross() > 0 is clockwise on the row-down screen,
            // so counter-clockwise as GL sees it (y up) is cross() < 0.
            std::int64_t area2 = 0;
            for (std::size_t i = 1; i + 1 < windowSize; ++i)
                area2 += cross(window[0], window[i], window[i + 1]);
            if (area2 == 0)
                continue;
            const bool front = fs.frontFaceCCW ? area2 < 0 : area2 > 0;
            if (fs.cull == CullFace::FrontAndBack || (fs.cull == CullFace::Front && front) ||
                (fs.cull == CullFace::Back && !front))
                continue;

            for (std::size_t i = 1; i + 1 < windowSize; ++i) {
                const WindowVertex* v[3] = {&window[0], &window[i], &window[i + 1]};
                const std::int64_t a2 = cross(*v[0], *v[1], *v[2]);
                // A fan triangle whose snapped orientation disagrees with the polygon's is a snapping
                // sliver of zero true area: drop it with the zero-area ones.
                if (a2 == 0 || (a2 > 0) != (area2 > 0))
                    continue;
                if (a2 < 0)
                    std::swap(v[1], v[2]);
                ++sink.setUp;

                // Pixels whose centers (x + 0.5) can be inside, clipped to the scissored viewport rectangle.
                const std::int64_t minX = std::min({v[0]->x, v[1]->x, v[2]->x}), maxX = std::max({v[0]->x, v[1]->x, v[2]->x});
                const std::int64_t minY = std::min({v[0]->y, v[1]->y, v[2]->y}), maxY = std::max({v[0]->y, v[1]->y, v[2]->y});
                const std::int64_t half = CLVR_SUBPIXEL_SCALE / 2;
                const int px0 = static_cast<int>(std::max<std::int64_t>(clip.x, ceilSubpixel(minX - half)));
                const int px1 = static_cast<int>(std::min<std::int64_t>(clip.x + clip.width - 1, floorSubpixel(maxX - half)));
                const int py0 = static_cast<int>(std::max<std::int64_t>(clip.y, ceilSubpixel(minY - half)));
                const int py1 = static_cast<int>(std::min<std::int64_t>(clip.y + clip.height - 1, floorSubpixel(maxY - half)));
                if (px0 > px1 || py0 > py1)
                    continue;

                ClTriangle t{};
                for (int j = 0; j < 3; ++j) {
                    const WindowVertex& a = *v[j];
                    const WindowVertex& b = *v[(j + 1) % 3];
                    t.x[j] = static_cast<cl_int>(a.x);
                    t.y[j] = static_cast<cl_int>(a.y);
                    const std::int64_t dx = b.x - a.x, dy = b.y - a.y;
                    // Top-left rule (row-down, edge functions positive inside): a left edge runs up, a
                    // top edge runs exactly horizontal to the right.
                    t.bias[j] = (dy < 0 || (dy == 0 && dx > 0)) ? 0 : -1;
                }
                t.front_facing = front ? 1u : 0u;
                t.inv_area = f(1.0 / static_cast<double>(std::llabs(a2)));
                t.col_min = px0;
                t.col_max = px1;
                t.row_min = py0;
                t.row_max = py1;
                t.depth = cl_float4{{f(v[0]->depth), f(v[1]->depth), f(v[2]->depth), 0.0f}};
                t.inv_w = cl_float4{{f(v[0]->invW), f(v[1]->invW), f(v[2]->invW), 0.0f}};
                std::array<cl_float4, CLVR_TRIANGLE_FLOAT4S(kMaxAttributes)> record;
                std::memcpy(record.data(), &t, sizeof t);
                for (int k = 0; k < attributes; ++k)
                    for (int j = 0; j < 3; ++j)
                        record[CLVR_TRIANGLE_FLOAT4S(k) + j] = toCl4(v[j]->attrOverW[k]);
                sink.triangles.insert(sink.triangles.end(), record.begin(), record.begin() + static_cast<std::ptrdiff_t>(stride));

                // Binned now, while the record is in cache: every tile of its pixel box that it can cover.
                const auto index = static_cast<cl_uint>(sink.index++);
                const int tx0 = (px0 - rect.x) >> tileWLog2, tx1 = (px1 - rect.x) >> tileWLog2;
                const int ty0 = (py0 - rect.y) >> tileHLog2, ty1 = (py1 - rect.y) >> tileHLog2;
                // One tile holds every center the triangle can cover: the corner test could only drop it.
                const bool single = tx0 == tx1 && ty0 == ty1;
                for (int ty = ty0; ty <= ty1; ++ty)
                    for (int tx = tx0; tx <= tx1; ++tx)
                        if (single || touches(t, grid, tx, ty)) {
                            const std::size_t local = static_cast<std::size_t>(ty) * tilesX + tx;
                            ++sink.tileCounts[local];
                            sink.pairs.push_back({static_cast<cl_uint>(tileBase + local), index});
                        }
            }
        }
    }
};

// Sets up and bins one draw into `out` (docs/raster.md, steps 1-6), extending its last pass when the draw
// shares that pass's program, buffers, uniforms, rectangle and fragment state.
void setUpDraw(SetUpDraws& out, const DrawState& state, Topology topology, const std::vector<Vertex>& vertices,
               const cl::Kernel& kernel, const FragmentProgram& program, int attributes)
{
    if (state.clipPlanes.size() > static_cast<std::size_t>(kMaxClipPlanes))
        throw InternalError("draw: " + std::to_string(state.clipPlanes.size()) + " clip planes, at most " +
                            std::to_string(kMaxClipPlanes));
    if (program.uniforms.size() > static_cast<std::size_t>(kMaxUniforms))
        throw InternalError("draw: " + std::to_string(program.uniforms.size()) +
                            " fragment program uniforms, at most " + std::to_string(kMaxUniforms));
    const ResolvedViewport vp = resolveViewport(state.viewport, out.fbWidth, out.fbHeight);
    const Rect rect = vp.scissor;
    // GL's scissor test: the launch and the tiles stay those of the viewport rectangle (one launch shape for
    // every scissor, so PoCL builds no new work-group variant per rectangle); triangles are binned only
    // within `clip`, and their pixel bounds keep the kernel inside it.
    Rect clip = rect;
    if (state.scissor.test) {
        const Scissor& sc = state.scissor;
        if (sc.width < 0 || sc.height < 0)
            throw InternalError("draw: scissor of size " + std::to_string(sc.width) + "x" +
                                std::to_string(sc.height));
        const int x0 = std::max(rect.x, sc.x), y0 = std::max(rect.y, sc.y);
        const int x1 = std::min(rect.x + rect.width, sc.x + sc.width), y1 = std::min(rect.y + rect.height, sc.y + sc.height);
        clip = {x0, y0, std::max(0, x1 - x0), std::max(0, y1 - y0)};
    }
    const std::vector<glm::dvec4> planes = clipPlanes(state, vp);
    const FragmentState& fs = state.fragment;
    ++out.draws;

    // The pass this draw joins.
    const ClFragmentState clFragment = toCl(fs);
    const ClBlendState clBlend = toCl(fs.blend);
    std::array<cl_float4, kMaxUniforms> uniforms{};
    const std::size_t uniformCount = std::max<std::size_t>(program.uniforms.size(), 1);
    for (std::size_t i = 0; i < program.uniforms.size(); ++i)
        uniforms[i] = toCl4(program.uniforms[i]);
    const auto sameBuffers = [&](const Pass& p) {
        for (std::size_t i = 0; i < p.buffers.size(); ++i)
            if (p.buffers[i]() != program.buffers[i]())
                return false;
        return true;
    };
    const auto sameUniforms = [&](const Pass& p) {
        return p.uniformCount == uniformCount &&
               std::memcmp(out.uniforms.data() + p.uniformBase, uniforms.data(), uniformCount * sizeof(cl_float4)) == 0;
    };
    if (out.passes.empty() || out.passes.back().kernel() != kernel() || !sameBuffers(out.passes.back()) ||
        !sameBytes(out.passes.back().fragment, clFragment) || !sameBytes(out.passes.back().blend, clBlend) ||
        !sameBytes(out.passes.back().grid.rect, rect) || !sameUniforms(out.passes.back())) {
        Pass p{kernel, program.buffers, clFragment, clBlend, TileGrid{rect, out.shape.tileW, out.shape.tileH},
               out.uniforms.size(), uniformCount, out.triangles.size(), 0, out.tileCounts.size()};
        out.uniforms.insert(out.uniforms.end(), uniforms.begin(), uniforms.begin() + static_cast<std::ptrdiff_t>(uniformCount));
        out.tileCounts.resize(out.tileCounts.size() + static_cast<std::size_t>(p.grid.tilesX()) * p.grid.tilesY(), 0);
        out.passes.push_back(std::move(p));
    }
    Pass& pass = out.passes.back();
    const TileGrid& grid = pass.grid;

    const TriangleSetUp setUpTriangles{topology, vertices, planes, vp, rect, clip, fs, attributes, grid, pass.tileBase};
    const std::uint32_t count = triangleCount(topology, vertices.size());
    const int threads = count >= 2 * kSetUpChunk ? threadsToUse(0, static_cast<int>(count / kSetUpChunk)) : 1;
    if (threads == 1) {  // into `out` directly
        TriangleSink sink{out.triangles, out.pairs, out.tileCounts.data() + pass.tileBase, pass.triangles, 0,
                          out.polygon, out.scratch};
        setUpTriangles.run(0, count, sink);
        pass.triangles = sink.index;
        out.setUp += sink.setUp;
        return;
    }
    // In chunks of kSetUpChunk triangles on the host's threads, each into its own arrays; then joined in
    // submission order, the chunks' triangle indices moved past the triangles before them: the arrays a single
    // thread makes.
    const std::size_t chunkCount = (count + kSetUpChunk - 1) / kSetUpChunk;
    const std::size_t tiles = static_cast<std::size_t>(grid.tilesX()) * grid.tilesY();
    if (out.chunks.size() < chunkCount)
        out.chunks.resize(chunkCount);
    std::atomic<std::size_t> next{0};
    runOnThreads(threads, threads, [&] {
        for (std::size_t c; (c = next.fetch_add(1)) < chunkCount;) {
            SetUpDraws::Chunk& chunk = out.chunks[c];
            chunk.triangles.clear();
            chunk.pairs.clear();
            chunk.tileCounts.assign(tiles, 0);
            TriangleSink sink{chunk.triangles, chunk.pairs, chunk.tileCounts.data(), 0, 0, chunk.polygon, chunk.scratch};
            const auto first = static_cast<std::uint32_t>(c * kSetUpChunk);
            setUpTriangles.run(first, static_cast<std::uint32_t>(std::min<std::size_t>(first + kSetUpChunk, count)), sink);
            chunk.count = sink.index;
            chunk.setUp = sink.setUp;
        }
    });
    std::size_t records = out.triangles.size(), pairs = out.pairs.size();
    for (std::size_t c = 0; c < chunkCount; ++c) {
        records += out.chunks[c].triangles.size();
        pairs += out.chunks[c].pairs.size();
    }
    out.triangles.reserve(records);
    out.pairs.reserve(pairs);
    cl_uint* tileCounts = out.tileCounts.data() + pass.tileBase;
    for (std::size_t c = 0; c < chunkCount; ++c) {
        const SetUpDraws::Chunk& chunk = out.chunks[c];
        out.triangles.insert(out.triangles.end(), chunk.triangles.begin(), chunk.triangles.end());
        const auto base = static_cast<cl_uint>(pass.triangles);
        for (const std::array<cl_uint, 2>& p : chunk.pairs)
            out.pairs.push_back({p[0], p[1] + base});
        for (std::size_t t = 0; t < tiles; ++t)
            tileCounts[t] += chunk.tileCounts[t];
        pass.triangles += chunk.count;
        out.setUp += chunk.setUp;
    }
}

}  // namespace

std::vector<std::array<std::uint32_t, 3>> assembleTriangles(Topology topology, std::size_t vertexCount)
{
    std::vector<std::array<std::uint32_t, 3>> out;
    const std::uint32_t count = triangleCount(topology, vertexCount);
    out.reserve(count);
    for (std::uint32_t i = 0; i < count; ++i)
        out.push_back(triangleIndices(topology, i));
    return out;
}

glm::vec4 clipPlaneFromWorld(const glm::vec4& worldPlane, const glm::mat4& viewProjection)
{
    const glm::dmat4 m = glm::transpose(glm::inverse(glm::dmat4(viewProjection)));
    return glm::vec4(m * glm::dvec4(worldPlane));
}

RasterShape RasterShape::forDevice(Device& device)
{
    RasterShape shape;
    if (device.device().getInfo<CL_DEVICE_TYPE>() & CL_DEVICE_TYPE_GPU)
        shape.itemW = shape.itemH = 1;
    // A 1x1 item spends about 4 loop iterations on a triangle (list, row, pixel, row load); the rest of
    // the 32 leaves room for loops in fragment programs.
    if (const std::uint64_t cap = device.loopIterationCap()) {
        shape.itemW = shape.itemH = 1;
        shape.listChunk = static_cast<std::uint32_t>(std::max<std::uint64_t>(1, cap / 32));
    }
    return shape;
}

Rasterizer::Rasterizer(Device& device, RasterShape shape)
    : device_(device), shape_(shape), scratch_(std::make_unique<RasterScratch>()),
      immediate_(std::make_unique<SetUpDraws>())
{
    if (!powerOfTwoUpTo(shape.tileW, CLVR_TILE_SIZE) || !powerOfTwoUpTo(shape.tileH, CLVR_TILE_SIZE) ||
        !powerOfTwoUpTo(shape.itemW, shape.tileW) || !powerOfTwoUpTo(shape.itemH, shape.tileH))
        throw InternalError("raster shape: tiles " + std::to_string(shape.tileW) + "x" + std::to_string(shape.tileH) +
                            ", items " + std::to_string(shape.itemW) + "x" + std::to_string(shape.itemH) +
                            " (powers of two, items inside tiles, at most " + std::to_string(CLVR_TILE_SIZE) + ")");
    defaultProgram_.source = kDefaultFragmentProgram;
    defaultProgram_.attributes = 1;
    immediate_->shape = shape_;
    RasterScratch& s = *scratch_;
    s.maxUniforms = device.device().getInfo<CL_DEVICE_MAX_CONSTANT_BUFFER_SIZE>() / sizeof(cl_float4);
    s.fragmentCounts = device.buffer("raster fragment counts", kMaxRows * sizeof(cl_uint));
    device.queue().enqueueFillBuffer(s.fragmentCounts, cl_uint{0}, 0, kMaxRows * sizeof(cl_uint));
    s.dummy = device.buffer("fragment program dummy buffer", sizeof(cl_float4));
}

Rasterizer::~Rasterizer()
{
    try {  // the staged host arrays must outlive their uploads
        scratch_->uploadsDone();
    } catch (...) {
    }
}

const CompiledFragmentProgram& Rasterizer::compiled(const FragmentProgram& program)
{
    // The empty source is the default program; its memo lives in the Rasterizer (callers pass a temporary).
    const FragmentProgram& p = program.source.empty() ? defaultProgram_ : program;
    if (p.attributes < 0 || p.attributes > kMaxAttributes)
        throw InternalError("draw: a fragment program of " + std::to_string(p.attributes) + " attributes, at most " +
                            std::to_string(kMaxAttributes));
    const cl_context context = device_.context()();
    const int itemPixels = shape_.itemW * shape_.itemH;
    if (p.compiled && p.compiled->context == context && p.compiled->sourceSize == p.source.size() &&
        p.compiled->attributes == p.attributes && p.compiled->itemPixels == itemPixels)
        return *p.compiled;
    auto c = std::make_shared<CompiledFragmentProgram>();
    c->context = context;
    c->sourceSize = p.source.size();
    c->attributes = p.attributes;
    c->itemPixels = itemPixels;
    c->kernel = device_.kernel("raster.cl", "raster_fragments", p.source,
                               "-DCLVR_ATTRIBUTES=" + std::to_string(p.attributes) +
                                   " -DCLVR_ITEM_PIXELS=" + std::to_string(itemPixels));
    p.compiled = c;
    return *c;
}

void Rasterizer::draw(Framebuffer& fb, const DrawState& state, Topology topology, const std::vector<Vertex>& vertices,
                      const FragmentProgram& program)
{
    SetUpDraws& d = *immediate_;
    d.clear();
    d.fbWidth = fb.width();
    d.fbHeight = fb.height();
    const CompiledFragmentProgram& c = compiled(program);
    setUpDraw(d, state, topology, vertices, c.kernel, program, c.attributes);
    submit(fb, d);
}

void Rasterizer::submit(Framebuffer& fb, SetUpDraws& draws)
{
    if (draws.fbWidth != fb.width() || draws.fbHeight != fb.height())
        throw InternalError("raster: draws set up for " + std::to_string(draws.fbWidth) + "x" +
                            std::to_string(draws.fbHeight) + ", frame buffer is " + std::to_string(fb.width()) + "x" +
                            std::to_string(fb.height()));
    RasterScratch& s = *scratch_;
    s.setUp += draws.setUp;
    if (draws.pairs.empty()) {
        draws.clear();
        return;
    }
    s.uploadsDone();

    // Tile lists in submission order, a counting sort: the per-tile counts become starts (tile t's
    // entries are stagedTileTris[start[t] .. start[t + 1])), and the pairs, still in submission order,
    // are scattered into place.
    const std::size_t tiles = draws.tileCounts.size();
    s.stagedTileStarts.resize(tiles + 1);
    std::uint64_t entries = 0;
    for (std::size_t t = 0; t < tiles; ++t) {
        s.stagedTileStarts[t] = static_cast<cl_uint>(entries);
        entries += draws.tileCounts[t];
    }
    if (entries > std::numeric_limits<cl_uint>::max())
        throw InputError("draw: more than 2^32 triangle-tile pairs in one submission; split the draw");
    s.stagedTileStarts[tiles] = static_cast<cl_uint>(entries);
    s.stagedTileTris.resize(entries);
    std::vector<cl_uint>& cursor = draws.tileCounts;  // reused: the counts are not needed any more
    std::copy(s.stagedTileStarts.begin(), s.stagedTileStarts.end() - 1, cursor.begin());
    for (const auto& [tile, triangle] : draws.pairs)
        s.stagedTileTris[cursor[tile]++] = triangle;

    // This submission's triangles and uniforms become the staging; the caller refills the old staging.
    s.stagedTriangles.swap(draws.triangles);
    s.stagedUniforms.swap(draws.uniforms);

    const auto upload = [&](std::string_view what, cl::Buffer& buffer, std::size_t& capacity, const auto& data,
                            cl_mem_flags flags) {
        const std::size_t bytes = data.size() * sizeof(data[0]);
        reserve(device_, what, buffer, capacity, bytes, flags);
        if (bytes) {
            cl::Event e;
            device_.queue().enqueueWriteBuffer(buffer, CL_FALSE, 0, bytes, data.data(), nullptr, &e);
            s.uploads.push_back(e);
        }
    };
    upload("raster triangles", s.triangles, s.triangleBytes, s.stagedTriangles, CL_MEM_READ_ONLY);
    upload("raster tile starts", s.tileStarts, s.tileStartBytes, s.stagedTileStarts, CL_MEM_READ_ONLY);
    upload("raster tile lists", s.tileTris, s.tileTrisBytes, s.stagedTileTris, CL_MEM_READ_ONLY);
    upload("fragment program uniforms", s.uniforms, s.uniformBytes, s.stagedUniforms, CL_MEM_READ_ONLY);

    const std::size_t groupW = shape_.tileW / shape_.itemW, groupH = shape_.tileH / shape_.itemH;
    for (const Pass& pass : draws.passes) {
        const TileGrid& grid = pass.grid;
        const Rect& rect = grid.rect;
        if (pass.triangles == 0 || rect.width == 0 || rect.height == 0)
            continue;
        ClRasterPass p{};
        p.fb_width = fb.width();
        p.rect_x = rect.x;
        p.rect_y = rect.y;
        p.rect_w = rect.width;
        p.rect_h = rect.height;
        p.tile_w_log2 = log2Of(grid.tileW);
        p.tile_h_log2 = log2Of(grid.tileH);
        p.tiles_x = grid.tilesX();
        p.item_w_log2 = log2Of(shape_.itemW);
        p.item_h_log2 = log2Of(shape_.itemH);
        p.tile_base = static_cast<cl_uint>(pass.tileBase);
        p.uniform_base = static_cast<cl_uint>(pass.uniformBase);
        p.triangle_base = pass.triangleBase;
        p.fragment = pass.fragment;
        p.blend = pass.blend;
        cl::Kernel k = pass.kernel;
        int arg = 0;
        k.setArg(arg++, fb.color());
        k.setArg(arg++, fb.depth());
        k.setArg(arg++, fb.stencil());
        k.setArg(arg++, p);
        k.setArg(arg++, s.triangles);
        k.setArg(arg++, s.tileStarts);
        k.setArg(arg++, s.tileTris);
        k.setArg(arg++, s.uniforms);
        for (const cl::Buffer& b : pass.buffers)
            k.setArg(arg++, b() ? b : s.dummy);
        k.setArg(arg++, s.fragmentCounts);
        // A CPU runs one item per work-group: PoCL would otherwise keep the private pixels of every
        // work-item of a group in one stack array (its context arrays), far apart in memory.
        const std::size_t itemsX = (static_cast<std::size_t>(rect.width) + shape_.itemW - 1) / shape_.itemW;
        const std::size_t itemsY = (static_cast<std::size_t>(rect.height) + shape_.itemH - 1) / shape_.itemH;
        cl_uint longest = 0;
        const std::size_t passTiles = static_cast<std::size_t>(grid.tilesX()) * grid.tilesY();
        for (std::size_t t = pass.tileBase; t < pass.tileBase + passTiles; ++t)
            longest = std::max(longest, s.stagedTileStarts[t + 1] - s.stagedTileStarts[t]);
        const cl_uint chunk = shape_.listChunk ? shape_.listChunk : std::max<cl_uint>(longest, 1);
        for (cl_uint first = 0; first < longest; first += chunk) {
            p.list_first = first;
            p.list_count = chunk;
            k.setArg(3, p);
            device_.launch("raster: fragments", k, itemsX, itemsY, groupW, groupH);
        }
        s.rowsCounted = std::max(s.rowsCounted, itemsY);
    }
    draws.clear();
}

DrawStats Rasterizer::takeStats()
{
    RasterScratch& s = *scratch_;
    DrawStats stats;
    stats.triangles = s.setUp;
    s.setUp = 0;
    if (s.rowsCounted == 0)
        return stats;
    for (cl_uint c : device_.download<cl_uint>(s.fragmentCounts, s.rowsCounted))
        stats.fragments += c;
    device_.queue().enqueueFillBuffer(s.fragmentCounts, cl_uint{0}, 0, s.rowsCounted * sizeof(cl_uint));
    s.rowsCounted = 0;
    return stats;
}

DrawBatch::DrawBatch(Rasterizer& rasterizer, Framebuffer& fb)
    : rasterizer_(rasterizer), fb_(fb), draws_(std::make_unique<SetUpDraws>())
{
    draws_->fbWidth = fb.width();
    draws_->fbHeight = fb.height();
    draws_->shape = rasterizer.shape_;
    lendCapacity(*rasterizer_.immediate_, *draws_);
}

DrawBatch::~DrawBatch() { lendCapacity(*draws_, *rasterizer_.immediate_); }

void DrawBatch::add(const DrawState& state, Topology topology, const std::vector<Vertex>& vertices,
                    const FragmentProgram& program)
{
    // The uniforms of one submission are one constant buffer: flush before it would overflow.
    if (draws_->uniforms.size() + kMaxUniforms > rasterizer_.scratch_->maxUniforms)
        flush();
    const CompiledFragmentProgram& c = rasterizer_.compiled(program);
    setUpDraw(*draws_, state, topology, vertices, c.kernel, program, c.attributes);
}

void DrawBatch::flush()
{
    rasterizer_.submit(fb_, *draws_);
    draws_->fbWidth = fb_.width();
    draws_->fbHeight = fb_.height();
}

std::size_t DrawBatch::pendingDraws() const { return draws_->draws; }

DrawStats draw(Device& device, Framebuffer& fb, const DrawState& state, Topology topology,
               const std::vector<Vertex>& vertices, const FragmentProgram& program)
{
    Rasterizer rasterizer(device);
    rasterizer.draw(fb, state, topology, vertices, program);
    return rasterizer.takeStats();
}

}  // namespace clvr::raster
