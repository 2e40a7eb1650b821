// tools/bench_mesh.h — the tetrahedral-mesh side of `clvr bench` (tools/bench.cpp): the figures of merit
// of seeds/001 Tables 2–3 computed from a frame's stats, the TetGen mesh cache for scenes whose mesh
// is meshed from a surface, and the files the VTK peer (tools/peer_vtk_unstructured.py) reads.
// docs/benchmarks.md says what each figure means.
#pragma once

#include "host/model/camera.h"
#include "host/model/mesh.h"
#include "host/model/scene.h"

#include <nlohmann/json.hpp>

#include <cstdint>
#include <filesystem>
#include <functional>
#include <string>

namespace clvr::tools {

// A mesh frame's figures. tets is the renderer's `tets_rendered` (the tetrahedra on the device, after
// degenerate ones are dropped: the count the paper multiplies by frames/s); steps its `steps` (cells
// entered by all rays of the frame); bytesPerTet its `bytes_per_tet` (everything resident / tets).
struct MeshFigures {
    std::uint64_t tets = 0;
    std::uint64_t steps = 0;
    double frameMs = 0.0;
    double fps = 0.0;          // 1000 / frameMs
    double tetsPerS = 0.0;     // tets * fps
    double stepsPerS = 0.0;    // steps / (frameMs / 1000)
    double bytesPerTet = 0.0;
};

// The figures of a frame with FrameStats::extra `extra` (needs tets_rendered, bytes_per_tet, and steps:
// harc's traversal steps, or for the cell-face techniques, which have none, cells_drawn — the cells
// drawn, summed over the frame's slices — and for projtet raster_fragments — each fragment integrates one
// ray segment, as a harc step does — as their unit of work) that took frameMs (the median steady frame).
// InputError naming a missing key or a frameMs <= 0.
MeshFigures meshFigures(const nlohmann::json& extra, double frameMs);

// The scene's mesh, loaded as `clvr render` loads it (host/io/mesh_io.h loadMesh), except that a mesh
// meshed from a surface ({"surface": ...}) is kept in cacheDir as TetGen BASE.{node,ele,neigh}, BASE =
// <scene stem>-<16 hex digits of meshCacheKey>: read from there when present, else meshed, written
// there (renamed into place, .node last) and returned. `progress` gets one line before meshing.
TetMesh loadBenchMesh(const Scene& scene, const std::string& name, const std::filesystem::path& cacheDir,
                      const std::function<void(const std::string&)>& progress);

// FNV-1a 64 of the surface spec's fields (path, quality, max_volume, scalar), the surface file's bytes
// and the scalar volume's bytes: a changed option or file meshes again. InputError when the surface
// cannot be read.
std::uint64_t meshCacheKey(const MeshSpec& spec);

// The cache folder: `bench-data` beside the clvr executable (build/bench-data for build/clvr).
std::filesystem::path defaultMeshCacheDir();

// What the peer renders: the mesh exactly as clvr loaded it (VTK legacy binary, scalar "scalars") at
// meshPath, and at scenePath a scene naming that file (absolute path), the camera clvr used (fitted
// when the scene has none), the image, the transfer function and the options: a valid clvr scene.
void writePeerMeshScene(const Scene& scene, const TetMesh& mesh, const Camera& camera,
                        const std::filesystem::path& meshPath, const std::filesystem::path& scenePath);

// A camera as scene JSON ("camera" object of DESIGN.md).
nlohmann::json cameraJson(const Camera& camera);

}  // namespace clvr::tools
