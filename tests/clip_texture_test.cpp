// tests/clip_texture_test.cpp — slice3d clipped by a second "stencil" texture (seeds/003, "Clipping
// with arbitrary clipping geometry"; host/optics/clip_texture.h): the signed-distance textures of a sphere, a
// box and a cylinder and a voxel mask, inside and inverse, on the fused and the raster path, against
// the reference integral restricted to the unclipped parts of each ray; the placement (offset, matrix)
// moving the clipped region as moving the shape does, without a new texture; bad input.
#include "host/optics/clip_texture.h"

#include "host/runtime/errors.h"
#include "host/io/generators.h"
#include "host/io/image_io.h"
#include "host/reference/reference_integral.h"
#include "host/render/renderer.h"
#include "host/render/grid/slice3d.h"
#include "tests/support/clip_reference.h"
#include "tests/support/test_util.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>

namespace clvr {
namespace {

using nlohmann::json;

constexpr double kTauMax = 8.0;  // of mlTransferFunction

// The cameras of tests/slice3d_test.cpp.
Camera perspectiveCamera()
{
    return test::obliquePerspectiveCamera(40.0);
}

Camera parallelCamera()
{
    return test::obliqueParallelCamera(1.8);
}

const Volume& marschnerLobb41()
{
    static const Volume v = generateVolume("marschner-lobb", {41, 41, 41});
    return v;
}

constexpr int kSlices = 512;

Scene makeScene(const Camera& camera, const json& clipTexture, const std::string& path = "fused",
                const std::filesystem::path& baseDir = test::repoData("scenes"))
{
    Scene s;
    s.technique = "slice3d";
    s.baseDir = baseDir;
    s.camera = camera;
    s.image = ImageSpec{64, 64, {0.1, 0.2, 0.3}};
    s.transferFunction = test::designTransferFunction(kTauMax);
    s.options = {{"slices", kSlices}, {"path", path}, {"clip_texture", clipTexture}};
    return s;
}

Image4f render(const Scene& scene, FrameStats* stats = nullptr)
{
    auto renderer = makeRenderer(test::device(), scene, marschnerLobb41());
    FrameStats local;
    return renderer->render(stats ? *stats : local);
}

ClipTextureSpec specOf(const Scene& scene) { return *parseSlice3dOptions(scene.options).clipTexture; }

// The references of tests/support/clip_reference.h for this file's volume and the scene's clip texture.
Image4d shapeReference(const Scene& scene) { return test::shapeClipReference(marschnerLobb41(), scene, specOf(scene)); }

Image4d textureReference(const Scene& scene) { return test::textureClipReference(marschnerLobb41(), scene, specOf(scene)); }

void report(const std::string& label, const test::ImageError& e, const test::Tolerance& t)
{
    std::printf("[ measured ] %s: max %.3g %.3g %.3g %.3g, mean %.3g %.3g %.3g %.3g (tolerance %.3g / %.3g)\n",
                label.c_str(), e.maxAbs.r, e.maxAbs.g, e.maxAbs.b, e.maxAbs.a, e.meanAbs.r, e.meanAbs.g, e.meanAbs.b,
                e.meanAbs.a, t.maxAbs, t.meanAbs);
}

void writePng(const std::string& name, const Image4f& image)
{
    std::filesystem::create_directories("test_output");
    writeImage("test_output/" + name + ".png", image);
}

// Slicing tolerance, derived as tests/slice3d_clip_test.cpp's: each place where a ray's integrated
// part begins or ends lies inside some slice's slab, whose sample is taken whole or not at all, so a
// ray gains or loses at most one slice's opacity 1 - exp(-tauMax Delta) per boundary; B boundaries (2
// of the box, 2 of a convex clip region; a ray leaving the texture's box counts as well). Mean: 0.01
// tauMax deltaS per boundary, as there.
test::Tolerance sliceTolerance(const Scene& scene, int boundaries)
{
    const Camera& c = *scene.camera;
    const Volume& v = marschnerLobb41();
    const SlicePlan plan = planSlices(c, v.boundsMin(), v.boundsMax(), parseSlice3dOptions(scene.options));
    const Ray corner = c.ray(0, 0, scene.image.width, scene.image.height);
    const double maxSliceLength = plan.deltaS / glm::dot(corner.direction, c.forward());
    return {boundaries * (1.0 - std::exp(-kTauMax * maxSliceLength)), 0.01 * boundaries * kTauMax * plan.deltaS};
}

// The render against the texture's own crossings (the slicing error alone).
test::ImageError checkAgainstTexture(const Scene& scene, const std::string& label, int boundaries = 4)
{
    FrameStats stats;
    const Image4f image = render(scene, &stats);
    writePng("clip_texture_" + label, image);
    const Image4d want = textureReference(scene);
    const test::Tolerance tolerance = sliceTolerance(scene, boundaries);
    const test::ImageError e = test::imageError(image, want);
    report(label + " vs texture crossings", e, tolerance);
    EXPECT_TRUE(test::imagesNear(image, want, tolerance)) << label;
    EXPECT_EQ(stats.extra["path"], scene.options["path"]);
    EXPECT_EQ(stats.extra["clip_texture_inverse"], specOf(scene).inverse);
    return e;
}

double maxChannel(const glm::dvec4& v) { return std::max({v.r, v.g, v.b, v.a}); }

const json kSphere = {{"shape", "sphere"}, {"center", {0.1, -0.05, 0.0}}, {"radius", 0.75}};
const json kBox = {{"shape", "box"}, {"min", {-0.7, -0.4, -0.9}}, {"max", {0.5, 0.8, 0.6}}};
const json kCylinder = {{"shape", "cylinder"}, {"center", {0.0, 0.1, 0.0}}, {"axis", {1, 1, 0}},
                        {"radius", 0.45}, {"height", 1.6}};

// The texture's geometry alone (no rendering): where the exact signed distance f of the placed shape
// is farther from 0 than delta, the texture must agree with it. f is 1-Lipschitz and the trilinear
// value is a convex combination of f at the 8 texel centers around p, each within the cell diagonal
// sqrt(3) h of p, so |f(p)| > sqrt(3) h fixes the sign (any shape). For the sphere, tighter: f = |p - c|
// - r has second derivatives <= 1 / rho per axis, so trilinear interpolation is off by at most
// 3 h^2 / (8 rho), rho >= r - sqrt(3) h near the surface; plus float rounding of the texels (1e-6 r).
TEST(ClipTexture, TextureAgreesWithTheShapeAwayFromItsSurface)
{
    test::Rng rng(7);
    const json placedBox = {{"shape", "box"}, {"min", {-0.7, -0.4, -0.9}}, {"max", {0.5, 0.8, 0.6}},
                            {"offset", {0.2, -0.1, 0.05}}, {"matrix", {{0.8, -0.6, 0}, {0.6, 0.8, 0}, {0, 0, 1.2}}}};
    for (const json& j : {kSphere, kBox, kCylinder, placedBox}) {
        const ClipTextureSpec spec = parseClipTextureSpec(j, "clip_texture");
        const ClipTexture texture = makeClipTexture(spec, ".");
        const glm::dmat4 coordinates = clipTextureCoordinates(texture, spec.offset, spec.matrix);
        const double h = texture.spacing.x;
        const bool sphere = spec.shape == ClipTextureSpec::Shape::Sphere;
        const double delta = sphere ? 3.0 * h * h / (8.0 * (spec.radius - std::sqrt(3.0) * h)) + 1e-6 * spec.radius
                                    : std::sqrt(3.0) * h;
        // Points q drawn in the texture's own frame and placed (p); the placed texture at p must say
        // what the unplaced shape says at q, whatever the matrix does to distances.
        int checked = 0, disagree = 0, total = 0;
        double worst = 0.0;
        for (int i = 0; i < 20000; ++i) {
            const glm::dvec3 q = texture.origin + glm::dvec3(rng.uniform(), rng.uniform(), rng.uniform()) *
                                                      glm::dvec3(texture.dims() - 1) * texture.spacing;
            const glm::dvec3 p = texture.pivot + spec.offset + spec.matrix * (q - texture.pivot);  // placed
            const double f = shapeSignedDistance(spec, q);  // in the texture's own frame
            const bool in = insideClipTexture(texture, coordinates, p);
            ++total;
            if (in != (f < 0.0)) {
                ++disagree;
                worst = std::max(worst, std::abs(f));
            }
            if (std::abs(f) > delta) {
                ++checked;
                EXPECT_EQ(in, f < 0.0) << j.dump() << " at " << p.x << " " << p.y << " " << p.z << ", f = " << f;
            }
        }
        std::printf("[ measured ] %s: %d x %d x %d texels, h %.4g; %d of %d points disagree, the farthest at "
                    "|f| = %.3g (bound %.3g = %.3g h)\n",
                    j["shape"].get<std::string>().c_str(), texture.dims().x, texture.dims().y, texture.dims().z, h,
                    disagree, total, worst, delta, delta / h);
        EXPECT_GT(checked, total / 2);
    }
}

TEST(ClipTexture, ShapesMatchTheirTextureReferenceOnBothPaths)
{
    for (const std::string path : {"fused", "raster"}) {
        checkAgainstTexture(makeScene(perspectiveCamera(), kSphere, path), "sphere_perspective_" + path);
        checkAgainstTexture(makeScene(parallelCamera(), kBox, path), "box_parallel_" + path);
        checkAgainstTexture(makeScene(perspectiveCamera(), kCylinder, path), "cylinder_perspective_" + path);
    }
}

// The sphere's texture against the exact sphere, for the render compared with the exact reference:
// the two inside sets differ only within the shell ||p - c| - r| <= delta (delta as in
// TextureAgreesWithTheShapeAwayFromItsSurface). A line runs at most 4 sqrt(r delta) inside that shell
// (the outer chord at the inner sphere's tangent), so a ray's integrated part changes by at most that
// length of medium: max + 1 - exp(-tauMax 4 sqrt(r delta)). Mean: a ray meeting the surface at angle
// theta to its normal moves each of its 2 crossings by <= delta / cos theta, and over a disc of rays
// the mean of 1 / cos theta is 2: mean + tauMax * 2 * 2 * delta * 2 = 8 tauMax delta.
test::Tolerance sphereTextureTerm(const ClipTexture& texture, double radius)
{
    const double h = texture.spacing.x;
    const double delta = 3.0 * h * h / (8.0 * (radius - std::sqrt(3.0) * h)) + 1e-6 * radius;
    return {1.0 - std::exp(-kTauMax * 4.0 * std::sqrt(radius * delta)), 8.0 * kTauMax * delta};
}

test::ImageError checkAgainstShape(const Scene& scene, const std::string& label, const test::Tolerance& extra,
                                   int boundaries = 4)
{
    const Image4f image = render(scene);
    writePng("clip_texture_" + label, image);
    const Image4d want = shapeReference(scene);
    test::Tolerance tolerance = sliceTolerance(scene, boundaries);
    tolerance.maxAbs = std::min(1.0, tolerance.maxAbs + extra.maxAbs);
    tolerance.meanAbs += extra.meanAbs;
    const test::ImageError e = test::imageError(image, want);
    report(label + " vs exact shape", e, tolerance);
    EXPECT_TRUE(test::imagesNear(image, want, tolerance)) << label;
    return e;
}

TEST(ClipTexture, SphereAndInverseMatchTheExactReferenceOnBothPaths)
{
    const ClipTextureSpec spec = parseClipTextureSpec(kSphere, "clip_texture");
    const test::Tolerance term = sphereTextureTerm(makeClipTexture(spec, "."), spec.radius);
    json inverse = kSphere;
    inverse["inverse"] = true;
    for (const std::string path : {"fused", "raster"}) {
        checkAgainstShape(makeScene(perspectiveCamera(), kSphere, path), "sphere_perspective_" + path, term);
        checkAgainstShape(makeScene(parallelCamera(), kSphere, path), "sphere_parallel_" + path, term);
        checkAgainstShape(makeScene(perspectiveCamera(), inverse, path), "sphere_inverse_perspective_" + path, term);
    }
    checkAgainstTexture(makeScene(parallelCamera(), inverse, "fused"), "sphere_inverse_parallel_fused");
}

// Box and cylinder: the texture is exact on flat faces (the distance is linear across a texel there)
// and on the cylinder's side up to the sphere's curvature term; it differs from the shape only within
// sqrt(3) h of an edge or rim. A ray running along an edge can stay in that tube for the edge's whole
// length, so no useful max bound: max 1 (still no NaN, and the texture reference above holds the
// slicing max). Mean, for the parallel camera: at most the pixels whose rays pass within sqrt(3) h of
// an edge can differ, by at most 1: the edges' total length x 2 sqrt(3) h over the image's world area.
TEST(ClipTexture, BoxAndCylinderMatchTheExactReferenceInTheMean)
{
    const Camera camera = parallelCamera();
    const double imageArea = 4.0 * camera.parallelScale * camera.parallelScale;  // square image
    for (const json& j : {kBox, kCylinder}) {
        const ClipTextureSpec spec = parseClipTextureSpec(j, "clip_texture");
        const double h = makeClipTexture(spec, ".").spacing.x;
        const glm::dvec3 e = spec.max - spec.min;
        const double edges = spec.shape == ClipTextureSpec::Shape::Box ? 4.0 * (e.x + e.y + e.z)
                                                                       : 2.0 * 2.0 * M_PI * spec.radius;
        const test::Tolerance term{1.0, edges * 2.0 * std::sqrt(3.0) * h / imageArea};
        const std::string name = j["shape"].get<std::string>();
        checkAgainstShape(makeScene(camera, j, "fused"), name + "_parallel_exact_fused", term);
    }
}

// Moving the clip texture by its coordinates moves the clipped region exactly as moving the shape:
// the texture made for the unmoved sphere, placed by offset (and a rotation with scaling for the box),
// against the exact reference of the moved shape (shapeClipIntervals applies the same placement).
TEST(ClipTexture, OffsetAndMatrixMoveTheClippedRegionLikeTheShape)
{
    json moved = kSphere;
    moved["offset"] = {0.25, -0.2, 0.15};
    const ClipTextureSpec spec = parseClipTextureSpec(kSphere, "clip_texture");
    const test::Tolerance term = sphereTextureTerm(makeClipTexture(spec, "."), spec.radius);
    for (const std::string path : {"fused", "raster"})
        checkAgainstShape(makeScene(perspectiveCamera(), moved, path), "sphere_offset_" + path, term);
    // The moved sphere as a new shape at the moved center: the same region.
    json atMovedCenter = kSphere;
    atMovedCenter["center"] = {0.35, -0.25, 0.15};
    const Image4d a = shapeReference(makeScene(perspectiveCamera(), moved)),
                  b = shapeReference(makeScene(perspectiveCamera(), atMovedCenter));
    double diff = 0.0;
    for (std::size_t i = 0; i < a.pixelCount(); ++i)
        diff = std::max(diff, maxChannel(glm::abs(a.pixels()[i] - b.pixels()[i])));
    EXPECT_LT(diff, 1e-5);  // two converged references of the same region: within their 1e-6 tolerance
    json box = kBox;
    box["offset"] = {0.1, 0.2, -0.1};
    box["matrix"] = {{0.8, -0.6, 0.0}, {0.6, 0.8, 0.0}, {0.0, 0.0, 0.9}};  // 36.87 degrees about z, z scaled
    checkAgainstTexture(makeScene(parallelCamera(), box, "fused"), "box_rotated_fused");
    checkAgainstTexture(makeScene(parallelCamera(), box, "raster"), "box_rotated_raster");
}

// setSlice3dClipPlacement moves the clip for the next frame without making the texture again: the
// frame is bit-identical to a new renderer's made with that placement in the scene, and differs from
// the unmoved frame.
TEST(ClipTexture, MovingBetweenFramesEqualsAFreshRenderer)
{
    for (const std::string path : {"fused", "raster"}) {
        const Scene still = makeScene(perspectiveCamera(), kSphere, path);
        auto renderer = makeRenderer(test::device(), still, marschnerLobb41());
        FrameStats stats;
        const Image4f before = renderer->render(stats);
        const glm::dvec3 offset(0.25, -0.2, 0.15);
        const glm::dmat3 matrix(glm::dvec3(0.8, 0.6, 0.0), glm::dvec3(-0.6, 0.8, 0.0), glm::dvec3(0.0, 0.0, 1.0));
        setSlice3dClipPlacement(*renderer, offset, matrix);
        const Image4f after = renderer->render(stats);
        json moved = kSphere;
        moved["offset"] = {offset.x, offset.y, offset.z};
        moved["matrix"] = {{0.8, -0.6, 0.0}, {0.6, 0.8, 0.0}, {0.0, 0.0, 1.0}};  // rows of the same matrix
        const Image4f fresh = render(makeScene(perspectiveCamera(), moved, path));
        ASSERT_EQ(after.pixels().size(), fresh.pixels().size());
        EXPECT_EQ(std::memcmp(after.pixels().data(), fresh.pixels().data(), after.pixels().size() * sizeof(glm::vec4)), 0)
            << path;
        EXPECT_NE(std::memcmp(after.pixels().data(), before.pixels().data(), after.pixels().size() * sizeof(glm::vec4)), 0)
            << path;
    }
    auto renderer = makeRenderer(test::device(), makeScene(perspectiveCamera(), kSphere), marschnerLobb41());
    EXPECT_THROW(setSlice3dClipPlacement(*renderer, glm::dvec3(0.0), glm::dmat3(0.0)), InputError);  // singular
}

// The clip test sits inside the fused kernel's loops: empty-space skipping must still give the same
// bits (a clipped sample and a stepped-over one both leave the pixel unchanged), and front to back
// the same sum as back to front up to float rounding (tests/slice3d_test.cpp's 5e-5 / 5e-6).
TEST(ClipTexture, SkippingAndOrderAreUnchangedByClipping)
{
    json inverse = kSphere;
    inverse["inverse"] = true;
    for (const json& clip : {kSphere, inverse}) {
        Scene scene = makeScene(perspectiveCamera(), clip, "fused");
        scene.transferFunction = TransferFunction({{0.0, {0, 0, 0}, 0.0}, {0.45, {0, 0, 0}, 0.0}, {0.5, {1, 0.5, 0}, 4.0},
                                                   {1.0, {1, 1, 1}, kTauMax}});  // tau 0 below 0.45: empty bricks
        FrameStats withSkip, without;
        const Image4f a = render(scene, &withSkip);
        scene.options["empty_space_skipping"] = false;
        const Image4f b = render(scene, &without);
        EXPECT_GT(withSkip.extra["samples_skipped"].get<std::uint64_t>(), 0u);
        EXPECT_EQ(std::memcmp(a.pixels().data(), b.pixels().data(), a.pixels().size() * sizeof(glm::vec4)), 0);
        scene.options["order"] = "front-to-back";
        const Image4f c = render(scene);
        Image4d want(a.width(), a.height());
        for (std::size_t i = 0; i < a.pixelCount(); ++i)
            want.pixels()[i] = glm::dvec4(a.pixels()[i]);
        report("front-to-back vs back-to-front " + clip.dump(), test::imageError(c, want), {5e-5, 5e-6});
        EXPECT_TRUE(test::imagesNear(c, want, {.maxAbs = 5e-5, .meanAbs = 5e-6}));
    }
}

// A voxel mask as a raw float32 file in `dir`, on a 33^3 grid over the volume box (spacing 1/16): binary
// (1 inside the sphere of radius r about c, else 0) or soft (0.5 - f / (4 h), clamped to [0, 1]).
std::filesystem::path writeMask(const test::TempDir& dir, const glm::dvec3& c, double r, bool soft, double& spacing)
{
    const Volume& v = marschnerLobb41();
    const int n = 33;
    spacing = (v.boundsMax().x - v.boundsMin().x) / (n - 1);
    std::string bytes;
    std::vector<float> values;
    for (int z = 0; z < n; ++z)
        for (int y = 0; y < n; ++y)
            for (int x = 0; x < n; ++x) {
                const glm::dvec3 p = v.boundsMin() + glm::dvec3(x, y, z) * spacing;
                const double f = glm::length(p - c) - r;
                values.push_back(soft ? static_cast<float>(std::clamp(0.5 - f / (4.0 * spacing), 0.0, 1.0))
                                      : (f < 0.0 ? 1.0f : 0.0f));
            }
    bytes.assign(reinterpret_cast<const char*>(values.data()), values.size() * sizeof(float));
    const std::filesystem::path path = dir / (soft ? "soft_mask.raw" : "mask.raw");
    test::writeFile(path, bytes);
    return path;
}

json maskSpec(const std::filesystem::path& file, double spacing)
{
    const glm::dvec3 lo = marschnerLobb41().boundsMin();
    return {{"file", file.filename().string()}, {"dims", {33, 33, 33}}, {"type", "float32"}, {"endian", "little"},
            {"spacing", {spacing, spacing, spacing}}, {"origin", {lo.x, lo.y, lo.z}}};
}

// A binary mask: its 0.5 level is a staircase-like surface, so a ray may cross it more than twice;
// against the texture reference with 6 boundaries (as the torus mesh: box 2 + 4). A soft mask (0.5 -
// f / (4 h), clamped: linear in the distance within 2 h >= sqrt(3) h of the surface, so its 0.5 level
// is the trilinear zero set of the distance, as a shape texture) against the exact sphere, with the
// sphere's terms for its texel size.
TEST(ClipTexture, VoxelMasksMatchTheirReferences)
{
    const test::TempDir dir;
    const glm::dvec3 c(0.1, -0.05, 0.0);
    const double r = 0.75;
    double spacing = 0.0;
    const std::filesystem::path binary = writeMask(dir, c, r, false, spacing);
    const std::filesystem::path soft = writeMask(dir, c, r, true, spacing);
    for (const std::string path : {"fused", "raster"}) {
        const Scene scene = makeScene(perspectiveCamera(), {{"mask", maskSpec(binary, spacing)}}, path, dir.path());
        checkAgainstTexture(scene, "mask_binary_" + path, 6);
        json inverse = {{"mask", maskSpec(binary, spacing)}, {"inverse", true}};
        checkAgainstTexture(makeScene(parallelCamera(), inverse, path, dir.path()), "mask_binary_inverse_" + path, 6);
    }
    ClipTexture texture;
    texture.spacing = glm::dvec3(spacing);
    const Scene softScene = makeScene(perspectiveCamera(), {{"mask", maskSpec(soft, spacing)}}, "fused", dir.path());
    // The exact reference of the same sphere: a sphere scene with the same camera.
    const Image4f image = render(softScene);
    const Scene sphereScene = makeScene(perspectiveCamera(), {{"shape", "sphere"}, {"center", {c.x, c.y, c.z}}, {"radius", r}});
    const Image4d want = shapeReference(sphereScene);
    test::Tolerance tolerance = sliceTolerance(softScene, 4);
    const test::Tolerance term = sphereTextureTerm(texture, r);
    tolerance.maxAbs += term.maxAbs;
    tolerance.meanAbs += term.meanAbs;
    const test::ImageError e = test::imageError(image, want);
    report("soft mask vs exact sphere", e, tolerance);
    EXPECT_TRUE(test::imagesNear(image, want, tolerance));
}

// The mask of data/scenes/engine-clip-texture-mask.json (an ASCII NRRD, given as a file name): read in
// its own placement (9x9x5 points 32 apart), inside on the plus-shaped bars from z = 16 (the 0.5 level
// between the rows k = 0 and 1) up, and moved by an offset as the texture coordinates say.
TEST(ClipTexture, MaskFileFromTheEngineSceneIsReadAndPlaced)
{
    const ClipTextureSpec spec = parseClipTextureSpec({{"mask", "../masks/engine-plus.nrrd"}}, "clip_texture");
    const ClipTexture texture = makeClipTexture(spec, test::repoData("scenes"));
    EXPECT_EQ(texture.dims(), glm::ivec3(9, 9, 5));
    EXPECT_EQ(texture.spacing, glm::dvec3(32.0));
    const glm::dmat4 still = clipTextureCoordinates(texture, glm::dvec3(0.0), glm::dmat3(1.0));
    EXPECT_TRUE(insideClipTexture(texture, still, {128, 128, 64}));   // where the bars cross
    EXPECT_TRUE(insideClipTexture(texture, still, {20, 128, 100}));   // one bar, near its end
    EXPECT_FALSE(insideClipTexture(texture, still, {20, 20, 64}));    // a corner between the bars
    EXPECT_FALSE(insideClipTexture(texture, still, {128, 128, 15}));  // below z = 16
    EXPECT_TRUE(insideClipTexture(texture, still, {128, 128, 17}));
    EXPECT_FALSE(insideClipTexture(texture, still, {128, 128, 129}));  // above the mask's box
    const glm::dmat4 moved = clipTextureCoordinates(texture, glm::dvec3(0.0, 0.0, 40.0), glm::dmat3(1.0));
    EXPECT_FALSE(insideClipTexture(texture, moved, {128, 128, 55}));  // the bottom moved to z = 56
    EXPECT_TRUE(insideClipTexture(texture, moved, {128, 128, 57}));
}

void expectInputError(const json& options, const std::string& fragment)
{
    try {
        parseSlice3dOptions(options);
        ADD_FAILURE() << "no InputError for " << options.dump();
    } catch (const InputError& e) {
        EXPECT_NE(std::string(e.what()).find(fragment), std::string::npos) << e.what();
    }
}

TEST(ClipTexture, BadOptionsThrowInputErrorNamingTheKey)
{
    expectInputError({{"clip_texture", true}}, "options.clip_texture: must be an object");
    expectInputError({{"clip_texture", json::object()}}, "options.clip_texture: give either \"shape\"");
    expectInputError({{"clip_texture", {{"shape", "torus"}}}},
                     "options.clip_texture.shape: must be \"sphere\", \"box\" or \"cylinder\", got \"torus\"");
    expectInputError({{"clip_texture", {{"shape", "sphere"}, {"radius", -1}}}},
                     "options.clip_texture.radius: must be a positive number, got -1");
    expectInputError({{"clip_texture", {{"shape", "sphere"}, {"half_size", 1}}}},
                     "options.clip_texture.half_size: unknown key (known: shape, center, radius, resolution, inverse, "
                     "offset, matrix)");
    expectInputError({{"clip_texture", {{"shape", "box"}, {"min", {0, 0, 0}}, {"max", {1, 0, 1}}}}},
                     "options.clip_texture.max: must be greater than min");
    expectInputError({{"clip_texture", {{"shape", "cylinder"}, {"axis", {0, 0, 0}}}}},
                     "options.clip_texture.axis: must not be zero");
    expectInputError({{"clip_texture", {{"shape", "sphere"}, {"resolution", 4}}}},
                     "options.clip_texture.resolution: must be an integer in [8, 512], got 4");
    expectInputError({{"clip_texture", {{"shape", "sphere"}, {"inverse", "yes"}}}},
                     "options.clip_texture.inverse: must be true or false");
    expectInputError({{"clip_texture", {{"shape", "sphere"}, {"offset", {1, 2}}}}},
                     "options.clip_texture.offset: must be [x, y, z]");
    expectInputError({{"clip_texture", {{"shape", "sphere"}, {"matrix", {{1, 0, 0}, {0, 1, 0}, {1, 1, 0}}}}}},
                     "options.clip_texture.matrix: must be invertible");
    expectInputError({{"clip_texture", {{"mask", 3}}}}, "options.clip_texture.mask: must be a volume file name");
    expectInputError({{"clip_texture", {{"mask", "m.nrrd"}, {"shape", "sphere"}}}},
                     "options.clip_texture: give either");
    expectInputError({{"clip_texture", {{"mask", "m.nrrd"}, {"radius", 1}}}},
                     "options.clip_texture.radius: unknown key (known: mask, inverse, offset, matrix)");
    expectInputError({{"foo", 1}}, "clip, clip_texture)");
    // Given, the clip texture keeps the default fused path.
    EXPECT_EQ(parseSlice3dOptions({{"clip_texture", kSphere}}).path, Slice3dOptions::Path::Fused);
}

void expectRenderError(const Scene& scene, const std::string& fragment)
{
    try {
        render(scene);
        ADD_FAILURE() << "no InputError";
    } catch (const InputError& e) {
        EXPECT_NE(std::string(e.what()).find(fragment), std::string::npos) << e.what();
    }
}

TEST(ClipTexture, BadMaskFilesAreClearErrors)
{
    const test::TempDir dir;
    expectRenderError(makeScene(perspectiveCamera(), {{"mask", "no-such-mask.nrrd"}}, "fused", dir.path()),
                      "no-such-mask.nrrd: no such file (clip texture mask)");
    // A mask with a NaN: the volume reader's check names the file and the value.
    std::vector<float> values(4 * 4 * 4, 1.0f);
    values[5] = std::nanf("");
    test::writeFile(dir / "nan.raw", std::string(reinterpret_cast<const char*>(values.data()), values.size() * 4));
    const json nan = {{"file", "nan.raw"}, {"dims", {4, 4, 4}}, {"type", "float32"}, {"endian", "little"}};
    expectRenderError(makeScene(perspectiveCamera(), {{"mask", nan}}, "fused", dir.path()),
                      "options.clip_texture.mask: " + (dir / "nan.raw").string() + ": value at grid point (1,1,0) is NaN");
    // A mask of the wrong size, and one whose raw layout is incomplete: the reader's message, prefixed.
    expectRenderError(makeScene(perspectiveCamera(), {{"mask", {{"file", "nan.raw"}, {"dims", {4, 4, 4}}}}}, "fused", dir.path()),
                      "options.clip_texture.mask: volume: \"type\" is missing");
    const json small = {{"file", "nan.raw"}, {"dims", {5, 5, 5}}, {"type", "float32"}, {"endian", "little"}};
    try {
        render(makeScene(perspectiveCamera(), {{"mask", small}}, "fused", dir.path()));
        ADD_FAILURE() << "no InputError";
    } catch (const InputError& e) {
        EXPECT_NE(std::string(e.what()).find("nan.raw"), std::string::npos) << e.what();
    }
}

}  // namespace
}  // namespace clvr
