// tools/cluster_command.cpp — `mpirun -np N clvr render` (docs/cluster.md): one image (or --orbit frames)
// from N ranks, the same files and errors as one process.
//   sort-last: every rank loads its k-d part (host/cluster/partition.h), cut by the view's estimated work
//              and re-cut in an orbit when the ranks' times drift apart (host/cluster/balance.h), and
//              renders it with the scene's technique into premultiplied RGBA on a black background; IceT
//              composites the parts in the view's visibility order (host/cluster/compositor.h); rank 0
//              adds the background and writes.
//   sort-first: every rank holds the whole data and renders a band of image rows (Camera::bandFullHeight),
//              balanced by the previous frame's cost; rank 0 gathers the rows and writes.
//   frames:    frame k of --orbit N on rank k mod N; each rank writes its own frames.
// Every step that can fail runs inside World::agree, so a failure on any rank becomes the same error on
// every rank (rank 0 prints it, every rank exits with its status) and nobody waits in a collective.
#include "tools/commands.h"

#include "host/cluster/balance.h"
#include "host/cluster/compositor.h"
#include "host/cluster/partition.h"
#include "host/cluster/world.h"
#include "host/io/image_io.h"
#include "host/io/volume_io.h"
#include "host/model/scene.h"
#include "host/render/scaffold.h"
#include "host/runtime/device.h"
#include "host/runtime/errors.h"
#include "host/runtime/parallel.h"
#include "host/session.h"
#include "tools/render_output.h"

#include <nlohmann/json.hpp>

#include <algorithm>
#include <cstring>
#include <iomanip>
#include <iostream>
#include <memory>
#include <optional>
#include <sstream>
#include <thread>

namespace clvr::tools {
namespace {

using cluster::World;

// The rank's OpenCL device: --device or $CLVR_DEVICE when given, else the GPUs shared out by node-local
// rank, else the usual default (the first CPU device).
std::string rankDevice(const RenderOptions& options, const World& world)
{
    if (!options.deviceSpec.empty())
        return options.deviceSpec;
    if (const char* env = std::getenv("CLVR_DEVICE"); env && *env)
        return env;
    std::vector<DeviceListing> gpus;
    for (const DeviceListing& d : listDevices())
        if (d.type == "GPU")
            gpus.push_back(d);
    if (gpus.empty())
        return "";
    return std::to_string(gpus[static_cast<std::size_t>(world.nodeRank()) % gpus.size()].index);
}

// The job's distribution: --distribution, else the scene's, else frames with --orbit, else sort-last where
// the technique renders a part of the data and sort-first where it does not (`note` then says so). A
// sort-last asked for by name is kept: the technique's refusal is the error.
std::string distributionOf(const RenderOptions& options, const Scene& scene, std::string& note)
{
    if (!options.distribution.empty()) {
        checkDistribution(options.distribution, "--distribution");
        return options.distribution;
    }
    if (!scene.distribution.empty())
        return scene.distribution;
    if (options.orbit > 0)
        return "frames";
    if (const TechniqueInfo* t = findTechnique(scene.technique); t && !t->sortLast) {
        note = "clvr: note: " + t->name + " does not render a part of the data: sort-first (each rank renders image "
               "rows of the whole data; --distribution to choose)";
        return "sort-first";
    }
    return "sort-last";
}

struct Job {
    Scene scene;
    std::string sceneLabel;
    std::vector<std::string> outputs;
    std::string distribution;
};

// Rank 0, sort-last and sort-first: the job's --stats, rank 0's own frame-0 session stats (with the mode's
// own figures already in `stats`) plus the job's; nothing without --stats.
void writeImageJobStats(const RenderOptions& options, const World& world, const Job& job, nlohmann::json stats,
                        const nlohmann::json& frames, double frame0Ms)
{
    if (world.rank() != 0 || options.statsPath.empty())
        return;
    stats["scene"] = job.sceneLabel;
    stats["distribution"] = job.distribution;
    stats["ranks"] = world.size();
    stats["frame_ms"] = frame0Ms;
    stats["frames"] = frames;
    if (options.orbit > 0)
        stats["orbit"] = options.orbit;
    writeFileAtomically(options.statsPath, stats.dump(2) + "\n");
}

// Rank 0, sort-last and sort-first: the one line a finished job prints.
void printImageJobDone(const RenderOptions& options, const World& world, const Job& job, double frame0Ms)
{
    if (world.rank() != 0)
        return;
    std::ostringstream line;
    line << "wrote " << options.output;
    if (options.orbit > 0)
        line << ": " << job.outputs.size() << " frames";
    line << " (" << job.scene.image.width << "x" << job.scene.image.height << ", " << job.scene.technique << ", "
         << job.distribution << " on " << world.size() << " ranks, " << std::fixed << std::setprecision(1) << frame0Ms
         << " ms/frame)";
    std::cout << line.str() << std::endl;
}

// Frames: each rank renders and writes the orbit frames k with k mod size == rank.
int renderFrames(const RenderOptions& options, World& world, Job& job)
{
    const int count = static_cast<int>(job.outputs.size());
    WrittenFiles written;
    std::vector<double> frameMs(static_cast<std::size_t>(count), 0.0);
    std::unique_ptr<Session> session;
    world.agree([&] {
        if (world.rank() >= count)
            return;  // nothing to do: more ranks than frames
        session = std::make_unique<Session>(job.scene, job.sceneLabel, rankDevice(options, world));
        const Camera camera0 = session->camera();
        for (int k = world.rank(); k < count; k += world.size()) {
            if (k != 0)
                session->setCamera(orbitCamera(camera0, k, count));
            Frame frame = session->render();
            if (!options.singleFrame && k == world.rank())
                frame = session->render();  // the first frame builds kernels; time a steady one
            writeImage(job.outputs[static_cast<std::size_t>(k)], frame.image);
            written.add(job.outputs[static_cast<std::size_t>(k)]);
            frameMs[static_cast<std::size_t>(k)] = frame.stats.frameMs;
        }
    });
    std::vector<double> all = frameMs;
    for (int k = 0; k < count; ++k)
        all[static_cast<std::size_t>(k)] = world.maxOver(frameMs[static_cast<std::size_t>(k)]);
    world.agree([&] {
        if (world.rank() == 0 && !options.statsPath.empty()) {
            nlohmann::json frames = nlohmann::json::array();
            for (int k = 0; k < count; ++k)
                frames.push_back({{"index", k}, {"rank", k % world.size()}, {"output", job.outputs[static_cast<std::size_t>(k)]},
                                  {"frame_ms", all[static_cast<std::size_t>(k)]}});
            nlohmann::json stats = {{"scene", job.sceneLabel}, {"technique", job.scene.technique},
                                    {"distribution", "frames"}, {"ranks", world.size()}, {"frames", frames}};
            writeFileAtomically(options.statsPath, stats.dump(2) + "\n");
        }
    });
    written.keep();
    if (world.rank() == 0)
        std::cout << "wrote " << options.output << ": " << count << " frame" << (count == 1 ? "" : "s") << " on "
                  << world.size() << " ranks (" << job.scene.technique << ", frames)" << std::endl;
    return 0;
}

// Sort-last: each rank renders its part; IceT composites; rank 0 writes.
int renderSortLast(const RenderOptions& options, World& world, Job& job)
{
    const int count = static_cast<int>(job.outputs.size());
    const int width = job.scene.image.width, height = job.scene.image.height;
    std::unique_ptr<Device> device;
    std::unique_ptr<Session> session;
    std::optional<GridPartition> gridCut;  // the parts now rendered (one of the two)
    std::optional<MeshPartition> meshCut;
    std::optional<GridHeader> grid;  // the whole grid's points and placement, with gridCut
    bool readsRegions = false;       // the volume's format reads by regions: grid is its header
    KdTree tree;
    std::string partText;
    const bool byCost = options.balance != "data";
    // The grid's parts for `view` (after a measured frame, by the rates measured too: host/cluster/balance.h).
    const auto cutGrid = [&](const ViewCost& view, const MeasuredFrame* measured) {
        gridCut = byCost ? balanceGrid(grid->dims, grid->origin, grid->spacing, world.size(), view,
                                       gridCut ? &*gridCut : nullptr, measured)
                         : partitionGrid(grid->dims, grid->origin, grid->spacing, world.size());
        tree = gridCut->tree;
    };
    // This rank's part for the view `camera`, cut by its estimated work and, after a measured frame, by
    // the rates measured; `gridCut`/`meshCut` and `tree` set to the new cut. A volume whose format reads
    // by regions (raw, NRRD, Fortran-order .npy, .vti, .pvti, .mhd): the rank reads only its part's points,
    // placed as cutGridPart would cut them from the whole. Else every rank loads the whole data (or takes
    // `whole`, loaded already) and cuts out its part (the rest is freed here).
    const auto loadPart = [&](const Camera& camera, const MeasuredFrame* measured,
                              std::optional<SceneData> whole = std::nullopt) {
        const ViewCost view(camera, width, height);
        const int ghost = technique(job.scene.technique).sortLastGhost;
        SceneData data;
        if (readsRegions) {
            const auto t0 = std::chrono::steady_clock::now();
            cutGrid(view, measured);
            data.volume = loadVolumeRegion(*job.scene.volume, gridPartRegion(*gridCut, grid->dims, world.rank(), ghost));
            data.volume.part = gridPartPlacement(*gridCut, grid->dims, grid->origin, world.rank(), ghost);
            data.loadMs = msSince(t0);
            const glm::ivec3 n = data.volume.dims;
            partText = std::to_string(n.x) + "x" + std::to_string(n.y) + "x" + std::to_string(n.z) + " points read";
            return data;
        }
        data = whole ? std::move(*whole) : loadSceneData(job.scene);
        if (job.scene.mesh) {
            meshCut = byCost ? balanceMesh(data.mesh, world.size(), view, meshCut ? &*meshCut : nullptr, measured)
                             : partitionMesh(data.mesh, world.size());
            data.mesh = cutMeshPart(data.mesh, *meshCut, world.rank());
            tree = meshCut->tree;
            partText = std::to_string(data.mesh.tets.size()) + " tets";
        } else {
            grid = GridHeader{data.volume.dims, data.volume.spacing, data.volume.origin};
            cutGrid(view, measured);
            data.volume = cutGridPart(data.volume, *gridCut, world.rank(), ghost);
            const glm::ivec3 n = data.volume.dims;
            partText = std::to_string(n.x) + "x" + std::to_string(n.y) + "x" + std::to_string(n.z) + " points";
        }
        return data;
    };
    // The part's session for `camera`: premultiplied parts on black; the background goes on last.
    const auto startSession = [&](SceneData data, const Camera& camera) {
        Scene partScene = job.scene;
        partScene.camera = camera;
        partScene.image.background = glm::dvec3(0.0);
        session = std::make_unique<Session>(*device, partScene, std::move(data), job.sceneLabel);
    };
    double setupMs = 0.0;
    world.agree([&] {
        const auto t0 = std::chrono::steady_clock::now();
        // The whole data's camera, on every rank (it decides the cut): from the grid's header where the
        // format reads by regions, else from the whole data, loaded here and cut by loadPart.
        grid = job.scene.volume ? volumeHeader(*job.scene.volume) : std::nullopt;
        readsRegions = grid.has_value();
        SceneData data;
        if (readsRegions) {
            if (!job.scene.camera)
                job.scene.camera = fitCamera(grid->origin, grid->origin + glm::dvec3(grid->dims - 1) * grid->spacing);
            data = loadPart(*job.scene.camera, nullptr);
        } else {
            SceneData whole = loadSceneData(job.scene);
            job.scene.camera = sceneCamera(job.scene, whole);
            data = loadPart(*job.scene.camera, nullptr, std::move(whole));
        }
        device = std::make_unique<Device>(rankDevice(options, world));
        startSession(std::move(data), *job.scene.camera);
        setupMs = msSince(t0);
    });
    cluster::Compositor compositor(world, job.scene.image.width, job.scene.image.height);

    WrittenFiles written;
    nlohmann::json frames = nlohmann::json::array();
    nlohmann::json frame0Stats;
    double frame0Ms = 0.0, composite0Ms = 0.0;
    const Camera camera0 = *job.scene.camera;
    // What a rank's part costs: its render time, or where ranks share cores (more on the node than it
    // has hardware threads) its CPU time, since its wall time then counts the others' work too.
    const bool sharedCores = world.nodeSize() > static_cast<int>(std::thread::hardware_concurrency());
    std::vector<double> lastMs, lastCpuMs;  // the previous frame's render and CPU time per rank
    // Each part's estimated work for the previous frame's view (empty after a re-cut, until measured).
    std::vector<double> estimated;
    const auto partEstimates = [&](const ViewCost& view) {
        if (meshCut)  // each rank knows its own part's tetrahedra
            return world.allGather(meshPartWork(session->data().mesh, tree, world.rank(), view));
        return gridPartCosts(*gridCut, grid->origin, grid->spacing, [&](const glm::dvec3& p) { return view.density(p); });
    };
    int recuts = 0;
    for (int k = 0; k < count; ++k) {
        const Camera camera = orbitCamera(camera0, k, count);
        // Re-cut where the current parts would be out of balance for this frame's view: the previous
        // frame's per-rank times, over its estimate per part, are the rates by which this frame's
        // estimate predicts them, and then cuts (the old session freed first).
        const std::vector<double>& lastCost = sharedCores ? lastCpuMs : lastMs;
        bool recut = false;
        double recutMs = 0.0;
        if (byCost && k > 0 && world.size() > 1) {
            const ViewCost before(orbitCamera(camera0, k - 1, count), width, height), next(camera, width, height);
            if (estimated.empty())  // new parts: their estimate for the view they were measured in
                estimated = partEstimates(before);
            const std::vector<double> estimateNext = partEstimates(next);
            recut = predictedImbalance(estimated, estimateNext, lastCost) > options.rebalanceAbove;
            estimated = recut ? std::vector<double>{} : estimateNext;
            if (recut) {
                const auto t0 = std::chrono::steady_clock::now();
                world.agree([&] {
                    session.reset();
                    const MeasuredFrame measured{before, lastCost};
                    startSession(loadPart(camera, &measured), camera);
                });
                recutMs = msSince(t0);
                ++recuts;
            }
        }
        Frame frame;
        double cpuMs = 0.0;
        world.agree([&] {
            if (k != 0 && !recut)
                session->setCamera(camera);
            if (k == 0 && !options.singleFrame)
                session->render();  // the first frame builds kernels; time a steady one
            const double cpu0 = processCpuMs();
            frame = session->render();
            cpuMs = processCpuMs() - cpu0;
        });
        const auto t0 = std::chrono::steady_clock::now();
        Image4f image;
        world.agree([&] { image = compositor.composite(frame.image, tree.frontToBack(camera)); });
        const double compositeMs = msSince(t0);
        lastMs = world.allGather(frame.stats.frameMs);
        lastCpuMs = world.allGather(cpuMs);
        const double renderMs = *std::max_element(lastMs.begin(), lastMs.end());  // the slowest part
        world.agree([&] {
            if (world.rank() != 0)
                return;
            addBackground(image, job.scene.image.background);
            const std::string& path = job.outputs[static_cast<std::size_t>(k)];
            writeImage(path, image);
            written.add(path);
            nlohmann::json f = {{"index", k}, {"output", path}, {"render_ms", renderMs}, {"composite_ms", compositeMs},
                                {"frame_ms", renderMs + compositeMs}, {"render_ms_per_rank", lastMs},
                                {"render_cpu_ms_per_rank", lastCpuMs}, {"imbalance", imbalance(lastMs)},
                                {"cpu_imbalance", imbalance(lastCpuMs)}};
            if (recut)
                f["recut_ms"] = recutMs;  // the new parts' reads and set-up, before the frame
            frames.push_back(f);
            if (k == 0) {
                frame0Stats = session->stats(frame);
                frame0Ms = renderMs + compositeMs;
                composite0Ms = compositeMs;
                noteEmptyImage(image, job.scene.technique);
            }
        });
    }
    // Memory per rank (issue 37 goal 4): each rank's peak resident set and its most device bytes at once.
    const std::vector<double> hostPeaks = world.gather(static_cast<double>(hostPeakBytes()));
    const std::vector<double> devicePeaks = world.gather(static_cast<double>(device->deviceBytesPeak()));
    world.agree([&] {
        nlohmann::json stats = frame0Stats;  // rank 0's own part
        stats["host_peak_bytes_per_rank"] = hostPeaks;
        stats["device_peak_bytes_per_rank"] = devicePeaks;
        stats["rank0_part"] = partText;  // the last cut's
        stats["recuts"] = recuts;
        stats["setup_ms"] = setupMs;
        stats["composite_ms"] = composite0Ms;
        writeImageJobStats(options, world, job, stats, frames, frame0Ms);
    });
    written.keep();
    printImageJobDone(options, world, job, frame0Ms);
    return 0;
}

// Sort-first: each rank renders a band of rows of every frame with all the data; rank 0 gathers the rows.
int renderSortFirst(const RenderOptions& options, World& world, Job& job)
{
    const int count = static_cast<int>(job.outputs.size());
    const int width = job.scene.image.width, height = job.scene.image.height;
    std::unique_ptr<Device> device;
    std::unique_ptr<Session> session;
    std::vector<int> rows(static_cast<std::size_t>(world.size()), 0);
    std::vector<double> lastMs(static_cast<std::size_t>(world.size()), 0.0);
    const auto band = [&](const Camera& camera) {
        int y0 = 0;
        for (int r = 0; r < world.rank(); ++r)
            y0 += rows[static_cast<std::size_t>(r)];
        Camera c = camera;
        c.bandFullHeight = height;
        c.bandY0 = y0;
        ImageSpec image = job.scene.image;
        image.height = rows[static_cast<std::size_t>(world.rank())];
        return std::make_pair(c, image);
    };
    Camera camera0;
    world.agree([&] {
        if (height < world.size())
            throw InputError("sort-first needs at least one image row per rank: " + std::to_string(height) +
                             " rows for " + std::to_string(world.size()) + " ranks");
        SceneData data = loadSceneData(job.scene);
        camera0 = sceneCamera(job.scene, data);
        rows = balanceRows(height, rows, lastMs);
        auto [camera, image] = band(camera0);
        Scene bandScene = job.scene;
        bandScene.camera = camera;
        bandScene.image = image;
        device = std::make_unique<Device>(rankDevice(options, world));
        session = std::make_unique<Session>(*device, bandScene, std::move(data), job.sceneLabel);
    });
    WrittenFiles written;
    nlohmann::json frames = nlohmann::json::array();
    nlohmann::json frame0Stats;
    double frame0Ms = 0.0;
    for (int k = 0; k < count; ++k) {
        Frame frame;
        world.agree([&] {
            if (k != 0) {
                rows = balanceRows(height, rows, lastMs);
                auto [camera, image] = band(orbitCamera(camera0, k, count));
                session->setView(camera, image);
            }
            frame = session->render();
            if (k == 0 && !options.singleFrame)
                frame = session->render();  // the first frame builds kernels; time a steady one
        });
        lastMs = world.allGather(frame.stats.frameMs);
        const auto t0 = std::chrono::steady_clock::now();
        std::vector<float> mine(frame.image.pixelCount() * 4);
        std::memcpy(mine.data(), frame.image.pixels().data(), mine.size() * sizeof(float));
        const std::vector<float> all = world.gather(mine);
        const double gatherMs = msSince(t0);
        world.agree([&] {
            if (world.rank() != 0)
                return;
            Image4f image(width, height);
            if (all.size() != image.pixelCount() * 4)
                throw InternalError("sort-first: the ranks' rows do not add up to the image");
            std::memcpy(image.pixels().data(), all.data(), all.size() * sizeof(float));
            const std::string& path = job.outputs[static_cast<std::size_t>(k)];
            writeImage(path, image);
            written.add(path);
            const double renderMs = *std::max_element(lastMs.begin(), lastMs.end());  // the slowest band
            frames.push_back({{"index", k}, {"output", path}, {"render_ms", renderMs}, {"gather_ms", gatherMs},
                              {"frame_ms", renderMs + gatherMs}, {"render_ms_per_rank", lastMs}, {"rows_per_rank", rows}});
            if (k == 0) {
                frame0Stats = session->stats(frame);
                frame0Ms = renderMs + gatherMs;
                noteEmptyImage(image, job.scene.technique);
            }
        });
    }
    world.agree([&] {
        nlohmann::json stats = frame0Stats;  // rank 0's band
        stats["width"] = width;
        stats["height"] = height;
        writeImageJobStats(options, world, job, stats, frames, frame0Ms);
    });
    written.keep();
    printImageJobDone(options, world, job, frame0Ms);
    return 0;
}

}  // namespace

int renderCluster(const RenderOptions& options)
{
    World world(nullptr, nullptr);
    // Host threads: the budget shared by the ranks on a node unless --threads or $CLVR_THREADS said.
    if (!options.threadsGiven) {
        setThreadBudget(std::max(1, static_cast<int>(std::thread::hardware_concurrency()) / world.nodeSize()));
        passThreadBudgetToPocl();
    }
    try {
        Job job;
        std::string note;
        world.agree([&] {
            if (options.orbit < 0)
                throw InputError("--orbit: the frame count must be at least 1, got " + std::to_string(options.orbit));
            job.outputs = outputPaths(options);
            if (!options.statsPath.empty())
                checkWritable(options.statsPath, "--stats");
            const bool useDefault = options.scene.empty() || options.scene == "default";
            job.sceneLabel = useDefault ? "default scene" : options.scene;
            job.scene = useDefault ? defaultScene(options.overrides, options.unsets)
                                   : loadScene(options.scene, options.overrides, options.unsets);
            job.distribution = distributionOf(options, job.scene, note);
        });
        if (world.rank() == 0 && !note.empty())
            std::cerr << note << std::endl;
        if (job.distribution == "frames")
            return renderFrames(options, world, job);
        if (job.distribution == "sort-first")
            return renderSortFirst(options, world, job);
        return renderSortLast(options, world, job);
    } catch (...) {
        if (world.rank() != 0)
            quietErrors();  // the same error on every rank: rank 0 prints it
        throw;
    }
}

}  // namespace clvr::tools
