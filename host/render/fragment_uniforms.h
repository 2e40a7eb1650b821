// host/render/fragment_uniforms.h — a fragment program's uniforms as one struct: a technique's
// Cl...Uniforms of kernels/..._params.h (float4 fields only) copied into
// raster::FragmentProgram::uniforms, which the program reads back through a pointer to that struct.
#pragma once

#include <glm/glm.hpp>

#include <cstring>
#include <type_traits>
#include <vector>

namespace clvr {

template <typename T>
std::vector<glm::vec4> fragmentUniforms(const T& uniforms)
{
    static_assert(std::is_trivially_copyable_v<T> && sizeof(T) % sizeof(glm::vec4) == 0,
                  "a uniforms struct is float4s only");
    std::vector<glm::vec4> out(sizeof(T) / sizeof(glm::vec4));
    std::memcpy(out.data(), &uniforms, sizeof(T));
    return out;
}

}  // namespace clvr
