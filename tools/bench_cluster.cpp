// tools/bench_cluster.cpp — `clvr bench --suite cluster` (docs/cluster.md): each scene rendered sort-last by
// `mpirun -np N clvr render` for N = 1, 2, 4 on this machine, several runs each; from every run's --stats the
// steady frame's render time (the slowest rank's), IceT's composite time (blend and collection on rank 0)
// and their sum, with each rank count's image against one rank's. Then sort-first on 1, 2 and 4 ranks: an
// --orbit of kSortFirstFrames frames, each frame's bands balanced by the previous frame's cost; the median
// over frames 1.. of the slowest rank's render time and the row gather; frame 0 against 1 rank's. Then
// sort-last's balance on 4 ranks: the same orbit cut by data size (--balance data) and by work (--balance
// cost, re-cut when the ranks' times drift), each frame's slowest rank over the mean, by wall and by CPU
// time (the ranks share this machine's cores: a rank's CPU time is its own work). Each sort-last row keeps
// every rank's peak resident memory.
// tools/cluster_model.py fits the scaling model to the sort-last figures and projects it (docs/cluster.md).
#include "tools/bench.h"

#include "host/cluster/balance.h"
#include "host/io/image_io.h"
#include "host/runtime/errors.h"
#include "tools/bench_machine.h"

#include <nlohmann/json.hpp>

#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <fstream>
#include <iomanip>
#include <iostream>
#include <sstream>
#include <thread>

namespace clvr::tools {
namespace {

namespace fs = std::filesystem;

double median(std::vector<double> v)
{
    std::sort(v.begin(), v.end());
    return v.empty() ? 0.0 : v[v.size() / 2];
}

double maxDifference(const Image4f& a, const Image4f& b)
{
    if (a.width() != b.width() || a.height() != b.height())
        return INFINITY;
    double worst = 0.0;
    for (std::size_t i = 0; i < a.pixelCount(); ++i)
        for (int c = 0; c < 4; ++c)
            worst = std::max(worst, std::abs(double(a.pixels()[i][c]) - double(b.pixels()[i][c])));
    return worst;
}

// One `mpirun -np ranks clvr render` of the scene; its --stats.
nlohmann::json runRanks(const fs::path& scene, int ranks, const fs::path& image, const fs::path& stats,
                        const BenchOptions& options, const std::string& distribution = "sort-last", int orbit = 0,
                        const std::string& extra = "")
{
    std::ostringstream cmd;
    cmd << "mpirun --oversubscribe --bind-to none -np " << ranks << " '" << fs::read_symlink("/proc/self/exe").string()
        << "' render '" << scene.string() << "' --distribution " << distribution << " -o '" << image.string()
        << "' --stats '" << stats.string() << "'";
    if (orbit > 0)
        cmd << " --orbit " << orbit;
    cmd << extra;
    if (!options.deviceSpec.empty())
        cmd << " --device '" << options.deviceSpec << "'";
    for (const std::string& o : options.overrides)
        cmd << " --set '" << o << "'";
    for (const std::string& u : options.unsets)
        cmd << " --unset '" << u << "'";
    cmd << " > /dev/null";
    std::error_code ec;
    fs::remove(stats, ec);
    const int rc = std::system(cmd.str().c_str());
    std::ifstream in(stats);
    if (rc != 0 || !in)
        throw DeviceError("clvr bench --suite cluster: `" + cmd.str() + "` failed (status " + std::to_string(rc) + ")");
    return nlohmann::json::parse(in);
}

// One row of the table: render, composite (sort-first: gather) and frame ms, the speed-up over one rank's
// frame, the image against one rank's.
void printRow(const std::string& label, int ranks, double renderMs, double secondMs, double frameMs,
              double oneRankFrameMs, double diff)
{
    std::cout << std::left << std::setw(26) << label << std::right << std::setw(6) << ranks << std::fixed
              << std::setprecision(1) << std::setw(12) << renderMs << std::setw(14) << secondMs << std::setw(11)
              << frameMs << std::setprecision(2) << std::setw(10) << oneRankFrameMs / frameMs << std::scientific
              << std::setprecision(1) << std::setw(14) << diff << std::defaultfloat << '\n';
}

// Sort-first's orbit: frame 0 has equal bands, frames 1.. are balanced by the frame before (a turn of
// 360/kSortFirstFrames degrees between frames, so the cost moves a little, as in an interactive session).
constexpr int kSortFirstFrames = 12;

// Per frame of a run's stats: the slowest rank's time over the mean, of `key` (render_ms_per_rank or
// render_cpu_ms_per_rank).
std::vector<double> frameImbalances(const nlohmann::json& run, const std::string& key)
{
    std::vector<double> out;
    for (const nlohmann::json& f : run["frames"])
        out.push_back(imbalance(f[key].get<std::vector<double>>()));
    return out;
}

}  // namespace

int benchCluster(const BenchOptions& options)
{
#if !CLVR_HAVE_MPI
    (void)options;
    throw InputError("--suite cluster: this clvr was built without MPI (CLVR_MPI=OFF; docs/cluster.md)");
#else
    std::vector<fs::path> scenes(options.scenes.begin(), options.scenes.end());
    if (scenes.empty())
        for (const char* name : {"reg-slice3d-ml256.json", "harc-bluntfin-10.json", "slice3d-engine.json"})
            scenes.push_back(repoFile(fs::path("data/scenes/bench") / name));
    const int runs = std::max(3, options.frames / 2);  // each run: a first frame and a steady one
    const fs::path outJson = options.outJson;
    const fs::path outDir = outJson.has_parent_path() ? outJson.parent_path() : fs::path(".");
    fs::create_directories(outDir);
    if (::geteuid() == 0) {  // Open MPI refuses root without these (../shared/CLUSTER-NOTES.md)
        ::setenv("OMPI_ALLOW_RUN_AS_ROOT", "1", 0);
        ::setenv("OMPI_ALLOW_RUN_AS_ROOT_CONFIRM", "1", 0);
    }
    nlohmann::json report;
    report["machine"] = {{"cpu", cpuModel()}, {"cores", std::thread::hardware_concurrency()}, {"date", utcNow()},
                         {"load_average_start", loadAverage()}};
    report["runs"] = runs;
    report["scenes"] = nlohmann::json::array();
    std::cout << "clvr bench --suite cluster: " << cpuModel() << ", " << std::thread::hardware_concurrency()
              << " cores, " << utcNow() << ", load average " << loadAverage() << "\n\n";
    // (sort-first rows: the composite column holds the gather of the rows on rank 0)
    std::cout << std::left << std::setw(26) << "scene" << std::right << std::setw(6) << "ranks" << std::setw(12)
              << "render ms" << std::setw(14) << "composite ms" << std::setw(11) << "frame ms" << std::setw(10)
              << "speed-up" << std::setw(14) << "max |diff|" << '\n';
    for (const fs::path& scene : scenes) {
        const std::string name = scene.stem().string();
        nlohmann::json entry = {{"scene", scene.string()}, {"ranks", nlohmann::json::array()}};
        Image4f oneRank;
        double oneRankFrame = 0.0;
        for (int ranks : {1, 2, 4}) {
            const fs::path image = outDir / ("bench.cluster." + name + ".n" + std::to_string(ranks) + ".exr");
            const fs::path stats = outDir / ("bench.cluster." + name + ".n" + std::to_string(ranks) + ".json");
            std::vector<double> render, composite, frame;
            nlohmann::json last;
            for (int r = 0; r < runs; ++r) {
                last = runRanks(scene, ranks, image, stats, options);
                render.push_back(last["frames"][0]["render_ms"].get<double>());
                composite.push_back(last["frames"][0]["composite_ms"].get<double>());
                frame.push_back(last["frames"][0]["frame_ms"].get<double>());
            }
            const Image4f picture = readImage(image.string());
            if (ranks == 1) {
                oneRank = picture;
                oneRankFrame = median(frame);
            }
            const double diff = maxDifference(picture, oneRank);
            const nlohmann::json row = {{"ranks", ranks},
                                        {"render_ms", median(render)},
                                        {"composite_ms", median(composite)},
                                        {"frame_ms", median(frame)},
                                        {"render_ms_runs", render},
                                        {"composite_ms_runs", composite},
                                        {"render_ms_per_rank", last["frames"][0]["render_ms_per_rank"]},
                                        {"render_cpu_ms_per_rank", last["frames"][0]["render_cpu_ms_per_rank"]},
                                        {"host_peak_bytes_per_rank", last["host_peak_bytes_per_rank"]},
                                        {"device_peak_bytes_per_rank", last["device_peak_bytes_per_rank"]},
                                        {"setup_ms", last["setup_ms"]},
                                        {"width", last["width"]},
                                        {"height", last["height"]},
                                        {"max_diff_vs_one_rank", diff}};
            entry["ranks"].push_back(row);
            printRow(name, ranks, median(render), median(composite), median(frame), oneRankFrame, diff);
        }
        // Sort-first: the frames after the first, each balanced by the one before; frame 0's image (the
        // scene's camera, equal bands) against one rank's.
        entry["sort_first"] = nlohmann::json::array();
        Image4f firstOneRank;
        double firstOneRankFrame = 0.0;
        for (int ranks : {1, 2, 4}) {
            const std::string base = "bench.cluster." + name + ".first.n" + std::to_string(ranks);
            const fs::path stats = outDir / (base + ".json");
            const nlohmann::json run =
                runRanks(scene, ranks, outDir / (base + ".%02d.exr"), stats, options, "sort-first", kSortFirstFrames);
            std::vector<double> render, gather, frame;
            for (std::size_t k = 1; k < run["frames"].size(); ++k) {
                render.push_back(run["frames"][k]["render_ms"].get<double>());
                gather.push_back(run["frames"][k]["gather_ms"].get<double>());
                frame.push_back(run["frames"][k]["frame_ms"].get<double>());
            }
            const Image4f picture = readImage((outDir / (base + ".00.exr")).string());
            if (ranks == 1) {
                firstOneRank = picture;
                firstOneRankFrame = median(frame);
            }
            const double diff = maxDifference(picture, firstOneRank);
            entry["sort_first"].push_back({{"ranks", ranks},
                                           {"render_ms", median(render)},
                                           {"gather_ms", median(gather)},
                                           {"frame_ms", median(frame)},
                                           {"frames", run["frames"]},
                                           {"max_diff_vs_one_rank", diff}});
            printRow(name + " (sort-first)", ranks, median(render), median(gather), median(frame), firstOneRankFrame,
                     diff);
        }
        // Sort-last's balance: 4 ranks, the orbit cut by data size and by work.
        entry["sort_last_balance"] = nlohmann::json::array();
        for (const char* balance : {"data", "cost"}) {
            const std::string base = "bench.cluster." + name + ".balance-" + balance;
            const nlohmann::json run = runRanks(scene, 4, outDir / (base + ".%02d.exr"), outDir / (base + ".json"),
                                                options, "sort-last", kSortFirstFrames,
                                                std::string(" --balance ") + balance);
            const std::vector<double> wall = frameImbalances(run, "render_ms_per_rank");
            const std::vector<double> cpu = frameImbalances(run, "render_cpu_ms_per_rank");
            std::vector<double> slowest, recutMs;
            for (const nlohmann::json& f : run["frames"]) {
                slowest.push_back(f["render_ms"].get<double>());
                if (f.contains("recut_ms"))
                    recutMs.push_back(f["recut_ms"].get<double>());
            }
            entry["sort_last_balance"].push_back(
                {{"balance", balance}, {"ranks", 4}, {"frames", run["frames"]}, {"recuts", run["recuts"]},
                 {"cpu_imbalance_median", median(cpu)}, {"cpu_imbalance_max", *std::max_element(cpu.begin(), cpu.end())},
                 {"wall_imbalance_median", median(wall)},
                 {"wall_imbalance_max", *std::max_element(wall.begin(), wall.end())},
                 {"render_ms_median", median(slowest)}, {"recut_ms_median", median(recutMs)}});
            std::cout << std::left << std::setw(26) << (name + " (balance " + balance + ")") << std::right << std::fixed
                      << std::setprecision(2) << "  4 ranks, " << kSortFirstFrames << " frames: slowest/mean cpu median "
                      << median(cpu) << " max " << *std::max_element(cpu.begin(), cpu.end()) << ", wall median "
                      << median(wall) << " max " << *std::max_element(wall.begin(), wall.end()) << "; render "
                      << std::setprecision(1) << median(slowest) << " ms; " << run["recuts"].get<int>() << " re-cuts ("
                      << median(recutMs) << " ms)" << std::defaultfloat << '\n';
        }
        report["scenes"].push_back(entry);
    }
    report["machine"]["load_average_end"] = loadAverage();
    std::ofstream(outJson) << report.dump(2) << '\n';
    std::cout << "\nwrote " << outJson.string() << '\n';
    return 0;
#endif
}

}  // namespace clvr::tools
