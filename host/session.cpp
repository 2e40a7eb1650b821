// host/session.cpp — clvr::Session: one scene's data, device and renderer kept across frames.
#include "host/session.h"

#include "host/cluster/bricks.h"
#include "host/render/scaffold.h"
#include "host/runtime/errors.h"
#include "host/io/mesh_io.h"
#include "host/io/volume_io.h"

#include <sys/resource.h>
#include <time.h>

#include <chrono>
#include <cmath>
#include <numbers>
#include <utility>

namespace clvr {
namespace {

using Clock = std::chrono::steady_clock;

// Rodrigues' rotation of v by `angle` radians about the unit axis k.
glm::dvec3 rotate(const glm::dvec3& v, const glm::dvec3& k, double angle)
{
    const double c = std::cos(angle), s = std::sin(angle);
    return v * c + glm::cross(k, v) * s + k * (glm::dot(k, v) * (1.0 - c));
}

}  // namespace

Camera sceneCamera(const Scene& scene, const SceneData& data)
{
    if (scene.camera)
        return *scene.camera;
    if (scene.mesh)
        return fitCamera(data.mesh.boundsMin(), data.mesh.boundsMax());
    return fitCamera(data.volume.boundsMin(), data.volume.boundsMax());
}

SceneData loadSceneData(const Scene& scene)
{
    const Clock::time_point t0 = Clock::now();
    SceneData data;
    if (scene.volume)
        data.volume = loadVolume(*scene.volume);
    if (scene.mesh)
        data.mesh = loadMesh(*scene.mesh);
    data.loadMs = msSince(t0);
    return data;
}

Camera orbitCamera(const Camera& camera, int k, int n)
{
    if (n < 1)
        throw InputError("orbit: the frame count must be at least 1, got " + std::to_string(n));
    if (k % n == 0)
        return camera;
    const glm::dvec3 axis = glm::normalize(camera.viewUp);
    const double angle = 2.0 * std::numbers::pi * static_cast<double>(k % n) / static_cast<double>(n);
    Camera out = camera;
    out.position = camera.focalPoint + rotate(camera.position - camera.focalPoint, axis, angle);
    return out;
}

Session::Session(Scene scene, std::string label, const std::string& deviceSpec)
    : scene_(std::move(scene)), label_(std::move(label))
{
    data_ = loadSceneData(scene_);  // bad data is an InputError before any device is opened
    scene_.camera = sceneCamera(scene_, data_);
    ownedDevice_ = std::make_unique<Device>(deviceSpec);
    device_ = ownedDevice_.get();
    makeRenderer();
}

Session::Session(Device& device, Scene scene, SceneData data, std::string label)
    : device_(&device), scene_(std::move(scene)), data_(std::move(data)), label_(std::move(label))
{
    scene_.camera = sceneCamera(scene_, data_);
    makeRenderer();
}

void Session::makeRenderer()
{
    renderer_.reset();  // the old renderer's device buffers go before the new one's are allocated
    const Clock::time_point t0 = Clock::now();
    try {
        try {
            renderer_ = isMesh() ? makeMeshRenderer(*device_, scene_, data_.mesh)
                                 : clvr::makeRenderer(*device_, scene_, data_.volume);
        } catch (const DeviceError& e) {
            // A volume that does not fit one device allocation renders in bricks, where the technique
            // renders parts (host/cluster/bricks.h); anything else is the error it was.
            const TechniqueInfo* t = findTechnique(scene_.technique);
            if (isMesh() || data_.volume.part || !t || !t->sortLast || !isOutOfDeviceMemory(e))
                throw;
            renderer_ = makeBrickedRenderer(*device_, scene_, data_.volume);
        }
    } catch (const DeviceError&) {
        throw;
    } catch (const InputError& e) {  // technique or options: say which scene they came from
        throw InputError(label_ + ": " + e.what());
    }
    setupMs_ = msSince(t0);
}

Frame Session::render()
{
    Frame frame;
    device_->takePassTimes();  // set-up launches (uploads, tables) are not this frame's
    const Clock::time_point t0 = Clock::now();
    frame.image = renderer_->render(frame.stats);
    frame.wallMs = msSince(t0);
    if (frame.stats.frameMs <= 0.0)
        frame.stats.frameMs = frame.wallMs;
    if (frame.stats.passes.empty())
        frame.stats.passes = device_->takePassTimes();
    if (frame.image.width() != scene_.image.width || frame.image.height() != scene_.image.height)
        throw InternalError("the renderer returned a " + std::to_string(frame.image.width()) + "x" +
                          std::to_string(frame.image.height()) + " image for a " +
                          std::to_string(scene_.image.width) + "x" + std::to_string(scene_.image.height) +
                          " scene");
    return frame;
}

std::uint64_t hostPeakBytes()
{
    rusage usage{};  // Linux gives ru_maxrss in kilobytes
    return ::getrusage(RUSAGE_SELF, &usage) == 0 ? static_cast<std::uint64_t>(usage.ru_maxrss) * 1024 : 0;
}

double processCpuMs()
{
    timespec t{};
    return ::clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &t) == 0 ? t.tv_sec * 1e3 + t.tv_nsec * 1e-6 : 0.0;
}

nlohmann::json Session::stats(const Frame& frame) const
{
    nlohmann::json passes = nlohmann::json::array();
    for (const PassTime& p : frame.stats.passes)
        passes.push_back({{"name", p.name}, {"ms", p.ms}});
    nlohmann::json out = {
        {"technique", scene_.technique},
        {"device", device_->listing().name},
        {"device_description", device_->description()},
        {"width", scene_.image.width},
        {"height", scene_.image.height},
        {"frame_ms", frame.stats.frameMs},
        {"compile_ms", device_->compileMs()},
        {"load_ms", data_.loadMs},
        {"passes", passes},
        {"samples", frame.stats.samples},
        {"resident_bytes", renderer_->residentBytes()},
        // Memory as a figure (issue 37 goal 4): the process's peak resident set so far, and the device
        // buffers alive now and at most.
        {"host_peak_bytes", hostPeakBytes()},
        {"device_bytes", device_->deviceBytes()},
        {"device_peak_bytes", device_->deviceBytesPeak()},
    };
    if (!isMesh())
        out["voxels"] = data_.volume.voxelCount();
    for (const auto& [key, value] : frame.stats.extra.items())
        if (!out.contains(key))
            out[key] = value;
    return out;
}

void Session::setCamera(const Camera& camera)
{
    setView(camera, scene_.image);
}

void Session::setView(const Camera& camera, const ImageSpec& image)
{
    camera.validate();
    if (image.width < 1 || image.height < 1)
        throw InputError("image: width and height must be at least 1");
    scene_.camera = camera;
    scene_.image = image;
    // The renderer keeps its data where it can take a new view (Renderer::setCamera: slice3d, spherical, planes,
    // blend, harc); else a new one.
    const Clock::time_point t0 = Clock::now();
    if (renderer_ && renderer_->setCamera(scene_)) {
        setupMs_ = msSince(t0);
        return;
    }
    makeRenderer();
}

}  // namespace clvr
