// raster/rasterizer.cpp — primitive assembly, clipping, set-up and tile binning on the host (in
// double precision, then snapped to the subpixel grid), and the one ordered fragment launch.
#include "raster/rasterizer.h"

#include "host/runtime/errors.h"

#include <algorithm>
#include <cmath>
#include <cstddef>
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
        throw InputError("viewport of size " + std::to_string(w) + "x" + std::to_string(h) + " is empty");
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

struct Binned {
    ClTriangle triangle;
    int tileX0, tileY0, tileX1, tileY1;  // inclusive
};

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
    }
    return out;
}

glm::vec4 clipPlaneFromWorld(const glm::vec4& worldPlane, const glm::mat4& viewProjection)
{
    const glm::dmat4 m = glm::transpose(glm::inverse(glm::dmat4(viewProjection)));
    return glm::vec4(m * glm::dvec4(worldPlane));
}

DrawStats draw(Device& device, Framebuffer& fb, const DrawState& state, Topology topology,
               const std::vector<Vertex>& vertices, const FragmentProgram& program)
{
    if (state.clipPlanes.size() > static_cast<std::size_t>(kMaxClipPlanes))
        throw InputError("draw: " + std::to_string(state.clipPlanes.size()) + " clip planes, at most " +
                         std::to_string(kMaxClipPlanes));
    if (program.uniforms.size() > static_cast<std::size_t>(kMaxUniforms))
        throw InputError("draw: " + std::to_string(program.uniforms.size()) + " fragment program uniforms, at most " +
                         std::to_string(kMaxUniforms));
    const ResolvedViewport vp = resolveViewport(state.viewport, fb.width(), fb.height());
    const Rect rect = vp.scissor;
    // GL's scissor test: the launch and the tiles stay those of the viewport rectangle (one launch shape for
    // every scissor, so PoCL builds no new work-group variant per rectangle); triangles are binned only
    // within `clip`, and the kernel skips pixels outside it.
    Rect clip = rect;
    if (state.scissor.test) {
        const Scissor& sc = state.scissor;
        if (sc.width < 0 || sc.height < 0)
            throw InputError("draw: scissor of size " + std::to_string(sc.width) + "x" + std::to_string(sc.height));
        const int x0 = std::max(rect.x, sc.x), y0 = std::max(rect.y, sc.y);
        const int x1 = std::min(rect.x + rect.width, sc.x + sc.width), y1 = std::min(rect.y + rect.height, sc.y + sc.height);
        clip = {x0, y0, std::max(0, x1 - x0), std::max(0, y1 - y0)};
    }
    const std::vector<glm::dvec4> planes = clipPlanes(state, vp);
    const FragmentState& fs = state.fragment;

    DrawStats stats;
    std::vector<Binned> binned;
    std::vector<ClipVertex> polygon, scratch;
    std::vector<WindowVertex> window;
    const int tilesX = (rect.width + CLVR_TILE_SIZE - 1) / CLVR_TILE_SIZE;
    const int tilesY = (rect.height + CLVR_TILE_SIZE - 1) / CLVR_TILE_SIZE;

    for (const auto& indices : assembleTriangles(topology, vertices.size())) {
        polygon.clear();
        bool inside = true;
        for (std::uint32_t i : indices) {
            ClipVertex v{glm::dvec4(vertices[i].position), {}};
            for (int k = 0; k < kMaxAttributes; ++k)
                v.attributes[k] = glm::dvec4(vertices[i].attributes[k]);
            for (const glm::dvec4& p : planes)
                inside = inside && glm::dot(p, v.position) >= 0.0;
            polygon.push_back(v);
        }
        if (!inside)
            for (const glm::dvec4& p : planes) {
                clipPolygon(polygon, p, scratch);
                if (polygon.size() < 3)
                    break;
            }
        if (polygon.size() < 3)
            continue;

        // Perspective divide, viewport transform (clip +y to the top row), snap to the subpixel grid.
        window.clear();
        bool finite = true;
        for (const ClipVertex& v : polygon) {
            const double w = v.position.w;
            if (!(w > 0.0)) {
                finite = false;
                break;
            }
            const glm::dvec3 ndc = glm::dvec3(v.position) / w;
            WindowVertex wv;
            wv.x = static_cast<std::int64_t>(std::floor((vp.x + (ndc.x + 1.0) * 0.5 * vp.width) * CLVR_SUBPIXEL_SCALE + 0.5));
            wv.y = static_cast<std::int64_t>(std::floor((vp.y + (1.0 - ndc.y) * 0.5 * vp.height) * CLVR_SUBPIXEL_SCALE + 0.5));
            wv.depth = vp.nearZ + (ndc.z + 1.0) * 0.5 * (vp.farZ - vp.nearZ);
            wv.invW = 1.0 / w;
            for (int k = 0; k < kMaxAttributes; ++k)
                wv.attrOverW[k] = v.attributes[k] * wv.invW;
            window.push_back(wv);
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
            ++stats.triangles;

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
                for (int k = 0; k < kMaxAttributes; ++k) {
                    const glm::dvec4& aw = a.attrOverW[k];
                    t.attr_over_w[j][k] = cl_float4{{f(aw.x), f(aw.y), f(aw.z), f(aw.w)}};
                }
            }
            t.front_facing = front ? 1u : 0u;
            t.inv_area = f(1.0 / static_cast<double>(std::llabs(a2)));
            t.depth = cl_float4{{f(v[0]->depth), f(v[1]->depth), f(v[2]->depth), 0.0f}};
            t.inv_w = cl_float4{{f(v[0]->invW), f(v[1]->invW), f(v[2]->invW), 0.0f}};

            // Pixels whose centers (x + 0.5) can be inside, clipped to the viewport rectangle.
            std::int64_t minX = std::min({v[0]->x, v[1]->x, v[2]->x}), maxX = std::max({v[0]->x, v[1]->x, v[2]->x});
            std::int64_t minY = std::min({v[0]->y, v[1]->y, v[2]->y}), maxY = std::max({v[0]->y, v[1]->y, v[2]->y});
            const double half = CLVR_SUBPIXEL_SCALE / 2;
            const int px0 = std::max<int>(clip.x, int(std::ceil((double(minX) - half) / CLVR_SUBPIXEL_SCALE)));
            const int px1 = std::min<int>(clip.x + clip.width - 1, int(std::floor((double(maxX) - half) / CLVR_SUBPIXEL_SCALE)));
            const int py0 = std::max<int>(clip.y, int(std::ceil((double(minY) - half) / CLVR_SUBPIXEL_SCALE)));
            const int py1 = std::min<int>(clip.y + clip.height - 1, int(std::floor((double(maxY) - half) / CLVR_SUBPIXEL_SCALE)));
            if (px0 > px1 || py0 > py1)
                continue;
            binned.push_back({t, (px0 - rect.x) / CLVR_TILE_SIZE, (py0 - rect.y) / CLVR_TILE_SIZE,
                              (px1 - rect.x) / CLVR_TILE_SIZE, (py1 - rect.y) / CLVR_TILE_SIZE});
        }
    }
    if (binned.empty() || rect.width == 0 || rect.height == 0)
        return stats;

    // A tile is skipped when one edge function (with its fill-rule bias) is negative at all four
    // corner pixel centers of the tile's part of the rectangle: exact, so no covered center is lost.
    const auto touches = [&](const ClTriangle& t, int tx, int ty) {
        const std::int64_t x0 = rect.x + tx * CLVR_TILE_SIZE, y0 = rect.y + ty * CLVR_TILE_SIZE;
        const std::int64_t x1 = std::min<std::int64_t>(x0 + CLVR_TILE_SIZE, rect.x + rect.width) - 1;
        const std::int64_t y1 = std::min<std::int64_t>(y0 + CLVR_TILE_SIZE, rect.y + rect.height) - 1;
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
    };

    // Tile lists in submission order: count, prefix sum, fill.
    const std::size_t tileCount = static_cast<std::size_t>(tilesX) * tilesY;
    std::vector<cl_uint> tileStart(tileCount + 1, 0);
    std::uint64_t entries = 0;
    for (const Binned& b : binned)
        for (int ty = b.tileY0; ty <= b.tileY1; ++ty)
            for (int tx = b.tileX0; tx <= b.tileX1; ++tx)
                if (touches(b.triangle, tx, ty))
                    ++tileStart[static_cast<std::size_t>(ty) * tilesX + tx + 1];
    for (std::size_t i = 0; i < tileCount; ++i) {
        entries += tileStart[i + 1];
        if (entries > std::numeric_limits<cl_uint>::max())
            throw InputError("draw: more than 2^32 triangle-tile pairs; split the draw");
        tileStart[i + 1] = static_cast<cl_uint>(entries);
    }
    std::vector<cl_uint> tileTris(std::max<std::uint64_t>(entries, 1));
    std::vector<cl_uint> cursor(tileStart.begin(), tileStart.end() - 1);
    std::vector<ClTriangle> triangles;
    triangles.reserve(binned.size());
    for (const Binned& b : binned) {
        const auto index = static_cast<cl_uint>(triangles.size());
        triangles.push_back(b.triangle);
        for (int ty = b.tileY0; ty <= b.tileY1; ++ty)
            for (int tx = b.tileX0; tx <= b.tileX1; ++tx)
                if (touches(b.triangle, tx, ty))
                    tileTris[cursor[static_cast<std::size_t>(ty) * tilesX + tx]++] = index;
    }

    std::vector<cl_float4> uniforms(std::max<std::size_t>(program.uniforms.size(), 1), cl_float4{{0, 0, 0, 0}});
    for (std::size_t i = 0; i < program.uniforms.size(); ++i) {
        const glm::vec4& u = program.uniforms[i];
        uniforms[i] = cl_float4{{u.x, u.y, u.z, u.w}};
    }
    cl::Buffer triangleBuffer = device.upload("raster triangles", triangles);
    cl::Buffer tileStartBuffer = device.upload("raster tile starts", tileStart);
    cl::Buffer tileTrisBuffer = device.upload("raster tile lists", tileTris);
    cl::Buffer uniformBuffer = device.upload("fragment program uniforms", uniforms);
    std::vector<cl_uint> zeros(static_cast<std::size_t>(rect.height), 0u);
    cl::Buffer countBuffer = device.upload("raster fragment counts", zeros, CL_MEM_READ_WRITE);
    cl::Buffer dummy;

    cl::Kernel k = device.kernel("raster.cl", "raster_fragments",
                                 program.source.empty() ? std::string_view(kDefaultFragmentProgram)
                                                        : std::string_view(program.source));
    int arg = 0;
    k.setArg(arg++, fb.color());
    k.setArg(arg++, fb.depth());
    k.setArg(arg++, fb.stencil());
    k.setArg(arg++, static_cast<cl_int>(fb.width()));
    k.setArg(arg++, static_cast<cl_int>(rect.x));
    k.setArg(arg++, static_cast<cl_int>(rect.y));
    k.setArg(arg++, static_cast<cl_int>(rect.width));
    k.setArg(arg++, static_cast<cl_int>(rect.height));
    k.setArg(arg++, cl_int4{{clip.x, clip.y, clip.x + clip.width, clip.y + clip.height}});
    k.setArg(arg++, static_cast<cl_int>(tilesX));
    k.setArg(arg++, triangleBuffer);
    k.setArg(arg++, tileStartBuffer);
    k.setArg(arg++, tileTrisBuffer);
    k.setArg(arg++, toCl(fs));
    k.setArg(arg++, toCl(fs.blend));
    k.setArg(arg++, uniformBuffer);
    for (const cl::Buffer& b : program.buffers) {
        if (b())
            k.setArg(arg++, b);
        else {
            if (!dummy())
                dummy = device.buffer("fragment program dummy buffer", sizeof(cl_float4));
            k.setArg(arg++, dummy);
        }
    }
    k.setArg(arg++, countBuffer);
    static_assert(CLVR_TILE_SIZE % CLVR_PIXELS_PER_ITEM == 0);
    const std::size_t items = (static_cast<std::size_t>(rect.width) + CLVR_PIXELS_PER_ITEM - 1) / CLVR_PIXELS_PER_ITEM;
    device.launch("raster: fragments", k, items, static_cast<std::size_t>(rect.height));

    for (cl_uint c : device.download<cl_uint>(countBuffer, zeros.size()))
        stats.fragments += c;
    return stats;
}

}  // namespace clvr::raster
