// raster/rasterizer.cpp — primitive assembly, clipping, set-up and tile binning on the host (in
// double precision, then snapped to the subpixel grid), and the ordered fragment launches: one per pass
// (a run of draws with the same program and state), from buffers that persist in the Rasterizer.
#include "raster/rasterizer.h"

#include "host/runtime/errors.h"

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstddef>
#include <cstring>
#include <limits>

namespace clvr::raster {

static_assert(sizeof(ClTriangle) == 288, "also probed on the device by tests/layout_test.cpp");
static_assert(offsetof(ClTriangle, depth) == 64);
static_assert(offsetof(ClTriangle, attr_over_w) == 96);

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
    std::array<glm::dvec4, kMaxAttributes> attrOverW;
};

std::int64_t cross(const WindowVertex& a, const WindowVertex& b, const WindowVertex& c)
{
    return (b.x - a.x) * (c.y - a.y) - (b.y - a.y) * (c.x - a.x);
}

float f(double v) { return static_cast<float>(v); }

// Perspective divide, viewport transform (clip +y to the top row), snap to the subpixel grid.
// False for a vertex at w <= 0.
bool toWindow(const glm::dvec4& position, const std::array<glm::dvec4, kMaxAttributes>& attributes,
              const ResolvedViewport& vp, WindowVertex& wv)
{
    const double w = position.w;
    if (!(w > 0.0))
        return false;
    const glm::dvec3 ndc = glm::dvec3(position) / w;
    wv.x = static_cast<std::int64_t>(std::floor((vp.x + (ndc.x + 1.0) * 0.5 * vp.width) * CLVR_SUBPIXEL_SCALE + 0.5));
    wv.y = static_cast<std::int64_t>(std::floor((vp.y + (1.0 - ndc.y) * 0.5 * vp.height) * CLVR_SUBPIXEL_SCALE + 0.5));
    wv.depth = vp.nearZ + (ndc.z + 1.0) * 0.5 * (vp.farZ - vp.nearZ);
    wv.invW = 1.0 / w;
    for (int k = 0; k < kMaxAttributes; ++k)
        wv.attrOverW[k] = attributes[k] * wv.invW;
    return true;
}

// Tiles of a pass: tileW x tileH pixels from the rectangle's corner, powers of two (the kernel shifts).
// tileW is a multiple of CLVR_PIXELS_PER_ITEM, so a work-item's pixels share a tile.
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

// Grows `buffer` to hold `bytes` (capacity at least doubles, so n draws cost O(log n) allocations).
void reserve(Device& device, std::string_view what, cl::Buffer& buffer, std::size_t& capacity, std::size_t bytes,
             cl_mem_flags flags)
{
    if (buffer() && bytes <= capacity)
        return;
    capacity = std::max({bytes, 2 * capacity, std::size_t{4096}});
    buffer = device.buffer(what, capacity, flags);
}

constexpr std::size_t kMaxRows = 16384;  // Framebuffer's largest height: one fragment counter per row

}  // namespace

// The raster kernel built for one fragment program source on one context.
struct CompiledFragmentProgram {
    cl_context context = nullptr;
    std::size_t sourceSize = 0;
    cl::Kernel kernel;  // set per launch; only one thread uses a Rasterizer (rasterizer.h)
};

// One fragment launch: consecutive draws that share everything but geometry and scissor.
struct Pass {
    cl::Kernel kernel;
    std::array<cl::Buffer, 4> buffers;
    ClFragmentState fragment;
    ClBlendState blend;
    Rect rect;                      // the viewport rectangle: the launch's extent and its tiles' origin
    std::size_t uniformBase = 0;    // first uniform in SetUpDraws::uniforms
    std::size_t uniformCount = 0;
    std::size_t firstTriangle = 0;  // triangles [firstTriangle, endTriangle) of SetUpDraws::triangles
    std::size_t endTriangle = 0;
};

struct SetUpDraws {
    int fbWidth = 0, fbHeight = 0;
    std::vector<ClTriangle> triangles;  // set up, in submission order
    std::vector<Pass> passes;
    std::vector<cl_float4> uniforms;
    std::uint64_t setUp = 0;            // DrawStats::triangles: also those whose pixel box is empty
    std::size_t draws = 0;
    std::vector<ClipVertex> polygon, scratch;
    std::vector<WindowVertex> window;

    void clear()
    {
        triangles.clear();
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
    std::vector<ClTriangle> stagedTriangles;
    std::vector<cl_uint> stagedTileStarts, stagedTileTris;
    std::vector<std::array<cl_uint, 2>> binPairs;  // binPass's (tile, triangle) scratch
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

// Hands the (empty) triangle array of `from`, with its capacity, to `to`: a DrawBatch borrows the
// Rasterizer's, so that a batch per frame does not grow its array from nothing (and fault in fresh
// pages) every frame. Only the capacity moves; pending draws are never lost.
void lendCapacity(SetUpDraws& from, SetUpDraws& to)
{
    if (!from.triangles.empty())
        return;
    to.triangles.clear();
    if (to.triangles.capacity() < from.triangles.capacity())
        to.triangles.swap(from.triangles);
}

// Sets up and bins one draw into `out` (docs/raster.md, steps 1-6), extending its last pass when the draw
// shares that pass's program, buffers, uniforms, rectangle and fragment state.
void setUpDraw(SetUpDraws& out, const DrawState& state, Topology topology, const std::vector<Vertex>& vertices,
               const cl::Kernel& kernel, const FragmentProgram& program)
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
    std::vector<cl_float4> uniforms(std::max<std::size_t>(program.uniforms.size(), 1), cl_float4{{0, 0, 0, 0}});
    for (std::size_t i = 0; i < program.uniforms.size(); ++i)
        uniforms[i] = toCl4(program.uniforms[i]);
    const auto sameBuffers = [&](const Pass& p) {
        for (std::size_t i = 0; i < p.buffers.size(); ++i)
            if (p.buffers[i]() != program.buffers[i]())
                return false;
        return true;
    };
    const auto sameUniforms = [&](const Pass& p) {
        return p.uniformCount == uniforms.size() &&
               std::memcmp(out.uniforms.data() + p.uniformBase, uniforms.data(), uniforms.size() * sizeof(cl_float4)) == 0;
    };
    if (out.passes.empty() || out.passes.back().kernel() != kernel() || !sameBuffers(out.passes.back()) ||
        !sameBytes(out.passes.back().fragment, clFragment) || !sameBytes(out.passes.back().blend, clBlend) ||
        !sameBytes(out.passes.back().rect, rect) || !sameUniforms(out.passes.back())) {
        Pass p{kernel, program.buffers, clFragment, clBlend, rect, out.uniforms.size(), uniforms.size(),
               out.triangles.size(), out.triangles.size()};
        out.uniforms.insert(out.uniforms.end(), uniforms.begin(), uniforms.end());
        out.passes.push_back(std::move(p));
    }
    Pass& pass = out.passes.back();

    std::vector<ClipVertex>& polygon = out.polygon;
    std::vector<ClipVertex>& scratch = out.scratch;
    std::vector<WindowVertex>& window = out.window;
    for (const auto& indices : assembleTriangles(topology, vertices.size())) {
        bool inside = true;
        glm::dvec4 position[3];
        for (int j = 0; j < 3; ++j) {
            position[j] = glm::dvec4(vertices[indices[j]].position);
            for (const glm::dvec4& p : planes)
                inside = inside && glm::dot(p, position[j]) >= 0.0;
        }
        window.clear();
        bool finite = true;
        const auto project = [&](const glm::dvec4& pos, const std::array<glm::dvec4, kMaxAttributes>& attributes) {
            WindowVertex wv;
            finite = finite && toWindow(pos, attributes, vp, wv);
            window.push_back(wv);
        };
        std::array<glm::dvec4, kMaxAttributes> attributes;
        if (inside) {  // the common case: no clipping, straight from the vertices
            for (int j = 0; j < 3 && finite; ++j) {
                for (int k = 0; k < kMaxAttributes; ++k)
                    attributes[k] = glm::dvec4(vertices[indices[j]].attributes[k]);
                project(position[j], attributes);
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
        for (std::size_t i = 1; i + 1 < window.size(); ++i)
            area2 += cross(window[0], window[i], window[i + 1]);
        if (area2 == 0)
            continue;
        const bool front = fs.frontFaceCCW ? area2 < 0 : area2 > 0;
        if (fs.cull == CullFace::FrontAndBack || (fs.cull == CullFace::Front && front) ||
            (fs.cull == CullFace::Back && !front))
            continue;

        for (std::size_t i = 1; i + 1 < window.size(); ++i) {
            const WindowVertex* v[3] = {&window[0], &window[i], &window[i + 1]};
            const std::int64_t a2 = cross(*v[0], *v[1], *v[2]);
            // A fan triangle whose snapped orientation disagrees with the polygon's is a snapping
            // sliver of zero true area: drop it with the zero-area ones.
            if (a2 == 0 || (a2 > 0) != (area2 > 0))
                continue;
            if (a2 < 0)
                std::swap(v[1], v[2]);
            ++out.setUp;

            // Pixels whose centers (x + 0.5) can be inside, clipped to the scissored viewport rectangle.
            const std::int64_t minX = std::min({v[0]->x, v[1]->x, v[2]->x}), maxX = std::max({v[0]->x, v[1]->x, v[2]->x});
            const std::int64_t minY = std::min({v[0]->y, v[1]->y, v[2]->y}), maxY = std::max({v[0]->y, v[1]->y, v[2]->y});
            const double half = CLVR_SUBPIXEL_SCALE / 2;
            const int px0 = std::max<int>(clip.x, int(std::ceil((double(minX) - half) / CLVR_SUBPIXEL_SCALE)));
            const int px1 = std::min<int>(clip.x + clip.width - 1, int(std::floor((double(maxX) - half) / CLVR_SUBPIXEL_SCALE)));
            const int py0 = std::max<int>(clip.y, int(std::ceil((double(minY) - half) / CLVR_SUBPIXEL_SCALE)));
            const int py1 = std::min<int>(clip.y + clip.height - 1, int(std::floor((double(maxY) - half) / CLVR_SUBPIXEL_SCALE)));
            if (px0 > px1 || py0 > py1)
                continue;

            ClTriangle& t = out.triangles.emplace_back();
            for (int j = 0; j < 3; ++j) {
                const WindowVertex& a = *v[j];
                const WindowVertex& b = *v[(j + 1) % 3];
                t.x[j] = static_cast<cl_int>(a.x);
                t.y[j] = static_cast<cl_int>(a.y);
                const std::int64_t dx = b.x - a.x, dy = b.y - a.y;
                // Top-left rule (row-down, edge functions positive inside): a left edge runs up, a
                // top edge runs exactly horizontal to the right.
                t.bias[j] = (dy < 0 || (dy == 0 && dx > 0)) ? 0 : -1;
                for (int k = 0; k < kMaxAttributes; ++k) {
                    const glm::dvec4& aw = a.attrOverW[k];
                    t.attr_over_w[j][k] = cl_float4{{f(aw.x), f(aw.y), f(aw.z), f(aw.w)}};
                }
            }
            t.front_facing = front ? 1u : 0u;
            t.inv_area = f(1.0 / static_cast<double>(std::llabs(a2)));
            t.col_min = px0;
            t.col_max = px1;
            t.row_min = py0;
            t.row_max = py1;
            t.pad0 = 0;
            t.depth = cl_float4{{f(v[0]->depth), f(v[1]->depth), f(v[2]->depth), 0.0f}};
            t.inv_w = cl_float4{{f(v[0]->invW), f(v[1]->invW), f(v[2]->invW), 0.0f}};
        }
    }
    pass.endTriangle = out.triangles.size();
}

// The tiles of a pass. Every work-item walks its tile's whole list, so small triangles get one-row
// tiles of one work-item (each entry then is a triangle crossing that work-item's pixels) and large ones
// 16x16 tiles (a triangle over the whole screen makes 1/32 of the entries). Only speed depends on it.
TileGrid tileGrid(const std::vector<ClTriangle>& triangles, const Pass& pass)
{
    std::uint64_t rows = 0;
    for (std::size_t i = pass.firstTriangle; i < pass.endTriangle; ++i)
        rows += static_cast<std::uint64_t>(triangles[i].row_max - triangles[i].row_min + 1);
    const bool small = rows <= 8 * (pass.endTriangle - pass.firstTriangle);  // mean height <= 8 rows
    return small ? TileGrid{pass.rect, CLVR_PIXELS_PER_ITEM, 1} : TileGrid{pass.rect, CLVR_TILE_SIZE, CLVR_TILE_SIZE};
}

// Tile lists of one pass in submission order, appended to the staging arrays: tile t's triangles are
// tileTris[tileStarts[base + t] .. tileStarts[base + t + 1]). A counting sort: one walk over the
// triangles records each (tile, triangle) pair in `pairs` and counts per tile, a prefix sum gives the
// starts, and the pairs, still in submission order, are scattered into place. Returns base.
std::size_t binPass(const std::vector<ClTriangle>& triangles, const Pass& pass, const TileGrid& grid,
                    std::vector<cl_uint>& tileStarts, std::vector<cl_uint>& tileTris,
                    std::vector<std::array<cl_uint, 2>>& pairs)
{
    const int tilesX = grid.tilesX();
    const std::size_t tileCount = static_cast<std::size_t>(tilesX) * grid.tilesY();
    const std::size_t base = tileStarts.size();
    tileStarts.resize(base + tileCount + 1, 0);
    cl_uint* start = tileStarts.data() + base;
    pairs.clear();
    for (std::size_t i = pass.firstTriangle; i < pass.endTriangle; ++i) {
        const ClTriangle& t = triangles[i];
        const int tx0 = (t.col_min - grid.rect.x) / grid.tileW, tx1 = (t.col_max - grid.rect.x) / grid.tileW;
        const int ty0 = (t.row_min - grid.rect.y) / grid.tileH, ty1 = (t.row_max - grid.rect.y) / grid.tileH;
        // One tile holds every center the triangle can cover: the corner test could only drop it.
        const bool single = tx0 == tx1 && ty0 == ty1;
        for (int ty = ty0; ty <= ty1; ++ty)
            for (int tx = tx0; tx <= tx1; ++tx)
                if (single || touches(t, grid, tx, ty)) {
                    const auto tile = static_cast<cl_uint>(static_cast<std::size_t>(ty) * tilesX + tx);
                    ++start[tile + 1];
                    pairs.push_back({tile, static_cast<cl_uint>(i)});
                }
    }
    std::uint64_t entries = tileTris.size();
    start[0] = static_cast<cl_uint>(entries);
    for (std::size_t i = 0; i < tileCount; ++i) {
        entries += start[i + 1];
        if (entries > std::numeric_limits<cl_uint>::max())
            throw InputError("draw: more than 2^32 triangle-tile pairs in one submission; split the draw");
        start[i + 1] = static_cast<cl_uint>(entries);
    }
    std::vector<cl_uint> cursor(start, start + tileCount);
    tileTris.resize(entries);
    for (const auto& [tile, triangle] : pairs)
        tileTris[cursor[tile]++] = triangle;
    return base;
}

}  // namespace

std::vector<std::array<std::uint32_t, 3>> assembleTriangles(Topology topology, std::size_t vertexCount)
{
    std::vector<std::array<std::uint32_t, 3>> out;
    const auto n = static_cast<std::uint32_t>(vertexCount);
    switch (topology) {
    case Topology::Triangles:
        for (std::uint32_t i = 0; i + 2 < n; i += 3)
            out.push_back({i, i + 1, i + 2});
        break;
    case Topology::TriangleStrip:
        for (std::uint32_t i = 0; i + 2 < n; ++i)
            out.push_back(i % 2 == 0 ? std::array<std::uint32_t, 3>{i, i + 1, i + 2}
                                     : std::array<std::uint32_t, 3>{i + 1, i, i + 2});
        break;
    case Topology::TriangleFan:
        for (std::uint32_t i = 1; i + 1 < n; ++i)
            out.push_back({0, i, i + 1});
        break;
    default:
        throw InternalError("assembleTriangles: topology " + std::to_string(static_cast<int>(topology)) +
                            " is unknown");
    }
    return out;
}

glm::vec4 clipPlaneFromWorld(const glm::vec4& worldPlane, const glm::mat4& viewProjection)
{
    const glm::dmat4 m = glm::transpose(glm::inverse(glm::dmat4(viewProjection)));
    return glm::vec4(m * glm::dvec4(worldPlane));
}

Rasterizer::Rasterizer(Device& device)
    : device_(device), scratch_(std::make_unique<RasterScratch>()), immediate_(std::make_unique<SetUpDraws>())
{
    defaultProgram_.source = kDefaultFragmentProgram;
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
    const cl_context context = device_.context()();
    if (p.compiled && p.compiled->context == context && p.compiled->sourceSize == p.source.size())
        return *p.compiled;
    auto c = std::make_shared<CompiledFragmentProgram>();
    c->context = context;
    c->sourceSize = p.source.size();
    c->kernel = device_.kernel("raster.cl", "raster_fragments", p.source);
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
    setUpDraw(d, state, topology, vertices, compiled(program).kernel, program);
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
    if (draws.triangles.empty()) {
        draws.clear();
        return;
    }
    s.uploadsDone();
    s.stagedTileStarts.clear();
    s.stagedTileTris.clear();
    std::vector<std::size_t> bases;
    std::vector<TileGrid> grids;
    for (const Pass& pass : draws.passes) {
        grids.push_back(tileGrid(draws.triangles, pass));
        bases.push_back(pass.firstTriangle == pass.endTriangle || pass.rect.width == 0 || pass.rect.height == 0
                            ? std::size_t(-1)
                            : binPass(draws.triangles, pass, grids.back(), s.stagedTileStarts, s.stagedTileTris,
                                      s.binPairs));
    }
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

    static_assert(CLVR_TILE_SIZE % CLVR_PIXELS_PER_ITEM == 0);  // both tile widths hold whole work-items
    for (std::size_t i = 0; i < draws.passes.size(); ++i) {
        const Pass& pass = draws.passes[i];
        if (bases[i] == std::size_t(-1))
            continue;
        const Rect& rect = pass.rect;
        cl::Kernel k = pass.kernel;
        int arg = 0;
        k.setArg(arg++, fb.color());
        k.setArg(arg++, fb.depth());
        k.setArg(arg++, fb.stencil());
        k.setArg(arg++, static_cast<cl_int>(fb.width()));
        k.setArg(arg++, static_cast<cl_int>(rect.x));
        k.setArg(arg++, static_cast<cl_int>(rect.y));
        k.setArg(arg++, static_cast<cl_int>(rect.width));
        k.setArg(arg++, static_cast<cl_int>(rect.height));
        k.setArg(arg++, static_cast<cl_int>(std::countr_zero(static_cast<unsigned>(grids[i].tileW))));
        k.setArg(arg++, static_cast<cl_int>(std::countr_zero(static_cast<unsigned>(grids[i].tileH))));
        k.setArg(arg++, static_cast<cl_int>(grids[i].tilesX()));
        k.setArg(arg++, static_cast<cl_uint>(bases[i]));
        k.setArg(arg++, s.triangles);
        k.setArg(arg++, s.tileStarts);
        k.setArg(arg++, s.tileTris);
        k.setArg(arg++, pass.fragment);
        k.setArg(arg++, pass.blend);
        k.setArg(arg++, s.uniforms);
        k.setArg(arg++, static_cast<cl_uint>(pass.uniformBase));
        for (const cl::Buffer& b : pass.buffers)
            k.setArg(arg++, b() ? b : s.dummy);
        k.setArg(arg++, s.fragmentCounts);
        const std::size_t items = (static_cast<std::size_t>(rect.width) + CLVR_PIXELS_PER_ITEM - 1) / CLVR_PIXELS_PER_ITEM;
        device_.launch("raster: fragments", k, items, static_cast<std::size_t>(rect.height));
        s.rowsCounted = std::max<std::size_t>(s.rowsCounted, static_cast<std::size_t>(rect.height));
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
    lendCapacity(*rasterizer_.immediate_, *draws_);
}

DrawBatch::~DrawBatch() { lendCapacity(*draws_, *rasterizer_.immediate_); }

void DrawBatch::add(const DrawState& state, Topology topology, const std::vector<Vertex>& vertices,
                    const FragmentProgram& program)
{
    // The uniforms of one submission are one constant buffer: flush before it would overflow.
    if (draws_->uniforms.size() + kMaxUniforms > rasterizer_.scratch_->maxUniforms)
        flush();
    setUpDraw(*draws_, state, topology, vertices, rasterizer_.compiled(program).kernel, program);
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
