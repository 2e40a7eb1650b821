// host/render/grid/cube_fans.h — cell classification and the remapping tables of seeds/002
// (Schussman & Max 2001, §3-5): the six face dot products (d, f), the 10 cases in 3 classes (Fig. 3),
// the standard fan/strip templates (Figs. 4-6) and the vertex remapping tables (Figs. 7, 8, class 3a/3b).
// Numbering (Fig. 2, recovered from the tables): vertex v = x + 2y + 4z of the unit cube; faces
// 0 -x, 1 +x, 2 -y, 3 +y, 4 -z, 5 +z. projectCube turns one box into the triangles of its class's
// template with the thickness at every vertex (§4, §7); host/render/grid/cubefan.h draws them.
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
// The same for a parallel projection: towardsEyeUnit is the direction towards the viewer (minus the
// view direction) in the unit cube's coordinates; d = n_f . towardsEye / |towardsEye|.
Classification classifyParallel(const glm::dvec3& towardsEyeUnit);

// The standard templates of Figs. 4-6 as triangle lists (fans and strips expanded in GL's order),
// vertices numbered as the standard cube's (0..7) plus the edge intersections A = 8 and B = 9, and the
// edges (standard vertex pairs, front edge first) whose crossing in the projection A and B are.
struct Template {
    int triangleCount = 0;
    std::array<std::array<int, 3>, 12> triangles{};
    int crossings = 0;                            // 0 (class 1) or 2 (A, B)
    std::array<std::array<int, 4>, 2> edges{};    // (front a, front b, back a, back b) for A, then B
};
enum class TemplateKind { Class1, Class2, Class3a, Class3b };
const Template& standardTemplate(TemplateKind kind);

// How a view sees one box. viewProjection takes world points to clip coordinates; eye is the camera
// position (perspective) and forward the unit view direction (parallel).
struct CubeView {
    glm::dmat4 viewProjection{1.0};
    glm::dvec3 eye{0.0};
    glm::dvec3 forward{0.0, 0.0, -1.0};
    bool parallel = false;
};

// Corner v = x + 2y + 4z of the box [lo, hi] (bit a of v: the hi side on axis a).
glm::dvec3 cornerOf(const glm::dvec3& lo, const glm::dvec3& hi, int v);

// The length of the chord of the viewing ray through world point p with the box [lo, hi] (the part in
// front of the eye for perspective; the whole line along forward for parallel). 0 when it misses.
double chordThrough(const CubeView& view, const glm::dvec3& lo, const glm::dvec3& hi, const glm::dvec3& p);

// One box projected: its template remapped to the box's corners (corner v = x + 2y + 4z of the box,
// x the lo/hi choice on each axis), A and B computed, and per vertex the normalized device coordinates
// and the thickness l (the ray's chord through the box there: 0 on the silhouette).
struct ProjectedCube {
    Classification classification;
    TemplateKind kind = TemplateKind::Class1;
    int vertexCount = 0;                       // 8 corners, then A, B when the template has them
    std::array<glm::dvec2, 10> ndc{};
    std::array<double, 10> thickness{};
    std::array<glm::dvec3, 10> world{};        // the vertex's front point (A, B: on the front edge)
    int triangleCount = 0;
    std::array<std::array<int, 3>, 12> triangles{};  // indices into the vertices above
};
// Class 0 (the eye inside or on the box, or a parallel view along a face plane that hides no face)
// returns triangleCount 0: the caller draws such a box another way (cubefan.cpp: its back faces).
// corners: the box's eight corners' clip coordinates divided by w (the caller projects shared corners
// once, so that neighbouring boxes get identical bits).
ProjectedCube projectCube(const CubeView& view, const glm::dvec3& lo, const glm::dvec3& hi,
                          const std::array<glm::dvec2, 8>& cornersNdc);

}  // namespace clvr::cubefan
