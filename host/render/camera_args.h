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
    const double aspect = static_cast<double>(width) / height;
    const double scale = camera.parallel ? camera.parallelScale : std::tan(glm::radians(camera.viewAngle) * 0.5);
    auto pack = [](const glm::dvec3& v) {
        return cl_float4{{static_cast<float>(v.x), static_cast<float>(v.y), static_cast<float>(v.z), 0.0f}};
    };
    ClCamera cl{};
    cl.position = pack(camera.position - shift);
    cl.forward = pack(camera.forward());
    cl.right = pack(camera.right());
    cl.up = pack(camera.up());
    cl.params = cl_float4{{static_cast<float>(scale), static_cast<float>(aspect), camera.parallel ? 1.0f : 0.0f, 0.0f}};
    return cl;
}

}  // namespace clvr
