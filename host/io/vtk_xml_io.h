// host/io/vtk_xml_io.h — the formats VTK's own readers read for clvr (ParaView's VTK, Debian's paraview-dev):
// VTK XML image data (.vti: ascii, binary and appended, raw/zlib/lz4/lzma) and its parallel form (.pvti),
// MetaImage (.mhd with its data file, .mha), VTK XML unstructured grids (.vtu) and their parallel form
// (.pvtu). No XML, base64 or zlib is parsed here: VTK reads, and this file checks what it read and turns it
// into clvr's Volume and TetMesh. In a build without VTK every function throws one InputError saying so.
// docs/data-formats.md lists what is accepted.
#pragma once

#include "host/model/mesh.h"
#include "host/model/volume.h"

#include <glm/glm.hpp>

#include <filesystem>
#include <optional>
#include <string>

namespace clvr {

// Whether this build links VTK's readers (CMake found ParaView's VTK; CLVR_HAVE_VTK).
bool haveVtkReaders();

// The grid a .vti, .pvti, .mhd or .mha file describes, read from its header alone (no voxel is read).
GridHeader readVtkImageHeader(const std::filesystem::path& path);

// A one-component point array of a .vti, .pvti, .mhd or .mha file as a Volume. `scalar` names the array;
// empty: the file's active scalars, else its first one-component point array. Cell data is not sampled:
// a file with cell arrays only gets an InputError naming them. Integer and float types convert to float
// (float64 is narrowed, as every reader does today). `region`, when given, is the grid points
// [lo, hi] (inclusive) to read: VTK reads only the pieces (.pvti) and the rows or compressed blocks
// (.vti) that hold them, so a sort-last rank reads its part of the file, not the whole (host/cluster/).
// The returned Volume then has the region's dims and origin; the caller places it in the whole (GridPart).
Volume readVtkImage(const std::filesystem::path& path, const std::string& scalar = "",
                    const std::optional<GridRegion>& region = std::nullopt);

// A .vtu or .pvtu unstructured grid as a TetMesh: tetrahedra as they are, hexahedra, voxels and wedges
// split as the legacy reader splits them (host/io/mesh_io.h), other cell types refused by name. `scalar`
// names a one-component point array; empty: the active scalars, else the first one. Not yet checked:
// loadMesh applies checkMesh.
TetMesh readVtkXmlUnstructured(const std::filesystem::path& path, const std::string& scalar = "");

}  // namespace clvr
