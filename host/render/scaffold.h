// host/render/scaffold.h — the pieces every renderer's set-up and frame share, so that a technique is
// its kernel, its renderer (what is particular to it) and its test:
//   set-up:  checkGridVolume (regular grids), frameCamera (the image size and the camera, or the camera
//            fitted to the data), the transfer function's upload (host/render/transfer_function_upload.h);
//   frame:   FrameClock (wall time of a frame), readImage and sumCounts (read-back of the image and of
//            per-pixel counters), finishFrame (pass times and frame time into FrameStats).
#pragma once

#include "host/model/camera.h"
#include "host/model/image.h"
#include "host/model/mesh.h"
#include "host/model/scene.h"
#include "host/model/volume.h"
#include "host/render/renderer.h"
#include "host/runtime/device.h"

#include <chrono>
#include <cstddef>
#include <cstdint>
#include <string_view>
#include <vector>

namespace clvr {

// The checks every regular-grid technique makes of its volume: consistent (Volume::validate) and at
// most 2^32 - 1 grid points, since kernels index voxels with 32 bits. InputError naming the volume's
// source and `technique`.
void checkGridVolume(const Volume& volume, std::string_view technique);

// The camera of a frame: the scene's, else one fitted to the data's box [lo, hi] (fitCamera); checked
// (Camera::validate). Also checks the scene's image size (>= 1 each way; parseScene already holds it in
// 1..16384, a scene built in code may not). InputError for either.
Camera frameCamera(const Scene& scene, const glm::dvec3& lo, const glm::dvec3& hi);

// The last pass of every technique that blends premultiplied (I, A) into an RGBA float buffer
// (slice3d.cl's slice3d_over_background): each of its `pixels` pixels becomes DESIGN.md's final pixel
// I + (1 - A) background, alpha A, in place. One per renderer (it holds the kernel); run() enqueues it.
class OverBackground {
public:
    explicit OverBackground(Device& device);
    void run(const cl::Buffer& rgba, std::size_t pixels, const glm::dvec3& background, const std::string& passName);

private:
    Device* device_;
    cl::Kernel kernel_;
};

// Wall time of one frame, host to host, from construction.
class FrameClock {
public:
    FrameClock() : start_(std::chrono::steady_clock::now()) {}
    double ms() const { return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start_).count(); }

private:
    std::chrono::steady_clock::time_point start_;
};

// Milliseconds since t0 (host set-up steps a renderer reports: gradient volume, tables, bricks).
double msSince(std::chrono::steady_clock::time_point t0);

// The rendered image: `buffer` holds width x height float4 (row 0 at the top), read back blocking.
Image4f readImage(Device& device, const cl::Buffer& buffer, int width, int height);

// The sum of `count` 32-bit per-pixel counters in `buffer` (samples taken, steps, ...), read back blocking.
std::uint64_t sumCounts(Device& device, const cl::Buffer& buffer, std::size_t count);

// Ends a frame's bookkeeping: stats.passes becomes `hostPasses` (timed by the renderer itself, e.g. host
// stages) followed by the device's pass times since the last frame, and stats.frameMs the frame's wall time.
void finishFrame(Device& device, const FrameClock& clock, FrameStats& stats, std::vector<PassTime> hostPasses = {});

// What a mesh technique reports of its mesh in --stats (docs/cli.md): points, tets (as read or split),
// tets_rendered, tets_degenerate (zero-volume cells checkMesh dropped), tets_reoriented (inverted cells
// whose vertex order it fixed). Taken at set-up, since a renderer outlives the caller's mesh.
struct MeshCounts {
    std::uint64_t points = 0, read = 0, rendered = 0, degenerate = 0, reoriented = 0;
    static MeshCounts of(const TetMesh& mesh);
    void report(FrameStats& stats) const;
};

// Sums the pass times of equal names into one entry each, in the order each name first appears: for a
// technique with launches per slice, so that --stats lists a handful of passes instead of thousands.
// Returns how many entries there were.
std::size_t mergePassesByName(std::vector<PassTime>& passes);

}  // namespace clvr
