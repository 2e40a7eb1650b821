// host/io/volume_io.h — regular-volume input: NRRD (attached, detached, multi-file; raw, gzip, ascii),
// raw files with a stated layout, VTK legacy STRUCTURED_POINTS, and the scene's "volume" object.
// Every reader returns a validated Volume with values converted to float in data units, or throws a
// one-line InputError that names the file and what is wrong. docs/data-formats.md lists what is accepted.
#pragma once

#include "host/model/volume.h"

#include <glm/glm.hpp>
#include <nlohmann/json_fwd.hpp>

#include <cstdint>
#include <filesystem>
#include <string>

namespace clvr {

// The sample types the readers convert from. Integers convert exactly to float up to 2^24.
enum class ScalarType : std::uint32_t { UInt8, Int8, Int16, UInt16, Int32, UInt32, Float32, Float64 };
enum class Endian : std::uint32_t { Little, Big };

// Bytes per sample of `type`.
std::size_t scalarSize(ScalarType type);

// Largest volume any reader accepts: 2^34 grid points (64 GiB of float values). A header that asks
// for more is almost certainly corrupt, and is rejected before anything is allocated.
inline constexpr std::uint64_t kMaxVoxels = std::uint64_t(1) << 34;

// How a headerless raw file is laid out: x fastest, then y, then z; no padding between samples.
struct RawLayout {
    glm::ivec3 dims{0};                  // grid points per axis
    ScalarType type = ScalarType::UInt8;
    Endian endian = Endian::Little;      // of multi-byte samples
    glm::dvec3 spacing{1.0};             // world units between grid points
    glm::dvec3 origin{0.0};              // world position of grid point (0,0,0)
    std::uint64_t headerBytes = 0;       // skipped at the start of the file
};

// Loads the scene's "volume" object:
//   {"file": "x.nrrd"} or "x.nhdr" (NRRD), {"file": "x.vtk"} (VTK legacy STRUCTURED_POINTS),
//   {"file": "x.raw", "dims": [nx,ny,nz], "type": "uint8|int8|int16|uint16|int32|uint32|float32|float64",
//    "endian": "little|big", "spacing": [..] (opt), "origin": [..] (opt), "header_bytes": N (opt)},
//   {"generator": "marschner-lobb"|"sphere"|"blobs"|"atmosphere", "dims": [nx,ny,nz]} (host/io/generators.h).
// A file with "dims" is read as raw whatever its extension. Relative paths are relative to baseDir.
// Unknown keys and wrongly typed values throw InputError naming the key.
Volume loadVolume(const nlohmann::json& spec, const std::filesystem::path& baseDir);

// NRRD (http://teem.sourceforge.net/nrrd/format.html), 3D only (or 4D with a first axis of size 1).
Volume readNrrd(const std::filesystem::path& path);

// A headerless file laid out as `layout` says; the file must hold exactly headerBytes + the samples.
Volume readRaw(const std::filesystem::path& path, const RawLayout& layout);

// VTK legacy format, DATASET STRUCTURED_POINTS with one-component POINT_DATA SCALARS, ASCII or BINARY
// (big-endian, as VTK writes it).
Volume readVtkStructuredPoints(const std::filesystem::path& path);

}  // namespace clvr
