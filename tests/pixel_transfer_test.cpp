// tests/pixel_transfer_test.cpp — kernels/pixel_transfer.cl against raster/reference/pixel_transfer.cpp
// (double), and analytic checks: shifted draws land shifted, an identity-ramp pixel texture returns
// the coordinates, glAccum's formulas.
#include "host/runtime/errors.h"
#include "raster/framebuffer.h"
#include "raster/pixel_transfer.h"
#include "raster/reference/pixel_transfer.h"
#include "raster/texture.h"
#include "tests/support/test_util.h"

#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <vector>

namespace {

using clvr::Image4d;
using clvr::Image4f;
using clvr::raster::AccumOp;
using clvr::raster::DrawPixelsBlend;
using clvr::raster::Filter;
using clvr::raster::Framebuffer;
using clvr::raster::PixelTransfer;
using clvr::raster::Texture;
using clvr::raster::TextureDesc;
using clvr::raster::Wrap;
namespace ref = clvr::raster::reference;

// Smooth ramps in [0,1] that differ per channel, so swapped channels or rows show.
Image4f rampImage(int w, int h)
{
    Image4f img(w, h);
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x)
            img.at(x, y) = {float(x) / (w - 1), float(y) / (h - 1), float(x + y) / (w + h - 2),
                            0.25f + 0.5f * float(x * y) / float((w - 1) * (h - 1))};
    return img;
}

Image4f randomImage(int w, int h, clvr::test::Rng& rng, double lo, double hi)
{
    Image4f img(w, h);
    for (glm::vec4& p : img.pixels())
        p = glm::vec4(rng.uniform(lo, hi), rng.uniform(lo, hi), rng.uniform(lo, hi), rng.uniform(lo, hi));
    return img;
}

// Not identity, not symmetric, with an alpha column: swapped rows or columns would show.
PixelTransfer testTransfer()
{
    PixelTransfer xf;
    // glm::mat4 columns; row r of the matrix is (m[0][r], m[1][r], m[2][r], m[3][r]).
    xf.colorMatrix = glm::mat4(glm::vec4(0.299f, 0.1f, -0.2f, 0.0f), glm::vec4(0.587f, 0.7f, 0.3f, 0.1f),
                               glm::vec4(0.114f, 0.2f, 0.9f, 0.0f), glm::vec4(0.0f, -0.3f, 0.05f, 0.8f));
    xf.scale = {2.0f, 2.0f, 2.0f, 1.0f};
    xf.bias = {-0.5f, -0.5f, -0.5f, 0.0f};
    return xf;
}

Image4d toDouble(const Image4f& img)
{
    return ref::toDouble(img);
}

TEST(PixelTransfer, MatchesReferenceOnRamp)
{
    clvr::Device& device = clvr::test::device();
    const Image4f input = rampImage(37, 23);  // odd sizes catch index bugs
    const PixelTransfer xf = testTransfer();
    Framebuffer fb(device, input.width(), input.height());
    fb.writeColor(device, input);
    clvr::raster::applyPixelTransfer(device, fb, xf);
    // float32 4-term dot of values <= 1 with |row| sums <= 1.3: a few ulp of 2 (2.4e-7 each), times 2,
    // plus the bias add: < 2e-6.
    EXPECT_TRUE(clvr::test::imagesNear(fb.readColor(device), ref::pixelTransfer(input, xf), {.maxAbs = 2e-6, .meanAbs = 5e-7}));
}

TEST(PixelTransfer, MatrixRowsActOnColumnVectors)
{
    // Analytic: red <- blue, green <- 2 red + alpha, blue <- 0, alpha <- green; then scale and bias.
    clvr::Device& device = clvr::test::device();
    PixelTransfer xf;
    xf.colorMatrix = glm::mat4(0.0f);
    xf.colorMatrix[2][0] = 1.0f;  // column 2 (blue) into row 0 (red)
    xf.colorMatrix[0][1] = 2.0f;
    xf.colorMatrix[3][1] = 1.0f;
    xf.colorMatrix[1][3] = 1.0f;
    xf.scale = {1.0f, 0.5f, 1.0f, 4.0f};
    xf.bias = {0.0f, 0.25f, 0.125f, 0.0f};
    Framebuffer fb(device, 3, 1);
    Image4f in(3, 1);
    in.at(0, 0) = {0.5f, 0.25f, 0.75f, 1.0f};
    in.at(1, 0) = {0.0f, 1.0f, 0.0f, 0.0f};
    in.at(2, 0) = {1.0f, 0.0f, 0.5f, 0.5f};
    fb.writeColor(device, in);
    clvr::raster::applyPixelTransfer(device, fb, xf);
    const Image4f out = fb.readColor(device);
    // Every product and sum below is exact in float.
    EXPECT_EQ(out.at(0, 0), glm::vec4(0.75f, 0.25f + 0.5f * (1.0f + 1.0f), 0.125f, 4.0f * 0.25f));
    EXPECT_EQ(out.at(1, 0), glm::vec4(0.0f, 0.25f, 0.125f, 4.0f));
    EXPECT_EQ(out.at(2, 0), glm::vec4(0.5f, 0.25f + 0.5f * 2.5f, 0.125f, 0.0f));
}

TEST(PixelTransfer, LookupTablesInterpolateLinearlyBetweenEntries)
{
    clvr::Device& device = clvr::test::device();
    clvr::test::Rng rng(31);
    const Image4f input = randomImage(37, 23, rng, -0.2, 1.2);  // outside [0,1] clamps the index
    PixelTransfer xf = testTransfer();
    std::array<std::vector<float>, 4> tables;
    for (int i = 0; i < 16; ++i)
        tables[0].push_back(static_cast<float>(rng.uniform()));
    tables[1] = {0.375f};  // one entry: a constant
    // tables[2] empty: blue unchanged
    for (int i = 0; i < 33; ++i)
        tables[3].push_back(static_cast<float>(rng.uniform(-1.0, 2.0)));
    xf.lookup = tables;
    Framebuffer fb(device, input.width(), input.height());
    fb.writeColor(device, input);
    clvr::raster::applyPixelTransfer(device, fb, xf);
    // The transfer's error (< 2e-6, above) moves the index x = c (n - 1) by < 2e-6 * 32 entries, and
    // rounding of x (ulp of 32: 4e-6) adds 4e-6 entries; each times an entry step <= 3: 2e-4. Then the
    // float mix() rounding (< 5e-7). Bound 2.5e-4 max; the mean is two orders smaller.
    EXPECT_TRUE(clvr::test::imagesNear(fb.readColor(device), ref::pixelTransfer(input, xf), {.maxAbs = 2.5e-4, .meanAbs = 5e-6}));

    // Analytic: the identity table i / (n - 1) returns clamp(c, 0, 1).
    PixelTransfer identity;
    std::array<std::vector<float>, 4> ramp;
    for (auto& t : ramp)
        for (int i = 0; i < 9; ++i)
            t.push_back(i / 8.0f);
    identity.lookup = ramp;
    fb.writeColor(device, input);
    clvr::raster::applyPixelTransfer(device, fb, identity);
    Image4d want(input.width(), input.height());
    for (std::size_t i = 0; i < input.pixelCount(); ++i)
        want.pixels()[i] = glm::clamp(glm::dvec4(input.pixels()[i]), 0.0, 1.0);
    // x = c * 8 rounds by <= 0.5 ulp of 8 (4.8e-7), / 8 entries per unit: 6e-8; mix rounds once: 6e-8.
    EXPECT_TRUE(clvr::test::imagesNear(fb.readColor(device), want, {.maxAbs = 3e-7, .meanAbs = 1e-7}));
}

TEST(PixelTransfer, DrawPixelsOffsetLandsShiftedAndDropsOutside)
{
    clvr::Device& device = clvr::test::device();
    const glm::vec4 background{0.1f, 0.2f, 0.3f, 0.4f};
    Image4f src(11, 7);
    for (int y = 0; y < 7; ++y)
        for (int x = 0; x < 11; ++x)
            src.at(x, y) = {float(x), float(y), float(x * 7 + y), 1.0f};  // every pixel distinct
    for (const glm::ivec2 offset : {glm::ivec2(5, 3), glm::ivec2(-4, -2), glm::ivec2(30, 19), glm::ivec2(-11, 0),
                                    glm::ivec2(100, 0), glm::ivec2(0, -7), glm::ivec2(26, 16)}) {
        SCOPED_TRACE("offset (" + std::to_string(offset.x) + ", " + std::to_string(offset.y) + ")");
        Framebuffer fb(device, 37, 23);
        fb.clearColor(device, background);
        clvr::raster::drawPixels(device, fb, src, offset, PixelTransfer{});
        const Image4f out = fb.readColor(device);
        int drawn = 0;
        for (int y = 0; y < 23; ++y)
            for (int x = 0; x < 37; ++x) {
                const int sx = x - offset.x, sy = y - offset.y;
                const bool inside = sx >= 0 && sy >= 0 && sx < 11 && sy < 7;
                drawn += inside;
                // Identity transfer and replace: copies, exactly.
                ASSERT_EQ(out.at(x, y), inside ? src.at(sx, sy) : background) << "pixel (" << x << ", " << y << ")";
            }
        const int wantDrawn = std::max(0, std::min(37, offset.x + 11) - std::max(0, offset.x)) *
                              std::max(0, std::min(23, offset.y + 7) - std::max(0, offset.y));
        EXPECT_EQ(drawn, wantDrawn);
    }
}

TEST(PixelTransfer, DrawPixelsBlendsMatchReference)
{
    clvr::Device& device = clvr::test::device();
    clvr::test::Rng rng(5);
    const Image4f dstImage = randomImage(37, 23, rng, 0.0, 1.0);
    const Image4f src = rampImage(19, 13);
    const PixelTransfer xf = testTransfer();
    for (DrawPixelsBlend blend : {DrawPixelsBlend::Replace, DrawPixelsBlend::Add, DrawPixelsBlend::Subtract,
                                  DrawPixelsBlend::ReverseSubtract, DrawPixelsBlend::Min, DrawPixelsBlend::Max}) {
        SCOPED_TRACE("blend " + std::to_string(static_cast<int>(blend)));
        Framebuffer fb(device, 37, 23);
        fb.writeColor(device, dstImage);
        clvr::raster::drawPixels(device, fb, src, {24, -3}, xf, blend);
        // The transfer's error (< 2e-6) plus one float add or subtract of values < 3 (1.2e-7 each).
        EXPECT_TRUE(clvr::test::imagesNear(fb.readColor(device), ref::drawPixels(toDouble(dstImage), src, {24, -3}, xf, blend),
                                           {.maxAbs = 3e-6, .meanAbs = 5e-7}));
    }
}

// texel (i, j, k) = ((i + 0.5) / nx, (j + 0.5) / ny, (k + 0.5) / nz, 1): linear reproduces str.
ref::TextureData identityRamp(int nx, int ny, int nz, Wrap wrap)
{
    ref::TextureData t{{nx, ny, nz, 4, Filter::Linear, wrap, glm::vec4(0.0f)}, {}};
    for (int k = 0; k < nz; ++k)
        for (int j = 0; j < ny; ++j)
            for (int i = 0; i < nx; ++i)
                for (float v : {(i + 0.5f) / nx, (j + 0.5f) / ny, (k + 0.5f) / nz, 1.0f})
                    t.texels.push_back(v);
    return t;
}

TEST(PixelTransfer, PixelTextureWithIdentityRampReturnsTheCoordinates)
{
    clvr::Device& device = clvr::test::device();
    clvr::test::Rng rng(11);
    const ref::TextureData ramp = identityRamp(9, 7, 5, Wrap::ClampToEdge);
    const Texture texture(device, ramp.desc, ramp.texels);
    Image4f input(37, 23);
    const int n[3] = {9, 7, 5};
    for (glm::vec4& p : input.pixels()) {
        for (int a = 0; a < 3; ++a)  // between the outermost texel centers, where the ramp is linear
            p[a] = static_cast<float>(rng.uniform(0.5 / n[a], 1.0 - 0.5 / n[a]));
        p.w = static_cast<float>(rng.uniform());
    }
    Framebuffer fb(device, 37, 23);
    fb.writeColor(device, input);
    clvr::raster::pixelTexture(device, fb, texture);
    Image4d want(37, 23);
    for (std::size_t i = 0; i < input.pixelCount(); ++i)
        want.pixels()[i] = glm::dvec4(glm::dvec3(input.pixels()[i]), 1.0);  // alpha: the texel's 1
    // As Texture.LinearFilteringReproducesALinearRamp: the weight is off by ~1 ulp of u n <= 9.5
    // (1e-6), / n per axis; 7 mix() roundings (6e-8 each). Bound 1e-6.
    EXPECT_TRUE(clvr::test::imagesNear(fb.readColor(device), want, {.maxAbs = 1e-6, .meanAbs = 3e-7}));
}

TEST(PixelTransfer, PixelTextureMatchesReferenceInBothWrapModes)
{
    clvr::Device& device = clvr::test::device();
    clvr::test::Rng rng(12);
    for (Wrap wrap : {Wrap::ClampToEdge, Wrap::ClampToBorder}) {
        ref::TextureData t{{6, 5, 4, 4, Filter::Linear, wrap, {0.2f, 0.4f, 0.6f, 0.8f}}, {}};
        for (int i = 0; i < 6 * 5 * 4 * 4; ++i)
            t.texels.push_back(static_cast<float>(rng.uniform()));
        const Texture texture(device, t.desc, t.texels);
        const Image4f input = randomImage(37, 23, rng, -0.2, 1.2);
        Framebuffer fb(device, 37, 23);
        fb.writeColor(device, input);
        clvr::raster::pixelTexture(device, fb, texture);
        // As Texture.SamplingMatchesReferenceInEveryModeAndDimension (linear): 5e-6.
        EXPECT_TRUE(clvr::test::imagesNear(fb.readColor(device), ref::pixelTexture(input, t), {.maxAbs = 5e-6, .meanAbs = 1e-6}));
    }
}

// Gradientless shading (seeds/000 §3): the scalar image drawn through the pixel texture, then drawn
// again shifted by one pixel towards the light and subtracted (ReverseSubtract: d - s).
TEST(PixelTransfer, ShiftedPixelTextureDrawsSubtractAsReference)
{
    clvr::Device& device = clvr::test::device();
    clvr::test::Rng rng(13);
    ref::TextureData t{{8, 8, 8, 1, Filter::Linear, Wrap::ClampToEdge, glm::vec4(0.0f)}, {}};
    for (int i = 0; i < 8 * 8 * 8; ++i)
        t.texels.push_back(static_cast<float>(rng.uniform()));
    const Texture texture(device, t.desc, t.texels);
    const Image4f coords = randomImage(37, 23, rng, 0.0, 1.0);
    PixelTransfer xf;
    xf.bias = {0.0625f, -0.0625f, 0.0f, 0.0f};
    Framebuffer fb(device, 37, 23);
    fb.clearColor(device, glm::vec4(0.0f));
    clvr::raster::drawPixels(device, fb, coords, {0, 0}, xf, DrawPixelsBlend::Replace, &texture);
    clvr::raster::drawPixels(device, fb, coords, {1, -1}, xf, DrawPixelsBlend::ReverseSubtract, &texture);
    Image4d want(37, 23, glm::dvec4(0.0));
    want = ref::drawPixels(want, coords, {0, 0}, xf, DrawPixelsBlend::Replace, &t);
    want = ref::drawPixels(want, coords, {1, -1}, xf, DrawPixelsBlend::ReverseSubtract, &t);
    // The bias add rounds the coordinate by <= 6e-8 (a slope of <= 8 texels per unit times a texel
    // step <= 1: 5e-7 per axis), plus the sampling bound 5e-6, twice (two draws): 1.2e-5.
    EXPECT_TRUE(clvr::test::imagesNear(fb.readColor(device), want, {.maxAbs = 1.2e-5, .meanAbs = 2e-6}));
}

TEST(PixelTransfer, AccumulationOpsFollowGLFormulas)
{
    clvr::Device& device = clvr::test::device();
    clvr::test::Rng rng(17);
    const Image4f a = randomImage(37, 23, rng, 0.0, 1.0);
    const Image4f b = rampImage(37, 23);
    Framebuffer fb(device, 37, 23, true);
    fb.clearAccum(device, glm::vec4(0.3f));
    Image4d color = toDouble(a), acc(37, 23, glm::dvec4(double(0.3f)));

    // Each step rounds once in float (values <= 2: <= 1.2e-7), and Accum's multiply-add at most twice;
    // five steps accumulate < 1e-6. The expected planes follow GL 1.2 §4.2.4, written out here.
    const clvr::test::Tolerance tol{.maxAbs = 1e-6, .meanAbs = 3e-7};
    fb.writeColor(device, a);
    clvr::raster::accumulate(device, fb, AccumOp::Load, 0.5f);  // acc = 0.5 a
    for (std::size_t i = 0; i < acc.pixelCount(); ++i)
        acc.pixels()[i] = 0.5 * glm::dvec4(a.pixels()[i]);
    EXPECT_TRUE(clvr::test::imagesNear(fb.readAccum(device), acc, tol)) << "Load";

    fb.writeColor(device, b);
    clvr::raster::accumulate(device, fb, AccumOp::Accum, 0.25f);  // acc += 0.25 b
    for (std::size_t i = 0; i < acc.pixelCount(); ++i)
        acc.pixels()[i] += 0.25 * glm::dvec4(b.pixels()[i]);
    EXPECT_TRUE(clvr::test::imagesNear(fb.readAccum(device), acc, tol)) << "Accum";

    clvr::raster::accumulate(device, fb, AccumOp::Mult, 1.75f);  // acc *= 1.75
    for (glm::dvec4& p : acc.pixels())
        p *= 1.75;
    EXPECT_TRUE(clvr::test::imagesNear(fb.readAccum(device), acc, tol)) << "Mult";

    clvr::raster::accumulate(device, fb, AccumOp::Add, -0.125f);  // acc += -0.125
    for (glm::dvec4& p : acc.pixels())
        p += glm::dvec4(-0.125);
    EXPECT_TRUE(clvr::test::imagesNear(fb.readAccum(device), acc, tol)) << "Add";

    clvr::raster::accumulate(device, fb, AccumOp::Return, 1.5f);  // color = 1.5 acc
    Image4d wantColor(37, 23);
    for (std::size_t i = 0; i < acc.pixelCount(); ++i)
        wantColor.pixels()[i] = 1.5 * acc.pixels()[i];
    EXPECT_TRUE(clvr::test::imagesNear(fb.readColor(device), wantColor, tol)) << "Return";
    EXPECT_TRUE(clvr::test::imagesNear(fb.readAccum(device), acc, tol)) << "Return leaves acc";

    // The reference module agrees with the formulas above.
    Image4d refColor = toDouble(a), refAcc(37, 23, glm::dvec4(double(0.3f)));
    ref::accumulate(refColor, refAcc, AccumOp::Load, 0.5);
    refColor = toDouble(b);
    ref::accumulate(refColor, refAcc, AccumOp::Accum, 0.25);
    ref::accumulate(refColor, refAcc, AccumOp::Mult, 1.75);
    ref::accumulate(refColor, refAcc, AccumOp::Add, -0.125);
    ref::accumulate(refColor, refAcc, AccumOp::Return, 1.5);
    for (std::size_t i = 0; i < acc.pixelCount(); ++i) {
        ASSERT_EQ(refAcc.pixels()[i], acc.pixels()[i]);
        ASSERT_EQ(refColor.pixels()[i], wantColor.pixels()[i]);
    }
}

TEST(PixelTransfer, BadInputsThrow)
{
    clvr::Device& device = clvr::test::device();
    Framebuffer fb(device, 5, 4);
    EXPECT_THROW(clvr::raster::accumulate(device, fb, AccumOp::Load, 1.0f), clvr::InternalError) << "no accum buffer";
    EXPECT_THROW(clvr::raster::drawPixels(device, fb, Image4f(), {0, 0}, PixelTransfer{}), clvr::InternalError);
    PixelTransfer huge;
    huge.lookup = std::array<std::vector<float>, 4>{};
    (*huge.lookup)[2].resize((std::size_t(1) << 20) + 1);
    EXPECT_THROW(clvr::raster::applyPixelTransfer(device, fb, huge), clvr::InputError);
    Framebuffer withAccum(device, 5, 4, true);
    EXPECT_THROW(clvr::raster::accumulate(device, withAccum, static_cast<AccumOp>(9), 1.0f), clvr::InternalError);
}

}  // namespace
