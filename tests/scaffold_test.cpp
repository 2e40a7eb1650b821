// tests/scaffold_test.cpp — the renderer scaffold (host/render/scaffold.h): the set-up checks every
// technique shares, and the read-back of images and counters against what was uploaded.
#include "host/render/scaffold.h"

#include "host/runtime/errors.h"
#include "tests/support/test_util.h"

#include <gtest/gtest.h>

#include <cstdint>
#include <vector>

namespace clvr {
namespace {

Volume smallVolume()
{
    Volume v;
    v.source = "small.nrrd";
    v.dims = {3, 2, 2};
    v.spacing = {1.0, 2.0, 0.5};
    v.origin = {-1.0, 0.0, 1.0};
    v.values.assign(v.voxelCount(), 1.0f);
    return v;
}

TEST(Scaffold, CheckGridVolumeNamesTheVolumeAndTheTechnique)
{
    EXPECT_NO_THROW(checkGridVolume(smallVolume(), "slice3d"));
    Volume short1 = smallVolume();
    short1.values.pop_back();
    try {
        checkGridVolume(short1, "slice3d");
        FAIL() << "a volume with too few values passed";
    } catch (const InputError& e) {
        EXPECT_NE(std::string(e.what()).find("small.nrrd"), std::string::npos) << e.what();
    }
    Volume nan = smallVolume();
    nan.values[4] = std::numeric_limits<float>::quiet_NaN();
    EXPECT_THROW(checkGridVolume(nan, "iso3d"), InputError);
}

TEST(Scaffold, FrameCameraIsTheScenesElseTheFittedOne)
{
    const Volume v = smallVolume();
    Scene scene;
    const Camera fitted = frameCamera(scene, v.boundsMin(), v.boundsMax());
    const Camera expected = fitCamera(v.boundsMin(), v.boundsMax());
    EXPECT_EQ(fitted.position, expected.position);
    EXPECT_EQ(fitted.focalPoint, expected.focalPoint);

    Camera own;
    own.position = {3.0, 4.0, 5.0};
    own.focalPoint = {0.0, 0.5, 1.0};
    own.viewUp = {0.0, 0.0, 1.0};
    scene.camera = own;
    const Camera kept = frameCamera(scene, v.boundsMin(), v.boundsMax());
    EXPECT_EQ(kept.position, own.position);
    EXPECT_EQ(kept.viewUp, own.viewUp);

    scene.camera->focalPoint = scene.camera->position;  // no view direction
    EXPECT_THROW(frameCamera(scene, v.boundsMin(), v.boundsMax()), InputError);
    scene.camera = own;
    scene.image.width = 0;
    EXPECT_THROW(frameCamera(scene, v.boundsMin(), v.boundsMax()), InputError);
}

TEST(Scaffold, ReadImageAndSumCountsReturnWhatTheDeviceHolds)
{
    Device& device = test::device();
    const int w = 5, h = 3;
    std::vector<glm::vec4> pixels(w * h);
    std::vector<cl_uint> counts(w * h);
    std::uint64_t expectedSum = 0;
    for (int i = 0; i < w * h; ++i) {
        pixels[i] = glm::vec4(0.25f * i, -1.0f * i, 0.5f, 1.0f / (i + 1));
        counts[i] = 0xfffffff0u - static_cast<cl_uint>(i);  // the sum needs 64 bits
        expectedSum += counts[i];
    }
    const cl::Buffer image = device.upload("scaffold test image", pixels);
    const cl::Buffer counters = device.upload("scaffold test counts", counts);
    const Image4f back = readImage(device, image, w, h);
    ASSERT_EQ(back.width(), w);
    ASSERT_EQ(back.height(), h);
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x)
            EXPECT_EQ(back.at(x, y), pixels[y * w + x]) << x << "," << y;
    EXPECT_EQ(sumCounts(device, counters, counts.size()), expectedSum);
}

TEST(Scaffold, FinishFramePutsTheHostPassesFirstAndReplacesAnEarlierFramesPasses)
{
    Device& device = test::device();
    device.takePassTimes();  // what earlier tests left
    FrameStats stats;
    stats.passes.push_back({"an earlier frame's pass", 9.0});
    const FrameClock clock;
    finishFrame(device, clock, stats, {{"host pass", 1.5}});
    ASSERT_EQ(stats.passes.size(), 1u);  // no device launch since takePassTimes
    EXPECT_EQ(stats.passes.front().name, "host pass");
    EXPECT_EQ(stats.passes.front().ms, 1.5);
    EXPECT_GE(stats.frameMs, 0.0);
    EXPECT_TRUE(device.takePassTimes().empty());
}

}  // namespace
}  // namespace clvr
