// tests/clip_mesh_test.cpp — clip surfaces (host/optics/clip_mesh.h): generators closed and facing out with
// the right volume, the readers (.off and ASCII .stl through tetgenio, binary .stl and .obj by clvr),
// the closedness check, the scene spec's errors, and ray parity (watertight at shared edges and points) against analytic shapes.
#include "host/optics/clip_mesh.h"

#include "host/runtime/errors.h"
#include "tests/support/test_util.h"

#include <nlohmann/json.hpp>

#include <cmath>
#include <cstring>
#include <functional>
#include <numbers>

namespace clvr {
namespace {

using nlohmann::json;
constexpr double kPi = std::numbers::pi;

void expectInputError(const std::function<void()>& f, const std::string& fragment)
{
    try {
        f();
        ADD_FAILURE() << "no InputError (expected one containing \"" << fragment << "\")";
    } catch (const InputError& e) {
        EXPECT_NE(std::string(e.what()).find(fragment), std::string::npos) << e.what();
    }
}

// Volumes of the inscribed polyhedra: box exact; UV sphere and cylinder a little under the round
// shapes (the sphere with 64 meridians and 32 rings: 0.5 %, measured; the 48-gon: 0.29 %).
TEST(ClipMesh, GeneratedSurfacesAreClosedAndFaceOutward)
{
    ClipMesh box = boxMesh({-0.7, -0.4, -0.9}, {0.5, 0.8, 0.6});
    closeClipMesh(box);
    EXPECT_EQ(box.triangles.size(), 12u);
    EXPECT_NEAR(signedVolume(box), 1.2 * 1.2 * 1.5, 1e-12);

    ClipMesh sphere = sphereMesh({0.1, -0.2, 0.3}, 0.75, 64);
    const std::size_t triangles = sphere.triangles.size();
    const double before = signedVolume(sphere);  // generated outward already: closing changes nothing
    closeClipMesh(sphere);
    EXPECT_EQ(sphere.triangles.size(), triangles);
    EXPECT_EQ(signedVolume(sphere), before);
    const double ball = 4.0 / 3.0 * kPi * std::pow(0.75, 3);
    EXPECT_LT(signedVolume(sphere), ball);
    EXPECT_GT(signedVolume(sphere), 0.99 * ball);

    ClipMesh cylinder = cylinderMesh({0.0, 0.1, 0.0}, {1.0, 1.0, 0.0}, 0.4, 1.3, 48);
    closeClipMesh(cylinder);
    const double round = kPi * 0.4 * 0.4 * 1.3;
    EXPECT_LT(signedVolume(cylinder), round);
    EXPECT_GT(signedVolume(cylinder), 0.995 * round);
}

TEST(ClipMesh, CloseMergesStlPointsFlipsInwardMeshesAndRejectsOpenOnes)
{
    // Every triangle with its own three points (as STL stores them), all wound inward.
    const ClipMesh box = boxMesh({0, 0, 0}, {1, 2, 3});
    ClipMesh soup;
    soup.source = "soup";
    for (const auto& t : box.triangles) {
        const std::uint32_t n = static_cast<std::uint32_t>(soup.points.size());
        for (int i : {0, 2, 1})
            soup.points.push_back(box.points[t[i]]);
        soup.triangles.push_back({n, n + 1, n + 2});
    }
    closeClipMesh(soup);
    EXPECT_EQ(soup.points.size(), 8u);
    EXPECT_NEAR(signedVolume(soup), 6.0, 1e-12);

    ClipMesh open = box;
    open.source = "open";
    open.triangles.pop_back();
    expectInputError([&] { closeClipMesh(open); }, "open: the clip mesh is not a closed, consistently oriented surface");
    ClipMesh twisted = box;
    twisted.source = "twisted";
    std::swap(twisted.triangles[3][1], twisted.triangles[3][2]);
    expectInputError([&] { closeClipMesh(twisted); }, "twisted: the clip mesh is not a closed");
    ClipMesh empty;
    empty.source = "empty";
    expectInputError([&] { closeClipMesh(empty); }, "empty: the clip mesh has no triangles");
}

// The repository's torus (R = 0.6, r = 0.25 about z; 768 points, 1536 triangles) through TetGen's
// .off reader; its volume is 2 pi^2 R r^2 less the polygonal loss (a 16-gon tube keeps 97.4 % of the
// disc's area; measured 98.2 % of the volume).
TEST(ClipMesh, ReadsTheTorusOff)
{
    const ClipMesh torus = loadClipMesh(parseClipMeshSpec(test::repoData("surfaces/torus.off"), "mesh"), {});
    EXPECT_EQ(torus.points.size(), 768u);
    EXPECT_EQ(torus.triangles.size(), 1536u);
    const double exact = 2.0 * kPi * kPi * 0.6 * 0.25 * 0.25;
    EXPECT_LT(signedVolume(torus), exact);
    EXPECT_GT(signedVolume(torus), 0.97 * exact);
}

TEST(ClipMesh, ReadsObjAndAsciiAndBinaryStlWithPlacement)
{
    test::TempDir dir;
    // A unit cube as OBJ quads, with texture/normal indices, a negative index, and ignored statements.
    test::writeFile(dir / "cube.obj",
                    "# cube\no cube\nv 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 0 0 1\nv 1 0 1\nv 1 1 1\nv 0 1 1\n"
                    "vt 0 0\nvn 0 0 1\ns off\n"
                    "f 1/1 4/1 3/1 2/1\nf 5//1 6//1 7//1 8//1\nf 1 2 6 5\nf 2 3 7 6\nf 3 4 8 7\nf 4 1 5 -1\n");
    ClipMeshSpec spec = parseClipMeshSpec(json{{"file", "cube.obj"}, {"scale", {2, 1, 0.5}}, {"translate", {1, 2, 3}}},
                                          "mesh");
    const ClipMesh cube = loadClipMesh(spec, dir.path());
    EXPECT_EQ(cube.triangles.size(), 12u);
    EXPECT_NEAR(signedVolume(cube), 1.0, 1e-12);
    EXPECT_TRUE(insideClipMesh(cube, {2.9, 2.5, 3.4}));
    EXPECT_FALSE(insideClipMesh(cube, {3.1, 2.5, 3.4}));

    // ASCII STL of a box (TetGen's load_stl; one point per triangle corner, merged by closeClipMesh).
    const ClipMesh box = boxMesh({-1, -1, -1}, {1, 1, 1});
    std::string stl = "solid box\n";
    for (const auto& t : box.triangles) {
        stl += " facet normal 0 0 0\n  outer loop\n";
        for (std::uint32_t i : t)
            stl += "   vertex " + std::to_string(box.points[i].x) + " " + std::to_string(box.points[i].y) + " " +
                   std::to_string(box.points[i].z) + "\n";
        stl += "  endloop\n endfacet\n";
    }
    stl += "endsolid box\n";
    test::writeFile(dir / "box.stl", stl);
    const ClipMesh read = loadClipMesh(parseClipMeshSpec("box.stl", "mesh"), dir.path());
    EXPECT_EQ(read.points.size(), 8u);
    EXPECT_NEAR(signedVolume(read), 8.0, 1e-12);

    // The same box as binary STL (little-endian floats), which tetgenio cannot read.
    std::string binary(80, ' ');
    auto u32 = [&](std::uint32_t v) {
        for (int i = 0; i < 4; ++i)
            binary += static_cast<char>((v >> (8 * i)) & 0xff);
    };
    auto f32 = [&](float f) {
        std::uint32_t v;
        std::memcpy(&v, &f, 4);
        u32(v);
    };
    u32(static_cast<std::uint32_t>(box.triangles.size()));
    for (const auto& t : box.triangles) {
        for (int i = 0; i < 3; ++i)
            f32(0.0f);
        for (std::uint32_t i : t)
            for (int axis = 0; axis < 3; ++axis)
                f32(static_cast<float>(box.points[i][axis]));
        binary += std::string(2, '\0');
    }
    test::writeFile(dir / "box-binary.stl", binary);
    const ClipMesh readBinary = loadClipMesh(parseClipMeshSpec("box-binary.stl", "mesh"), dir.path());
    EXPECT_EQ(readBinary.points.size(), 8u);
    EXPECT_NEAR(signedVolume(readBinary), 8.0, 1e-12);
    test::writeFile(dir / "cut-binary.stl", binary.substr(0, binary.size() - 10));  // neither binary nor ASCII
    expectInputError([&] { readSurface(dir / "cut-binary.stl"); }, "cut-binary.stl: TetGen's reader could not read a surface");

    test::writeFile(dir / "bad.obj", "v 0 0 0\nv 1 0 0\nf 1 2 3\n");
    expectInputError([&] { readSurface(dir / "bad.obj"); }, "bad.obj:3: face index 3 names no vertex read so far (2)");
    expectInputError([&] { readSurface(dir / "missing.off"); }, "missing.off: no such file (clip mesh)");
    test::writeFile(dir / "x.ply", "ply\n");
    expectInputError([&] { readSurface(dir / "x.ply"); }, "unknown surface format \".ply\" (.off, .stl, .obj)");
}

TEST(ClipMesh, BadSpecsNameTheKey)
{
    auto bad = [](const json& spec, const std::string& fragment) {
        expectInputError([&] { parseClipMeshSpec(spec, "options.clip.mesh"); }, fragment);
    };
    bad(3, "options.clip.mesh: must be a file name or an object");
    bad(json::object(), "options.clip.mesh: give either \"file\" or \"generator\"");
    bad({{"generator", "cone"}}, "options.clip.mesh.generator: must be \"box\", \"sphere\" or \"cylinder\"");
    bad({{"generator", "sphere"}, {"radius", -1}}, "options.clip.mesh.radius: must be a positive number");
    bad({{"generator", "sphere"}, {"height", 1}}, "options.clip.mesh.height: unknown key (known: generator, center, radius, segments)");
    bad({{"generator", "sphere"}, {"segments", 2}}, "options.clip.mesh.segments: must be an integer in [3, 4096]");
    bad({{"generator", "cylinder"}, {"axis", {0, 0, 0}}}, "options.clip.mesh.axis: must not be zero");
    bad({{"generator", "box"}, {"min", {0, 0, 0}}, {"max", {1, 0, 1}}}, "options.clip.mesh.max: must be greater than min");
    bad({{"generator", "box"}, {"center", {0, 0}}}, "options.clip.mesh.center: unknown key");
    bad({{"file", "a.off"}, {"scale", 0}}, "options.clip.mesh.scale: must be a finite non-zero number");
    bad({{"file", "a.off"}, {"translate", {1, 2}}}, "options.clip.mesh.translate: must be [x, y, z]");
}

// Rays exactly through shared edges and points must cross a closed surface an even number of times
// (once in, once out): the box's face diagonals on the axes, its corners on the main diagonal, the
// sphere's poles (64 triangles share each).
TEST(ClipMesh, RayCrossingsAreWatertightAtEdgesAndPoints)
{
    ClipMesh box = boxMesh({-1, -1, -1}, {1, 1, 1});
    closeClipMesh(box);
    for (const glm::dvec3 d : {glm::dvec3(0, 0, 1), glm::dvec3(1, 0, 0), glm::dvec3(0, -1, 0), glm::dvec3(1, 1, 1),
                               glm::dvec3(-1, 1, -1), glm::dvec3(1, 1, 0)}) {
        const glm::dvec3 u = glm::normalize(d);
        const std::vector<double> c = rayCrossings(box, Ray{-5.0 * u, u});
        ASSERT_EQ(c.size(), 2u) << d.x << " " << d.y << " " << d.z;
        EXPECT_NEAR(c[1] - c[0], 2.0 * glm::length(d) / std::max({std::abs(d.x), std::abs(d.y), std::abs(d.z)}), 1e-12);
    }
    ClipMesh sphere = sphereMesh({0, 0, 0}, 1.0, 64);
    closeClipMesh(sphere);
    const std::vector<double> c = rayCrossings(sphere, Ray{{0, 0, -3}, {0, 0, 1}});
    ASSERT_EQ(c.size(), 2u);
    EXPECT_NEAR(c[0], 2.0, 1e-12);
    EXPECT_NEAR(c[1], 4.0, 1e-12);
    // Intervals: inside [2, 4] of [0, 10], outside its complement; clipped to [2.5, 3].
    const Ray axis{{0, 0, -3}, {0, 0, 1}};
    EXPECT_EQ(clipIntervals(sphere, axis, 0.0, 10.0, false), (std::vector<glm::dvec2>{{c[0], c[1]}}));
    EXPECT_EQ(clipIntervals(sphere, axis, 0.0, 10.0, true), (std::vector<glm::dvec2>{{0.0, c[0]}, {c[1], 10.0}}));
    EXPECT_EQ(clipIntervals(sphere, axis, 2.5, 3.0, false), (std::vector<glm::dvec2>{{2.5, 3.0}}));
    EXPECT_TRUE(clipIntervals(sphere, axis, 2.5, 3.0, true).empty());
}

// Ray parity against the analytic torus (R = 0.6, r = 0.25 about z) at random points away from the
// surface by more than the polygon's deviation from it (< 0.006 here; margin 0.02).
TEST(ClipMesh, InsideMatchesTheAnalyticTorus)
{
    const ClipMesh torus = loadClipMesh(parseClipMeshSpec(test::repoData("surfaces/torus.off"), "mesh"), {});
    test::Rng rng(11);
    int inside = 0, tested = 0;
    for (int i = 0; i < 4000; ++i) {
        const glm::dvec3 p(rng.uniform(-1, 1), rng.uniform(-1, 1), rng.uniform(-0.4, 0.4));
        const double tube = std::hypot(std::hypot(p.x, p.y) - 0.6, p.z) - 0.25;  // signed distance
        if (std::abs(tube) < 0.02)
            continue;
        ++tested;
        inside += tube < 0;
        ASSERT_EQ(insideClipMesh(torus, p), tube < 0) << p.x << " " << p.y << " " << p.z;
    }
    EXPECT_GT(inside, 200);
    EXPECT_GT(tested - inside, 200);
}

}  // namespace
}  // namespace clvr
