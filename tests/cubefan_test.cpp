// tests/cubefan_test.cpp — seeds/002's tables and classification (host/render/grid/cube_fans.h),
// checked against brute-force constructions from the cube's own geometry.
#include "host/render/grid/cube_fans.h"
#include "host/render/grid/cube_octree.h"

#include "raster/framebuffer.h"
#include "raster/rasterizer.h"
#include "tests/support/test_util.h"

#include <glm/gtc/matrix_transform.hpp>
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <set>
#include <vector>

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

// ---- the templates drawn through the raster stage -------------------------------------------------------

// The ten eyes of TenCasesOfFigure3 (unit cube coordinates).
const glm::dvec3 kCaseEyes[10] = {{0.3, 0.6, 3.0},   {0.3, 1.0, 3.0},    {1.0, 1.0, 3.0},  {-0.4, 0.6, 2.5},
                                   {-0.5, 0.6, 1.5},  {-0.4, 1.0, 2.5},   {-0.5, 1.0, 1.5}, {-0.6, 1.3, 2.0},
                                   {-0.75, 1.3, 1.75}, {-0.5, 1.5, 1.5}};

// Symmetry s (0..47) of the unit cube applied to a point: axes permuted (s / 8 of the six
// permutations), then mirrored (bit a of s % 8 mirrors axis a about 0.5).
glm::dvec3 symmetric(const glm::dvec3& e, int s)
{
    static const int perms[6][3] = {{0, 1, 2}, {0, 2, 1}, {1, 0, 2}, {1, 2, 0}, {2, 0, 1}, {2, 1, 0}};
    glm::dvec3 r;
    for (int a = 0; a < 3; ++a) {
        r[a] = e[perms[s / 8][a]];
        if ((s % 8) & (1 << a))
            r[a] = 1.0 - r[a];
    }
    return r;
}

// A camera at `eye` (world) looking at the box centre whose image holds the whole box.
Camera viewOf(const glm::dvec3& lo, const glm::dvec3& hi, const glm::dvec3& eye, bool parallel)
{
    Camera camera;
    camera.position = eye;
    camera.focalPoint = 0.5 * (lo + hi);
    const glm::dvec3 forward = glm::normalize(camera.focalPoint - eye);
    camera.viewUp = std::abs(forward.y) < 0.9 ? glm::dvec3(0.0, 1.0, 0.0) : glm::dvec3(1.0, 0.0, 0.0);
    double angle = 0.0, extent = 0.0;
    for (int v = 0; v < 8; ++v) {
        const glm::dvec3 p((v & 1) ? hi.x : lo.x, (v & 2) ? hi.y : lo.y, (v & 4) ? hi.z : lo.z);
        const glm::dvec3 d = p - eye;
        angle = std::max(angle, std::acos(std::clamp(glm::dot(glm::normalize(d), forward), -1.0, 1.0)));
        extent = std::max(extent, glm::length(d - glm::dot(d, forward) * forward));
    }
    camera.viewAngle = std::min(2.4 * glm::degrees(angle), 150.0);
    camera.parallel = parallel;
    camera.parallelScale = 1.2 * extent;
    return camera;
}

struct Drawn {
    std::vector<std::uint8_t> stencil;  // fragments per pixel
    Image4f color;                      // r: the interpolated thickness of the last fragment
    ProjectedCube cube;
};

// The box's template drawn as projectCube makes it: stencil INCR per fragment, color = thickness.
Drawn drawCube(const Camera& camera, const glm::dvec3& lo, const glm::dvec3& hi, int size)
{
    CubeView view;
    view.viewProjection = camera.projectionMatrix(size, size, 0.01, 100.0) * camera.viewMatrix();
    view.eye = camera.position;
    view.forward = camera.forward();
    view.parallel = camera.parallel;
    std::array<glm::dvec2, 8> corners;
    for (int v = 0; v < 8; ++v) {
        const glm::dvec4 c = view.viewProjection * glm::dvec4((v & 1) ? hi.x : lo.x, (v & 2) ? hi.y : lo.y,
                                                                (v & 4) ? hi.z : lo.z, 1.0);
        corners[v] = glm::dvec2(c) / c.w;
    }
    Drawn d;
    d.cube = projectCube(view, lo, hi, corners);
    std::vector<raster::Vertex> vertices;
    for (int t = 0; t < d.cube.triangleCount; ++t)
        for (const int i : d.cube.triangles[t]) {
            raster::Vertex v;
            v.position = glm::vec4(static_cast<float>(d.cube.ndc[i].x), static_cast<float>(d.cube.ndc[i].y), 0.0f, 1.0f);
            v.attributes[0] = glm::vec4(static_cast<float>(d.cube.thickness[i]), 0.0f, 0.0f, 1.0f);
            vertices.push_back(v);
        }
    Device& device = test::device();
    raster::Framebuffer fb(device, size, size);
    fb.clearColor(device, glm::vec4(0.0f));
    fb.clearStencil(device, 0);
    raster::DrawState state;
    state.fragment.stencil.test = true;
    state.fragment.stencil.dppass = raster::StencilOp::Incr;
    raster::FragmentProgram program;
    program.attributes = 1;
    raster::draw(device, fb, state, raster::Topology::Triangles, vertices, program);
    d.stencil = fb.readStencil(device);
    d.color = fb.readColor(device);
    return d;
}

// Signed distance (pixels, > 0 inside) of a window point to the convex hull of the box's projected
// corners: the smallest over the hull's edges (the hull from the 8 points by gift wrapping).
double hullDistance(const std::vector<glm::dvec2>& hull, const glm::dvec2& p)
{
    double d = std::numeric_limits<double>::infinity();
    for (std::size_t i = 0; i < hull.size(); ++i) {
        const glm::dvec2 a = hull[i], b = hull[(i + 1) % hull.size()];
        const glm::dvec2 e = b - a;
        d = std::min(d, (e.x * (p.y - a.y) - e.y * (p.x - a.x)) / glm::length(e));
    }
    return d;
}
std::vector<glm::dvec2> convexHull(std::vector<glm::dvec2> p)
{
    // Andrew's monotone chain; counter-clockwise in a y-up frame, so "inside" is to the left.
    std::sort(p.begin(), p.end(), [](const glm::dvec2& a, const glm::dvec2& b) { return a.x < b.x || (a.x == b.x && a.y < b.y); });
    auto cross = [](const glm::dvec2& o, const glm::dvec2& a, const glm::dvec2& b) {
        return (a.x - o.x) * (b.y - o.y) - (a.y - o.y) * (b.x - o.x);
    };
    std::vector<glm::dvec2> h(2 * p.size());
    std::size_t k = 0;
    for (std::size_t i = 0; i < p.size(); ++i) {
        while (k >= 2 && cross(h[k - 2], h[k - 1], p[i]) <= 0.0)
            --k;
        h[k++] = p[i];
    }
    for (std::size_t i = p.size() - 1, t = k + 1; i > 0; --i) {
        while (k >= t && cross(h[k - 2], h[k - 1], p[i - 1]) <= 0.0)
            --k;
        h[k++] = p[i - 1];
    }
    h.resize(k - 1);
    return h;
}

// Every case of Fig. 3 in all 48 orientations of the cube (and of a box that is not a cube), perspective
// and parallel: the template's triangles cover the projected box exactly once (stencil 1 at every pixel
// centre more than 1/64 pixel inside the hull of the projected corners, 0 more than 1/64 outside, never
// more than 1 anywhere), and the interpolated thickness is the ray's chord through the box: closely for
// parallel projection, within a stated bound for perspective from afar (§7: linear interpolation of l
// across a triangle is an approximation under perspective, a poor one close up: printed, not asserted).
TEST(CubefanTemplates, CoverTheProjectedBoxOnceWithTheChordAsThickness)
{
    const int size = 48;
    const struct { glm::dvec3 lo, hi; } boxes[] = {{glm::dvec3(0.0), glm::dvec3(1.0)},
                                                   {glm::dvec3(-0.2, 0.1, 0.3), glm::dvec3(1.3, 0.8, 1.4)}};
    std::set<std::string> labels;
    std::set<std::array<int, 3>> class3Triples;
    double worstChord[3] = {0.0, 0.0, 0.0}, largestChord = 0.0;
    int views = 0;
    for (const auto& box : boxes)
        for (const glm::dvec3& caseEye : kCaseEyes)
            for (int s = 0; s < 48; ++s)
                for (const int mode : {0, 1, 2}) {
                    // 0: perspective from the case's eye (1 to 2.5 box sizes away), 1: parallel along it,
                    // 2: perspective from 8 times as far (the case may become a neighbouring one).
                    const bool parallel = mode == 1;
                    const glm::dvec3 unitEye = mode == 2 ? 0.5 + 8.0 * (symmetric(caseEye, s) - 0.5) : symmetric(caseEye, s);
                    const glm::dvec3 eye = box.lo + unitEye * (box.hi - box.lo);
                    const Camera camera = viewOf(box.lo, box.hi, eye, parallel);
                    const Drawn d = drawCube(camera, box.lo, box.hi, size);
                    ASSERT_GT(d.cube.triangleCount, 0);
                    ++views;
                    if (mode == 0) {
                        labels.insert(d.cube.classification.caseLabel);
                        if (d.cube.classification.cls == 3)
                            class3Triples.insert(d.cube.classification.f);
                    }
                    std::vector<glm::dvec2> window;
                    for (int v = 0; v < 8; ++v)  // y up, so the hull is counter-clockwise as computed
                        window.push_back({(d.cube.ndc[v].x + 1.0) * 0.5 * size, (d.cube.ndc[v].y + 1.0) * 0.5 * size});
                    const std::vector<glm::dvec2> hull = convexHull(window);
                    const PixelRays rays(camera, size, size);
                    CubeView view;
                    view.eye = camera.position;
                    view.forward = camera.forward();
                    view.parallel = parallel;
                    int mismatches = 0;
                    for (int y = 0; y < size; ++y)
                        for (int x = 0; x < size; ++x) {
                            const int count = d.stencil[static_cast<std::size_t>(y) * size + x];
                            const double inside = hullDistance(hull, {x + 0.5, size - (y + 0.5)});
                            const bool wrong = count > 1 || (inside > 1.0 / 64 && count != 1) || (inside < -1.0 / 64 && count != 0);
                            mismatches += wrong;
                            if (count != 1)
                                continue;
                            const Ray ray = rays.at(x, y);
                            const double chord = chordThrough(view, box.lo, box.hi, ray.origin + ray.direction);
                            largestChord = std::max(largestChord, chord);
                            worstChord[mode] = std::max(worstChord[mode], std::abs(d.color.at(x, y).r - chord));
                        }

                    EXPECT_EQ(mismatches, 0) << "case " << d.cube.classification.caseLabel << " symmetry " << s
                                             << (parallel ? " parallel" : " perspective") << " eye " << eye.x << " "
                                             << eye.y << " " << eye.z;
                }
    std::printf("%d views; thickness vs chord: max |error| perspective near %.3g, far %.3g, parallel %.3g (largest "
                "chord %.3g)\n", views, worstChord[0], worstChord[2], worstChord[1], largestChord);
    EXPECT_EQ(labels.size(), 10u);         // every case of Fig. 3
    EXPECT_EQ(class3Triples.size(), 48u);  // every class-3 (f0, f1, f2), 3a and 3b
    // Parallel: linear per triangle (exact in double on the host), so what is left is the raster stage's
    // 1/256-pixel snapping of the vertices under steep thickness gradients: 2.4e-3 (of 1.9) at 48², 9.3e-4
    // at 144² (docs/cubefan.md); perspective from 8-20 box sizes away: the linear interpolation's error (measured
    // 0.053, 2.8% of the largest chord; it falls with the box's depth over its distance).
    EXPECT_LT(worstChord[1], 2e-3 * largestChord);
    EXPECT_LT(worstChord[2], 0.05 * largestChord);
}

// ---- the octree (§6) -------------------------------------------------------------------------------------

Volume randomVolume(glm::ivec3 dims, std::uint64_t seed)
{
    Volume v;
    v.dims = dims;
    v.spacing = {0.5, 0.7, 0.6};
    v.origin = {-1.0, 0.2, 0.4};
    test::Rng rng(seed);
    for (int i = 0; i < dims.x * dims.y * dims.z; ++i)
        v.values.push_back(static_cast<float>(rng.uniform()));
    return v;
}

// Every cube of every level against the voxels inside its box, by brute force.
TEST(CubefanOctree, ValuesAreLeafMeansAndErrorsTheLargestLeafDeviation)
{
    const Volume v = randomVolume({7, 5, 6}, 11);
    const CubeOctree tree(v);
    ASSERT_EQ(tree.levels(), 4);  // 7 -> 4 -> 2 -> 1
    EXPECT_EQ(tree.dims(3), glm::ivec3(1));
    for (int level = 0; level < tree.levels(); ++level) {
        glm::ivec3 i;
        for (i.z = 0; i.z < tree.dims(level).z; ++i.z)
            for (i.y = 0; i.y < tree.dims(level).y; ++i.y)
                for (i.x = 0; i.x < tree.dims(level).x; ++i.x) {
                    glm::dvec3 lo, hi;
                    tree.box(level, i, lo, hi);
                    std::vector<double> inside;
                    for (int z = 0; z < v.dims.z; ++z)
                        for (int y = 0; y < v.dims.y; ++y)
                            for (int x = 0; x < v.dims.x; ++x) {
                                const glm::dvec3 p = v.origin + glm::dvec3(x, y, z) * v.spacing;
                                if (glm::all(glm::greaterThan(p, lo)) && glm::all(glm::lessThan(p, hi)))
                                    inside.push_back(v.at(x, y, z));
                            }
                    ASSERT_FALSE(inside.empty());
                    double mean = 0.0;
                    for (double x : inside)
                        mean += x / inside.size();
                    double err = 0.0;
                    for (double x : inside)
                        err = std::max(err, std::abs(x - tree.value(level, i)));
                    EXPECT_NEAR(tree.value(level, i), mean, 1e-6) << level;
                    EXPECT_NEAR(tree.error(level, i), err, 1e-6) << level;
                }
    }
}

// Two boxes that share a face with positive area: +1 when the eye (or, parallel, the viewer) is on b's
// side of the shared plane (a must come first), -1 on a's side, 0 when they do not share a face.
int frontOf(const Cube& a, const Cube& b, const glm::dvec3& eye, const glm::dvec3& forward, bool parallel)
{
    for (int axis = 0; axis < 3; ++axis)
        for (const int sign : {-1, 1}) {
            const double plane = sign > 0 ? a.hi[axis] : a.lo[axis];
            const double other = sign > 0 ? b.lo[axis] : b.hi[axis];
            if (std::abs(plane - other) > 1e-9)
                continue;
            bool overlap = true;
            for (int q = 0; q < 3; ++q)
                if (q != axis && !(std::min(a.hi[q], b.hi[q]) - std::max(a.lo[q], b.lo[q]) > 1e-9))
                    overlap = false;
            if (!overlap)
                continue;
            const double towardsB = parallel ? -sign * forward[axis] : sign * (eye[axis] - plane);
            return towardsB > 0.0 ? 1 : (towardsB < 0.0 ? -1 : 0);
        }
    return 0;
}

// Tolerance 0 selects every voxel the transfer function does not make transparent; larger tolerances
// select cubes within it; in every case disjoint cubes, and of every two that share a face, the one
// behind (from the eye outside or inside the volume, or along a parallel view) comes first.
TEST(CubefanOctree, SelectionIsWithinToleranceAndBackToFront)
{
    const Volume v = randomVolume({9, 6, 7}, 5);
    const CubeOctree tree(v);
    const TransferFunction tf({{0.0, glm::dvec3(0.0), 0.0}, {0.3, glm::dvec3(0.0), 0.0}, {0.5, glm::dvec3(1.0), 2.0},
                               {1.0, glm::dvec3(1.0), 3.0}});
    const glm::dvec3 inside = v.origin + glm::dvec3(4.2, 2.3, 3.1) * v.spacing;
    const struct { glm::dvec3 eye; bool parallel; } views[] = {
        {{6.0, -3.0, 9.0}, false}, {inside, false}, {{0.0, 0.0, 0.0}, true}};
    const glm::dvec3 forward = glm::normalize(glm::dvec3(0.3, 0.8, -0.5));
    std::uint64_t opaqueVoxels = 0;
    for (float x : v.values)
        opaqueVoxels += tf(x).a > 0.0;
    for (const double tolerance : {0.0, 0.3, 0.6})
        for (const auto& view : views) {
            SelectionStats stats;
            const std::vector<Cube> cubes = tree.select(tolerance, tf, view.eye, forward, view.parallel, &stats);
            EXPECT_EQ(stats.selected, cubes.size());
            if (tolerance == 0.0) {
                EXPECT_EQ(cubes.size(), opaqueVoxels);
            }
            int shared = 0;
            for (std::size_t i = 0; i < cubes.size(); ++i) {
                EXPECT_LE(tree.error(cubes[i].level, cubes[i].index), tolerance * tree.dataRange() + 1e-6);
                EXPECT_GT(tf(cubes[i].value).a, 0.0);
                for (std::size_t j = i + 1; j < cubes.size(); ++j) {
                    bool disjoint = false;
                    for (int q = 0; q < 3; ++q)
                        disjoint |= std::min(cubes[i].hi[q], cubes[j].hi[q]) - std::max(cubes[i].lo[q], cubes[j].lo[q]) <= 1e-9;
                    EXPECT_TRUE(disjoint);
                    const int order = frontOf(cubes[i], cubes[j], view.eye, forward, view.parallel);
                    shared += order != 0;
                    EXPECT_GE(order, 0) << "cube " << j << " is behind cube " << i << " but comes later";
                }
            }
            if (cubes.size() > 4) {  // enough cubes that some share faces
                EXPECT_GT(shared, 0) << cubes.size() << " cubes at tolerance " << tolerance;
            }
            std::printf("tolerance %.1f: %zu cubes, %d face pairs\n", tolerance, cubes.size(), shared);
        }
    // Tolerance 1 takes the root unless it is transparent.
    EXPECT_EQ(tree.select(1.0, tf, views[0].eye, forward, false).size(), tf(tree.value(tree.levels() - 1, glm::ivec3(0))).a > 0.0 ? 1u : 0u);
}

// The tile path's selection tree orders the same cubes for each eye as select() does, nearest first: frontToBack is
// select()'s list reversed, cube for cube, from eyes outside in several octants, inside the volume and on a cube's
// split planes, and along parallel views (the eye then unused); the tree's stats are select()'s.
TEST(CubefanOctree, SelectionTreeOrdersTheCubesAsSelect)
{
    const Volume v = randomVolume({13, 9, 11}, 7);
    const CubeOctree octree(v);
    const TransferFunction tf({{0.0, glm::dvec3(0.0), 0.0}, {0.3, glm::dvec3(0.0), 0.0}, {0.5, glm::dvec3(1.0), 2.0},
                               {1.0, glm::dvec3(1.0), 3.0}});
    const glm::dvec3 inside = v.origin + glm::dvec3(4.2, 2.3, 3.1) * v.spacing;
    const glm::dvec3 onPlanes = v.origin + glm::dvec3(3.5, 3.5, 7.5) * v.spacing;  // on split planes of several levels
    const glm::dvec3 eyes[] = {{6.0, -3.0, 9.0}, {-4.0, 8.0, -2.0}, {0.1, 0.2, -9.0}, inside, onPlanes};
    const glm::dvec3 forwards[] = {glm::normalize(glm::dvec3(0.3, 0.8, -0.5)), glm::normalize(glm::dvec3(-0.6, 0.1, 0.7))};
    int compared = 0;
    for (const double tolerance : {0.0, 0.2, 0.5, 1.0}) {
        SelectionStats treeStats;
        const CubeOctree::SelectionTree tree = octree.selectTree(tolerance, tf, &treeStats);
        std::vector<std::uint32_t> order;
        auto check = [&](const glm::dvec3& eye, const glm::dvec3& forward, bool parallel) {
            SelectionStats stats;
            const std::vector<Cube> cubes = octree.select(tolerance, tf, eye, forward, parallel, &stats);
            EXPECT_EQ(treeStats.selected, stats.selected);
            EXPECT_EQ(treeStats.visited, stats.visited);
            EXPECT_EQ(treeStats.transparent, stats.transparent);
            tree.frontToBack(eye, forward, parallel, order);
            ASSERT_EQ(order.size(), cubes.size());
            for (std::size_t k = 0; k < cubes.size(); ++k) {
                const Cube& a = cubes[cubes.size() - 1 - k];
                const Cube& b = tree.cubes[order[k]];
                EXPECT_TRUE(a.level == b.level && a.index == b.index && a.value == b.value && a.lo == b.lo && a.hi == b.hi)
                    << "tolerance " << tolerance << ", cube " << k << " of " << cubes.size();
            }
            ++compared;
        };
        for (const glm::dvec3& eye : eyes)
            check(eye, forwards[0], false);
        for (const glm::dvec3& forward : forwards)
            check(glm::dvec3(0.0), forward, true);
    }
    EXPECT_EQ(compared, 4 * 7);
}

// The fused path's selection grid holds the same selection as select(): every selected cube's voxels carry
// its level and value, every other voxel (and the bricks' padding beyond the grid) is marked transparent,
// and the counts agree. Checked voxel by voxel through selectionGridIndex, which must be a one-to-one map
// into the grid.
TEST(CubefanOctree, SelectionGridHoldsTheSelectedCubes)
{
    const Volume v = randomVolume({9, 6, 7}, 5);
    const CubeOctree tree(v);
    const TransferFunction tf({{0.0, glm::dvec3(0.0), 0.0}, {0.3, glm::dvec3(0.0), 0.0}, {0.5, glm::dvec3(1.0), 2.0},
                               {1.0, glm::dvec3(1.0), 3.0}});
    for (const double tolerance : {0.0, 0.3, 0.6, 1.0}) {
        SelectionStats listed, gridded;
        const std::vector<Cube> cubes = tree.select(tolerance, tf, glm::dvec3(6.0, -3.0, 9.0), glm::dvec3(0, 0, 1), false, &listed);
        const CubeOctree::SelectionGrid grid = tree.selectGrid(tolerance, tf, &gridded);
        ASSERT_EQ(grid.level.size(), std::size_t(3 * 2 * 2 * 64));  // 9 x 6 x 7 voxels in bricks of 4^3
        ASSERT_EQ(grid.value.size(), grid.level.size());
        EXPECT_EQ(gridded.selected, listed.selected);
        EXPECT_EQ(gridded.transparent, listed.transparent);
        EXPECT_EQ(gridded.visited, listed.visited);
        EXPECT_EQ(gridded.largestDiagonal, listed.largestDiagonal);
        std::vector<int> owner(grid.level.size(), -1);  // the selected cube holding each entry
        for (std::size_t c = 0; c < cubes.size(); ++c) {
            const glm::ivec3 first = cubes[c].index * (1 << cubes[c].level);
            const glm::ivec3 end = glm::min(first + (1 << cubes[c].level), v.dims);
            glm::ivec3 p;
            for (p.z = first.z; p.z < end.z; ++p.z)
                for (p.y = first.y; p.y < end.y; ++p.y)
                    for (p.x = first.x; p.x < end.x; ++p.x) {
                        const std::size_t at = selectionGridIndex(p, v.dims);
                        ASSERT_LT(at, owner.size());
                        EXPECT_EQ(owner[at], -1) << "two cubes on one voxel";
                        owner[at] = static_cast<int>(c);
                    }
        }
        std::size_t entries = 0;
        glm::ivec3 p;
        for (p.z = 0; p.z < v.dims.z; ++p.z)
            for (p.y = 0; p.y < v.dims.y; ++p.y)
                for (p.x = 0; p.x < v.dims.x; ++p.x, ++entries) {
                    const std::size_t at = selectionGridIndex(p, v.dims);
                    const int c = owner[at];
                    owner[at] = -2;  // seen: a second voxel on this entry would find -2
                    ASSERT_NE(c, -2) << "two voxels on one entry";
                    if (c < 0) {
                        EXPECT_TRUE(grid.level[at] & CubeOctree::kTransparent);
                        continue;
                    }
                    EXPECT_EQ(grid.level[at], cubes[c].level);
                    EXPECT_EQ(grid.value[at], cubes[c].value);
                }
        EXPECT_EQ(entries, std::size_t(9 * 6 * 7));
        for (std::size_t at = 0; at < owner.size(); ++at)  // the padding: transparent
            if (owner[at] == -1) {
                EXPECT_TRUE(grid.level[at] & CubeOctree::kTransparent) << at;
            }
    }
}

}  // namespace
}  // namespace clvr::cubefan
