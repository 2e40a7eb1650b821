// tests/mesh_io_test.cpp — tetrahedral mesh input: the real data sets (bluntfin PLOT3D, post.vtk,
// tetraMesh.vtk) with their counts and topology, round trips through TetGen and VTK ASCII/BINARY files
// written here, hexahedron and wedge splits, the scene's "mesh" object, and malformed files giving a
// one-line InputError that names the file. Files are written to a temporary directory.
#include "host/runtime/errors.h"
#include "host/io/generators.h"
#include "host/model/mesh.h"
#include "host/io/mesh_io.h"
#include "host/io/tetgen_mesher.h"
#include "tests/support/test_util.h"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <unistd.h>

#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <functional>
#include <numbers>
#include <sstream>

namespace fs = std::filesystem;
using clvr::InputError;
using clvr::TetMesh;

namespace {

using clvr::test::readFile;
using clvr::test::TempDir;
using clvr::test::writeFile;

std::string messageOf(const std::function<void()>& f)
{
    try {
        f();
    } catch (const InputError& e) {
        return e.what();
    }
    return "(no InputError)";
}

// Expects a one-line InputError mentioning `part` (and the file, when given).
void expectError(const std::function<void()>& f, const std::string& part, const std::string& file = "")
{
    const std::string msg = messageOf(f);
    EXPECT_NE(msg.find(part), std::string::npos) << msg;
    if (!file.empty()) {
        EXPECT_NE(msg.find(file), std::string::npos) << msg;
    }
    EXPECT_EQ(msg.find('\n'), std::string::npos) << msg;
}

double totalVolume(const TetMesh& m)
{
    double v = 0;
    for (const auto& c : m.tets)
        v += clvr::signedVolume6(m.points[c[0]], m.points[c[1]], m.points[c[2]], m.points[c[3]]) / 6.0;
    return v;
}

TetMesh sampleMesh()
{
    TetMesh m;
    m.points = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1}, {1, 1, 1}, {0.1, 0.2, 0.30000000000000004}};
    m.scalars = {0.5, -1.25, 3e-7, 1e10, 2.0 / 3.0, 7};
    m.tets = {{0, 1, 2, 3}, {1, 2, 3, 4}, {0, 1, 3, 5}};
    return m;
}

void expectSame(const TetMesh& a, const TetMesh& b)
{
    ASSERT_EQ(a.points.size(), b.points.size());
    ASSERT_EQ(a.tets.size(), b.tets.size());
    for (std::size_t i = 0; i < a.points.size(); ++i) {
        EXPECT_EQ(a.points[i], b.points[i]) << i;
        EXPECT_EQ(a.scalars[i], b.scalars[i]) << i;
    }
    for (std::size_t t = 0; t < a.tets.size(); ++t)
        EXPECT_EQ(a.tets[t], b.tets[t]) << t;
}

}  // namespace

// ---------------------------------------------------------------------------------------------------
// Real data.

TEST(MeshIo, BluntfinGives224874Tets)
{
    const std::string dir = clvr::test::sharedData("bluntfin");
    TetMesh m = clvr::loadMesh({{"file", "bluntfinxyz.bin"}, {"q_file", "bluntfinq.bin"}}, dir);
    EXPECT_EQ(m.points.size(), 40u * 32 * 32);
    EXPECT_EQ(m.tetsRead, 224874u);
    EXPECT_EQ(m.tets.size() + m.tetsDegenerate, 224874u);
    const clvr::TetTopology topo = clvr::buildTopology(m);  // throws for a face shared by three
    std::printf("bluntfin: %llu tets read, %llu degenerate, %llu reoriented, %zu boundary faces, density %g..%g\n",
                static_cast<unsigned long long>(m.tetsRead), static_cast<unsigned long long>(m.tetsDegenerate),
                static_cast<unsigned long long>(m.tetsReoriented), topo.boundary.size(), m.scalarRange().x,
                m.scalarRange().y);
    EXPECT_GT(m.scalarRange().x, 0.0);
    EXPECT_EQ(m.tetsDegenerate, 115u);        // measured: cells where the grid collapses onto itself
    EXPECT_EQ(topo.boundary.size(), 13438u);  // measured; the block's six sides have 2*2*(39*31*2 + 31*31) = 13,516
    for (const auto& c : m.tets)
        ASSERT_GT(clvr::signedVolume6(m.points[c[0]], m.points[c[1]], m.points[c[2]], m.points[c[3]]), 0.0);
    // Every scalar choice loads; pressure is positive in this flow.
    for (const char* s : {"momentum", "energy", "pressure"}) {
        TetMesh q = clvr::loadMesh({{"file", "bluntfinxyz.bin"}, {"q_file", "bluntfinq.bin"}, {"scalar", s}}, dir);
        EXPECT_EQ(q.tetsRead, 224874u) << s;
        if (std::string(s) == "pressure") {
            EXPECT_GT(q.scalarRange().x, 0.0);
        }
    }
}

TEST(MeshIo, PostVtkGives8750Tets)
{
    TetMesh m = clvr::loadMesh({{"file", "post.vtk"}}, clvr::test::sharedData("post"));
    EXPECT_EQ(m.points.size(), 2288u);
    EXPECT_EQ(m.tetsRead, 8750u);
    const clvr::TetTopology topo = clvr::buildTopology(m);
    std::printf("post: %llu tets read, %llu degenerate, %llu reoriented, %zu boundary faces, Pressure %g..%g\n",
                static_cast<unsigned long long>(m.tetsRead), static_cast<unsigned long long>(m.tetsDegenerate),
                static_cast<unsigned long long>(m.tetsReoriented), topo.boundary.size(), m.scalarRange().x,
                m.scalarRange().y);
    EXPECT_GT(m.scalarRange().y, m.scalarRange().x);
    // Chosen by name, and a wrong name lists what there is.
    TetMesh p = clvr::loadMesh({{"file", "post.vtk"}, {"scalar", "Pressure"}}, clvr::test::sharedData("post"));
    EXPECT_EQ(p.scalars, m.scalars);
    expectError([] { clvr::loadMesh({{"file", "post.vtk"}, {"scalar", "rho"}}, clvr::test::sharedData("post")); },
                "no point array named \"rho\" (it has Pressure)", "post.vtk");
}

TEST(MeshIo, TetraMeshVtk)
{
    TetMesh m = clvr::loadMesh({{"file", "tetraMesh.vtk"}}, clvr::test::sharedData("post"));
    EXPECT_EQ(m.points.size(), 55u);
    EXPECT_EQ(m.tetsRead, 160u);
    const clvr::TetTopology topo = clvr::buildTopology(m);
    EXPECT_GT(topo.boundary.size(), 0u);
    EXPECT_EQ(m.scalarRange(), glm::dvec2(0, 4));  // SCALARS scalars int, values 0 and 4
}

// ---------------------------------------------------------------------------------------------------
// Round trips.

TEST(MeshIo, TetgenRoundTrip)
{
    TempDir dir;
    const TetMesh m = sampleMesh();
    clvr::writeTetgen(m, dir / "s");
    expectSame(m, clvr::readTetgen(dir / "s.ele"));
    expectSame(m, clvr::readTetgen(dir / "s.node"));
    TetMesh l = clvr::loadMesh({{"file", "s.ele"}}, dir.path());
    EXPECT_EQ(l.tetsRead, 3u);
    EXPECT_GT(totalVolume(l), 0.0);
}

TEST(MeshIo, TetgenOneBasedWithAttributesAndComments)
{
    TempDir dir;
    writeFile(dir / "a.node", "# points\n4 3 2 1\n1 0 0 0 10 20 1\n2 1 0 0 11 21 1\n3 0 1 0 12 22 0\n"
                               "4 0 0 1 13 23 1  # last\n");
    writeFile(dir / "a.ele", "1 4 0\n1 1 2 3 4\n");
    TetMesh m = clvr::readTetgen(dir / "a.node");
    EXPECT_EQ(m.tets[0], glm::uvec4(0, 1, 2, 3));
    EXPECT_EQ(m.scalars, (std::vector<double>{10, 11, 12, 13}));
    TetMesh s = clvr::loadMesh({{"file", "a.ele"}, {"scalar", 1}}, dir.path());
    EXPECT_EQ(s.scalars, (std::vector<double>{20, 21, 22, 23}));
    expectError([&] { clvr::loadMesh({{"file", "a.ele"}, {"scalar", "2"}}, dir.path()); }, "scalar attribute 2 out of range",
                "a.node");
}

TEST(MeshIo, VtkAsciiAndBinaryRoundTrip)
{
    TempDir dir;
    const TetMesh m = sampleMesh();
    for (bool binary : {false, true}) {
        const fs::path p = dir / (binary ? "b.vtk" : "a.vtk");
        clvr::writeVtkUnstructured(m, p, binary, "temperature");
        expectSame(m, clvr::readVtkUnstructured(p));
        expectSame(m, clvr::readVtkUnstructured(p, "temperature"));
    }
}

TEST(MeshIo, OffTetRoundTrip)
{
    TempDir dir;
    writeFile(dir / "a.off", "OFF\n# tetrahedral\n5 2 0\n0 0 0 1\n1 0 0 2\n0 1 0 3\n0 0 1 4\n1 1 1 5\n4 0 1 2 3\n1 2 3 4\n");
    TetMesh m = clvr::loadMesh({{"file", "a.off"}}, dir.path());
    EXPECT_EQ(m.tetsRead, 2u);
    EXPECT_EQ(m.scalars, (std::vector<double>{1, 2, 3, 4, 5}));
    EXPECT_NEAR(totalVolume(m), 1.0 / 6 + 1.0 / 3, 1e-15);  // the second tet has volume 1/3
    expectError([&] { clvr::loadMesh({{"file", "a.off"}, {"scalar", 1}}, dir.path()); }, "line 4", "a.off");
}

// A hexahedron (type 12) splits into 6 tetrahedra filling it; a wedge (13) into 3; a 2x1x1 block of
// hexahedra sharing a face is conforming (the shared face is interior).
TEST(MeshIo, VtkHexahedraAndWedgesAreSplit)
{
    TempDir dir;
    std::string pts = "POINTS 12 float\n";
    for (int k = 0; k < 2; ++k)
        for (int j = 0; j < 2; ++j)
            for (int i = 0; i < 3; ++i)
                pts += std::to_string(i) + " " + std::to_string(j) + " " + std::to_string(k) + "\n";
    auto id = [](int i, int j, int k) { return std::to_string(i + 3 * (j + 2 * k)); };
    auto hex = [&](int i) {
        return "8 " + id(i, 0, 0) + " " + id(i + 1, 0, 0) + " " + id(i + 1, 1, 0) + " " + id(i, 1, 0) + " " + id(i, 0, 1) +
               " " + id(i + 1, 0, 1) + " " + id(i + 1, 1, 1) + " " + id(i, 1, 1) + "\n";
    };
    std::string scal = "POINT_DATA 12\nSCALARS s float\nLOOKUP_TABLE default\n";
    for (int i = 0; i < 12; ++i)
        scal += std::to_string(i) + "\n";
    writeFile(dir / "hex.vtk", "# vtk DataFile Version 2.0\nhex\nASCII\nDATASET UNSTRUCTURED_GRID\n" + pts +
                                   "CELLS 2 18\n" + hex(0) + hex(1) + "CELL_TYPES 2\n12\n12\n" + scal);
    TetMesh h = clvr::loadMesh({{"file", "hex.vtk"}}, dir.path());
    EXPECT_EQ(h.tetsRead, 12u);
    EXPECT_NEAR(totalVolume(h), 2.0, 1e-14);
    EXPECT_EQ(clvr::buildTopology(h).boundary.size(), 20u);  // 10 unit squares, 2 triangles each

    // Two wedges making the cube [0,1]^3 (split along the diagonal plane x = y), numbered unevenly.
    writeFile(dir / "wedge.vtk",
              "# vtk DataFile Version 2.0\nwedge\nASCII\nDATASET UNSTRUCTURED_GRID\nPOINTS 8 float\n"
              "0 0 0  1 0 0  1 1 0  0 1 0  0 0 1  1 0 1  1 1 1  0 1 1\n"
              "CELLS 2 14\n6 0 1 2 4 5 6\n6 7 4 6 3 0 2\nCELL_TYPES 2\n13 13\n"
              "POINT_DATA 8\nSCALARS s double 1\nLOOKUP_TABLE default\n0 1 2 3 4 5 6 7\n");
    TetMesh w = clvr::loadMesh({{"file", "wedge.vtk"}}, dir.path());
    EXPECT_EQ(w.tetsRead, 6u);
    EXPECT_EQ(w.tetsDegenerate, 0u);
    EXPECT_NEAR(totalVolume(w), 1.0, 1e-14);
    EXPECT_EQ(clvr::buildTopology(w).boundary.size(), 12u);  // the diagonal plane is interior and conforming
}

// VTK 9's file version 5.1: OFFSETS and CONNECTIVITY arrays, METADATA blocks; BINARY as well.
TEST(MeshIo, VtkVersion51)
{
    TempDir dir;
    writeFile(dir / "v5.vtk", "# vtk DataFile Version 5.1\nvtk output\nASCII\nDATASET UNSTRUCTURED_GRID\n"
                              "POINTS 5 float\n0 0 0 1 0 0 0 1 0\n0 0 1 1 1 1\n"
                              "METADATA\nINFORMATION 1\nNAME L2_NORM_RANGE LOCATION vtkDataArray\nDATA 2 0 1.7\n\n"
                              "CELLS 3 8\nOFFSETS vtktypeint64\n0 4 8\nCONNECTIVITY vtktypeint64\n0 1 2 3\n1 2 3 4\n"
                              "CELL_TYPES 2\n10\n10\n\nCELL_DATA 2\nFIELD FieldData 1\nid 1 2 int\n7 8\n"
                              "POINT_DATA 5\nFIELD FieldData 2\nvel 3 5 float\n0 0 0 0 0 0 0 0 0 0 0 0 0 0 0\n"
                              "temp 1 5 double\n1 2 3 4 5\nMETADATA\nCOMPONENT_NAMES\nT\n\n");
    TetMesh m = clvr::loadMesh({{"file", "v5.vtk"}}, dir.path());
    EXPECT_EQ(m.tetsRead, 2u);
    EXPECT_EQ(m.scalars, (std::vector<double>{1, 2, 3, 4, 5}));

    // The same in BINARY (big-endian int64 offsets and connectivity).
    auto be = [](auto v) {
        std::string b(sizeof(v), '\0');
        std::memcpy(b.data(), &v, sizeof(v));
        if constexpr (std::endian::native == std::endian::little)
            std::reverse(b.begin(), b.end());
        return b;
    };
    std::string bin = "# vtk DataFile Version 5.1\nvtk output\nBINARY\nDATASET UNSTRUCTURED_GRID\nPOINTS 5 double\n";
    for (double v : {0., 0., 0., 1., 0., 0., 0., 1., 0., 0., 0., 1., 1., 1., 1.})
        bin += be(v);
    bin += "\nCELLS 3 8\nOFFSETS vtktypeint64\n";
    for (std::int64_t v : {0, 4, 8})
        bin += be(v);
    bin += "\nCONNECTIVITY vtktypeint64\n";
    for (std::int64_t v : {0, 1, 2, 3, 1, 2, 3, 4})
        bin += be(v);
    bin += "\nCELL_TYPES 2\n" + be(std::int32_t(10)) + be(std::int32_t(10)) + "\nPOINT_DATA 5\nSCALARS t float 1\nLOOKUP_TABLE default\n";
    for (float v : {1.f, 2.f, 3.f, 4.f, 5.f})
        bin += be(v);
    bin += "\n";
    writeFile(dir / "b5.vtk", bin);
    TetMesh b = clvr::loadMesh({{"file", "b5.vtk"}, {"scalar", "t"}}, dir.path());
    EXPECT_EQ(b.tetsRead, 2u);
    EXPECT_EQ(b.scalars, (std::vector<double>{1, 2, 3, 4, 5}));
    EXPECT_EQ(b.points, m.points);
}

TEST(MeshIo, SceneObjectKeys)
{
    TempDir dir;
    clvr::writeTetgen(sampleMesh(), dir / "s");
    expectError([&] { clvr::loadMesh({{"file", "s.ele"}, {"scalr", "x"}}, dir.path()); }, "mesh.scalr");
    expectError([&] { clvr::loadMesh({{"files", "s.ele"}}, dir.path()); }, "mesh.files");
    expectError([&] { clvr::loadMesh({{"file", 3}}, dir.path()); }, "mesh.file");
    expectError([&] { clvr::loadMesh({{"file", "s.ply"}}, dir.path()); }, "unknown mesh format");
    expectError([&] { clvr::loadMesh({{"file", "missing.vtk"}}, dir.path()); }, "no such file", "missing.vtk");
    expectError([&] { clvr::loadMesh({{"file", "x.bin"}}, dir.path()); }, "q_file");
    expectError(
        [&] {
            clvr::loadMesh({{"file", "bluntfinxyz.bin"}, {"q_file", "bluntfinq.bin"}, {"scalar", "mach"}},
                           clvr::test::sharedData("bluntfin"));
        },
        "\"mach\" is not one of density, momentum, energy, pressure");
}

// ---------------------------------------------------------------------------------------------------
// Malformed files.

TEST(MeshIo, MalformedTetgen)
{
    TempDir dir;
    clvr::writeTetgen(sampleMesh(), dir / "s");
    const std::string node = readFile(dir / "s.node"), ele = readFile(dir / "s.ele");
    writeFile(dir / "t.node", node.substr(0, node.size() / 2));
    writeFile(dir / "t.ele", ele);
    expectError([&] { clvr::readTetgen(dir / "t.ele"); }, "points (truncated or a wrong count)", "t.node");
    writeFile(dir / "t.node", node);
    writeFile(dir / "t.ele", "4 4 0\n0 0 1 2 3\n1 1 2 3 4\n2 0 1 3 5\n");
    expectError([&] { clvr::readTetgen(dir / "t.ele"); }, "ends after 3 of 4 tetrahedra", "t.ele");
    writeFile(dir / "t.ele", "1 4 0\n0 0 1 2 6\n");
    expectError([&] { clvr::readTetgen(dir / "t.ele"); }, "tetrahedron 0 has point index 6, out of range", "t.ele line 2");
    writeFile(dir / "t.ele", "99999999 4 0\n0 0 1 2 3\n");
    expectError([&] { clvr::readTetgen(dir / "t.ele"); }, "more than the file can hold", "t.ele");
    writeFile(dir / "t.ele", "1 4 0\n0 0 1 2 x\n");
    expectError([&] { clvr::readTetgen(dir / "t.ele"); }, "\"x\" is not an integer", "t.ele line 2");
    writeFile(dir / "t.node", "1 3 1 0\n0 nan 0 0 1\n");
    writeFile(dir / "t.ele", "1 4 0\n0 0 0 0 0\n");
    expectError([&] { clvr::loadMesh({{"file", "t.ele"}}, dir.path()); }, "tetrahedron 0 has point 0 with a non-finite coordinate");
    writeFile(dir / "t.node", "4 3 1 0\n0 0 0 0 1\n1 1 0 0 nan\n2 0 1 0 1\n3 0 0 1 1\n");
    writeFile(dir / "t.ele", "1 4 0\n0 0 1 2 3\n");
    expectError([&] { clvr::loadMesh({{"file", "t.ele"}}, dir.path()); }, "tetrahedron 0 has point 1 with a non-finite scalar");
    writeFile(dir / "t.node", "4 3 1 0\n0 0 0 0 1\n1 1 0 0 1\n2 0 1 0 1\n3 1 1 0 1\n");  // all in z = 0
    writeFile(dir / "t.ele", "1 4 0\n0 0 1 2 3\n");
    expectError([&] { clvr::loadMesh({{"file", "t.ele"}}, dir.path()); }, "no tetrahedra left (1 read, 1 of zero volume)",
                "t.ele");
    writeFile(dir / "t.node", "4 3 0 0\n0 0 0 0\n1 1 0 0\n2 0 1 0\n3 0 0 1\n");
    expectError([&] { clvr::readTetgen(dir / "t.ele"); }, "no node attributes", "t.node");
}

// The smallest long long as a point or neighbor number of a 1-based file was subtracted from before it
// was compared (signed overflow, found by fuzz_tetgen; fuzz/regressions/tetgen): now out of range.
TEST(MeshIo, TetgenSmallestNumberIsOutOfRange)
{
    TempDir dir;
    writeFile(dir / "a.node", "5 3 1 0\n1 0 0 0 0\n2 1 0 0 1\n3 0 1 0 2\n4 0 0 1 3\n5 1 1 1 4\n");
    writeFile(dir / "a.ele", "2 4 0\n1 1 2 3 -9223372036854775808\n2 2 3 5 4\n");
    expectError([&] { clvr::readTetgen(dir / "a.ele"); },
                "tetrahedron 0 has point index -9223372036854775808, out of range (points are numbered 1 to 5)",
                "a.ele line 2");
    writeFile(dir / "a.ele", "2 4 0\n1 1 2 3 4\n2 2 3 5 4\n");
    writeFile(dir / "a.neigh", "2 4\n1 -9223372036854775808 -1 -1 -1\n2 -1 -1 1 -1\n");
    expectError([&] { clvr::readTetgen(dir / "a.ele"); }, "neighbor -9223372036854775808 out of range", "a.neigh line 2");
}

TEST(MeshIo, MalformedVtk)
{
    TempDir dir;
    const TetMesh m = sampleMesh();
    clvr::writeVtkUnstructured(m, dir / "a.vtk", false);
    clvr::writeVtkUnstructured(m, dir / "b.vtk", true);
    const std::string ascii = readFile(dir / "a.vtk"), binary = readFile(dir / "b.vtk");

    // Truncated binary: inside the points, inside the cells.
    for (std::size_t cut : {std::size_t(120), binary.find("CELL_TYPES") - 10, binary.size() - 20}) {
        writeFile(dir / "t.vtk", binary.substr(0, cut));
        expectError([&] { clvr::readVtkUnstructured(dir / "t.vtk"); }, "", "t.vtk");
        EXPECT_NE(messageOf([&] { clvr::readVtkUnstructured(dir / "t.vtk"); }), "(no InputError)") << cut;
    }
    // Truncated ASCII.
    writeFile(dir / "t.vtk", ascii.substr(0, ascii.find("CELLS") + 20));
    expectError([&] { clvr::readVtkUnstructured(dir / "t.vtk"); }, "truncated", "t.vtk");

    auto edited = [&](const std::string& from, const std::string& to) {
        std::string s = ascii;
        const std::size_t at = s.find(from);
        EXPECT_NE(at, std::string::npos) << from;
        s.replace(at, from.size(), to);
        writeFile(dir / "t.vtk", s);
    };
    edited("CELL_TYPES 3\n10\n", "CELL_TYPES 3\n5\n");
    expectError([&] { clvr::readVtkUnstructured(dir / "t.vtk"); }, "cell 0 has type 5, only tetra (10), hexahedron (12) and wedge (13)",
                "t.vtk");
    edited("CELLS 3 15", "CELLS 3 16");
    expectError([&] { clvr::readVtkUnstructured(dir / "t.vtk"); }, "", "t.vtk");
    edited("CELL_TYPES 3\n", "CELL_TYPES 2\n");
    expectError([&] { clvr::readVtkUnstructured(dir / "t.vtk"); }, "", "t.vtk");
    edited("POINTS 6 double", "POINTS 7 double");
    expectError([&] { clvr::readVtkUnstructured(dir / "t.vtk"); }, "", "t.vtk");
    edited("4 1 2 3 4", "4 1 2 3 9");
    expectError([&] { clvr::readVtkUnstructured(dir / "t.vtk"); }, "cell 1 has point index 9, out of range", "t.vtk");
    edited("DATASET UNSTRUCTURED_GRID", "DATASET STRUCTURED_POINTS");
    expectError([&] { clvr::readVtkUnstructured(dir / "t.vtk"); }, "not an unstructured grid", "t.vtk");
    edited("ASCII", "TEXT");
    expectError([&] { clvr::readVtkUnstructured(dir / "t.vtk"); }, "ASCII or BINARY", "t.vtk");
    edited("POINT_DATA", "POINT_DATUM");
    expectError([&] { clvr::readVtkUnstructured(dir / "t.vtk"); }, "unknown keyword \"POINT_DATUM\"", "t.vtk");
    edited("SCALARS scalars double 1\n", "VECTORS v double\n");
    expectError([&] { clvr::readVtkUnstructured(dir / "t.vtk"); }, "", "t.vtk");
    writeFile(dir / "t.vtk", "hello\n");
    expectError([&] { clvr::readVtkUnstructured(dir / "t.vtk"); }, "expected \"# vtk DataFile Version x.y\"", "t.vtk");
}

TEST(MeshIo, MalformedPlot3d)
{
    TempDir dir;
    const std::string xyz = readFile(clvr::test::sharedData("bluntfin/bluntfinxyz.bin"));
    const std::string q = readFile(clvr::test::sharedData("bluntfin/bluntfinq.bin"));
    writeFile(dir / "x.bin", xyz.substr(0, xyz.size() / 2));
    writeFile(dir / "q.bin", q);
    expectError([&] { clvr::readPlot3d(dir / "x.bin", dir / "q.bin"); }, "(truncated)", "x.bin");
    writeFile(dir / "x.bin", xyz);
    writeFile(dir / "q.bin", q.substr(0, 1000));
    expectError([&] { clvr::readPlot3d(dir / "x.bin", dir / "q.bin"); }, "(truncated)", "q.bin");
    std::string wrong = q;
    wrong[3] = 41;  // nx 40 -> 41
    writeFile(dir / "q.bin", wrong);
    expectError([&] { clvr::readPlot3d(dir / "x.bin", dir / "q.bin"); }, "differ from the grid's", "q.bin");
    std::string little = xyz;
    std::reverse(little.begin(), little.begin() + 4);  // a little-endian header: 40 << 24
    writeFile(dir / "x.bin", little);
    expectError([&] { clvr::readPlot3d(dir / "x.bin", dir / "q.bin"); }, "", "x.bin");
    writeFile(dir / "x.bin", "abc");
    expectError([&] { clvr::readPlot3d(dir / "x.bin", dir / "q.bin"); }, "too short", "x.bin");
}

// ---------------------------------------------------------------------------------------------------
// TetGen as a library (`clvr mesh`): closed surfaces written here, meshed, written and read back.

namespace {

// Volume enclosed by a closed, outward-oriented triangle surface (divergence theorem).
double enclosedVolume(const std::vector<glm::dvec3>& p, const std::vector<glm::uvec3>& tris)
{
    double v = 0;
    for (const auto& t : tris)
        v += glm::dot(p[t[0]], glm::cross(p[t[1]], p[t[2]])) / 6.0;
    return v;
}

void expectGoodMesh(const TetMesh& m, double volume, double tolerance)
{
    EXPECT_GT(m.tets.size(), 0u);
    EXPECT_EQ(m.tetsDegenerate, 0u);
    for (const auto& c : m.tets)
        ASSERT_GT(clvr::signedVolume6(m.points[c[0]], m.points[c[1]], m.points[c[2]], m.points[c[3]]), 0.0);
    EXPECT_NEAR(totalVolume(m), volume, tolerance);
    const clvr::TetTopology topo = clvr::buildTopology(m);
    EXPECT_GT(topo.boundary.size(), 0u);
}

}  // namespace

TEST(MeshIo, TetgenMesherTorusOffRoundTrip)
{
    TempDir dir;
    const int n = 24, m = 12;
    const double R = 0.6, r = 0.25;
    std::vector<glm::dvec3> pts;
    std::vector<glm::uvec3> tris;
    for (int i = 0; i < n; ++i)
        for (int j = 0; j < m; ++j) {
            const double a = 2 * std::numbers::pi * i / n, b = 2 * std::numbers::pi * j / m;
            pts.push_back({(R + r * std::cos(b)) * std::cos(a), (R + r * std::cos(b)) * std::sin(a), r * std::sin(b)});
        }
    auto id = [&](int i, int j) { return static_cast<unsigned>((i % n) * m + (j % m)); };
    for (int i = 0; i < n; ++i)
        for (int j = 0; j < m; ++j) {
            tris.push_back({id(i, j), id(i + 1, j), id(i + 1, j + 1)});
            tris.push_back({id(i, j), id(i + 1, j + 1), id(i, j + 1)});
        }
    std::ostringstream off;
    off.precision(17);
    off << "OFF\n" << pts.size() << ' ' << tris.size() << " 0\n";
    for (const auto& p : pts)
        off << p.x << ' ' << p.y << ' ' << p.z << '\n';
    for (const auto& t : tris)
        off << "3 " << t[0] << ' ' << t[1] << ' ' << t[2] << '\n';
    writeFile(dir / "torus.off", off.str());
    const double volume = std::abs(enclosedVolume(pts, tris));

    clvr::MesherOptions options;
    options.quality = 1.5;
    options.maxVolume = 0.002;
    options.scalar = "blobs";
    const TetMesh meshed = clvr::meshSurface(dir / "torus.off", options);
    expectGoodMesh(meshed, volume, 1e-9 * volume);
    clvr::writeTetgen(meshed, dir / "torus");
    const TetMesh back = clvr::loadMesh({{"file", "torus.ele"}}, dir.path());
    expectSame(meshed, back);
    expectGoodMesh(back, volume, 1e-9 * volume);
    std::printf("torus: %zu points, %zu tets, volume %.6f (surface encloses %.6f)\n", back.points.size(),
                back.tets.size(), totalVolume(back), volume);
}

TEST(MeshIo, TetgenMesherLBlockPoly)
{
    TempDir dir;
    // The L profile (0,0) (2,0) (2,1) (1,1) (1,2) (0,2) extruded over z in [0,1]: volume 3.
    writeFile(dir / "l.poly", "12 3 0 0\n"
                              "0 0 0 0\n1 2 0 0\n2 2 1 0\n3 1 1 0\n4 1 2 0\n5 0 2 0\n"
                              "6 0 0 1\n7 2 0 1\n8 2 1 1\n9 1 1 1\n10 1 2 1\n11 0 2 1\n"
                              "8 0\n"
                              "1\n6 0 1 2 3 4 5\n1\n6 6 7 8 9 10 11\n"
                              "1\n4 0 1 7 6\n1\n4 1 2 8 7\n1\n4 2 3 9 8\n1\n4 3 4 10 9\n1\n4 4 5 11 10\n1\n4 5 0 6 11\n"
                              "0\n0\n");
    clvr::MesherOptions options;
    options.maxVolume = 0.01;
    const TetMesh meshed = clvr::meshSurface(dir / "l.poly", options);
    expectGoodMesh(meshed, 3.0, 1e-12);
    EXPECT_GT(meshed.tets.size(), 300u);  // the volume bound is honored
    clvr::writeTetgen(meshed, dir / "l");
    expectGoodMesh(clvr::loadMesh({{"file", "l.node"}}, dir.path()), 3.0, 1e-12);

    expectError([&] { clvr::meshSurface(dir / "l.ply", options); }, "no such file", "l.ply");
    writeFile(dir / "bad.off", "OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n");  // one triangle: not closed
    expectError([&] { clvr::meshSurface(dir / "bad.off", options); }, "the surface is flat", "bad.off");
    options.scalar = "nosuch";
    expectError([&] { clvr::meshSurface(dir / "l.poly", options); }, "neither a generator");
}

// The two surface formats TetGen reads that the tests above do not use: an ASCII STL (triangles with
// repeated corners, which TetGen merges) and a .smesh (nodes, then quadrilateral facets, no holes or
// regions), both the unit cube: volume 1.
TEST(MeshIo, TetgenMesherStlAndSmeshCubes)
{
    TempDir dir;
    const glm::dvec3 corner[8] = {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}, {0, 0, 1}, {1, 0, 1}, {1, 1, 1}, {0, 1, 1}};
    const int quads[6][4] = {{0, 3, 2, 1}, {4, 5, 6, 7}, {0, 1, 5, 4}, {1, 2, 6, 5}, {2, 3, 7, 6}, {3, 0, 4, 7}};
    std::ostringstream stl, smesh;
    stl << "solid cube\n";
    for (const auto& q : quads)
        for (const std::array<int, 3> t : {std::array<int, 3>{q[0], q[1], q[2]}, std::array<int, 3>{q[0], q[2], q[3]}}) {
            const glm::dvec3 n = glm::normalize(glm::cross(corner[t[1]] - corner[t[0]], corner[t[2]] - corner[t[0]]));
            stl << "facet normal " << n.x << ' ' << n.y << ' ' << n.z << "\nouter loop\n";
            for (const int v : t)
                stl << "vertex " << corner[v].x << ' ' << corner[v].y << ' ' << corner[v].z << '\n';
            stl << "endloop\nendfacet\n";
        }
    stl << "endsolid cube\n";
    writeFile(dir / "cube.stl", stl.str());
    smesh << "8 3 0 0\n";
    for (int v = 0; v < 8; ++v)
        smesh << v << ' ' << corner[v].x << ' ' << corner[v].y << ' ' << corner[v].z << '\n';
    smesh << "6 0\n";
    for (const auto& q : quads)
        smesh << "4 " << q[0] << ' ' << q[1] << ' ' << q[2] << ' ' << q[3] << '\n';
    smesh << "0\n0\n";
    writeFile(dir / "cube.smesh", smesh.str());

    clvr::MesherOptions options;
    options.maxVolume = 0.01;
    for (const char* name : {"cube.stl", "cube.smesh"}) {
        SCOPED_TRACE(name);
        const TetMesh meshed = clvr::meshSurface(dir / name, options);
        expectGoodMesh(meshed, 1.0, 1e-12);
        EXPECT_GT(meshed.tets.size(), 100u);  // the volume bound is honored
        const glm::dvec3 lo = meshed.boundsMin(), hi = meshed.boundsMax();
        EXPECT_EQ(lo, glm::dvec3(0.0));
        EXPECT_EQ(hi, glm::dvec3(1.0));
    }
}

TEST(MeshIo, SceneSurfaceIsMeshedAtLoad)
{
    // data/surfaces/l-block.poly through the scene's {"surface": ...} form: TetGen at load time, the
    // volume bound honored, the scalar from a generator; a volume file as the scalar is resolved
    // against the scene's folder like every other path.
    const std::string dir = clvr::test::repoData("surfaces");
    const TetMesh coarse = clvr::loadMesh({{"surface", "l-block.poly"}, {"scalar", "sphere"}}, dir);
    const TetMesh fine = clvr::loadMesh({{"surface", "l-block.poly"}, {"max_volume", 0.01}, {"quality", 1.5}}, dir);
    expectGoodMesh(coarse, 3.0, 1e-12);
    expectGoodMesh(fine, 3.0, 1e-12);
    EXPECT_GT(fine.tets.size(), 300u);
    EXPECT_GT(fine.tets.size(), 10 * coarse.tets.size());
    for (std::size_t i = 0; i < coarse.points.size(); ++i)
        ASSERT_DOUBLE_EQ(coarse.scalars[i], clvr::sphereField(coarse.points[i]));

    expectError([&] { clvr::loadMesh({{"surface", "l-block.poly"}, {"file", "x.ele"}}, dir); }, "mesh.file");
    expectError([&] { clvr::loadMesh({{"surface", "l-block.poly"}, {"max_volume", -1}}, dir); }, "mesh.max_volume");
    expectError([&] { clvr::loadMesh({{"surface", "l-block.poly"}, {"quality", "high"}}, dir); }, "mesh.quality");
    expectError([&] { clvr::loadMesh({{"surface", 3}}, dir); }, "mesh.surface");
    expectError([&] { clvr::loadMesh({{"surface", "l-block.poly"}, {"scalar", "head.nrrd"}}, dir); }, "head.nrrd");
    expectError([&] { clvr::loadMesh({{"surface", "nosuch.off"}}, dir); }, "nosuch.off");
}

TEST(MeshIo, TetgenNeighIsUsedWhenPresentAndChecked)
{
    TempDir dir;
    // Written by writeTetgen (as `clvr mesh` does) and read back: the same adjacency as face matching.
    {
        clvr::MesherOptions options;
        options.maxVolume = 0.05;
        const TetMesh meshed = clvr::meshSurface(clvr::test::repoData("surfaces/l-block.poly"), options);
        clvr::writeTetgen(meshed, dir / "l");
        const TetMesh back = clvr::loadMesh({{"file", "l.ele"}}, dir.path());
        ASSERT_EQ(back.neighbors.size(), back.tets.size());
        TetMesh matched = back;
        matched.neighbors.clear();
        const clvr::TetTopology a = clvr::buildTopology(back), b = clvr::buildTopology(matched);
        EXPECT_EQ(a.neighbor, b.neighbor);
        ASSERT_EQ(a.boundary.size(), b.boundary.size());
        for (std::size_t i = 0; i < a.boundary.size(); ++i)
            EXPECT_TRUE(a.boundary[i].tet == b.boundary[i].tet && a.boundary[i].face == b.boundary[i].face) << i;
    }
    // 1-based, the second tetrahedron inverted (points 4 and 5 swapped): checkMesh reorients it and
    // swaps its neighbors 2 and 3 with it.
    writeFile(dir / "a.node", "5 3 1 0\n1 0 0 0 0\n2 1 0 0 1\n3 0 1 0 2\n4 0 0 1 3\n5 1 1 1 4\n");
    writeFile(dir / "a.ele", "2 4 0\n1 1 2 3 4\n2 2 3 5 4\n");
    writeFile(dir / "a.neigh", "2 4\n1 2 -1 -1 -1\n2 -1 -1 1 -1\n");
    TetMesh m = clvr::loadMesh({{"file", "a.ele"}}, dir.path());
    EXPECT_EQ(m.tetsReoriented, 1u);
    ASSERT_EQ(m.neighbors.size(), 2u);
    EXPECT_EQ(m.neighbors[1], (std::array<std::int32_t, 4>{-1, -1, -1, 0}));
    const clvr::TetTopology topo = clvr::buildTopology(m);
    EXPECT_EQ(topo.neighbor[0], (std::array<std::int32_t, 4>{1, -1, -1, -1}));
    EXPECT_EQ(topo.boundary.size(), 6u);

    // What a wrong .neigh gets: one line naming the file (reading) or the cell (checking).
    auto topologyOf = [&](const std::string& neigh) {
        writeFile(dir / "a.neigh", neigh);
        clvr::buildTopology(clvr::loadMesh({{"file", "a.ele"}}, dir.path()));
    };
    expectError([&] { topologyOf("3 4\n1 2 -1 -1 -1\n2 -1 -1 1 -1\n"); }, "3 tetrahedra", "a.neigh");
    expectError([&] { topologyOf("2 4\n1 2 -1 -1 -1\n"); }, "ends after 1 of 2", "a.neigh");
    expectError([&] { topologyOf("2 4\n1 3 -1 -1 -1\n2 -1 -1 1 -1\n"); }, "neighbor 3 out of range", "a.neigh");
    expectError([&] { topologyOf("2 4\n1 2 -1 -1 -1\n2 -1 -1 -1 -1\n"); }, "not symmetric", "tetrahedron 0, face 0");
    expectError([&] { topologyOf("2 4\n1 -1 2 -1 -1\n2 -1 -1 1 -1\n"); }, "do not share that face", "tetrahedron 0, face 1");
}
