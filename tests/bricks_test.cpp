// tests/bricks_test.cpp — a volume larger than the device's largest allocation renders in bricks on one
// device (host/cluster/bricks.h), through clvr::Session as `clvr render` uses it: the image of the whole
// volume on a device where it fits, within the sort-last composite's tolerance, for slice3d and planes
// (whose bricks need a ghost layer), perspective, parallel and an eye inside; a camera change keeps the bricks.
#include "host/cluster/bricks.h"

#include "host/io/generators.h"
#include "host/runtime/errors.h"
#include "host/session.h"
#include "tests/support/test_util.h"

#include <gtest/gtest.h>

#include <cstdio>
#include <cstdlib>

namespace clvr {
namespace {

// A device whose largest allocation is `limit` bytes ($CLVR_DEVICE_MEMORY_LIMIT, read when it opens).
std::unique_ptr<Device> smallDevice(const char* limit)
{
    ::setenv("CLVR_DEVICE_MEMORY_LIMIT", limit, 1);
    auto device = std::make_unique<Device>();
    ::unsetenv("CLVR_DEVICE_MEMORY_LIMIT");
    return device;
}

double maxDifference(const Image4f& a, const Image4f& b)
{
    double d = 0.0;
    for (std::size_t i = 0; i < a.pixelCount(); ++i)
        for (int c = 0; c < 4; ++c)
            d = std::max(d, static_cast<double>(std::abs(a.pixels()[i][c] - b.pixels()[i][c])));
    return d;
}

TEST(Bricks, VolumeBeyondOneAllocationRendersTheWholeImage)
{
    Camera inside = test::obliquePerspectiveCamera(70.0);
    inside.position = {0.15, -0.1, 0.3};
    const std::vector<Camera> cameras = {test::obliquePerspectiveCamera(30.0), test::obliqueParallelCamera(1.3), inside};
    struct Case {
        const char* technique;
        glm::ivec3 dims;
        const char* limit;  // below the volume's largest buffer: 273 KB as float32; 8.4 MB as planes' float4
    };
    for (const Case& c : {Case{"slice3d", {41, 37, 45}, "96K"}, Case{"planes", {81, 73, 89}, "3M"}}) {
        SCOPED_TRACE(c.technique);
        const Volume ml = generateVolume("marschner-lobb", c.dims);
        const std::unique_ptr<Device> small = smallDevice(c.limit);
        Scene scene;
        scene.technique = c.technique;
        scene.image = ImageSpec{48, 40, {0.1, 0.2, 0.3}};
        scene.transferFunction = test::designTransferFunction();
        if (std::string(c.technique) == "planes") {
            scene.lighting = test::twoLightLighting();
            // Without early termination, as partition_test.cpp: a brick cannot see the opacity in front of
            // it, so with it the whole image stops its rays earlier (by at most 1 - 0.99, docs/cluster.md).
            scene.options = {{"early_termination", 1.0}};
        }
        scene.camera = cameras[0];
        Session whole(test::device(), scene, SceneData{ml, {}, 0.0}, "whole");
        Session bricked(*small, scene, SceneData{ml, {}, 0.0}, "bricked");
        for (std::size_t k = 0; k < cameras.size(); ++k) {
            if (k > 0) {
                whole.setCamera(cameras[k]);
                bricked.setCamera(cameras[k]);
            }
            const Frame a = whole.render(), b = bricked.render();
            ASSERT_TRUE(b.stats.extra.contains("volume_parts"));
            EXPECT_GE(b.stats.extra["volume_parts"].get<int>(), 4) << "camera " << k;
            EXPECT_FALSE(a.stats.extra.contains("volume_parts"));
            EXPECT_EQ(a.stats.samples, b.stats.samples) << "camera " << k;  // every sample once
            const double d = maxDifference(a.image, b.image);
            std::printf("%s, camera %zu, %d parts: max |bricks - whole| = %.2g\n", c.technique, k,
                        b.stats.extra["volume_parts"].get<int>(), d);
            EXPECT_LE(d, 2e-5) << "camera " << k;  // the sort-last composite's tolerance (partition_test.cpp)
        }
    }
}

// A technique that cannot render a part stays the out-of-memory error it was; a device too small for even
// the smallest brick is one too.
TEST(Bricks, WhatCannotBeBrickedIsStillOneError)
{
    const Volume ml = generateVolume("marschner-lobb", {41, 37, 45});
    Scene scene;
    scene.technique = "spherical";
    scene.image = ImageSpec{32, 32, {0, 0, 0}};
    scene.transferFunction = test::designTransferFunction();
    scene.camera = test::obliquePerspectiveCamera(30.0);
    const std::unique_ptr<Device> small = smallDevice("96K");
    EXPECT_THROW(Session(*small, scene, SceneData{ml, {}, 0.0}, "s"), DeviceError);
    scene.technique = "slice3d";
    const std::unique_ptr<Device> tiny = smallDevice("64");
    EXPECT_THROW(Session(*tiny, scene, SceneData{ml, {}, 0.0}, "s"), DeviceError);
}

}  // namespace
}  // namespace clvr
