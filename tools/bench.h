// tools/bench.h — `clvr bench`: steady-state speed of the benchmark scenes, the plain C++ ceiling
// loop and (with --peer) VTK on the same scenes, printed as a table and written as JSON.
// docs/benchmarks.md says what each figure means and how it is measured.
#pragma once

#include <string>
#include <vector>

namespace clvr::tools {

struct BenchOptions {
    std::vector<std::string> scenes;   // scene files; empty: data/scenes/bench/slice3d-{ml256,engine}.json
    std::string outJson = "bench.json";  // figures and machine info; images go beside it
    std::string deviceSpec;            // as --device (else $CLVR_DEVICE, else the first CPU device)
    int frames = 5;                    // steady frames after the first (at least 5 are taken)
    bool peer = false;                 // also render each scene with VTK (tools/peer_vtk.py)
};

// Runs the benchmark; returns the exit status (0). Throws InputError / DeviceError like `render`.
int bench(const BenchOptions& options);

}  // namespace clvr::tools
