// tests/scene_test.cpp — scene JSON parsing and validation: every bad input is an InputError that
// names the file and the key; --set overrides; the embedded default scene equals data/scenes/default.json.
#include "host/runtime/errors.h"
#include "host/model/scene.h"
#include "tests/support/test_util.h"

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>

namespace {

using clvr::InputError;
using clvr::Scene;

// A minimal valid scene; tests edit it with --set or replace pieces of the text.
const std::string kMinimal = R"({
  "volume": {"generator": "sphere", "dims": [8, 8, 8]},
  "transfer_function": {"points": [[0, 0,0,0, 0], [1, 1,1,1, 4]]}
})";

Scene parse(const std::string& text, const std::vector<std::string>& overrides = {},
            const std::vector<std::string>& unsets = {})
{
    return clvr::parseScene(text, "scene.json", "/data/scenes", overrides, unsets);
}

// The InputError message parsing `text` gives; fails the test when there is none.
std::string errorOf(const std::string& text, const std::vector<std::string>& overrides = {},
                    const std::vector<std::string>& unsets = {})
{
    try {
        parse(text, overrides, unsets);
    } catch (const InputError& e) {
        return e.what();
    } catch (const std::exception& e) {
        ADD_FAILURE() << "not an InputError: " << e.what();
        return {};
    }
    ADD_FAILURE() << "no error for:\n" << text;
    return {};
}

// Asserts that the message starts with the file name and contains every fragment.
#define EXPECT_SCENE_ERROR(message, ...)                                                        \
    do {                                                                                        \
        const std::string m_ = (message);                                                       \
        EXPECT_EQ(m_.rfind("scene.json: ", 0), 0u) << m_;                                       \
        for (const char* f_ : {__VA_ARGS__})                                                    \
            EXPECT_NE(m_.find(f_), std::string::npos) << "missing \"" << f_ << "\" in: " << m_; \
    } while (0)

TEST(Scene, MinimalUsesDefaults)
{
    const Scene s = parse(kMinimal);
    EXPECT_EQ(s.technique, "slice3d");
    EXPECT_EQ(s.baseDir, std::filesystem::path("/data/scenes"));
    ASSERT_TRUE(s.volume.has_value());
    EXPECT_EQ(s.volume->generator, "sphere");
    EXPECT_FALSE(s.mesh.has_value());
    EXPECT_FALSE(s.camera.has_value());
    EXPECT_EQ(s.image.width, 512);
    EXPECT_EQ(s.image.height, 512);
    EXPECT_EQ(s.transferFunction.points().size(), 2u);
    EXPECT_TRUE(s.options.is_object());
    EXPECT_TRUE(s.options.empty());
    EXPECT_FALSE(s.iso.has_value());
    EXPECT_FALSE(s.lighting.shaded());
    EXPECT_EQ(s.lighting.material.shininess, clvr::Material{}.shininess);
}

TEST(Scene, FullSceneParses)
{
    const Scene s = parse(R"({
      "technique": "slice3d",
      "volume": {"file": "ct.nrrd"},
      "camera": {"position": [0,0,4], "focal_point": [0,0,0], "view_up": [0,1,0], "view_angle": 20,
                 "projection": "parallel", "parallel_scale": 2},
      "image": {"width": 320, "height": 200, "background": [0.1, 0.2, 0.3]},
      "transfer_function": {"points": [[0.0, 0,0,0, 0.0], [0.5, 1,0.5,0, 4.0], [1.0, 1,1,1, 8.0]]},
      "options": {"slices": 64},
      "iso": {"value": 0.5, "shading": "gradientless", "light": [0,0,2], "ambient": 0.2, "diffuse": 0.7},
      "lights": [{"direction": [1,1,1], "color": [1,0.5,1]}],
      "material": {"ambient": 0.1, "diffuse": 0.6, "specular": 0.2, "shininess": 30}
    })");
    ASSERT_TRUE(s.camera.has_value());
    EXPECT_EQ(s.camera->viewAngle, 20.0);
    EXPECT_TRUE(s.camera->parallel);
    EXPECT_EQ(s.camera->parallelScale, 2.0);
    EXPECT_EQ(s.image.width, 320);
    EXPECT_EQ(s.image.height, 200);
    EXPECT_DOUBLE_EQ(s.image.background.b, 0.3);
    EXPECT_EQ(s.transferFunction.points().size(), 3u);
    EXPECT_EQ(s.options["slices"], 64);
    ASSERT_TRUE(s.iso.has_value());
    EXPECT_EQ(s.iso->value, 0.5);
    EXPECT_EQ(s.iso->shading, clvr::IsoSpec::Shading::Gradientless);
    ASSERT_TRUE(s.iso->light.has_value());
    EXPECT_EQ(*s.iso->light, glm::dvec3(0, 0, 1));  // normalized
    EXPECT_EQ(s.iso->ambient, 0.2);
    EXPECT_EQ(s.iso->diffuse, 0.7);
    ASSERT_EQ(s.lighting.lights.size(), 1u);
    EXPECT_NEAR(glm::length(s.lighting.lights[0].direction - glm::normalize(glm::dvec3(1.0))), 0.0, 1e-15);
    EXPECT_EQ(s.lighting.lights[0].color, glm::dvec3(1, 0.5, 1));
    EXPECT_EQ(s.lighting.material.diffuse, 0.6);
    EXPECT_EQ(s.lighting.material.shininess, 30.0);
}

TEST(Scene, DistributionIsOneOfTheThreeModes)
{
    EXPECT_EQ(parse(kMinimal).distribution, "");
    EXPECT_EQ(parse(kMinimal, {"distribution=\"frames\""}).distribution, "frames");
    EXPECT_EQ(parse(kMinimal, {"distribution=\"sort-last\""}).distribution, "sort-last");
    EXPECT_SCENE_ERROR(errorOf(kMinimal, {"distribution=\"tiles\""}), "scene.json: distribution: unknown distribution");
    EXPECT_THROW(clvr::checkDistribution("sortlast", "--distribution"), clvr::InputError);
}

TEST(Scene, IsoWithoutLightUsesTheHeadlight)
{
    const Scene s = parse(kMinimal, {"iso.value=0.5"});
    ASSERT_TRUE(s.iso.has_value());
    EXPECT_FALSE(s.iso->light.has_value());
    clvr::Camera camera;
    camera.position = {3, 0, 4};
    camera.focalPoint = {0, 0, 0};
    EXPECT_NEAR(glm::length(s.iso->lightFor(camera) - glm::dvec3(0.6, 0, 0.8)), 0.0, 1e-15);
}

TEST(Scene, BadIsoLightsAndMaterialNameTheKey)
{
    EXPECT_SCENE_ERROR(errorOf(kMinimal, {"iso={\"value\": 0.5, \"shading\": \"phong\"}"}),
                       "iso.shading must be \"gradient\", \"gradientless\" or \"none\", got \"phong\"");
    EXPECT_SCENE_ERROR(errorOf(kMinimal, {"iso={\"value\": 0.5, \"light\": [0,0,0]}"}), "iso.light must not be the zero");
    EXPECT_SCENE_ERROR(errorOf(kMinimal, {"iso={\"value\": 0.5, \"ambient\": -1}"}), "iso.ambient must be >= 0");
    EXPECT_SCENE_ERROR(errorOf(kMinimal, {"iso={\"light\": [0,0,1]}"}), "iso.value is missing");
    EXPECT_SCENE_ERROR(errorOf(kMinimal, {"lights=[{\"color\": [1,1,1]}]"}), "lights[0].direction is missing");
    EXPECT_SCENE_ERROR(errorOf(kMinimal, {"lights=[{\"direction\": [1,0,0], \"color\": [2,1,1]}]"}),
                       "lights[0].color must have components in [0, 1]");
    EXPECT_SCENE_ERROR(errorOf(kMinimal, {"material.shininess=-2"}), "material.shininess must be >= 0");
}

// A scene with every top-level key --unset may remove.
const std::string kUnsetScene = R"({
  "volume": {"generator": "sphere", "dims": [8, 8, 8]},
  "camera": {"position": [0, 0, 9], "view_angle": 20},
  "transfer_function": {"points": [[0, 0,0,0, 0], [1, 1,1,1, 4]]},
  "options": {"slices": 64, "early_termination": 0.9},
  "lights": [{"direction": [0, 0, 1]}]
})";

TEST(Scene, UnsetRemovesKeysBeforeValidation)
{
    EXPECT_TRUE(parse(kUnsetScene).camera.has_value());
    EXPECT_FALSE(parse(kUnsetScene, {}, {"camera"}).camera.has_value());  // the fitted camera
    EXPECT_TRUE(parse(kUnsetScene, {}, {"options"}).options.empty());    // the defaults
    const Scene one = parse(kUnsetScene, {}, {"options.slices"});
    EXPECT_FALSE(one.options.contains("slices"));
    EXPECT_EQ(one.options["early_termination"], 0.9);
    EXPECT_EQ(parse(kUnsetScene, {}, {"camera.view_angle"}).camera->viewAngle, clvr::Camera{}.viewAngle);
    EXPECT_FALSE(parse(kUnsetScene, {}, {"lights"}).lighting.shaded());
    // Unsets come first, then --set: a fresh options object.
    const Scene reset = parse(kUnsetScene, {"options.slices=16"}, {"options"});
    EXPECT_EQ(reset.options, nlohmann::json({{"slices", 16}}));
    // Removing what validation needs is then an error about the scene.
    EXPECT_SCENE_ERROR(errorOf(kUnsetScene, {}, {"transfer_function"}), "transfer_function is missing");
}

TEST(Scene, UnsetOfAMissingKeyNamesIt)
{
    EXPECT_SCENE_ERROR(errorOf(kUnsetScene, {}, {"iso"}), "--unset \"iso\"", "no key \"iso\"");
    EXPECT_SCENE_ERROR(errorOf(kUnsetScene, {}, {"options.slice_spacing"}), "no key \"options.slice_spacing\"");
    EXPECT_SCENE_ERROR(errorOf(kUnsetScene, {}, {"camera.position.x"}), "no key \"camera.position.x\"");
    EXPECT_SCENE_ERROR(errorOf(kUnsetScene, {}, {"image.width"}), "no key \"image.width\"");
    EXPECT_SCENE_ERROR(errorOf(kUnsetScene, {}, {"options..slices"}), "empty key");
}

TEST(Scene, MalformedJsonGivesLineAndColumn)
{
    const std::string m = errorOf("{\n  \"technique\": \"slice3d\",\n  \"volume\": {\"file\" \"x\"}\n}");
    EXPECT_SCENE_ERROR(m, "malformed JSON", "line 3, column 23");
}

TEST(Scene, TruncatedJson)
{
    const std::string m = errorOf("{\n  \"volume\": {\"generator\": \"sphere\",\n");
    EXPECT_SCENE_ERROR(m, "malformed JSON", "line 3", "end of input");
}

TEST(Scene, EmptyFile)
{
    EXPECT_SCENE_ERROR(errorOf(""), "malformed JSON", "line 1, column 1");
}

TEST(Scene, NotAnObject)
{
    EXPECT_SCENE_ERROR(errorOf("[1, 2]"), "must be a JSON object");
}

TEST(Scene, DuplicateKey)
{
    EXPECT_SCENE_ERROR(errorOf(R"({"volume": {"file": "a"}, "volume": {"file": "b"}})"), "duplicate key \"volume\"");
}

TEST(Scene, UnknownTopLevelKey)
{
    EXPECT_SCENE_ERROR(errorOf(kMinimal, {"colour=1"}), "unknown key \"colour\"", "known: technique, volume");
}

TEST(Scene, UnknownCameraKey)
{
    EXPECT_SCENE_ERROR(errorOf(kMinimal, {"camera.fov=30"}), "unknown key \"camera.fov\"",
                       "(known: position, focal_point, view_up, view_angle, projection, parallel_scale)");
}

TEST(Scene, UnknownImageKey)
{
    EXPECT_SCENE_ERROR(errorOf(kMinimal, {"image.depth=8"}), "unknown key \"image.depth\"", "width, height");
}

TEST(Scene, UnknownTransferFunctionKey)
{
    EXPECT_SCENE_ERROR(errorOf(kMinimal, {"transfer_function.scale=2"}), "unknown key \"transfer_function.scale\"");
}

TEST(Scene, UnknownIsoLightMaterialKeys)
{
    EXPECT_SCENE_ERROR(errorOf(kMinimal, {"iso={\"value\": 0.5, \"colour\": 1}"}), "unknown key \"iso.colour\"");
    EXPECT_SCENE_ERROR(errorOf(kMinimal, {"lights=[{\"direction\": [0,0,1], \"power\": 2}]"}),
                       "unknown key \"lights[0].power\"");
    EXPECT_SCENE_ERROR(errorOf(kMinimal, {"material.gloss=2"}), "unknown key \"material.gloss\"");
}

TEST(Scene, WrongTypes)
{
    EXPECT_SCENE_ERROR(errorOf(kMinimal, {"image.width=64.5"}), "image.width must be an integer");
    EXPECT_SCENE_ERROR(errorOf(kMinimal, {"image.width=\"64\""}), "image.width must be an integer");
    EXPECT_SCENE_ERROR(errorOf(kMinimal, {"technique=3"}), "technique must be a string");
    EXPECT_SCENE_ERROR(errorOf(kMinimal, {"volume=\"ct.nrrd\""}), "volume must be an object");
    EXPECT_SCENE_ERROR(errorOf(kMinimal, {"mesh=[1]"}), "mesh must be an object");
    EXPECT_SCENE_ERROR(errorOf(kMinimal, {"options=5"}), "options must be an object");
    EXPECT_SCENE_ERROR(errorOf(kMinimal, {"camera=[0,0,4]"}), "camera must be an object");
    EXPECT_SCENE_ERROR(errorOf(kMinimal, {"camera.position=[0,0]"}), "camera.position must be an array of 3 numbers");
    EXPECT_SCENE_ERROR(errorOf(kMinimal, {"camera.position=[0,\"a\",4]"}), "camera.position[1] must be a number");
    EXPECT_SCENE_ERROR(errorOf(kMinimal, {"camera.view_angle=wide"}), "camera.view_angle must be a number");
    EXPECT_SCENE_ERROR(errorOf(kMinimal, {"camera.projection=fisheye"}), "camera.projection must be");
    EXPECT_SCENE_ERROR(errorOf(kMinimal, {"image.background=[0,0,2]"}), "image.background must have components");
    EXPECT_SCENE_ERROR(errorOf(kMinimal, {"transfer_function.points=3"}), "transfer_function.points must be an array");
    EXPECT_SCENE_ERROR(errorOf(kMinimal, {"lights={}"}), "lights must be an array");
    EXPECT_SCENE_ERROR(errorOf(kMinimal, {"iso.value=high"}), "iso.value must be a number");
}

TEST(Scene, ImageSizeLimits)
{
    EXPECT_SCENE_ERROR(errorOf(kMinimal, {"image.width=0"}), "image.width must be in 1..16384, got 0");
    EXPECT_SCENE_ERROR(errorOf(kMinimal, {"image.height=16385"}), "image.height must be in 1..16384, got 16385");
    EXPECT_SCENE_ERROR(errorOf(kMinimal, {"image.width=-3"}), "image.width");
    EXPECT_EQ(parse(kMinimal, {"image.width=16384", "image.height=1"}).image.width, 16384);
}

TEST(Scene, CameraPositionEqualsFocalPoint)
{
    EXPECT_SCENE_ERROR(errorOf(kMinimal, {"camera={\"position\": [1,2,3], \"focal_point\": [1,2,3]}"}), "camera:",
                       "focal_point");
}

TEST(Scene, CameraUpParallelToView)
{
    EXPECT_SCENE_ERROR(errorOf(kMinimal, {"camera={\"position\": [0,0,4], \"view_up\": [0,0,-2]}"}), "camera:",
                       "view_up");
}

TEST(Scene, CameraViewAngleOutOfRange)
{
    EXPECT_SCENE_ERROR(errorOf(kMinimal, {"camera.view_angle=180"}), "view_angle");
    EXPECT_SCENE_ERROR(errorOf(kMinimal, {"camera.projection=parallel", "camera.parallel_scale=0"}),
                       "parallel_scale");
}

TEST(Scene, TransferFunctionWithOnePoint)
{
    EXPECT_SCENE_ERROR(errorOf(kMinimal, {"transfer_function.points=[[0, 1,1,1, 1]]"}), "transfer_function",
                       "two control points");
}

// Bounded work (issue 15): kernels walk the control points a segment crosses, so their count is bounded.
TEST(Scene, TransferFunctionWithTooManyPoints)
{
    std::string points = "transfer_function.points=[";
    for (int i = 0; i <= 4096; ++i)
        points += (i ? ", [" : "[") + std::to_string(i) + ", 1,1,1, 1]";
    EXPECT_SCENE_ERROR(errorOf(kMinimal, {points + "]"}), "transfer_function", "4097 control points, at most 4096");
}

TEST(Scene, TransferFunctionUnsorted)
{
    EXPECT_SCENE_ERROR(errorOf(kMinimal, {"transfer_function.points=[[1, 0,0,0, 0], [0, 1,1,1, 1]]"}),
                       "transfer_function", "increase");
}

TEST(Scene, TransferFunctionNegativeTau)
{
    EXPECT_SCENE_ERROR(errorOf(kMinimal, {"transfer_function.points=[[0, 0,0,0, 0], [1, 1,1,1, -1]]"}),
                       "transfer_function", "negative");
}

TEST(Scene, TransferFunctionColorAboveOne)
{
    EXPECT_SCENE_ERROR(errorOf(kMinimal, {"transfer_function.points=[[0, 0,0,0, 0], [1, 1,1.5,1, 1]]"}),
                       "transfer_function", "color");
}

TEST(Scene, TransferFunctionPointWithFourNumbers)
{
    EXPECT_SCENE_ERROR(errorOf(kMinimal, {"transfer_function.points=[[0, 0,0,0, 0], [1, 1,1,1]]"}),
                       "transfer_function.points[1] must be an array of 5 numbers");
}

TEST(Scene, TransferFunctionNanOrInfinity)
{
    // JSON cannot spell NaN; a huge exponent parses to infinity, and "nan" is a string.
    EXPECT_SCENE_ERROR(errorOf(kMinimal, {"transfer_function.points=[[0, 0,0,0, 0], [1, 1,1,1, 1e999]]"}),
                       "--set \"transfer_function.points=", "line 1, column 28", "1e999 is out of range");
    EXPECT_SCENE_ERROR(errorOf(kMinimal, {"transfer_function.points=[[0, 0,0,0, 0], [1, \"nan\",1,1, 1]]"}),
                       "transfer_function.points[1][1] must be a number");
    const std::string text = R"({"volume": {"generator": "sphere", "dims": [8,8,8]},
      "transfer_function": {"points": [[-1e999, 0,0,0, 0], [1, 1,1,1, 1]]}})";
    EXPECT_SCENE_ERROR(errorOf(text), "malformed JSON at line 2, column 41", "-1e999 is out of range", "finite");
}

TEST(Scene, TransferFunctionRequiredUnlessIso)
{
    const std::string noTf = R"({"volume": {"generator": "sphere", "dims": [8,8,8]}})";
    EXPECT_SCENE_ERROR(errorOf(noTf), "transfer_function is missing");
    const Scene s = parse(noTf, {"iso.value=0.5", "technique=iso3d"});
    EXPECT_TRUE(s.transferFunction.points().empty());
    EXPECT_EQ(s.technique, "iso3d");
}

TEST(Scene, NeedsVolumeOrMesh)
{
    EXPECT_SCENE_ERROR(errorOf(R"({"transfer_function": {"points": [[0, 0,0,0, 0], [1, 1,1,1, 4]]}})"),
                       "neither \"volume\" nor \"mesh\"");
}

TEST(Scene, SetNestedPathCreatesObjects)
{
    const Scene s = parse(kMinimal, {"camera.position=[0,0,5]", "camera.view_angle=20", "options.slices=64",
                                     "image={\"width\": 64, \"height\": 32}"});
    ASSERT_TRUE(s.camera.has_value());
    EXPECT_EQ(s.camera->position, glm::dvec3(0, 0, 5));
    EXPECT_EQ(s.camera->viewAngle, 20.0);
    EXPECT_EQ(s.options["slices"], 64);
    EXPECT_EQ(s.image.width, 64);
    EXPECT_EQ(s.image.height, 32);
}

TEST(Scene, SetLaterOverrideWins)
{
    EXPECT_EQ(parse(kMinimal, {"image.width=64", "image.width=96"}).image.width, 96);
}

TEST(Scene, SetStringFallback)
{
    EXPECT_EQ(parse(kMinimal, {"technique=slice3d"}).technique, "slice3d");
    EXPECT_EQ(parse(kMinimal, {"technique=\"harc\""}).technique, "harc");
    // --unset, not --set ...=null: a null "generator" is still a key, and a spec with both is malformed.
    EXPECT_EQ(parse(kMinimal, {"volume.file=my volume.nrrd"}, {"volume.generator", "volume.dims"}).volume->file,
              std::filesystem::path("/data/scenes/my volume.nrrd"));
}

TEST(Scene, SetMalformed)
{
    EXPECT_SCENE_ERROR(errorOf(kMinimal, {"image.width"}), "--set \"image.width\"", "path=value");
    EXPECT_SCENE_ERROR(errorOf(kMinimal, {"=5"}), "--set \"=5\"", "path=value");
    EXPECT_SCENE_ERROR(errorOf(kMinimal, {"camera..view_angle=5"}), "--set", "empty key");
    EXPECT_SCENE_ERROR(errorOf(kMinimal, {"camera.position=[0,0,"}), "--set \"camera.position=[0,0,\"",
                       "malformed value", "column");
    EXPECT_SCENE_ERROR(errorOf(kMinimal, {"volume.generator.name=x"}), "--set",
                       "\"volume.generator\" is not an object");
}

TEST(Scene, SetAppliesBeforeValidation)
{
    // The scene text alone is invalid; the override repairs it.
    const std::string bad = R"({"volume": {"generator": "sphere", "dims": [8,8,8]}, "image": {"width": 0},
      "transfer_function": {"points": [[0, 0,0,0, 0], [1, 1,1,1, 4]]}})";
    EXPECT_EQ(parse(bad, {"image.width=64"}).image.width, 64);
}

TEST(Scene, LoadMissingFile)
{
    try {
        clvr::loadScene("/no/such/dir/scene.json");
        FAIL() << "no error";
    } catch (const InputError& e) {
        EXPECT_NE(std::string(e.what()).find("/no/such/dir/scene.json: "), std::string::npos) << e.what();
    }
}

TEST(Scene, LoadFileSetsBaseDir)
{
    const std::filesystem::path dir = std::filesystem::path(CLVR_BINARY_DIR) / "test_output" / "scene_test";
    std::filesystem::create_directories(dir);
    const std::filesystem::path file = dir / "s.json";
    std::ofstream(file) << kMinimal;
    const Scene s = clvr::loadScene(file);
    EXPECT_EQ(s.baseDir, dir);
}

TEST(Scene, DefaultSceneEqualsFile)
{
    std::ifstream in(clvr::test::repoData("scenes/default.json"));
    ASSERT_TRUE(in) << clvr::test::repoData("scenes/default.json");
    std::stringstream text;
    text << in.rdbuf();
    const Scene fromFile = clvr::parseScene(text.str(), "default.json", {});
    const Scene embedded = clvr::defaultScene();
    EXPECT_EQ(embedded.technique, fromFile.technique);
    EXPECT_EQ(embedded.volume, fromFile.volume);
    EXPECT_EQ(embedded.options, fromFile.options);
    ASSERT_TRUE(embedded.camera && fromFile.camera);
    EXPECT_EQ(embedded.camera->position, fromFile.camera->position);
    EXPECT_EQ(embedded.camera->focalPoint, fromFile.camera->focalPoint);
    EXPECT_EQ(embedded.camera->viewAngle, fromFile.camera->viewAngle);
    EXPECT_EQ(embedded.image.width, fromFile.image.width);
    EXPECT_EQ(embedded.image.height, fromFile.image.height);
    ASSERT_EQ(embedded.transferFunction.points().size(), fromFile.transferFunction.points().size());
    for (std::size_t i = 0; i < embedded.transferFunction.points().size(); ++i) {
        EXPECT_EQ(embedded.transferFunction.points()[i].s, fromFile.transferFunction.points()[i].s);
        EXPECT_EQ(embedded.transferFunction.points()[i].color, fromFile.transferFunction.points()[i].color);
        EXPECT_EQ(embedded.transferFunction.points()[i].tau, fromFile.transferFunction.points()[i].tau);
    }
    ASSERT_TRUE(embedded.volume.has_value());
    EXPECT_EQ(embedded.volume->generator, "marschner-lobb");
    EXPECT_EQ(embedded.volume->dims, glm::ivec3(128));
}

TEST(Scene, DefaultSceneTakesOverrides)
{
    const Scene s = clvr::defaultScene({"image.width=64"});
    EXPECT_EQ(s.image.width, 64);
    try {
        clvr::defaultScene({"image.widht=64"});
        FAIL() << "no error";
    } catch (const InputError& e) {
        EXPECT_NE(std::string(e.what()).find("default scene: unknown key \"image.widht\""), std::string::npos)
            << e.what();
    }
}

TEST(Scene, ExampleScenesParse)
{
    for (const char* name : {"scenes/default.json", "scenes/headsq.json", "scenes/engine.json",
                             "scenes/engine-clip-sphere.json", "scenes/engine-clip-torus.json"}) {
        SCOPED_TRACE(name);
        EXPECT_NO_THROW(clvr::loadScene(clvr::test::repoData(name)));
    }
}

TEST(Scene, FitCameraSeesTheWholeBox)
{
    const glm::dvec3 lo(0, 0, 0), hi(255, 255, 127);
    const clvr::Camera c = clvr::fitCamera(lo, hi, 30.0);
    EXPECT_NO_THROW(c.validate());
    const glm::dvec3 center = 0.5 * (lo + hi);
    EXPECT_EQ(c.focalPoint, center);
    EXPECT_GT(c.position.z, hi.z);
    // The bounding sphere is tangent to the view cone: distance * sin(15 deg) == radius.
    const double radius = 0.5 * glm::length(hi - lo);
    EXPECT_NEAR(glm::length(c.position - center) * std::sin(glm::radians(15.0)), radius, 1e-9 * radius);
    // Every corner projects inside the image.
    for (int i = 0; i < 8; ++i) {
        const glm::dvec3 p((i & 1) ? hi.x : lo.x, (i & 2) ? hi.y : lo.y, (i & 4) ? hi.z : lo.z);
        const glm::dvec3 d = glm::normalize(p - c.position);
        const double angle = std::acos(glm::dot(d, c.forward()));
        EXPECT_LT(angle, glm::radians(15.0)) << i;
    }
}

TEST(Scene, FitCameraDegenerateBox)
{
    const clvr::Camera c = clvr::fitCamera(glm::dvec3(1.0), glm::dvec3(1.0));
    EXPECT_NO_THROW(c.validate());
}

}  // namespace
