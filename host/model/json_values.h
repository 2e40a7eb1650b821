// host/model/json_values.h — reading checked values out of a scene's JSON where the key path is built as it
// goes ("options.clip.mesh.radius"): each failure is one InputError "KEY: what is wrong, got VALUE".
// For the flat "options.KEY" of a technique, host/render/options_util.h has the same in that form.
#pragma once

#include "host/runtime/errors.h"

#include <glm/glm.hpp>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <cmath>
#include <string>

namespace clvr {

[[noreturn]] inline void badKey(const std::string& key, const std::string& what)
{
    throw InputError(key + ": " + what);
}

// [x, y, z] of finite numbers.
inline glm::dvec3 jsonVec3(const nlohmann::json& v, const std::string& key)
{
    if (!v.is_array() || v.size() != 3 ||
        !std::all_of(v.begin(), v.end(), [](const nlohmann::json& x) { return x.is_number(); }))
        badKey(key, "must be [x, y, z], got " + v.dump());
    const glm::dvec3 p(v[0].get<double>(), v[1].get<double>(), v[2].get<double>());
    if (!std::isfinite(p.x) || !std::isfinite(p.y) || !std::isfinite(p.z))
        badKey(key, "must be finite, got " + v.dump());
    return p;
}

// A finite number > 0.
inline double jsonPositive(const nlohmann::json& v, const std::string& key)
{
    if (!v.is_number() || !(v.get<double>() > 0.0) || !std::isfinite(v.get<double>()))
        badKey(key, "must be a positive number, got " + v.dump());
    return v.get<double>();
}

}  // namespace clvr
