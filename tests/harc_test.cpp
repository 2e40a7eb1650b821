// tests/harc_test.cpp — HARC with partial pre-integration (host/render/tet/harc.h): options, the 80-byte
// layout, a single tetrahedron against the closed form, Kuhn-split box grids (convex and non-convex)
// against an exact double-precision integral of a globally linear field, identical bits, independence
// from splitting the transfer function, the step bound, and the paper's meshes against the exact
// tetrahedral reference when host/tet_reference and host/mesh_io are present.
#include "host/render/tet/harc.h"

#include "host/runtime/errors.h"
#include "host/optics/psi_table.h"
#include "host/reference/tet_reference.h"
#include "tests/support/mesh_fixtures.h"
#include "tests/support/test_util.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <map>
#include <random>
#include <string>

namespace clvr {
namespace {

using nlohmann::json;
using test::Box;
using test::boxMesh;
using test::meshCamera;
using test::parallelView;
using test::perspective;

// Face adjacency by hand (sorted point triples), as buildTopology defines it.
TetTopology handTopology(const TetMesh& mesh)
{
    TetTopology topo;
    topo.neighbor.assign(mesh.tets.size(), {-1, -1, -1, -1});
    std::map<std::array<unsigned, 3>, std::pair<std::uint32_t, std::uint32_t>> open;
    for (std::uint32_t t = 0; t < mesh.tets.size(); ++t)
        for (std::uint32_t f = 0; f < 4; ++f) {
            std::array<unsigned, 3> key;
            int n = 0;
            for (int i = 0; i < 4; ++i)
                if (i != static_cast<int>(f))
                    key[n++] = mesh.tets[t][i];
            std::sort(key.begin(), key.end());
            auto it = open.find(key);
            if (it == open.end()) {
                open[key] = {t, f};
            } else {
                topo.neighbor[t][f] = static_cast<std::int32_t>(it->second.first);
                topo.neighbor[it->second.first][it->second.second] = static_cast<std::int32_t>(t);
                open.erase(it);
            }
        }
    for (const auto& [key, tf] : open)
        topo.boundary.push_back({tf.first, tf.second});
    std::sort(topo.boundary.begin(), topo.boundary.end(),
              [](const auto& a, const auto& b) { return a.tet != b.tet ? a.tet < b.tet : a.face < b.face; });
    return topo;
}

// Exact integral (double, ψ by quadrature) of a globally linear field over a union of disjoint boxes:
// clip the ray to each box, cut at control points, Eq. 2.
Image4d boxReference(const std::vector<Box>& boxes, const glm::dvec3& gradient, double offset,
                     const TransferFunction& tf, const Camera& camera, const ImageSpec& spec)
{
    Image4d image(spec.width, spec.height);
    for (int y = 0; y < spec.height; ++y)
        for (int x = 0; x < spec.width; ++x) {
            const Ray ray = camera.ray(x, y, spec.width, spec.height);
            std::vector<std::pair<double, double>> spans;
            for (const Box& b : boxes) {
                double t0 = 0.0, t1 = INFINITY;
                for (int a = 0; a < 3; ++a) {
                    if (ray.direction[a] == 0.0) {
                        if (ray.origin[a] < b.lo[a] || ray.origin[a] > b.hi[a])
                            t1 = -1.0;
                        continue;
                    }
                    const double u = (b.lo[a] - ray.origin[a]) / ray.direction[a];
                    const double v = (b.hi[a] - ray.origin[a]) / ray.direction[a];
                    t0 = std::max(t0, std::min(u, v));
                    t1 = std::min(t1, std::max(u, v));
                }
                if (t1 > t0)
                    spans.push_back({t0, t1});
            }
            std::sort(spans.begin(), spans.end());
            glm::dvec3 color(0.0);
            double transmittance = 1.0;
            for (const auto& [l0, l1] : spans) {
                const double sf = glm::dot(gradient, ray.origin + l0 * ray.direction) + offset;
                const double sb = glm::dot(gradient, ray.origin + l1 * ray.direction) + offset;
                std::vector<double> cuts = {0.0};
                for (const ControlPoint& cp : tf.points())
                    if ((cp.s - sf) * (cp.s - sb) < 0.0)
                        cuts.push_back((cp.s - sf) / (sb - sf));
                cuts.push_back(1.0);
                std::sort(cuts.begin(), cuts.end());
                for (std::size_t c = 0; c + 1 < cuts.size(); ++c) {
                    const double l = (cuts[c + 1] - cuts[c]) * (l1 - l0);
                    const glm::dvec4 front = tf(sf + cuts[c] * (sb - sf)), back = tf(sf + cuts[c + 1] * (sb - sf));
                    const double zeta = std::exp(-0.5 * l * (front.w + back.w));
                    const double psi = psiNumerical(front.w * l, back.w * l);
                    color += transmittance * (glm::dvec3(back) * (psi - zeta) + glm::dvec3(front) * (1.0 - psi));
                    transmittance *= zeta;
                }
            }
            image.at(x, y) = glm::dvec4(color + transmittance * spec.background, 1.0 - transmittance);
        }
    return image;
}

TransferFunction rampTf() { return test::rampTransferFunction(); }

Scene makeScene(const Camera& camera, const TransferFunction& tf, int size, json options = json::object())
{
    return test::meshScene("harc", camera, tf, size, std::move(options));
}

Image4f renderHarc(const Scene& scene, const TetMesh& mesh, FrameStats* statsOut = nullptr)
{
    auto renderer = makeHarcRenderer(test::device(), scene, mesh, handTopology(mesh));
    FrameStats stats;
    Image4f image = renderer->render(stats);
    if (statsOut)
        *statsOut = stats;
    return image;
}

struct TopologyAndSlots {
    TetTopology topology;
    std::vector<std::uint32_t> slot;
};

void printError(const char* what, const Image4f& actual, const Image4d& expected)
{
    const test::ImageError e = test::imageError(actual, expected);
    std::printf("%s: max |error| (%.2g %.2g %.2g %.2g), mean (%.2g %.2g %.2g %.2g)\n", what, e.maxAbs.r,
                e.maxAbs.g, e.maxAbs.b, e.maxAbs.a, e.meanAbs.r, e.meanAbs.g, e.meanAbs.b, e.meanAbs.a);
}

TEST(HarcOptions, ParsesAndRejects)
{
    const HarcOptions o = parseHarcOptions(json{{"integration", "average"}, {"max_steps", 7}, {"early_termination", 0.9}});
    EXPECT_EQ(o.integration, HarcOptions::Integration::Average);
    EXPECT_EQ(o.maxSteps, 7u);
    EXPECT_DOUBLE_EQ(o.earlyTermination, 0.9);
    EXPECT_THROW(parseHarcOptions(json{{"slices", 3}}), InputError);
    EXPECT_THROW(parseHarcOptions(json{{"integration", "fancy"}}), InputError);
    EXPECT_THROW(parseHarcOptions(json{{"max_steps", 0}}), InputError);
    EXPECT_THROW(parseHarcOptions(json{{"early_termination", 1.5}}), InputError);
    EXPECT_EQ(parseHarcOptions(json::object()).entry, HarcOptions::Entry::Host);
    const HarcOptions r = parseHarcOptions(json{{"entry", "raster"}, {"max_layers", 3}});
    EXPECT_EQ(r.entry, HarcOptions::Entry::Raster);
    EXPECT_EQ(r.maxLayers, 3);
    EXPECT_THROW(parseHarcOptions(json{{"entry", "peel"}}), InputError);
    EXPECT_THROW(parseHarcOptions(json{{"max_layers", 0}}), InputError);
    EXPECT_THROW(parseHarcOptions(json{{"max_layers", 256}}), InputError);
    try {
        parseHarcOptions(json{{"bogus", 1}});
        ADD_FAILURE() << "options.bogus accepted";
    } catch (const InputError& e) {
        EXPECT_NE(std::string(e.what()).find("options.bogus"), std::string::npos) << e.what();
    }
}

// The message of the InputError that parseHarcOptions throws for `options`, or "" if none.
std::string optionError(const json& options)
{
    try {
        parseHarcOptions(options);
    } catch (const InputError& e) {
        return e.what();
    }
    return "";
}

TEST(HarcOptions, FullTableParsesAndRejects)
{
    const HarcOptions d = parseHarcOptions(json{{"integration", "full"}});
    EXPECT_EQ(d.integration, HarcOptions::Integration::Full);
    EXPECT_EQ(d.fullScalarSamples, 64);
    EXPECT_EQ(d.fullLengthSamples, 64);
    const HarcOptions o = parseHarcOptions(json{{"integration", "full"}, {"full_table", {128, 32}}});
    EXPECT_EQ(o.fullScalarSamples, 128);
    EXPECT_EQ(o.fullLengthSamples, 32);
    // 256 x 256 x 256 x 16 bytes is exactly the 256 MiB bound; one more l sample is over it.
    EXPECT_EQ(parseHarcOptions(json{{"integration", "full"}, {"full_table", {256, 256}}}).fullLengthSamples, 256);
    const char* bad[] = {"128", "[128, 32, 4]", "[1, 64]", "[64, 513]", "[64.5, 64]", "[\"64\", 64]", "\"64x64\"",
                         "[256, 257]", "[512, 512]", "[-64, 64]"};
    for (const char* text : bad) {
        const json value = json::parse(text);
        const std::string what = optionError(json{{"integration", "full"}, {"full_table", value}});
        EXPECT_NE(what.find("options.full_table"), std::string::npos) << value.dump() << ": " << what;
    }
    EXPECT_NE(optionError(json{{"integration", "full"}, {"full_table", {512, 512}}}).find("MiB"), std::string::npos);
    // Without full integration the table would be silently ignored: say so instead.
    EXPECT_NE(optionError(json{{"full_table", {64, 64}}}).find("options.full_table"), std::string::npos);
    EXPECT_NE(optionError(json{{"integration", "full2"}}).find("options.integration"), std::string::npos);
}

TEST(HarcLayout, PlanesAndGradientReproduceTheTet)
{
    TetMesh mesh;
    mesh.points = {{10.0, 20.0, 30.0}, {11.0, 20.2, 30.1}, {10.3, 21.0, 29.9}, {10.2, 20.1, 31.0}};
    mesh.scalars = {0.5, 1.5, -2.0, 3.0};
    mesh.tets = {{0, 1, 2, 3}};
    const glm::dvec3 shift(10.0, 20.0, 30.0);
    const std::vector<cl_float4> packed = packHarcTets(mesh, handTopology(mesh), shift);
    ASSERT_EQ(packed.size() * sizeof(cl_float4), kHarcBytesPerTet);
    EXPECT_EQ(kHarcBytesPerTet, 80u);
    glm::dvec4 planes[4];
    for (int i = 0; i < 3; ++i)
        planes[i] = glm::dvec4(packed[i].s[0], packed[i].s[1], packed[i].s[2], packed[i].s[3]);
    planes[3] = glm::dvec4(-(glm::dvec3(planes[0]) + glm::dvec3(planes[1]) + glm::dvec3(planes[2])),
                           1.0 - (planes[0].w + planes[1].w + planes[2].w));
    const glm::dvec4 g(packed[3].s[0], packed[3].s[1], packed[3].s[2], packed[3].s[3]);
    for (int v = 0; v < 4; ++v) {
        const glm::dvec3 x = mesh.points[v] - shift;
        for (int i = 0; i < 4; ++i)
            EXPECT_NEAR(glm::dot(glm::dvec3(planes[i]), x) + planes[i].w, i == v ? 1.0 : 0.0, 1e-5);
        EXPECT_NEAR(glm::dot(glm::dvec3(g), x) + g.w, mesh.scalars[v], 1e-5);
    }
    cl_int adj[4];
    std::memcpy(adj, &packed[4], sizeof adj);
    for (int i = 0; i < 4; ++i)
        EXPECT_EQ(adj[i], -1);
}

// The adjacency word across face i is neighbor * 4 + the neighbor's face that is the same triangle.
TEST(HarcLayout, AdjacencyNamesTheNeighborsEntryFace)
{
    const TetMesh mesh = boxMesh({{{0.0, 0.0, 0.0}, {1.0, 1.0, 1.0}, 2}}, {0.5, 0.3, 0.2}, 0.1);
    const TetTopology topology = handTopology(mesh);
    const std::vector<cl_float4> packed = packHarcTets(mesh, topology, glm::dvec3(0.5));
    std::size_t inner = 0;
    for (std::size_t t = 0; t < mesh.tets.size(); ++t) {
        cl_int adj[4];
        std::memcpy(adj, &packed[5 * t + 4], sizeof adj);
        for (int i = 0; i < 4; ++i) {
            if (topology.neighbor[t][i] < 0) {
                EXPECT_EQ(adj[i], -1);
                continue;
            }
            ++inner;
            const int n = adj[i] >> 2, j = adj[i] & 3;
            ASSERT_EQ(n, topology.neighbor[t][i]);
            std::array<std::uint32_t, 3> mine{}, theirs{};
            for (int k = 0, a = 0, b = 0; k < 4; ++k) {
                if (k != i)
                    mine[a++] = mesh.tets[t][k];
                if (k != j)
                    theirs[b++] = mesh.tets[n][k];
            }
            std::sort(mine.begin(), mine.end());
            std::sort(theirs.begin(), theirs.end());
            EXPECT_EQ(mine, theirs) << "tet " << t << " face " << i;
        }
    }
    EXPECT_GT(inner, mesh.tets.size());  // the grid has inner faces
}

// The mesh's cells in a fixed random order (as a mesher may number them), the points kept.
TetMesh shuffledCells(TetMesh mesh, unsigned seed)
{
    std::mt19937 random(seed);
    std::shuffle(mesh.tets.begin(), mesh.tets.end(), random);
    return mesh;
}

// harcCellOrder: a permutation that puts face neighbours near each other on the device, and packHarcTets with
// it: each cell's planes and gradient at its place, its adjacency naming the neighbours' places.
TEST(HarcLayout, CellOrderPlacesNeighboursNearAndMapsTheAdjacency)
{
    const TetMesh mesh = shuffledCells(boxMesh({{{0.0, 0.0, 0.0}, {1.0, 1.0, 1.0}, 6}}, {0.5, 0.3, 0.2}, 0.1), 7);
    const TetTopology topology = handTopology(mesh);
    const std::vector<std::uint32_t> slot = harcCellOrder(mesh, topology);
    ASSERT_EQ(slot.size(), mesh.tets.size());
    std::vector<std::uint32_t> sorted = slot;
    std::sort(sorted.begin(), sorted.end());
    for (std::size_t i = 0; i < sorted.size(); ++i)
        ASSERT_EQ(sorted[i], i) << "not a permutation";
    // The mean distance in memory between face neighbours: the shuffled order's is a third of the cells.
    double shuffled = 0.0, ordered = 0.0;
    std::size_t pairs = 0;
    for (std::size_t t = 0; t < mesh.tets.size(); ++t)
        for (const std::int32_t n : topology.neighbor[t])
            if (n >= 0) {
                shuffled += std::abs(static_cast<double>(t) - n);
                ordered += std::abs(static_cast<double>(slot[t]) - slot[static_cast<std::size_t>(n)]);
                ++pairs;
            }
    std::printf("mean distance of face neighbours: %.1f cells shuffled, %.1f ordered (%zu cells); log2: %.2f, %.2f\n",
                shuffled / pairs, ordered / pairs, mesh.tets.size(), harcNeighbourDistance(topology),
                harcNeighbourDistance(topology, slot));
    EXPECT_LT(ordered * 8.0, shuffled);
    EXPECT_LT(harcNeighbourDistance(topology, slot) + 3.0, harcNeighbourDistance(topology));
    // A mesh numbered in that order already keeps its own.
    TetMesh numbered = mesh;
    for (std::size_t t = 0; t < mesh.tets.size(); ++t)
        numbered.tets[slot[t]] = mesh.tets[t];
    EXPECT_TRUE(harcCellOrder(numbered, handTopology(numbered)).empty()) << "a mesh in Morton order was reordered";

    const glm::dvec3 shift(0.5);
    const std::vector<cl_float4> plain = packHarcTets(mesh, topology, shift);
    const std::vector<cl_float4> placed = packHarcTets(mesh, topology, shift, slot);
    ASSERT_EQ(placed.size(), plain.size());
    for (std::size_t t = 0; t < mesh.tets.size(); ++t) {
        EXPECT_EQ(std::memcmp(&placed[5 * slot[t]], &plain[5 * t], 4 * sizeof(cl_float4)), 0) << "tet " << t;
        cl_int a[4], b[4];
        std::memcpy(a, &placed[5 * slot[t] + 4], sizeof a);
        std::memcpy(b, &plain[5 * t + 4], sizeof b);
        for (int i = 0; i < 4; ++i)
            EXPECT_EQ(a[i], b[i] < 0 ? -1 : harcDeviceCode(b[i], slot)) << "tet " << t << " face " << i;
    }
    EXPECT_EQ(harcDeviceCode(-1 - 5, slot), -1 - static_cast<std::int32_t>(slot[5]));  // the eye's cell
    EXPECT_EQ(harcDeviceCode(4 * 9 + 3, slot), static_cast<std::int32_t>(4 * slot[9] + 3));
}

// buildHarcEntryLists against every pixel's ray tested against every boundary face (no boxes, no bands) by the
// textbook Möller–Trumbore test with its divisions, which buildHarcEntryLists computes as affine functions per face
// without them (kernels/harc.cl's walk needs these exact lists: the faces a ray enters through, λ >= 0, margins at
// the edges), sorted by λ, then code. Perspective from outside and from inside (faces behind the eye clipped), parallel,
// a sort-first band of rows, sizes that are no multiple of the 8-row bands.
HarcEntryLists bruteForceEntryLists(const TetMesh& mesh, const TetTopology& topology, const Camera& camera, int width,
                                    int height)
{
    HarcEntryLists lists;
    lists.offsets.push_back(0);
    for (int y = 0; y < height; ++y)
        for (int x = 0; x < width; ++x) {
            const Ray ray = PixelRays(camera, width, height).at(x, y);
            std::vector<std::pair<float, std::int32_t>> hits;
            for (const TetTopology::BoundaryFace& bf : topology.boundary) {
                const std::array<glm::dvec3, 3> p = outwardFace(mesh, bf.tet, bf.face);
                const glm::dvec3 e1 = p[1] - p[0], e2 = p[2] - p[0];
                if (!(glm::dot(glm::cross(e1, e2), ray.direction) < 0.0))
                    continue;
                const glm::dvec3 pv = glm::cross(ray.direction, e2);
                const double det = glm::dot(e1, pv);
                if (det == 0.0)
                    continue;
                const glm::dvec3 tv0 = ray.origin - p[0], qv = glm::cross(tv0, e1);
                const double bu = glm::dot(tv0, pv) / det, bv = glm::dot(ray.direction, qv) / det;
                const double lambda = glm::dot(e2, qv) / det;
                if (bu >= -1e-7 && bv >= -1e-7 && bu + bv <= 1.0 + 1e-7 && lambda >= 0.0)
                    hits.push_back({static_cast<float>(lambda), static_cast<std::int32_t>(bf.tet * 4 + bf.face)});
            }
            std::sort(hits.begin(), hits.end());
            for (const auto& [lambda, code] : hits) {
                cl_int bits;
                std::memcpy(&bits, &lambda, sizeof bits);
                lists.entries.push_back(cl_int2{{bits, code}});
            }
            lists.offsets.push_back(static_cast<cl_uint>(lists.entries.size()));
        }
    return lists;
}

TEST(HarcEntryLists, EqualTheCrossingsOfEveryRayWithEveryFace)
{
    const std::vector<Box> lShape = {{{0.0, 0.0, 0.0}, {2.0, 1.0, 1.0}, 4}, {{0.0, 1.0, 0.0}, {1.0, 2.0, 1.0}, 3}};
    TetMesh l = boxMesh(lShape, {0.3, 0.35, -0.4}, 0.4);
    checkMesh(l);
    const TetMesh gap = boxMesh({{{0.0, 0.0, 0.0}, {1.0, 1.0, 0.4}, 3}, {{0.0, 0.0, 0.7}, {1.0, 1.0, 1.1}, 3}}, {0.3, 0.5, 0.2}, 0.1);
    Camera band = perspective({0.9, 0.7, 3.2}, {0.5, 0.5, 0.5}, 40.0);
    band.bandFullHeight = 53;  // rows 17..36 of a 53-row image
    band.bandY0 = 17;
    struct Case {
        const char* name;
        const TetMesh* mesh;
        Camera camera;
        int width, height;
    };
    const Case cases[] = {
        {"L, perspective", &l, perspective({3.1, 2.4, 2.6}), 61, 45},
        {"L, eye inside", &l, perspective({0.55, 0.45, 0.6}, {1.6, 1.3, 0.3}, 95.0), 40, 33},
        {"L, parallel", &l, parallelView({3.5, -1.5, 2.5}, {1.0, 1.0, 0.5}, 1.4), 37, 29},
        {"gap, a band of rows", &gap, band, 47, 20},
        {"gap, one pixel", &gap, perspective({0.9, 0.7, 3.2}, {0.5, 0.5, 0.5}, 40.0), 1, 1},
    };
    std::vector<Case> all(std::begin(cases), std::end(cases));
    std::mt19937 random(17);  // and views from all round, near and far, wide and narrow
    std::uniform_real_distribution<double> unit(-1.0, 1.0), angle(25.0, 80.0), distance(1.6, 5.0);
    for (int i = 0; i < 8; ++i) {
        const glm::dvec3 direction = glm::normalize(glm::dvec3(unit(random), unit(random), unit(random)) + 1e-3);
        const glm::dvec3 focal(0.8 + 0.3 * unit(random), 0.7 + 0.3 * unit(random), 0.5 + 0.3 * unit(random));
        all.push_back({"L, a random view", &l, perspective(focal + distance(random) * direction, focal, angle(random)), 31, 27});
    }
    for (const Case& c : all) {
        const TetTopology topology = handTopology(*c.mesh);
        const HarcEntryLists lists = buildHarcEntryLists(*c.mesh, topology, c.camera, c.width, c.height);
        const HarcEntryLists expected = bruteForceEntryLists(*c.mesh, topology, c.camera, c.width, c.height);
        ASSERT_EQ(lists.offsets.size(), static_cast<std::size_t>(c.width) * c.height + 1) << c.name;
        EXPECT_GT(expected.entries.size(), 0u) << c.name;  // the mesh is in view
        EXPECT_TRUE(lists.offsets == expected.offsets) << c.name;
        ASSERT_EQ(lists.entries.size(), expected.entries.size()) << c.name;
        std::size_t differ = 0;
        for (std::size_t k = 0; k < lists.entries.size(); ++k)
            differ += lists.entries[k].s[0] != expected.entries[k].s[0] || lists.entries[k].s[1] != expected.entries[k].s[1];
        EXPECT_EQ(differ, 0u) << c.name;
    }
}

// The cells' order on the device changes no bit of any integration, packets or not, with the host's entry
// lists, the raster's and an eye inside the mesh (whose entries name cells by their place).
TEST(Harc, CellOrderChangesNoBit)
{
    const std::vector<Box> lShape = {{{0.0, 0.0, 0.0}, {2.0, 1.0, 1.0}, 4}, {{0.0, 1.0, 0.0}, {1.0, 2.0, 1.0}, 3}};
    TetMesh inside = boxMesh(lShape, {0.3, 0.35, -0.4}, 0.4);
    checkMesh(inside);
    inside = shuffledCells(inside, 3);
    const TetMesh gap = shuffledCells(
        boxMesh({{{0.0, 0.0, 0.0}, {1.0, 1.0, 0.4}, 3}, {{0.0, 0.0, 0.7}, {1.0, 1.0, 1.1}, 3}}, {0.3, 0.5, 0.2}, 0.1), 5);
    const TetMesh grid = shuffledCells(boxMesh({{{0.0, 0.0, 0.0}, {1.0, 1.0, 1.0}, 3}}, {0.6, 0.25, -0.4}, 0.35), 11);
    struct Case {
        const char* name;
        const TetMesh* mesh;
        Camera camera;
        json options;
    };
    const Camera eyeInside = perspective({0.55, 0.45, 0.6}, {1.6, 1.3, 0.3}, 95.0);
    const Camera overGap = perspective({0.9, 0.7, 3.2}, {0.5, 0.5, 0.5}, 40.0);
    const Case cases[] = {
        {"grid, partial", &grid, perspective({1.9, 1.4, 2.6}), json::object()},
        {"eye inside the L, partial", &inside, eyeInside, json::object()},
        {"eye inside the L, full", &inside, eyeInside, json{{"integration", "full"}, {"full_table", {16, 16}}}},
        {"gap, average", &gap, overGap, json{{"integration", "average"}}},
        {"gap, raster entry", &gap, overGap, json{{"entry", "raster"}}},
        {"gap, slices", &gap, overGap, json::object()},
        {"L, iso", &inside, parallelView({3.5, -1.5, 2.5}, {1.0, 1.0, 0.5}, 1.4), json::object()},
    };
    int compared = 0;
    for (const Case& c : cases) {
        TopologyAndSlots check{handTopology(*c.mesh), {}};
        check.slot = harcCellOrder(*c.mesh, check.topology);
        ASSERT_FALSE(std::is_sorted(check.slot.begin(), check.slot.end())) << c.name << ": the order is the mesh's";
        for (const bool packets : {true, false}) {
            Scene scene = makeScene(c.camera, rampTf(), 41, c.options);
            scene.image.height = 29;
            HarcOptions options = parseHarcOptions(scene.options);
            options.packets = packets;
            const std::string name(c.name);
            if (name.ends_with("slices")) {
                options.integration = HarcOptions::Integration::Slices;
                options.sliceDepth0 = 0.5;
                options.sliceSpacing = 0.05;
                options.sliceCount = 100;
            } else if (name.ends_with("iso")) {
                options.integration = HarcOptions::Integration::Iso;
                options.iso.value = 0.4;
                for (const glm::dvec3& point : c.mesh->points)  // a different normal at every point
                    options.iso.normals.push_back(glm::normalize(point - glm::dvec3(0.7, 0.6, -0.5)));
            }
            FrameStats stats[2];
            Image4f images[2];
            for (int i = 0; i < 2; ++i) {
                options.meshCellOrder = i == 1;
                images[i] = makeHarcRenderer(test::device(), scene, *c.mesh, check.topology, options)->render(stats[i]);
            }
            const std::string what = name + (packets ? ", packets" : ", one pixel per work-item");
            EXPECT_TRUE(test::sameBits(images[0], images[1])) << what;
            for (const char* key : {"steps", "pieces", "entry_crossings", "eye_tet"})
                EXPECT_EQ(stats[0].extra[key], stats[1].extra[key]) << what << ": " << key;
            EXPECT_GT(stats[0].extra["steps"].get<std::uint64_t>(), 0u) << what;
            EXPECT_GT(stats[0].extra["pieces"].get<std::uint64_t>(), 0u) << what;  // pieces, samples or hits
            ++compared;
        }
    }
    EXPECT_EQ(compared, 7 * 2);
}

TEST(Harc, SingleTetConstantMatchesClosedForm)
{
    TetMesh mesh;
    mesh.points = {{0.0, 0.0, 0.0}, {1.0, 0.0, 0.0}, {0.0, 1.0, 0.0}, {0.0, 0.0, 1.0}};
    mesh.scalars = {0.0, 1.0, 0.2, 0.7};
    mesh.tets = {{0, 1, 2, 3}};
    mesh.source = "one tet";
    const glm::dvec3 c(0.9, 0.4, 0.1);
    const double tau = 2.5;
    const TransferFunction tf({{-1.0, c, tau}, {2.0, c, tau}});
    const Scene scene = makeScene(perspective({1.6, 1.2, 2.1}, {0.25, 0.25, 0.25}, 30.0), tf, 48);
    const Image4f image = renderHarc(scene, mesh);
    // C (1 - exp(-τ L)) + exp(-τ L) background, L the ray's length inside the tet (double clip).
    Image4d expected(48, 48);
    const glm::dvec4 planes[4] = {{-1, -1, -1, 1}, {1, 0, 0, 0}, {0, 1, 0, 0}, {0, 0, 1, 0}};  // >= 0 inside
    int covered = 0;
    for (int y = 0; y < 48; ++y)
        for (int x = 0; x < 48; ++x) {
            const Ray ray = scene.camera->ray(x, y, 48, 48);
            double t0 = 0.0, t1 = INFINITY;
            for (const glm::dvec4& p : planes) {
                const double a = glm::dot(glm::dvec3(p), ray.origin) + p.w, b = glm::dot(glm::dvec3(p), ray.direction);
                if (b == 0.0) {
                    if (a < 0.0)
                        t1 = -1.0;
                } else if (b > 0.0) {
                    t0 = std::max(t0, -a / b);
                } else {
                    t1 = std::min(t1, -a / b);
                }
            }
            const double l = std::max(0.0, t1 - t0);
            covered += l > 0.0;
            const double tr = std::exp(-tau * l);
            expected.at(x, y) = glm::dvec4(c * (1.0 - tr) + tr * scene.image.background, 1.0 - tr);
        }
    EXPECT_GT(covered, 200);
    printError("single tet, constant C and tau", image, expected);
    // float32 geometry and ψ table at τl <= 4.3: well below 1e-4.
    EXPECT_TRUE(test::imagesNear(image, expected, {.maxAbs = 2e-4, .meanAbs = 2e-5}));
}

TEST(Harc, ConvexBoxGridMatchesExactIntegral)
{
    const std::vector<Box> boxes = {{{0.0, 0.0, 0.0}, {1.0, 1.0, 1.0}, 4}};  // 384 tets
    const glm::dvec3 gradient(0.6, 0.25, -0.4);
    const TetMesh mesh = boxMesh(boxes, gradient, 0.35);
    const TransferFunction tf = rampTf();
    for (const bool parallel : {false, true}) {
        Camera camera = perspective({1.9, 1.4, 2.6});
        if (parallel) {
            camera.parallel = true;
            camera.parallelScale = 1.0;
        }
        const Scene scene = makeScene(camera, tf, 64);
        FrameStats stats;
        const Image4f image = renderHarc(scene, mesh, &stats);
        const Image4d expected = boxReference(boxes, gradient, 0.35, tf, camera, scene.image);
        printError(parallel ? "box grid, parallel" : "box grid, perspective", image, expected);
        EXPECT_TRUE(test::imagesNear(image, expected, {.maxAbs = 2e-3, .meanAbs = 2e-4}));
        EXPECT_EQ(stats.extra["rays_step_bound"].get<std::uint64_t>(), 0u);
        EXPECT_GT(stats.extra["steps"].get<std::uint64_t>(), 1000u);
        EXPECT_EQ(stats.extra["tet_layout_bytes"].get<std::uint64_t>(), 80u);
    }
}

TEST(Harc, EyeInsideTheMeshStartsEveryRayInItsCell)
{
    // A perspective eye inside a non-convex mesh (two boxes): the rays start in the eye's cell, not at the
    // first boundary face ahead; before this they lost everything between the eye and that face.
    const std::vector<Box> boxes = {{{0.0, 0.0, 0.0}, {2.0, 1.0, 1.0}, 4}, {{0.0, 1.0, 0.0}, {1.0, 2.0, 1.0}, 3}};
    const glm::dvec3 gradient(0.3, 0.35, -0.4);
    TetMesh mesh = boxMesh(boxes, gradient, 0.4);
    checkMesh(mesh);
    const TransferFunction tf = rampTf();
    Camera camera = perspective({0.55, 0.45, 0.6}, {1.6, 1.3, 0.3}, 95.0);
    const Scene scene = makeScene(camera, tf, 48);
    FrameStats stats;
    const Image4f image = renderHarc(scene, mesh, &stats);
    EXPECT_GE(stats.extra["eye_tet"].get<std::int64_t>(), 0);
    const Image4d expected = tetReferenceIntegral(mesh, tf, camera, scene.image);
    printError("eye inside", image, expected);
    EXPECT_TRUE(test::imagesNear(image, expected, {.maxAbs = 2e-3, .meanAbs = 2e-4}));
    EXPECT_EQ(locatePoint(mesh, glm::dvec3(1.5, 1.5, 0.5)), -1);  // in the L's gap
}

TEST(Harc, NonConvexRayContinuesBehindTheGap)
{
    // Two boxes with a gap along the view direction, and an L-shape (three boxes in a corner).
    const glm::dvec3 gradient(0.3, 0.5, 0.2);
    const std::vector<std::vector<Box>> cases = {
        {{{0.0, 0.0, 0.0}, {1.0, 1.0, 0.4}, 3}, {{0.0, 0.0, 0.7}, {1.0, 1.0, 1.1}, 3}},
        {{{0.0, 0.0, 0.0}, {0.5, 0.5, 0.5}, 2}, {{0.5, 0.0, 0.0}, {1.0, 0.5, 0.5}, 2}, {{0.0, 0.5, 0.0}, {0.5, 1.0, 0.5}, 2}},
    };
    const TransferFunction tf = rampTf();
    for (std::size_t c = 0; c < cases.size(); ++c) {
        // Boxes are separate meshes here (their faces are not shared), so the L-shape's inner walls
        // are boundary faces too: every re-entry goes through the crossing list.
        const TetMesh mesh = boxMesh(cases[c], gradient, 0.1);
        const Camera camera = perspective({0.9, 0.7, 3.2}, {0.5, 0.5, 0.5}, 40.0);
        const Scene scene = makeScene(camera, tf, 64);
        const Image4f image = renderHarc(scene, mesh);
        const Image4d expected = boxReference(cases[c], gradient, 0.1, tf, camera, scene.image);
        printError(c == 0 ? "two boxes with a gap" : "L-shape of three boxes", image, expected);
        EXPECT_TRUE(test::imagesNear(image, expected, {.maxAbs = 2e-3, .meanAbs = 2e-4}));
    }
    // Welded L-shape (one mesh: shared faces connected): the rays leave through the concave corner
    // and re-enter; seen from a side where they do.
    {
        TetMesh mesh = boxMesh({{{0.0, 0.0, 0.0}, {2.0, 1.0, 1.0}, 2}}, gradient, 0.1);
        // Drop the tets of the cube x in [1,2], y in [0.5,1] ... simpler: keep the box and cut tets whose
        // centroid lies in the notch x > 1, z > 0.5.
        std::vector<glm::uvec4> kept;
        for (const glm::uvec4& t : mesh.tets) {
            glm::dvec3 ctr(0.0);
            for (int i = 0; i < 4; ++i)
                ctr += 0.25 * mesh.points[t[i]];
            if (!(ctr.x > 1.0 && ctr.z > 0.5))
                kept.push_back(t);
        }
        mesh.tets = kept;
        mesh.tetsRead = kept.size();
        const std::vector<Box> asBoxes = {{{0.0, 0.0, 0.0}, {1.0, 1.0, 1.0}, 1}, {{1.0, 0.0, 0.0}, {2.0, 1.0, 0.5}, 1}};
        const Camera camera = perspective({3.5, 0.5, 1.6}, {1.0, 0.5, 0.5}, 40.0);
        const Scene scene = makeScene(camera, tf, 64);
        const Image4f image = renderHarc(scene, mesh);
        const Image4d expected = boxReference(asBoxes, gradient, 0.1, tf, camera, scene.image);
        printError("welded L-shape", image, expected);
        EXPECT_TRUE(test::imagesNear(image, expected, {.maxAbs = 2e-3, .meanAbs = 2e-4}));
    }
}

// Raster entry lists (depth peeling) on the two boxes with a gap: the same image as the exact host
// lists within the reference tolerance, two layers; with max_layers 1 the rays that had a second entry
// are counted in rays_layer_bound and lose the far box.
TEST(Harc, RasterEntryPeelsTheGapAndCountsTheLayerBound)
{
    const glm::dvec3 gradient(0.3, 0.5, 0.2);
    const std::vector<Box> boxes = {{{0.0, 0.0, 0.0}, {1.0, 1.0, 0.4}, 3}, {{0.0, 0.0, 0.7}, {1.0, 1.0, 1.1}, 3}};
    const TetMesh mesh = boxMesh(boxes, gradient, 0.1);
    const Camera camera = perspective({0.9, 0.7, 3.2}, {0.5, 0.5, 0.5}, 40.0);
    const Image4d expected = boxReference(boxes, gradient, 0.1, rampTf(), camera, ImageSpec{64, 64, {0.1, 0.2, 0.3}});
    FrameStats stats;
    const Image4f peeled = renderHarc(makeScene(camera, rampTf(), 64, json{{"entry", "raster"}}), mesh, &stats);
    printError("two boxes with a gap, raster entry", peeled, expected);
    EXPECT_TRUE(test::imagesNear(peeled, expected, {.maxAbs = 2e-3, .meanAbs = 2e-4}));
    EXPECT_EQ(stats.extra["entry_layers"].get<int>(), 2);
    EXPECT_EQ(stats.extra["rays_layer_bound"].get<std::uint64_t>(), 0u);

    FrameStats cutStats;
    const Image4f cut =
        renderHarc(makeScene(camera, rampTf(), 64, json{{"entry", "raster"}, {"max_layers", 1}}), mesh, &cutStats);
    EXPECT_EQ(cutStats.extra["entry_layers"].get<int>(), 1);
    EXPECT_GT(cutStats.extra["rays_layer_bound"].get<std::uint64_t>(), 1000u);
    EXPECT_FALSE(test::imagesNear(cut, expected, {.maxAbs = 2e-3, .meanAbs = 2e-4}));
}

TEST(Harc, IdenticalBitsTwice)
{
    const TetMesh mesh = boxMesh({{{0.0, 0.0, 0.0}, {1.0, 1.0, 1.0}, 3}}, {0.5, 0.3, 0.2}, 0.1);
    const Scene scene = makeScene(perspective({1.7, 1.3, 2.4}), rampTf(), 40);
    const Image4f a = renderHarc(scene, mesh), b = renderHarc(scene, mesh);
    ASSERT_EQ(a.pixelCount(), b.pixelCount());
    EXPECT_EQ(std::memcmp(a.pixels().data(), b.pixels().data(), a.pixelCount() * sizeof(glm::vec4)), 0);
}

// Renderer::setCamera: a harc renderer pointed at new cameras (outside, the eye inside the non-convex mesh,
// parallel) gives the images new renderers give, bit for bit, with host and raster entry lists and full
// pre-integration; a new image size is refused.
TEST(Harc, SetCameraEqualsAFreshRenderer)
{
    // EyeInsideTheMeshStartsEveryRayInItsCell's mesh and inside camera
    const std::vector<Box> boxes = {{{0.0, 0.0, 0.0}, {2.0, 1.0, 1.0}, 4}, {{0.0, 1.0, 0.0}, {1.0, 2.0, 1.0}, 3}};
    TetMesh mesh = boxMesh(boxes, {0.3, 0.35, -0.4}, 0.4);
    checkMesh(mesh);  // orients the cells, as every loader does
    ASSERT_GE(locatePoint(mesh, glm::dvec3(0.55, 0.45, 0.6)), 0);
    const Camera parallel = parallelView({3.5, -1.5, 2.5}, {1.0, 1.0, 0.5}, 1.4);
    const Camera cameras[] = {perspective({3.2, 2.6, 2.4}, {1.0, 1.0, 0.5}, 40.0),
                              perspective({0.55, 0.45, 0.6}, {1.6, 1.3, 0.3}, 95.0), parallel,
                              perspective({-1.5, 3.0, 1.8}, {1.0, 1.0, 0.5}, 40.0)};
    for (const json& options : {json::object(), json{{"entry", "raster"}}, json{{"integration", "full"}}}) {
        Scene scene = makeScene(cameras[0], rampTf(), 33, options);
        auto moved = makeHarcRenderer(test::device(), scene, mesh, handTopology(mesh));
        FrameStats stats;
        moved->render(stats);
        for (std::size_t c = 1; c < std::size(cameras); ++c) {
            scene.camera = cameras[c];
            ASSERT_TRUE(moved->setCamera(scene)) << options.dump();
            const Image4f a = moved->render(stats);
            EXPECT_TRUE(test::sameBits(a, renderHarc(scene, mesh))) << options.dump() << " camera " << c;
            if (c == 1) {
                EXPECT_GE(stats.extra["eye_tet"].get<std::int64_t>(), 0) << "the eye is inside the mesh";
            }
        }
        Scene wider = scene;
        wider.image.width = 34;
        EXPECT_FALSE(moved->setCamera(wider)) << options.dump();
    }
}

TEST(Harc, TransferFunctionChangeBetweenFramesEqualsAFreshRenderer)
{
    const TetMesh mesh = boxMesh({{{0.0, 0.0, 0.0}, {1.0, 1.0, 1.0}, 3}}, {0.5, 0.3, 0.2}, 0.1);
    const TransferFunction other({{0.0, {1.0, 0.2, 0.2}, 4.0}, {0.5, {0.2, 1.0, 0.2}, 0.0}, {1.0, {0.2, 0.2, 1.0}, 8.0}});
    const Scene scene = makeScene(perspective({1.7, 1.3, 2.4}), rampTf(), 40);
    auto renderer = makeHarcRenderer(test::device(), scene, mesh, handTopology(mesh));
    FrameStats stats;
    renderer->render(stats);
    const std::uint64_t resident = renderer->residentBytes();
    renderer->setTransferFunction(other);
    const Image4f edited = renderer->render(stats);
    const Image4f fresh = renderHarc(makeScene(perspective({1.7, 1.3, 2.4}), other, 40), mesh);
    EXPECT_EQ(std::memcmp(edited.pixels().data(), fresh.pixels().data(), edited.pixelCount() * sizeof(glm::vec4)), 0);
    // 5 control points -> 3: the packed table shrinks by (8 - 4) + 8 * 2 floats; the mesh stays.
    EXPECT_EQ(resident - renderer->residentBytes(), (4 + 16) * sizeof(float));
}

TEST(Harc, FullTransferFunctionChangeRebuildsTheTableAndEqualsAFreshRenderer)
{
    const TetMesh mesh = boxMesh({{{0.0, 0.0, 0.0}, {1.0, 1.0, 1.0}, 3}}, {0.5, 0.3, 0.2}, 0.1);
    // A different s range than rampTf ([-0.5, 1.5] vs [0, 1]): the rebuilt table's range moves too.
    const TransferFunction other(
        {{-0.5, {1.0, 0.2, 0.2}, 4.0}, {0.5, {0.2, 1.0, 0.2}, 0.0}, {1.5, {0.2, 0.2, 1.0}, 8.0}});
    const json full{{"integration", "full"}, {"full_table", {24, 16}}};
    const Scene scene = makeScene(perspective({1.7, 1.3, 2.4}), rampTf(), 40, full);
    auto renderer = makeHarcRenderer(test::device(), scene, mesh, handTopology(mesh));
    FrameStats before;
    const Image4f first = renderer->render(before);
    const std::uint64_t resident = renderer->residentBytes();
    renderer->setTransferFunction(other);
    FrameStats stats;
    const Image4f edited = renderer->render(stats);
    const Image4f fresh = renderHarc(makeScene(perspective({1.7, 1.3, 2.4}), other, 40, full), mesh);
    EXPECT_EQ(std::memcmp(edited.pixels().data(), fresh.pixels().data(), edited.pixelCount() * sizeof(glm::vec4)), 0);
    EXPECT_NE(std::memcmp(edited.pixels().data(), first.pixels().data(), edited.pixelCount() * sizeof(glm::vec4)), 0);
    EXPECT_EQ(stats.extra["integration"], "full");
    EXPECT_EQ(stats.extra["full_table"], "24x24x16");
    EXPECT_EQ(stats.extra["full_table_bytes"].get<std::uint64_t>(), 24u * 24u * 16u * 16u);
    EXPECT_GT(stats.extra["full_table_build_ms"].get<double>(), 0.0);
    // The longest edge of a Kuhn tetrahedron of a cube of side 1/3 is the cube's diagonal.
    EXPECT_NEAR(stats.extra["full_table_l_max"].get<double>(), std::sqrt(3.0) / 3.0, 1e-12);
    EXPECT_EQ(stats.extra["full_table_s_range"][0].get<double>(), -0.5);
    // The table is rebuilt, not grown; 5 control points -> 3 shrink the packed table by 20 floats.
    EXPECT_EQ(resident - renderer->residentBytes(), (4 + 16) * sizeof(float));
    EXPECT_GE(resident, 24u * 24u * 16u * 16u + 80u * mesh.tets.size());
}

TEST(Harc, FullOnAGlobalLinearFieldApproachesTheExactIntegral)
{
    // One box: every segment's l is at most the cell diagonal, and the table's error shrinks with it.
    const std::vector<Box> boxes = {{{0.0, 0.0, 0.0}, {1.0, 1.0, 1.0}, 3}};
    const glm::dvec3 gradient(0.5, 0.3, 0.2);
    const TetMesh mesh = boxMesh(boxes, gradient, 0.1);
    const Camera camera = perspective({1.7, 1.3, 2.4});
    const Scene scene = makeScene(camera, rampTf(), 40);
    const Image4d expected = boxReference(boxes, gradient, 0.1, rampTf(), camera, scene.image);
    test::ImageError errors[2];
    const int sizes[2] = {16, 64};
    for (int n = 0; n < 2; ++n) {
        const json options{{"integration", "full"}, {"full_table", {sizes[n], 64}}};
        const Image4f image = renderHarc(makeScene(camera, rampTf(), 40, options), mesh);
        errors[n] = test::imageError(image, expected);
        const std::string what = "box, full " + std::to_string(sizes[n]) + "x" + std::to_string(sizes[n]) + "x64";
        printError(what.c_str(), image, expected);
    }
    // Measured 64x64x64: max 3.2e-3, mean 2.8e-4 (red); 16x16x64: max 2.8e-2, mean 4.1e-3. 256x256x64
    // gave max 5.9e-4, mean 3.4e-5 (not run here: its 4M-entry table takes seconds).
    for (int c = 0; c < 4; ++c) {
        EXPECT_LT(errors[1].maxAbs[c], 4e-3) << "channel " << c;
        EXPECT_LT(errors[1].meanAbs[c], 4e-4) << "channel " << c;
        EXPECT_LT(errors[1].maxAbs[c] * 4.0, errors[0].maxAbs[c]) << "channel " << c << ": 4x the s samples";
        EXPECT_LT(errors[1].meanAbs[c] * 4.0, errors[0].meanAbs[c]) << "channel " << c << ": 4x the s samples";
    }
}

TEST(Harc, IndependentOfSplittingTheTransferFunction)
{
    const TetMesh mesh = boxMesh({{{0.0, 0.0, 0.0}, {1.0, 1.0, 1.0}, 3}}, {0.5, 0.3, 0.2}, 0.1);
    const TransferFunction coarse = rampTf();
    // Every segment split into 8 collinear pieces: 33 control points, the same function.
    std::vector<ControlPoint> fine;
    const auto& pts = coarse.points();
    for (std::size_t i = 0; i + 1 < pts.size(); ++i)
        for (int k = 0; k < 8; ++k) {
            const double s = pts[i].s + (pts[i + 1].s - pts[i].s) * k / 8.0;
            const glm::dvec4 v = coarse(s);
            fine.push_back({s, glm::dvec3(v), v.w});
        }
    fine.push_back(pts.back());
    const Camera camera = perspective({1.7, 1.3, 2.4});
    const Image4f a = renderHarc(makeScene(camera, coarse, 48), mesh);
    const Image4f b = renderHarc(makeScene(camera, TransferFunction(fine), 48), mesh);
    Image4d bd(48, 48);
    for (std::size_t p = 0; p < b.pixelCount(); ++p)
        bd.pixels()[p] = glm::dvec4(b.pixels()[p]);
    printError("5 vs 33 collinear control points", a, bd);
    EXPECT_TRUE(test::imagesNear(a, bd, {.maxAbs = 1e-4, .meanAbs = 1e-5}));
}

TEST(Harc, StepBoundStopsRaysAndIsCounted)
{
    const TetMesh mesh = boxMesh({{{0.0, 0.0, 0.0}, {1.0, 1.0, 1.0}, 3}}, {0.5, 0.3, 0.2}, 0.1);
    FrameStats stats;
    renderHarc(makeScene(perspective({1.7, 1.3, 2.4}), rampTf(), 32, json{{"max_steps", 2}}), mesh, &stats);
    EXPECT_GT(stats.extra["rays_step_bound"].get<std::uint64_t>(), 100u);
    FrameStats full;
    renderHarc(makeScene(perspective({1.7, 1.3, 2.4}), rampTf(), 32), mesh, &full);
    EXPECT_EQ(full.extra["rays_step_bound"].get<std::uint64_t>(), 0u);
}

TEST(Harc, EarlyTerminationStaysWithinItsThreshold)
{
    const TetMesh mesh = boxMesh({{{0.0, 0.0, 0.0}, {1.0, 1.0, 1.0}, 4}}, {0.5, 0.3, 0.2}, 0.1);
    const TransferFunction dense({{0.0, {1.0, 0.5, 0.2}, 20.0}, {1.0, {0.2, 0.5, 1.0}, 20.0}});
    const Camera camera = perspective({1.7, 1.3, 2.4});
    FrameStats off, on;
    const Image4f a = renderHarc(makeScene(camera, dense, 32), mesh, &off);
    const Image4f b = renderHarc(makeScene(camera, dense, 32, json{{"early_termination", 0.99}}), mesh, &on);
    EXPECT_LT(on.extra["steps"].get<std::uint64_t>(), off.extra["steps"].get<std::uint64_t>());
    Image4d ad(32, 32);
    for (std::size_t p = 0; p < a.pixelCount(); ++p)
        ad.pixels()[p] = glm::dvec4(a.pixels()[p]);
    // What is left behind a stopped ray is at most its transmittance (<= 0.01) times the color range.
    EXPECT_TRUE(test::imagesNear(b, ad, {.maxAbs = 1e-2, .meanAbs = 5e-3}));
}

// Ray packets: harc_render_packet walks 8 pixels' rays as vector lanes, each through its own cells, entry list
// and pieces. The same bits as one pixel per work-item and the same steps, pieces and step-bound rays: a convex
// grid from outside, a perspective eye inside a non-convex mesh (its rays start in the eye's cell), a parallel
// view, two boxes with a gap (rays leave and re-enter), a transfer function of 33 control points (several
// pieces per cell, up and down), early termination, a step bound, full pre-integration and the average, and
// widths that leave lanes out of the image.
TEST(Harc, PacketsAreBitIdenticalToOnePixelPerWorkItem)
{
    const std::vector<Box> lShape = {{{0.0, 0.0, 0.0}, {2.0, 1.0, 1.0}, 4}, {{0.0, 1.0, 0.0}, {1.0, 2.0, 1.0}, 3}};
    TetMesh inside = boxMesh(lShape, {0.3, 0.35, -0.4}, 0.4);
    checkMesh(inside);
    const TetMesh grid = boxMesh({{{0.0, 0.0, 0.0}, {1.0, 1.0, 1.0}, 3}}, {0.6, 0.25, -0.4}, 0.35);
    const TetMesh gap = boxMesh({{{0.0, 0.0, 0.0}, {1.0, 1.0, 0.4}, 3}, {{0.0, 0.0, 0.7}, {1.0, 1.0, 1.1}, 3}}, {0.3, 0.5, 0.2}, 0.1);
    std::vector<ControlPoint> fine;  // 33 points, tau up and down
    for (int k = 0; k <= 32; ++k) {
        const double s = k / 32.0;
        fine.push_back({s, {s, 0.5 + 0.4 * std::sin(9.0 * s), 1.0 - s}, 2.0 + 1.5 * std::sin(13.0 * s)});
    }
    const Camera parallel = parallelView({3.5, -1.5, 2.5}, {1.0, 1.0, 0.5}, 1.4);
    struct Case {
        const char* name;
        const TetMesh* mesh;
        Camera camera;
        TransferFunction tf;
        json options;
    };
    const Case cases[] = {
        {"grid, outside", &grid, perspective({1.9, 1.4, 2.6}), rampTf(), json::object()},
        {"grid, 33 control points", &grid, perspective({1.9, 1.4, 2.6}), TransferFunction(fine), json::object()},
        {"eye inside the L", &inside, perspective({0.55, 0.45, 0.6}, {1.6, 1.3, 0.3}, 95.0), rampTf(), json::object()},
        {"L, parallel", &inside, parallel, TransferFunction(fine), json::object()},
        {"gap", &gap, perspective({0.9, 0.7, 3.2}, {0.5, 0.5, 0.5}, 40.0), rampTf(), json::object()},
        {"early termination", &grid, perspective({1.9, 1.4, 2.6}),
         TransferFunction({{0.0, {1.0, 0.5, 0.2}, 20.0}, {1.0, {0.2, 0.5, 1.0}, 20.0}}), json{{"early_termination", 0.9}}},
        {"step bound", &grid, perspective({1.9, 1.4, 2.6}), rampTf(), json{{"max_steps", 3}}},
        {"full pre-integration, eye inside", &inside, perspective({0.55, 0.45, 0.6}, {1.6, 1.3, 0.3}, 95.0), rampTf(),
         json{{"integration", "full"}, {"full_table", {16, 16}}}},
        {"average, gap", &gap, perspective({0.9, 0.7, 3.2}, {0.5, 0.5, 0.5}, 40.0), TransferFunction(fine),
         json{{"integration", "average"}}},
    };
    int compared = 0;
    for (const Case& c : cases)
        for (const int width : {61, 5}) {
            Scene scene = makeScene(c.camera, c.tf, width, c.options);
            scene.image.height = 37;
            const FrameStats stats = test::expectPacketsEqualPixels(
                scene, [&](const Scene& s, FrameStats& st) { return renderHarc(s, *c.mesh, &st); },
                {"steps", "pieces", "rays_step_bound"}, std::string(c.name) + ", width " + std::to_string(width));
            EXPECT_GT(stats.extra["steps"].get<std::uint64_t>(), 0u) << c.name;
            ++compared;
        }
    EXPECT_EQ(compared, 9 * 2);
}

}  // namespace
}  // namespace clvr

// ---- the paper's meshes against the exact tetrahedral reference (host/reference/tet_reference.h) -------------
#include "host/io/mesh_io.h"
#include "host/model/scene.h"
#include "host/reference/tet_reference.h"

namespace clvr {
namespace {

struct MeshCase {
    const char* name;
    nlohmann::json spec;
    TransferFunction tf;
};

// Entry lists from the raster stage (options.entry "raster") against the exact integral: the same
// tolerance on the mean, and the per-pixel one everywhere but at rays whose entry is a boundary face
// seen nearly edge-on, which the raster stage's subpixel snapping can miss (measured: 1 of 4096
// pixels on the torus seen through its hole, parallel; none on bluntfin, post and the L-block).
std::size_t pixelsOver(const Image4f& actual, const Image4d& expected, double limit)
{
    std::size_t n = 0;
    for (std::size_t p = 0; p < actual.pixelCount(); ++p) {
        const glm::dvec4 d = glm::abs(glm::dvec4(actual.pixels()[p]) - expected.pixels()[p]);
        n += std::max(std::max(d.r, d.g), std::max(d.b, d.a)) > limit ? 1 : 0;
    }
    return n;
}

void expectRasterEntryNear(const std::string& what, const Image4f& image, const Image4d& expected,
                           const FrameStats& stats)
{
    printError((what + ", raster entry").c_str(), image, expected);
    const std::size_t over = pixelsOver(image, expected, 2e-3);
    std::printf("%s, raster entry: %zu pixels over 2e-3, %d layers\n", what.c_str(), over,
                stats.extra["entry_layers"].get<int>());
    EXPECT_TRUE(test::imagesNear(image, expected, {.maxAbs = 1.0, .meanAbs = 2e-4})) << what;
    EXPECT_LE(over * 100, image.pixelCount()) << what;  // at most 1% of the pixels
    EXPECT_EQ(stats.extra["entry"].get<std::string>(), "raster");
    EXPECT_EQ(stats.extra["rays_layer_bound"].get<std::uint64_t>(), 0u);
}

Image4f renderWithEntry(Scene scene, const TetMesh& mesh, const TetTopology& topology, const char* entry,
                        FrameStats& stats)
{
    scene.options["entry"] = entry;
    auto renderer = makeHarcRenderer(test::device(), scene, mesh, topology);
    return renderer->render(stats);
}


void checkMeshAgainstReference(const MeshCase& c, bool parallel)
{
    TetMesh mesh = loadMesh(c.spec, "/");
    const Camera camera = meshCamera(mesh, parallel);
    Scene scene = makeScene(camera, c.tf, 64);
    const TetTopology topology = buildTopology(mesh);
    FrameStats stats;
    const Image4f image = renderWithEntry(scene, mesh, topology, "host", stats);
    const Image4d expected = tetReferenceIntegral(mesh, c.tf, camera, scene.image);
    const std::string what = std::string(c.name) + (parallel ? ", parallel" : ", perspective");
    printError(what.c_str(), image, expected);
    EXPECT_TRUE(test::imagesNear(image, expected, {.maxAbs = 2e-3, .meanAbs = 2e-4})) << what;
    EXPECT_EQ(stats.extra["rays_step_bound"].get<std::uint64_t>(), 0u);
    FrameStats rasterStats;
    const Image4f raster = renderWithEntry(scene, mesh, topology, "raster", rasterStats);
    expectRasterEntryNear(what, raster, expected, rasterStats);
}

MeshCase bluntfinCase()
{
    return {"bluntfin",
            {{"file", test::sharedData("bluntfin/bluntfinxyz.bin")},
             {"q_file", test::sharedData("bluntfin/bluntfinq.bin")},
             {"scalar", "density"}},
            test::bluntfinTransferFunction()};
}

TEST(HarcMeshes, BluntfinMatchesExactReference)
{
    const MeshCase c = bluntfinCase();
    checkMeshAgainstReference(c, false);
    checkMeshAgainstReference(c, true);
}

MeshCase postCase()
{
    const TetMesh probe = loadMesh(nlohmann::json{{"file", test::sharedData("post/post.vtk")}}, "/");
    return {"post", {{"file", test::sharedData("post/post.vtk")}}, test::postTransferFunction(probe)};
}

TEST(HarcMeshes, PostMatchesExactReference)
{
    const MeshCase c = postCase();
    checkMeshAgainstReference(c, false);
    checkMeshAgainstReference(c, true);
}

// Figure 8 of seeds/001 in numbers: one mesh, one camera, the exact reference once, then partial,
// full pre-integration with two table sizes and the plain average, each error against the reference.
struct ModeErrors {
    double maxAbs = 0.0, meanAbs = 0.0;  // the worst channel's
};

std::map<std::string, ModeErrors> integrationErrors(const MeshCase& c, bool parallel)
{
    const TetMesh mesh = loadMesh(c.spec, "/");
    const TetTopology topology = buildTopology(mesh);
    const Camera camera = meshCamera(mesh, parallel);
    const Image4d expected = tetReferenceIntegral(mesh, c.tf, camera, ImageSpec{64, 64, {0.1, 0.2, 0.3}});
    const std::pair<const char*, json> modes[] = {
        {"partial", json{{"integration", "partial"}}},
        {"full 64x64x64", json{{"integration", "full"}}},
        {"full 16x16x64", json{{"integration", "full"}, {"full_table", {16, 64}}}},
        {"average", json{{"integration", "average"}}}};
    std::map<std::string, ModeErrors> out;
    for (const auto& [name, options] : modes) {
        auto renderer = makeHarcRenderer(test::device(), makeScene(camera, c.tf, 64, options), mesh, topology);
        FrameStats stats;
        const Image4f image = renderer->render(stats);
        const test::ImageError e = test::imageError(image, expected);
        EXPECT_EQ(e.nanCount, 0u) << name;
        ModeErrors& m = out[name];
        for (int ch = 0; ch < 4; ++ch) {
            m.maxAbs = std::max(m.maxAbs, e.maxAbs[ch]);
            m.meanAbs = std::max(m.meanAbs, e.meanAbs[ch]);
        }
        std::printf("%s, %s, %s: max |error| %.3g, mean %.3g%s\n", c.name, parallel ? "parallel" : "perspective",
                    name, m.maxAbs, m.meanAbs,
                    stats.extra.contains("full_table_build_ms")
                        ? (", table " + stats.extra["full_table"].get<std::string>() + " built in " +
                           std::to_string(stats.extra["full_table_build_ms"].get<double>()) + " ms, l_max " +
                           std::to_string(stats.extra["full_table_l_max"].get<double>())).c_str()
                        : "");
    }
    return out;
}

// Full pre-integration (64³ and 16x16x64 tables) and the plain average against the exact reference, both
// cameras: full 64³ within the measured bounds; the finer table is closer; in max error partial beats
// full beats the average (Figure 8's order).
void expectFigure8Order(const MeshCase& c, double fullMax, double fullMean)
{
    for (const bool parallel : {false, true}) {
        auto e = integrationErrors(c, parallel);
        const std::string what = std::string(c.name) + (parallel ? ", parallel" : ", perspective");
        EXPECT_LT(e["full 64x64x64"].maxAbs, fullMax) << what;
        EXPECT_LT(e["full 64x64x64"].meanAbs, fullMean) << what;
        EXPECT_LT(e["full 64x64x64"].maxAbs, e["full 16x16x64"].maxAbs) << what;
        EXPECT_LT(e["full 64x64x64"].meanAbs, e["full 16x16x64"].meanAbs) << what;
        EXPECT_LT(e["partial"].maxAbs, e["full 64x64x64"].maxAbs) << what;
        EXPECT_LT(e["full 64x64x64"].maxAbs, e["average"].maxAbs) << what;
    }
}

TEST(HarcMeshes, FullBluntfinErrorsAsFigure8)
{
    // Measured (perspective / parallel), the worst channel: full 64x64x64 max 9.7e-3 / 1.02e-2, mean
    // 3.5e-4 / 3.8e-4; 16x16x64 max 2.9e-2 / 2.7e-2, mean 6.3e-3 / 6.9e-3; partial max 8.7e-6 / 6.8e-6;
    // average max 2.3e-2 / 1.6e-2 but mean 1.3e-4 / 9.6e-5 (lower than full's: most of bluntfin's
    // cells are small, where the average is good and full's s and l spacing is not). docs/harc.md.
    expectFigure8Order(bluntfinCase(), 1.2e-2, 4.5e-4);
}

TEST(HarcMeshes, FullPostErrors)
{
    // Measured (perspective / parallel), the worst channel: full 64x64x64 max 3.84e-4 / 3.87e-4, mean
    // 3.3e-5 / 3.4e-5; 16x16x64 max 5.0e-3 / 5.3e-3; partial max 1.9e-6 / 1.3e-6; average max 6.3e-3.
    expectFigure8Order(postCase(), 4.5e-4, 4e-5);
}

// The shipped non-convex scenes (data/scenes/torus.json, l-block.json): TetGen meshes made from the
// surfaces in data/surfaces at load time. Rendered with the scene's camera, then with a camera (and a
// parallel one) along which many rays leave the mesh and enter it again: the torus seen nearly edge-on
// (near tube, gap, far tube), the L along the diagonal across its notch (arm, notch, other arm).
void checkShippedScene(const char* name, const Camera& through)
{
    Scene scene = loadScene(test::repoData(std::string("scenes/") + name));
    scene.image.width = scene.image.height = 64;
    const TetMesh mesh = loadMesh(*scene.mesh);
    const TetTopology topology = buildTopology(mesh);
    Camera parallel = through;
    parallel.parallel = true;
    parallel.parallelScale = 0.5 * glm::length(mesh.boundsMax() - mesh.boundsMin());
    const std::pair<const char*, Camera> cameras[] = {{"scene camera", *scene.camera},
                                                      {"through the gap", through},
                                                      {"through the gap, parallel", parallel}};
    for (const auto& [label, camera] : cameras) {
        scene.camera = camera;
        FrameStats stats;
        const Image4f image = renderWithEntry(scene, mesh, topology, "host", stats);
        const Image4d expected = tetReferenceIntegral(mesh, scene.transferFunction, camera, scene.image);
        const std::string what = std::string(name) + ", " + label;
        printError(what.c_str(), image, expected);
        EXPECT_TRUE(test::imagesNear(image, expected, {.maxAbs = 2e-3, .meanAbs = 2e-4})) << what;
        EXPECT_EQ(stats.extra["rays_step_bound"].get<std::uint64_t>(), 0u);
        FrameStats rasterStats;
        const Image4f raster = renderWithEntry(scene, mesh, topology, "raster", rasterStats);
        expectRasterEntryNear(what, raster, expected, rasterStats);
        if (label != cameras[0].first) {
            EXPECT_GE(rasterStats.extra["entry_layers"].get<int>(), 2) << what;  // peeled behind the gap
        }
        if (label != cameras[0].first) {
            // Non-convex for real: at least 20% more boundary front-face crossings than rays that hit.
            std::uint64_t hit = 0;
            for (std::size_t p = 0; p < image.pixelCount(); ++p)
                hit += expected.pixels()[p].a > 0.0 ? 1 : 0;
            const auto crossings = stats.extra["entry_crossings"].get<std::uint64_t>();
            std::printf("%s: %llu crossings for %llu rays that hit\n", what.c_str(),
                        static_cast<unsigned long long>(crossings), static_cast<unsigned long long>(hit));
            EXPECT_GT(crossings * 10, hit * 12) << what;
        }
    }
}

TEST(HarcMeshes, TetgenTorusMatchesExactReference)
{
    checkShippedScene("torus.json", perspective({0.3, -2.6, 0.35}, {0.0, 0.0, 0.0}, 40.0));
}

TEST(HarcMeshes, TetgenLBlockMatchesExactReference)
{
    checkShippedScene("l-block.json", perspective({-2.2, 2.6, -0.2}, {0.25, 0.15, -0.5}, 40.0));
}

}  // namespace
}  // namespace clvr
