// host/io/cell_split.cpp — the hexahedron and wedge splits (host/io/cell_split.h).
#include "host/io/cell_split.h"

#include <algorithm>

namespace clvr {

namespace {
constexpr int kHexSplit[6][4] = {{0, 1, 2, 6}, {0, 2, 3, 6}, {0, 3, 7, 6}, {0, 7, 4, 6}, {0, 4, 5, 6}, {0, 5, 1, 6}};

}  // namespace

void splitHex(const std::array<std::uint32_t, 8>& v, std::vector<glm::uvec4>& tets)
{
    for (const auto& t : kHexSplit)
        tets.emplace_back(v[t[0]], v[t[1]], v[t[2]], v[t[3]]);
}

void splitWedge(const std::array<std::uint32_t, 6>& w, std::vector<glm::uvec4>& tets)
{
    static constexpr int kRot[6][6] = {{0, 1, 2, 3, 4, 5}, {1, 2, 0, 4, 5, 3}, {2, 0, 1, 5, 3, 4},
                                       {3, 5, 4, 0, 2, 1}, {4, 3, 5, 1, 0, 2}, {5, 4, 3, 2, 1, 0}};
    const int m = static_cast<int>(std::min_element(w.begin(), w.end()) - w.begin());
    std::array<std::uint32_t, 6> v;
    for (int i = 0; i < 6; ++i)
        v[i] = w[kRot[m][i]];
    if (std::min(v[1], v[5]) < std::min(v[2], v[4])) {
        tets.emplace_back(v[0], v[1], v[2], v[5]);
        tets.emplace_back(v[0], v[1], v[5], v[4]);
    } else {
        tets.emplace_back(v[0], v[1], v[2], v[4]);
        tets.emplace_back(v[0], v[4], v[2], v[5]);
    }
    tets.emplace_back(v[0], v[4], v[5], v[3]);
}

}  // namespace clvr
