// host/optics/gradient_volume.h — §2.3 of seeds/004_35d3c76e603b55b1.txt: Sobel gradients precomputed once per
// volume and stored with the value as one RGBA grid point, so that a renderer interpolates value and
// gradient together (the paper's "three gradient values and raw density" in an RGBA texture).
// clvr stores float32, not the paper's 8 bits: 16 bytes per grid point, no gradient quantization.
#pragma once

#include "host/model/volume.h"

#include <glm/glm.hpp>

#include <vector>

namespace clvr {

// Per grid point (x fastest, as Volume::values): (df/dx, df/dy, df/dz, f), the gradient in data units per
// world unit. The 3x3x3 Sobel operator: along the derivative axis the central difference
// (f[i+1] - f[i-1]) / (2 h), across it the smoothing weights (1, 2, 1)/4 on each of the other two axes,
// so a linear field gives its exact gradient. At a face the missing neighbour is the point itself
// (indices clamped): the difference becomes one-sided, (f[1] - f[0]) / h, still exact for linear fields.
std::vector<glm::vec4> sobelGradientVolume(const Volume& volume);

}  // namespace clvr
