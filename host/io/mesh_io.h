// host/io/mesh_io.h — tetrahedral mesh input and output: TetGen .node/.ele, VTK legacy UNSTRUCTURED_GRID
// (ASCII and big-endian BINARY; tetrahedra, hexahedra and wedges), .off tetrahedral meshes, PLOT3D
// curvilinear grids (split into tetrahedra), and the scene's "mesh" (a MeshSpec). Every reader throws a
// one-line InputError that names the file (and line or cell) and what is wrong; counts are checked
// against the file's size before anything is allocated. docs/meshes.md lists what is accepted.
#pragma once

#include "host/model/data_spec.h"
#include "host/model/mesh.h"

#include <nlohmann/json_fwd.hpp>

#include <filesystem>
#include <string>

namespace clvr {

// Loads what the scene's "mesh" names (host/model/data_spec.h) and returns a checked mesh (checkMesh
// applied): a .node/.ele/.vtk/.off file, a PLOT3D grid with its q file, or a surface meshed with TetGen
// at load time (host/io/tetgen_mesher.h).
TetMesh loadMesh(const MeshSpec& spec);

// parseMeshSpec(spec, baseDir) then loadMesh (tests): {"file": ..., "scalar": ...}, {"file": ...,
// "q_file": ...}, {"surface": ..., "quality": Q, "max_volume": V, "scalar": ...}; docs/scene-format.md.
TetMesh loadMesh(const nlohmann::json& spec, const std::filesystem::path& baseDir);

// The readers return the mesh as read (tetsRead set), not yet checked: call checkMesh().
// `scalar` chooses the point scalar; empty: the first one the file has.

// TetGen: `path` is BASE.node, BASE.ele or BASE; reads BASE.node and BASE.ele. 0- or 1-based (as the
// first point's number says); `scalar` is the 0-based index of the node attribute (default 0).
TetMesh readTetgen(const std::filesystem::path& path, const std::string& scalar = "");

// VTK legacy DATASET UNSTRUCTURED_GRID, ASCII or BINARY (big-endian), file versions 2.0 to 5.1.
// Cell types 10 (tetra), 12 (hexahedron: 6 tetrahedra around the diagonal 0-6) and 13 (wedge:
// 3 tetrahedra, conforming by the smallest-point-index rule); others: InputError naming the type.
// `scalar` names a one-component point array (SCALARS or FIELD); empty: the first one.
TetMesh readVtkUnstructured(const std::filesystem::path& path, const std::string& scalar = "");

// .off tetrahedral mesh (docs/meshes.md): optional "OFF" line, "npoints ntets", point lines
// "x y z [s ...]", cell lines "a b c d" or "4 a b c d", 0-based. `scalar` is the 0-based index of the
// value after x y z (default 0).
TetMesh readOffTet(const std::filesystem::path& path, const std::string& scalar = "");

// PLOT3D single grid, binary big-endian, no record markers (whole-file layout as VTK's data uses it).
// Each hexahedral cell is split into 6 tetrahedra around its (i,j,k)-(i+1,j+1,k+1) diagonal, the same
// way in every cell, so the split is conforming. scalar: density (default), momentum (magnitude),
// energy, pressure = (gamma - 1) (E - |m|^2 / (2 rho)) with gamma = 1.4.
TetMesh readPlot3d(const std::filesystem::path& xyzPath, const std::filesystem::path& qPath,
                   const std::string& scalar = "density");

// Writers (tests and `clvr mesh`). TetGen: BASE.node (one attribute: the scalar) and BASE.ele, 0-based.
void writeTetgen(const TetMesh& mesh, const std::filesystem::path& base);
// VTK legacy UNSTRUCTURED_GRID of tetrahedra with the scalar as point SCALARS `scalarName` (float).
void writeVtkUnstructured(const TetMesh& mesh, const std::filesystem::path& path, bool binary,
                          const std::string& scalarName = "scalars");

}  // namespace clvr
