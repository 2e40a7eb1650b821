// host/io/tetgen_mesher.h — a tetrahedral mesh of a closed surface, made with TetGen linked as a library
// (tetgenio + tetrahedralize, built with TETLIBRARY), with a point scalar from a generator or sampled
// from a regular volume. `clvr mesh` (tools/mesh_command.cpp) writes the result as TetGen .node/.ele.
#pragma once

#include "host/model/mesh.h"

#include <filesystem>
#include <string>

namespace clvr {

struct MesherOptions {
    double quality = 0.0;    // > 0: TetGen -q (maximum radius-edge ratio, e.g. 1.414); 0: no quality bound
    double maxVolume = 0.0;  // > 0: TetGen -a (maximum tetrahedron volume); 0: none
    // A generator name (host/io/generators.h: "marschner-lobb", "sphere", "blobs"), evaluated at each point's
    // position, or a regular volume file (.nrrd/.nhdr) sampled trilinearly (positions clamped to its bounds).
    std::string scalar = "sphere";
};

// The TetGen switches the options give: always "p" (a PLC in; -q/-a without -p yield no mesh), "Q"
// (quiet), "z" (0-based), then "q<Q>" and "a<V>" when set.
std::string tetgenSwitches(const MesherOptions& options);

// Tetrahedralizes the closed surface in `surface` (.poly, .smesh, .off or .stl). InputError for an
// unreadable surface, a TetGen failure (with its code's meaning) or an empty result. The mesh is checked
// (checkMesh) and carries its scalar.
TetMesh meshSurface(const std::filesystem::path& surface, const MesherOptions& options);

// Sets mesh.scalars from `scalar` as MesherOptions::scalar describes.
void assignScalar(TetMesh& mesh, const std::string& scalar);

}  // namespace clvr
