// host/io/cell_split.h — hexahedra and wedges as tetrahedra, the same way for every reader that meets them
// (VTK legacy and XML unstructured grids, PLOT3D), so that neighbouring cells split their shared faces
// alike and the mesh stays conforming.
#pragma once

#include <glm/glm.hpp>

#include <array>
#include <cstdint>
#include <vector>

namespace clvr {

// A hexahedron in VTK's vertex order (0-3 bottom, 4-7 top, 0-4 an edge) as the six tetrahedra around its
// diagonal 0-6, appended to `tets`. Applied with the same orientation in every cell of a structured grid,
// neighbouring cells choose the same diagonal on their shared face.
void splitHex(const std::array<std::uint32_t, 8>& v, std::vector<glm::uvec4>& tets);

// A wedge (VTK order: triangle 0 1 2, triangle 3 4 5, edges 0-3 1-4 2-5) as 3 tetrahedra by Dompierre et
// al.'s rule: every quadrilateral face is cut through its smallest point index, so neighbours agree.
void splitWedge(const std::array<std::uint32_t, 6>& w, std::vector<glm::uvec4>& tets);

}  // namespace clvr
