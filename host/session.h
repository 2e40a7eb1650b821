// host/session.h — one scene rendered for as many frames as a caller wants: scene -> data load -> camera
// fit -> device -> renderer -> frames -> stats, with the data resident across frames. `clvr render` and
// `clvr bench` are thin layers over it; a cluster layer or a language binding calls the same.
#pragma once

#include "host/model/camera.h"
#include "host/runtime/device.h"
#include "host/model/image.h"
#include "host/model/mesh.h"
#include "host/render/renderer.h"
#include "host/model/scene.h"
#include "host/model/volume.h"

#include <nlohmann/json.hpp>

#include <memory>
#include <string>

namespace clvr {

// The data a scene names, loaded on the host: a volume or a tetrahedral mesh (the other stays empty).
struct SceneData {
    Volume volume;
    TetMesh mesh;
    double loadMs = 0.0;  // wall time of the load
};

// Loads what scene.volume or scene.mesh names (paths resolved at parse time). InputError naming the file.
SceneData loadSceneData(const Scene& scene);

// The scene's camera, or one that fits its data's bounds (as clvr render always did). A part of a larger
// data set (Volume::part, TetMesh::part) must be given the whole data's camera.
Camera sceneCamera(const Scene& scene, const SceneData& data);

// The peak resident memory of this process so far, in bytes (getrusage; 0 where the system does not say):
// --stats' host_peak_bytes, per rank under MPI.
std::uint64_t hostPeakBytes();

// The CPU time this process (all its threads, PoCL's among them) has used so far, in milliseconds: a
// sort-last rank's own work where ranks share cores and its wall time counts the others' too.
double processCpuMs();

// One rendered frame: the image and what the frame did. stats.frameMs is the renderer's own time, or
// the wall time where the renderer reports none; stats.passes the device time of each named launch.
struct Frame {
    Image4f image;
    FrameStats stats;
    double wallMs = 0.0;  // host to host, this frame only (not the renderer's set-up)
};

// frame k of an n-frame orbit: the camera rotated by k * 360 / n degrees about the axis through its
// focal point along its view-up vector (right-handed), so the distance to the focal point is kept and
// view_up is unchanged. k % n == 0 returns `camera` itself, bit for bit. InputError for n < 1.
Camera orbitCamera(const Camera& camera, int k, int n);

// A scene set up on a device. The constructor loads the data (unless given), fits the camera to the
// data bounds when the scene has none, opens the device (unless given) and sets up the technique's
// renderer (upload, kernel builds; the Device's program cache keeps kernels across renderers).
//
// Camera changes: a renderer that can take a new view in place (Renderer::setCamera; slice3d, spherical,
// planes, blend and harc, the same image size) keeps its data on the device; any other is recreated from the
// data the Session keeps on the host, on the same device, with the programs already built (the data is uploaded
// again). Either way the images are those a new Session with that camera would give.
class Session {
public:
    // Loads the data, opens the device `deviceSpec` names (as Device's constructor), sets up the renderer.
    // `label` (the scene file, or "default scene") prefixes the InputErrors of the technique's options.
    Session(Scene scene, std::string label, const std::string& deviceSpec);
    // The same on a device the caller owns (it must outlive the Session), with data already loaded.
    Session(Device& device, Scene scene, SceneData data, std::string label);
    Session(const Session&) = delete;
    Session& operator=(const Session&) = delete;

    // Renders one frame with the current camera. Blocks until done. InternalError if the renderer returns an
    // image of another size than the scene's.
    Frame render();
    // The camera of the following frames (validated: InputError); the renderer takes it or is recreated (above).
    void setCamera(const Camera& camera);
    // The camera and the image size of the following frames (sort-first gives each rank a band of rows
    // as its image: Camera::bandFullHeight); as setCamera.
    void setView(const Camera& camera, const ImageSpec& image);

    const Scene& scene() const { return scene_; }
    const Camera& camera() const { return *scene_.camera; }
    const SceneData& data() const { return data_; }
    bool isMesh() const { return scene_.mesh.has_value(); }
    Device& device() { return *device_; }
    const Renderer& renderer() const { return *renderer_; }
    // Wall time of the latest renderer set-up (upload, kernel builds), in ms.
    double setupMs() const { return setupMs_; }
    // The --stats object of docs/cli.md for `frame`: technique, device, device_description, width, height,
    // frame_ms, compile_ms, load_ms, passes, samples, resident_bytes, voxels (volume scenes), then the
    // technique's own counts (FrameStats::extra), which never replace those keys. The caller adds what
    // only it knows (clvr render: scene, first_frame_ms, orbit frames).
    nlohmann::json stats(const Frame& frame) const;

private:
    void makeRenderer();

    std::unique_ptr<Device> ownedDevice_;  // null when the caller owns the device
    Device* device_ = nullptr;
    Scene scene_;
    SceneData data_;
    std::string label_;
    std::unique_ptr<Renderer> renderer_;
    double setupMs_ = 0.0;
};

}  // namespace clvr
