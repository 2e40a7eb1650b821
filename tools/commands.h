// tools/commands.h — the clvr subcommands (render, info, bench), called from main().
#pragma once

#include <string>
#include <vector>

namespace clvr::tools {

// Parses the command line and runs one subcommand; returns the exit status. Throws the library's
// errors (InputError, DeviceError, BuildError) for main() to report.
int run(int argc, char** argv);

// `clvr render` (docs/cli.md).
struct RenderOptions {
    std::string scene;                   // scene file; empty or "default": the embedded default scene
    std::string output;                  // .png or .exr
    std::vector<std::string> overrides;  // --set path=json, applied in order
    std::vector<std::string> unsets;     // --unset path, applied before the overrides
    std::string deviceSpec;              // --device (else $CLVR_DEVICE, else the first CPU device)
    std::string statsPath;               // --stats: JSON with times and counts; empty: none
};

// Renders one image: checks the output paths, loads the scene and its data, opens the device, renders
// a first frame (compiles kernels) and a steady frame, writes the image (and the stats) atomically
// and prints one line to stdout. Returns 0; throws InputError / DeviceError / BuildError.
int render(const RenderOptions& options);

}  // namespace clvr::tools
