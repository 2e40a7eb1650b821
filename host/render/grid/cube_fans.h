// host/render/grid/cube_fans.h — cell classification and the remapping tables of seeds/002
// (Schussman & Max 2001, §3-5): the six face dot products (d, f), the 10 cases in 3 classes (Fig. 3),
// the standard fan/strip templates (Figs. 4-6) and the vertex remapping tables (Figs. 7, 8, class 3a/3b).
// Numbering (Fig. 2, recovered from the tables): vertex v = x + 2y + 4z of the unit cube; faces
// 0 -x, 1 +x, 2 -y, 3 +y, 4 -z, 5 +z. Work in progress for issue 12: the renderer is not built yet.
#pragma once

#include <glm/glm.hpp>

#include <array>
#include <string>

namespace clvr::cubefan {

// Fig. 7: class 1, row f0: standard vertex i -> actual vertex.
extern const int kClass1Remap[6][8];
// Fig. 8: classes 2 and 3a, row (f0, f1); rows never used (f1 == f0 or opposite) hold -1.
extern const int kClass2Remap[6][6][8];
// The 24 (f0, f1, f2) of class 3a listed in §5; every other class-3 triple is 3b.
extern const std::array<std::array<int, 3>, 24> kClass3aTriples;
bool isClass3a(int f0, int f1, int f2);

// The classification of a box seen from `eye` (perspective) in the box's unit-cube coordinates,
// where the projection's topology is that of the box (an affine map keeps it).
struct Classification {
    int cls = 0;                 // number of d > 0: 1, 2, 3; 0 when the eye is inside or on the box
    std::array<int, 3> f{};      // faces of the three largest d, descending (ties by face number)
    std::array<double, 3> d{};
    std::string caseLabel;       // "10", "11", "12", "20a", ..., "30c" (Fig. 3); "" for cls 0
};
// eyeUnit: the eye in the unit cube's coordinates.
Classification classify(const glm::dvec3& eyeUnit);

}  // namespace clvr::cubefan
