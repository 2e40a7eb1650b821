// raster/rasterizer.h — the ordered triangle rasterizer and GL's per-fragment operations
// (DESIGN.md, raster stage; the exact rules are in docs/raster.md). Triangles are clipped, set up
// and binned to screen tiles on the host in submission order; one work-item per pixel then walks
// its tile's list in that order, so blending is exactly ordered and two runs give identical bits.
#pragma once

#include "host/runtime/device.h"
#include "raster/fragment_state.h"
#include "raster/framebuffer.h"

#include <glm/glm.hpp>

#include <array>
#include <cstdint>
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

// The per-fragment work of a technique, compiled into the raster kernel (cached by Device). `source`
// is OpenCL C defining
//     int clvr_fragment(const ClFragment* f, const ClFragmentResources* r, float4* color);
// (return 0 to discard); it is appended after kernels/raster.cl and may use its includes
// (texture.h). Empty: color = attribute 0.
struct FragmentProgram {
    std::string source;
    std::array<cl::Buffer, 4> buffers;  // r->buffer[i]; null ones are bound to a dummy
    std::vector<glm::vec4> uniforms;    // r->uniforms[i], up to kMaxUniforms
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

// Draws `vertices` into fb in submission order. Throws InputError for bad counts or state.
DrawStats draw(Device& device, Framebuffer& fb, const DrawState& state, Topology topology,
               const std::vector<Vertex>& vertices, const FragmentProgram& program = {});

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
