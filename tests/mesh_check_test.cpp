// tests/mesh_check_test.cpp — checkMesh and buildTopology on hand-made meshes: two tetrahedra sharing a
// face, a cube split into 6, inverted and degenerate cells, a non-manifold face, bad indices and NaN, an
// O-grid-like ring whose seam has duplicated points, and the time for a mesh of over a million tetrahedra.
#include "host/runtime/errors.h"
#include "host/model/mesh.h"

#include <gtest/gtest.h>

#include <chrono>
#include <cstdio>
#include <functional>
#include <cmath>
#include <limits>
#include <map>
#include <numbers>

using clvr::InputError;
using clvr::TetMesh;

namespace {

TetMesh twoTets()
{
    TetMesh m;
    m.source = "two";
    m.points = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1}, {1, 1, 1}};
    m.scalars = {0, 1, 2, 3, 4};
    m.tets = {{0, 1, 2, 3}, {1, 2, 3, 4}};
    return m;
}

// The unit cube's 8 corners in VTK hexahedron order, split into 6 tetrahedra around the diagonal 0-6.
TetMesh cube6()
{
    TetMesh m;
    m.source = "cube";
    m.points = {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}, {0, 0, 1}, {1, 0, 1}, {1, 1, 1}, {0, 1, 1}};
    m.scalars.assign(8, 0.5);
    m.tets = {{0, 1, 2, 6}, {0, 2, 3, 6}, {0, 3, 7, 6}, {0, 7, 4, 6}, {0, 4, 5, 6}, {0, 5, 1, 6}};
    return m;
}

double volume(const TetMesh& m, std::size_t t)
{
    const auto c = m.tets[t];
    return clvr::signedVolume6(m.points[c[0]], m.points[c[1]], m.points[c[2]], m.points[c[3]]) / 6.0;
}

std::string messageOf(const std::function<void()>& f)
{
    try {
        f();
    } catch (const InputError& e) {
        return e.what();
    }
    return "(no InputError)";
}

}  // namespace

TEST(MeshCheck, TwoTetsShareOneFace)
{
    TetMesh m = twoTets();
    clvr::checkMesh(m);
    ASSERT_EQ(m.tets.size(), 2u);
    const clvr::TetTopology topo = clvr::buildTopology(m);
    EXPECT_EQ(topo.boundary.size(), 6u);
    // Tet 0's face opposite vertex 0 (points 1 2 3) is shared; so is tet 1's face opposite its point 4.
    int shared0 = 0, shared1 = 0;
    for (int f = 0; f < 4; ++f) {
        if (topo.neighbor[0][f] == 1) {
            ++shared0;
            EXPECT_EQ(m.tets[0][f], 0u);
        }
        if (topo.neighbor[1][f] == 0) {
            ++shared1;
            EXPECT_EQ(m.tets[1][f], 4u);
        }
    }
    EXPECT_EQ(shared0, 1);
    EXPECT_EQ(shared1, 1);
    for (std::size_t t = 0; t < m.tets.size(); ++t)
        EXPECT_GT(volume(m, t), 0.0);
}

TEST(MeshCheck, CubeSplitIntoSixHasTheCubesVolume)
{
    TetMesh m = cube6();
    clvr::checkMesh(m);
    ASSERT_EQ(m.tets.size(), 6u);
    double total = 0;
    for (std::size_t t = 0; t < m.tets.size(); ++t) {
        EXPECT_GT(volume(m, t), 0.0);
        total += volume(m, t);
    }
    EXPECT_NEAR(total, 1.0, 1e-14);
    const clvr::TetTopology topo = clvr::buildTopology(m);
    EXPECT_EQ(topo.boundary.size(), 12u);  // 6 square faces, 2 triangles each
    int interior = 0;
    for (std::size_t t = 0; t < 6; ++t)
        for (int f = 0; f < 4; ++f)
            if (const int n = topo.neighbor[t][f]; n >= 0) {
                ++interior;
                int back = 0;
                for (int g = 0; g < 4; ++g)
                    back += topo.neighbor[n][g] == static_cast<int>(t);
                EXPECT_EQ(back, 1) << "tet " << t << " face " << f;
            }
    EXPECT_EQ(interior, 12);  // 6 interior faces, seen from both sides
}

TEST(MeshCheck, InvertedTetIsReoriented)
{
    TetMesh m = twoTets();
    std::swap(m.tets[0][0], m.tets[0][1]);
    ASSERT_LT(volume(m, 0), 0.0);
    clvr::checkMesh(m);
    EXPECT_EQ(m.tetsReoriented, 1u);
    EXPECT_GT(volume(m, 0), 0.0);
    EXPECT_GT(volume(m, 1), 0.0);
}

TEST(MeshCheck, DegenerateTetsAreDroppedAndCounted)
{
    TetMesh m = twoTets();
    m.points.push_back({0.5, 0.5, 0});  // in the plane z = 0 with points 0 1 2
    m.scalars.push_back(9);
    m.tets.push_back({0, 1, 2, 5});          // flat
    m.tets.push_back({0, 1, 1, 2});          // repeated point
    m.points.push_back({1e-9, 1e-9, 1e-9});  // far from zero volume relative to scale 1? 6V ~ 1e-9 > 1e-12
    m.scalars.push_back(0);
    m.tets.push_back({0, 1, 2, 6});
    clvr::checkMesh(m);
    EXPECT_EQ(m.tetsRead, 5u);
    EXPECT_EQ(m.tetsDegenerate, 2u);
    EXPECT_EQ(m.tets.size(), 3u);
}

TEST(MeshCheck, FaceSharedByThreeNamesTheCell)
{
    TetMesh m = twoTets();
    m.points.push_back({0.2, 0.2, 0.2});  // a third tet on the face 1 2 3, overlapping tet 0
    m.scalars.push_back(0);
    m.tets.push_back({1, 2, 3, 5});
    clvr::checkMesh(m);
    const std::string msg = messageOf([&] { clvr::buildTopology(m); });
    EXPECT_NE(msg.find("two: tetrahedron 0"), std::string::npos) << msg;
    EXPECT_NE(msg.find("three or more"), std::string::npos) << msg;
    EXPECT_EQ(msg.find('\n'), std::string::npos);
}

TEST(MeshCheck, BadIndexAndNonFiniteValuesNameTheCell)
{
    {
        TetMesh m = twoTets();
        m.tets[1][2] = 7;
        const std::string msg = messageOf([&] { clvr::checkMesh(m); });
        EXPECT_NE(msg.find("tetrahedron 1 has point index 7, out of range"), std::string::npos) << msg;
    }
    {
        TetMesh m = twoTets();
        m.points[4].y = std::numeric_limits<double>::quiet_NaN();
        const std::string msg = messageOf([&] { clvr::checkMesh(m); });
        EXPECT_NE(msg.find("tetrahedron 1 has point 4 with a non-finite coordinate"), std::string::npos) << msg;
    }
    {
        TetMesh m = twoTets();
        m.scalars[2] = std::numeric_limits<double>::quiet_NaN();
        const std::string msg = messageOf([&] { clvr::checkMesh(m); });
        EXPECT_NE(msg.find("tetrahedron 0 has point 2 with a non-finite scalar"), std::string::npos) << msg;
    }
    {
        TetMesh m = twoTets();
        m.scalars.pop_back();
        const std::string msg = messageOf([&] { clvr::checkMesh(m); });
        EXPECT_NE(msg.find("4 scalars for 5 points"), std::string::npos) << msg;
    }
}

// A ring (annulus extruded in z) as a structured grid whose angular index wraps with duplicated points
// at the seam, like an O-grid, split 6 tets per cell: buildTopology welds the seam.
TEST(MeshCheck, OGridSeamIsConnected)
{
    const int ni = 3, nj = 17, nk = 2;  // radial, angular (j = 0 and j = nj-1 coincide), axial
    TetMesh m;
    m.source = "ring";
    auto id = [&](int i, int j, int k) { return static_cast<std::uint32_t>(i + ni * (j + nj * k)); };
    for (int k = 0; k < nk; ++k)
        for (int j = 0; j < nj; ++j)
            for (int i = 0; i < ni; ++i) {
                const double a = 2 * std::numbers::pi * (j % (nj - 1)) / (nj - 1), r = 1.0 + 0.5 * i;
                m.points.push_back({r * std::cos(a), r * std::sin(a), 0.5 * k});
                m.scalars.push_back(r);
            }
    static const int split[6][4] = {{0, 1, 2, 6}, {0, 2, 3, 6}, {0, 3, 7, 6}, {0, 7, 4, 6}, {0, 4, 5, 6}, {0, 5, 1, 6}};
    for (int k = 0; k + 1 < nk; ++k)
        for (int j = 0; j + 1 < nj; ++j)
            for (int i = 0; i + 1 < ni; ++i) {
                const std::uint32_t v[8] = {id(i, j, k),         id(i + 1, j, k),         id(i + 1, j + 1, k),
                                            id(i, j + 1, k),     id(i, j, k + 1),         id(i + 1, j, k + 1),
                                            id(i + 1, j + 1, k + 1), id(i, j + 1, k + 1)};
                for (const auto& s : split)
                    m.tets.push_back({v[s[0]], v[s[1]], v[s[2]], v[s[3]]});
            }
    clvr::checkMesh(m);
    ASSERT_EQ(m.tetsDegenerate, 0u);
    const clvr::TetTopology topo = clvr::buildTopology(m);
    // Boundary: inner and outer cylinders (nj-1 quads each) and two annular caps ((ni-1)(nj-1) quads
    // each), 2 triangles per quad; no faces at the seam.
    const std::size_t quads = 2 * (nj - 1) * (nk - 1) + 2 * (ni - 1) * (nj - 1);
    EXPECT_EQ(topo.boundary.size(), 2 * quads);
    for (const auto& b : topo.boundary) {
        const auto c = m.tets[b.tet];
        bool allAtSeam = true;  // a seam face has all three points at angle 0 (y == 0, x > 0)
        for (int k = 0; k < 4; ++k)
            if (k != static_cast<int>(b.face))
                allAtSeam = allAtSeam && std::abs(m.points[c[k]].y) < 1e-12 && m.points[c[k]].x > 0;
        EXPECT_FALSE(allAtSeam) << "boundary face at the seam: tet " << b.tet << " face " << b.face;
    }
}

// A structured block of 6-tet cells: over a million tetrahedra checked and connected in seconds.
TEST(MeshCheck, MillionTetsIsFast)
{
    const int n = 56;  // 55^3 * 6 = 998,250 tets; 56^3 points
    TetMesh m;
    m.source = "block";
    auto id = [&](int i, int j, int k) { return static_cast<std::uint32_t>(i + n * (j + n * k)); };
    for (int k = 0; k < n; ++k)
        for (int j = 0; j < n; ++j)
            for (int i = 0; i < n; ++i) {
                m.points.push_back({double(i), double(j), double(k)});
                m.scalars.push_back(i + j + k);
            }
    static const int split[6][4] = {{0, 1, 2, 6}, {0, 2, 3, 6}, {0, 3, 7, 6}, {0, 7, 4, 6}, {0, 4, 5, 6}, {0, 5, 1, 6}};
    for (int k = 0; k + 1 < n; ++k)
        for (int j = 0; j + 1 < n; ++j)
            for (int i = 0; i + 1 < n; ++i) {
                const std::uint32_t v[8] = {id(i, j, k),     id(i + 1, j, k),     id(i + 1, j + 1, k),     id(i, j + 1, k),
                                            id(i, j, k + 1), id(i + 1, j, k + 1), id(i + 1, j + 1, k + 1), id(i, j + 1, k + 1)};
                for (const auto& s : split)
                    m.tets.push_back({v[s[0]], v[s[1]], v[s[2]], v[s[3]]});
            }
    const auto t0 = std::chrono::steady_clock::now();
    clvr::checkMesh(m);
    const clvr::TetTopology topo = clvr::buildTopology(m);
    const double s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    EXPECT_EQ(m.tets.size(), 998250u);
    EXPECT_EQ(topo.boundary.size(), 6u * 55 * 55 * 2);
    EXPECT_LT(s, 20.0);
    std::printf("check + topology of %zu tets: %.2f s\n", m.tets.size(), s);
}
