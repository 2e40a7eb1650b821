// tests/surface_io_test.cpp — host/io/surface_io.h against tetgenio's own readers (same points, polygons,
// holes and numbering, so TetGen makes the same mesh), and TetGen silenced without touching stdout:
// meshing and reading clip surfaces print nothing.
#include "host/io/surface_io.h"

#include "host/optics/clip_mesh.h"
#include "host/runtime/errors.h"
#include "host/io/tetgen_mesher.h"
#include "tests/support/test_util.h"

#include <tetgen.h>

#include <gtest/gtest.h>

#include <array>

#include <string>
#include <vector>

namespace clvr {
namespace {

std::vector<char> cString(const std::string& s)
{
    std::vector<char> v(s.begin(), s.end());
    v.push_back('\0');
    return v;
}

// `path` through tetgenio::load_off / load_stl / load_plc (which print; captured and dropped).
bool loadWithTetgen(const std::filesystem::path& path, tetgenio& io)
{
    const std::string ext = path.extension().string();
    std::filesystem::path base = path;
    base.replace_extension();
    auto name = cString(ext == ".poly" || ext == ".smesh" ? base.string() : path.string());
    testing::internal::CaptureStdout();
    const bool ok = ext == ".off"   ? io.load_off(name.data())
                    : ext == ".stl" ? io.load_stl(name.data())
                                    : io.load_plc(name.data(), static_cast<int>(tetgenbehavior::POLY));
    testing::internal::GetCapturedStdout();
    return ok;
}

void expectSameAsTetgen(const std::filesystem::path& path)
{
    SCOPED_TRACE(path.string());
    tetgenio io;
    ASSERT_TRUE(loadWithTetgen(path, io));
    const Plc plc = readPlc(path);
    EXPECT_EQ(plc.firstNumber, io.firstnumber);
    ASSERT_EQ(static_cast<int>(plc.points.size()), io.numberofpoints);
    for (int i = 0; i < io.numberofpoints; ++i)
        for (int a = 0; a < 3; ++a)
            ASSERT_EQ(plc.points[i][a], io.pointlist[3 * i + a]) << "point " << i;  // both strtod: exact
    ASSERT_EQ(static_cast<int>(plc.facets.size()), io.numberoffacets);
    for (int f = 0; f < io.numberoffacets; ++f) {
        const tetgenio::facet& facet = io.facetlist[f];
        ASSERT_EQ(static_cast<int>(plc.facets[f].polygons.size()), facet.numberofpolygons) << "facet " << f;
        EXPECT_EQ(static_cast<int>(plc.facets[f].holes.size()), facet.numberofholes) << "facet " << f;
        for (int p = 0; p < facet.numberofpolygons; ++p) {
            const tetgenio::polygon& poly = facet.polygonlist[p];
            const std::vector<int> want(poly.vertexlist, poly.vertexlist + poly.numberofvertices);
            EXPECT_EQ(plc.facets[f].polygons[p], want) << "facet " << f << " polygon " << p;
        }
    }
    EXPECT_EQ(static_cast<int>(plc.holes.size()), io.numberofholes);
    EXPECT_EQ(static_cast<int>(plc.regions.size()), io.numberofregions);
}

// An ASCII STL of a unit tetrahedron's four faces, numbers in TetGen's loose style.
const char* kTetraStl = "solid tetra\n"
                        " facet normal 0 0 -1\n  outer loop\n   vertex 0 0 0\n   vertex 0 1 0\n   vertex 1 0 0\n"
                        "  endloop\n endfacet\n"
                        " facet normal 0 -1 0\n  outer loop\n   vertex 0 0 0\n   vertex 1 0 0\n   vertex 0 0 1\n"
                        "  endloop\n endfacet\n"
                        " facet normal -1 0 0\n  outer loop\n   vertex 0 0 0\n   vertex 0 0 1\n   vertex 0 1 0\n"
                        "  endloop\n endfacet\n"
                        " facet normal 1 1 1\n  outer loop\n   vertex 1 0 0\n   vertex 0 1 0\n   vertex 0 0 1.0e0\n"
                        "  endloop\n endfacet\n"
                        "endsolid tetra\n";

// A .poly with a facet hole, a volume hole and a region, 1-based, comments and blank lines.
const char* kHolePoly = "# a box with a square hole in its top facet region\n"
                        "8 3 0 1\n"
                        "1 0 0 0 1\n2 1 0 0 1\n3 1 1 0 1\n4 0 1 0 1\n"
                        "5 0 0 1 2\n6 1 0 1 2\n7 1 1 1 2\n8 0 1 1 2\n"
                        "\n6 1\n"
                        "1 0 1\n4 1 2 3 4\n"
                        "2 1 2\n4 5 6 7 8\n3 5 6 7\n1 0.6 0.4 1.0\n"  // two polygons, one hole point
                        "1 0 3\n4 1 2 6 5\n1 0 4\n4 2 3 7 6\n1 0 5\n4 3 4 8 7\n1 0 6\n4 4 1 5 8\n"
                        "1\n1 5 5 5\n"
                        "1\n1 0.5 0.5 0.5 7 0.01\n";

TEST(SurfaceIo, ReadsWhatTetgenReads)
{
    expectSameAsTetgen(test::repoData("surfaces/torus.off"));
    expectSameAsTetgen(test::repoData("surfaces/l-block.poly"));
    test::TempDir dir;
    test::writeFile(dir / "tetra.stl", kTetraStl);
    expectSameAsTetgen(dir / "tetra.stl");
    test::writeFile(dir / "holes.poly", kHolePoly);
    expectSameAsTetgen(dir / "holes.poly");
    const Plc holes = readPlc(dir / "holes.poly");
    ASSERT_EQ(holes.facets[1].holes.size(), 1u);
    EXPECT_EQ(holes.facets[1].holes[0], glm::dvec3(0.6, 0.4, 1.0));
    ASSERT_EQ(holes.regions.size(), 1u);
    EXPECT_EQ(holes.regions[0].maxVolume, 0.01);
    EXPECT_EQ(holes.facets[5].marker, 6);
    test::writeFile(dir / "one-based.off", "OFF\n4 4 0\n0 0 0\n1 0 0\n0 1 0\n0 0 1\n"
                                           "3 1 3 2\n3 1 2 4\n3 1 4 3\n3 2 3 4\n");
    expectSameAsTetgen(dir / "one-based.off");
}

TEST(SurfaceIo, BadFilesAreInputErrorsNamingTheLine)
{
    test::TempDir dir;
    test::writeFile(dir / "short.off", "OFF\n4 1 0\n0 0 0\n1 0 0\n");
    test::writeFile(dir / "corner.off", "OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 7\n");
    test::writeFile(dir / "word.poly", "3 3 0 0\n0 0 0 0\n1 1 0 x\n");
    test::writeFile(dir / "empty.stl", "solid nothing\nendsolid nothing\n");
    const std::vector<std::pair<std::string, std::string>> cases = {
        {"short.off", "short.off: ends before point 2"},
        {"corner.off", "corner.off:6: polygon corner 7 names no point (3 points)"},
        {"word.poly", "word.poly:3: point: \"x\" is not a finite number"},
        {"empty.stl", "empty.stl: 0 vertices"},
        {"none.off", "none.off: no such file"},
    };
    for (const auto& [file, message] : cases) {
        try {
            readPlc(dir / file);
            ADD_FAILURE() << file << ": no InputError";
        } catch (const InputError& e) {
            EXPECT_NE(std::string(e.what()).find(message), std::string::npos) << e.what();
        }
    }
}

// Surfaces as they come (issue 15): two closed tetrahedra that overlap (TetGen's mesher segfaulted on
// them), an open one, two that share an edge (non-manifold), one with a zero-area facet, and an STL whose
// repeated corners make a closed tetrahedron: one InputError each, before TetGen meshes anything.
TEST(SurfaceIo, SelfIntersectingAndOpenSurfacesAreInputErrors)
{
    test::TempDir dir;
    const std::string tet = "3 0 2 1\n3 0 1 3\n3 0 3 2\n3 1 2 3\n";
    test::writeFile(dir / "crossing.off", "OFF\n8 8 0\n0 0 0\n1 0 0\n0 1 0\n0 0 1\n"
                                          "0.2 0.2 0.2\n1.2 0.2 0.2\n0.2 1.2 0.2\n0.2 0.2 1.2\n" + tet +
                                          "3 4 6 5\n3 4 5 7\n3 4 7 6\n3 5 6 7\n");
    test::writeFile(dir / "open.off", "OFF\n4 3 0\n0 0 0\n1 0 0\n0 1 0\n0 0 1\n3 0 2 1\n3 0 1 3\n3 0 3 2\n");
    test::writeFile(dir / "apart.off", "OFF\n8 8 0\n0 0 0\n1 0 0\n0 1 0\n0 0 1\n"
                                       "3 3 3\n4 3 3\n3 4 3\n3 3 4\n" + tet +
                                       "3 4 6 5\n3 4 5 7\n3 4 7 6\n3 5 6 7\n");
    test::writeFile(dir / "edge.off", "OFF\n6 8 0\n0 0 0\n1 0 0\n0 1 0\n0 0 1\n0 -1 0\n0 0 -1\n" + tet +
                                      "3 0 1 4\n3 0 5 1\n3 1 5 4\n3 0 4 5\n");
    test::writeFile(dir / "flat.off", "OFF\n5 5 0\n0 0 0\n1 0 0\n0 1 0\n0 0 1\n0.5 0 0\n3 0 2 1\n3 0 1 3\n3 1 2 3\n"
                                      "3 0 3 2\n3 0 4 1\n");
    std::string stl = "solid t\n";
    const char* corners[4] = {"0 0 0", "1 0 0", "0 1 0", "0 0 1"};
    for (const auto& f : {std::array{0, 2, 1}, std::array{0, 1, 3}, std::array{0, 3, 2}, std::array{1, 2, 3}}) {
        stl += "facet normal 0 0 0\nouter loop\n";
        for (int c : f)
            stl += std::string("vertex ") + corners[c] + "\n";
        stl += "endloop\nendfacet\n";
    }
    test::writeFile(dir / "tet.stl", stl + "endsolid t\n");
    test::writeFile(dir / "open.stl", stl.substr(0, stl.rfind("facet normal")) + "endsolid t\n");
    const std::pair<const char*, const char*> cases[] = {
        {"crossing.off", "the surface intersects itself"},
        {"open.off", "borders 1 facet: the surface is open (a hole)"},
        {"open.stl", "borders 1 facet: the surface is open (a hole)"},
        {"edge.off", "the edge (0, 0, 0) - (1, 0, 0) borders 4 facets: the surface is not a manifold"},
        {"flat.off", "facet 4 (points 0 4 1) has zero area"},
    };
    for (const auto& [file, message] : cases) {
        try {
            meshSurface(dir / file, MesherOptions{});
            ADD_FAILURE() << file << ": no InputError";
        } catch (const InputError& e) {
            EXPECT_NE(std::string(e.what()).find(message), std::string::npos) << e.what();
        }
    }
    // The same two tetrahedra apart are a valid (two-part) surface, and the STL's 12 corners are 4 points.
    EXPECT_GE(meshSurface(dir / "apart.off", MesherOptions{}).tets.size(), 2u);
    EXPECT_EQ(meshSurface(dir / "tet.stl", MesherOptions{}).tets.size(), 1u);
}

// A scalar volume the mesh lies entirely outside of gives an error, not a constant border value.
TEST(SurfaceIo, ScalarVolumeMissingTheMeshIsAnInputError)
{
    test::TempDir dir;
    test::writeFile(dir / "far.nrrd", std::string("NRRD0004\ntype: uchar\ndimension: 3\nsizes: 2 2 2\nspace dimension: 3\n"
                                                  "space origin: (100,100,100)\nencoding: raw\n\n") +
                                          std::string("\x01\x02\x03\x04\x05\x06\x07\x08", 8));
    MesherOptions options;
    options.scalar = (dir / "far.nrrd").string();
    try {
        meshSurface(test::repoData("surfaces/torus.off"), options);
        ADD_FAILURE() << "no InputError";
    } catch (const InputError& e) {
        EXPECT_NE(std::string(e.what()).find("no point of the mesh lies inside the volume's bounds"), std::string::npos)
            << e.what();
    }
}

TEST(SurfaceIo, MeshingPrintsNothingAndMatchesTetgensOwnReader)
{
    const std::filesystem::path torus = test::repoData("surfaces/torus.off");
    MesherOptions options;  // "pQz": TetGen's own quiet switch
    testing::internal::CaptureStdout();
    const TetMesh meshed = meshSurface(torus, options);
    const TetMesh block = meshSurface(test::repoData("surfaces/l-block.poly"), options);
    const ClipMesh clip = readSurface(torus);
    const std::string printed = testing::internal::GetCapturedStdout();
    EXPECT_EQ(printed, "");
    EXPECT_GT(block.tets.size(), 0u);
    EXPECT_EQ(clip.triangles.size(), 1536u);

    // The same tetrahedralization from tetgenio::load_off's input: identical points and tetrahedra.
    tetgenio in, out;
    ASSERT_TRUE(loadWithTetgen(torus, in));
    auto switches = cString(tetgenSwitches(options));
    tetrahedralize(switches.data(), &in, &out);
    ASSERT_EQ(static_cast<int>(meshed.points.size()), out.numberofpoints);
    ASSERT_EQ(static_cast<int>(meshed.tets.size()), out.numberoftetrahedra);
    for (int i = 0; i < out.numberofpoints; ++i)
        for (int a = 0; a < 3; ++a)
            ASSERT_EQ(meshed.points[i][a], out.pointlist[3 * i + a]) << "point " << i;
    for (int t = 0; t < out.numberoftetrahedra; ++t)
        for (int k = 0; k < 4; ++k)
            ASSERT_EQ(static_cast<int>(meshed.tets[t][k]), out.tetrahedronlist[t * out.numberofcorners + k]);
}

}  // namespace
}  // namespace clvr
