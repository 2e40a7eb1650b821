// raster/reference/texture.h — GL texture sampling in double precision, the specification that
// kernels/texture.h is tested against (DESIGN.md, raster stage: CPU reference).
#pragma once

#include "raster/texture.h"

#include <glm/glm.hpp>

#include <vector>

namespace clvr::raster::reference {

// The texture sampled at normalized coordinate (s, t, r) as a `dimensions`-D texture (1, 2 or 3;
// unused coordinates are ignored): the rules of kernels/texture.h, in double. Validates like Texture.
glm::dvec4 sampleTexture(const TextureDesc& desc, const std::vector<float>& texels, glm::dvec3 coord, int dimensions);

// The dimension from the shape: depth > 1: 3D, else height > 1: 2D, else 1D.
glm::dvec4 sampleTexture(const TextureDesc& desc, const std::vector<float>& texels, glm::dvec3 coord);

}  // namespace clvr::raster::reference
