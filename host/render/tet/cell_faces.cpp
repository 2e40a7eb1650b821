// host/render/tet/cell_faces.cpp — faces wound outward, facing per camera, face vertices with cell ids.
#include "host/render/tet/cell_faces.h"

#include "host/runtime/errors.h"

#include <string>
#include <utility>

namespace clvr {

CellFaces::CellFaces(const TetMesh& mesh, const glm::dvec3& shift, const char* technique)
{
    if (mesh.tets.empty())
        throw InputError(mesh.source + ": " + technique + " needs a mesh with at least one tetrahedron");
    if (mesh.tets.size() > kMaxFaceCells)
        throw InputError(mesh.source + ": " + technique +
                         " takes at most 2^24 tetrahedra (cell ids in two 12-bit halves), got " +
                         std::to_string(mesh.tets.size()));
    points_.reserve(mesh.points.size());
    for (const glm::dvec3& p : mesh.points)
        points_.push_back(p - shift);
    faces_.resize(mesh.tets.size());
    for (std::size_t c = 0; c < mesh.tets.size(); ++c) {
        const glm::uvec4& t = mesh.tets[c];
        for (int i = 0; i < 4; ++i) {
            std::uint32_t a = t[(i + 1) % 4], b = t[(i + 2) % 4], v = t[(i + 3) % 4];
            const glm::dvec3 n = glm::cross(points_[b] - points_[a], points_[v] - points_[a]);
            if (glm::dot(n, points_[t[i]] - points_[a]) > 0.0)  // the normal points at the opposite vertex
                std::swap(b, v);
            faces_[c][3 * i] = a;
            faces_[c][3 * i + 1] = b;
            faces_[c][3 * i + 2] = v;
        }
    }
}

std::vector<std::uint8_t> CellFaces::backFacing(const Camera& camera) const
{
    const glm::dvec3 forward = camera.forward();
    std::vector<std::uint8_t> mask(faces_.size(), 0);
    for (std::size_t c = 0; c < faces_.size(); ++c)
        for (int i = 0; i < 4; ++i) {
            const glm::dvec3& a = points_[faces_[c][3 * i]];
            const glm::dvec3 n = glm::cross(points_[faces_[c][3 * i + 1]] - a, points_[faces_[c][3 * i + 2]] - a);
            const double facing = camera.parallel ? glm::dot(n, forward) : glm::dot(n, a - camera.position);
            if (facing > 0.0)
                mask[c] |= static_cast<std::uint8_t>(1u << i);
        }
    return mask;
}

void CellFaces::appendFaces(const std::vector<std::uint32_t>& cells, const std::vector<std::uint8_t>& backMask,
                            bool back, const std::vector<raster::Vertex>& pointVertex, unsigned idAttributes,
                            std::vector<raster::Vertex>& out) const
{
    out.reserve(out.size() + 6 * cells.size());  // a cell has about two back and two front faces: 6 vertices
    for (const std::uint32_t c : cells) {
        const float idLo = static_cast<float>(c & 0xfffu), idHi = static_cast<float>(c >> 12);
        for (int i = 0; i < 4; ++i) {
            if ((((backMask[c] >> i) & 1u) != 0) != back)
                continue;
            for (int j = 0; j < 3; ++j) {
                raster::Vertex v = pointVertex[faces_[c][3 * i + j]];
                for (std::size_t k = 0; k < v.attributes.size(); ++k)
                    if ((idAttributes >> k) & 1u) {
                        v.attributes[k].y = idLo;
                        v.attributes[k].z = idHi;
                    }
                out.push_back(v);
            }
        }
    }
}

}  // namespace clvr
