// host/optics/reflectance_map.cpp — scene lighting, direct Phong and the reflectance map (host/optics/reflectance_map.h).
#include "host/optics/reflectance_map.h"

#include <algorithm>
#include <cmath>

namespace clvr {
namespace {

// The one-sided Phong sum at unit normal N (no flip): what each map entry holds.
glm::dvec3 phongOneSided(const Lighting& lighting, const glm::dvec3& N, const glm::dvec3& toEye)
{
    const Material& m = lighting.material;
    glm::dvec3 shade(m.ambient);
    for (const DirectionalLight& light : lighting.lights) {
        const double diffuse = std::max(0.0, glm::dot(N, light.direction));
        const glm::dvec3 h = light.direction + toEye;
        double specular = 0.0;
        if (glm::length(h) > 1e-12)  // light straight behind the object: no half vector, no highlight
            specular = std::pow(std::max(0.0, glm::dot(N, glm::normalize(h))), m.shininess);
        shade += light.color * (m.diffuse * diffuse + m.specular * specular);
    }
    return shade;
}

// N = g / |g| turned to face the viewer (two-sided shading).
glm::dvec3 facingNormal(const glm::dvec3& g, const glm::dvec3& toEye)
{
    const glm::dvec3 N = glm::normalize(g);
    return glm::dot(N, toEye) < 0.0 ? -N : N;
}

}  // namespace

Lighting sceneLighting(const Scene& scene)
{
    Lighting lighting;
    if (scene.lights.is_array()) {
        for (const auto& l : scene.lights) {
            DirectionalLight light;
            const auto& d = l["direction"];
            light.direction = glm::normalize(glm::dvec3(d[0].get<double>(), d[1].get<double>(), d[2].get<double>()));
            if (l.contains("color"))
                light.color = {l["color"][0].get<double>(), l["color"][1].get<double>(), l["color"][2].get<double>()};
            lighting.lights.push_back(light);
        }
    }
    if (scene.material.is_object()) {
        Material& m = lighting.material;
        m.ambient = scene.material.value("ambient", m.ambient);
        m.diffuse = scene.material.value("diffuse", m.diffuse);
        m.specular = scene.material.value("specular", m.specular);
        m.shininess = scene.material.value("shininess", m.shininess);
    }
    return lighting;
}

glm::dvec3 phongShade(const Lighting& lighting, const glm::dvec3& g, const glm::dvec3& toEye)
{
    if (!lighting.shaded())
        return glm::dvec3(1.0);
    if (g == glm::dvec3(0.0))
        return glm::dvec3(lighting.material.ambient);
    return phongOneSided(lighting, facingNormal(g, toEye), toEye);
}

std::size_t ReflectanceMap::index(const glm::dvec3& N) const
{
    const glm::dvec3 a = glm::abs(N);
    const int major = a.x >= a.y && a.x >= a.z ? 0 : (a.y >= a.z ? 1 : 2);
    if (a[major] == 0.0)
        return 6 * static_cast<std::size_t>(n) * n;
    const int face = 2 * major + (N[major] < 0.0 ? 1 : 0);
    const double u = N[(major + 1) % 3] / a[major], v = N[(major + 2) % 3] / a[major];
    const int i = std::min(static_cast<int>((u + 1.0) * 0.5 * n), n - 1);
    const int j = std::min(static_cast<int>((v + 1.0) * 0.5 * n), n - 1);
    return (static_cast<std::size_t>(face) * n + j) * n + i;
}

glm::dvec3 ReflectanceMap::lookup(const glm::dvec3& g, const glm::dvec3& toEye) const
{
    const std::size_t k = g == glm::dvec3(0.0) ? 6 * static_cast<std::size_t>(n) * n : index(facingNormal(g, toEye));
    return glm::dvec3(entries[k]);
}

ReflectanceMap buildReflectanceMap(const Lighting& lighting, const glm::dvec3& toEye, int n)
{
    ReflectanceMap map;
    map.n = n;
    map.entries.resize(6 * static_cast<std::size_t>(n) * n + 1);
    for (int face = 0; face < 6; ++face) {
        const int major = face / 2;
        for (int j = 0; j < n; ++j) {
            for (int i = 0; i < n; ++i) {
                glm::dvec3 N(0.0);
                N[major] = face % 2 ? -1.0 : 1.0;
                N[(major + 1) % 3] = -1.0 + (i + 0.5) * 2.0 / n;  // patch center, face coordinates
                N[(major + 2) % 3] = -1.0 + (j + 0.5) * 2.0 / n;
                const glm::dvec3 shade =
                    lighting.shaded() ? phongOneSided(lighting, glm::normalize(N), toEye) : glm::dvec3(1.0);
                map.entries[(static_cast<std::size_t>(face) * n + j) * n + i] = glm::vec4(glm::vec3(shade), 0.0f);
            }
        }
    }
    const double ambient = lighting.shaded() ? lighting.material.ambient : 1.0;
    map.entries.back() = glm::vec4(glm::vec3(static_cast<float>(ambient)), 0.0f);
    return map;
}

double reflectanceMapBound(const Lighting& lighting, int n)
{
    const double theta = std::sqrt(2.0) / n;
    const Material& m = lighting.material;
    const double perUnitColor =
        m.diffuse * theta + m.specular * (m.shininess >= 1.0 ? m.shininess * theta : std::pow(theta, m.shininess));
    glm::dvec3 sum(0.0);
    for (const DirectionalLight& light : lighting.lights)
        sum += light.color * perUnitColor;
    return std::max({sum.r, sum.g, sum.b});
}

}  // namespace clvr
