// tests/cubefan_test.cpp — seeds/002's tables and classification (host/render/grid/cube_fans.h),
// checked against brute-force constructions from the cube's own geometry.
#include "host/render/grid/cube_fans.h"

#include <gtest/gtest.h>

#include <set>

namespace clvr::cubefan {
namespace {

// The face (0..5) whose four vertices are `v` (a set of cube vertex numbers), or -1.
int faceOf(const std::set<int>& v)
{
    for (int f = 0; f < 6; ++f) {
        std::set<int> face;
        for (int i = 0; i < 8; ++i)
            if (((i >> (f / 2)) & 1) == (f % 2))
                face.insert(i);
        if (face == v)
            return f;
    }
    return -1;
}

// Where the vertex map `m` sends face f (-1 unless it is a face).
int mapFace(const int* m, int f)
{
    std::set<int> image;
    for (int i = 0; i < 8; ++i)
        if (((i >> (f / 2)) & 1) == (f % 2))
            image.insert(m[i]);
    return faceOf(image);
}

// True when m is one of the 48 symmetries of the cube: a permutation that maps edges to edges.
bool isCubeSymmetry(const int* m)
{
    std::set<int> seen(m, m + 8);
    if (seen.size() != 8 || *seen.begin() != 0 || *seen.rbegin() != 7)
        return false;
    for (int a = 0; a < 8; ++a)
        for (int b = 0; b < 8; ++b)
            if (__builtin_popcount(a ^ b) == 1 && __builtin_popcount(m[a] ^ m[b]) != 1)
                return false;
    return true;
}

TEST(CubefanTables, Class1RowsAreSymmetriesTakingFace5ToF0)
{
    for (int f0 = 0; f0 < 6; ++f0) {
        EXPECT_TRUE(isCubeSymmetry(kClass1Remap[f0])) << "row " << f0;
        EXPECT_EQ(mapFace(kClass1Remap[f0], 5), f0) << "row " << f0;
    }
}

TEST(CubefanTables, Class2RowsAreSymmetriesTakingFaces5And0ToF0F1)
{
    int rows = 0;
    for (int f0 = 0; f0 < 6; ++f0)
        for (int f1 = 0; f1 < 6; ++f1) {
            const bool used = f1 / 2 != f0 / 2;
            if (!used) {
                EXPECT_EQ(kClass2Remap[f0][f1][0], -1);
                continue;
            }
            ++rows;
            EXPECT_TRUE(isCubeSymmetry(kClass2Remap[f0][f1])) << f0 << f1;
            EXPECT_EQ(mapFace(kClass2Remap[f0][f1], 5), f0) << f0 << f1;
            EXPECT_EQ(mapFace(kClass2Remap[f0][f1], 0), f1) << f0 << f1;
        }
    EXPECT_EQ(rows, 24);
}

// 3a is the chirality of the standard 3a view (d5 > d0 > d3): (f0, f1, f2) is 3a exactly when the row
// (f0, f1) takes standard face 3 to f2; otherwise the swapped row (f1, f0) does (class 3b).
TEST(CubefanTables, Class3aListIsTheChiralityOfTheRows)
{
    int a = 0, b = 0;
    for (int f0 = 0; f0 < 6; ++f0)
        for (int f1 = 0; f1 < 6; ++f1)
            for (int f2 = 0; f2 < 6; ++f2) {
                if (f0 / 2 == f1 / 2 || f0 / 2 == f2 / 2 || f1 / 2 == f2 / 2)
                    continue;
                const bool byRow = mapFace(kClass2Remap[f0][f1], 3) == f2;
                EXPECT_EQ(isClass3a(f0, f1, f2), byRow) << f0 << f1 << f2;
                if (!byRow) {
                    EXPECT_EQ(mapFace(kClass2Remap[f1][f0], 3), f2) << f0 << f1 << f2;
                }
                (byRow ? a : b)++;
            }
    EXPECT_EQ(a, 24);
    EXPECT_EQ(b, 24);
}

// Eye positions (unit cube) that give each of Fig. 3's ten cases, exactly (the degenerate ones on
// face planes or at equal distances).
TEST(CubefanClassify, TenCasesOfFigure3)
{
    const struct { glm::dvec3 eye; const char* label; int cls; } cases[] = {
        {{0.3, 0.6, 3.0}, "10", 1},   {{0.3, 1.0, 3.0}, "11", 1},   {{1.0, 1.0, 3.0}, "12", 1},
        {{-0.4, 0.6, 2.5}, "20a", 2}, {{-0.5, 0.6, 1.5}, "20b", 2}, {{-0.4, 1.0, 2.5}, "21a", 2},
        {{-0.5, 1.0, 1.5}, "21b", 2}, {{-0.6, 1.3, 2.0}, "30a", 3}, {{-0.75, 1.3, 1.75}, "30b", 3},
        {{-0.5, 1.5, 1.5}, "30c", 3},
    };
    for (const auto& c : cases) {
        const Classification k = classify(c.eye);
        EXPECT_EQ(k.caseLabel, c.label) << c.eye.x << " " << c.eye.y << " " << c.eye.z;
        EXPECT_EQ(k.cls, c.cls) << c.label;
    }
    EXPECT_EQ(classify({0.5, 0.5, 0.5}).cls, 0);  // eye inside: no face towards it
    // Standard 3a view: d5 > d0 > d3, listed as 3a; the mirrored view d0 > d5 > d3 is 3b.
    const Classification a = classify({-0.6, 1.3, 2.0});
    EXPECT_TRUE(isClass3a(a.f[0], a.f[1], a.f[2]));
    const Classification b = classify({-1.0, 1.3, 1.6});
    EXPECT_FALSE(isClass3a(b.f[0], b.f[1], b.f[2]));
}

}  // namespace
}  // namespace clvr::cubefan
