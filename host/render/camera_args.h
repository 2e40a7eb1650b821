// host/render/camera_args.h — the camera as every kernel and fragment program takes it: ClCamera of
// kernels/ray.h, position, forward, right, up and (scale, aspect, 1 if parallel, 0), with scale =
// tan(view_angle / 2) (perspective) or parallel_scale (parallel). kernels/ray.h turns a pixel into
// host/camera.cpp's PixelRays::at ray from it. The one place where a camera is packed for the device.
#pragma once

#include "host/camera.h"

#include "kernels/ray.h"

#include <glm/glm.hpp>

#include <array>
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

// The same five float4s as fragment-program uniforms (kernels/ray.h's clvr_ray_camera reads them).
inline std::array<glm::vec4, 5> cameraVectors(const Camera& camera, int width, int height,
                                              const glm::dvec3& shift = glm::dvec3(0.0))
{
    const ClCamera cl = toClCamera(camera, width, height, shift);
    auto vec = [](const cl_float4& v) { return glm::vec4(v.s[0], v.s[1], v.s[2], v.s[3]); };
    return {vec(cl.position), vec(cl.forward), vec(cl.right), vec(cl.up), vec(cl.params)};
}

}  // namespace clvr
