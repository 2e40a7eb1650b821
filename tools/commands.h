// tools/commands.h — the clvr subcommands (render, info, bench), called from main().
#pragma once

#include <string>
#include <vector>

namespace clvr::tools {

// Parses the command line and runs one subcommand; returns the exit status. Throws the library's
// errors (InputError, DeviceError, BuildError) for main() to report.
int run(int argc, char** argv);

// InputError unless `path` names a file in an existing, writable directory ("PATH: directory D does not
// exist", ...); `what` names the option in the message. Every command checks its outputs before working.
void checkWritable(const std::string& path, const std::string& what);

// `clvr render` (docs/cli.md).
struct RenderOptions {
    std::string scene;                   // scene file; empty or "default": the embedded default scene
    std::string output;                  // .png or .exr
    std::vector<std::string> overrides;  // --set path=json, applied in order
    std::vector<std::string> unsets;     // --unset path, applied before the overrides
    std::string deviceSpec;              // --device (else $CLVR_DEVICE, else the first CPU device)
    std::string statsPath;               // --stats: JSON with times and counts; empty: none
    int orbit = 0;                       // --orbit N: N frames about view-up, `output` a %d pattern; 0: one image
    bool singleFrame = false;            // --single-frame: render once (no separate steady frame)
    std::string distribution;            // --distribution (MPI jobs): sort-last, sort-first, frames; empty: the scene's
    std::string balance = "cost";        // --balance (sort-last): cost (by estimated and measured work) or data
    double rebalanceAbove = 1.2;         // --rebalance-above: re-cut when the predicted slowest/mean passes it
    bool threadsGiven = false;           // --threads or $CLVR_THREADS set the thread budget
};

// Renders one image (or --orbit N frames) through clvr::Session: checks every output path, loads the
// scene and its data, opens the device, renders a first frame (compiles kernels) and, unless
// --single-frame, a steady frame; then each further orbit frame once; writes the images (and the stats)
// atomically and prints one line to stdout. Returns 0; throws InputError / DeviceError / BuildError.
int render(const RenderOptions& options);

// main() prints an error line unless quietErrors() was called: ranks other than 0 of an MPI job, which
// fail with the same agreed error as rank 0 (host/cluster/world.h), leave the line to rank 0.
void quietErrors();
bool errorsQuiet();

// `mpirun -np N clvr render` (docs/cluster.md): render() calls it when an MPI launcher started the
// process and clvr was built with CLVR_MPI. Same outputs and errors; every rank returns the same status.
int renderCluster(const RenderOptions& options);

}  // namespace clvr::tools
