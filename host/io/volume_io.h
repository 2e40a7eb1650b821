// host/io/volume_io.h — regular-volume input: NRRD (attached, detached, multi-file; raw, gzip, ascii),
// raw files with a stated layout, VTK legacy STRUCTURED_POINTS, numpy .npy, and the scene's "volume" (a
// VolumeSpec); .vti/.pvti/.mhd/.mha go to VTK's readers (host/io/vtk_xml_io.h).
// Every reader returns a validated Volume with values converted to float in data units, or throws a
// one-line InputError that names the file and what is wrong. docs/data-formats.md lists what is accepted.
#pragma once

#include "host/model/data_spec.h"
#include "host/model/volume.h"

#include <glm/glm.hpp>
#include <nlohmann/json_fwd.hpp>

#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>

namespace clvr {

// Bytes per sample of `type`.
std::size_t scalarSize(ScalarType type);

// Largest volume any reader accepts: 2^34 grid points (64 GiB of float values). A header that asks
// for more is almost certainly corrupt, and is rejected before anything is allocated.
inline constexpr std::uint64_t kMaxVoxels = std::uint64_t(1) << 34;

// Loads what the scene's "volume" names (host/model/data_spec.h; docs/scene-format.md lists the forms):
// a generator (host/io/generators.h), a NRRD, VTK STRUCTURED_POINTS, raw or .npy file, or a file VTK's
// readers take (.vti, .pvti, .mhd, .mha).
Volume loadVolume(const VolumeSpec& spec);

// What the spec's header says of its grid, for the kinds loadVolumeRegion reads a part of: raw, .npy in
// Fortran order, NRRD with raw encoding in one data stream (attached or one detached file), and VTK's
// formats (.vti, .pvti, .mhd, .mha). nullopt for the others (NRRD gzip, ascii or in several files, VTK
// legacy, C-order .npy, generators), which a caller loads whole and cuts. InputError for a bad header.
std::optional<GridHeader> volumeHeader(const VolumeSpec& spec);

// The grid points `region` of the volume `spec` names, read alone: only those rows (raw, .npy) or the
// pieces and blocks that hold them (VTK's formats) are read. The Volume has the region's dims and origin
// (its `part` left for the caller to set). Only for specs volumeHeader() answers; the region must lie in
// the grid (InternalError otherwise).
Volume loadVolumeRegion(const VolumeSpec& spec, const GridRegion& region);

// parseVolumeSpec(spec, baseDir) then loadVolume: for specs that are not part of a scene (tests, the
// clip mask of options.clip). Unknown keys and wrongly typed values throw InputError naming the key.
Volume loadVolume(const nlohmann::json& spec, const std::filesystem::path& baseDir);

// NRRD (http://teem.sourceforge.net/nrrd/format.html), 3D only (or 4D with a first axis of size 1).
Volume readNrrd(const std::filesystem::path& path);

// A headerless file laid out as `layout` says; the file must hold exactly headerBytes + the samples.
Volume readRaw(const std::filesystem::path& path, const RawLayout& layout);

// VTK legacy format, DATASET STRUCTURED_POINTS with one-component POINT_DATA SCALARS, ASCII or BINARY
// (big-endian, as VTK writes it).
Volume readVtkStructuredPoints(const std::filesystem::path& path);

// numpy's .npy (versions 1-3): a 3-D array indexed [x, y, z] (as pyvista's and VTK's dimensions), of
// uint8, int8, uint16, int16, uint32, int32, float32 or float64, either byte order, C or Fortran order.
// The file holds no geometry: `spacing` and `origin` come from the scene.
Volume readNpy(const std::filesystem::path& path, const glm::dvec3& spacing = glm::dvec3(1.0),
               const glm::dvec3& origin = glm::dvec3(0.0));

}  // namespace clvr
