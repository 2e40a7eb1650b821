// tools/commands.cpp — command-line parsing (CLI11) and the info and techniques subcommands; render lives in
// tools/render_command.cpp, bench in tools/bench.cpp. docs/cli.md documents every option.
#include "tools/commands.h"

#include "host/runtime/device.h"
#include "host/runtime/errors.h"
#include "host/runtime/parallel.h"
#include "host/render/renderer.h"
#if __has_include("tools/bench.h")  // tools/bench.{h,cpp} land separately; without them no `bench`
#include "tools/bench.h"
#define CLVR_HAVE_BENCH 1
#else
#define CLVR_HAVE_BENCH 0
#endif

#include <CLI/CLI.hpp>

#include <algorithm>
#include <cstdlib>
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

// The value an option's default is listed as: its JSON, or what the registry says happens.
std::string defaultShown(const OptionInfo& o)
{
    return o.defaultValue.is_null() ? "(" + o.defaultText + ")" : o.defaultValue.dump();
}

// `clvr techniques [NAME]`: every technique (or one) with its data kind, one line, and its options
// with defaults and one line each, from the registry (host/render/renderer.h).
int listTechniques(const std::string& name)
{
    if (!name.empty() && !findTechnique(name))
        throw InputError("technique: unknown technique \"" + name + "\" (known: " + techniqueList() + ")");
    for (const TechniqueInfo& t : techniques()) {
        if (!name.empty() && t.name != name)
            continue;
        std::cout << t.name << " (" << dataKindName(t.data) << "): " << t.description << '\n';
        std::size_t nameWidth = 0, defaultWidth = 0;
        for (const OptionInfo& o : t.options) {
            nameWidth = std::max(nameWidth, o.name.size());
            defaultWidth = std::max(defaultWidth, defaultShown(o).size());
        }
        for (const OptionInfo& o : t.options) {
            const std::string shown = defaultShown(o);
            std::cout << "  " << o.name << std::string(nameWidth - o.name.size() + 2, ' ') << shown
                      << std::string(defaultWidth - shown.size() + 2, ' ') << o.description << '\n';
        }
    }
    return 0;
}

// The thread budget (host/runtime/parallel.h): --threads, else $CLVR_THREADS, else one per hardware thread (and
// PoCL left to its own default). Set before the first OpenCL call, so that PoCL's CPU device reads it.
// Returns whether either set it.
bool applyThreadBudget(const std::string& threadsOption)
{
    const char* env = std::getenv("CLVR_THREADS");
    if (!threadsOption.empty())
        setThreadBudget(parseThreadCount(threadsOption, "--threads"));
    else if (env && *env)
        setThreadBudget(parseThreadCount(env, "CLVR_THREADS"));
    else
        return false;
    passThreadBudgetToPocl();
    return true;
}

bool quiet = false;

}  // namespace

void quietErrors()
{
    quiet = true;
}

bool errorsQuiet()
{
    return quiet;
}

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
    render->add_option("--unset", renderOptions.unsets,
                       "remove a scene key before --set and validation: dotted.path, e.g. --unset camera (the "
                       "fitted camera) or --unset options (the defaults); a key not in the scene is an error; repeatable")
        ->expected(1)
        ->allow_extra_args(false)
        ->multi_option_policy(CLI::MultiOptionPolicy::TakeAll);
    render->add_option("--device", renderOptions.deviceSpec, deviceHelp);
    render->add_option("--stats", renderOptions.statsPath, "write per-pass times and counts as JSON to this file");
    render->add_option("--orbit", renderOptions.orbit,
                       "render N frames, frame k with the camera rotated by k*360/N degrees about view-up through "
                       "the focal point; -o is then a printf pattern with one integer conversion, e.g. f%03d.png")
        ->check(CLI::Range(1, 100000));
    render->add_option("--distribution", renderOptions.distribution,
                       "under mpirun: sort-last (the data split over the ranks, images composited by IceT), "
                       "sort-first (image rows shared out, every technique) or frames (--orbit frames shared out); default: the scene's, else sort-last, "
                       "frames with --orbit (docs/cluster.md)");
    render->add_option("--balance", renderOptions.balance,
                       "under mpirun, sort-last: cut the data by work (cost: the view's estimated ray work, re-cut in "
                       "an orbit from the ranks' measured times; the default) or by size (data: equal parts, never "
                       "re-cut) (docs/cluster.md)")
        ->check(CLI::IsMember({"cost", "data"}));
    render->add_option("--rebalance-above", renderOptions.rebalanceAbove,
                       "under mpirun, sort-last with --balance cost: re-cut the parts before a frame when the slowest "
                       "rank is predicted to take more than X times the mean (default 1.2; 1: every frame)")
        ->check(CLI::Range(1.0, 1e9));
    render->add_flag("--single-frame", renderOptions.singleFrame,
                     "render once (by default a first frame and a steady frame are rendered; frame_ms is the steady one)");
    std::string threads;
    const std::string threadsHelp =
        "host threads and PoCL compute units to use (default: $CLVR_THREADS, else all cores; docs/cli.md)";
    render->add_option("--threads", threads, threadsHelp);
    render->footer("techniques: " + techniqueList() + " (clvr techniques lists their options)");

    std::string techniqueName;
    CLI::App* techniquesCommand =
        app.add_subcommand("techniques", "list the techniques with their options, defaults and one line each");
    techniquesCommand->add_option("name", techniqueName, "only this technique");

    std::string infoDevice;
    CLI::App* infoCommand = app.add_subcommand("info", "list OpenCL platforms and devices and say which one is used");
    infoCommand->add_option("--device", infoDevice, deviceHelp);
    infoCommand->add_option("--threads", threads, threadsHelp);

#if CLVR_HAVE_BENCH
    BenchOptions benchOptions;
    CLI::App* benchCommand = app.add_subcommand("bench", "run the benchmark scenes, print and write the figures");
    benchCommand->add_option("scenes", benchOptions.scenes,
                             "scene files (default: the --suite's scenes in data/scenes/bench/)");
    benchCommand->add_option("--suite", benchOptions.suite,
                             "without scene files: slice3d (slice3d-{ml256,engine}), harc (harc-bluntfin-{10,255}, "
                             "harc-bluntfin-10-full, harc-tetgen-1m), rts (rts-*: planes and blend, tools/make_rts_bench.py), "
                             "regular (reg-*: iso3d, stack2d, clipping, tools/make_regular_bench.py), tetfaces (tetfaces-*: "
                             "tetslice, tetiso, tools/make_tetfaces_bench.py), cubefan (cubefan-*: seeds/002 Figure 9 and "
                             "slice3d on its view, tools/make_cubefan_bench.py), projtet (projtet-* beside their harc twins: bluntfin, "
                             "the oxygen post, the 1 M-tet TetGen torus), accuracy (acc-*: slice3d per sample and pre-integrated over "
                             "slice counts, for --reference; tools/make_accuracy_bench.py), all, or raster "
                             "(no scenes: the raster stage on 100,000 small triangles, tools/bench_raster.h), or cluster "
                             "(mpirun -np 1, 2, 4 sort-last on reg-slice3d-ml256 and harc-bluntfin-10 or the scenes given; "
                             "docs/cluster.md)")
        ->check(CLI::IsMember({"slice3d", "harc", "rts", "regular", "tetfaces", "cubefan", "projtet", "accuracy", "all", "raster",
                                      "cluster"}))
        ->capture_default_str();
    benchCommand->add_option("-o,--output", benchOptions.outJson, "figures as JSON; images go beside it")
        ->capture_default_str();
    benchCommand->add_option("--device", benchOptions.deviceSpec, deviceHelp);
    benchCommand->add_option("--frames", benchOptions.frames, "steady frames per scene after the first")
        ->check(CLI::Range(1, 100000))
        ->capture_default_str();
    benchCommand->add_flag("--peer", benchOptions.peer,
                           "also render each scene with VTK (tools/peer_vtk.py; meshes: tools/peer_vtk_unstructured.py)");
    benchCommand->add_flag("--reference", benchOptions.reference,
                           "also compute each slice3d scene's CPU reference integral (once per volume, camera, transfer "
                           "function and size) and report the image error against it, the peer's too");
    benchCommand->add_option("--peer-frames", benchOptions.peerFrames, "the peer's steady frames (0: as --frames)")
        ->check(CLI::Range(0, 100000))
        ->capture_default_str();
    benchCommand->add_option("--set", benchOptions.overrides,
                             "override a value of every scene, path=json (e.g. options.integration=\"full\")");
    benchCommand->add_option("--unset", benchOptions.unsets,
                             "remove a key of every scene before --set, dotted.path (e.g. options)");
    benchCommand->add_option("--threads", threads, threadsHelp);
    benchCommand->add_option("--mesh-cache", benchOptions.meshCache,
                             "folder for TetGen meshes of surface scenes (default: bench-data beside clvr)");
#endif

    CLI::App* meshCommand = addMeshCommand(app);

    // CLI11 would only say "A subcommand is required" for a misspelt one.
    const std::string first = argc > 1 ? argv[1] : "";
    if (!first.empty() && first[0] != '-' && first != "render" && first != "info" && first != "bench" &&
        first != "mesh" && first != "techniques")
        throw InputError("command line: unknown command \"" + std::string(argv[1]) +
                         "\" (known: render, info, techniques, bench, mesh; see clvr --help)");
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
    renderOptions.threadsGiven = applyThreadBudget(threads);
    if (*render)
        return tools::render(renderOptions);
    if (*infoCommand)
        return info(infoDevice);
    if (*techniquesCommand)
        return listTechniques(techniqueName);
    if (*meshCommand)
        return runMeshCommand();
#if CLVR_HAVE_BENCH
    if (*benchCommand)
        return bench(benchOptions);
#endif
    return 0;
}

}  // namespace clvr::tools
