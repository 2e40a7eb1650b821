// tools/commands.cpp — command-line parsing (CLI11) and the info subcommand; render lives in
// tools/render_command.cpp, bench in tools/bench.cpp. docs/cli.md documents every option.
#include "tools/commands.h"

#include "host/runtime/device.h"
#include "host/runtime/errors.h"
#include "host/render/renderer.h"
#if __has_include("tools/bench.h")  // tools/bench.{h,cpp} land separately; without them no `bench`
#include "tools/bench.h"
#define CLVR_HAVE_BENCH 1
#else
#define CLVR_HAVE_BENCH 0
#endif

#include <CLI/CLI.hpp>

#include <algorithm>
#include <iostream>

namespace clvr::tools {
namespace {

// CLI11's messages, on one line (DESIGN.md: one error line).
std::string oneLine(std::string text)
{
    std::replace(text.begin(), text.end(), '\n', ' ');
    while (!text.empty() && text.back() == ' ')
        text.pop_back();
    return text;
}

int info(const std::string& deviceSpec)
{
    const auto devices = listDevices();
    if (devices.empty())
        throw DeviceError("no OpenCL device found (is an ICD such as pocl-opencl-icd installed?)");
    const DeviceListing used = chooseDevice(deviceSpec);
    for (const DeviceListing& d : devices)
        std::cout << (d.index == used.index ? "* " : "  ") << d.index << ": " << d.name << " [" << d.type << "] on "
                  << d.platform << ", " << d.version << ", " << d.computeUnits << " compute units, "
                  << (d.globalMemBytes >> 20) << " MiB\n";
    std::cout << "using device " << used.index << " (" << used.name << ")\n";
    return 0;
}

std::string techniqueList()
{
    std::string out;
    for (const std::string& name : techniqueNames())
        out += (out.empty() ? "" : ", ") + name;
    return out;
}

}  // namespace

// `clvr mesh` (tools/mesh_command.cpp).
CLI::App* addMeshCommand(CLI::App& app);
int runMeshCommand();

int run(int argc, char** argv)
{
    CLI::App app{"clvr: OpenCL volume renderer (docs/cli.md)", "clvr"};
    app.require_subcommand(1);
    app.set_version_flag("--version", "clvr 0.1.0");
    const std::string deviceHelp =
        "OpenCL device: index from `clvr info` or a case-insensitive substring of the platform or device name "
        "(default: $CLVR_DEVICE, else the first CPU device)";

    RenderOptions renderOptions;
    CLI::App* render = app.add_subcommand("render", "render one image of a scene");
    render->add_option("scene", renderOptions.scene,
                       "scene file (JSON, docs/scene-format.md); omitted or \"default\": the built-in "
                       "Marschner-Lobb scene");
    render->add_option("-o,--output", renderOptions.output, "output image, .png (8-bit) or .exr (float RGBA)")
        ->required();
    render->add_option("--set", renderOptions.overrides,
                       "override a scene value before validation: dotted.path=JSON (a plain string if not JSON), "
                       "e.g. --set camera.view_angle=20 --set technique=slice3d; repeatable")
        ->expected(1)
        ->allow_extra_args(false)
        ->multi_option_policy(CLI::MultiOptionPolicy::TakeAll);
    render->add_option("--device", renderOptions.deviceSpec, deviceHelp);
    render->add_option("--stats", renderOptions.statsPath, "write per-pass times and counts as JSON to this file");
    render->footer("techniques: " + techniqueList());

    std::string infoDevice;
    CLI::App* infoCommand = app.add_subcommand("info", "list OpenCL platforms and devices and say which one is used");
    infoCommand->add_option("--device", infoDevice, deviceHelp);

#if CLVR_HAVE_BENCH
    BenchOptions benchOptions;
    CLI::App* benchCommand = app.add_subcommand("bench", "run the benchmark scenes, print and write the figures");
    benchCommand->add_option("scenes", benchOptions.scenes,
                             "scene files (default: the --suite's scenes in data/scenes/bench/)");
    benchCommand->add_option("--suite", benchOptions.suite,
                             "without scene files: slice3d (slice3d-{ml256,engine}), harc (harc-bluntfin-{10,255}, "
                             "harc-bluntfin-10-full, harc-tetgen-1m), rts (rts-*: planes and blend, tools/make_rts_bench.py), "
                             "regular (reg-*: iso3d, stack2d, clipping, tools/make_regular_bench.py), all, or raster "
                             "(no scenes: the raster stage on 100,000 small triangles, tools/bench_raster.h)")
        ->check(CLI::IsMember({"slice3d", "harc", "rts", "regular", "all", "raster"}))
        ->capture_default_str();
    benchCommand->add_option("-o,--output", benchOptions.outJson, "figures as JSON; images go beside it")
        ->capture_default_str();
    benchCommand->add_option("--device", benchOptions.deviceSpec, deviceHelp);
    benchCommand->add_option("--frames", benchOptions.frames, "steady frames per scene after the first")
        ->check(CLI::Range(1, 100000))
        ->capture_default_str();
    benchCommand->add_flag("--peer", benchOptions.peer,
                           "also render each scene with VTK (tools/peer_vtk.py; meshes: tools/peer_vtk_unstructured.py)");
    benchCommand->add_option("--peer-frames", benchOptions.peerFrames, "the peer's steady frames (0: as --frames)")
        ->check(CLI::Range(0, 100000))
        ->capture_default_str();
    benchCommand->add_option("--set", benchOptions.overrides,
                             "override a value of every scene, path=json (e.g. options.integration=\"full\")");
    benchCommand->add_option("--mesh-cache", benchOptions.meshCache,
                             "folder for TetGen meshes of surface scenes (default: bench-data beside clvr)");
#endif

    CLI::App* meshCommand = addMeshCommand(app);

    // CLI11 would only say "A subcommand is required" for a misspelt one.
    const std::string first = argc > 1 ? argv[1] : "";
    if (!first.empty() && first[0] != '-' && first != "render" && first != "info" && first != "bench" &&
        first != "mesh")
        throw InputError("command line: unknown command \"" + std::string(argv[1]) +
                         "\" (known: render, info, bench, mesh; see clvr --help)");
    try {
        app.parse(argc, argv);
    } catch (const CLI::CallForHelp& e) {
        return app.exit(e);
    } catch (const CLI::CallForAllHelp& e) {
        return app.exit(e);
    } catch (const CLI::CallForVersion& e) {
        return app.exit(e);
    } catch (const CLI::ParseError& e) {
        throw InputError("command line: " + oneLine(e.what()) + " (see clvr --help)");
    }
    if (*render)
        return tools::render(renderOptions);
    if (*infoCommand)
        return info(infoDevice);
    if (*meshCommand)
        return runMeshCommand();
#if CLVR_HAVE_BENCH
    if (*benchCommand)
        return bench(benchOptions);
#endif
    return 0;
}

}  // namespace clvr::tools
