// host/render/scaffold.cpp — the renderer scaffold's checks, read-back and frame bookkeeping.
#include "host/render/scaffold.h"

#include "host/render/options_util.h"  // toCl4
#include "host/runtime/errors.h"
#include "kernels/slice3d_params.h"      // ClSlice3dOverBackgroundParams

#include <map>
#include <numeric>
#include <string>
#include <vector>

namespace clvr {

void checkGridVolume(const Volume& volume, std::string_view technique)
{
    volume.validate();
    if (volume.voxelCount() > 0xffffffffull)
        throw InputError(volume.source + ": " + std::string(technique) +
                         " takes at most 2^32 - 1 grid points (32-bit voxel indices)");
}

Camera frameCamera(const Scene& scene, const glm::dvec3& lo, const glm::dvec3& hi)
{
    Camera camera = scene.camera ? *scene.camera : fitCamera(lo, hi);
    camera.validate();
    if (scene.image.width < 1 || scene.image.height < 1)
        throw InputError("image: width and height must be >= 1");
    return camera;
}

OverBackground::OverBackground(Device& device)
    : device_(&device), kernel_(device.kernel("slice3d.cl", "slice3d_over_background"))
{
}

void OverBackground::run(const cl::Buffer& rgba, std::size_t pixels, const glm::dvec3& background,
                         const std::string& passName)
{
    ClSlice3dOverBackgroundParams params{};
    params.background = toCl4(background, 0.0);
    params.count = static_cast<cl_int>(pixels);
    kernel_.setArg(0, rgba);
    kernel_.setArg(1, params);
    device_->launch(passName, kernel_, pixels);
}

double msSince(std::chrono::steady_clock::time_point t0)
{
    return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
}

Image4f readImage(Device& device, const cl::Buffer& buffer, int width, int height)
{
    Image4f image(width, height);
    const std::size_t pixels = static_cast<std::size_t>(width) * height;
    device.queue().enqueueReadBuffer(buffer, CL_TRUE, 0, pixels * sizeof(glm::vec4), image.pixels().data());
    return image;
}

std::uint64_t sumCounts(Device& device, const cl::Buffer& buffer, std::size_t count)
{
    const std::vector<cl_uint> counts = device.download<cl_uint>(buffer, count);
    return std::accumulate(counts.begin(), counts.end(), std::uint64_t(0));
}

void finishFrame(Device& device, const FrameClock& clock, FrameStats& stats, std::vector<PassTime> hostPasses)
{
    stats.passes = std::move(hostPasses);
    for (PassTime& t : device.takePassTimes())
        stats.passes.push_back(std::move(t));
    stats.frameMs = clock.ms();
}

MeshCounts MeshCounts::of(const TetMesh& mesh)
{
    MeshCounts c;
    c.points = mesh.points.size();
    c.read = mesh.tetsRead ? mesh.tetsRead : mesh.tets.size();
    c.rendered = mesh.tets.size();
    c.degenerate = mesh.tetsDegenerate;
    c.reoriented = mesh.tetsReoriented;
    return c;
}

void MeshCounts::report(FrameStats& stats) const
{
    stats.extra["points"] = points;
    stats.extra["tets"] = read;
    stats.extra["tets_rendered"] = rendered;
    stats.extra["tets_degenerate"] = degenerate;
    stats.extra["tets_reoriented"] = reoriented;
}

std::size_t mergePassesByName(std::vector<PassTime>& passes)
{
    const std::size_t count = passes.size();
    std::vector<PassTime> merged;
    std::map<std::string, std::size_t> at;
    for (PassTime& p : passes) {
        const auto [it, added] = at.try_emplace(p.name, merged.size());
        if (added)
            merged.push_back(std::move(p));
        else
            merged[it->second].ms += p.ms;
    }
    passes = std::move(merged);
    return count;
}

}  // namespace clvr
