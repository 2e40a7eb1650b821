// tests/generators_test.cpp — procedural volumes: Marschner–Lobb at points with closed-form values, the
// [-1,1]^3 grid mapping, the sphere and blobs fields, and bad names and dims.
#include "host/runtime/errors.h"
#include "host/io/generators.h"
#include "host/io/mesh_io.h"
#include "host/model/data_spec.h"

#include <gtest/gtest.h>

#include <cmath>
#include <set>
#include <tuple>

namespace {

constexpr double kPi = 3.14159265358979323846;

TEST(Generators, MarschnerLobbAtAnalyticPoints)
{
    // rho = (1 - sin(pi z/2) + alpha (1 + rho_r)) / (2 (1 + alpha)), alpha = 0.25, so 2 (1 + alpha) = 2.5.
    // On the z axis r = 0 and rho_r = cos(2 pi 6) = 1: rho = (1 - sin(pi z/2) + 0.5) / 2.5.
    EXPECT_NEAR(clvr::marschnerLobb({0, 0, 0}), 1.5 / 2.5, 1e-15);
    EXPECT_NEAR(clvr::marschnerLobb({0, 0, 1}), 0.5 / 2.5, 1e-15);
    EXPECT_NEAR(clvr::marschnerLobb({0, 0, -1}), 1.0, 1e-15);
    // r = 1: cos(pi/2) = 0, rho_r = cos(0) = 1.
    EXPECT_NEAR(clvr::marschnerLobb({1, 0, 0}), 0.6, 1e-15);
    EXPECT_NEAR(clvr::marschnerLobb({0, -1, 0}), 0.6, 1e-15);
    // cos(pi r/2) = 1/24 makes rho_r = cos(pi/2) = 0: rho = 1.25 / 2.5 at z = 0.
    const double r0 = 2.0 / kPi * std::acos(1.0 / 24.0);
    EXPECT_NEAR(clvr::marschnerLobb({r0, 0, 0}), 0.5, 1e-12);
    EXPECT_NEAR(clvr::marschnerLobb({r0 / std::sqrt(2.0), r0 / std::sqrt(2.0), 0}), 0.5, 1e-12);
    // cos(pi r/2) = 1/12 makes rho_r = cos(pi) = -1: rho = 1 / 2.5 at z = 0; at z = 1/3, sin(pi/6) = 1/2.
    const double r1 = 2.0 / kPi * std::acos(1.0 / 12.0);
    EXPECT_NEAR(clvr::marschnerLobb({0, r1, 0}), 0.4, 1e-12);
    EXPECT_NEAR(clvr::marschnerLobb({0, r1, 1.0 / 3.0}), 0.5 / 2.5, 1e-12);
}

TEST(Generators, MarschnerLobbGridMapsIndicesToMinusOneToOne)
{
    const clvr::Volume v = clvr::generateVolume("marschner-lobb", {41, 21, 11});
    EXPECT_EQ(v.dims, glm::ivec3(41, 21, 11));
    EXPECT_EQ(v.origin, glm::dvec3(-1.0));
    EXPECT_DOUBLE_EQ(v.spacing.x, 2.0 / 40);
    EXPECT_DOUBLE_EQ(v.spacing.y, 2.0 / 20);
    EXPECT_DOUBLE_EQ(v.spacing.z, 2.0 / 10);
    EXPECT_DOUBLE_EQ(v.boundsMax().x, 1.0);
    EXPECT_EQ(v.source, "generator marschner-lobb");
    EXPECT_EQ(v.at(20, 10, 5), static_cast<float>(0.6));
    EXPECT_EQ(v.at(20, 10, 10), static_cast<float>(0.2));
    EXPECT_EQ(v.at(20, 10, 0), 1.0f);
    for (int k = 0; k < 11; k += 3)
        for (int j = 0; j < 21; j += 4)
            for (int i = 0; i < 41; i += 7) {
                const glm::dvec3 p(-1.0 + i / 20.0, -1.0 + j / 10.0, -1.0 + k / 5.0);
                ASSERT_NEAR(v.at(i, j, k), clvr::marschnerLobb(p), 1e-7) << i << "," << j << "," << k;
            }
    const glm::dvec2 range = v.range();
    EXPECT_GE(range.x, 0.0);
    EXPECT_LE(range.y, 1.0);
}

TEST(Generators, SphereIsOneMinusRadiusClamped)
{
    EXPECT_EQ(clvr::sphereField({0, 0, 0}), 1.0);
    EXPECT_DOUBLE_EQ(clvr::sphereField({0.5, 0, 0}), 0.5);
    EXPECT_DOUBLE_EQ(clvr::sphereField({0, 0.3, 0.4}), 0.5);
    EXPECT_EQ(clvr::sphereField({1, 0, 0}), 0.0);
    EXPECT_EQ(clvr::sphereField({1, 1, 1}), 0.0);
    const clvr::Volume v = clvr::generateVolume("sphere", {5, 5, 5});
    EXPECT_EQ(v.at(2, 2, 2), 1.0f);
    EXPECT_EQ(v.at(3, 2, 2), 0.5f);
    EXPECT_EQ(v.at(0, 0, 0), 0.0f);
    EXPECT_EQ(v.range(), glm::dvec2(0.0, 1.0));
}

TEST(Generators, BlobsStayInUnitRangeAndAreFixed)
{
    const clvr::Volume v = clvr::generateVolume("blobs", {33, 33, 33});
    const glm::dvec2 range = v.range();
    EXPECT_GE(range.x, 0.0);
    EXPECT_LE(range.y, 1.0);
    EXPECT_GT(range.y, 0.99) << "the largest blob (amplitude 1) must show";
    // At each center: its amplitude plus the others' tails (values from an independent evaluation).
    EXPECT_EQ(clvr::blobsField({-0.35, -0.25, -0.2}), 1.0);  // 1.00006 before the clamp
    EXPECT_NEAR(clvr::blobsField({0.40, 0.15, 0.25}), 0.755866, 1e-6);
    EXPECT_NEAR(clvr::blobsField({-0.05, 0.50, -0.45}), 0.518997, 1e-6);
    EXPECT_NEAR(clvr::blobsField({0.15, -0.45, 0.50}), 0.268125, 1e-6);
    EXPECT_LT(clvr::blobsField({1, 1, 1}), 1e-6);
    // Deterministic: a second generation is bit-identical.
    EXPECT_EQ(clvr::generateVolume("blobs", {33, 33, 33}).values, v.values);
}

TEST(Generators, UnknownNameAndBadDimsThrowInputError)
{
    EXPECT_THROW(clvr::generateVolume("torus", {8, 8, 8}), clvr::InputError);
    EXPECT_THROW(clvr::generateVolume("sphere", {1, 8, 8}), clvr::InputError);
    EXPECT_THROW(clvr::generateVolume("sphere", {8, 0, 8}), clvr::InputError);
    EXPECT_THROW(clvr::generateVolume("sphere", {8, 8, -3}), clvr::InputError);
    EXPECT_THROW(clvr::generateVolume("sphere", {4096, 4096, 4096}), clvr::InputError);  // 2^36 points
    try {
        clvr::generateVolume("torus", {8, 8, 8});
    } catch (const clvr::InputError& e) {
        EXPECT_NE(std::string(e.what()).find("torus"), std::string::npos) << e.what();
    }
    try {
        clvr::generateVolume("blobs", {8, 1, 8});
    } catch (const clvr::InputError& e) {
        EXPECT_NE(std::string(e.what()).find("dims[1] is 1"), std::string::npos) << e.what();
    }
}

}  // namespace

namespace clvr {

// seeds/000's binary cellular automaton: distinct cubes of the lattice, 12 tetrahedra and 9 own points
// each, value 1 at the center and 0 at the corners, every tetrahedron of volume h^3 / 12.
TEST(Generators, AutomatonCellsAreSeparateCubesOfTwelveTets)
{
    const int cells = 500, grid = 12;
    TetMesh mesh = automatonMesh(cells, grid);
    ASSERT_EQ(mesh.points.size(), 9u * cells);
    ASSERT_EQ(mesh.tets.size(), 12u * cells);
    const double h = 2.0 / grid;
    std::set<std::tuple<long, long, long>> cubes;
    for (int c = 0; c < cells; ++c) {
        const glm::dvec3 center = mesh.points[9 * c + 8];
        EXPECT_EQ(mesh.scalars[9 * c + 8], 1.0);
        for (int k = 0; k < 8; ++k)
            EXPECT_EQ(mesh.scalars[9 * c + k], 0.0);
        cubes.insert({std::lround((center.x + 1.0) / h - 0.5), std::lround((center.y + 1.0) / h - 0.5),
                      std::lround((center.z + 1.0) / h - 0.5)});
        for (int t = 0; t < 12; ++t) {
            const glm::uvec4 tet = mesh.tets[12 * c + t];
            for (int k = 0; k < 4; ++k)
                EXPECT_EQ(tet[k] / 9, static_cast<unsigned>(c));  // no vertex of another cube
            const double v6 = signedVolume6(mesh.points[tet[0]], mesh.points[tet[1]], mesh.points[tet[2]], mesh.points[tet[3]]);
            EXPECT_NEAR(std::abs(v6) / 6.0, h * h * h / 12.0, 1e-12);
        }
    }
    EXPECT_EQ(cubes.size(), static_cast<std::size_t>(cells));  // distinct
    checkMesh(mesh);
    EXPECT_EQ(mesh.tetsDegenerate, 0u);
    EXPECT_EQ(mesh.tets.size(), 12u * cells);
    EXPECT_THROW(automatonMesh(0, 10), InputError);
    EXPECT_THROW(automatonMesh(1001, 10), InputError);
    EXPECT_THROW(automatonMesh(1, 0), InputError);
}

TEST(Generators, AutomatonMeshSpecParsesLoadsAndRejects)
{
    const TetMesh mesh = loadMesh(nlohmann::json{{"generator", "automaton"}, {"cells", 100}, {"grid", 10}}, "/");
    EXPECT_EQ(mesh.tets.size(), 1200u);
    EXPECT_EQ(parseMeshSpec(nlohmann::json{{"generator", "automaton"}}, "/").cells, 8000);
    EXPECT_THROW(parseMeshSpec(nlohmann::json{{"generator", "bunny"}}, "/"), InputError);
    EXPECT_THROW(parseMeshSpec(nlohmann::json{{"generator", "automaton"}, {"cells", -1}}, "/"), InputError);
    EXPECT_THROW(parseMeshSpec(nlohmann::json{{"generator", "automaton"}, {"size", 3}}, "/"), InputError);
    EXPECT_THROW(loadMesh(nlohmann::json{{"generator", "automaton"}, {"cells", 2000}, {"grid", 10}}, "/"), InputError);
}

TEST(Generators, KernelFieldGlowsAtTheLCorner)
{
    EXPECT_DOUBLE_EQ(kernelField({-0.5, -0.5, -0.5}), 1.0);
    EXPECT_NEAR(kernelField({-0.5, -0.5, -0.5 + 0.3}), 0.1 + 0.9 * std::exp(-0.5), 1e-12);
    EXPECT_GT(kernelField({0.9, -0.9, -0.1}), 0.1);
    EXPECT_LT(kernelField({0.9, -0.9, -0.1}), 0.11);
}

}  // namespace clvr
