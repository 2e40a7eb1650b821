// tests/partition_test.cpp — sort-last on one process (host/cluster/partition.h): the k-d tree's
// visibility order against rays cast through the boxes, grid and mesh parts that cover the data, and the
// parts' images, rendered on their own and composited "over" in that order, against the one-part image
// (slice3d fused, harc) for 1..8 parts, perspective, parallel and an eye inside the bounds.
#include "host/cluster/partition.h"

#include "host/io/generators.h"
#include "host/io/volume_io.h"
#include "host/model/data_spec.h"
#include "host/render/renderer.h"
#include "host/runtime/errors.h"
#include "tests/support/mesh_fixtures.h"
#include "tests/support/test_util.h"

#include <nlohmann/json.hpp>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <functional>
#include <string>

namespace clvr {
namespace {

// The parts a ray e + t d (t >= 0 for perspective, all t for parallel) passes through, in the order
// it enters them (slab tests in double).
std::vector<int> partsAlongRay(const std::vector<glm::dvec3>& lo, const std::vector<glm::dvec3>& hi,
                               const glm::dvec3& e, const glm::dvec3& d, bool fromEye)
{
    std::vector<std::pair<double, int>> hits;
    for (std::size_t p = 0; p < lo.size(); ++p) {
        double t0 = fromEye ? 0.0 : -INFINITY, t1 = INFINITY;
        for (int a = 0; a < 3; ++a) {
            const double u = (lo[p][a] - e[a]) / d[a], v = (hi[p][a] - e[a]) / d[a];
            t0 = std::max(t0, std::min(u, v));
            t1 = std::min(t1, std::max(u, v));
        }
        if (t1 - t0 > 1e-9)  // a real stretch inside, not a touch of an edge
            hits.emplace_back(t0, static_cast<int>(p));
    }
    std::sort(hits.begin(), hits.end());
    std::vector<int> out;
    for (const auto& h : hits)
        out.push_back(h.second);
    return out;
}

// Every ray through the camera's image visits the parts in an order consistent with frontToBack.
void expectOrderHoldsAlongRays(const KdTree& tree, const std::vector<glm::dvec3>& lo,
                               const std::vector<glm::dvec3>& hi, const Camera& camera)
{
    const std::vector<int> order = tree.frontToBack(camera);
    ASSERT_EQ(order.size(), lo.size());
    std::vector<int> rank(order.size());
    for (std::size_t i = 0; i < order.size(); ++i)
        rank[static_cast<std::size_t>(order[i])] = static_cast<int>(i);
    int checked = 0;
    for (int y = 0; y < 24; ++y)
        for (int x = 0; x < 24; ++x) {
            const Ray ray = camera.ray(x, y, 24, 24);
            const std::vector<int> along = partsAlongRay(lo, hi, ray.origin, ray.direction, !camera.parallel);
            for (std::size_t i = 1; i < along.size(); ++i, ++checked)
                ASSERT_LT(rank[static_cast<std::size_t>(along[i - 1])], rank[static_cast<std::size_t>(along[i])])
                    << "pixel " << x << "," << y << ": part " << along[i - 1] << " is in front of part " << along[i];
        }
    EXPECT_GT(checked, 0) << "no ray crossed two parts: the test checks nothing";
}

std::vector<Camera> sortLastCameras()
{
    Camera inside = test::obliquePerspectiveCamera(70.0);
    inside.position = {0.15, -0.1, 0.3};  // inside [-1, 1]^3
    inside.focalPoint = {-0.6, 0.4, -0.9};
    return {test::obliquePerspectiveCamera(40.0), test::obliqueParallelCamera(1.8), inside};
}

TEST(Partition, KdOrderIsTheVisibilityOrderOfTheBoxesForEveryEye)
{
    const glm::ivec3 dims(33, 29, 41);
    const glm::dvec3 origin(-1.0), spacing = 2.0 / glm::dvec3(dims - 1);
    for (int n = 2; n <= 8; ++n) {
        const GridPartition grid = partitionGrid(dims, origin, spacing, n);
        std::vector<glm::dvec3> lo, hi;
        for (int p = 0; p < n; ++p) {
            lo.push_back(origin + glm::dvec3(grid.lo[static_cast<std::size_t>(p)]) * spacing);
            hi.push_back(origin + glm::dvec3(grid.hi[static_cast<std::size_t>(p)]) * spacing);
        }
        for (const Camera& camera : sortLastCameras()) {
            SCOPED_TRACE("n = " + std::to_string(n));
            expectOrderHoldsAlongRays(grid.tree, lo, hi, camera);
        }
    }
}

TEST(Partition, GridPartsShareOneLayerAndCoverEveryCellOnce)
{
    const glm::ivec3 dims(17, 9, 12);
    for (int n = 1; n <= 8; ++n) {
        const GridPartition g = partitionGrid(dims, glm::dvec3(0.0), glm::dvec3(1.0), n);
        std::vector<int> cover(static_cast<std::size_t>((dims.x - 1) * (dims.y - 1) * (dims.z - 1)), 0);
        std::size_t smallest = SIZE_MAX, largest = 0;
        for (int p = 0; p < n; ++p) {
            const glm::ivec3 lo = g.lo[static_cast<std::size_t>(p)], hi = g.hi[static_cast<std::size_t>(p)];
            ASSERT_TRUE(glm::all(glm::lessThan(lo, hi))) << "part " << p << " has no cell";
            const std::size_t cells = static_cast<std::size_t>((hi - lo).x) * (hi - lo).y * (hi - lo).z;
            smallest = std::min(smallest, cells);
            largest = std::max(largest, cells);
            for (int k = lo.z; k < hi.z; ++k)
                for (int j = lo.y; j < hi.y; ++j)
                    for (int i = lo.x; i < hi.x; ++i)
                        ++cover[static_cast<std::size_t>((k * (dims.y - 1) + j) * (dims.x - 1) + i)];
        }
        EXPECT_TRUE(std::all_of(cover.begin(), cover.end(), [](int c) { return c == 1; })) << n << " parts";
        EXPECT_LE(static_cast<double>(largest), 2.5 * static_cast<double>(smallest)) << n << " parts: unbalanced";
    }
    EXPECT_THROW(partitionGrid(glm::ivec3(3, 2, 2), glm::dvec3(0.0), glm::dvec3(1.0), 3), InputError);
}

TEST(Partition, GridPartHoldsItsPointsAndKnowsWhereItSits)
{
    Volume v = generateVolume("marschner-lobb", glm::ivec3(9, 7, 8));
    const GridPartition g = partitionGrid(v.dims, v.origin, v.spacing, 4);
    for (int p = 0; p < 4; ++p) {
        const Volume part = cutGridPart(v, g, p);
        ASSERT_TRUE(part.part.has_value());
        EXPECT_EQ(part.part->offset, g.lo[static_cast<std::size_t>(p)]);
        EXPECT_EQ(part.part->fullDims, v.dims);
        const glm::ivec3 o = part.part->offset;
        for (int k = 0; k < part.dims.z; ++k)
            for (int j = 0; j < part.dims.y; ++j)
                for (int i = 0; i < part.dims.x; ++i)
                    ASSERT_EQ(part.at(i, j, k), v.at(i + o.x, j + o.y, k + o.z));
        EXPECT_NO_THROW(part.validate());
    }
}

// The largest channel difference of two images of the same size; infinite where either holds a NaN.
double maxChannelDifference(const Image4f& a, const Image4f& b)
{
    double worst = 0.0;
    for (std::size_t i = 0; i < a.pixelCount(); ++i)
        for (int c = 0; c < 4; ++c) {
            const double d = std::abs(double(a.pixels()[i][c]) - double(b.pixels()[i][c]));
            worst = std::isnan(d) ? INFINITY : std::max(worst, d);
        }
    return worst;
}

// Renders `scene` whole and as n parts (each part on its own, background 0, composited over in the
// tree's order, then the background added), and returns the largest channel difference.
double sortLastDifference(const Scene& scene, const std::function<Image4f(const Scene&, int, int)>& renderPart,
                          const KdTree& tree, int n)
{
    const Image4f whole = renderPart(scene, -1, n);
    Scene partScene = scene;
    partScene.image.background = glm::dvec3(0.0);
    std::vector<Image4f> images;
    for (int p = 0; p < n; ++p)
        images.push_back(renderPart(partScene, p, n));
    std::vector<const Image4f*> ordered;
    for (int p : tree.frontToBack(*scene.camera))
        ordered.push_back(&images[static_cast<std::size_t>(p)]);
    Image4f composite = compositeOver(ordered);
    addBackground(composite, scene.image.background);
    return maxChannelDifference(composite, whole);
}

// Float tolerance of the sort-last composite against the whole image: the same samples (slice3d) or the
// same segments cut at the boxes (harc), blended in another association. 8-bit: far below 1/255.
constexpr double kSortLastFloatTolerance = 2e-5;

// What a rank reads by itself (loadVolumeRegion of its gridPartRegion, placed by gridPartPlacement) is what
// cutGridPart cuts from the whole: values, geometry and placement, for every part of 1..8, with and without
// the ghost layer; for a raw file of every sample type and a Fortran-order .npy.
TEST(Partition, PartReadByItselfEqualsPartCutFromTheWhole)
{
    test::TempDir dir;
    const glm::ivec3 dims(13, 9, 11);
    test::Rng rng(7);
    std::string raw16, rawF;
    for (int i = 0; i < dims.x * dims.y * dims.z; ++i) {
        const auto v = static_cast<std::uint16_t>(rng.integer(0, 65535));
        raw16.append(reinterpret_cast<const char*>(&v), 2);
        const float f = static_cast<float>(rng.uniform(-1.0, 1.0));
        rawF.append(reinterpret_cast<const char*>(&f), 4);
    }
    test::writeFile(dir / "v16.raw", raw16);
    test::writeFile(dir / "vf.raw", rawF);
    std::string npyHeader = "{'descr': '<u2', 'fortran_order': True, 'shape': (13, 9, 11), }";
    while ((10 + npyHeader.size() + 1) % 64 != 0)
        npyHeader += ' ';
    npyHeader += '\n';
    test::writeFile(dir / "v.npy", std::string("\x93NUMPY\x01\x00", 8) + static_cast<char>(npyHeader.size()) + '\0' +
                                       npyHeader + raw16);
    // NRRD, raw encoding: attached after its header, and detached with a byte skip and trailing bytes.
    test::writeFile(dir / "attached.nrrd", "NRRD0004\ntype: uint16\ndimension: 3\nsizes: 13 9 11\nendian: little\n"
                                           "encoding: raw\nspacings: 0.5 1 2\nspace origin: (1,2,3)\n\n" + raw16);
    test::writeFile(dir / "skip.data", std::string(7, 'x') + raw16 + "trailing");
    test::writeFile(dir / "detached.nhdr", "NRRD0004\ntype: uint16\ndimension: 3\nsizes: 13 9 11\nendian: little\n"
                                           "encoding: raw\nbyte skip: 7\ndata file: skip.data\n");
    // NRRD, gzip: attached, with a byte skip inside the inflated data, in two gzip members.
    test::writeFile(dir / "gz.nrrd", "NRRD0004\ntype: uint16\ndimension: 3\nsizes: 13 9 11\nendian: little\n"
                                     "encoding: gzip\nbyte skip: 5\nspacings: 0.5 1 2\n\n" +
                                         test::gzip("skip!" + raw16.substr(0, 1000)) + test::gzip(raw16.substr(1000)));
    const std::vector<nlohmann::json> specs = {
        {{"file", "gz.nrrd"}},
        {{"file", "attached.nrrd"}},
        {{"file", "detached.nhdr"}},
        {{"file", "v16.raw"}, {"dims", {13, 9, 11}}, {"type", "uint16"}, {"endian", "little"}, {"spacing", {0.5, 1, 2}}, {"origin", {1, 2, 3}}},
        {{"file", "vf.raw"}, {"dims", {13, 9, 11}}, {"type", "float32"}, {"endian", "little"}},
        {{"file", "v.npy"}, {"spacing", {0.5, 1, 2}}, {"origin", {1, 2, 3}}},
    };
    for (const nlohmann::json& json : specs) {
        SCOPED_TRACE(json.dump());
        const VolumeSpec spec = parseVolumeSpec(json, dir.path());
        const Volume whole = loadVolume(spec);
        const std::optional<GridHeader> header = volumeHeader(spec);
        ASSERT_TRUE(header);
        EXPECT_EQ(header->dims, whole.dims);
        EXPECT_EQ(header->spacing, whole.spacing);
        EXPECT_EQ(header->origin, whole.origin);
        for (int n = 1; n <= 8; ++n)
            for (int ghost = 0; ghost <= 1; ++ghost) {
                const GridPartition partition = partitionGrid(whole.dims, whole.origin, whole.spacing, n);
                for (int p = 0; p < n; ++p) {
                    const Volume cut = cutGridPart(whole, partition, p, ghost);
                    Volume read = loadVolumeRegion(spec, gridPartRegion(partition, header->dims, p, ghost));
                    read.part = gridPartPlacement(partition, header->dims, header->origin, p, ghost);
                    ASSERT_EQ(read.dims, cut.dims) << n << " parts, part " << p;
                    EXPECT_EQ(read.origin, cut.origin);
                    EXPECT_EQ(read.spacing, cut.spacing);
                    EXPECT_EQ(read.voxelType, cut.voxelType);
                    EXPECT_EQ(read.values, cut.values) << n << " parts, part " << p;
                    EXPECT_EQ(read.voxels, cut.voxels) << n << " parts, part " << p;
                    EXPECT_EQ(read.part->offset, cut.part->offset);
                    EXPECT_EQ(read.part->ghostLo, cut.part->ghostLo);
                    EXPECT_EQ(read.part->ghostHi, cut.part->ghostHi);
                    EXPECT_EQ(read.part->fullDims, cut.part->fullDims);
                    EXPECT_EQ(read.part->fullOrigin, cut.part->fullOrigin);
                }
            }
    }
    // Formats that cannot read a region say so (the caller loads them whole).
    EXPECT_FALSE(volumeHeader(parseVolumeSpec({{"generator", "sphere"}, {"dims", {8, 8, 8}}}, dir.path())));
    test::writeFile(dir / "ascii.nrrd", "NRRD0004\ntype: uint8\ndimension: 3\nsizes: 2 2 2\nencoding: ascii\n\n"
                                        "1 2 3 4 5 6 7 8\n");
    EXPECT_FALSE(volumeHeader(parseVolumeSpec({{"file", "ascii.nrrd"}}, dir.path())));
    // The engine (gzip NRRD, uint8, 256x256x128): a rank's part inflated in order is the cut of the whole.
    const VolumeSpec engine = parseVolumeSpec({{"file", test::sharedData("engine/engine.nrrd")}}, dir.path());
    const Volume whole = loadVolume(engine);
    EXPECT_EQ(whole.voxelType, VoxelType::UInt8);
    const GridPartition four = partitionGrid(whole.dims, whole.origin, whole.spacing, 4);
    for (int p = 0; p < 4; ++p)
        EXPECT_EQ(loadVolumeRegion(engine, gridPartRegion(four, whole.dims, p, 1)).voxels,
                  cutGridPart(whole, four, p, 1).voxels) << "part " << p;
    // A NRRD shorter than its samples is the same one-line error as when read whole.
    test::writeFile(dir / "short.nrrd", "NRRD0004\ntype: uint16\ndimension: 3\nsizes: 13 9 11\nendian: little\n"
                                        "encoding: raw\n\n" + raw16.substr(0, 100));
    EXPECT_THROW(volumeHeader(parseVolumeSpec({{"file", "short.nrrd"}}, dir.path())), InputError);
}

TEST(SortLast, Slice3dPartsCompositeToTheWholeImage)
{
    const Volume v = generateVolume("marschner-lobb", glm::ivec3(41, 37, 45));
    Scene scene;
    scene.technique = "slice3d";
    scene.image = ImageSpec{64, 64, {0.1, 0.2, 0.3}};
    scene.transferFunction = test::designTransferFunction();
    scene.options = {{"slices", 160}};
    for (const Camera& camera : sortLastCameras()) {
        scene.camera = camera;
        for (int n : {1, 2, 3, 5, 8}) {
            const GridPartition g = partitionGrid(v.dims, v.origin, v.spacing, n);
            const auto render = [&](const Scene& s, int p, int) {
                FrameStats stats;
                return p < 0 ? test::renderScene(s, v) : test::renderScene(s, cutGridPart(v, g, p), &stats);
            };
            const double d = sortLastDifference(scene, render, g.tree, n);
            std::printf("slice3d, %s camera, %d parts: max |composite - whole| = %.2g\n",
                        camera.parallel ? "parallel" : "perspective", n, d);
            EXPECT_LE(d, kSortLastFloatTolerance) << n << " parts";
        }
    }
}

TEST(SortLast, Slice3dPartTakesEachSampleOnce)
{
    // The samples the parts take add up to the whole image's (every sample owned by one part).
    const Volume v = generateVolume("marschner-lobb", glm::ivec3(21, 19, 23));
    Scene scene;
    scene.technique = "slice3d";
    scene.image = ImageSpec{48, 48, {0.0, 0.0, 0.0}};
    scene.transferFunction = test::designTransferFunction();
    scene.camera = test::obliquePerspectiveCamera(40.0);
    scene.options = {{"slices", 97}, {"empty_space_skipping", false}};
    FrameStats whole;
    test::renderScene(scene, v, &whole);
    const GridPartition g = partitionGrid(v.dims, v.origin, v.spacing, 6);
    std::uint64_t sum = 0;
    for (int p = 0; p < 6; ++p) {
        FrameStats stats;
        test::renderScene(scene, cutGridPart(v, g, p), &stats);
        sum += stats.samples;
    }
    EXPECT_EQ(sum, whole.samples);
    EXPECT_GT(whole.samples, 0u);
}

TEST(SortLast, HarcPartsCompositeToTheWholeImage)
{
    // Two boxes (a non-convex L of cells) with a linear field: the k-d boxes cut through cells.
    TetMesh mesh = test::boxMesh({{{-1.0, -1.0, -1.0}, {1.0, 0.0, 1.0}, 5}, {{-1.0, 0.0, -1.0}, {0.0, 1.0, 1.0}, 3}},
                                 {0.3, 0.2, -0.25}, 0.5);
    checkMesh(mesh);
    Scene scene = test::meshScene("harc", Camera{}, test::rampTransferFunction(), 48);
    // Close to the mesh, looking across the cuts, and the eye inside the mesh (in some parts' boxes).
    Camera near = test::perspective({1.9, 0.8, 1.6}, {-0.2, 0.1, -0.3}, 60.0);
    for (const Camera& camera : {sortLastCameras()[0], sortLastCameras()[1], near, sortLastCameras()[2]}) {
        scene.camera = camera;
        for (int n : {1, 2, 3, 4, 7}) {
            const MeshPartition m = partitionMesh(mesh, n);
            const auto render = [&](const Scene& s, int p, int) {
                const TetMesh part = p < 0 ? mesh : cutMeshPart(mesh, m, p);
                FrameStats stats;
                return makeMeshRenderer(test::device(), s, part)->render(stats);
            };
            const double d = sortLastDifference(scene, render, m.tree, n);
            std::printf("harc, %s camera, %d parts: max |composite - whole| = %.2g\n",
                        camera.parallel ? "parallel" : "perspective", n, d);
            EXPECT_LE(d, kSortLastFloatTolerance) << n << " parts";
        }
    }
}

TEST(SortLast, PlanesAndBlendPartsWithAGhostLayerCompositeToTheWholeImage)
{
    // Shaded (two lights), so the Sobel gradients at the parts' faces matter; planes without early
    // termination in the whole image too (a part cannot see the opacity in front of it).
    const Volume v = generateVolume("marschner-lobb", glm::ivec3(33, 29, 35));
    for (const char* technique : {"planes", "blend"}) {
        Scene scene;
        scene.technique = technique;
        scene.image = ImageSpec{48, 48, {0.1, 0.2, 0.3}};
        scene.transferFunction = test::designTransferFunction();
        scene.lighting = test::twoLightLighting();
        scene.options = std::string(technique) == "planes" ? nlohmann::json{{"early_termination", 1.0}}
                                                           : nlohmann::json{{"slices", 90}};
        for (const Camera& camera : sortLastCameras()) {
            scene.camera = camera;
            for (int n : {2, 3, 6}) {
                const GridPartition g = partitionGrid(v.dims, v.origin, v.spacing, n);
                for (int ghost : {1, 0}) {
                    const auto render = [&](const Scene& s, int p, int) {
                        return p < 0 ? test::renderScene(s, v) : test::renderScene(s, cutGridPart(v, g, p, ghost));
                    };
                    const double d = sortLastDifference(scene, render, g.tree, n);
                    std::printf("%s, %s camera, %d parts, ghost %d: max |composite - whole| = %.2g\n", technique,
                                camera.parallel ? "parallel" : "perspective", n, ghost, d);
                    if (ghost == 1)
                        EXPECT_LE(d, kSortLastFloatTolerance) << technique << ", " << n << " parts";
                    else  // without it the gradients at the cuts are one-sided: the seam the ghost removes
                        EXPECT_GT(d, 100 * kSortLastFloatTolerance) << technique << ", " << n << " parts";
                }
            }
        }
    }
}

TEST(SortLast, MeshPartsKeepEveryCellThatMeetsTheirBox)
{
    TetMesh mesh = test::boxMesh({{{0.0, 0.0, 0.0}, {1.0, 1.0, 1.0}, 4}}, {1.0, 0.0, 0.0}, 0.0);
    checkMesh(mesh);
    const MeshPartition m = partitionMesh(mesh, 4);
    std::size_t kept = 0;
    for (int p = 0; p < 4; ++p) {
        const TetMesh part = cutMeshPart(mesh, m, p);
        kept += part.tets.size();
        // Every centroid inside the box has its cell in the part.
        std::size_t inside = 0;
        for (const glm::uvec4& t : mesh.tets) {
            const glm::dvec3 c = 0.25 * (mesh.points[t.x] + mesh.points[t.y] + mesh.points[t.z] + mesh.points[t.w]);
            inside += glm::all(glm::greaterThanEqual(c, m.lo[static_cast<std::size_t>(p)])) &&
                      glm::all(glm::lessThanEqual(c, m.hi[static_cast<std::size_t>(p)]));
        }
        EXPECT_GE(part.tets.size(), inside);
        EXPECT_EQ(part.points.size(), part.scalars.size());
    }
    EXPECT_GE(kept, mesh.tets.size());  // cells on a cut belong to both sides
}

// Sort-first on one process: the whole image against its bands (Camera::bandFullHeight), each rendered
// as its own image of its rows and stacked top to bottom, as rank 0 gathers them.
double sortFirstDifference(const Scene& scene, const std::function<Image4f(const Scene&)>& render,
                           const std::vector<int>& rows)
{
    const Image4f whole = render(scene);
    float coverage = 0.0f;
    for (const glm::vec4& p : whole.pixels())
        coverage = std::max(coverage, p.a);
    EXPECT_GT(coverage, 0.2f) << scene.technique << ": the whole image is (nearly) empty, the test checks little";
    Image4f stacked(scene.image.width, scene.image.height);
    int y0 = 0;
    for (int r : rows) {
        Scene band = scene;
        band.camera->bandFullHeight = scene.image.height;
        band.camera->bandY0 = y0;
        band.image.height = r;
        const Image4f part = render(band);
        std::copy(part.pixels().begin(), part.pixels().end(),
                  stacked.pixels().begin() + static_cast<std::ptrdiff_t>(y0) * scene.image.width);
        y0 += r;
    }
    return maxChannelDifference(stacked, whole);
}

// Bands of uneven heights (balanceRows' output after an uneven frame), down to one row.
std::vector<std::vector<int>> sortFirstBands(int height)
{
    return {{height}, {height / 2, height - height / 2}, {1, height - 8, 7}, {5, 13, 1, 20, height - 39}};
}

// The stacked bands equal the whole image bit for bit: a band's kernels take the full image's rays
// (kernels/ray.h clvr_ray_window_offset), the raster stage's off-centre projection puts every fragment
// on the full image's pixel centre, and harc's entry lists are built in the full image's rows.
constexpr double kSortFirstTolerance = 0.0;

TEST(SortFirst, GridBandsStackToTheWholeImage)
{
    const Volume v = generateVolume("marschner-lobb", glm::ivec3(33, 29, 31));
    struct Case {
        std::string technique;
        nlohmann::json options;
    };
    const std::vector<Case> cases = {{"slice3d", {{"slices", 120}}},
                                     {"slice3d", {{"slices", 60}, {"path", "raster"}}},
                                     {"iso3d", {{"slices", 60}}},
                                     {"stack2d", nlohmann::json::object()},
                                     {"planes", nlohmann::json::object()},
                                     {"blend", {{"slices", 60}}},
                                     {"cubefan", {{"error", 0.1}, {"path", "fused"}}},
                                     {"cubefan", {{"error", 0.1}, {"path", "tiles"}}}};
    for (const Case& c : cases)
        for (const Camera& camera : {test::obliquePerspectiveCamera(40.0), test::obliqueParallelCamera(1.8)}) {
            Scene scene;
            scene.technique = c.technique;
            scene.image = ImageSpec{40, 48, {0.1, 0.2, 0.3}};
            scene.transferFunction = test::designTransferFunction();
            scene.options = c.options;
            scene.camera = camera;
            if (c.technique == "iso3d")
                scene.iso = test::isoSpec(0.5, {0.4, 0.6, 1.0}, 0.1, 0.9);
            for (const std::vector<int>& rows : sortFirstBands(48)) {
                const double d = sortFirstDifference(scene, [&](const Scene& s) { return test::renderScene(s, v); }, rows);
                std::printf("sort-first %s %s, %s camera, %zu bands: max |stacked - whole| = %.2g\n",
                            c.technique.c_str(), c.options.dump().c_str(), camera.parallel ? "parallel" : "perspective",
                            rows.size(), d);
                EXPECT_LE(d, kSortFirstTolerance) << c.technique << ", " << rows.size() << " bands";
            }
        }
}

TEST(SortFirst, MeshBandsStackToTheWholeImage)
{
    TetMesh mesh = test::boxMesh({{{-1.0, -1.0, -1.0}, {1.0, 0.0, 1.0}, 5}, {{-1.0, 0.0, -1.0}, {0.0, 1.0, 1.0}, 3}},
                                 {0.3, 0.2, -0.25}, 0.5);
    checkMesh(mesh);
    Camera inside = test::perspective({-0.5, 0.4, 0.1}, {0.6, -0.5, -0.2}, 70.0);  // the eye in a cell
    const std::vector<Camera> cameras = {sortLastCameras()[0], sortLastCameras()[1], inside};
    for (const char* technique : {"harc", "projtet"})
        for (std::size_t i = 0; i < cameras.size(); ++i) {
            const Camera& camera = cameras[i];
            Scene scene = test::meshScene(technique, camera, test::rampTransferFunction(), 48);
            const auto render = [&](const Scene& s) {
                FrameStats stats;
                return makeMeshRenderer(test::device(), s, mesh)->render(stats);
            };
            for (const std::vector<int>& rows : sortFirstBands(48)) {
                const double d = sortFirstDifference(scene, render, rows);
                std::printf("sort-first %s, %s camera, %zu bands: max |stacked - whole| = %.2g\n", technique,
                            camera.parallel ? "parallel" : "perspective", rows.size(), d);
                EXPECT_LE(d, kSortFirstTolerance) << technique << ", " << rows.size() << " bands";
            }
        }
}

TEST(SortFirst, BalancedRowsTileTheImageAndEvenTheCost)
{
    // No times yet: equal shares, the first ranks one row more.
    EXPECT_EQ(balanceRows(10, {0, 0, 0}, {0.0, 0.0, 0.0}), (std::vector<int>{4, 3, 3}));
    // Rank 0's rows cost 3x rank 1's: the cut moves to where the cumulative cost halves.
    // Costs 0.6 and 0.2 per row, total 40: 34 rows of rank 0's reach 20.4 >= 20.
    EXPECT_EQ(balanceRows(100, {50, 50}, {30.0, 10.0}), (std::vector<int>{34, 66}));
    // One row holding all the cost still leaves every rank a row.
    EXPECT_EQ(balanceRows(6, {1, 2, 3}, {100.0, 0.0, 0.0}), (std::vector<int>{1, 1, 4}));
    // Random costs: the bands tile the image, each rank keeps a row, and every band's predicted cost is
    // within one row's cost of the mean.
    std::uint32_t seed = 12345;
    const auto next = [&] { return (seed = seed * 1664525u + 1013904223u) >> 8; };
    for (int trial = 0; trial < 200; ++trial) {
        const int n = 1 + static_cast<int>(next() % 8), height = n + static_cast<int>(next() % 300);
        std::vector<int> rows = balanceRows(height, std::vector<int>(n, 0), std::vector<double>(n, 0.0));
        std::vector<double> ms(static_cast<std::size_t>(n));
        for (double& t : ms)
            t = 1.0 + next() % 1000;
        const std::vector<int> out = balanceRows(height, rows, ms);
        std::vector<double> rowCost;
        double total = 0.0, maxRow = 0.0;
        for (int r = 0; r < n; ++r)
            for (int i = 0; i < rows[static_cast<std::size_t>(r)]; ++i) {
                rowCost.push_back(ms[static_cast<std::size_t>(r)] / rows[static_cast<std::size_t>(r)]);
                maxRow = std::max(maxRow, rowCost.back());
            }
        for (double t : ms)
            total += t;
        int y = 0;
        for (int r = 0; r < n; ++r) {
            ASSERT_GE(out[static_cast<std::size_t>(r)], 1);
            double cost = 0.0;
            for (int i = 0; i < out[static_cast<std::size_t>(r)]; ++i)
                cost += rowCost[static_cast<std::size_t>(y++)];
            // The last bands can be forced to one row each; all others are cut at the first row past
            // their share of the cumulative cost.
            if (out[static_cast<std::size_t>(r)] > 1 && r < n - 1) {
                EXPECT_LE(cost, total / n + maxRow + 1e-9 * total) << "trial " << trial << ", rank " << r;
            }
        }
        ASSERT_EQ(y, height) << "trial " << trial;
    }
    EXPECT_THROW(balanceRows(2, {1, 1, 1}, {0.0, 0.0, 0.0}), InternalError);
    EXPECT_THROW(balanceRows(5, {1, 1}, {1.0, 1.0}), InternalError);
}

TEST(SortLast, TechniquesThatCannotRenderAPartSaySo)
{
    const Volume v = generateVolume("sphere", glm::ivec3(9, 9, 9));
    const GridPartition g = partitionGrid(v.dims, v.origin, v.spacing, 2);
    Scene scene;
    scene.technique = "iso3d";
    scene.image = ImageSpec{16, 16, {0.0, 0.0, 0.0}};
    scene.transferFunction = test::designTransferFunction();
    try {
        makeRenderer(test::device(), scene, cutGridPart(v, g, 0));
        FAIL() << "iso3d took a part";
    } catch (const InputError& e) {
        EXPECT_NE(std::string(e.what()).find("--distribution sort-first"), std::string::npos) << e.what();
    }
    scene.technique = "slice3d";
    scene.options = {{"path", "raster"}};
    EXPECT_THROW(makeRenderer(test::device(), scene, cutGridPart(v, g, 0)), InputError);
}

}  // namespace
}  // namespace clvr
