// host/render/camera_args.h — the camera as every kernel and fragment program takes it: ClCamera of
// kernels/ray.h, position, forward, right, up and (scale, aspect, 1 if parallel, 0), with scale =
// tan(view_angle / 2) (perspective) or parallel_scale (parallel). kernels/ray.h turns a pixel into
// host/model/camera.cpp's PixelRays::at ray from it. The one place where a camera is packed for the device.
#pragma once

#include "host/model/camera.h"

#include "kernels/ray.h"

#include <glm/glm.hpp>

#include <cmath>

namespace clvr {

// `shift` is subtracted from the position (a renderer that moves its data to the origin for float
// precision moves the camera with it).
inline ClCamera toClCamera(const Camera& camera, int width, int height, const glm::dvec3& shift = glm::dvec3(0.0))
{
    // A band (Camera::bandFullHeight) of rows [y0, y0 + height) of an image H rows tall: position.w = y0,
    // forward.w = H, and the full image's aspect, so the kernels take the full image's ray of each row
    // (kernels/ray.h's clvr_ray_window_offset). The whole image: both 0.
    const double scale = camera.parallel ? camera.parallelScale : std::tan(glm::radians(camera.viewAngle) * 0.5);
    const double aspect = static_cast<double>(width) / camera.fullHeight(height);
    auto pack = [](const glm::dvec3& v) {
        return cl_float4{{static_cast<float>(v.x), static_cast<float>(v.y), static_cast<float>(v.z), 0.0f}};
    };
    ClCamera cl{};
    cl.position = pack(camera.position - shift);
    cl.forward = pack(camera.forward());
    cl.right = pack(camera.right());
    cl.up = pack(camera.up());
    cl.params = cl_float4{{static_cast<float>(scale), static_cast<float>(aspect), camera.parallel ? 1.0f : 0.0f, 0.0f}};
    if (camera.bandFullHeight > 0) {
        cl.position.s[3] = static_cast<float>(camera.bandY0);
        cl.forward.s[3] = static_cast<float>(camera.bandFullHeight);
    }
    return cl;
}

}  // namespace clvr
