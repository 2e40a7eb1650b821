// tests/harc_entry_test.cpp — HARC's entry pass through the raster stage (host/render/tet/harc_entry.h)
// against the exact host crossing lists (buildHarcEntryLists: double ray-triangle intersections):
// the same faces in the same order at almost every pixel and λ within float rounding on the non-convex
// TetGen torus (two layers and more), perspective and parallel; nothing when the mesh is out of view.
#include "host/render/tet/harc_entry.h"

#include "host/runtime/errors.h"
#include "host/io/mesh_io.h"
#include "host/model/scene.h"
#include "tests/support/test_util.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <cstring>

namespace clvr {
namespace {

struct Agreement {
    std::size_t pixels = 0, sameCount = 0, sameFaces = 0;
    double maxLambdaError = 0.0;  // relative, where the faces agree
    std::size_t lambdaOver1e5 = 0;  // entries (where the faces agree) with a relative difference above 1e-5
};

Agreement compare(const HarcEntryLists& raster, const HarcEntryLists& exact)
{
    Agreement a;
    a.pixels = exact.offsets.size() - 1;
    for (std::size_t p = 0; p < a.pixels; ++p) {
        const cl_uint r0 = raster.offsets[p], r1 = raster.offsets[p + 1];
        const cl_uint e0 = exact.offsets[p], e1 = exact.offsets[p + 1];
        // The exact lists include edges with a margin: a ray through a shared edge lists both faces at
        // the same λ (the walk skips the second); the raster's fill rule keeps one. Drop such repeats.
        std::vector<cl_int2> e;
        for (cl_uint k = e0; k < e1; ++k) {
            float l, prev;
            std::memcpy(&l, &exact.entries[k].s[0], sizeof l);
            if (!e.empty()) {
                std::memcpy(&prev, &e.back().s[0], sizeof prev);
                if (l <= prev + 1e-5f * (1.0f + std::abs(prev)))
                    continue;
            }
            e.push_back(exact.entries[k]);
        }
        if (r1 - r0 != e.size())
            continue;
        ++a.sameCount;
        bool same = true;
        for (cl_uint k = 0; k < e.size(); ++k)
            same = same && raster.entries[r0 + k].s[1] == e[k].s[1];
        if (!same)
            continue;
        ++a.sameFaces;
        for (cl_uint k = 0; k < e.size(); ++k) {
            float lr, le;
            std::memcpy(&lr, &raster.entries[r0 + k].s[0], sizeof lr);
            std::memcpy(&le, &e[k].s[0], sizeof le);
            const double d = std::abs(static_cast<double>(lr) - le) / (1.0 + std::abs(le));
            a.maxLambdaError = std::max(a.maxLambdaError, d);
            a.lambdaOver1e5 += d > 1e-5 ? 1 : 0;
        }
    }
    return a;
}

void expectAgreement(const char* what, const TetMesh& mesh, const Camera& camera, int size, int minLayers)
{
    const TetTopology topology = buildTopology(mesh);
    const glm::dvec3 shift = 0.5 * (mesh.boundsMin() + mesh.boundsMax());
    const cl::Buffer tets = test::device().upload("tets", packHarcTets(mesh, topology, shift));
    HarcRasterEntries pass(test::device(), mesh, topology, shift, tets, size, size, 64);
    HarcRasterEntryStats stats;
    const HarcEntryLists raster = pass.build(camera, stats);
    const HarcEntryLists exact = buildHarcEntryLists(mesh, topology, camera, size, size);
    const Agreement a = compare(raster, exact);
    std::printf("%s: %d layers, %zu/%zu pixels with the same count, %zu with the same faces, max relative "
                "lambda difference %.2g (%zu above 1e-5); raster %zu entries, exact %zu\n",
                what, stats.layers, a.sameCount, a.pixels, a.sameFaces, a.maxLambdaError, a.lambdaOver1e5, raster.entries.size(),
                exact.entries.size());
    EXPECT_GE(stats.layers, minLayers) << what;
    EXPECT_FALSE(stats.layerBound) << what;
    // Pixel centers on a silhouette or shared edge may fall either way: at most 1% of pixels differ.
    EXPECT_GE(a.sameCount * 100, a.pixels * 99) << what;
    EXPECT_GE(a.sameFaces * 100, a.sameCount * 99) << what;
    EXPECT_LT(a.maxLambdaError, 1e-5) << what;  // λ from the face plane in float: measured 2.3e-6
    EXPECT_GT(raster.entries.size(), static_cast<std::size_t>(size) * size / 10) << what;  // the mesh is in view
}

Camera lookAt(glm::dvec3 position, glm::dvec3 focal, glm::dvec3 up, bool parallel, double scale)
{
    Camera c;
    c.position = position;
    c.focalPoint = focal;
    c.viewUp = up;
    c.viewAngle = 40.0;
    c.parallel = parallel;
    c.parallelScale = scale;
    return c;
}

TEST(HarcEntry, RasterLayersMatchExactCrossingsOnTheTorus)
{
    const TetMesh mesh =
        loadMesh({{"surface", "torus.off"}, {"max_volume", 0.002}, {"scalar", "blobs"}}, test::repoData("surfaces"));
    for (const bool parallel : {false, true}) {
        // Nearly edge-on: rays cross the near tube, the hole, the far tube (two layers and more).
        const Camera camera = lookAt({0.3, -2.6, 0.35}, {0.0, 0.0, 0.0}, {0.0, 0.0, 1.0}, parallel, 1.0);
        expectAgreement(parallel ? "torus, parallel" : "torus, perspective", mesh, camera, 96, 2);
    }
}

TEST(HarcEntry, NoLayerWhenTheMeshIsOutOfView)
{
    const TetMesh mesh =
        loadMesh({{"surface", "l-block.poly"}, {"scalar", "sphere"}}, test::repoData("surfaces"));
    const TetTopology topology = buildTopology(mesh);
    const cl::Buffer tets = test::device().upload("tets", packHarcTets(mesh, topology, glm::dvec3(0.0)));
    HarcRasterEntries pass(test::device(), mesh, topology, glm::dvec3(0.0), tets, 32, 32, 8);
    HarcRasterEntryStats stats;
    // Looking away from the block.
    const HarcEntryLists lists = pass.build(lookAt({0.0, 0.0, 5.0}, {0.0, 0.0, 10.0}, {0.0, 1.0, 0.0}, false, 1.0), stats);
    EXPECT_EQ(lists.entries.size(), 0u);
    EXPECT_EQ(lists.offsets.back(), 0u);
    EXPECT_EQ(stats.layers, 0);
    EXPECT_THROW(HarcRasterEntries bad(test::device(), mesh, topology, glm::dvec3(0.0), tets, 32, 32, 0), InputError);
}

}  // namespace
}  // namespace clvr
