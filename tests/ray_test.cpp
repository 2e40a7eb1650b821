// tests/ray_test.cpp — kernels/ray.h against host/model/camera.cpp's PixelRays (double precision): every
// pixel of an odd-sized image, both cameras, each of the three forms the kernels use.
#include "host/model/camera.h"
#include "host/render/camera_args.h"
#include "tests/support/test_util.h"

#include <gtest/gtest.h>

#include <algorithm>
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

// Sort-first (Camera::bandFullHeight): a band of rows [7, 12) of a 37x23 image renders the full image's
// rays of those rows, on the host, in the kernels (bit for bit) and through the raster stage's projection.
TEST(Ray, BandRaysAreTheFullImagesRows)
{
    for (const clvr::Camera& full : {clvr::test::obliquePerspectiveCamera(30.0), clvr::test::obliqueParallelCamera(1.3)}) {
        SCOPED_TRACE(full.parallel ? "parallel" : "perspective");
        const int width = 37, height = 23, y0 = 7, rows = 5;
        clvr::Camera band = full;
        band.bandFullHeight = height;
        band.bandY0 = y0;
        const clvr::PixelRays wholeRays(full, width, height), bandRays(band, width, rows);
        const DeviceRays device = deviceRays(band, width, rows, Unit);
        double hostErr = 0.0, originErr = 0.0, directionErr = 0.0;
        for (int y = 0; y < rows; ++y)
            for (int x = 0; x < width; ++x) {
                const clvr::Ray want = wholeRays.at(x, y0 + y), got = bandRays.at(x, y);
                hostErr = std::max({hostErr, glm::length(got.origin - want.origin), glm::length(got.direction - want.direction)});
                const std::size_t i = static_cast<std::size_t>(y) * width + x;
                originErr = std::max(originErr, glm::length(glm::dvec3(device.origin(i)) - want.origin));
                directionErr = std::max(directionErr, glm::length(glm::normalize(glm::dvec3(device.direction(i))) - want.direction));
            }
        EXPECT_LE(hostErr, 1e-12);
        EXPECT_LE(originErr, kOriginTol);
        EXPECT_LE(directionErr, kDirectionTol);
        // And bit for bit the full image's device rays of those rows (the band's window is moved to the
        // full image's before ndc is taken: kernels/ray.h clvr_ray_window_offset).
        const DeviceRays wholeDevice = deviceRays(full, width, height, Unit);
        int differing = 0;
        for (std::size_t i = 0; i < 2 * static_cast<std::size_t>(width) * rows; ++i)
            differing += device.values[i] != wholeDevice.values[2 * static_cast<std::size_t>(width) * y0 + i];
        EXPECT_EQ(differing, 0) << "of " << 2 * width * rows << " ray vectors";
        // The projection: a point on the ray through a band pixel's centre lands on that pixel's centre of the
        // band's viewport (rows counted from the top, as the framebuffer's).
        const glm::dmat4 wholePv = full.projectionMatrix(width, height, 0.1, 100.0) * full.viewMatrix();
        const glm::dmat4 bandPv = band.projectionMatrix(width, rows, 0.1, 100.0) * band.viewMatrix();
        for (int y = 0; y < rows; ++y) {
            const clvr::Ray r = wholeRays.at(11, y0 + y);
            const glm::dvec4 p(r.origin + 3.0 * r.direction, 1.0);
            const glm::dvec4 cw = wholePv * p, cb = bandPv * p;
            const double rowWhole = (1.0 - cw.y / cw.w) * 0.5 * height - 0.5, rowBand = (1.0 - cb.y / cb.w) * 0.5 * rows - 0.5;
            EXPECT_NEAR(rowWhole, y0 + y, 1e-9);
            EXPECT_NEAR(rowBand, y, 1e-9);
            EXPECT_NEAR(cb.x / cb.w, cw.x / cw.w, 1e-12);
            EXPECT_NEAR(cb.z / cb.w, cw.z / cw.w, 1e-12);  // the same depth
        }
    }
}

}  // namespace
