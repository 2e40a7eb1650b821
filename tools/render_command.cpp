// tools/render_command.cpp — `clvr render`: the command line over clvr::Session (host/session.h): one
// image, or with --orbit N a camera path of N frames, plus stats. Every check that can fail on bad input runs before the device is opened; outputs are written to a
// temporary file and renamed into place, so a failure never leaves a partial file (DESIGN.md).
#include "tools/commands.h"
#include "tools/render_output.h"
#if CLVR_HAVE_MPI
#include "host/cluster/world.h"
#endif

#include "host/runtime/device.h"
#include "host/runtime/errors.h"
#include "host/io/image_io.h"
#include "host/render/renderer.h"
#include "host/model/scene.h"
#include "host/render/scaffold.h"
#include "host/session.h"

#include <nlohmann/json.hpp>

#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <cctype>
#include <chrono>
#include <condition_variable>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <iostream>
#include <mutex>
#include <set>
#include <sstream>
#include <stop_token>
#include <thread>

namespace clvr::tools {

namespace fs = std::filesystem;

namespace {

using Clock = std::chrono::steady_clock;

}  // namespace

std::string lowerExtension(const fs::path& p)
{
    std::string ext = p.extension().string();
    std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return std::tolower(c); });
    return ext;
}

// Writes `text` to `path` through a temporary file in the same folder, renamed into place.
void writeFileAtomically(const std::string& path, const std::string& text)
{
    const fs::path target(path);
    std::string tempName = ".";  // hidden, beside the target, so the rename stays on one file system
    tempName += target.filename().string();
    tempName += ".tmp";
    tempName += std::to_string(::getpid());
    const fs::path temp = target.parent_path() / tempName;
    {
        std::ofstream out(temp, std::ios::binary | std::ios::trunc);
        out << text;
        out.close();
        if (!out) {
            std::error_code ec;
            fs::remove(temp, ec);
            throw InputError(path + ": cannot write the file");
        }
    }
    std::error_code ec;
    fs::rename(temp, target, ec);
    if (ec) {
        std::error_code ignored;
        fs::remove(temp, ignored);
        throw InputError(path + ": cannot rename the temporary file into place: " + ec.message());
    }
}

namespace {

// "\rclvr: rendering slice3d 512x512 ... 2.3 s" on stderr every 0.5 s once a render has taken a
// second, only when stderr is a terminal; setLabel() changes the text (frame k of N); the line is
// cleared when the guard goes out of scope (also while an exception unwinds, so the error line that
// main() prints stands alone).
class ProgressLine {
public:
    explicit ProgressLine(std::string text) : label_(std::move(text))
    {
        if (!::isatty(2))
            return;
        thread_ = std::jthread([this, t0 = Clock::now()](std::stop_token stop) {
            std::mutex m;
            std::condition_variable_any cv;
            std::unique_lock lock(m);
            const auto never = [] { return false; };  // wake only on timeout or stop
            cv.wait_for(lock, stop, std::chrono::seconds(1), never);
            while (!stop.stop_requested()) {
                std::fprintf(stderr, "\r\033[Kclvr: %s ... %.1f s", label().c_str(), msSince(t0) / 1000.0);
                std::fflush(stderr);
                printed_ = true;
                cv.wait_for(lock, stop, std::chrono::milliseconds(500), never);
            }
        });
    }
    ~ProgressLine()
    {
        if (!thread_.joinable())
            return;
        thread_.request_stop();
        thread_.join();
        if (printed_) {
            std::fputs("\r\033[K", stderr);
            std::fflush(stderr);
        }
    }
    ProgressLine(const ProgressLine&) = delete;
    ProgressLine& operator=(const ProgressLine&) = delete;

    void setLabel(std::string label)
    {
        const std::lock_guard lock(labelMutex_);
        label_ = std::move(label);
    }

private:
    std::string label()
    {
        const std::lock_guard lock(labelMutex_);
        return label_;
    }

    std::mutex labelMutex_;
    std::string label_;
    std::atomic<bool> printed_{false};
    std::jthread thread_;  // last: stopped and joined before the label goes
};

}  // namespace

// The --orbit output pattern: printf-style with exactly one integer conversion (%d, %i or %u, with flags,
// width and precision, e.g. %03d), "%%" for a literal percent sign. InputError otherwise.
void checkFramePattern(const std::string& pattern)
{
    const std::string bad = pattern + ": --orbit needs an output pattern with exactly one integer conversion "
                                      "such as %03d (and %% for a percent sign)";
    int conversions = 0;
    for (std::size_t i = 0; i < pattern.size(); ++i) {
        if (pattern[i] != '%')
            continue;
        if (++i < pattern.size() && pattern[i] == '%')
            continue;
        while (i < pattern.size() && std::strchr("-+ #0", pattern[i]) && pattern[i] != '\0')
            ++i;
        while (i < pattern.size() && std::isdigit(static_cast<unsigned char>(pattern[i])))
            ++i;
        if (i < pattern.size() && pattern[i] == '.')
            for (++i; i < pattern.size() && std::isdigit(static_cast<unsigned char>(pattern[i]));)
                ++i;
        if (i >= pattern.size() || !std::strchr("diu", pattern[i]) || pattern[i] == '\0')
            throw InputError(bad);
        ++conversions;
    }
    if (conversions != 1)
        throw InputError(bad);
}

// Frame k's file name from a pattern checkFramePattern accepted.
std::string framePath(const std::string& pattern, int k)
{
    const int size = std::snprintf(nullptr, 0, pattern.c_str(), k);
    std::string out(static_cast<std::size_t>(size) + 1, '\0');
    std::snprintf(out.data(), out.size(), pattern.c_str(), k);
    out.resize(static_cast<std::size_t>(size));
    return out;
}

// The image files the command writes: one, or one per orbit frame; each checked (format, writable
// folder, a name of its own) before anything is rendered.
std::vector<std::string> outputPaths(const RenderOptions& options)
{
    std::vector<std::string> paths;
    if (options.orbit == 0) {
        paths.push_back(options.output);
    } else {
        checkFramePattern(options.output);
        for (int k = 0; k < options.orbit; ++k)
            paths.push_back(framePath(options.output, k));
    }
    for (const std::string& path : paths) {
        const std::string ext = lowerExtension(path);
        if (ext != ".png" && ext != ".exr")
            throw InputError(path + ": unsupported image format \"" + ext + "\" (use .png or .exr)");
        checkWritable(path, "output");
    }
    std::set<std::string> seen;
    for (const std::string& path : paths)
        if (!seen.insert(path).second)
            throw InputError(options.output + ": two frames would both be written to " + path);
    return paths;
}


// One stderr note when checkMesh changed the mesh (docs/meshes.md): the counts are in --stats too.
void noteMeshRepairs(const FrameStats& stats)
{
    const auto count = [&](const char* key) { return stats.extra.value(key, std::uint64_t{0}); };
    const std::uint64_t dropped = count("tets_degenerate"), reoriented = count("tets_reoriented");
    if (dropped == 0 && reoriented == 0)
        return;
    std::cerr << "clvr: note: the mesh had " << dropped << " zero-volume tetrahedra (dropped) and " << reoriented
              << " inverted ones (reoriented); --stats has tets_degenerate and tets_reoriented\n";
}

// One stderr note when frame 0 is empty (alpha 0 everywhere): a silent all-background image is the most
// common surprise (the data outside the view, a transfer function transparent over the data's range,
// Cartesian data given to spherical), and the image alone cannot say which.
void noteEmptyImage(const Image4f& image, const std::string& technique)
{
    const auto& pixels = image.pixels();
    if (pixels.empty() || std::any_of(pixels.begin(), pixels.end(), [](const glm::vec4& p) { return p.a > 0.0f; }))
        return;
    std::cerr << "clvr: note: the image is empty (alpha 0 in every pixel): is the data in view, and is the transfer "
                 "function opaque anywhere in the data's range?"
              << (technique == "spherical" ? " spherical reads the volume's axes as (phi, theta, r), docs/spherical.md" : "")
              << '\n';
}

int render(const RenderOptions& options)
{
#if CLVR_HAVE_MPI
    if (cluster::launchedByMpi())
        return renderCluster(options);
#else
    if (const char* size = std::getenv("OMPI_COMM_WORLD_SIZE"); size && std::string(size) != "1")
        throw InputError("this clvr was built without MPI (CLVR_MPI=OFF): under mpirun every rank would render the "
                         "whole image; rebuild with libopenmpi-dev and paraview-dev installed (docs/cluster.md)");
#endif
    if (!options.distribution.empty())  // one process renders everything; the value must still be one
        checkDistribution(options.distribution, "--distribution");
    // 1. Outputs: a known format and a writable folder for every file, before anything expensive happens.
    if (options.orbit < 0)
        throw InputError("--orbit: the frame count must be at least 1, got " + std::to_string(options.orbit));
    const std::vector<std::string> outputs = outputPaths(options);
    if (!options.statsPath.empty())
        checkWritable(options.statsPath, "--stats");

    // 2. Scene, data, device and renderer (Session): every InputError names its file.
    const bool useDefault = options.scene.empty() || options.scene == "default";
    const std::string sceneLabel = useDefault ? "default scene" : options.scene;
    Scene scene = useDefault ? defaultScene(options.overrides, options.unsets)
                             : loadScene(options.scene, options.overrides, options.unsets);
    const std::string size = std::to_string(scene.image.width) + "x" + std::to_string(scene.image.height);
    const std::string label = "rendering " + scene.technique + " " + size;
    const int frameCount = static_cast<int>(outputs.size());
    auto progress =
        std::make_unique<ProgressLine>(frameCount > 1 ? label + ", frame 1 of " + std::to_string(frameCount) : label);
    Session session(std::move(scene), sceneLabel, options.deviceSpec);
    const Camera camera0 = session.camera();

    // 3. Frame 0: a first frame (finishes lazy set-up) and a steady one, or with --single-frame the first
    // only; then each orbit frame once, on a renderer set up for its camera; images written as they come.
    double firstFrameMs = session.setupMs();
    Frame frame0 = session.render();
    firstFrameMs += frame0.wallMs;
    if (!options.singleFrame)
        frame0 = session.render();
    WrittenFiles written;
    writeImage(outputs[0], frame0.image);
    written.add(outputs[0]);
    nlohmann::json frames = nlohmann::json::array();
    frames.push_back({{"index", 0}, {"output", outputs[0]}, {"frame_ms", frame0.stats.frameMs},
                      {"setup_ms", session.setupMs()}});
    for (int k = 1; k < frameCount; ++k) {
        progress->setLabel(label + ", frame " + std::to_string(k + 1) + " of " + std::to_string(frameCount));
        session.setCamera(orbitCamera(camera0, k, frameCount));
        const Frame frame = session.render();
        writeImage(outputs[static_cast<std::size_t>(k)], frame.image);
        written.add(outputs[static_cast<std::size_t>(k)]);
        frames.push_back({{"index", k}, {"output", outputs[static_cast<std::size_t>(k)]},
                          {"frame_ms", frame.stats.frameMs}, {"setup_ms", session.setupMs()}});
    }

    progress.reset();  // the line is cleared before the summary
    noteMeshRepairs(frame0.stats);
    noteEmptyImage(frame0.image, session.scene().technique);

    // 4. Stats, atomically; frame 0's figures at the top level as without --orbit.
    const FrameStats& steady = frame0.stats;
    if (!options.statsPath.empty()) {
        nlohmann::json stats = session.stats(frame0);
        stats["scene"] = useDefault ? std::string("default") : options.scene;
        stats["first_frame_ms"] = firstFrameMs;
        if (options.orbit > 0) {
            stats["orbit"] = options.orbit;
            stats["frames"] = frames;
        }
        writeFileAtomically(options.statsPath, stats.dump(2) + "\n");
    }
    written.keep();

    std::ostringstream line;
    line << "wrote " << options.output;
    if (options.orbit > 0)
        line << ": " << frameCount << " frames";
    line << " (" << size << ", " << session.scene().technique << ", " << std::fixed << std::setprecision(1)
         << steady.frameMs << " ms/frame)";
    std::cout << line.str() << std::endl;
    return 0;
}

void checkWritable(const std::string& path, const std::string& what)
{
    if (path.empty())
        throw InputError(what + " path is empty");
    const fs::path p(path);
    if (p.filename().empty() || p.filename() == "." || p.filename() == "..")
        throw InputError(path + ": " + what + " path names a directory, not a file");
    const fs::path dir = p.parent_path().empty() ? fs::path(".") : p.parent_path();
    std::error_code ec;
    if (!fs::is_directory(dir, ec))
        throw InputError(path + ": directory " + dir.string() + " does not exist");
    if (::access(dir.c_str(), W_OK) != 0)
        throw InputError(path + ": directory " + dir.string() + " is not writable");
    if (fs::is_directory(p, ec))
        throw InputError(path + ": is a directory");
}

}  // namespace clvr::tools
