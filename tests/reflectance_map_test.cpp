// tests/reflectance_map_test.cpp — the reflectance map (host/optics/reflectance_map.h) against direct Phong within
// its derived quantization bound, the cube-face indexing, and the scene's lights and material.
#include "host/optics/reflectance_map.h"

#include "tests/support/test_util.h"

#include <cmath>
#include <cstdio>
#include <set>

namespace clvr {
namespace {

Lighting twoLights()
{
    Lighting l;
    l.lights.push_back({glm::normalize(glm::dvec3(0.3, 0.5, 1.0)), {1.0, 0.9, 0.8}});
    l.lights.push_back({glm::normalize(glm::dvec3(-1.0, 0.2, 0.1)), {0.2, 0.3, 0.6}});
    l.material = {0.1, 0.7, 0.4, 12.0};
    return l;
}

glm::dvec3 randomDirection(test::Rng& rng)
{
    for (;;) {  // rejection sampling in the unit ball: uniform directions
        const glm::dvec3 p(rng.uniform(-1, 1), rng.uniform(-1, 1), rng.uniform(-1, 1));
        const double r = glm::length(p);
        if (r > 1e-3 && r <= 1.0)
            return p / r;
    }
}

TEST(ReflectanceMap, MatchesDirectPhongWithinQuantizationBound)
{
    const Lighting lighting = twoLights();
    const glm::dvec3 toEye = glm::normalize(glm::dvec3(0.2, -0.4, 1.0));
    test::Rng rng(7);
    for (int n : {4, 16, 64, 256}) {
        const ReflectanceMap map = buildReflectanceMap(lighting, toEye, n);
        ASSERT_EQ(map.entries.size(), 6u * n * n + 1);
        // The derived bound, plus float storage of entries <= ~2 (ulp 2.4e-7).
        const double bound = reflectanceMapBound(lighting, n) + 1e-6;
        double worst = 0.0;
        for (int s = 0; s < 20000; ++s) {
            const glm::dvec3 g = randomDirection(rng) * rng.uniform(0.01, 10.0);  // any gradient length
            const glm::dvec3 d = glm::abs(map.lookup(g, toEye) - phongShade(lighting, g, toEye));
            worst = std::max({worst, d.r, d.g, d.b});
        }
        std::printf("[ measured ] n = %d: max |map - Phong| %.3e, bound %.3e\n", n, worst, bound);
        EXPECT_LE(worst, bound) << "n = " << n;
        // The bound is not vacuous: the real error is within a factor 10 of it (and shrinks as 1/n).
        EXPECT_GE(worst, bound / 10) << "n = " << n;
    }
}

TEST(ReflectanceMap, ErrorFallsAsOneOverN)
{
    const Lighting lighting = twoLights();
    const glm::dvec3 toEye(0.0, 0.0, 1.0);
    auto meanError = [&](int n) {
        const ReflectanceMap map = buildReflectanceMap(lighting, toEye, n);
        test::Rng rng(11);
        double sum = 0.0;
        const int count = 20000;
        for (int s = 0; s < count; ++s) {
            const glm::dvec3 g = randomDirection(rng);
            const glm::dvec3 d = glm::abs(map.lookup(g, toEye) - phongShade(lighting, g, toEye));
            sum += d.r + d.g + d.b;
        }
        return sum / (3 * count);
    };
    const double e32 = meanError(32), e128 = meanError(128);
    EXPECT_LT(e128, e32 / 3.0) << e32 << " " << e128;  // 1/n: a factor 4 expected
}

TEST(ReflectanceMap, FaceIndexing)
{
    ReflectanceMap map;
    map.n = 8;
    // Each axis direction lands in the center patches of its own face, and every face gets used.
    std::set<std::size_t> faces;
    for (int a = 0; a < 3; ++a) {
        for (double sign : {1.0, -1.0}) {
            glm::dvec3 N(0.0);
            N[a] = sign;
            const std::size_t k = map.index(N);
            faces.insert(k / 64);
            EXPECT_EQ(k / 64, static_cast<std::size_t>(2 * a + (sign < 0)));
            EXPECT_EQ(k % 8, 4u);      // u = 0 -> patch n/2
            EXPECT_EQ(k / 8 % 8, 4u);  // v = 0
        }
    }
    EXPECT_EQ(faces.size(), 6u);
    EXPECT_EQ(map.index(glm::dvec3(0.0)), 6u * 64);  // zero gradient: the ambient entry
    EXPECT_EQ(map.index(glm::dvec3(1.0, 1.0, -1.0) / std::sqrt(3.0)) / 64, 0u);  // ties: x first
    EXPECT_EQ(map.index(glm::normalize(glm::dvec3(1.0, 1.0, -1.0))) % 8, 7u);   // u = y/x = 1 clamps to n-1
}

TEST(ReflectanceMap, ZeroGradientAndUnshaded)
{
    const Lighting lighting = twoLights();
    const glm::dvec3 toEye(0.0, 0.0, 1.0);
    const ReflectanceMap map = buildReflectanceMap(lighting, toEye, 16);
    EXPECT_EQ(map.lookup(glm::dvec3(0.0), toEye), glm::dvec3(glm::vec3(0.1f)));
    EXPECT_EQ(phongShade(lighting, glm::dvec3(0.0), toEye), glm::dvec3(0.1));
    // Two-sided: a gradient and its negative shade alike.
    const glm::dvec3 g(0.3, -0.2, 0.9);
    EXPECT_EQ(phongShade(lighting, g, toEye), phongShade(lighting, -g, toEye));
    const Lighting none;
    const ReflectanceMap flat = buildReflectanceMap(none, toEye, 4);
    for (const glm::vec4& e : flat.entries)
        EXPECT_EQ(glm::vec3(e), glm::vec3(1.0f));
    EXPECT_EQ(phongShade(none, g, toEye), glm::dvec3(1.0));
}

TEST(ReflectanceMap, SceneLightingDefaultsAndValues)
{
    const Scene s = parseScene(R"({"volume": {"generator": "sphere", "dims": [8,8,8]},
        "transfer_function": {"points": [[0, 1,1,1, 1], [1, 1,1,1, 1]]},
        "lights": [{"direction": [0, 0, 2]}, {"direction": [3, 0, 4], "color": [0.5, 0.25, 1]}],
        "material": {"specular": 0.5}})",
                               "test.json", ".");
    const Lighting l = sceneLighting(s);
    ASSERT_EQ(l.lights.size(), 2u);
    EXPECT_EQ(l.lights[0].direction, glm::dvec3(0, 0, 1));
    EXPECT_EQ(l.lights[0].color, glm::dvec3(1.0));
    EXPECT_NEAR(glm::length(l.lights[1].direction - glm::dvec3(0.6, 0, 0.8)), 0.0, 1e-15);
    EXPECT_EQ(l.lights[1].color, glm::dvec3(0.5, 0.25, 1));
    EXPECT_EQ(l.material.specular, 0.5);
    EXPECT_EQ(l.material.ambient, Material{}.ambient);
    EXPECT_EQ(l.material.shininess, Material{}.shininess);
}

}  // namespace
}  // namespace clvr
