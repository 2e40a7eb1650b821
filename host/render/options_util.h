// host/render/options_util.h — small pieces every renderer shares: the InputError for a bad scene
// option ("options.KEY: what"), and a host vector as a cl_float4 kernel argument.
#pragma once

#include "host/errors.h"

#include <CL/opencl.hpp>
#include <glm/glm.hpp>

#include <string>

namespace clvr {

[[noreturn]] inline void badOption(const std::string& key, const std::string& what)
{
    throw InputError("options." + key + ": " + what);
}

inline cl_float4 toCl4(const glm::dvec3& v, double w = 0.0)
{
    return {{static_cast<float>(v.x), static_cast<float>(v.y), static_cast<float>(v.z), static_cast<float>(w)}};
}

}  // namespace clvr
