// host/io/volume_io.h — regular-volume input: NRRD (attached, detached, multi-file; raw, gzip, ascii),
// raw files with a stated layout, VTK legacy STRUCTURED_POINTS, and the scene's "volume" (a VolumeSpec).
// Every reader returns a validated Volume with values converted to float in data units, or throws a
// one-line InputError that names the file and what is wrong. docs/data-formats.md lists what is accepted.
#pragma once

#include "host/model/data_spec.h"
#include "host/model/volume.h"

#include <glm/glm.hpp>
#include <nlohmann/json_fwd.hpp>

#include <cstdint>
#include <filesystem>
#include <string>

namespace clvr {

// Bytes per sample of `type`.
std::size_t scalarSize(ScalarType type);

// Largest volume any reader accepts: 2^34 grid points (64 GiB of float values). A header that asks
// for more is almost certainly corrupt, and is rejected before anything is allocated.
inline constexpr std::uint64_t kMaxVoxels = std::uint64_t(1) << 34;

// Loads what the scene's "volume" names (host/model/data_spec.h; docs/scene-format.md lists the forms):
// a generator (host/io/generators.h), a NRRD, VTK STRUCTURED_POINTS or raw file.
Volume loadVolume(const VolumeSpec& spec);

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

}  // namespace clvr
