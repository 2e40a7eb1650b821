// host/render/grid/cube_fans.cpp — the tables of seeds/002 §5 and the classification of §3.
#include "host/render/grid/cube_fans.h"

#include <algorithm>
#include <cmath>
#include <initializer_list>
#include <limits>
#include <vector>

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

namespace {

// The class and case from the six d (§3): the three largest, descending, ties by face number.
Classification fromDots(const std::array<double, 6>& dots)
{
    std::array<std::pair<double, int>, 6> pairs;
    for (int f = 0; f < 6; ++f)
        pairs[f] = {dots[f], f};
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

}  // namespace

Classification classify(const glm::dvec3& e)
{
    // d = n_f . (eye - c_f) / |eye - c_f|: the unit normal with the unit viewing vector (§3).
    std::array<double, 6> dots;
    for (int f = 0; f < 6; ++f) {
        const int axis = f / 2;
        const double sign = (f % 2) ? 1.0 : -1.0;
        glm::dvec3 c(0.5);
        c[axis] = (f % 2) ? 1.0 : 0.0;
        const glm::dvec3 v = e - c;
        const double len = glm::length(v);
        dots[f] = len > 0.0 ? sign * v[axis] / len : 0.0;
    }
    return fromDots(dots);
}

Classification classifyParallel(const glm::dvec3& towardsEye)
{
    const double len = glm::length(towardsEye);
    std::array<double, 6> dots;
    for (int f = 0; f < 6; ++f)
        dots[f] = len > 0.0 ? ((f % 2) ? 1.0 : -1.0) * towardsEye[f / 2] / len : 0.0;
    return fromDots(dots);
}

// ---- templates (Figs. 4-6) ----------------------------------------------------------------------------

namespace {

constexpr int A = 8, B = 9;

// Appends a fan (GL: (c, v_i, v_i+1)) or a strip (GL: (i, i+1, i+2), odd ones reordered) to t.
void addFan(Template& t, std::initializer_list<int> v)
{
    const std::vector<int> p(v);
    for (std::size_t i = 1; i + 1 < p.size(); ++i)
        t.triangles[t.triangleCount++] = {p[0], p[i], p[i + 1]};
}
void addStrip(Template& t, std::initializer_list<int> v)
{
    const std::vector<int> p(v);
    for (std::size_t i = 0; i + 2 < p.size(); ++i)
        t.triangles[t.triangleCount++] = (i % 2) ? std::array<int, 3>{p[i + 1], p[i], p[i + 2]}
                                                 : std::array<int, 3>{p[i], p[i + 1], p[i + 2]};
}

Template makeTemplate(TemplateKind kind)
{
    // The standard views: class 1 sees face 5; class 2 faces 5 and 0; class 3 faces 5, 0 and 3, 3a with
    // d5 > d0 (row (f0, f1) of Fig. 8), 3b with d0 > d5 (row (f1, f0)). Edge intersections in docs/cubefan.md.
    Template t;
    switch (kind) {
    case TemplateKind::Class1:
        addFan(t, {2, 3, 7, 6, 4, 0, 3});
        addFan(t, {1, 3, 0, 4, 5, 7, 3});
        break;
    case TemplateKind::Class2:
        addFan(t, {1, 7, 3, B, A, 4, 5, 7});
        addStrip(t, {7, 3, 6, B, 2, A, 0, 4});
        t.crossings = 2;
        t.edges = {{{4, 6, 0, 1}, {4, 6, 2, 3}}};
        break;
    case TemplateKind::Class3a:
        addFan(t, {A, 6, 2, 0, 4, 5, 1, B, 6});
        addFan(t, {B, 1, 5, 7, 3, 2, 6});
        t.crossings = 2;
        t.edges = {{{4, 6, 0, 1}, {6, 7, 1, 3}}};
        break;
    case TemplateKind::Class3b:
        addFan(t, {A, 6, B, 1, 0, 4, 5, 7, 6});
        addFan(t, {B, 6, 7, 3, 2, 0, 1});
        t.crossings = 2;
        t.edges = {{{4, 6, 1, 5}, {2, 6, 1, 3}}};
        break;
    }
    return t;
}

}  // namespace

const Template& standardTemplate(TemplateKind kind)
{
    static const std::array<Template, 4> all = {makeTemplate(TemplateKind::Class1), makeTemplate(TemplateKind::Class2),
                                                makeTemplate(TemplateKind::Class3a), makeTemplate(TemplateKind::Class3b)};
    return all[static_cast<int>(kind)];
}

// ---- one box projected ----------------------------------------------------------------------------------

double chordThrough(const CubeView& view, const glm::dvec3& lo, const glm::dvec3& hi, const glm::dvec3& p)
{
    // The line o + t d; perspective: o the eye, d = p - eye, t >= 0; parallel: o = p, d = forward, any t.
    const glm::dvec3 o = view.parallel ? p : view.eye;
    const glm::dvec3 d = view.parallel ? view.forward : p - view.eye;
    double tIn = view.parallel ? -std::numeric_limits<double>::infinity() : 0.0;
    double tOut = std::numeric_limits<double>::infinity();
    for (int a = 0; a < 3; ++a) {
        if (d[a] == 0.0) {
            if (o[a] < lo[a] || o[a] > hi[a])
                return 0.0;
            continue;
        }
        double t0 = (lo[a] - o[a]) / d[a], t1 = (hi[a] - o[a]) / d[a];
        if (t0 > t1)
            std::swap(t0, t1);
        tIn = std::max(tIn, t0);
        tOut = std::min(tOut, t1);
    }
    return tOut > tIn ? (tOut - tIn) * glm::length(d) : 0.0;
}

glm::dvec3 cornerOf(const glm::dvec3& lo, const glm::dvec3& hi, int v)
{
    return {(v & 1) ? hi.x : lo.x, (v & 2) ? hi.y : lo.y, (v & 4) ? hi.z : lo.z};
}

namespace {

// The point of segment [q0, q1] that the viewing ray through the segment [p0, p1] also meets: the
// segment cut by the plane through the eye (perspective) or along forward (parallel) holding p0 and p1.
glm::dvec3 crossingOnFrontEdge(const CubeView& view, const glm::dvec3& q0, const glm::dvec3& q1, const glm::dvec3& p0,
                               const glm::dvec3& p1)
{
    const glm::dvec3 n = view.parallel ? glm::cross(p1 - p0, view.forward) : glm::cross(p0 - view.eye, p1 - view.eye);
    const double denominator = glm::dot(n, q1 - q0);
    double t = denominator != 0.0 ? glm::dot(n, p0 - q0) / denominator : 0.5;
    t = std::clamp(std::isfinite(t) ? t : 0.5, 0.0, 1.0);  // degenerate views: the edges' projections touch
    return q0 + t * (q1 - q0);
}

}  // namespace

ProjectedCube projectCube(const CubeView& view, const glm::dvec3& lo, const glm::dvec3& hi,
                          const std::array<glm::dvec2, 8>& cornersNdc)
{
    ProjectedCube r;
    const glm::dvec3 size = hi - lo;
    r.classification = view.parallel ? classifyParallel(-view.forward / size) : classify((view.eye - lo) / size);
    const Classification& c = r.classification;
    if (c.cls == 0)
        return r;
    const int* remap = nullptr;
    if (c.cls == 1) {
        r.kind = TemplateKind::Class1;
        remap = kClass1Remap[c.f[0]];
    } else if (c.cls == 2) {
        r.kind = TemplateKind::Class2;
        remap = kClass2Remap[c.f[0]][c.f[1]];
    } else if (isClass3a(c.f[0], c.f[1], c.f[2])) {
        r.kind = TemplateKind::Class3a;
        remap = kClass2Remap[c.f[0]][c.f[1]];
    } else {
        r.kind = TemplateKind::Class3b;
        remap = kClass2Remap[c.f[1]][c.f[0]];
    }
    const Template& t = standardTemplate(r.kind);
    // Vertex i of the result is standard vertex i (0..7), A (8), B (9).
    for (int i = 0; i < 8; ++i) {
        const int v = remap[i];
        r.world[i] = cornerOf(lo, hi, v);
        r.ndc[i] = cornersNdc[v];
        r.thickness[i] = chordThrough(view, lo, hi, r.world[i]);
    }
    r.vertexCount = 8;
    for (int k = 0; k < t.crossings; ++k) {
        const auto& e = t.edges[k];
        const glm::dvec3 p = crossingOnFrontEdge(view, r.world[e[0]], r.world[e[1]], r.world[e[2]], r.world[e[3]]);
        const glm::dvec4 clip = view.viewProjection * glm::dvec4(p, 1.0);
        r.world[8 + k] = p;
        r.ndc[8 + k] = glm::dvec2(clip) / clip.w;
        r.thickness[8 + k] = chordThrough(view, lo, hi, p);
        r.vertexCount = 9 + k;
    }
    r.triangleCount = t.triangleCount;
    r.triangles = t.triangles;
    return r;
}

}  // namespace clvr::cubefan
