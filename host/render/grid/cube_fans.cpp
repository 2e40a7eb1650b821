// host/render/grid/cube_fans.cpp — the tables of seeds/002 §5 and the classification of §3.
#include "host/render/grid/cube_fans.h"

#include <algorithm>
#include <cmath>

namespace clvr::cubefan {

const int kClass1Remap[6][8] = {
    {1, 5, 3, 7, 0, 4, 2, 6}, {4, 0, 6, 2, 5, 1, 7, 3}, {2, 3, 6, 7, 0, 1, 4, 5},
    {4, 5, 0, 1, 6, 7, 2, 3}, {6, 7, 4, 5, 2, 3, 0, 1}, {0, 1, 2, 3, 4, 5, 6, 7},
};

// Fig. 8 as printed, with three OCR slips of the seed's text corrected: row (1,2) "0 2 4 6 1 3 5 7",
// row (4,0) "6 7 4 5 2 3 0 1", and rows (2,5) / (3,0) split apart (tests/cubefan_test.cpp checks every
// row is a symmetry of the cube taking standard faces 5, 0 to f0, f1).
#define U {-1, -1, -1, -1, -1, -1, -1, -1}
const int kClass2Remap[6][6][8] = {
    {U, U, {5, 7, 1, 3, 4, 6, 0, 2}, {3, 1, 7, 5, 2, 0, 6, 4}, {1, 5, 3, 7, 0, 4, 2, 6}, {7, 3, 5, 1, 6, 2, 4, 0}},
    {U, U, {0, 2, 4, 6, 1, 3, 5, 7}, {6, 4, 2, 0, 7, 5, 3, 1}, {2, 6, 0, 4, 3, 7, 1, 5}, {4, 0, 6, 2, 5, 1, 7, 3}},
    {{2, 3, 6, 7, 0, 1, 4, 5}, {7, 6, 3, 2, 5, 4, 1, 0}, U, U, {3, 7, 2, 6, 1, 5, 0, 4}, {6, 2, 7, 3, 4, 0, 5, 1}},
    {{4, 5, 0, 1, 6, 7, 2, 3}, {1, 0, 5, 4, 3, 2, 7, 6}, U, U, {0, 4, 1, 5, 2, 6, 3, 7}, {5, 1, 4, 0, 7, 3, 6, 2}},
    {{6, 7, 4, 5, 2, 3, 0, 1}, {5, 4, 7, 6, 1, 0, 3, 2}, {4, 6, 5, 7, 0, 2, 1, 3}, {7, 5, 6, 4, 3, 1, 2, 0}, U, U},
    {{0, 1, 2, 3, 4, 5, 6, 7}, {3, 2, 1, 0, 7, 6, 5, 4}, {1, 3, 0, 2, 5, 7, 4, 6}, {2, 0, 3, 1, 6, 4, 7, 5}, U, U},
};
#undef U

const std::array<std::array<int, 3>, 24> kClass3aTriples = {{
    {0, 2, 4}, {0, 5, 2}, {0, 4, 3}, {0, 3, 5}, {1, 4, 2}, {1, 5, 3}, {1, 3, 4}, {1, 2, 5},
    {2, 4, 0}, {2, 1, 4}, {2, 0, 5}, {2, 5, 1}, {3, 5, 0}, {3, 1, 5}, {3, 4, 1}, {3, 0, 4},
    {4, 1, 3}, {4, 3, 0}, {4, 2, 1}, {4, 0, 2}, {5, 0, 3}, {5, 1, 2}, {5, 2, 0}, {5, 3, 1},
}};

bool isClass3a(int f0, int f1, int f2)
{
    for (const auto& t : kClass3aTriples)
        if (t[0] == f0 && t[1] == f1 && t[2] == f2)
            return true;
    return false;
}

Classification classify(const glm::dvec3& e)
{
    // d = n_f . (eye - c_f) / |eye - c_f|: the unit normal with the unit viewing vector (§3).
    std::array<std::pair<double, int>, 6> pairs;
    for (int f = 0; f < 6; ++f) {
        const int axis = f / 2;
        const double sign = (f % 2) ? 1.0 : -1.0;
        glm::dvec3 c(0.5);
        c[axis] = (f % 2) ? 1.0 : 0.0;
        const glm::dvec3 v = e - c;
        const double len = glm::length(v);
        const double dist = sign * v[axis];
        pairs[f] = {len > 0.0 ? dist / len : 0.0, f};
    }
    std::stable_sort(pairs.begin(), pairs.end(), [](const auto& a, const auto& b) { return a.first > b.first; });
    Classification c;
    for (int i = 0; i < 3; ++i) {
        c.d[i] = pairs[i].first;
        c.f[i] = pairs[i].second;
        c.cls += c.d[i] > 0.0 ? 1 : 0;
    }
    const double d0 = c.d[0], d1 = c.d[1], d2 = c.d[2];
    switch (c.cls) {
    case 1: c.caseLabel = d1 < 0.0 ? "10" : (d2 < 0.0 ? "11" : "12"); break;
    case 2: c.caseLabel = std::string(d2 < 0.0 ? "20" : "21") + (d0 == d1 ? "b" : "a"); break;
    case 3: c.caseLabel = d0 > d1 ? "30a" : (d1 > d2 ? "30b" : "30c"); break;
    default: break;
    }
    return c;
}

}  // namespace clvr::cubefan
