// host/render/tet/cell_faces.h — what the cell-face techniques (tetslice, tetiso; seeds/000 §4) draw:
// every tetrahedron's four faces wound counter-clockwise seen from outside, their facing for a camera,
// and the raster-stage vertices of a list of cells' back or front faces, each carrying its cell's id.
#pragma once

#include "host/model/camera.h"
#include "host/model/mesh.h"
#include "raster/rasterizer.h"

#include <glm/glm.hpp>

#include <array>
#include <cstdint>
#include <vector>

namespace clvr {

// Cell ids travel in two float channels as 12-bit halves (exact after rounding an interpolated constant).
inline constexpr std::uint32_t kMaxFaceCells = 1u << 24;

// The id channels' clear value in the face draws' frame buffer: no face passed at this pixel.
inline constexpr float kNoFace = -1.0f;

class CellFaces {
public:
    // The mesh relative to `shift` (float precision near the origin). InputError for an empty mesh or
    // more than kMaxFaceCells cells, naming `technique`.
    CellFaces(const TetMesh& mesh, const glm::dvec3& shift, const char* technique);

    std::size_t cellCount() const { return faces_.size(); }
    const std::vector<glm::dvec3>& points() const { return points_; }  // shifted
    // Point indices of face i (opposite vertex i) of cell c: faces()[c][3i .. 3i+2].
    const std::vector<std::array<std::uint32_t, 12>>& faces() const { return faces_; }

    // Bit i of result[c]: face i of cell c faces away from the eye of `camera` (shifted coordinates),
    // decided in double as GL's culling would, except that a face seen exactly edge-on counts as a front
    // face instead of being dropped.
    std::vector<std::uint8_t> backFacing(const Camera& camera) const;

    // Appends, for each cell in `cells`, its back faces (back = true) or its front faces (backMask from
    // backFacing): three vertices per face, copies of pointVertex[point] in which every attribute k with
    // bit k of `idAttributes` set has its y and z replaced by the cell id's low and high 12 bits.
    void appendFaces(const std::vector<std::uint32_t>& cells, const std::vector<std::uint8_t>& backMask, bool back,
                     const std::vector<raster::Vertex>& pointVertex, unsigned idAttributes,
                     std::vector<raster::Vertex>& out) const;

private:
    std::vector<glm::dvec3> points_;
    std::vector<std::array<std::uint32_t, 12>> faces_;
};

}  // namespace clvr
