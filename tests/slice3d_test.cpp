// tests/slice3d_test.cpp — 3D-texture slicing: slice polygons, options, the fused kernel against the
// CPU reference integral (error falling with the slice count), back-to-front == front-to-back,
// early ray termination bound, fused == pass-by-pass raster path, identical bits, orientation.
#include "host/render/grid/slice3d.h"
#include "host/cluster/partition.h"  // cutGridPart
#include "host/render/transfer_function_upload.h"  // tauZeroOn

#include "host/runtime/errors.h"
#include "host/io/generators.h"
#include "host/io/image_io.h"
#include "host/reference/reference_integral.h"
#include "raster/reference/pixel_transfer.h"
#include "host/render/renderer.h"
#include "host/render/options_util.h"  // packetsOnDevice
#include "host/io/volume_io.h"
#include "tests/support/test_util.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <ctime>
#include <cstdlib>
#include <cstring>
#include <filesystem>

namespace clvr {
namespace {

using nlohmann::json;

Camera perspectiveCamera()
{
    return test::obliquePerspectiveCamera(40.0);
}

Camera parallelCamera()
{
    return test::obliqueParallelCamera(1.8);
}

Scene makeScene(const Camera& camera, const TransferFunction& tf, int size, json options = json::object(),
                glm::dvec3 background = {0.1, 0.2, 0.3})
{
    Scene s;
    s.technique = "slice3d";
    s.camera = camera;
    s.image = ImageSpec{size, size, background};
    s.transferFunction = tf;
    s.options = std::move(options);
    return s;
}

Image4d reference(const Scene& scene, const Volume& volume) { return test::referenceImage(scene, volume); }

const Volume& marschnerLobb41()
{
    static const Volume v = generateVolume("marschner-lobb", {41, 41, 41});
    return v;
}

double maxChannel(const glm::dvec4& v) { return std::max({v.r, v.g, v.b, v.a}); }

// ---- slice polygons --------------------------------------------------------------------------

TEST(Slice3dPolygon, RandomPlanesGiveConvexPolygonsOnTheBox)
{
    test::Rng rng(7);
    const glm::dvec3 lo(-1.0, -0.5, 0.2), hi(0.8, 1.5, 0.9);
    int counts[7] = {};
    for (int trial = 0; trial < 2000; ++trial) {
        glm::dvec3 n;
        do
            n = {rng.uniform(-1, 1), rng.uniform(-1, 1), rng.uniform(-1, 1)};
        while (glm::length(n) < 0.1);
        n = glm::normalize(n);
        // Offsets spanning the box's range along n, so nearly every plane cuts it.
        double dMin = 1e30, dMax = -1e30;
        for (int c = 0; c < 8; ++c) {
            const double d = glm::dot(n, glm::dvec3((c & 1) ? hi.x : lo.x, (c & 2) ? hi.y : lo.y, (c & 4) ? hi.z : lo.z));
            dMin = std::min(dMin, d);
            dMax = std::max(dMax, d);
        }
        const double offset = rng.uniform(dMin, dMax);
        const std::vector<glm::dvec3> poly = slicePolygon(lo, hi, n, offset);
        ASSERT_GE(poly.size(), 3u);
        ASSERT_LE(poly.size(), 6u);
        ++counts[poly.size()];
        double sign = 0.0;
        for (std::size_t i = 0; i < poly.size(); ++i) {
            const glm::dvec3& p = poly[i];
            EXPECT_NEAR(glm::dot(n, p), offset, 1e-12);  // on the plane
            int onFace = 0;
            for (int a = 0; a < 3; ++a) {
                EXPECT_GE(p[a], lo[a] - 1e-12);
                EXPECT_LE(p[a], hi[a] + 1e-12);
                onFace += std::abs(p[a] - lo[a]) < 1e-12 || std::abs(p[a] - hi[a]) < 1e-12;
            }
            EXPECT_GE(onFace, 2) << "a vertex lies on a box edge";
            // Convex and consistently ordered: every turn has the same sign about n.
            const glm::dvec3 e0 = poly[(i + 1) % poly.size()] - p;
            const glm::dvec3 e1 = poly[(i + 2) % poly.size()] - poly[(i + 1) % poly.size()];
            const double turn = glm::dot(glm::cross(e0, e1), n);
            if (sign == 0.0)
                sign = turn;
            EXPECT_GT(turn * sign, 0.0);
        }
        EXPECT_GT(sign, 0.0);  // counter-clockwise about n
    }
    EXPECT_GT(counts[3], 0);
    EXPECT_GT(counts[4], 0);
    EXPECT_GT(counts[5], 0);
    EXPECT_GT(counts[6], 0);
}

TEST(Slice3dPolygon, SpecialPlanes)
{
    const glm::dvec3 lo(-1.0), hi(1.0);
    EXPECT_TRUE(slicePolygon(lo, hi, {0, 0, 1}, 1.5).empty());  // misses
    EXPECT_EQ(slicePolygon(lo, hi, {0, 0, 1}, 0.0).size(), 4u);  // axis-aligned square
    EXPECT_EQ(slicePolygon(lo, hi, {0, 0, 1}, 1.0).size(), 4u);  // the face itself
    const glm::dvec3 diag = glm::normalize(glm::dvec3(1.0));
    EXPECT_EQ(slicePolygon(lo, hi, diag, 0.0).size(), 6u);                      // regular hexagon
    EXPECT_EQ(slicePolygon(lo, hi, diag, glm::dot(diag, glm::dvec3(1, 1, -1))).size(), 3u);  // through 3 corners
    EXPECT_TRUE(slicePolygon(lo, hi, diag, std::sqrt(3.0)).empty());            // touches a corner only
}

TEST(Slice3dPlan, SlicesSpanTheEyeDepthRange)
{
    Camera c;
    c.position = {0, 0, 4};
    Slice3dOptions o;
    o.slices = 10;
    SlicePlan p = planSlices(c, glm::dvec3(-1), glm::dvec3(1), o);
    EXPECT_DOUBLE_EQ(p.depthMin, 3.0);
    EXPECT_DOUBLE_EQ(p.depthMax, 5.0);
    EXPECT_EQ(p.count, 10);
    EXPECT_DOUBLE_EQ(p.depth(0), 3.1);
    o.sliceSpacing = 0.3;
    p = planSlices(c, glm::dvec3(-1), glm::dvec3(1), o);
    EXPECT_EQ(p.count, 7);  // ceil(2 / 0.3)
    EXPECT_DOUBLE_EQ(p.deltaS, 0.3);
    c.position = {0, 0, 0.5};  // inside: slices start at the camera
    o.sliceSpacing = 0.0;
    p = planSlices(c, glm::dvec3(-1), glm::dvec3(1), o);
    EXPECT_DOUBLE_EQ(p.depthMin, 0.0);
    EXPECT_DOUBLE_EQ(p.depthMax, 1.5);
}

// ---- options ---------------------------------------------------------------------------------

void expectInputError(const json& options, const std::string& fragment)
{
    try {
        parseSlice3dOptions(options);
        ADD_FAILURE() << "no InputError for " << options.dump();
    } catch (const InputError& e) {
        EXPECT_NE(std::string(e.what()).find(fragment), std::string::npos) << e.what();
    }
}

TEST(Slice3dOptions, BadOptionsThrowInputErrorNamingTheKey)
{
    expectInputError({{"foo", 1}},
                     "options.foo: unknown option for slice3d (known: slices, slice_spacing, order, early_termination, path, empty_space_skipping, voxel_type, packets, integration, clip, clip_texture)");
    expectInputError({{"slices", 0}}, "options.slices");
    expectInputError({{"slices", 65537}}, "options.slices");
    expectInputError({{"slices", 2.5}}, "options.slices");
    expectInputError({{"slices", "many"}}, "options.slices");
    expectInputError({{"slice_spacing", -0.1}}, "options.slice_spacing");
    expectInputError({{"slice_spacing", 0.1}, {"slices", 4}}, "options.slice_spacing");
    expectInputError({{"order", "sideways"}}, "options.order");
    expectInputError({{"path", "gpu"}}, "options.path");
    expectInputError({{"voxel_type", "int8"}}, "options.voxel_type");
    expectInputError({{"empty_space_skipping", 1}}, "options.empty_space_skipping");
    expectInputError({{"packets", "yes"}}, "options.packets");
    expectInputError({{"early_termination", 1.5}}, "options.early_termination");
    expectInputError({{"early_termination", 0.9}}, "options.early_termination");  // needs front-to-back
    expectInputError({{"early_termination", 0.9}, {"order", "front-to-back"}, {"path", "raster"}},
                     "options.early_termination");
    EXPECT_NO_THROW(parseSlice3dOptions({{"slices", 65536}, {"order", "front-to-back"}, {"early_termination", 0.99},
                                         {"path", "fused"}}));
}

TEST(Slice3dOptions, MakeRendererRejectsUnknownTechniqueAndMissingVolume)
{
    Scene scene = makeScene(perspectiveCamera(), test::designTransferFunction(), 16);
    scene.technique = "raytrace";
    try {
        makeRenderer(test::device(), scene, marschnerLobb41());
        ADD_FAILURE() << "no InputError";
    } catch (const InputError& e) {
        EXPECT_NE(std::string(e.what()).find("slice3d"), std::string::npos) << e.what();
        EXPECT_NE(std::string(e.what()).find("raytrace"), std::string::npos) << e.what();
    }
    scene.technique = "slice3d";
    EXPECT_THROW(makeRenderer(test::device(), scene, Volume{}), InputError);
    scene.options = {{"slices", -3}};
    EXPECT_THROW(makeRenderer(test::device(), scene, marschnerLobb41()), InputError);
    // slice_spacing so fine that the view needs more than 65536 slices.
    scene.options = {{"slice_spacing", 1e-6}};
    EXPECT_THROW(makeRenderer(test::device(), scene, marschnerLobb41()), InputError);
}

TEST(Slice3dRenderer, ResidentBytesAreFloat32Volume)
{
    auto renderer = makeRenderer(test::device(), makeScene(perspectiveCamera(), test::designTransferFunction(), 16),
                                 marschnerLobb41());
    // 4 bytes per grid point, plus the packed transfer function (3 points: 4 + 12 + 12 floats), plus
    // one empty-space byte per brick (40 cells per axis: 10^3 bricks of 4^3 cells).
    static_assert(kBrickCells == 4);
    EXPECT_EQ(renderer->residentBytes(), 41u * 41u * 41u * 4u + 28u * 4u + 1000u);
}

// ---- empty-space skipping ----------------------------------------------------------------------

TEST(Slice3dEmptySpace, TauZeroOnFollowsThePiecewiseLinearTau)
{
    // tau 0 up to s = 0.3, rising to 2 at 0.6, back to 0 at 0.8 and beyond.
    const TransferFunction tf({{0.1, {1, 0, 0}, 0.0}, {0.3, {1, 1, 0}, 0.0}, {0.6, {1, 1, 1}, 2.0},
                               {0.8, {0, 1, 1}, 0.0}, {0.9, {0, 0, 1}, 0.0}});
    EXPECT_TRUE(tauZeroOn(tf, -5.0f, 0.05f));  // below s_0: tau_0 held
    EXPECT_TRUE(tauZeroOn(tf, 0.0f, 0.3f));    // up to the last zero point, inclusive
    EXPECT_FALSE(tauZeroOn(tf, 0.0f, 0.3001f));
    EXPECT_FALSE(tauZeroOn(tf, 0.2f, 0.9f));    // the bump inside
    EXPECT_FALSE(tauZeroOn(tf, 0.61f, 0.62f));  // inside a rising segment
    EXPECT_TRUE(tauZeroOn(tf, 0.8f, 0.85f));
    EXPECT_TRUE(tauZeroOn(tf, 0.8f, 100.0f));   // above s_{n-1}: tau_{n-1} = 0 held
    EXPECT_FALSE(tauZeroOn(tf, 0.79f, 0.85f));
    const TransferFunction ml = test::designTransferFunction();  // tau 0 only at s = 0
    EXPECT_TRUE(tauZeroOn(ml, -1.0f, 0.0f));
    EXPECT_FALSE(tauZeroOn(ml, 0.0f, 1e-6f));
}

TEST(Slice3dEmptySpace, BrickGridHoldsEachBricksMinMaxWithOnePointOverlap)
{
    Volume v;
    v.dims = {19, 17, 9};  // odd sizes: partial last bricks, a last brick of one cell in z
    v.spacing = glm::dvec3(0.1);
    v.source = "random";
    v.values.resize(v.voxelCount());
    std::uint32_t state = 12345;
    for (float& x : v.values) {
        state = state * 1664525u + 1013904223u;
        x = static_cast<float>(state >> 8) / 16777216.0f;
    }
    const BrickGrid grid = buildBrickGrid(v);
    constexpr int B = kBrickCells;
    ASSERT_EQ(grid.dims, (glm::ivec3(18, 16, 8) + B - 1) / B);
    for (int bz = 0; bz < grid.dims.z; ++bz)
        for (int by = 0; by < grid.dims.y; ++by)
            for (int bx = 0; bx < grid.dims.x; ++bx) {
                float mn = 2.0f, mx = -1.0f;
                for (int k = B * bz; k <= std::min(B * bz + B, v.dims.z - 1); ++k)
                    for (int j = B * by; j <= std::min(B * by + B, v.dims.y - 1); ++j)
                        for (int i = B * bx; i <= std::min(B * bx + B, v.dims.x - 1); ++i) {
                            mn = std::min(mn, v.at(i, j, k));
                            mx = std::max(mx, v.at(i, j, k));
                        }
                const glm::vec2 got = grid.minMax[(bz * grid.dims.y + by) * grid.dims.x + bx];
                EXPECT_EQ(got, glm::vec2(mn, mx)) << bx << " " << by << " " << bz;
            }
}

// The box the fused kernel's sample loop runs in: the bricks that are not empty, per axis their lowest and
// highest index; none at all: lo = the brick counts, hi = -1 (an empty box).
TEST(Slice3dEmptySpace, FilledBricksSpanTheNonEmptyOnes)
{
    const glm::ivec3 dims(5, 4, 3);
    std::vector<cl_uchar> empty(60, 1);
    glm::ivec3 lo, hi;
    filledBricks(dims, empty, lo, hi);
    EXPECT_EQ(lo, dims);
    EXPECT_EQ(hi, glm::ivec3(-1));
    auto at = [&](int x, int y, int z) -> cl_uchar& { return empty[(static_cast<std::size_t>(z) * 4 + y) * 5 + x]; };
    at(3, 1, 2) = 0;
    at(1, 2, 0) = 0;
    filledBricks(dims, empty, lo, hi);
    EXPECT_EQ(lo, glm::ivec3(1, 1, 0));
    EXPECT_EQ(hi, glm::ivec3(3, 2, 2));
}

TEST(Slice3dEmptySpace, RadiiAreChebyshevDistancesToTheNearestNonEmptyBrick)
{
    const glm::ivec3 n(7, 5, 3);
    std::vector<cl_uchar> empty(n.x * n.y * n.z, 1);
    empty[(1 * n.y + 2) * n.x + 1] = 0;  // one non-empty brick at (1, 2, 1)
    const std::vector<cl_uchar> space = emptySpaceRadii(n, empty);
    for (int z = 0; z < n.z; ++z)
        for (int y = 0; y < n.y; ++y)
            for (int x = 0; x < n.x; ++x) {
                const int d = std::max({std::abs(x - 1), std::abs(y - 2), std::abs(z - 1)});
                EXPECT_EQ(space[(z * n.y + y) * n.x + x], d) << x << " " << y << " " << z;  // r + 1 = d
            }
    EXPECT_EQ(emptySpaceRadii({2, 1, 1}, {1, 1}), (std::vector<cl_uchar>{255, 255}));  // all empty: capped
    // Random grids (a few non-empty bricks among many empty ones, odd sizes) against the brute-force distance to
    // the nearest non-empty brick, capped at 255; and a line longer than the cap with one non-empty brick at
    // its end (300 bricks: the far ones stay at 255).
    std::srand(7);
    for (const glm::ivec3 m : {glm::ivec3(13, 9, 6), glm::ivec3(1, 17, 4), glm::ivec3(21, 1, 1)}) {
        std::vector<cl_uchar> flags(static_cast<std::size_t>(m.x) * m.y * m.z);
        std::vector<glm::ivec3> filled;
        for (int z = 0; z < m.z; ++z)
            for (int y = 0; y < m.y; ++y)
                for (int x = 0; x < m.x; ++x) {
                    const bool isEmpty = std::rand() % 23 != 0;
                    flags[(static_cast<std::size_t>(z) * m.y + y) * m.x + x] = isEmpty ? 1 : 0;
                    if (!isEmpty)
                        filled.emplace_back(x, y, z);
                }
        const std::vector<cl_uchar> r = emptySpaceRadii(m, flags);
        for (int z = 0; z < m.z; ++z)
            for (int y = 0; y < m.y; ++y)
                for (int x = 0; x < m.x; ++x) {
                    int want = 255;
                    for (const glm::ivec3& f : filled)
                        want = std::min(want, std::max({std::abs(x - f.x), std::abs(y - f.y), std::abs(z - f.z)}));
                    ASSERT_EQ(r[(static_cast<std::size_t>(z) * m.y + y) * m.x + x], want) << x << " " << y << " " << z;
                }
    }
    std::vector<cl_uchar> longLine(300, 1);
    longLine[299] = 0;
    const std::vector<cl_uchar> r = emptySpaceRadii({300, 1, 1}, longLine);
    for (int x = 0; x < 300; ++x)
        ASSERT_EQ(r[x], std::min(299 - x, 255)) << x;
}

// Integer volumes go to the device as uint8 (values in [0, 255]) or uint16 (in [0, 65535]); the
// kernel converts each grid value to float exactly, so the image equals the float32 one bit for bit.
TEST(Slice3dRenderer, NativeIntegerVoxelsGiveTheFloat32ImageBitForBit)
{
    const Volume sphere = generateVolume("sphere", {33, 29, 37});
    for (const float scale : {255.0f, 1000.0f}) {
        Volume v = sphere;
        for (float& x : v.values)
            x = std::round(x * scale);
        const TransferFunction tf({{0.0, {0, 0, 0}, 0.0}, {0.3 * scale, {0.2, 0.4, 1}, 0.0},
                                   {0.6 * scale, {1, 0.5, 0}, 6.0}, {scale, {1, 1, 1}, 12.0}});
        for (const char* order : {"back-to-front", "front-to-back"}) {
            const json options = {{"slices", 80}, {"order", order}};
            json asFloat = options;
            asFloat["voxel_type"] = "float32";
            FrameStats nativeStats, floatStats;
            auto renderer = makeRenderer(test::device(), makeScene(perspectiveCamera(), tf, 53, options), v);
            const Image4f native = renderer->render(nativeStats);
            const Image4f f32 = test::renderScene(makeScene(perspectiveCamera(), tf, 53, asFloat), v, &floatStats);
            const std::string type = scale == 255.0f ? "uint8" : "uint16";
            EXPECT_EQ(nativeStats.extra["voxel_type"], type);
            EXPECT_EQ(floatStats.extra["voxel_type"], "float32");
            const std::uint64_t bytesPerPoint = scale == 255.0f ? 1 : 2;
            const std::uint64_t bricks = 8 * 7 * 9;  // ceil((n - 1) / 4) per axis
            EXPECT_EQ(renderer->residentBytes(), v.voxelCount() * bytesPerPoint + (4 + 16 + 16) * 4 + bricks);
            EXPECT_EQ(std::memcmp(native.pixels().data(), f32.pixels().data(), native.pixelCount() * sizeof(glm::vec4)),
                      0) << type << " " << order;
            EXPECT_EQ(nativeStats.extra["samples_skipped"], floatStats.extra["samples_skipped"]);
        }
    }
}

// A volume held in its own 1- or 2-byte type on the host (Volume::voxels, as the raw, NRRD, .npy and VTK
// readers keep integer files) renders the bits of the same values held as float32: uploaded as it is where no
// value is negative (int8 and int16 as the same bits of uint8 and uint16), else converted to float32.
TEST(Slice3dRenderer, VolumesHeldInTheirOwnTypeGiveTheFloat32ImageBitForBit)
{
    const Volume sphere = generateVolume("sphere", {21, 19, 23});
    struct Case {
        VoxelType type;
        float scale, offset;
        const char* device;  // the type slice3d's kernel samples
    };
    const Case cases[] = {{VoxelType::UInt8, 255.0f, 0.0f, "uint8"},    {VoxelType::Int8, 127.0f, 0.0f, "uint8"},
                          {VoxelType::Int8, 100.0f, -50.0f, "float32"}, {VoxelType::UInt16, 60000.0f, 0.0f, "uint16"},
                          {VoxelType::Int16, 30000.0f, 0.0f, "uint16"}, {VoxelType::Int16, 2000.0f, -1000.0f, "float32"}};
    for (const Case& c : cases) {
        SCOPED_TRACE(std::string(voxelTypeName(c.type)) + " as " + c.device);
        Volume f = sphere;
        for (float& x : f.values)
            x = std::round(x * c.scale + c.offset);
        Volume n = f;  // the same values in their own type
        n.voxelType = c.type;
        n.values.clear();
        n.voxels.resize(f.voxelCount() * voxelTypeSize(c.type));
        for (std::size_t i = 0; i < f.voxelCount(); ++i) {
            if (voxelTypeSize(c.type) == 1) {
                n.voxels[i] = static_cast<std::uint8_t>(static_cast<int>(f.values[i]) & 0xff);
            } else {
                const auto v = static_cast<std::uint16_t>(static_cast<int>(f.values[i]) & 0xffff);
                std::memcpy(n.voxels.data() + 2 * i, &v, 2);
            }
        }
        ASSERT_NO_THROW(n.validate());
        ASSERT_EQ(n.at(10, 9, 11), f.at(10, 9, 11));
        EXPECT_EQ(n.range(), f.range());
        const TransferFunction tf({{c.offset, {0, 0, 0}, 0.0}, {c.offset + 0.3 * c.scale, {0.2, 0.4, 1}, 0.0},
                                   {c.offset + 0.6 * c.scale, {1, 0.5, 0}, 6.0}, {c.offset + c.scale, {1, 1, 1}, 12.0}});
        const Scene scene = makeScene(perspectiveCamera(), tf, 41, {{"slices", 64}});
        FrameStats nativeStats, floatStats;
        const Image4f native = test::renderScene(scene, n, &nativeStats);
        const Image4f f32 = test::renderScene(scene, f, &floatStats);
        EXPECT_EQ(nativeStats.extra["voxel_type"], c.device);
        EXPECT_TRUE(test::sameBits(native, f32));
    }
}

// The empty-space tests' scenes: the sphere field (0 outside the unit sphere) and its transfer function with
// tau 0 below 0.3, Marschner-Lobb's with tau 0 below 0.45, and a perspective camera on the z axis whose center
// ray runs along grid lines (zero direction components, samples on brick faces).
const Volume& sphereField()
{
    static const Volume v = generateVolume("sphere", {48, 40, 56});
    return v;
}
const TransferFunction kSphereTf({{0.0, {0, 0, 0}, 0.0}, {0.3, {0.2, 0.4, 1}, 0.0}, {0.6, {1, 0.5, 0}, 6.0},
                                  {1.0, {1, 1, 1}, 12.0}});
const TransferFunction kMlThreshold({{0.0, {0, 0, 0}, 0.0}, {0.45, {0.3, 0.3, 1}, 0.0}, {1.0, {1, 1, 0.5}, 9.0}});
Camera onAxisCamera()
{
    Camera c;
    c.position = {0.0, 0.0, 3.0};
    c.focalPoint = {0.0, 0.0, 0.0};
    c.viewUp = {0.0, 1.0, 0.0};
    c.viewAngle = 30.0;
    return c;
}

// Skipped samples would have contributed alpha = 1 - exp2(0) = 0 exactly, so the image with
// skipping must be bit-identical to the one without (memcmp), and the count of samples inside the
// box the same. Scenes with large zero-tau regions: the sphere field (0 outside the unit sphere) with
// tau 0 below 0.3, Marschner-Lobb with tau 0 below 0.45, and Marschner-Lobb with its usual transfer
// function (no empty brick: skipping stays off); both orders, early termination, both cameras, and
// a perspective camera on the z axis whose center ray runs along grid lines (zero direction
// components, samples on brick faces).
TEST(Slice3dEmptySpace, SkippingIsBitIdenticalToTheFullLoop)
{
    const Volume& sphere = sphereField();
    const TransferFunction& sphereTf = kSphereTf;
    const TransferFunction& mlThreshold = kMlThreshold;
    const Camera onAxis = onAxisCamera();
    struct Case {
        const char* name;
        const Volume* volume;
        TransferFunction tf;
        bool expectSkips;
    };
    // Data only in one corner block: the sample loop runs inside the box of the bricks that are not empty
    // (kernels/slice3d.cl), much smaller than the grid; the samples counted stay the grid's.
    static const Volume corner = [] {
        Volume v = generateVolume("marschner-lobb", {40, 36, 44});
        for (int z = 0; z < v.dims.z; ++z)
            for (int y = 0; y < v.dims.y; ++y)
                for (int x = 0; x < v.dims.x; ++x)
                    if (x < 21 || y < 17 || z > 26)
                        v.values[(static_cast<std::size_t>(z) * v.dims.y + y) * v.dims.x + x] = 0.0f;
        return v;
    }();
    const Case cases[] = {{"sphere", &sphere, sphereTf, true},
                          {"ml threshold", &marschnerLobb41(), mlThreshold, true},
                          {"ml usual", &marschnerLobb41(), test::designTransferFunction(), false},
                          {"corner block", &corner, mlThreshold, true}};
    const json orders[] = {{{"slices", 96}},
                           {{"slices", 96}, {"order", "front-to-back"}},
                           {{"slices", 128}, {"order", "front-to-back"}, {"early_termination", 0.9}}};
    for (const Case& c : cases)
        for (const Camera& camera : {perspectiveCamera(), parallelCamera(), onAxis})
            for (const json& base : orders) {
                json on = base, off = base;
                off["empty_space_skipping"] = false;
                FrameStats withStats, withoutStats;
                const Image4f with = test::renderScene(makeScene(camera, c.tf, 61, on), *c.volume, &withStats);
                const Image4f without = test::renderScene(makeScene(camera, c.tf, 61, off), *c.volume, &withoutStats);
                const std::string label = std::string(c.name) + (camera.parallel ? " parallel " : " perspective ") +
                                          base.dump();
                ASSERT_EQ(with.pixelCount(), without.pixelCount());
                EXPECT_EQ(std::memcmp(with.pixels().data(), without.pixels().data(),
                                      with.pixelCount() * sizeof(glm::vec4)), 0) << label;
                EXPECT_EQ(withStats.samples, withoutStats.samples) << label;
                EXPECT_EQ(withoutStats.extra["samples_skipped"].get<std::uint64_t>(), 0u) << label;
                const auto skipped = withStats.extra["samples_skipped"].get<std::uint64_t>();
                EXPECT_EQ(withStats.extra["samples_taken"].get<std::uint64_t>() + skipped, withStats.samples) << label;
                if (c.expectSkips) {
                    EXPECT_GT(skipped, withStats.samples / 10) << label;
                } else {
                    EXPECT_EQ(skipped, 0u) << label;
                }
                if (camera.position == onAxis.position && base.size() == 1)
                    std::printf("[ measured ] %s: %llu of %llu samples skipped\n", label.c_str(),
                                static_cast<unsigned long long>(skipped),
                                static_cast<unsigned long long>(withStats.samples));
            }
}


// The packet kernel (slice3d_fused_packet: 8 pixels of a row per work-item, one per float8 lane) computes
// each lane with the one-pixel kernel's expressions, so the images must be the same bits (memcmp), and the
// samples inside the box the same count; it takes at least the samples the one-pixel kernel takes (a lane in
// an empty brick samples while its neighbours do: tau 0 there, nothing changes). Float, uint8 and uint16
// volumes, empty-space skipping on and off, both orders and early termination, three cameras (one with its
// center ray along grid lines), images 61 and 5 pixels wide (the last packet of a row part empty, and a row
// narrower than one packet), and a sort-last part (its owned box and offset).
TEST(Slice3dPackets, BitIdenticalToOnePixelPerWorkItem)
{
    const Volume& sphere = sphereField();
    const TransferFunction& sphereTf = kSphereTf;
    const TransferFunction& mlThreshold = kMlThreshold;
    // Integer volumes (uint8 and uint16 on the device): Marschner-Lobb scaled to 0..255 and 0..4095 and rounded.
    const auto scaled = [](double top) {
        Volume v = marschnerLobb41();
        for (float& x : v.values)
            x = std::round(x * static_cast<float>(top));
        return v;
    };
    static const Volume ml8 = scaled(255.0), ml16 = scaled(4095.0);
    const TransferFunction tf8({{0.0, {0, 0, 0}, 0.0}, {115.0, {0.3, 0.3, 1}, 0.0}, {255.0, {1, 1, 0.5}, 0.035}});
    const TransferFunction tf16({{0.0, {0, 0, 0}, 0.0}, {1800.0, {0.3, 0.3, 1}, 0.0}, {4095.0, {1, 1, 0.5}, 0.002}});
    // A hollow box (the grid's faces 3 points thick, empty inside): where one lane's ray is in an empty run
    // through the inside, its neighbour may just be entering through a side face into the shell; the packet
    // must not step past that neighbour's first samples.
    static const Volume hollow = [] {
        Volume v = generateVolume("sphere", {45, 38, 41});
        for (int z = 0; z < v.dims.z; ++z)
            for (int y = 0; y < v.dims.y; ++y)
                for (int x = 0; x < v.dims.x; ++x) {
                    const int d = std::min({x, y, z, v.dims.x - 1 - x, v.dims.y - 1 - y, v.dims.z - 1 - z});
                    v.values[(static_cast<std::size_t>(z) * v.dims.y + y) * v.dims.x + x] = d < 3 ? 1.0f : 0.0f;
                }
        return v;
    }();
    const TransferFunction hollowTf({{0.0, {0, 0, 0}, 0.0}, {0.5, {0.2, 0.4, 1}, 0.0}, {1.0, {1, 0.6, 0.2}, 3.0}});
    static const Volume part = [] {
        const Volume& v = marschnerLobb41();
        return cutGridPart(v, partitionGrid(v.dims, v.origin, v.spacing, 3), 1);
    }();
    const Camera onAxis = onAxisCamera();
    struct Case {
        const char* name;
        const Volume* volume;
        TransferFunction tf;
        const char* voxelType;
    };
    const Case cases[] = {{"sphere", &sphere, sphereTf, "float32"},
                          {"hollow box", &hollow, hollowTf, "uint8"},
                          {"ml threshold", &marschnerLobb41(), mlThreshold, "float32"},
                          {"ml usual", &marschnerLobb41(), test::designTransferFunction(), "float32"},
                          {"ml uint8", &ml8, tf8, "uint8"},
                          {"ml uint16", &ml16, tf16, "uint16"},
                          {"ml part 1 of 3", &part, mlThreshold, "float32"}};
    const json orders[] = {{{"slices", 96}},
                           {{"slices", 96}, {"empty_space_skipping", false}},
                           {{"slices", 96}, {"order", "front-to-back"}},
                           {{"slices", 128}, {"order", "front-to-back"}, {"early_termination", 0.9}}};
    int compared = 0;
    for (const Case& c : cases)
        for (const Camera& camera : {perspectiveCamera(), parallelCamera(), onAxis})
            for (const json& base : orders)
                for (int width : {61, 5}) {
                    if (width == 5 && camera.position != onAxis.position && base.size() > 1)
                        continue;  // the narrow image: every camera once, the option sets on one
                    json packets = base, pixels = base;
                    packets["packets"] = true;  // the default on CPU devices only
                    pixels["packets"] = false;
                    Scene one = makeScene(camera, c.tf, width, packets), other = makeScene(camera, c.tf, width, pixels);
                    one.image.height = other.image.height = 47;
                    FrameStats ps, qs;
                    const Image4f p = test::renderScene(one, *c.volume, &ps);
                    const Image4f q = test::renderScene(other, *c.volume, &qs);
                    const std::string label = std::string(c.name) + (camera.parallel ? " parallel " : " perspective ") +
                                              base.dump() + " width " + std::to_string(width);
                    EXPECT_TRUE(test::sameBits(p, q)) << label;
                    EXPECT_TRUE(ps.extra["packets"].get<bool>()) << label;
                    EXPECT_FALSE(qs.extra["packets"].get<bool>()) << label;
                    EXPECT_EQ(ps.extra["voxel_type"], c.voxelType) << label;
                    EXPECT_EQ(ps.samples, qs.samples) << label;
                    const auto taken = [](const FrameStats& s) { return s.extra["samples_taken"].get<std::uint64_t>(); };
                    EXPECT_GE(taken(ps), taken(qs)) << label;
                    EXPECT_LE(taken(ps), ps.samples) << label;
                    EXPECT_GT(taken(qs), 0u) << label;
                    ++compared;
                }
    EXPECT_EQ(compared, 7 * (3 * 4 + 3 + 3));
}

// A transfer function with tau 0 everywhere empties every brick (the box of the bricks that are not empty is
// then empty, lo >= hi, and clvr_box_chord gives it no chord): neither kernel takes a sample, the image is the
// background, and the samples inside the box are still counted, all stepped over.
TEST(Slice3dPackets, TransparentTransferFunctionTakesNoSample)
{
    const TransferFunction clear({{0.0, {1, 0, 0}, 0.0}, {1.0, {0, 1, 0}, 0.0}});
    for (bool packets : {true, false}) {
        FrameStats stats;
        const Image4f image = test::renderScene(
            makeScene(perspectiveCamera(), clear, 29, {{"slices", 64}, {"packets", packets}}), marschnerLobb41(), &stats);
        EXPECT_EQ(stats.extra["samples_taken"].get<std::uint64_t>(), 0u) << packets;
        EXPECT_EQ(stats.extra["samples_skipped"].get<std::uint64_t>(), stats.samples) << packets;
        EXPECT_GT(stats.samples, 10000u) << packets;
        for (const glm::vec4& p : image.pixels())
            ASSERT_EQ(p, glm::vec4(0.1f, 0.2f, 0.3f, 0.0f)) << packets;
    }
}

// With a clip texture and with a clip mesh (peeled layers) the packet kernel runs each lane's clip test with the
// one-pixel kernel's code: the same bits, both orders and both clip methods, skipping on (a sample a clip test
// removes counts as taken); with pre-integrated slabs the fused path keeps one pixel per work-item (stats say
// which ran).
TEST(Slice3dPackets, ClippedImagesAreBitIdenticalPreintegratedKeepsOnePixel)
{
    const json sphereTexture = {{"shape", "sphere"}, {"center", {0.1, -0.05, 0.0}}, {"radius", 0.7}};
    const json sphereMesh = {{"generator", "sphere"}, {"center", {0.1, 0.0, 0.2}}, {"radius", 0.6}, {"segments", 32}};
    const TransferFunction& mlThreshold = kMlThreshold;
    const json clips[] = {{{"clip_texture", sphereTexture}},
                          {{"clip_texture", {{"shape", "sphere"}, {"radius", 0.6}, {"inverse", true}}}},
                          {{"clip", {{"mesh", sphereMesh}}}},
                          {{"clip", {{"mesh", sphereMesh}, {"inverse", true}, {"method", "naive"}}}}};
    int compared = 0;
    for (const json& clip : clips)
        for (const json& order : {json{{"order", "back-to-front"}}, json{{"order", "front-to-back"}, {"early_termination", 0.95}}})
            for (const Camera& camera : {perspectiveCamera(), parallelCamera()}) {
                json options = {{"slices", 80}, {"packets", true}};
                options.update(clip);
                options.update(order);
                json pixels = options;
                pixels["packets"] = false;
                FrameStats ps, qs;
                const Image4f p = test::renderScene(makeScene(camera, mlThreshold, 43, options), marschnerLobb41(), &ps);
                const Image4f q = test::renderScene(makeScene(camera, mlThreshold, 43, pixels), marschnerLobb41(), &qs);
                const std::string label = options.dump() + (camera.parallel ? " parallel" : " perspective");
                EXPECT_TRUE(test::sameBits(p, q)) << label;
                EXPECT_TRUE(ps.extra["packets"].get<bool>()) << label;
                EXPECT_EQ(ps.samples, qs.samples) << label;
                // the clip removes part of the image: some pixel is the background, some is not
                const auto background = [](const glm::vec4& v) { return v.a == 0.0f; };
                EXPECT_TRUE(std::any_of(p.pixels().begin(), p.pixels().end(), background)) << label;
                EXPECT_FALSE(std::all_of(p.pixels().begin(), p.pixels().end(), background)) << label;
                ++compared;
            }
    EXPECT_EQ(compared, 16);
    FrameStats pre;
    test::renderScene(makeScene(perspectiveCamera(), test::designTransferFunction(), 24,
                                {{"slices", 32}, {"integration", "preintegrated"}, {"packets", true}}),
                      marschnerLobb41(), &pre);
    EXPECT_FALSE(pre.extra["packets"].get<bool>());
}

// Renderer::setCamera: a slice3d renderer pointed at new cameras gives the images new renderers give, bit
// for bit, on every path that depends on the view in its own way — the fused kernel (slices, chords), a clip
// mesh (its depth range and peeled layers, peeled again), the raster path (the fragment program's camera and
// slab) with a clip mesh's stencil passes, pre-integration; a clip texture's placement does not move. A new
// image size is refused (false): the caller makes a new renderer.
TEST(Slice3dRenderer, SetCameraEqualsANewRenderer)
{
    const json sphereMesh = {{"generator", "sphere"}, {"center", {0.1, 0.0, 0.2}}, {"radius", 0.6}, {"segments", 24}};
    const json sets[] = {{{"slices", 48}},
                         {{"slices", 48}, {"packets", false}, {"order", "front-to-back"}, {"early_termination", 0.9}},
                         {{"slices", 32}, {"integration", "preintegrated"}},
                         {{"slices", 40}, {"clip", {{"mesh", sphereMesh}}}},
                         {{"slices", 40}, {"clip_texture", {{"shape", "sphere"}, {"radius", 0.6}, {"inverse", true}}}},
                         {{"slices", 32}, {"path", "raster"}},
                         {{"slices", 32}, {"path", "raster"}, {"clip", {{"mesh", sphereMesh}, {"inverse", true}}}}};
    Camera inside = perspectiveCamera();
    inside.position = glm::mix(inside.position, inside.focalPoint, 0.9);  // inside the box
    const std::vector<Camera> cameras = {perspectiveCamera(), parallelCamera(), inside, perspectiveCamera()};
    for (const json& options : sets) {
        Scene scene = makeScene(cameras[0], test::designTransferFunction(), 27, options);
        scene.image.height = 22;
        test::expectSetCameraEqualsNewRenderer(scene, marschnerLobb41(), cameras, options.dump());
    }
}

// Left out (or null), "packets" is on for CPU devices without a loop-iteration cap and off for the others (run
// GPU2: on an NVIDIA H200 the packet kernel took 2.7-4.2x the one-pixel kernel's time; llvmpipe caps loops and
// vectorizes work-items itself, docs/devices.md); given, it is what it says.
TEST(Slice3dPackets, DefaultIsOnForCpuDevicesOnly)
{
    EXPECT_TRUE(clvr::packetsByDefault("CPU", 0));
    EXPECT_FALSE(clvr::packetsByDefault("CPU", 65535));
    EXPECT_FALSE(clvr::packetsByDefault("GPU", 0));
    EXPECT_FALSE(clvr::packetsByDefault("accelerator", 0));
    EXPECT_TRUE(clvr::packetsOnDevice(true, test::device()));
    EXPECT_FALSE(clvr::packetsOnDevice(false, test::device()));
    const bool cpu = clvr::packetsByDefault(test::device().listing().type, test::device().loopIterationCap());
    for (const json& options : {json{{"slices", 16}}, json{{"slices", 16}, {"packets", nullptr}}}) {
        FrameStats stats;
        test::renderScene(makeScene(perspectiveCamera(), test::designTransferFunction(), 16, options), marschnerLobb41(),
                          &stats);
        EXPECT_EQ(stats.extra["packets"].get<bool>(), cpu) << options.dump();
    }
}

// ---- images ----------------------------------------------------------------------------------

void report(const char* what, const test::ImageError& e)
{
    std::printf("[ measured ] %s: max |diff| %.3g %.3g %.3g %.3g, mean %.3g %.3g %.3g %.3g\n", what, e.maxAbs.r,
                e.maxAbs.g, e.maxAbs.b, e.maxAbs.a, e.meanAbs.r, e.meanAbs.g, e.meanAbs.b, e.meanAbs.a);
}

// For looking at: the composited color with alpha set to 1 (viewers show A = 0 as transparent).
void writePng(const std::string& name, const Image4f& image)
{
    std::filesystem::create_directories("test_output");
    Image4f opaque = image;
    for (glm::vec4& p : opaque.pixels())
        p.a = 1.0f;
    writeImage("test_output/" + name + ".png", opaque);
}

using raster::reference::toDouble;  // Image4f -> Image4d, exactly

// Largest ray length of one slice in the image: deltaS / cos(theta) at the corner pixel.
double maxSliceLength(const Scene& scene, const Volume& volume)
{
    const Camera& c = *scene.camera;
    const SlicePlan plan = planSlices(c, volume.boundsMin(), volume.boundsMax(), parseSlice3dOptions(scene.options));
    const Ray corner = c.ray(0, 0, scene.image.width, scene.image.height);
    return plan.deltaS / glm::dot(corner.direction, c.forward());
}

// Slicing error against the converged integral. The slabs at the two ends of a chord are clipped to it
// (kernels/slice3d.cl's slice3d_slab_log2e), so the mean error is second order; a ray that crosses the box
// between two slices (or grazes an edge) still loses its whole chord: max <= 2 (1 - exp(-tauMax Delta)).
// The mean tolerance is the first-order bound the unclipped slabs needed, 0.02 tauMax deltaS (c ~ 0.01
// measured then on Marschner-Lobb; now 1e-3-4e-3 of it at 256 slices).
void checkAgainstReference(const Scene& scene, const Volume& volume, double tauMax, const char* label)
{
    FrameStats stats;
    const Image4f image = test::renderScene(scene, volume, &stats);
    writePng(std::string("slice3d_") + label, image);
    const Image4d want = reference(scene, volume);
    const double delta = maxSliceLength(scene, volume);
    const SlicePlan plan = planSlices(*scene.camera, volume.boundsMin(), volume.boundsMax(),
                                      parseSlice3dOptions(scene.options));
    const test::Tolerance tolerance{2.0 * (1.0 - std::exp(-tauMax * delta)), 0.02 * tauMax * plan.deltaS};
    report(label, test::imageError(image, want));
    std::printf("             tolerance max %.3g mean %.3g (deltaS %.4g)\n", tolerance.maxAbs, tolerance.meanAbs,
                plan.deltaS);
    EXPECT_TRUE(test::imagesNear(image, want, tolerance));
    EXPECT_GT(stats.samples, 0u);
    EXPECT_EQ(stats.extra["slices"], plan.count);
}

TEST(Slice3dFused, MarschnerLobbPerspectiveMatchesReference)
{
    checkAgainstReference(makeScene(perspectiveCamera(), test::designTransferFunction(), 64), marschnerLobb41(), 8.0,
                          "ml41_perspective");
}

TEST(Slice3dFused, MarschnerLobbParallelMatchesReference)
{
    checkAgainstReference(makeScene(parallelCamera(), test::designTransferFunction(), 64), marschnerLobb41(), 8.0,
                          "ml41_parallel");
}

TEST(Slice3dFused, HeadsqMatchesReference)
{
    const Volume volume = readNrrd(test::sharedData("headsq/quarter.nhdr"));
    // CT numbers: soft tissue ~1000 faint, bone towards 3000+ dense. tau per mm (the box is ~200 mm).
    const TransferFunction tf({{600.0, {0, 0, 0}, 0.0},
                               {1100.0, {0.9, 0.6, 0.4}, 0.01},
                               {2000.0, {1, 1, 0.9}, 0.05},
                               {4000.0, {1, 1, 1}, 0.1}});
    Camera camera = fitCamera(volume.boundsMin(), volume.boundsMax());
    Scene scene = makeScene(camera, tf, 64, {{"slices", 256}});
    checkAgainstReference(scene, volume, 0.1, "headsq_perspective");
    camera.position = camera.focalPoint + glm::dvec3(0.0, -1.0, 0.3) * glm::length(camera.position - camera.focalPoint);
    camera.viewUp = {0.0, 0.0, 1.0};
    camera.parallel = true;
    camera.parallelScale = 130.0;
    scene.camera = camera;
    checkAgainstReference(scene, volume, 0.1, "headsq_parallel");
}

// Second-order convergence (the slabs at the box faces clipped to the chord; first order before, when a
// ray gained or lost up to a slab at each face): the mean error falls about 4x with each doubling of the
// slice count. Asserted: strictly decreasing over 32..256 and at least a factor 20 from 32 to 256 slices
// (second order gives 64; measured 46, against ~9 before the clipping).
TEST(Slice3dFused, ErrorFallsWithSliceCount)
{
    const Scene base = makeScene(perspectiveCamera(), test::designTransferFunction(), 48);
    const Image4d want = reference(base, marschnerLobb41());
    std::vector<double> meanErrors;
    for (int n : {32, 64, 128, 256}) {
        Scene scene = base;
        scene.options = {{"slices", n}};
        const test::ImageError e = test::imageError(test::renderScene(scene, marschnerLobb41()), want);
        report(("ml41 perspective 48x48, slices " + std::to_string(n)).c_str(), e);
        meanErrors.push_back(maxChannel(e.meanAbs));
    }
    for (std::size_t i = 1; i < meanErrors.size(); ++i)
        EXPECT_LT(meanErrors[i], meanErrors[i - 1]);
    EXPECT_GT(meanErrors.front() / meanErrors.back(), 20.0);
}

// The same sum composited in the other order: only float rounding differs. ~256 blends of values
// <= 1, each a few ulp (6e-8): max 5e-5, mean 5e-6.
TEST(Slice3dFused, BackToFrontEqualsFrontToBack)
{
    for (const Camera& camera : {perspectiveCamera(), parallelCamera()}) {
        Scene scene = makeScene(camera, test::designTransferFunction(), 64);
        FrameStats btfStats, ftbStats;
        const Image4f btf = test::renderScene(scene, marschnerLobb41(), &btfStats);
        scene.options = {{"order", "front-to-back"}};
        const Image4f ftb = test::renderScene(scene, marschnerLobb41(), &ftbStats);
        report("back-to-front vs front-to-back", test::imageError(ftb, toDouble(btf)));
        EXPECT_TRUE(test::imagesNear(ftb, toDouble(btf), {.maxAbs = 5e-5, .meanAbs = 5e-6}));
        EXPECT_EQ(btfStats.samples, ftbStats.samples);
    }
}

// Stopping once A >= threshold drops at most the rest of the ray, whose contribution (and the
// background's share it would have absorbed) is bounded by the transmittance left, T <= 1 - threshold
// (colors and background in [0,1]). Plus float rounding (1e-5).
TEST(Slice3dFused, EarlyTerminationChangesPixelsByAtMostOneMinusThreshold)
{
    const double threshold = 0.9;
    Scene scene = makeScene(perspectiveCamera(), test::designTransferFunction(), 64, {{"order", "front-to-back"}});
    FrameStats fullStats, ertStats;
    const Image4f full = test::renderScene(scene, marschnerLobb41(), &fullStats);
    scene.options["early_termination"] = threshold;
    const Image4f ert = test::renderScene(scene, marschnerLobb41(), &ertStats);
    const test::ImageError e = test::imageError(ert, toDouble(full));
    report("early termination 0.9 vs none", e);
    EXPECT_TRUE(test::imagesNear(ert, toDouble(full), {.maxAbs = 1.0 - threshold + 1e-5, .meanAbs = 1.0 - threshold}));
    EXPECT_GT(maxChannel(e.maxAbs), 1e-4);           // it did something ...
    EXPECT_LT(ertStats.samples, fullStats.samples);  // ... by taking fewer samples
    for (std::size_t i = 0; i < ert.pixelCount(); ++i) {
        if (full.pixels()[i].a < threshold - 1e-4) {
            ASSERT_EQ(ert.pixels()[i], full.pixels()[i]) << "pixel " << i << " never reached the threshold";
        }
    }
}

// The pass-by-pass path (slice polygons through raster::draw, fragment program, GL blending) is the
// specification of the fused kernel. They sample the same points up to float rounding of the
// perspective-correct world position, so pixels agree to ~1e-5, except where a pixel center lies
// within the rasterizer's sub-pixel precision of a slice polygon's edge (a ray grazing a box face):
// one path may take that sample and the other not, a difference of at most one slice's opacity
// 1 - exp(-tauMax Delta). Asserted: that max, mean 2e-4, and at most 1% of the pixels differing by
// more than 1e-3 (measured: 1 to 2 of 4096).
TEST(Slice3dRaster, MatchesFused)
{
    for (const Camera& camera : {perspectiveCamera(), parallelCamera()}) {
        for (const char* order : {"back-to-front", "front-to-back"}) {
            Scene scene = makeScene(camera, test::designTransferFunction(), 64, {{"slices", 64}, {"order", order}});
            FrameStats fusedStats, rasterStats;
            const Image4f fused = test::renderScene(scene, marschnerLobb41(), &fusedStats);
            scene.options["path"] = "raster";
            const Image4f raster = test::renderScene(scene, marschnerLobb41(), &rasterStats);
            writePng(std::string("slice3d_raster_") + (camera.parallel ? "parallel" : "perspective"), raster);
            const test::ImageError e = test::imageError(raster, toDouble(fused));
            report((std::string("raster vs fused, 64 slices, ") + order).c_str(), e);
            const double oneSlice = 1.0 - std::exp(-8.0 * maxSliceLength(scene, marschnerLobb41()));
            EXPECT_TRUE(test::imagesNear(raster, toDouble(fused), {.maxAbs = oneSlice, .meanAbs = 2e-4}));
            std::size_t over = 0;
            for (std::size_t i = 0; i < fused.pixelCount(); ++i) {
                const glm::vec4 d = glm::abs(raster.pixels()[i] - fused.pixels()[i]);
                over += std::max({d.r, d.g, d.b, d.a}) > 1e-3f;
            }
            EXPECT_LE(over, fused.pixelCount() / 100);
            // Fragments of the slice polygons vs samples inside the bounds: equal up to boundary rounding.
            EXPECT_NEAR(double(rasterStats.samples), double(fusedStats.samples), 1e-3 * fusedStats.samples);
        }
    }
}

// A camera inside the volume: slices start at the camera (depth 0), on both paths, and the
// reference integrates from the camera on. Same tolerances as above (slice_spacing instead of a count).
TEST(Slice3dFused, CameraInsideVolumeMatchesReference)
{
    Camera camera;
    camera.position = {0.2, 0.1, 0.45};
    camera.focalPoint = {-0.1, -0.2, -1.0};
    camera.viewAngle = 70.0;
    const Scene scene = makeScene(camera, test::designTransferFunction(), 48, {{"slice_spacing", 0.008}});
    checkAgainstReference(scene, marschnerLobb41(), 8.0, "ml41_inside");
    FrameStats stats;
    Scene raster = scene;
    raster.options["path"] = "raster";
    const Image4f fused = test::renderScene(scene, marschnerLobb41(), &stats);
    ASSERT_EQ(stats.passes.size(), 1u);
    EXPECT_EQ(stats.passes[0].name, "slice3d: fused");
    EXPECT_DOUBLE_EQ(stats.extra["slice_spacing"].get<double>(), 0.008);
    const Image4f viaRaster = test::renderScene(raster, marschnerLobb41());
    const test::ImageError e = test::imageError(viaRaster, toDouble(fused));
    report("camera inside: raster vs fused", e);
    EXPECT_TRUE(test::imagesNear(viaRaster, toDouble(fused),
                                 {.maxAbs = 1.0 - std::exp(-8.0 * maxSliceLength(scene, marschnerLobb41())), .meanAbs = 2e-4}));
}

// DESIGN.md: two runs give identical bits (same renderer twice, and a fresh one).
TEST(Slice3dRenderer, RendersAreBitIdentical)
{
    for (const char* path : {"fused", "raster"}) {
        const Scene scene = makeScene(perspectiveCamera(), test::designTransferFunction(), 48, {{"slices", 48}, {"path", path}});
        auto renderer = makeRenderer(test::device(), scene, marschnerLobb41());
        FrameStats stats;
        const Image4f a = renderer->render(stats);
        const Image4f b = renderer->render(stats);
        const Image4f c = test::renderScene(scene, marschnerLobb41());
        ASSERT_EQ(a.pixelCount(), b.pixelCount());
        EXPECT_EQ(std::memcmp(a.pixels().data(), b.pixels().data(), a.pixelCount() * sizeof(glm::vec4)), 0) << path;
        EXPECT_EQ(std::memcmp(a.pixels().data(), c.pixels().data(), a.pixelCount() * sizeof(glm::vec4)), 0) << path;
    }
}

// An edit of the transfer function between frames gives the image a new renderer gives, on both paths.
// On the sphere field (1 - |p|): from a threshold at 0.5 to one at 0.2 (the shell between radius 0.5
// and 0.8 was empty and is not now: stale empty-space flags would skip it), to one with no empty
// brick and a different number of control points, and back.
TEST(Slice3dRenderer, TransferFunctionChangeBetweenFramesEqualsAFreshRenderer)
{
    static const Volume sphere = generateVolume("sphere", {33, 33, 33});
    const TransferFunction threshold({{0.0, {0, 0, 0}, 0.0}, {0.5, {0.3, 0.3, 1}, 0.0}, {1.0, {1, 1, 0.5}, 9.0}});
    const TransferFunction lower({{0.0, {0, 0, 0}, 0.0}, {0.2, {0.3, 0.3, 1}, 0.0}, {1.0, {1, 1, 0.5}, 9.0}});
    const TransferFunction dense = test::designTransferFunction();
    for (const char* path : {"fused", "raster"}) {
        const json options = {{"slices", 48}, {"path", path}};
        auto renderer = makeRenderer(test::device(), makeScene(perspectiveCamera(), threshold, 40, options), sphere);
        FrameStats stats;
        const Image4f first = renderer->render(stats);
        for (const TransferFunction* tf : {&lower, &dense, &threshold}) {
            renderer->setTransferFunction(*tf);
            const Image4f edited = renderer->render(stats);
            const Image4f fresh = test::renderScene(makeScene(perspectiveCamera(), *tf, 40, options), sphere);
            EXPECT_EQ(std::memcmp(edited.pixels().data(), fresh.pixels().data(), edited.pixelCount() * sizeof(glm::vec4)), 0)
                << path << ", " << tf->points().size() << " control points";
            if (tf == &lower) {  // the edit shows: the shell adds to the image
                EXPECT_NE(std::memcmp(edited.pixels().data(), first.pixels().data(), edited.pixelCount() * sizeof(glm::vec4)), 0);
            }
        }
    }
}

// A blob at world (-0.5, +0.5, 0) seen from +z with y up must land in the image's upper left
// (row 0 is the top row), on both paths and both cameras.
TEST(Slice3dRenderer, AsymmetricBlobLandsUpperLeft)
{
    Volume v;
    v.dims = {24, 24, 24};
    v.origin = glm::dvec3(-1.0);
    v.spacing = glm::dvec3(2.0 / 23.0);
    v.source = "blob";
    v.values.resize(v.voxelCount());
    for (int k = 0; k < 24; ++k)
        for (int j = 0; j < 24; ++j)
            for (int i = 0; i < 24; ++i) {
                const glm::dvec3 p = v.origin + glm::dvec3(i, j, k) * v.spacing;
                v.values[(k * 24 + j) * 24 + i] = static_cast<float>(std::exp(-glm::dot(p - glm::dvec3(-0.5, 0.5, 0.0), p - glm::dvec3(-0.5, 0.5, 0.0)) / 0.05));
            }
    const TransferFunction tf({{0.1, {1, 0.3, 0}, 0.0}, {1.0, {1, 0.3, 0}, 20.0}});
    Camera perspective;  // +z, looking at the origin, y up
    Camera parallel = perspective;
    parallel.parallel = true;
    parallel.parallelScale = 1.2;
    for (const Camera& camera : {perspective, parallel})
        for (const char* path : {"fused", "raster"}) {
            const Image4f image = test::renderScene(makeScene(camera, tf, 48, {{"slices", 64}, {"path", path}}, {0, 0, 0}), v);
            writePng(std::string("slice3d_blob_") + path + (camera.parallel ? "_parallel" : "_perspective"), image);
            double quadrant[2][2] = {};
            for (int y = 0; y < 48; ++y)
                for (int x = 0; x < 48; ++x)
                    quadrant[y / 24][x / 24] += image.at(x, y).a;
            EXPECT_GT(quadrant[0][0], 1.0) << path;  // upper left: the blob
            EXPECT_GT(quadrant[0][0], 20.0 * (quadrant[0][1] + quadrant[1][0] + quadrant[1][1])) << path;
        }
}

// Not a test (DESIGN.md: speed is measured by clvr bench): the brief's benchmark configuration,
// run by hand with --gtest_also_run_disabled_tests --gtest_filter='*Benchmark*'.
TEST(Slice3dBenchmark, DISABLED_MarschnerLobb256Image512Slices256)
{
    const Volume volume = generateVolume("marschner-lobb", {256, 256, 256});
    const char* only = std::getenv("CLVR_BENCH_PATH");  // "fused" or "raster": just that one
    for (const char* path : {"fused", "raster"}) {
        if (only && std::string(only) != path)
            continue;
        const Scene scene = makeScene(perspectiveCamera(), test::designTransferFunction(), 512, {{"slices", 256}, {"path", path}});
        auto renderer = makeRenderer(test::device(), scene, volume);
        std::vector<double> frame, device;
        FrameStats stats;
        Image4f image;
        renderer->render(stats);  // warm-up
        const std::clock_t cpu0 = std::clock();
        for (int i = 0; i < 5; ++i) {
            image = renderer->render(stats);
            frame.push_back(stats.frameMs);
            double ms = 0.0;
            for (const PassTime& p : stats.passes)
                ms += p.ms;
            device.push_back(ms);
        }
        const double cpuSeconds = double(std::clock() - cpu0) / CLOCKS_PER_SEC / 5.0;
        writePng(std::string("slice3d_bench_") + path, image);
        std::sort(frame.begin(), frame.end());
        std::sort(device.begin(), device.end());
        std::printf("[ bench    ] %s: %s, median frame %.1f ms (device %.1f ms), samples %llu, %.1f M samples/s, "
                    "compile %.0f ms\n",
                    path, test::device().description().c_str(), frame[2], device[2],
                    static_cast<unsigned long long>(stats.samples), stats.samples / frame[2] * 1e-3,
                    test::device().compileMs());
        // Process CPU time per frame over the device's 2 compute units: the frame time this machine
        // would give without other load.
        std::printf("    CPU %.1f ms per frame (%.1f M samples per CPU second)\n", cpuSeconds * 1e3,
                    stats.samples / cpuSeconds * 1e-6);
        for (const PassTime& p : stats.passes)
            std::printf("    %s %.1f ms\n", p.name.c_str(), p.ms);
    }
}

}  // namespace
}  // namespace clvr
