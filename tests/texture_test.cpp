// tests/texture_test.cpp — kernels/texture.h against raster/reference/texture.cpp (double), and
// analytic checks: a linear ramp texture reproduces the coordinate; nearest returns stored texels.
#include "host/runtime/errors.h"
#include "raster/reference/texture.h"
#include "raster/texture.h"
#include "tests/support/test_util.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstddef>
#include <limits>
#include <sstream>
#include <string>
#include <vector>

namespace {

using clvr::raster::Filter;
using clvr::raster::Texture;
using clvr::raster::TextureDesc;
using clvr::raster::Wrap;

// The texture sampled on the device at every coordinate (kernels/texture_test.cl).
std::vector<glm::vec4> sampleOnDevice(const TextureDesc& desc, const std::vector<float>& texels, int dimensions,
                                      const std::vector<glm::vec4>& coords)
{
    clvr::Device& device = clvr::test::device();
    Texture texture(device, desc, texels);
    cl::Buffer in = device.upload("coordinates", coords);
    cl::Buffer out = device.buffer("samples", coords.size() * sizeof(cl_float4), CL_MEM_WRITE_ONLY);
    cl::Kernel k = device.kernel("texture_test.cl", "texture_sample");
    k.setArg(0, texture.buffer());
    k.setArg(1, texture.toCl());
    k.setArg(2, static_cast<cl_uint>(dimensions));
    k.setArg(3, in);
    k.setArg(4, out);
    k.setArg(5, static_cast<cl_uint>(coords.size()));
    device.launch("texture sample", k, coords.size());
    return device.download<glm::vec4>(out, coords.size());
}

// Max and mean absolute error over all samples and channels; NaN fails; names the worst sample.
testing::AssertionResult samplesNear(const std::vector<glm::vec4>& got, const std::vector<glm::dvec4>& want,
                                     const std::vector<glm::vec4>& coords, double maxAbs, double meanAbs)
{
    double worst = -1.0, sum = 0.0;
    std::size_t worstAt = 0, nans = 0;
    for (std::size_t i = 0; i < got.size(); ++i)
        for (int c = 0; c < 4; ++c) {
            const double d = std::abs(double(got[i][c]) - want[i][c]);
            if (std::isnan(d)) {
                ++nans;
                continue;
            }
            sum += d;
            if (d > worst)
                worst = d, worstAt = i;
        }
    const double mean = sum / (4.0 * got.size());
    if (nans == 0 && worst <= maxAbs && mean <= meanAbs)
        return testing::AssertionSuccess();
    const glm::vec4 g = got[worstAt];
    const glm::dvec4 w = want[worstAt];
    const glm::vec4 c = coords[worstAt];
    std::ostringstream msg;
    msg.precision(9);
    msg << "max |diff| " << worst << " (tolerance " << maxAbs << ") at sample " << worstAt << " coord (" << c.x
        << ", " << c.y << ", " << c.z << "): got (" << g.x << ", " << g.y << ", " << g.z << ", " << g.w
        << "), want (" << w.x << ", " << w.y << ", " << w.z << ", " << w.w << "); mean " << mean << " (tolerance "
        << meanAbs << "); NaN " << nans;
    return testing::AssertionFailure() << msg.str();
}

// The smallest float u with u * n >= i in exact arithmetic. The device rounds u * n to float, and
// rounding is monotone with i representable, so it too gets u * n >= i: nearest picks texel i on
// both sides. (A float just below i / n can round up to i on the device and down in double.)
float edgeCoordinate(int i, int n)
{
    float u = static_cast<float>(double(i) / n);
    while (double(u) * n < i)
        u = std::nextafter(u, 2.0f);
    while (double(std::nextafter(u, -2.0f)) * n >= i)
        u = std::nextafter(u, -2.0f);
    return u;
}

// True when u * n is within `margin` texels of an integer: a nearest boundary, where float rounding
// of u * n (0.5 ulp, < 1e-6 texel for n <= 16) could pick the other texel than double does.
bool nearBoundary(float u, int n, double margin)
{
    const double p = double(u) * n;
    return std::abs(p - std::round(p)) < margin;
}

struct Case {
    int dimensions;
    int width, height, depth, channels;
};

std::string name(const Case& c, const TextureDesc& d)
{
    return std::to_string(c.dimensions) + "D " + std::to_string(c.width) + "x" + std::to_string(c.height) + "x" +
           std::to_string(c.depth) + " x" + std::to_string(c.channels) +
           (d.filter == Filter::Nearest ? " nearest" : " linear") +
           (d.wrap == Wrap::ClampToEdge ? " clamp-to-edge" : " clamp-to-border");
}

// Coordinates: random in [-0.3, 1.3] per axis; every texel center and every texel edge along each
// axis (others random); and far outside. For nearest, random ones within 1e-4 texel of a boundary
// are drawn again and edges are exactly representable-side (edgeCoordinate).
std::vector<glm::vec4> coordinates(const Case& c, Filter filter, clvr::test::Rng& rng)
{
    const int n[3] = {c.width, c.height, c.depth};
    const bool nearest = filter == Filter::Nearest;
    auto draw = [&](int axis) {
        for (;;) {
            const float u = static_cast<float>(rng.uniform(-0.3, 1.3));
            if (!nearest || !nearBoundary(u, n[axis], 1e-4))
                return u;
        }
    };
    auto random = [&] { return glm::vec4(draw(0), draw(1), draw(2), 0.0f); };
    std::vector<glm::vec4> out;
    for (int i = 0; i < 400; ++i)
        out.push_back(random());
    for (int axis = 0; axis < c.dimensions; ++axis)
        for (int i = 0; i <= n[axis]; ++i) {
            glm::vec4 center = random(), edge = random();
            if (i < n[axis])
                center[axis] = static_cast<float>((i + 0.5) / n[axis]), out.push_back(center);
            edge[axis] = edgeCoordinate(i, n[axis]);
            out.push_back(edge);
        }
    for (float far : {-1e30f, -3.0f, 2.5f, 1e30f, std::numeric_limits<float>::infinity(),
                      -std::numeric_limits<float>::infinity()}) {
        glm::vec4 v = random();
        v[rng.integer(0, c.dimensions - 1)] = far;
        out.push_back(v);
    }
    return out;
}

TEST(Texture, LayoutMatchesTheDevice)
{
    clvr::Device& device = clvr::test::device();
    cl::Buffer out = device.buffer("layout", 4 * sizeof(cl_uint));
    cl::Kernel k = device.kernel("texture_test.cl", "texture_layout");
    k.setArg(0, out);
    device.launch("texture layout", k, 1);
    const std::vector<cl_uint> got = device.download<cl_uint>(out, 4);
    EXPECT_EQ(got[0], sizeof(ClTexture));
    EXPECT_EQ(got[1], offsetof(ClTexture, channels));
    EXPECT_EQ(got[2], offsetof(ClTexture, filter));
    EXPECT_EQ(got[3], offsetof(ClTexture, border));
}

TEST(Texture, SamplingMatchesReferenceInEveryModeAndDimension)
{
    const Case cases[] = {{1, 13, 1, 1, 4}, {1, 9, 1, 1, 1}, {2, 7, 5, 1, 4}, {2, 6, 3, 1, 1},
                          {3, 5, 4, 3, 4},  {3, 4, 3, 5, 1}};
    clvr::test::Rng rng(20240611);
    for (const Case& c : cases)
        for (Filter filter : {Filter::Nearest, Filter::Linear})
            for (Wrap wrap : {Wrap::ClampToEdge, Wrap::ClampToBorder}) {
                TextureDesc d{c.width, c.height, c.depth, c.channels, filter, wrap, {0.25f, 0.5f, 0.75f, 1.0f}};
                if (c.channels == 1)
                    d.border = glm::vec4(0.625f);  // GL uses the border's R for INTENSITY; keep them equal
                SCOPED_TRACE(name(c, d));
                std::vector<float> texels(static_cast<std::size_t>(c.width) * c.height * c.depth * c.channels);
                for (float& v : texels)
                    v = static_cast<float>(rng.uniform());
                const std::vector<glm::vec4> coords = coordinates(c, filter, rng);
                std::vector<glm::dvec4> want;
                for (const glm::vec4& u : coords)
                    want.push_back(clvr::raster::reference::sampleTexture(d, texels, glm::dvec3(u), c.dimensions));
                const std::vector<glm::vec4> got = sampleOnDevice(d, texels, c.dimensions, coords);
                if (filter == Filter::Nearest) {
                    // Nearest copies a stored float (or the border): exact, given coordinates off boundaries.
                    EXPECT_TRUE(samplesNear(got, want, coords, 0.0, 0.0));
                } else {
                    // Texel values in [0,1]. Per axis the weight f = frac(float(u n) - 0.5) is off by at most
                    // ~1 ulp of n + 0.5 <= 16 (1e-6), times a texel difference <= 1; 3 axes: 3e-6. Up to 7
                    // float mix() roundings of values <= 1 add < 1e-6. Bound 5e-6; the mean is far smaller.
                    EXPECT_TRUE(samplesNear(got, want, coords, 5e-6, 1e-6));
                }
            }
}

TEST(Texture, NaNCoordinateSamplesADefinedTexel)
{
    // fmax(NaN, -0.5) is -0.5 in OpenCL C: a NaN coordinate acts as the lower limit, never NaN.
    const TextureDesc d{4, 1, 1, 1, Filter::Linear, Wrap::ClampToEdge, glm::vec4(0.0f)};
    const std::vector<float> texels = {0.2f, 0.4f, 0.6f, 0.8f};
    const std::vector<glm::vec4> coords = {glm::vec4(std::numeric_limits<float>::quiet_NaN())};
    const std::vector<glm::vec4> got = sampleOnDevice(d, texels, 1, coords);
    EXPECT_EQ(got[0], glm::vec4(0.2f));
}

// texel (i, j, k) = ((i + 0.5) / nx, (j + 0.5) / ny, (k + 0.5) / nz, 1): linear interpolation of a
// linear function is exact, so inside the texel centers the sample is the coordinate itself.
TEST(Texture, LinearFilteringReproducesALinearRamp)
{
    clvr::test::Rng rng(7);
    const int nx = 8, ny = 5, nz = 11;
    for (int dimensions = 1; dimensions <= 3; ++dimensions) {
        SCOPED_TRACE(std::to_string(dimensions) + "D");
        const int n[3] = {nx, dimensions >= 2 ? ny : 1, dimensions >= 3 ? nz : 1};
        std::vector<float> texels;
        for (int k = 0; k < n[2]; ++k)
            for (int j = 0; j < n[1]; ++j)
                for (int i = 0; i < n[0]; ++i)
                    for (float v : {(i + 0.5f) / n[0], (j + 0.5f) / n[1], (k + 0.5f) / n[2], 1.0f})
                        texels.push_back(v);
        for (Wrap wrap : {Wrap::ClampToEdge, Wrap::ClampToBorder}) {
            const TextureDesc d{n[0], n[1], n[2], 4, Filter::Linear, wrap, glm::vec4(0.0f)};
            std::vector<glm::vec4> coords;
            for (int s = 0; s < 500; ++s) {
                glm::vec4 u(0.0f);
                for (int a = 0; a < 3; ++a)  // [0.5/n, 1 - 0.5/n]: between the outermost texel centers
                    u[a] = static_cast<float>(rng.uniform(0.5 / n[a], 1.0 - 0.5 / n[a]));
                coords.push_back(u);
            }
            const std::vector<glm::vec4> got = sampleOnDevice(d, texels, dimensions, coords);
            std::vector<glm::dvec4> want;
            for (const glm::vec4& u : coords) {
                // An unused axis has one texel, holding (0 + 0.5) / 1.
                want.emplace_back(u.x, dimensions >= 2 ? u.y : 0.5, dimensions >= 3 ? u.z : 0.5, 1.0);
            }
            // Per axis: the value is t_i + f (t_i+1 - t_i) = t_i + f / n; f is off by ~1 ulp of u n <= 11.5
            // (1e-6), so 1e-7 after / n; each mix() rounds once (6e-8 at values <= 1), 7 of them, and
            // float(u) vs u in double is the same number. Bound 1e-6.
            EXPECT_TRUE(samplesNear(got, want, coords, 1e-6, 3e-7));
        }
    }
}

TEST(Texture, ClampToBorderBlendsTowardsTheBorderInTheOuterHalfTexel)
{
    // 1D, 4 texels all 1, border 0: at u = 0 (the edge) linear gives half texel 0, half border.
    const TextureDesc d{4, 1, 1, 1, Filter::Linear, Wrap::ClampToBorder, glm::vec4(0.0f)};
    const std::vector<float> texels(4, 1.0f);
    const std::vector<glm::vec4> coords = {glm::vec4(0.0f), glm::vec4(1.0f), glm::vec4(0.125f), glm::vec4(-0.125f),
                                           glm::vec4(-0.0625f), glm::vec4(0.5f)};
    const std::vector<glm::vec4> got = sampleOnDevice(d, texels, 1, coords);
    const float want[] = {0.5f, 0.5f, 1.0f, 0.0f, 0.25f, 1.0f};
    for (std::size_t i = 0; i < coords.size(); ++i)
        EXPECT_EQ(got[i], glm::vec4(want[i])) << "u = " << coords[i].x;
}

TEST(Texture, BadSizesAreInputErrorsBadDescriptionsInternalErrors)
{
    clvr::Device& device = clvr::test::device();
    EXPECT_THROW(Texture(device, TextureDesc{0, 1, 1, 1}, {}), clvr::InputError);
    EXPECT_THROW(Texture(device, TextureDesc{4, 0, 1, 1}, {}), clvr::InputError);
    EXPECT_THROW(Texture(device, TextureDesc{4, 1, 1, 3}, std::vector<float>(12)), clvr::InternalError);
    EXPECT_THROW(Texture(device, TextureDesc{4, 2, 1, 4}, std::vector<float>(31)), clvr::InternalError);
    EXPECT_THROW(Texture(device, TextureDesc{4, 2, 1, 1}, std::vector<float>(9)), clvr::InternalError);
    TextureDesc bad{2, 1, 1, 1};
    bad.filter = static_cast<Filter>(7);
    EXPECT_THROW(Texture(device, bad, std::vector<float>(2)), clvr::InternalError);
    const Texture ok(device, TextureDesc{3, 2, 2, 4}, std::vector<float>(48));
    EXPECT_EQ(ok.bytes(), 48u * sizeof(float));
    EXPECT_EQ(ok.toCl().depth, 2u);
}

}  // namespace
