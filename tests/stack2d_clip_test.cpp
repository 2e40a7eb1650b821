// tests/stack2d_clip_test.cpp — stack2d clipped by a second "stencil" texture (seeds/003, "Clipping
// with arbitrary clipping geometry"; host/optics/clip_texture.h, the same options.clip_texture as slice3d):
// sphere (inside, inverse, moved by an offset) and box, both cameras, the fused path and the raster path
// with one slice per quad and three slices per polygon, against the reference integral restricted to the clip intervals (as
// tests/clip_texture_test.cpp builds it); a clip texture holding the whole volume changes nothing;
// clipped samples are no iso-surface hits; bad input gives slice3d's errors.
#include "host/optics/clip_texture.h"

#include "host/runtime/errors.h"
#include "host/io/generators.h"
#include "host/io/image_io.h"
#include "host/reference/reference_integral.h"
#include "host/render/renderer.h"
#include "host/render/grid/slice3d.h"
#include "host/render/grid/stack2d.h"
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

// An "iso" at `value`, every other key left out (gradient shading, the headlight).
IsoSpec isoAt(double value)
{
    IsoSpec iso;
    iso.value = value;
    return iso;
}

constexpr double kTauMax = 8.0;  // of mlTransferFunction
constexpr int kSize = 48;

// The cameras of tests/stack2d_test.cpp (z stack, and x stack for the parallel one).
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

constexpr int kIntermediate = 1;
constexpr int kFused = 0;  // makeScene's slicesPerPolygon for the fused path

// slicesPerPolygon k >= 1: the raster path, k slices per quad; kFused: the fused path.
Scene makeScene(const Camera& camera, const json& clipTexture, int slicesPerPolygon)
{
    Scene s;
    s.technique = "stack2d";
    s.baseDir = test::repoData("scenes");
    s.camera = camera;
    s.image = ImageSpec{kSize, kSize, {0.1, 0.2, 0.3}};
    s.transferFunction = test::designTransferFunction(kTauMax);
    s.options = {{"intermediate", kIntermediate},
                 {"slices_per_polygon", std::max(slicesPerPolygon, 1)},
                 {"path", slicesPerPolygon == kFused ? "fused" : "raster"}};
    if (!clipTexture.is_null())
        s.options["clip_texture"] = clipTexture;
    return s;
}

Image4f render(const Scene& scene, const Volume& volume = marschnerLobb41(), FrameStats* stats = nullptr)
{
    auto renderer = makeRenderer(test::device(), scene, volume);
    FrameStats local;
    return renderer->render(stats ? *stats : local);
}

ClipTextureSpec specOf(const Scene& scene) { return *parseStack2dOptions(scene.options).clipTexture; }

// The references of tests/support/clip_reference.h for this file's volume and the scene's clip texture.
Image4d shapeReference(const Scene& scene) { return test::shapeClipReference(marschnerLobb41(), scene, specOf(scene)); }

Image4d textureReference(const Scene& scene) { return test::textureClipReference(marschnerLobb41(), scene, specOf(scene)); }

// Smallest |cos| between a pixel's ray and the stack axis over the image: the longest slab.
double minCos(const Camera& camera, int size, int axis)
{
    double c = 1.0;
    for (int y = 0; y < size; ++y)
        for (int x = 0; x < size; ++x)
            c = std::min(c, std::abs(glm::normalize(camera.ray(x, y, size, size).direction)[axis]));
    return c;
}

// Slab tolerance, derived as stack2d's own (tests/stack2d_test.cpp, docs/stack2d.md) and slice3d's
// clip tolerance (tests/clip_texture_test.cpp): every place where a ray's integrated part begins or
// ends lies inside some slice's slab, whose sample is taken whole or not at all, so the ray gains or
// loses at most one slab's opacity 1 - exp(-tau_max Delta_max) per boundary, Delta_max the longest
// slab along any pixel's ray (spacing / (intermediate + 1) / min |cos|). B boundaries: 2 of the box,
// 2 of a convex clip region (or of the inverse sphere's hole). Mean: first order in the slab, 0.01
// tau_max Delta_max per boundary (stack2d's own 0.02 for its 2 box boundaries).
test::Tolerance slabTolerance(const Scene& scene, int boundaries)
{
    const double deltaMax = 2.0 / 40.0 / (kIntermediate + 1) / minCos(*scene.camera, kSize, stackAxis(*scene.camera));
    return {boundaries * (1.0 - std::exp(-kTauMax * deltaMax)), 0.01 * boundaries * kTauMax * deltaMax};
}

// The sphere's texture against the exact sphere (tests/clip_texture_test.cpp's sphereTextureTerm):
// the inside sets differ only within the shell ||p - c| - r| <= delta, delta = 3 h^2 / (8 (r - sqrt(3)
// h)) + 1e-6 r (trilinear interpolation of the distance); a line runs at most 4 sqrt(r delta) in that
// shell (max term 1 - exp(-tau_max 4 sqrt(r delta))), and a ray's 2 crossings move by <= delta / cos,
// whose mean over a disc is 2 delta each (mean term 8 tau_max delta).
test::Tolerance sphereTextureTerm(const ClipTexture& texture, double radius)
{
    const double h = texture.spacing.x;
    const double delta = 3.0 * h * h / (8.0 * (radius - std::sqrt(3.0) * h)) + 1e-6 * radius;
    return {1.0 - std::exp(-kTauMax * 4.0 * std::sqrt(radius * delta)), 8.0 * kTauMax * delta};
}

double maxChannel(const glm::dvec4& v) { return std::max({v.r, v.g, v.b, v.a}); }

void writePng(const std::string& name, const Image4f& image)
{
    std::filesystem::create_directories("test_output");
    writeImage("test_output/" + name + ".png", image);
}

test::ImageError check(const Scene& scene, const Image4d& want, const test::Tolerance& tolerance, const std::string& label)
{
    FrameStats stats;
    const Image4f image = render(scene, marschnerLobb41(), &stats);
    writePng("stack2d_clip_" + label, image);
    const test::ImageError e = test::imageError(image, want);
    std::printf("[ measured ] %s: max %.3g, mean %.3g (tolerance %.3g / %.3g)\n", label.c_str(), maxChannel(e.maxAbs),
                maxChannel(e.meanAbs), tolerance.maxAbs, tolerance.meanAbs);
    EXPECT_TRUE(test::imagesNear(image, want, tolerance)) << label;
    EXPECT_EQ(stats.extra["clip_texture_inverse"], specOf(scene).inverse);
    EXPECT_EQ(stats.extra["slices_per_polygon"], scene.options["slices_per_polygon"]);
    return e;
}

const json kSphere = {{"shape", "sphere"}, {"center", {0.1, -0.05, 0.0}}, {"radius", 0.75}};
const json kBox = {{"shape", "box"}, {"min", {-0.7, -0.4, -0.9}}, {"max", {0.5, 0.8, 0.6}}};

// Sphere, inside and inverse and moved by an offset, against the exact sphere's intervals: the slab
// tolerance (4 boundaries) plus the texture term. The max tolerance comes out at 1 here (the per-
// boundary slab bound and the texture term add up): the mean carries the comparison. And the test can
// fail: a render with the wrong clip (none; not inverse; not moved) is outside the mean tolerance of
// each case's reference.
TEST(Stack2dClip, SphereInverseAndOffsetMatchTheExactReference)
{
    const ClipTextureSpec spec = parseClipTextureSpec(kSphere, "clip_texture");
    const test::Tolerance term = sphereTextureTerm(makeClipTexture(spec, "."), spec.radius);
    json inverse = kSphere;
    inverse["inverse"] = true;
    json moved = kSphere;
    moved["offset"] = {0.25, -0.2, 0.15};
    struct Case {
        std::string name;
        Camera camera;
        json clip, wrong;
    };
    for (const Case& c : {Case{"sphere_perspective", perspectiveCamera(), kSphere, json()},
                          Case{"sphere_parallel", parallelCamera(), kSphere, json()},
                          Case{"sphere_inverse_perspective", perspectiveCamera(), inverse, kSphere},
                          Case{"sphere_offset_parallel", parallelCamera(), moved, kSphere}}) {
        const Image4d want = shapeReference(makeScene(c.camera, c.clip, 1));
        for (const int k : {kFused, 1, 3}) {
            const Scene scene = makeScene(c.camera, c.clip, k);
            test::Tolerance tolerance = slabTolerance(scene, 4);
            tolerance.maxAbs = std::min(1.0, tolerance.maxAbs + term.maxAbs);
            tolerance.meanAbs += term.meanAbs;
            check(scene, want, tolerance, c.name + "_k" + std::to_string(k));
            const test::ImageError wrong = test::imageError(render(makeScene(c.camera, c.wrong, k)), want);
            std::printf("[ measured ] %s_k%d with the wrong clip %s: mean %.3g\n", c.name.c_str(), k,
                        c.wrong.dump().c_str(), maxChannel(wrong.meanAbs));
            EXPECT_GT(maxChannel(wrong.meanAbs), tolerance.meanAbs) << c.name << ": the tolerance must catch this";
        }
    }
}

// Box (still and moved by an offset), and the sphere inverse with the parallel camera, against the
// texture's own crossings (the slab error alone, 4 boundaries); a render with the wrong clip (none; not
// moved; not inverse) must be outside the mean tolerance.
TEST(Stack2dClip, BoxAndInverseSphereMatchTheirTextureReference)
{
    json inverse = kSphere;
    inverse["inverse"] = true;
    json box = kBox;
    box["offset"] = {0.1, 0.2, -0.1};
    for (const auto& [name, camera, clip, wrongClip] :
         {std::tuple{"box_parallel", parallelCamera(), kBox, json()},
          std::tuple{"box_offset_perspective", perspectiveCamera(), box, kBox},
          std::tuple{"sphere_inverse_parallel", parallelCamera(), inverse, kSphere}}) {
        const Image4d want = textureReference(makeScene(camera, clip, 1));
        for (const int k : {kFused, 1, 3}) {
            const Scene scene = makeScene(camera, clip, k);
            const test::Tolerance tolerance = slabTolerance(scene, 4);
            check(scene, want, tolerance, std::string(name) + "_k" + std::to_string(k));
            const test::ImageError wrong = test::imageError(render(makeScene(camera, wrongClip, k)), want);
            std::printf("[ measured ] %s_k%d with the wrong clip %s: mean %.3g\n", name, k, wrongClip.dump().c_str(),
                        maxChannel(wrong.meanAbs));
            EXPECT_GT(maxChannel(wrong.meanAbs), tolerance.meanAbs) << name << ": the tolerance must catch this";
        }
    }
}

// A clip texture whose inside holds the whole volume box ([-1, 1]^3 inside the box [-1.5, 1.5]^3, the
// texture's values there <= -0.5 - trilinear error, far from 0): the image of no clip texture within
// 1e-6 (the same arithmetic for every drawn sample; measured bit-identical), for direct volume
// rendering and iso-surfaces, one and three slices per polygon. Its inverse clips everything: the
// background, alpha 0.
TEST(Stack2dClip, AClipTextureHoldingTheVolumeChangesNothing)
{
    const json whole = {{"shape", "box"}, {"min", {-1.5, -1.5, -1.5}}, {"max", {1.5, 1.5, 1.5}}};
    json none = whole;
    none["inverse"] = true;
    for (const Camera& camera : {perspectiveCamera(), parallelCamera()})
        for (const int k : {kFused, 1, 3})
            for (const bool iso : {false, true}) {
                Scene plain = makeScene(camera, json(), k);
                if (iso)
                    plain.iso = isoAt(0.5);
                Scene clipped = plain;
                clipped.options["clip_texture"] = whole;
                const Image4f a = render(plain), b = render(clipped);
                Image4d ad(a.width(), a.height());
                for (std::size_t i = 0; i < a.pixelCount(); ++i)
                    ad.pixels()[i] = glm::dvec4(a.pixels()[i]);
                const test::ImageError e = test::imageError(b, ad);
                const bool identical = std::memcmp(a.pixels().data(), b.pixels().data(), a.pixels().size() * sizeof(glm::vec4)) == 0;
                std::printf("[ measured ] whole-volume clip, %s, k %d%s: max %.3g (%s)\n",
                            camera.parallel ? "parallel" : "perspective", k, iso ? ", iso" : "", maxChannel(e.maxAbs),
                            identical ? "bit-identical" : "not bit-identical");
                EXPECT_LE(maxChannel(e.maxAbs), 1e-6);
                float alphaMax = 0.0f;
                for (const glm::vec4& p : a.pixels())
                    alphaMax = std::max(alphaMax, p.a);
                EXPECT_GT(alphaMax, 0.2f);  // something is drawn
                clipped.options["clip_texture"] = none;
                const Image4f empty = render(clipped);
                for (const glm::vec4& p : empty.pixels()) {
                    ASSERT_EQ(p.a, 0.0f);
                    ASSERT_NEAR(p.b, 0.3f, 1e-6f);
                }
            }
}

// Moving the clip texture between frames (setStack2dClipPlacement) changes only texture coordinates:
// the next frame is bit-identical to a new renderer made with that placement, on both paths; moving it
// back gives the first image again; a renderer without a clip texture, or a singular matrix, is an
// InputError.
TEST(Stack2dClip, MovingTheClipBetweenFramesGivesTheImageOfANewRenderer)
{
    const json sphere = {{"shape", "sphere"}, {"center", {0.1, -0.1, 0.2}}, {"radius", 0.55}};
    const glm::dvec3 offset(0.2, 0.1, -0.15);
    const glm::dmat3 matrix(glm::dvec3(1.0, 0.0, 0.0), glm::dvec3(0.1, 0.9, 0.0), glm::dvec3(0.0, 0.0, 1.1));
    for (const int k : {kFused, 1, 3}) {
        const Scene scene = makeScene(perspectiveCamera(), sphere, k);
        auto renderer = makeRenderer(test::device(), scene, marschnerLobb41());
        FrameStats stats;
        const Image4f first = renderer->render(stats);
        setStack2dClipPlacement(*renderer, offset, matrix);
        const Image4f moved = renderer->render(stats);
        Scene movedScene = scene;
        movedScene.options["clip_texture"]["offset"] = {offset.x, offset.y, offset.z};
        movedScene.options["clip_texture"]["matrix"] = {{1.0, 0.1, 0.0}, {0.0, 0.9, 0.0}, {0.0, 0.0, 1.1}};  // rows
        const Image4f fresh = render(movedScene);
        const std::size_t bytes = first.pixels().size() * sizeof(glm::vec4);
        EXPECT_EQ(std::memcmp(moved.pixels().data(), fresh.pixels().data(), bytes), 0) << "k " << k;
        EXPECT_NE(std::memcmp(moved.pixels().data(), first.pixels().data(), bytes), 0) << "k " << k << ": it moved";
        setStack2dClipPlacement(*renderer, glm::dvec3(0.0));
        const Image4f back = renderer->render(stats);
        EXPECT_EQ(std::memcmp(back.pixels().data(), first.pixels().data(), bytes), 0) << "k " << k;
        EXPECT_THROW(setStack2dClipPlacement(*renderer, offset, glm::dmat3(0.0)), InputError);
    }
    auto unclipped = makeRenderer(test::device(), makeScene(perspectiveCamera(), json(), 1), marschnerLobb41());
    EXPECT_THROW(setStack2dClipPlacement(*unclipped, offset), InputError);
    // Asking a stack2d renderer for slice3d's placement is a programming error, not bad input.
    EXPECT_THROW(setSlice3dClipPlacement(*unclipped, offset), InternalError);
}

// Iso-surfaces: a clipped sample is no hit. The surface 0.5 of "sphere" (1 - |p|) is the sphere of
// radius 0.5; clipped to the sphere of radius 0.3 about the center, every kept sample lies inside the
// surface (value >= 0.7), so a pixel is covered exactly where its ray meets the clip sphere on a
// slice: rays passing the center farther than 0.3 + margin give the background (A = 0), nearer than
// 0.3 - margin the surface (A = 1). Margin 0.03: the chord of a ray at distance d from the center is
// 2 sqrt(0.09 - d^2) >= 0.24 > Delta_max (0.018 here) at d = 0.27, so it holds a sample; the texture's
// zero set lies within delta ~ 2e-4 of the sphere (sphereTextureTerm). Without the rule the 0.5 disc
// would be covered: the pixels between 0.33 and 0.47 fail.
TEST(Stack2dClip, ClippedSamplesAreNoIsoSurfaceHits)
{
    static const Volume sphere = generateVolume("sphere", {33, 33, 33});
    const json clip = {{"shape", "sphere"}, {"center", {0.0, 0.0, 0.0}}, {"radius", 0.3}};
    for (const Camera& camera : {perspectiveCamera(), parallelCamera()})
        for (const int k : {kFused, 1, 6}) {
            Scene scene = makeScene(camera, clip, k);
            scene.options["intermediate"] = 3;
            scene.transferFunction = TransferFunction();
            scene.iso = isoAt(0.5);
            const Image4f image = render(scene, sphere);
            int inside = 0, outside = 0, wrong = 0;
            for (int y = 0; y < kSize; ++y)
                for (int x = 0; x < kSize; ++x) {
                    const glm::vec4 p = image.pixels()[static_cast<std::size_t>(y) * kSize + x];
                    const Ray ray = camera.ray(x, y, kSize, kSize);
                    const glm::dvec3 dir = glm::normalize(ray.direction);
                    const double d = glm::length(ray.origin - glm::dot(ray.origin, dir) * dir);
                    if (d > 0.33) {
                        ++outside;
                        wrong += p.a != 0.0f;
                    } else if (d < 0.27) {
                        ++inside;
                        wrong += p.a != 1.0f;
                    }
                }
            std::printf("[ measured ] iso clipped %s, k %d: %d inside, %d outside, %d wrong\n",
                        camera.parallel ? "parallel" : "perspective", k, inside, outside, wrong);
            EXPECT_EQ(wrong, 0);
            EXPECT_GT(inside, 30);  // measured 52 (perspective) and 44 (parallel) at 48x48
            EXPECT_GT(outside, 1000);
        }
}

void expectInputError(const json& options, const std::string& fragment)
{
    try {
        parseStack2dOptions(options);
        ADD_FAILURE() << "no InputError for " << options.dump();
    } catch (const InputError& e) {
        EXPECT_NE(std::string(e.what()).find(fragment), std::string::npos) << e.what();
    }
}

// The parser is slice3d's (parseClipTextureSpec): the same messages (tests/clip_texture_test.cpp).
TEST(Stack2dClip, BadOptionsGiveSlice3dsErrors)
{
    expectInputError({{"clip_texture", true}}, "options.clip_texture: must be an object");
    expectInputError({{"clip_texture", json::object()}}, "options.clip_texture: give either \"shape\"");
    expectInputError({{"clip_texture", {{"shape", "torus"}}}},
                     "options.clip_texture.shape: must be \"sphere\", \"box\" or \"cylinder\", got \"torus\"");
    expectInputError({{"clip_texture", {{"shape", "sphere"}, {"radius", -1}}}},
                     "options.clip_texture.radius: must be a positive number, got -1");
    expectInputError({{"clip_texture", {{"shape", "box"}, {"min", {0, 0, 0}}, {"max", {1, 0, 1}}}}},
                     "options.clip_texture.max: must be greater than min");
    expectInputError({{"clip_texture", {{"shape", "sphere"}, {"resolution", 4}}}},
                     "options.clip_texture.resolution: must be an integer in [8, 512], got 4");
    expectInputError({{"clip_texture", {{"shape", "sphere"}, {"inverse", "yes"}}}},
                     "options.clip_texture.inverse: must be true or false");
    expectInputError({{"clip_texture", {{"shape", "sphere"}, {"matrix", {{1, 0, 0}, {0, 1, 0}, {1, 1, 0}}}}}},
                     "options.clip_texture.matrix: must be invertible");
    expectInputError({{"clip_texture", {{"mask", "m.nrrd"}, {"radius", 1}}}},
                     "options.clip_texture.radius: unknown key (known: mask, inverse, offset, matrix)");
    EXPECT_TRUE(parseStack2dOptions({{"clip_texture", kSphere}}).clipTexture.has_value());
    EXPECT_FALSE(parseStack2dOptions(json::object()).clipTexture.has_value());
    // A missing mask file: the error names it, at render time (as slice3d).
    const test::TempDir dir;
    Scene scene = makeScene(perspectiveCamera(), {{"mask", "no-such-mask.nrrd"}}, 1);
    scene.baseDir = dir.path();
    try {
        render(scene);
        ADD_FAILURE() << "no InputError";
    } catch (const InputError& e) {
        EXPECT_NE(std::string(e.what()).find("no-such-mask.nrrd: no such file (clip texture mask)"), std::string::npos)
            << e.what();
    }
}

}  // namespace
}  // namespace clvr
