// tests/default_scene_test.cpp — the scene `bash tools/setup.sh` renders (data/scenes/default.json,
// embedded as defaultScene()) against the CPU reference integral, as shipped: Marschner–Lobb 128³,
// 256 slices, fused slice3d; only the image is made small (48x48) so the reference stays cheap.
#include "host/io/generators.h"
#include "host/reference/reference_integral.h"
#include "host/render/renderer.h"
#include "host/render/grid/slice3d.h"
#include "host/model/scene.h"
#include "host/io/volume_io.h"
#include "tests/support/test_util.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

namespace {

using namespace clvr;

TEST(DefaultScene, MatchesReferenceIntegral)
{
    const Scene scene = defaultScene({"image.width=48", "image.height=48"});
    const Volume volume = loadVolume(*scene.volume);
    ASSERT_TRUE(scene.camera.has_value());

    auto renderer = makeRenderer(test::device(), scene, volume);
    FrameStats stats;
    const Image4f image = renderer->render(stats);
    const Image4d want = referenceIntegral(volume, scene.transferFunction, *scene.camera, scene.image);

    // Same bound as tests/slice3d_test.cpp: a ray can gain or lose one slice's opacity at each end of
    // its chord, max <= 2 (1 - exp(-tauMax Delta)) with Delta the longest per-pixel slice length
    // (corner pixel); the mean slicing error is first order, <= 0.02 tauMax deltaS.
    double tauMax = 0.0;
    for (const ControlPoint& p : scene.transferFunction.points())
        tauMax = std::max(tauMax, p.tau);
    const SlicePlan plan = planSlices(*scene.camera, volume.boundsMin(), volume.boundsMax(),
                                      parseSlice3dOptions(scene.options));
    const Ray corner = scene.camera->ray(0, 0, scene.image.width, scene.image.height);
    const double delta = plan.deltaS / glm::dot(corner.direction, scene.camera->forward());
    const test::Tolerance tolerance{2.0 * (1.0 - std::exp(-tauMax * delta)), 0.02 * tauMax * plan.deltaS};
    const test::ImageError e = test::imageError(image, want);
    std::printf("[ measured ] default scene 48x48: max %.3g %.3g %.3g %.3g, mean %.3g %.3g %.3g %.3g "
                "(tolerance %.3g / %.3g)\n",
                e.maxAbs.r, e.maxAbs.g, e.maxAbs.b, e.maxAbs.a, e.meanAbs.r, e.meanAbs.g, e.meanAbs.b, e.meanAbs.a,
                tolerance.maxAbs, tolerance.meanAbs);
    EXPECT_TRUE(test::imagesNear(image, want, tolerance));

    // Not a blank picture: the volume covers a good part of the image and is visibly colored.
    std::size_t covered = 0;
    for (const glm::vec4& p : image.pixels())
        covered += p.a > 0.05f;
    EXPECT_GT(covered, image.pixelCount() / 5) << "the default scene should fill a good part of the image";
    EXPECT_LT(covered, image.pixelCount()) << "and leave background around the volume";
}

}  // namespace
