// raster/reference/rasterizer.h — the CPU reference of raster/rasterizer.h: the same rules
// (docs/raster.md) in plain double-precision C++, one triangle at a time. Used only by tests.
#pragma once

#include "host/model/image.h"
#include "raster/rasterizer.h"

#include <glm/glm.hpp>

#include <array>
#include <cstdint>
#include <functional>
#include <vector>

namespace clvr::raster::reference {

// The frame buffer planes in double (color, depth) and uint8 (stencil), row 0 at the top.
struct Planes {
    Planes(int width, int height, glm::dvec4 color = glm::dvec4(0.0), double depth = 1.0, std::uint8_t stencil = 0);
    int width = 0, height = 0;
    std::vector<glm::dvec4> color;
    std::vector<double> depth;
    std::vector<std::uint8_t> stencil;
    Image4d colorImage() const;
};

struct Fragment {
    glm::dvec2 window;  // pixel center, row-down
    double depth = 0.0;
    bool frontFacing = true;
    std::array<glm::dvec4, kMaxAttributes> attributes{};
};

// The reference twin of a FragmentProgram: returns false to discard. Empty: color = attribute 0.
using FragmentFunction = std::function<bool(const Fragment&, glm::dvec4& color)>;

DrawStats draw(Planes& fb, const DrawState& state, Topology topology, const std::vector<Vertex>& vertices,
               const FragmentFunction& program = {});

// GL's per-fragment building blocks, exposed for the tests.
bool compare(CompareFunc func, double a, double b);
std::uint8_t stencilOp(StencilOp op, std::uint8_t s, std::uint8_t ref, std::uint8_t writeMask);
glm::dvec4 blend(const BlendState& state, const glm::dvec4& src, const glm::dvec4& dst);

}  // namespace clvr::raster::reference
