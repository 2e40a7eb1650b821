// tests/gradient_volume_test.cpp — the Sobel gradient RGBA volume (host/optics/gradient_volume.h): exact for linear
// fields (faces included), close to the analytic gradient of a smooth field, value kept in w.
#include "host/optics/gradient_volume.h"

#include "host/io/generators.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>

namespace clvr {
namespace {

TEST(GradientVolume, ExactForLinearFieldsIncludingFaces)
{
    Volume v;
    v.dims = {5, 4, 6};           // odd and unequal sizes catch swapped axes
    v.spacing = {0.5, 2.0, 0.25};  // world units: the gradient is per world unit
    v.origin = {1.0, -2.0, 0.5};
    const glm::dvec3 slope(0.3, -1.5, 2.0);
    for (int k = 0; k < v.dims.z; ++k)
        for (int j = 0; j < v.dims.y; ++j)
            for (int i = 0; i < v.dims.x; ++i) {
                const glm::dvec3 p = v.origin + glm::dvec3(i, j, k) * v.spacing;
                v.values.push_back(static_cast<float>(glm::dot(slope, p) + 4.0));
            }
    const std::vector<glm::vec4> g = sobelGradientVolume(v);
    ASSERT_EQ(g.size(), v.values.size());
    for (std::size_t i = 0; i < g.size(); ++i) {
        // float values ~ 10: differences carry ~1e-6 rounding, over a spacing of 0.25 at worst.
        EXPECT_NEAR(g[i].x, slope.x, 2e-5) << i;
        EXPECT_NEAR(g[i].y, slope.y, 2e-5) << i;
        EXPECT_NEAR(g[i].z, slope.z, 2e-5) << i;
        EXPECT_EQ(g[i].w, v.values[i]);
    }
}

TEST(GradientVolume, CloseToAnalyticGradientOfSmoothField)
{
    // f = sin(x) cos(2y) + z^2 on a 33^3 grid over [-1, 1]^3 (h = 1/16): central differences and the
    // smoothing are second order, error ~ h^2 |f'''| (up to 8 for cos(2y)) / 6 + smoothing h^2 |f''_cross|.
    const glm::ivec3 n(33);
    Volume v;
    v.dims = n;
    v.spacing = glm::dvec3(2.0 / 32);
    v.origin = glm::dvec3(-1.0);
    auto f = [](const glm::dvec3& p) { return std::sin(p.x) * std::cos(2 * p.y) + p.z * p.z; };
    for (int k = 0; k < n.z; ++k)
        for (int j = 0; j < n.y; ++j)
            for (int i = 0; i < n.x; ++i)
                v.values.push_back(static_cast<float>(f(v.origin + glm::dvec3(i, j, k) * v.spacing)));
    const std::vector<glm::vec4> g = sobelGradientVolume(v);
    double worst = 0.0;
    for (int k = 1; k < n.z - 1; ++k)
        for (int j = 1; j < n.y - 1; ++j)
            for (int i = 1; i < n.x - 1; ++i) {
                const glm::dvec3 p = v.origin + glm::dvec3(i, j, k) * v.spacing;
                const glm::dvec3 exact(std::cos(p.x) * std::cos(2 * p.y), -2 * std::sin(p.x) * std::sin(2 * p.y), 2 * p.z);
                const glm::vec4 s = g[(static_cast<std::size_t>(k) * n.y + j) * n.x + i];
                worst = std::max(worst, glm::length(glm::dvec3(s) - exact));
            }
    std::printf("[ measured ] max |Sobel - analytic gradient| %.3e\n", worst);
    // h^2 = 0.0039; measured 5.8e-3.
    EXPECT_LT(worst, 0.012);
}

}  // namespace
}  // namespace clvr
