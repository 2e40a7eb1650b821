// raster/rasterizer.h — the ordered triangle rasterizer and GL's per-fragment operations
// (DESIGN.md, raster stage; the exact rules are in docs/raster.md). Triangles are clipped, set up
// and binned to screen tiles on the host in submission order; one work-item per rectangle of pixels
// (a whole tile on a CPU) then walks its tile's list in that order, so blending is exactly ordered and
// two runs give identical bits. Rasterizer and DrawBatch (below) make many draws cheap; raster::draw
// is the one-shot form.
#pragma once

#include "host/runtime/device.h"
#include "raster/fragment_state.h"
#include "raster/framebuffer.h"

#include <glm/glm.hpp>

#include <array>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

namespace clvr::raster {

inline constexpr int kMaxAttributes = CLVR_MAX_ATTRIBUTES;
inline constexpr int kMaxClipPlanes = 6;
inline constexpr int kMaxUniforms = CLVR_MAX_UNIFORMS;
// Clip x and y only against a guard band this many pixels beyond the viewport; pixels outside the
// viewport are scissored, so coverage equals GL's x/y clipping.
inline constexpr int kGuardBandPixels = 4096;

struct Vertex {
    glm::vec4 position;                                 // clip space
    std::array<glm::vec4, kMaxAttributes> attributes{};  // interpolated perspective-correctly
};

enum class Topology { Triangles, TriangleStrip, TriangleFan };

// x, y: the viewport's top-left pixel (row 0 at the top); -1 sizes: the whole frame buffer.
// nearZ, farZ: glDepthRange, clamped to [0,1].
struct Viewport { int x = 0, y = 0, width = -1, height = -1; float nearZ = 0.0f, farZ = 1.0f; };

struct CompiledFragmentProgram;  // raster/rasterizer.cpp: the raster kernel built for one source

// The per-fragment work of a technique, compiled into the raster kernel (cached by Device). `source`
// is OpenCL C defining
//     int clvr_fragment(const ClFragment* f, const ClFragmentResources* r, float4* color);
// (return 0 to discard); it is appended after kernels/raster.cl and may use its includes
// (texture.h). Empty: color = attribute 0.
struct FragmentProgram {
    std::string source;
    // f->attr[0 .. attributes-1] are interpolated; the others read as zero. Each attribute adds 48 bytes
    // to every triangle record, so a program that reads one attribute says so (the default program does).
    int attributes = kMaxAttributes;
    std::array<cl::Buffer, 4> buffers;  // r->buffer[i]; null ones are bound to a dummy
    std::vector<glm::vec4> uniforms;    // r->uniforms[i], up to kMaxUniforms
    // Filled by the first draw with this program and shared by its copies: the built raster kernel, so
    // that later draws never look the (often 20 KB) source up again. Set `source` before the first draw;
    // to draw another source, use another FragmentProgram (a source of another length, or another
    // attribute count, is rebuilt).
    mutable std::shared_ptr<const CompiledFragmentProgram> compiled;
};

// GL's scissor test (glScissor): with `test`, only pixels inside the rectangle (x, y its top-left pixel,
// row 0 at the top) are visited. Coverage, depth and attributes of the pixels inside are unchanged:
// edge functions and interpolation use absolute pixel positions.
struct Scissor { bool test = false; int x = 0, y = 0, width = 0, height = 0; };

struct DrawState {
    FragmentState fragment;
    std::vector<glm::vec4> clipPlanes;  // CLIP coordinates: keep dot(plane, clipPos) >= 0; up to 6
    Viewport viewport;
    Scissor scissor;
};

// A world-space plane (keep dot(plane, (p,1)) >= 0) in clip coordinates: inverse-transpose of viewProjection.
glm::vec4 clipPlaneFromWorld(const glm::vec4& worldPlane, const glm::mat4& viewProjection);

struct DrawStats {
    std::uint64_t triangles = 0;  // after clipping, culling and dropping zero-area ones
    std::uint64_t fragments = 0;  // covered pixels inside the viewport, before any test or discard
};

// One draw, then its stats: a Rasterizer made for this call, so it allocates and reads back every time.
// Renderers that draw often keep a Rasterizer (below). InternalError for state out of range (more than
// kMaxClipPlanes planes or kMaxUniforms uniforms, an empty viewport, a negative scissor).
DrawStats draw(Device& device, Framebuffer& fb, const DrawState& state, Topology topology,
               const std::vector<Vertex>& vertices, const FragmentProgram& program = {});

// How a fragment launch divides the viewport rectangle: tiles of tileW x tileH pixels (one triangle list
// each) and items of itemW x itemH pixels (one work-item each, inside one tile), powers of two up to
// CLVR_TILE_SIZE. Only speed depends on it: every shape gives the same bits.
struct RasterShape {
    int tileW = CLVR_TILE_SIZE, tileH = CLVR_TILE_SIZE;
    int itemW = CLVR_TILE_SIZE, itemH = CLVR_TILE_SIZE;
    // Triangles of a tile list per launch: 0 walks each list in one launch; n > 0 launches a pass once per
    // n entries of its longest list (each launch continues from the frame buffer the last one left).
    std::uint32_t listChunk = 0;
    // A CPU walks each tile list once (item = tile); a GPU gives each pixel a work-item (1x1 items) and
    // each tile a work-group's worth of them. A device that caps loop iterations
    // (Device::loopIterationCap) gets 1x1 items and lists cut to fit the cap with room to spare.
    static RasterShape forDevice(Device& device);
};

#define CLVR_RASTER_BATCHES 1  // Rasterizer and DrawBatch exist (tools/bench_raster.cpp compiles without)

struct SetUpDraws;    // raster/rasterizer.cpp: draws set up and binned on the host, not yet launched
struct RasterScratch;  // raster/rasterizer.cpp: device buffers, host staging and counters kept across draws

// The raster stage for many draws (docs/raster.md, "Many draws"): one per renderer, for the device's
// lifetime. A draw costs in proportion to its triangles: programs are looked up once per
// FragmentProgram, buffers persist (grown geometrically), and nothing is read back until takeStats().
// Draws run in submission order on the device's in-order queue, after whatever was enqueued before them
// (clears, other passes). Not for use by several threads at once. Fragment counts are 32-bit per row:
// take the stats at least once a frame.
class Rasterizer {
public:
    explicit Rasterizer(Device& device) : Rasterizer(device, RasterShape::forDevice(device)) {}
    // InternalError for a shape that is not powers of two up to CLVR_TILE_SIZE with items inside tiles.
    Rasterizer(Device& device, RasterShape shape);
    ~Rasterizer();
    Rasterizer(const Rasterizer&) = delete;
    Rasterizer& operator=(const Rasterizer&) = delete;

    // Sets up and bins `vertices` on the host and enqueues the fragment launch; returns without waiting.
    // The same bits as raster::draw.
    void draw(Framebuffer& fb, const DrawState& state, Topology topology, const std::vector<Vertex>& vertices,
              const FragmentProgram& program = {});

    // Triangles and fragments of every draw and batch since the last call (or since construction). Waits
    // for the queue: the fragment count is a device counter.
    DrawStats takeStats();

    Device& device() { return device_; }
    const RasterShape& shape() const { return shape_; }

private:
    friend class DrawBatch;
    const CompiledFragmentProgram& compiled(const FragmentProgram& program);
    void submit(Framebuffer& fb, SetUpDraws& draws);

    Device& device_;
    RasterShape shape_;
    FragmentProgram defaultProgram_;  // kDefaultFragmentProgram, for draws with an empty source
    std::unique_ptr<RasterScratch> scratch_;
    std::unique_ptr<SetUpDraws> immediate_;  // draw()'s one-draw batch, reused
};

// Many draws into one frame buffer as one submission: each add() sets up and bins its triangles on the
// host, flush() uploads them once and launches one fragment pass per run of consecutive draws that
// share fragment program, buffers, uniforms, viewport and fragment state (a state change starts a new
// pass, so it takes effect exactly where it was added). Every pixel sees its fragments in add() order,
// so a batch gives the same bits as the same draws one by one. Nothing enqueued between add() and
// flush() (a clear, say) runs after the batch's draws: flush first. Draws not flushed are dropped.
// The batch borrows the Rasterizer's host arrays while it lives, so the Rasterizer must outlive it.
class DrawBatch {
public:
    DrawBatch(Rasterizer& rasterizer, Framebuffer& fb);
    ~DrawBatch();
    DrawBatch(const DrawBatch&) = delete;
    DrawBatch& operator=(const DrawBatch&) = delete;

    void add(const DrawState& state, Topology topology, const std::vector<Vertex>& vertices,
             const FragmentProgram& program = {});
    // Enqueues every draw added since the last flush, in order; returns without waiting.
    void flush();
    std::size_t pendingDraws() const;

private:
    Rasterizer& rasterizer_;
    Framebuffer& fb_;
    std::unique_ptr<SetUpDraws> draws_;
};

// The triangles of a list, strip or fan as vertex index triples, in GL's order and winding
// (strip triangle i is (i, i+1, i+2) for even i, (i+1, i, i+2) for odd i; fan: (0, i+1, i+2)).
std::vector<std::array<std::uint32_t, 3>> assembleTriangles(Topology topology, std::size_t vertexCount);

// The program used when FragmentProgram::source is empty.
inline constexpr const char* kDefaultFragmentProgram =
    "int clvr_fragment(const ClFragment* f, const ClFragmentResources* r, float4* color)\n"
    "{\n"
    "    (void)r;\n"
    "    *color = f->attr[0];\n"
    "    return 1;\n"
    "}\n";

}  // namespace clvr::raster
