// host/model/data_spec.h — the scene's "volume" and "mesh" objects as typed specs (docs/scene-format.md),
// parsed and checked with the rest of the scene, paths already resolved against the scene's folder.
// No I/O here: host/io/volume_io.h loadVolume() and host/io/mesh_io.h loadMesh() read what they name.
#pragma once

#include <glm/glm.hpp>
#include <nlohmann/json_fwd.hpp>

#include <cstdint>
#include <filesystem>
#include <string>

namespace clvr {

// The sample types the readers convert from. Integers convert exactly to float up to 2^24.
enum class ScalarType : std::uint32_t { UInt8, Int8, Int16, UInt16, Int32, UInt32, Float32, Float64 };
enum class Endian : std::uint32_t { Little, Big };

// How a headerless raw file is laid out: x fastest, then y, then z; no padding between samples.
struct RawLayout {
    glm::ivec3 dims{0};                  // grid points per axis
    ScalarType type = ScalarType::UInt8;
    Endian endian = Endian::Little;      // of multi-byte samples
    glm::dvec3 spacing{1.0};             // world units between grid points
    glm::dvec3 origin{0.0};              // world position of grid point (0,0,0)
    std::uint64_t headerBytes = 0;       // skipped at the start of the file
    bool operator==(const RawLayout&) const = default;
};

// The scene's "volume": a generator, or a file in one of the formats host/io/volume_io.h reads.
struct VolumeSpec {
    // Vtk: legacy STRUCTURED_POINTS; VtkImage: .vti, .pvti, .mhd, .mha through VTK's readers.
    enum class Kind { Generator, Nrrd, Vtk, Raw, Npy, VtkImage };
    Kind kind = Kind::Generator;
    std::string generator;        // Kind::Generator: its name (host/io/generators.h checks it)
    glm::ivec3 dims{0};           // Kind::Generator: grid points per axis
    std::filesystem::path file;   // the file kinds: resolved against the scene's folder
    RawLayout raw;                // Kind::Raw: the layout "dims", "type", "endian", ... give;
                                  // Kind::Npy: only its spacing and origin (the file says the rest)
    std::string scalar;           // Kind::VtkImage: the point array's name; empty: the active scalars
    bool operator==(const VolumeSpec&) const = default;
};

// The scene's "mesh": a tetrahedral mesh file, a PLOT3D grid and solution, or a surface TetGen meshes.
struct MeshSpec {
    enum class Kind { File, Plot3d, Surface, Generator };
    Kind kind = Kind::File;
    std::filesystem::path file;   // File, Plot3d: the mesh (.node, .ele, .vtk, .off) or the PLOT3D grid
    std::filesystem::path qFile;  // Plot3d: the solution
    std::filesystem::path surface;  // Surface: .off, .stl, .poly or .smesh
    // The point scalar. File: a name or 0-based index as text, empty: the file's first; Plot3d:
    // density (default), momentum, energy or pressure; Surface: a generator name (default "sphere") or
    // a .nrrd/.nhdr file (resolved against the scene's folder).
    std::string scalar;
    double quality = 0.0;    // Surface: TetGen -q bound (> 0), 0: none
    double maxVolume = 0.0;  // Surface: TetGen -a bound (> 0), 0: none
    std::string generator;   // Generator: "automaton" (host/io/generators.h)
    int cells = 8000;        // Generator: living cells
    int grid = 40;           // Generator: cells per axis of the lattice
    bool operator==(const MeshSpec&) const = default;
};

// Parse the scene's "volume" / "mesh" object; paths relative to baseDir. InputError naming the key
// ("volume: \"dims\" ...", "scene: mesh.scalar ...") for a malformed spec; no file is opened.
VolumeSpec parseVolumeSpec(const nlohmann::json& spec, const std::filesystem::path& baseDir);
MeshSpec parseMeshSpec(const nlohmann::json& spec, const std::filesystem::path& baseDir);

}  // namespace clvr
