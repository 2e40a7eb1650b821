// tools/bench.h — `clvr bench`: steady-state speed of the benchmark scenes, the plain C++ ceiling
// loop and (with --peer) VTK on the same scenes, printed as a table and written as JSON. Regular-grid
// scenes and tetrahedral-mesh scenes (tools/bench_mesh.h) alike.
// docs/benchmarks.md says what each figure means and how it is measured.
#pragma once

#include <filesystem>
#include <string>
#include <vector>

namespace clvr::tools {

struct BenchOptions {
    std::vector<std::string> scenes;   // scene files; empty: the suite's scenes (benchSuiteScenes)
    std::string suite = "slice3d";     // without scene files: "slice3d", "harc" or "all"
    std::string outJson = "bench.json";  // figures and machine info; images go beside it
    std::string deviceSpec;            // as --device (else $CLVR_DEVICE, else the first CPU device)
    int frames = 5;                    // steady frames after the first (at least 5 are taken)
    bool peer = false;                 // also render each scene with VTK (tools/peer_vtk.py, or
                                       // tools/peer_vtk_unstructured.py for mesh scenes)
    int peerFrames = 0;                // the peer's steady frames; 0: as many as clvr's
    std::string meshCache;             // TetGen meshes of surface scenes; empty: bench-data beside clvr
    std::vector<std::string> overrides;  // --set path=json, applied to every scene (as clvr render --set),
                                         // e.g. options.integration="full" on the harc suite
    std::vector<std::string> unsets;     // --unset path, removed from every scene before the overrides
    bool reference = false;            // regular-grid emission-absorption scenes: each image (and the peer's)
                                       // against the CPU reference integral (host/reference/reference_integral.h)
};

// The scene files (under data/scenes/bench/) a suite runs: "slice3d" -> slice3d-{ml256,engine}.json,
// "harc" -> harc-bluntfin-{10,255}.json and harc-tetgen-1m.json, "all" -> both. InputError otherwise.
std::vector<std::string> benchSuiteScenes(const std::string& suite);

// `relative` (a repository file such as data/scenes/bench/x.json) from the current folder, else from the
// folders above the clvr executable. InputError when neither has it.
std::filesystem::path repoFile(const std::filesystem::path& relative);

// --suite cluster (tools/bench_cluster.cpp): the scenes under mpirun on 1, 2 and 4 ranks, sort-last;
// render, composite and frame times per rank count, and each image against one rank's.
int benchCluster(const BenchOptions& options);

// Runs the benchmark; returns the exit status (0). Throws InputError / DeviceError like `render`.
int bench(const BenchOptions& options);

}  // namespace clvr::tools
