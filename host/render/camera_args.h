// host/render/camera_args.h — the camera as every kernel and fragment program takes it: five float4s,
// position, forward, right, up and (scale, aspect, 1 if parallel, 0), with scale = tan(view_angle / 2)
// (perspective) or parallel_scale (parallel). A pixel's ray is then host/model/camera.cpp's PixelRays::at:
// with ndc = ((x + 0.5) / width * 2 - 1, 1 - (y + 0.5) / height * 2), direction forward +
// ndc.x scale aspect right + ndc.y scale up from the position, or, parallel, direction forward from
// position + ndc.x scale aspect right + ndc.y scale up.
#pragma once

#include "host/model/camera.h"

#include <CL/opencl.hpp>
#include <glm/glm.hpp>

#include <array>
#include <cmath>

namespace clvr {

// In that order; `shift` is subtracted from the position (a renderer that moves its data to the
// origin for float precision moves the camera with it).
inline std::array<glm::vec4, 5> cameraVectors(const Camera& camera, int width, int height, const glm::dvec3& shift = glm::dvec3(0.0))
{
    const double aspect = static_cast<double>(width) / height;
    const double scale = camera.parallel ? camera.parallelScale : std::tan(glm::radians(camera.viewAngle) * 0.5);
    return {glm::vec4(glm::vec3(camera.position - shift), 0.0f), glm::vec4(glm::vec3(camera.forward()), 0.0f),
            glm::vec4(glm::vec3(camera.right()), 0.0f), glm::vec4(glm::vec3(camera.up()), 0.0f),
            glm::vec4(static_cast<float>(scale), static_cast<float>(aspect), camera.parallel ? 1.0f : 0.0f, 0.0f)};
}

// Sets the five as kernel arguments first .. first + 4; returns first + 5.
inline int setCameraArgs(cl::Kernel& kernel, int first, const Camera& camera, int width, int height,
                         const glm::dvec3& shift = glm::dvec3(0.0))
{
    for (const glm::vec4& v : cameraVectors(camera, width, height, shift))
        kernel.setArg(first++, cl_float4{{v.x, v.y, v.z, v.w}});
    return first;
}

}  // namespace clvr
