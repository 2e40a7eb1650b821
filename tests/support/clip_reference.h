// tests/support/clip_reference.h — the CPU references of clip textures shared by tests/clip_texture_test.cpp
// (slice3d) and tests/stack2d_clip_test.cpp: the reference integral (host/reference/reference_integral.h) over
// the parts of each ray that a clip texture lets through.
#pragma once

#include "host/optics/clip_texture.h"
#include "host/reference/reference_integral.h"
#include "host/model/scene.h"
#include "host/model/volume.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <functional>
#include <vector>

namespace clvr::test {

// The reference integral of `scene` over `volume`, each ray restricted to `intervals(ray, t0, t1)`.
inline Image4d referenceOver(const Volume& volume, const Scene& scene,
                             const std::function<std::vector<glm::dvec2>(const Ray&, double, double)>& intervals)
{
    ReferenceStats stats;
    ReferenceOptions options;
    options.stats = &stats;
    options.intervals = intervals;
    Image4d image = referenceIntegral(volume, scene.transferFunction, *scene.camera, scene.image, options);
    EXPECT_EQ(stats.raysNotConverged, 0u);
    return image;
}

// Over the exact parts of each ray inside the placed shape of `spec` (outside: inverse).
inline Image4d shapeClipReference(const Volume& volume, const Scene& scene, const ClipTextureSpec& spec)
{
    return referenceOver(volume, scene,
                         [&](const Ray& ray, double t0, double t1) { return shapeClipIntervals(spec, ray, t0, t1); });
}

// Over the parts of each ray where the texture itself says inside (its trilinear value < 0 in double,
// within its box): crossings found by 1/16-texel steps and bisection. A matrix that shrinks the texture
// shrinks its texels in the world, so the step shrinks with it.
inline Image4d textureClipReference(const Volume& volume, const Scene& scene, const ClipTextureSpec& spec)
{
    const ClipTexture texture = makeClipTexture(spec, scene.baseDir);
    const glm::dmat4 coordinates = clipTextureCoordinates(texture, spec.offset, spec.matrix);
    const glm::dmat3 inv = glm::inverse(spec.matrix);
    const double stretch =
        std::max(1.0, std::sqrt(glm::dot(inv[0], inv[0]) + glm::dot(inv[1], inv[1]) + glm::dot(inv[2], inv[2])));
    const double step = std::min({texture.spacing.x, texture.spacing.y, texture.spacing.z}) / 16.0 / stretch;
    return referenceOver(volume, scene, [&](const Ray& ray, double t0, double t1) {
        return textureClipIntervals(texture, coordinates, spec.inverse, ray, t0, t1, step);
    });
}

}  // namespace clvr::test
