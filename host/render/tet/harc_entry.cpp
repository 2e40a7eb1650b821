// host/render/tet/harc_entry.cpp — HARC's entry points by depth peeling the boundary front faces through
// the raster stage (host/render/tet/harc_entry.h).
#include "host/render/tet/harc_entry.h"

#include "host/runtime/embedded_kernels.h"
#include "host/render/scaffold.h"
#include "host/runtime/errors.h"
#include "host/render/camera_args.h"
#include "host/render/fragment_uniforms.h"
#include "kernels/harc_entry_params.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstring>
#include <string>

namespace clvr {
namespace {

constexpr float kNoLayerYet = -1e30f;  // the peel threshold before the first layer (finite: no NaN margins)

std::string entryFragmentSource()
{
    return "#define CLVR_HARC_ENTRY_FRAGMENT 1\n" + std::string(embeddedKernelSource("harc_entry.cl"));
}

}  // namespace

HarcRasterEntries::HarcRasterEntries(Device& device, const TetMesh& mesh, const TetTopology& topology,
                                     const glm::dvec3& shift, const cl::Buffer& tets, int width, int height,
                                     int maxLayers, const std::vector<std::uint32_t>& slot)
    : device_(device), width_(width), height_(height), maxLayers_(maxLayers), shift_(shift)
{
    if (maxLayers_ < 1 || maxLayers_ > 255)
        throw InputError("options.max_layers: must be an integer in [1, 255], got " + std::to_string(maxLayers_));
    // Outward-wound corners (outwardFace). Facing is decided per fragment from the face's plane, not by
    // culling: snapping can flip the screen winding of a face seen nearly edge-on.
    corners_.reserve(3 * topology.boundary.size());
    codes_.reserve(topology.boundary.size());
    glm::dvec3 lo(INFINITY), hi(-INFINITY);
    for (const TetTopology::BoundaryFace& bf : topology.boundary) {
        for (const glm::dvec3& world : outwardFace(mesh, bf.tet, bf.face)) {
            const glm::dvec3 q = world - shift;
            corners_.push_back(glm::vec3(q));
            lo = glm::min(lo, q);
            hi = glm::max(hi, q);
        }
        codes_.push_back(harcDeviceCode(static_cast<std::int32_t>(bf.tet * 4 + bf.face), slot));
    }
    if (!codes_.empty()) {
        boundsCenter_ = 0.5 * (lo + hi);
        boundsRadius_ = 0.5 * glm::length(hi - lo);
    }
    framebuffer_ = std::make_unique<raster::Framebuffer>(device_, width_, height_);
    previous_ = device_.buffer("harc entry peel threshold", static_cast<std::size_t>(width_) * height_ * sizeof(float));
    program_.source = entryFragmentSource();
    program_.attributes = 2;  // position, face code
    program_.buffers[0] = previous_;
    program_.buffers[1] = tets;
}

HarcEntryLists HarcRasterEntries::build(const Camera& worldCamera, HarcRasterEntryStats& stats)
{
    stats = HarcRasterEntryStats{};
    const std::size_t pixels = static_cast<std::size_t>(width_) * height_;
    HarcEntryLists lists;
    lists.offsets.assign(pixels + 1, 0);
    if (codes_.empty())
        return lists;

    // The camera relative to the mesh origin; near and far bracket the boundary's bounding sphere
    // (near clamped in front of the eye: faces behind it are clipped, as rays start at λ = 0).
    const Camera camera = worldCamera.relativeTo(shift_);
    const glm::dvec3 forward = camera.forward();
    const double centerDepth = glm::dot(boundsCenter_ - camera.position, forward);
    const double margin = 1e-3 * boundsRadius_ + 1e-6;
    const double farZ = centerDepth + boundsRadius_ + margin;
    if (!(farZ > 0.0))
        return lists;  // the whole mesh is behind the camera
    const double nearZ = std::max(centerDepth - boundsRadius_ - margin, farZ * 1e-5);
    const glm::mat4 viewProjection(camera.projectionMatrix(width_, height_, nearZ, farZ) * camera.viewMatrix());

    std::vector<raster::Vertex> vertices(corners_.size());
    for (std::size_t i = 0; i < corners_.size(); ++i) {
        const std::int32_t code = codes_[i / 3];
        vertices[i].position = viewProjection * glm::vec4(corners_[i], 1.0f);
        vertices[i].attributes[0] = glm::vec4(corners_[i], 0.0f);
        vertices[i].attributes[1] = glm::vec4(static_cast<float>(code & 0xffff), static_cast<float>(code >> 16), 0.0f, 0.0f);
    }
    ClHarcEntryUniforms uniforms{};
    uniforms.camera = toClCamera(camera, width_, height_);
    uniforms.size = cl_float4{{static_cast<float>(width_), static_cast<float>(height_), 0.0f, 0.0f}};
    program_.uniforms = fragmentUniforms(uniforms);
    raster::DrawState state;
    state.fragment.depth.test = true;
    state.fragment.depth.func = raster::CompareFunc::Less;
    state.fragment.cull = raster::CullFace::None;  // the fragment program decides facing (kernels/harc_entry.cl)

    std::vector<float> previous(pixels, kNoLayerYet);
    std::vector<std::uint8_t> count(pixels, 0);
    std::vector<cl_int2> byLayer;  // layer-major: layer k's entry for pixel p at k * pixels + p
    device_.queue().enqueueWriteBuffer(previous_, CL_TRUE, 0, pixels * sizeof(float), previous.data());
    for (int layer = 0;; ++layer) {
        auto t0 = std::chrono::steady_clock::now();
        framebuffer_->clearColor(device_, glm::vec4(-1.0f, 0.0f, 0.0f, 0.0f));
        framebuffer_->clearDepth(device_, 1.0f);
        const raster::DrawStats draw =
            raster::draw(device_, *framebuffer_, state, raster::Topology::Triangles, vertices, program_);
        const Image4f color = framebuffer_->readColor(device_);
        stats.rasterMs += msSince(t0);
        stats.triangles += draw.triangles;
        stats.fragments += draw.fragments;

        t0 = std::chrono::steady_clock::now();
        std::uint64_t added = 0;
        for (std::size_t p = 0; p < pixels; ++p) {
            const glm::vec4 c = color.pixels()[p];
            if (!(c.x >= 0.0f))
                continue;  // no face beyond the last layer here
            const std::int32_t code = static_cast<std::int32_t>(c.y) | (static_cast<std::int32_t>(c.z) << 16);
            if (count[p] != layer)
                continue;  // cannot happen (a pixel without layer k has none after it); kept safe
            byLayer.resize(std::max(byLayer.size(), (layer + 1) * pixels));
            cl_int2 entry;
            std::memcpy(&entry.s[0], &c.x, sizeof(float));
            entry.s[1] = code;
            byLayer[layer * pixels + p] = entry;
            ++count[p];
            previous[p] = c.x;
            ++added;
        }
        stats.compactMs += msSince(t0);
        if (added == 0)
            break;
        stats.layers = layer + 1;
        if (layer + 1 >= maxLayers_) {
            stats.layerBound = true;
            stats.pixelsAtBound = added;
            break;
        }
        device_.queue().enqueueWriteBuffer(previous_, CL_TRUE, 0, pixels * sizeof(float), previous.data());
    }

    const auto t0 = std::chrono::steady_clock::now();
    for (std::size_t p = 0; p < pixels; ++p)
        lists.offsets[p + 1] = lists.offsets[p] + count[p];
    lists.entries.resize(lists.offsets[pixels]);
    for (std::size_t p = 0; p < pixels; ++p)
        for (int k = 0; k < count[p]; ++k)
            lists.entries[lists.offsets[p] + k] = byLayer[k * pixels + p];
    stats.compactMs += msSince(t0);
    return lists;
}

}  // namespace clvr
