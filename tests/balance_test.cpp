// tests/balance_test.cpp — sort-last cuts by work (host/cluster/balance.h): the estimate of a view's work
// against rays counted through pixel centers and sums over every cell, cuts that split a given cost evenly,
// and re-cuts from measured times that converge where the estimate is wrong (times made by a known "true"
// cost, so the test knows what balanced means).
#include "host/cluster/balance.h"

#include "host/runtime/errors.h"
#include "tests/support/mesh_fixtures.h"
#include "tests/support/test_util.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>

namespace clvr {
namespace {

// Whether the ray o + t d (t >= 0 unless `anyT`) passes through the tetrahedron's interior: the stretch of
// t inside all four faces' half-spaces is not empty (the faces' planes in double).
bool rayCrossesTet(const glm::dvec3 (&v)[4], const glm::dvec3& o, const glm::dvec3& d, bool anyT)
{
    double t0 = anyT ? -INFINITY : 0.0, t1 = INFINITY;
    for (int f = 0; f < 4; ++f) {
        const glm::dvec3 a = v[(f + 1) % 4], b = v[(f + 2) % 4], c = v[(f + 3) % 4], opposite = v[f];
        glm::dvec3 n = glm::cross(b - a, c - a);
        if (glm::dot(n, opposite - a) < 0.0)
            n = -n;  // inward
        const double s = glm::dot(n, o - a), r = glm::dot(n, d);  // inside: s + t r >= 0
        if (r == 0.0) {
            if (s < 0.0)
                return false;
        } else if (r > 0.0) {
            t0 = std::max(t0, -s / r);
        } else {
            t1 = std::min(t1, -s / r);
        }
    }
    return t0 < t1;
}

TEST(ViewCost, TetWorkIsThePixelCentersWhoseRaysCrossTheTetrahedron)
{
    const int w = 160, h = 120;
    const glm::dvec3 v[4] = {{-0.7, -0.5, -0.4}, {0.8, -0.3, 0.1}, {0.0, 0.7, -0.2}, {0.1, 0.0, 0.9}};
    Camera near = test::obliquePerspectiveCamera(40.0);
    near.position = {0.9, 1.1, 2.2};
    for (const Camera& camera : {test::obliquePerspectiveCamera(40.0), near, test::obliqueParallelCamera(1.2)}) {
        const ViewCost view(camera, w, h);
        int count = 0;
        for (int y = 0; y < h; ++y)
            for (int x = 0; x < w; ++x) {
                const Ray ray = camera.ray(x, y, w, h);
                count += rayCrossesTet(v, ray.origin, ray.direction, camera.parallel);
            }
        const double work = view.tetWork(v[0], v[1], v[2], v[3]);
        std::printf("%s: %d pixel centers, tetWork %.1f\n", camera.parallel ? "parallel" : "perspective", count, work);
        ASSERT_GT(count, 1000) << "the tetrahedron must cover many pixels for the comparison to mean something";
        // The projection's area against a count of pixel centers: they differ by about its outline.
        EXPECT_NEAR(work, count, 0.02 * count);
    }
    // Behind the eye or out of the image: the floor only.
    const ViewCost view(test::obliquePerspectiveCamera(40.0), w, h);
    const glm::dvec3 behind(0.0, 0.0, 10.0);
    EXPECT_LT(view.tetWork(v[0] + behind, v[1] + behind, v[2] + behind, v[3] + behind), 0.01);
    const glm::dvec3 aside(20.0, 0.0, 0.0);
    EXPECT_LT(view.tetWork(v[0] + aside, v[1] + aside, v[2] + aside, v[3] + aside), 0.01);
}

TEST(ViewCost, DensityIsPixelsPerAreaAtTheDepth)
{
    Camera camera;
    camera.position = {0.0, 0.0, 5.0};
    camera.focalPoint = {0.0, 0.0, 0.0};
    camera.viewAngle = 30.0;
    const ViewCost view(camera, 200, 100);
    const double perUnit1 = 50.0 / std::tan(glm::radians(15.0));  // half the height's pixels at depth 1
    EXPECT_NEAR(view.density({0.0, 0.0, 0.0}), std::pow(perUnit1 / 5.0, 2), 1e-9 * std::pow(perUnit1 / 5.0, 2));
    EXPECT_NEAR(view.density({0.1, 0.0, 2.5}) / view.density({0.1, 0.0, 0.0}), 4.0, 1e-9);  // half the depth
    EXPECT_LT(view.density({5.0, 0.0, 0.0}), 0.01 * view.density({0.0, 0.0, 0.0}));         // out of view
    EXPECT_LT(view.density({0.0, 0.0, 6.0}), 0.01 * view.density({0.0, 0.0, 0.0}));         // behind the eye
    camera.parallel = true;
    camera.parallelScale = 2.0;
    const ViewCost flat(camera, 200, 100);
    EXPECT_DOUBLE_EQ(flat.density({0.3, 0.2, 3.0}), flat.density({-1.0, 0.5, -4.0}));
    EXPECT_DOUBLE_EQ(flat.density({0.0, 0.0, 0.0}), 25.0 * 25.0);  // 50 pixels over 2 units
}

TEST(Balance, GridPartCostsSumTheDensityOverEveryCell)
{
    // Parts of at most 16 cells per axis: the samples are the cells' centers, so the sum is exact.
    const glm::ivec3 dims(17, 13, 21);
    const glm::dvec3 origin(-1.0, -0.5, -1.2), spacing(0.08, 0.07, 0.09);
    const ViewCost view(test::obliquePerspectiveCamera(35.0), 64, 48);
    const CostDensity density = [&](const glm::dvec3& p) { return view.density(p); };
    const GridPartition g = partitionGrid(dims, origin, spacing, 4, density);
    const std::vector<double> costs = gridPartCosts(g, origin, spacing, density);
    const double cellVolume = spacing.x * spacing.y * spacing.z;
    for (std::size_t p = 0; p < 4; ++p) {
        ASSERT_TRUE(glm::all(glm::lessThanEqual(g.hi[p] - g.lo[p], glm::ivec3(16))));
        double sum = 0.0;
        for (int z = g.lo[p].z; z < g.hi[p].z; ++z)
            for (int y = g.lo[p].y; y < g.hi[p].y; ++y)
                for (int x = g.lo[p].x; x < g.hi[p].x; ++x)
                    sum += density(origin + (glm::dvec3(x, y, z) + 0.5) * spacing) * cellVolume;
        EXPECT_NEAR(costs[p], sum, 1e-9 * sum) << "part " << p;
    }
}

// The cost of each part: the sum of `cost` over the tetrahedra whose centroid `m` places in it.
std::vector<double> meshPartCosts(const TetMesh& mesh, const MeshPartition& m, const std::vector<double>& cost)
{
    const std::vector<glm::dvec3> centroids = tetCentroids(mesh);
    std::vector<double> out(m.lo.size(), 0.0);
    for (std::size_t t = 0; t < centroids.size(); ++t)
        out[static_cast<std::size_t>(m.tree.partAt(centroids[t]))] += cost[t];
    return out;
}

TEST(Balance, MeshCutsSplitTheGivenCostsEvenly)
{
    // The grid's points moved by up to a tenth of a cell, so that no two centroids share a coordinate: a
    // cut can then be exact to one tetrahedron (on the plain grid a layer of tetrahedra shares one).
    TetMesh mesh = test::boxMesh({{{-1.0, -1.0, -1.0}, {1.0, 1.0, 1.0}, 16}}, {1.0, 0.0, 0.0}, 0.0);
    test::Rng rng(37);
    for (glm::dvec3& p : mesh.points)
        p += glm::dvec3(rng.uniform(-1.0, 1.0), rng.uniform(-1.0, 1.0), rng.uniform(-1.0, 1.0)) * (0.1 * 2.0 / 16);
    const std::vector<glm::dvec3> centroids = tetCentroids(mesh);
    std::vector<double> cost;  // rising steeply along x, and a hot corner
    for (const glm::dvec3& c : centroids)
        cost.push_back(std::exp(2.0 * c.x) * (c.y > 0.5 && c.z > 0.5 ? 10.0 : 1.0));
    const double most = *std::max_element(cost.begin(), cost.end());
    for (int n : {2, 3, 4, 7}) {
        const MeshPartition m = partitionMesh(mesh, n, cost);
        const std::vector<double> parts = meshPartCosts(mesh, m, cost);
        double total = 0.0;
        for (double c : parts)
            total += c;
        // Each cut is exact to one tetrahedron (the largest costs about 1/800 of a part here).
        std::printf("%d parts: slowest/mean %.4f\n", n, imbalance(parts));
        EXPECT_LE(imbalance(parts), 1.0 + 2 * n * most / total) << n << " parts";
        EXPECT_LE(imbalance(parts), 1.02) << n << " parts";
        EXPECT_GT(most, 0.0);
    }
    // Equal costs cut as by count: the same boxes as no costs.
    const MeshPartition byCount = partitionMesh(mesh, 5), byOnes = partitionMesh(mesh, 5, std::vector<double>(cost.size(), 1.0));
    for (std::size_t p = 0; p < 5; ++p) {
        EXPECT_EQ(byCount.lo[p], byOnes.lo[p]);
        EXPECT_EQ(byCount.hi[p], byOnes.hi[p]);
    }
    EXPECT_THROW(partitionMesh(mesh, 2, std::vector<double>(3, 1.0)), InternalError);
    EXPECT_THROW(partitionMesh(mesh, 2, std::vector<double>(cost.size(), -1.0)), InternalError);
}

TEST(Balance, TheFirstMeshCutBalancesRayWorkWhereCountsDoNot)
{
    // Close to one corner: the near tetrahedra cover most of the image. The true work of a part is the
    // rays through its tetrahedra, counted here by the estimate itself (checked against rays above).
    const TetMesh mesh = test::boxMesh({{{-1.0, -1.0, -1.0}, {1.0, 1.0, 1.0}, 12}}, {1.0, 0.0, 0.0}, 0.0);
    Camera camera = test::obliquePerspectiveCamera(60.0);
    camera.position = {1.3, 1.5, 1.9};
    const ViewCost view(camera, 128, 128);
    const std::vector<double> rays = view.tetWork(mesh);
    const double byCount = imbalance(meshPartCosts(mesh, partitionMesh(mesh, 4), rays));
    const double byWork = imbalance(meshPartCosts(mesh, balanceMesh(mesh, 4, view), rays));
    std::printf("4 parts, slowest/mean of ray work: by count %.2f, by work %.2f\n", byCount, byWork);
    EXPECT_GT(byCount, 1.3);
    EXPECT_LE(byWork, 1.08);
}

// A known "true" cost the estimate does not see: six times the estimate where x > 0.3 (say, opaque data
// there), as a renderer's measured times would show it.
double hiddenFactor(const glm::dvec3& p)
{
    return p.x > 0.3 ? 6.0 : 1.0;
}

TEST(Balance, GridReCutsFromMeasuredTimesConverge)
{
    const glm::ivec3 dims(65, 57, 61);
    const glm::dvec3 origin(-1.0), spacing(2.0 / 64, 2.0 / 56, 2.0 / 60);
    const ViewCost view(test::obliquePerspectiveCamera(35.0), 96, 96);
    const CostDensity truth = [&](const glm::dvec3& p) { return view.density(p) * hiddenFactor(p); };
    GridPartition cut = balanceGrid(dims, origin, spacing, 4, view);
    std::vector<double> ms = gridPartCosts(cut, origin, spacing, truth);
    const double first = imbalance(ms);
    std::printf("grid, 4 parts, slowest/mean: estimate only %.3f", first);
    EXPECT_GT(first, 1.3) << "the hidden factor must unbalance the estimate's cut for the test to mean something";
    double last = first;
    for (int frame = 1; frame <= 3; ++frame) {
        const MeasuredFrame measured{view, ms};
        // What the orbit's next frame would predict for the current cut from the measured rates: the same view,
        // so the measured imbalance itself.
        EXPECT_NEAR(predictedImbalance(gridPartCosts(cut, origin, spacing, [&](const glm::dvec3& p) {
                                           return view.density(p);
                                       }),
                                       gridPartCosts(cut, origin, spacing,
                                                     [&](const glm::dvec3& p) { return view.density(p); }),
                                       ms),
                    imbalance(ms), 1e-12);
        cut = balanceGrid(dims, origin, spacing, 4, view, &cut, &measured);
        ms = gridPartCosts(cut, origin, spacing, truth);
        last = imbalance(ms);
        std::printf(", re-cut %d: %.3f", frame, last);
    }
    std::printf("\n");
    EXPECT_LE(last, 1.1);
}

TEST(Balance, MeshReCutsFromMeasuredTimesConverge)
{
    const TetMesh mesh = test::boxMesh({{{-1.0, -1.0, -1.0}, {1.0, 1.0, 1.0}, 14}}, {1.0, 0.0, 0.0}, 0.0);
    const std::vector<glm::dvec3> centroids = tetCentroids(mesh);
    const ViewCost view(test::obliqueParallelCamera(1.8), 96, 96);
    std::vector<double> truth = view.tetWork(mesh);
    for (std::size_t t = 0; t < truth.size(); ++t)
        truth[t] *= hiddenFactor(centroids[t]);
    MeshPartition cut = balanceMesh(mesh, 4, view);
    std::vector<double> ms = meshPartCosts(mesh, cut, truth);
    const double first = imbalance(ms);
    std::printf("mesh, 4 parts, slowest/mean: estimate only %.3f", first);
    EXPECT_GT(first, 1.3);
    double last = first;
    for (int frame = 1; frame <= 3; ++frame) {
        const MeasuredFrame measured{view, ms};
        cut = balanceMesh(mesh, 4, view, &cut, &measured);
        ms = meshPartCosts(mesh, cut, truth);
        last = imbalance(ms);
        std::printf(", re-cut %d: %.3f", frame, last);
    }
    std::printf("\n");
    EXPECT_LE(last, 1.1);
}

TEST(Balance, RatesAndPredictionsFollowTheMeasuredTimes)
{
    EXPECT_DOUBLE_EQ(imbalance({10.0, 10.0, 10.0}), 1.0);
    EXPECT_DOUBLE_EQ(imbalance({10.0, 20.0, 30.0}), 1.5);
    EXPECT_DOUBLE_EQ(imbalance({0.0, 0.0}), 1.0);
    // Part 1 took twice its estimate's share; a part with no estimated work gets the clamp.
    const std::vector<double> rates = partRates({1.0, 1.0, 0.0}, {1.0, 2.0, 0.5});
    const double whole = 3.5 / 2.0;
    EXPECT_DOUBLE_EQ(rates[0], 1.0);
    EXPECT_DOUBLE_EQ(rates[1], 2.0);
    EXPECT_DOUBLE_EQ(rates[2], 8.0 * whole);
    EXPECT_DOUBLE_EQ(partRates({1.0, 1.0}, {0.0, 0.0})[0], 1.0);  // nothing measured
    // The next view doubles part 0's work: measured 10 and 10 become 20 and 10.
    EXPECT_DOUBLE_EQ(predictedImbalance({1.0, 1.0}, {2.0, 1.0}, {10.0, 10.0}), 20.0 * 2.0 / 30.0);
    EXPECT_THROW(partRates({1.0}, {1.0, 2.0}), InternalError);
}

}  // namespace
}  // namespace clvr
