// host/render/options_util.h — small pieces every renderer shares: the walk over the scene's "options"
// with the InputError for a bad one ("options.KEY: what"), the checks of integer and number options,
// and a host vector as a cl_float4 kernel argument.
#pragma once

#include "host/runtime/errors.h"

#include <CL/opencl.hpp>
#include <glm/glm.hpp>
#include <nlohmann/json.hpp>

#include <cmath>
#include <string>

namespace clvr {

[[noreturn]] inline void badOption(const std::string& key, const std::string& what)
{
    throw InputError("options." + key + ": " + what);
}

// Calls visit(key, value) for every key of a scene's "options" (none when it is null); InputError
// "options: must be an object" for anything else.
template <class Visit>
void forEachOption(const nlohmann::json& options, Visit visit)
{
    if (options.is_null())
        return;
    if (!options.is_object())
        throw InputError("options: must be an object");
    for (const auto& [key, value] : options.items())
        visit(key, value);
}

// The value of integer option `key` in [lo, hi]; else "options.KEY: must be an integer in [lo, hi], got V".
inline int integerOption(const std::string& key, const nlohmann::json& value, long long lo, long long hi)
{
    if (!value.is_number_integer() || value.get<long long>() < lo || value.get<long long>() > hi)
        badOption(key, "must be an integer in [" + std::to_string(lo) + ", " + std::to_string(hi) + "], got " + value.dump());
    return static_cast<int>(value.get<long long>());
}

// The value of number option `key` when it is finite and ok(value); else "options.KEY: must be WHAT, got V".
inline double numberOption(const std::string& key, const nlohmann::json& value, bool (*ok)(double), const std::string& what)
{
    if (!value.is_number() || !std::isfinite(value.get<double>()) || !ok(value.get<double>()))
        badOption(key, "must be " + what + ", got " + value.dump());
    return value.get<double>();
}

inline cl_float4 toCl4(const glm::dvec3& v, double w = 0.0)
{
    return {{static_cast<float>(v.x), static_cast<float>(v.y), static_cast<float>(v.z), static_cast<float>(w)}};
}

}  // namespace clvr
