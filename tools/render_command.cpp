// tools/render_command.cpp — `clvr render`: scene -> volume -> device -> renderer -> image (+ stats).
// Every check that can fail on bad input runs before the device is opened; outputs are written to a
// temporary file and renamed into place, so a failure never leaves a partial file (DESIGN.md).
#include "tools/commands.h"

#include "host/runtime/device.h"
#include "host/runtime/errors.h"
#include "host/io/image_io.h"
#include "host/io/mesh_io.h"
#include "host/render/renderer.h"
#include "host/model/scene.h"
#include "host/model/volume.h"
#include "host/io/volume_io.h"

#include <nlohmann/json.hpp>

#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <cctype>
#include <chrono>
#include <condition_variable>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <iostream>
#include <mutex>
#include <sstream>
#include <stop_token>
#include <thread>

namespace clvr::tools {
namespace {

namespace fs = std::filesystem;
using Clock = std::chrono::steady_clock;

double msSince(Clock::time_point t0)
{
    return std::chrono::duration<double, std::milli>(Clock::now() - t0).count();
}

std::string lowerExtension(const fs::path& p)
{
    std::string ext = p.extension().string();
    std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return std::tolower(c); });
    return ext;
}

// The folder `path` will be written into must exist and be writable; checked before any rendering.
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

// "\rclvr: rendering slice3d 512x512 ... 2.3 s" on stderr every 0.5 s once a render has taken a
// second, only when stderr is a terminal; the line is cleared when the guard goes out of scope
// (also while an exception unwinds, so the error line that main() prints stands alone).
class ProgressLine {
public:
    explicit ProgressLine(std::string label)
    {
        if (!::isatty(2))
            return;
        thread_ = std::jthread([this, label = std::move(label), t0 = Clock::now()](std::stop_token stop) {
            std::mutex m;
            std::condition_variable_any cv;
            std::unique_lock lock(m);
            const auto never = [] { return false; };  // wake only on timeout or stop
            cv.wait_for(lock, stop, std::chrono::seconds(1), never);
            while (!stop.stop_requested()) {
                std::fprintf(stderr, "\rclvr: %s ... %.1f s", label.c_str(), msSince(t0) / 1000.0);
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

private:
    std::atomic<bool> printed_{false};
    std::jthread thread_;
};

nlohmann::json passesJson(const std::vector<PassTime>& passes)
{
    nlohmann::json out = nlohmann::json::array();
    for (const PassTime& p : passes)
        out.push_back({{"name", p.name}, {"ms", p.ms}});
    return out;
}

}  // namespace

int render(const RenderOptions& options)
{
    // 1. Outputs: a known format and a writable folder, before anything expensive happens.
    const std::string ext = lowerExtension(options.output);
    if (ext != ".png" && ext != ".exr")
        throw InputError(options.output + ": unsupported image format \"" + ext + "\" (use .png or .exr)");
    checkWritable(options.output, "output");
    if (!options.statsPath.empty())
        checkWritable(options.statsPath, "--stats");

    // 2. Scene and data: every InputError names its file.
    const bool useDefault = options.scene.empty() || options.scene == "default";
    const std::string sceneLabel = useDefault ? "default scene" : options.scene;
    Scene scene = useDefault ? defaultScene(options.overrides) : loadScene(options.scene, options.overrides);
    const Clock::time_point loadStart = Clock::now();
    Volume volume;
    if (!scene.volume.is_null())
        volume = loadVolume(scene.volume, scene.baseDir);
    TetMesh mesh;
    if (!scene.mesh.is_null())
        mesh = loadMesh(scene.mesh, scene.baseDir);
    const double loadMs = msSince(loadStart);
    if (!scene.camera && !scene.volume.is_null())
        scene.camera = fitCamera(volume.boundsMin(), volume.boundsMax());
    if (!scene.camera && !scene.mesh.is_null())
        scene.camera = fitCamera(mesh.boundsMin(), mesh.boundsMax());

    // 3. Device, set-up (upload, kernel builds) and a first frame; then one steady frame.
    Device device(options.deviceSpec);
    const std::string size = std::to_string(scene.image.width) + "x" + std::to_string(scene.image.height);
    FrameStats first, steady;
    double firstFrameMs = 0.0;
    Image4f image;
    std::unique_ptr<Renderer> renderer;
    {
        ProgressLine progress("rendering " + scene.technique + " " + size);
        const Clock::time_point t0 = Clock::now();
        try {
            renderer = scene.mesh.is_null() ? makeRenderer(device, scene, volume)
                                            : makeMeshRenderer(device, scene, mesh);
        } catch (const DeviceError&) {
            throw;
        } catch (const InputError& e) {  // technique or options: say which scene they came from
            throw InputError(sceneLabel + ": " + e.what());
        }
        image = renderer->render(first);
        firstFrameMs = msSince(t0);
        device.takePassTimes();
        const Clock::time_point t1 = Clock::now();
        image = renderer->render(steady);
        if (steady.frameMs <= 0.0)
            steady.frameMs = msSince(t1);
        if (steady.passes.empty())
            steady.passes = device.takePassTimes();
    }
    if (image.width() != scene.image.width || image.height() != scene.image.height)
        throw DeviceError("the renderer returned a " + std::to_string(image.width()) + "x" +
                          std::to_string(image.height()) + " image for a " + size + " scene");

    // 4. Outputs, each atomically.
    writeImage(options.output, image);
    if (!options.statsPath.empty()) {
        nlohmann::json stats = {
            {"technique", scene.technique},
            {"device", device.listing().name},
            {"device_description", device.description()},
            {"scene", useDefault ? std::string("default") : options.scene},
            {"width", scene.image.width},
            {"height", scene.image.height},
            {"frame_ms", steady.frameMs},
            {"compile_ms", device.compileMs()},
            {"first_frame_ms", firstFrameMs},
            {"load_ms", loadMs},
            {"passes", passesJson(steady.passes)},
            {"samples", steady.samples},
            {"resident_bytes", renderer->residentBytes()},
        };
        if (!scene.volume.is_null())
            stats["voxels"] = volume.voxelCount();
        for (const auto& [key, value] : steady.extra.items())
            if (!stats.contains(key))
                stats[key] = value;
        writeFileAtomically(options.statsPath, stats.dump(2) + "\n");
    }

    std::ostringstream line;
    line << "wrote " << options.output << " (" << size << ", " << scene.technique << ", " << std::fixed
         << std::setprecision(1) << steady.frameMs << " ms/frame)";
    std::cout << line.str() << std::endl;
    return 0;
}

}  // namespace clvr::tools
