// host/optics/reflectance_map.h — Phong shading of volume samples through a reflectance map (§2.2 of
// seeds/004_35d3c76e603b55b1.txt): the shade of 6 n^2 normal directions, a cube whose six faces are cut
// into n x n equal patches, looked up with the sample's gradient normalized by its largest component.
// Also the lights and material of a scene (DESIGN.md "lights" and "material") and direct Phong, which
// the CPU reference integral and the tests use.
#pragma once

#include "host/model/scene.h"

#include <glm/glm.hpp>

#include <vector>

namespace clvr {

struct DirectionalLight {
    glm::dvec3 direction{0.0, 0.0, 1.0};  // unit length, world space, towards the light
    glm::dvec3 color{1.0};
};

struct Material {  // defaults when the scene's "material" leaves a key out
    double ambient = 0.1;
    double diffuse = 0.7;
    double specular = 0.2;
    double shininess = 20.0;
};

struct Lighting {
    std::vector<DirectionalLight> lights;  // empty: unshaded (the shade is 1)
    Material material;
    bool shaded() const { return !lights.empty(); }
};

// The scene's "lights" and "material" (already checked by parseScene); directions normalized.
Lighting sceneLighting(const Scene& scene);

// The shade (r, g, b factors that multiply the transfer function's color) of a sample with gradient g
// seen along toEye (unit, towards the viewer). The model, shared by every shaded technique here:
//   N = g / |g|, flipped to face the viewer when dot(N, toEye) < 0 (two-sided: a gradient's sign says
//   which side is denser, not which side is lit);
//   shade = ka + sum_l color_l (kd max(0, N.L_l) + ks max(0, N.H_l)^p),  H_l = normalize(L_l + toEye)
//   (Blinn's half vector; ks term 0 when L_l = -toEye). g = 0: ka alone. Unshaded lighting: 1.
// toEye is one direction for the whole image (the camera's -forward, for perspective cameras too):
// the reflectance map holds one view direction, as the paper's does.
glm::dvec3 phongShade(const Lighting& lighting, const glm::dvec3& g, const glm::dvec3& toEye);

// The reflectance map. Cube-face convention (kernels/reflectance_map.h does the same in float):
// major axis a = the first axis of largest |N_a|; face = 2a + (N_a < 0); the other axes are
// u = (a + 1) % 3, v = (a + 2) % 3 with coordinates N_u / |N_a|, N_v / |N_a| in [-1, 1]; patch
// i = min(floor((u + 1) n / 2), n - 1), likewise j; entry (face n + j) n + i. Each entry is the one-sided
// Phong sum (no flip) at the patch's center direction; the lookup flips N to face the viewer first,
// exactly as phongShade does. Entry 6 n^2 (one past the cube) holds ka, the shade of a zero gradient.
struct ReflectanceMap {
    int n = 0;
    std::vector<glm::vec4> entries;  // 6 n^2 + 1, rgb = shade, w = 0 (float4 for vload4 on the device)

    // Index of the entry for the unit normal `normal` (already flipped), or 6 n^2 for the zero vector.
    std::size_t index(const glm::dvec3& normal) const;
    // The map's shade of gradient g seen along toEye: phongShade's model with the normal quantized.
    glm::dvec3 lookup(const glm::dvec3& g, const glm::dvec3& toEye) const;
};

// Builds the 6 n^2 (+1) entries for these lights and this view direction; rebuilt whenever either changes
// (n >= 1). Cost: 6 n^2 Phong evaluations, independent of the volume.
ReflectanceMap buildReflectanceMap(const Lighting& lighting, const glm::dvec3& toEye, int n);

// Largest |map shade - phongShade| of any channel, over all gradients (the quantization error, float
// storage aside): a normal lies within angle theta = sqrt(2) / n of its patch center (the half diagonal of
// a patch is sqrt(2)/n in face coordinates, and central projection onto the unit sphere from a plane at
// distance >= 1 shrinks lengths), the diffuse term kd max(0, N.L) changes by at most kd theta and the
// specular term ks max(0, N.H)^p by at most ks p theta for p >= 1 (its slope in the angle is at most p)
// and by at most ks theta^p for p < 1 (|a^p - b^p| <= |a - b|^p), per light:
//   bound = max over channels of sum_l color_l (kd theta + ks (p >= 1 ? p theta : theta^p)).
double reflectanceMapBound(const Lighting& lighting, int n);

}  // namespace clvr
