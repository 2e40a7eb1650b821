// tests/session_test.cpp — clvr::Session (host/session.h): the orbit camera path, and a camera change
// between frames equal to a fresh Session with that camera.
#include "host/session.h"

#include "host/runtime/errors.h"
#include "tests/support/test_util.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <numbers>

namespace clvr {
namespace {

// The default scene, small: a 16^3 Marschner-Lobb volume at 24x20 pixels, camera fitted to its bounds.
Scene tinyScene()
{
    return defaultScene({"image.width=24", "image.height=20",
                         R"(volume={"generator": "marschner-lobb", "dims": [16, 16, 16]})"});
}

// The angle from u to v about `axis` (both projected onto the plane normal to it), in degrees in [0, 360).
double angleAbout(const glm::dvec3& u, const glm::dvec3& v, const glm::dvec3& axis)
{
    const glm::dvec3 a = glm::normalize(axis);
    const glm::dvec3 pu = u - a * glm::dot(a, u), pv = v - a * glm::dot(a, v);
    const double degrees = std::atan2(glm::dot(a, glm::cross(pu, pv)), glm::dot(pu, pv)) * 180.0 / std::numbers::pi;
    return degrees < 0.0 ? degrees + 360.0 : degrees;
}

TEST(Orbit, KeepsDistanceAndTurnsByKTimes360OverN)
{
    Camera camera = test::obliquePerspectiveCamera(30.0);
    camera.focalPoint = {0.3, -0.2, 0.1};
    camera.viewUp = {0.1, 1.0, 0.2};  // not orthogonal to the view direction: the axis is view_up itself
    const int n = 7;
    const glm::dvec3 offset0 = camera.position - camera.focalPoint;
    for (int k = 0; k <= n; ++k) {
        const Camera c = orbitCamera(camera, k, n);
        const glm::dvec3 offset = c.position - c.focalPoint;
        // double rotation of a unit-scale vector: a few ulp of |offset| (~4), so 1e-12 is ample.
        EXPECT_NEAR(glm::length(offset), glm::length(offset0), 1e-12) << "frame " << k;
        EXPECT_NEAR(glm::dot(offset, glm::normalize(camera.viewUp)),
                    glm::dot(offset0, glm::normalize(camera.viewUp)), 1e-12) << "frame " << k;
        const double want = std::fmod(360.0 * k / n, 360.0);
        const double got = angleAbout(offset0, offset, camera.viewUp);
        EXPECT_NEAR(std::remainder(got - want, 360.0), 0.0, 1e-9) << "frame " << k;
        EXPECT_EQ(c.focalPoint, camera.focalPoint);
        EXPECT_EQ(c.viewUp, camera.viewUp);
        EXPECT_EQ(c.viewAngle, camera.viewAngle);
    }
    // Frame 0 and frame N are the scene's camera, bit for bit; frame N + 1 is frame 1.
    EXPECT_EQ(orbitCamera(camera, 0, n).position, camera.position);
    EXPECT_EQ(orbitCamera(camera, n, n).position, camera.position);
    EXPECT_EQ(orbitCamera(camera, n + 1, n).position, orbitCamera(camera, 1, n).position);
    // A quarter turn about +y takes +z to +x (right-handed).
    Camera simple;
    simple.position = {0.0, 0.0, 2.0};
    const glm::dvec3 quarter = orbitCamera(simple, 1, 4).position;
    EXPECT_NEAR(quarter.x, 2.0, 1e-15);
    EXPECT_NEAR(quarter.y, 0.0, 1e-15);
    EXPECT_NEAR(quarter.z, 0.0, 1e-15);
    EXPECT_THROW(orbitCamera(camera, 0, 0), InputError);
}

TEST(Session, CameraChangeMatchesAFreshSession)
{
    Device& device = test::device();
    const Scene scene = tinyScene();
    Session session(device, scene, loadSceneData(scene), "tiny");
    const Camera camera0 = session.camera();
    const Frame first = session.render();
    ASSERT_EQ(first.image.width(), 24);
    ASSERT_EQ(first.image.height(), 20);
    EXPECT_GT(first.stats.frameMs, 0.0);
    EXPECT_TRUE(test::sameBits(session.render().image, first.image)) << "two frames of one camera differ";
    const nlohmann::json stats = session.stats(first);
    EXPECT_EQ(stats["technique"], "slice3d");
    EXPECT_EQ(stats["width"], 24);
    EXPECT_EQ(stats["voxels"], 16 * 16 * 16);
    EXPECT_EQ(stats["frame_ms"].get<double>(), first.stats.frameMs);
    EXPECT_EQ(stats["passes"].size(), first.stats.passes.size());
    EXPECT_GT(stats["resident_bytes"].get<std::uint64_t>(), 0u);

    session.setCamera(orbitCamera(camera0, 1, 3));
    const Frame turned = session.render();
    EXPECT_FALSE(test::sameBits(turned.image, first.image)) << "frame 1 of 3 equals frame 0";

    Scene turnedScene = scene;
    turnedScene.camera = orbitCamera(camera0, 1, 3);
    Session fresh(device, turnedScene, loadSceneData(turnedScene), "tiny");
    EXPECT_TRUE(test::sameBits(fresh.render().image, turned.image)) << "setCamera differs from a new Session";

    session.setCamera(orbitCamera(camera0, 3, 3));
    EXPECT_TRUE(test::sameBits(session.render().image, first.image)) << "frame 3 of 3 differs from frame 0";

    Camera bad = camera0;
    bad.position = bad.focalPoint;
    EXPECT_THROW(session.setCamera(bad), InputError);
}

TEST(Session, TechniqueErrorsNameTheScene)
{
    Scene scene = tinyScene();
    scene.options = {{"no_such_option", 1}};
    try {
        Session session(test::device(), scene, loadSceneData(scene), "tiny.json");
        FAIL() << "no InputError for an unknown option";
    } catch (const InputError& e) {
        EXPECT_EQ(std::string(e.what()).rfind("tiny.json: ", 0), 0u) << e.what();
    }
}

}  // namespace
}  // namespace clvr
