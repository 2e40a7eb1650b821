// tests/ray_test.cpp — kernels/ray.h against host/model/camera.cpp's PixelRays (double precision): every
// pixel of an odd-sized image, both cameras, each of the three forms the kernels use.
#include "host/model/camera.h"
#include "host/render/camera_args.h"
#include "tests/support/test_util.h"

#include <gtest/gtest.h>

#include <cmath>
#include <vector>

namespace {

enum Form { Depth = 0, Unit = 1, OffsetFirst = 2, RoundedTerms = 3 };

struct DeviceRays {
    std::vector<glm::vec4> values;  // (origin, stretch), (direction, 0) per pixel
    glm::vec3 origin(std::size_t i) const { return glm::vec3(values[2 * i]); }
    float stretch(std::size_t i) const { return values[2 * i].w; }
    glm::vec3 direction(std::size_t i) const { return glm::vec3(values[2 * i + 1]); }
};

DeviceRays deviceRays(const clvr::Camera& camera, int width, int height, Form form)
{
    clvr::Device& device = clvr::test::device();
    cl::Kernel k = device.kernel("ray_test.cl", "ray_pixels");
    const std::size_t pixels = static_cast<std::size_t>(width) * height;
    cl::Buffer out = device.buffer("rays", 2 * pixels * sizeof(cl_float4), CL_MEM_WRITE_ONLY);
    k.setArg(0, out);
    k.setArg(1, clvr::toClCamera(camera, width, height));
    k.setArg(2, static_cast<cl_int>(width));
    k.setArg(3, static_cast<cl_int>(height));
    k.setArg(4, static_cast<cl_int>(form));
    device.launch("rays", k, width, height);
    DeviceRays rays;
    rays.values = device.download<glm::vec4>(out, 2 * pixels);
    device.takePassTimes();
    return rays;
}

// Float rays of a camera at distance ~4 from the origin: positions within a few ulp of 4 (4.8e-7
// each) after 3 rounded operations, directions within a few ulp of 1 (1.2e-7 each) plus the basis
// rounded to float: 2e-6 and 1e-6 bound both with margin.
constexpr double kOriginTol = 2e-6;
constexpr double kDirectionTol = 1e-6;

void expectRaysMatchHost(const clvr::Camera& camera, Form form)
{
    const int width = 37, height = 23;  // odd, and not square: catches swapped axes and aspect
    const DeviceRays rays = deviceRays(camera, width, height, form);
    const clvr::PixelRays host(camera, width, height);
    const glm::vec3 forward(camera.forward());
    double originErr = 0.0, directionErr = 0.0, forwardErr = 0.0, stretchErr = 0.0;
    for (int y = 0; y < height; ++y)
        for (int x = 0; x < width; ++x) {
            const std::size_t i = static_cast<std::size_t>(y) * width + x;
            const clvr::Ray want = host.at(x, y);
            const glm::dvec3 d(rays.direction(i));
            originErr = std::max(originErr, glm::length(glm::dvec3(rays.origin(i)) - want.origin));
            directionErr = std::max(directionErr, glm::length(glm::normalize(d) - want.direction));
            if (camera.parallel) {
                EXPECT_EQ(rays.direction(i), forward) << "pixel " << x << ", " << y;  // forward, not rounded
            } else if (form == Depth || form == OffsetFirst) {
                // eye depth parametrization: dot(d, forward) = 1, |d| = the stretch = 1 / cos(theta)
                forwardErr = std::max(forwardErr, std::abs(glm::dot(d, glm::dvec3(forward)) - 1.0));
                stretchErr = std::max(stretchErr, std::abs(glm::length(d) - rays.stretch(i)));
            } else {
                forwardErr = std::max(forwardErr, std::abs(glm::length(d) - 1.0));  // unit length
            }
        }
    EXPECT_LE(originErr, kOriginTol);
    EXPECT_LE(directionErr, kDirectionTol);
    EXPECT_LE(forwardErr, kDirectionTol);
    EXPECT_LE(stretchErr, kDirectionTol);
}

TEST(Ray, EveryFormMatchesHostRaysPerspective)
{
    const clvr::Camera camera = clvr::test::obliquePerspectiveCamera(30.0);
    for (Form form : {Depth, Unit, OffsetFirst, RoundedTerms}) {
        SCOPED_TRACE(form);
        expectRaysMatchHost(camera, form);
    }
}

TEST(Ray, EveryFormMatchesHostRaysParallel)
{
    const clvr::Camera camera = clvr::test::obliqueParallelCamera(1.3);
    for (Form form : {Depth, Unit, OffsetFirst, RoundedTerms}) {
        SCOPED_TRACE(form);
        expectRaysMatchHost(camera, form);
    }
}

// Row 0 is the top of the image and column 0 its left: the first pixel's ray leans up and left.
TEST(Ray, RowZeroIsTheTopRow)
{
    const clvr::Camera camera = clvr::test::obliquePerspectiveCamera(30.0);
    const DeviceRays rays = deviceRays(camera, 37, 23, Unit);
    const glm::dvec3 d(rays.direction(0));
    EXPECT_GT(glm::dot(d, camera.up()), 0.0);
    EXPECT_LT(glm::dot(d, camera.right()), 0.0);
    const glm::dvec3 last(rays.direction(37 * 23 - 1));
    EXPECT_LT(glm::dot(last, camera.up()), 0.0);
    EXPECT_GT(glm::dot(last, camera.right()), 0.0);
}

}  // namespace
