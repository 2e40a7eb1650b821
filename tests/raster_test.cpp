// tests/raster_test.cpp — the ordered triangle rasterizer (raster/rasterizer.h) against the CPU
// reference (raster/reference/rasterizer.h) and against closed-form geometry: coverage and stencil
// exact, color and depth within stated float tolerances, fill rule, clipping, perspective, order.
#include "host/runtime/errors.h"
#include "host/runtime/parallel.h"
#include "raster/rasterizer.h"
#include "raster/reference/rasterizer.h"
#include "raster/texture.h"
#include "tests/support/test_util.h"

#include <glm/gtc/matrix_transform.hpp>
#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <cstring>
#include <sstream>

namespace {

namespace raster = clvr::raster;
namespace ref = clvr::raster::reference;
using clvr::test::Rng;

glm::vec4 randomVec4(Rng& rng, double lo = 0.0, double hi = 1.0)
{
    return glm::vec4(rng.uniform(lo, hi), rng.uniform(lo, hi), rng.uniform(lo, hi), rng.uniform(lo, hi));
}

template <typename E>
E pick(Rng& rng, int count)
{
    return static_cast<E>(rng.integer(0, count - 1));
}

raster::FragmentState randomState(Rng& rng)
{
    raster::FragmentState s;
    s.depth.test = rng.integer(0, 2) != 0;
    s.depth.func = pick<raster::CompareFunc>(rng, 8);
    s.depth.write = rng.integer(0, 3) != 0;
    s.stencil.test = rng.integer(0, 2) != 0;
    s.stencil.func = pick<raster::CompareFunc>(rng, 8);
    s.stencil.ref = static_cast<std::uint8_t>(rng.integer(0, 255));
    s.stencil.readMask = rng.integer(0, 1) ? 0xff : static_cast<std::uint8_t>(rng.integer(0, 255));
    s.stencil.writeMask = rng.integer(0, 1) ? 0xff : static_cast<std::uint8_t>(rng.integer(0, 255));
    s.stencil.sfail = pick<raster::StencilOp>(rng, 8);
    s.stencil.dpfail = pick<raster::StencilOp>(rng, 8);
    s.stencil.dppass = pick<raster::StencilOp>(rng, 8);
    s.alpha.test = rng.integer(0, 3) == 0;
    s.alpha.func = pick<raster::CompareFunc>(rng, 8);
    s.alpha.ref = static_cast<float>(rng.uniform(0.0, 1.0));
    s.blend.enabled = rng.integer(0, 3) != 0;
    s.blend.rgbEquation = pick<raster::BlendEquation>(rng, 5);
    s.blend.alphaEquation = pick<raster::BlendEquation>(rng, 5);
    s.blend.srcRgb = pick<raster::BlendFactor>(rng, 15);
    s.blend.dstRgb = pick<raster::BlendFactor>(rng, 15);
    s.blend.srcAlpha = pick<raster::BlendFactor>(rng, 15);
    s.blend.dstAlpha = pick<raster::BlendFactor>(rng, 15);
    s.blend.constant = randomVec4(rng);
    s.colorMask = {rng.integer(0, 3) != 0, rng.integer(0, 3) != 0, rng.integer(0, 3) != 0, rng.integer(0, 3) != 0};
    s.cull = pick<raster::CullFace>(rng, 4);
    if (s.cull == raster::CullFace::FrontAndBack)  // keep most draws visible
        s.cull = raster::CullFace::None;
    s.frontFaceCCW = rng.integer(0, 1) != 0;
    return s;
}

// Clip-space vertices with w in [0.3, 2] and x, y, z up to 1.4 w: some cross the near, far and
// guard-free x/y limits, so clipping and the viewport scissor are exercised.
std::vector<raster::Vertex> randomVertices(Rng& rng, int count)
{
    std::vector<raster::Vertex> v(count);
    for (raster::Vertex& x : v) {
        const double w = rng.uniform(0.3, 2.0);
        x.position = glm::vec4(rng.uniform(-1.4, 1.4) * w, rng.uniform(-1.4, 1.4) * w, rng.uniform(-1.4, 1.4) * w, w);
        for (glm::vec4& a : x.attributes)
            a = randomVec4(rng);
    }
    return v;
}

struct Scene {
    int width, height;
    std::vector<glm::vec4> color;
    std::vector<float> depth;
    std::vector<std::uint8_t> stencil;
};

Scene randomScene(Rng& rng, int width, int height)
{
    Scene s{width, height, {}, {}, {}};
    for (int i = 0; i < width * height; ++i) {
        s.color.push_back(randomVec4(rng));
        s.depth.push_back(static_cast<float>(rng.uniform(0.3, 1.0)));
        s.stencil.push_back(static_cast<std::uint8_t>(rng.integer(0, 255)));
    }
    return s;
}

void load(clvr::Device& device, raster::Framebuffer& fb, const Scene& s)
{
    clvr::Image4f image(s.width, s.height);
    image.pixels() = s.color;
    fb.writeColor(device, image);
    fb.writeDepth(device, s.depth);
    fb.writeStencil(device, s.stencil);
}

ref::Planes load(const Scene& s)
{
    ref::Planes p(s.width, s.height);
    for (std::size_t i = 0; i < s.color.size(); ++i) {
        p.color[i] = glm::dvec4(s.color[i]);
        p.depth[i] = s.depth[i];
        p.stencil[i] = s.stencil[i];
    }
    return p;
}

// Per-pixel coverage count: every generated fragment increments the stencil (wrapping).
raster::DrawState coverageCountState(const raster::DrawState& s)
{
    raster::DrawState c;
    c.clipPlanes = s.clipPlanes;
    c.viewport = s.viewport;
    c.fragment.cull = s.fragment.cull;
    c.fragment.frontFaceCCW = s.fragment.frontFaceCCW;
    c.fragment.stencil.test = true;
    c.fragment.stencil.dppass = raster::StencilOp::IncrWrap;
    return c;
}

// Color: at most ~12 layers per pixel, each of ~10 float roundings (2^-24 relative) on values of
// magnitude <= M, so |error| <= 12 * 10 * 6e-8 * M ~ 7e-6 M; we allow 2e-5 M, M = max(1, max |want|).
// Depth: three products and two sums of values <= 1 with float barycentrics: a few ulp of 1, 1e-6.
testing::AssertionResult planesNear(raster::Framebuffer& fb, clvr::Device& device, const ref::Planes& want,
                                    const std::vector<std::uint8_t>& ignore)
{
    const clvr::Image4f color = fb.readColor(device);
    const std::vector<float> depth = fb.readDepth(device);
    const std::vector<std::uint8_t> stencil = fb.readStencil(device);
    double scale = 1.0;
    for (const glm::dvec4& c : want.color)
        for (int ch = 0; ch < 4; ++ch)
            scale = std::max(scale, std::abs(c[ch]));
    const double colorTol = 2e-5 * scale, depthTol = 1e-6;
    std::ostringstream why;
    int bad = 0;
    for (std::size_t i = 0; i < want.color.size(); ++i) {
        if (ignore[i])
            continue;
        const int x = int(i % want.width), y = int(i / want.width);
        if (stencil[i] != want.stencil[i] && bad++ < 5)
            why << "stencil at (" << x << "," << y << "): got " << int(stencil[i]) << ", want " << int(want.stencil[i]) << "\n";
        if (!(std::abs(depth[i] - want.depth[i]) <= depthTol) && bad++ < 5)
            why << "depth at (" << x << "," << y << "): got " << depth[i] << ", want " << want.depth[i] << "\n";
        for (int ch = 0; ch < 4; ++ch)
            if (!(std::abs(color.pixels()[i][ch] - want.color[i][ch]) <= colorTol) && bad++ < 5)
                why << "color[" << ch << "] at (" << x << "," << y << "): got " << color.pixels()[i][ch] << ", want "
                    << want.color[i][ch] << " (tolerance " << colorTol << ")\n";
    }
    if (bad)
        return testing::AssertionFailure() << bad << " mismatches\n" << why.str();
    return testing::AssertionSuccess();
}

// Pixels whose result hinges on a float comparison that the reference finds within 1e-5 of its
// threshold (depth or alpha test): float and double may legitimately decide them differently.
struct TieFinder {
    std::vector<std::uint8_t> ties;
    explicit TieFinder(std::size_t n) : ties(n, 0) {}
};

// The reference, once more, with every depth/alpha decision within 1e-5 of its threshold marking
// the pixel; the mark sticks for later draws.
void markTies(TieFinder& t, const ref::Planes& before, const raster::DrawState& s, raster::Topology topology,
              const std::vector<raster::Vertex>& v)
{
    ref::Planes p = before;
    const raster::FragmentState& fs = s.fragment;
    ref::draw(p, coverageCountState(s), topology, v, [&](const ref::Fragment& f, glm::dvec4& color) {
        const std::size_t i = std::size_t(f.window.y) * p.width + std::size_t(f.window.x);
        if (fs.alpha.test && std::abs(f.attributes[0].a - std::clamp(double(fs.alpha.ref), 0.0, 1.0)) < 1e-5)
            t.ties[i] = 1;
        color = f.attributes[0];
        return true;
    });
    // Depth ties: replay the real draw and look at every stored depth a fragment compares against.
    ref::Planes q = before;
    raster::DrawState plain = s;
    ref::draw(q, plain, topology, v, [&](const ref::Fragment& f, glm::dvec4& color) {
        const std::size_t i = std::size_t(f.window.y) * q.width + std::size_t(f.window.x);
        if (fs.depth.test && std::abs(f.depth - q.depth[i]) < 1e-5)
            t.ties[i] = 1;
        color = f.attributes[0];
        return true;
    });
}

TEST(RasterConformance, RandomTrianglesAndStatesMatchReference)
{
    clvr::Device& device = clvr::test::device();
    Rng rng(20240611);
    const int sizes[][2] = {{37, 23}, {61, 45}};
    std::size_t tiesTotal = 0, pixelsTotal = 0;
    std::uint64_t fragmentsTotal = 0;
    for (int round = 0; round < 16; ++round) {
        SCOPED_TRACE("round " + std::to_string(round));
        const int width = sizes[round % 2][0], height = sizes[round % 2][1];
        const Scene scene = randomScene(rng, width, height);
        raster::Framebuffer fb(device, width, height);
        load(device, fb, scene);
        ref::Planes want = load(scene);
        raster::Framebuffer cover(device, width, height);
        cover.clearStencil(device, 0);
        ref::Planes coverWant(width, height);
        TieFinder ties(std::size_t(width) * height);

        const int draws = rng.integer(2, 3);
        for (int d = 0; d < draws; ++d) {
            raster::DrawState state;
            state.fragment = randomState(rng);
            for (int p = rng.integer(0, 2); p > 0; --p)
                state.clipPlanes.push_back(glm::vec4(rng.uniform(-1, 1), rng.uniform(-1, 1), rng.uniform(-1, 1), rng.uniform(-0.3, 0.3)));
            if (rng.integer(0, 2) == 0)
                state.viewport = {rng.integer(-8, 8), rng.integer(-8, 8), rng.integer(10, width), rng.integer(10, height),
                                  float(rng.uniform(0, 0.3)), float(rng.uniform(0.6, 1.0))};
            const auto topology = static_cast<raster::Topology>(rng.integer(0, 2));
            const std::vector<raster::Vertex> v = randomVertices(rng, rng.integer(12, 36));

            markTies(ties, want, state, topology, v);
            const raster::DrawStats got = raster::draw(device, fb, state, topology, v);
            const raster::DrawStats expect = ref::draw(want, state, topology, v);
            EXPECT_EQ(got.triangles, expect.triangles);
            EXPECT_EQ(got.fragments, expect.fragments);
            fragmentsTotal += got.fragments;

            raster::draw(device, cover, coverageCountState(state), topology, v);
            ref::draw(coverWant, coverageCountState(state), topology, v);
        }
        EXPECT_EQ(cover.readStencil(device), coverWant.stencil) << "coverage counts differ";
        std::size_t tieCount = 0;
        for (std::uint8_t t : ties.ties)
            tieCount += t;
        tiesTotal += tieCount;
        pixelsTotal += ties.ties.size();
        EXPECT_TRUE(planesNear(fb, device, want, ties.ties));
    }
    EXPECT_LE(tiesTotal, pixelsTotal / 200) << "near-tie pixels are excluded from the comparison; they must be rare";
    EXPECT_GT(fragmentsTotal, pixelsTotal) << "the random scenes must cover a good part of the frame buffers";
    device.takePassTimes();
}

// Vertices given directly in window coordinates (row-down pixels) for a w x h viewport, w = 1.
raster::Vertex windowVertex(double x, double y, int w, int h, glm::vec4 attr0 = glm::vec4(1.0f))
{
    raster::Vertex v;
    v.position = glm::vec4(2.0 * x / w - 1.0, 1.0 - 2.0 * y / h, 0.0, 1.0);
    v.attributes[0] = attr0;
    return v;
}

raster::DrawState additiveOnes()
{
    raster::DrawState s;
    s.fragment.blend.enabled = true;
    s.fragment.blend.srcRgb = s.fragment.blend.dstRgb = raster::BlendFactor::One;
    s.fragment.blend.srcAlpha = s.fragment.blend.dstAlpha = raster::BlendFactor::One;
    return s;
}

TEST(RasterFillRule, PixelCentersOnEdgesFollowTheTopLeftRule)
{
    clvr::Device& device = clvr::test::device();
    const int w = 13, h = 11;
    raster::Framebuffer fb(device, w, h);
    fb.clearColor(device, glm::vec4(0.0f));
    // A rectangle whose edges run exactly through pixel centers: x = 2.5 and 6.5, y = 2.5 and 5.5.
    // Left (x 2.5) and top (y 2.5) edges own their centers, right and bottom do not: columns 2..5, rows 2..4.
    const auto a = windowVertex(2.5, 2.5, w, h), b = windowVertex(6.5, 2.5, w, h);
    const auto c = windowVertex(6.5, 5.5, w, h), d = windowVertex(2.5, 5.5, w, h);
    const raster::DrawStats stats = raster::draw(device, fb, additiveOnes(), raster::Topology::Triangles, {a, b, c, a, c, d});
    EXPECT_EQ(stats.triangles, 2u);
    EXPECT_EQ(stats.fragments, 12u);
    const clvr::Image4f image = fb.readColor(device);
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x)
            EXPECT_EQ(image.at(x, y).r, (x >= 2 && x <= 5 && y >= 2 && y <= 4) ? 1.0f : 0.0f) << x << "," << y;
}

TEST(RasterFillRule, SharedEdgesCoverEveryPixelExactlyOnce)
{
    clvr::Device& device = clvr::test::device();
    const int w = 61, h = 45;
    Rng rng(77);
    for (int round = 0; round < 4; ++round) {
        SCOPED_TRACE("round " + std::to_string(round));
        raster::Framebuffer fb(device, w, h);
        fb.clearColor(device, glm::vec4(0.0f));
        // A fan around a center on a pixel center (round 0) or anywhere, 9 spokes to a convex outline,
        // then a strip over a grid with jittered vertices (some on pixel centers), both additive.
        const double cx = round == 0 ? 30.5 : rng.uniform(25, 35), cy = round == 0 ? 22.5 : rng.uniform(18, 27);
        std::vector<raster::Vertex> fan{windowVertex(cx, cy, w, h)};
        const int spokes = 9;
        for (int i = 0; i <= spokes; ++i) {
            const double angle = 2.0 * M_PI * (i % spokes) / spokes;
            const double r = round == 0 ? 10.0 : rng.uniform(8, 12);
            fan.push_back(windowVertex(std::floor(cx + r * std::cos(angle)) + 0.5, std::floor(cy + r * std::sin(angle)) + 0.5, w, h));
        }
        fan.back() = fan[1];
        raster::draw(device, fb, additiveOnes(), raster::Topology::TriangleFan, fan);
        const clvr::Image4f fanImage = fb.readColor(device);
        // The fan's pixels: inside the outline polygon per the reference (exact, same rules).
        ref::Planes want(w, h);
        ref::draw(want, additiveOnes(), raster::Topology::TriangleFan, fan);
        int covered = 0;
        for (int i = 0; i < w * h; ++i) {
            ASSERT_EQ(fanImage.pixels()[i].r, float(want.color[i].r)) << "pixel " << i % w << "," << i / w;
            ASSERT_LE(fanImage.pixels()[i].r, 1.0f) << "pixel " << i % w << "," << i / w << " hit twice";
            covered += fanImage.pixels()[i].r == 1.0f;
        }
        // No holes: every pixel center well inside the convex outline (a 2-pixel-wide disk around the center) is hit.
        for (int y = 0; y < h; ++y)
            for (int x = 0; x < w; ++x)
                if (std::hypot(x + 0.5 - cx, y + 0.5 - cy) < 5.0) {
                    ASSERT_EQ(fanImage.at(x, y).r, 1.0f) << "hole at " << x << "," << y;
                }
        EXPECT_GT(covered, 200);

        // A strip grid: 2 rows of 6 cells, vertices jittered; shared edges everywhere.
        raster::Framebuffer grid(device, w, h);
        grid.clearColor(device, glm::vec4(0.0f));
        const int cols = 6;
        double xs[3][cols + 1], ys[3][cols + 1];
        for (int r = 0; r < 3; ++r)
            for (int c = 0; c <= cols; ++c) {
                const bool snap = rng.integer(0, 1) == 0;
                const double x = 3 + c * 9 + (c > 0 && c < cols ? rng.uniform(-3, 3) : 0.0);
                const double y = 3 + r * 18 + (r == 1 ? rng.uniform(-5, 5) : 0.0);
                xs[r][c] = snap ? std::floor(x) + 0.5 : x;
                ys[r][c] = snap ? std::floor(y) + 0.5 : y;
            }
        // Interior vertices are shared between the two strips; outline vertices too.
        for (int r = 0; r < 2; ++r) {
            std::vector<raster::Vertex> strip;
            for (int c = 0; c <= cols; ++c) {
                strip.push_back(windowVertex(xs[r][c], ys[r][c], w, h));
                strip.push_back(windowVertex(xs[r + 1][c], ys[r + 1][c], w, h));
            }
            raster::draw(device, grid, additiveOnes(), raster::Topology::TriangleStrip, strip);
        }
        const clvr::Image4f gridImage = grid.readColor(device);
        for (int y = 0; y < h; ++y)
            for (int x = 0; x < w; ++x) {
                const float v = gridImage.at(x, y).r;
                ASSERT_LE(v, 1.0f) << "pixel " << x << "," << y << " hit twice";
                // Inside the outer rectangle (its sides are straight) every center is hit once.
                const bool inside = x + 0.5 > xs[0][0] && x + 0.5 < xs[0][cols] && y + 0.5 > ys[0][0] && y + 0.5 < ys[2][0];
                if (inside) {
                    ASSERT_EQ(v, 1.0f) << "hole at " << x << "," << y;
                }
            }
    }
    device.takePassTimes();
}

std::vector<std::uint8_t> bytes(const clvr::Image4f& image)
{
    std::vector<std::uint8_t> b(image.pixelCount() * sizeof(glm::vec4));
    std::memcpy(b.data(), image.pixels().data(), b.size());
    return b;
}

void expectIdentical(clvr::Device& device, raster::Framebuffer& a, raster::Framebuffer& b)
{
    EXPECT_TRUE(bytes(a.readColor(device)) == bytes(b.readColor(device))) << "color bits differ";
    const std::vector<float> da = a.readDepth(device), db = b.readDepth(device);
    EXPECT_EQ(std::memcmp(da.data(), db.data(), da.size() * sizeof(float)), 0) << "depth bits differ";
    EXPECT_EQ(a.readStencil(device), b.readStencil(device));
}

raster::DrawState blendedDepthStencil()
{
    raster::DrawState s;
    s.fragment.blend.enabled = true;
    s.fragment.blend.srcRgb = raster::BlendFactor::SrcAlpha;
    s.fragment.blend.dstRgb = raster::BlendFactor::OneMinusSrcAlpha;
    s.fragment.depth.test = true;
    s.fragment.depth.func = raster::CompareFunc::LEqual;
    s.fragment.stencil.test = true;
    s.fragment.stencil.dppass = raster::StencilOp::IncrWrap;
    s.fragment.stencil.dpfail = raster::StencilOp::Invert;
    return s;
}

TEST(RasterTopology, StripAndFanEqualTheEquivalentList)
{
    clvr::Device& device = clvr::test::device();
    Rng rng(5);
    for (raster::Topology topology : {raster::Topology::TriangleStrip, raster::Topology::TriangleFan}) {
        const std::vector<raster::Vertex> v = randomVertices(rng, 11);
        std::vector<raster::Vertex> list;
        // GL 2.1 §2.6.1, written out here rather than taken from assembleTriangles.
        for (int i = 0; i + 2 < int(v.size()); ++i) {
            if (topology == raster::Topology::TriangleStrip) {
                const int a = i % 2 ? i + 1 : i, b = i % 2 ? i : i + 1;
                list.insert(list.end(), {v[a], v[b], v[i + 2]});
            } else {
                list.insert(list.end(), {v[0], v[i + 1], v[i + 2]});
            }
        }
        raster::DrawState state = blendedDepthStencil();
        state.fragment.cull = raster::CullFace::Back;  // winding must survive the decomposition
        raster::Framebuffer a(device, 37, 23), b(device, 37, 23);
        for (raster::Framebuffer* fb : {&a, &b}) {
            fb->clearColor(device, glm::vec4(0.1f));
            fb->clearDepth(device, 1.0f);
            fb->clearStencil(device, 3);
        }
        const raster::DrawStats sa = raster::draw(device, a, state, topology, v);
        const raster::DrawStats sb = raster::draw(device, b, state, raster::Topology::Triangles, list);
        EXPECT_EQ(sa.triangles, sb.triangles);
        EXPECT_EQ(sa.fragments, sb.fragments);
        EXPECT_GT(sa.fragments, 0u);
        expectIdentical(device, a, b);
    }
    device.takePassTimes();
}

TEST(RasterTopology, FacingFollowsGlCounterClockwiseWithYUp)
{
    clvr::Device& device = clvr::test::device();
    // Counter-clockwise in NDC (y up): front for glFrontFace(GL_CCW).
    std::vector<raster::Vertex> v(3);
    v[0].position = {-0.5f, -0.5f, 0.0f, 1.0f};
    v[1].position = {0.5f, -0.5f, 0.0f, 1.0f};
    v[2].position = {0.0f, 0.5f, 0.0f, 1.0f};
    raster::FragmentProgram facing;
    facing.source = "int clvr_fragment(const ClFragment* f, const ClFragmentResources* r, float4* color)\n"
                    "{ (void)r; *color = (float4)((float)f->front_facing, 0.0f, 0.0f, 1.0f); return 1; }\n";
    for (bool ccw : {true, false})
        for (raster::CullFace cull : {raster::CullFace::None, raster::CullFace::Back, raster::CullFace::Front}) {
            raster::Framebuffer fb(device, 16, 16);
            fb.clearColor(device, glm::vec4(-1.0f));
            raster::DrawState s;
            s.fragment.frontFaceCCW = ccw;
            s.fragment.cull = cull;
            const raster::DrawStats stats = raster::draw(device, fb, s, raster::Topology::Triangles, v, facing);
            const bool front = ccw;
            const bool culled = (cull == raster::CullFace::Back && !front) || (cull == raster::CullFace::Front && front);
            EXPECT_EQ(stats.triangles, culled ? 0u : 1u) << "ccw " << ccw << " cull " << int(cull);
            const float center = fb.readColor(device).at(8, 8).r;
            EXPECT_EQ(center, culled ? -1.0f : (front ? 1.0f : 0.0f)) << "ccw " << ccw << " cull " << int(cull);
        }
    device.takePassTimes();
}

// A ground plane y = -1 seen by a perspective camera; the quad reaches behind the camera, so it
// crosses the camera plane. Attribute 0 is the world position, so at every covered pixel the
// interpolated attribute must equal the ray/plane intersection: clipping and perspective together.
TEST(RasterClipping, NearPlaneCrossingMatchesRayPlaneIntersection)
{
    clvr::Device& device = clvr::test::device();
    const int w = 61, h = 45;
    const glm::mat4 proj = glm::perspective(glm::radians(60.0f), float(w) / h, 0.5f, 100.0f);
    const glm::mat4 view = glm::lookAt(glm::vec3(0, 0, 0), glm::vec3(0, -0.3f, -1), glm::vec3(0, 1, 0));
    const glm::mat4 vp = proj * view;
    const glm::vec3 corners[4] = {{-20, -1, 10}, {20, -1, 10}, {20, -1, -40}, {-20, -1, -40}};
    std::vector<raster::Vertex> v;
    for (int i : {0, 1, 2, 0, 2, 3}) {
        raster::Vertex x;
        x.position = vp * glm::vec4(corners[i], 1.0f);
        x.attributes[0] = glm::vec4(corners[i], 1.0f);
        v.push_back(x);
    }
    ASSERT_LT(v[0].position.w, 0.0f) << "the test needs a vertex behind the camera";
    raster::Framebuffer fb(device, w, h);
    fb.clearColor(device, glm::vec4(0.0f));
    const raster::DrawStats stats = raster::draw(device, fb, raster::DrawState{}, raster::Topology::Triangles, v);
    ref::Planes want(w, h);
    const raster::DrawStats wantStats = ref::draw(want, raster::DrawState{}, raster::Topology::Triangles, v);
    EXPECT_EQ(stats.fragments, wantStats.fragments);
    EXPECT_EQ(stats.triangles, wantStats.triangles);
    const clvr::Image4f image = fb.readColor(device);
    const glm::mat4 inv = glm::inverse(vp);
    int covered = 0;
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
            const glm::vec4 got = image.at(x, y);
            EXPECT_EQ(got.a > 0.5f, want.color[std::size_t(y) * w + x].a > 0.5) << "coverage at " << x << "," << y;
            // The ray through a point of the window (row-down pixels) meets the plane y = -1 at t in (0, 1).
            const auto hit = [&](double wx, double wy, bool& hits) {
                const double nx = 2.0 * wx / w - 1.0, ny = 1.0 - 2.0 * wy / h;
                const glm::dvec4 a = glm::dmat4(inv) * glm::dvec4(nx, ny, -1, 1), b = glm::dmat4(inv) * glm::dvec4(nx, ny, 1, 1);
                const glm::dvec3 p0 = glm::dvec3(a) / a.w, p1 = glm::dvec3(b) / b.w;
                const double t = (-1.0 - p0.y) / (p1.y - p0.y);
                hits = t > 0.0 && t < 1.0;
                return p0 + t * (p1 - p0);
            };
            bool hits = false, unused = false;
            const glm::dvec3 p = hit(x + 0.5, y + 0.5, hits);
            if (got.a < 0.5f) {
                EXPECT_FALSE(hits && std::abs(p.x) < 19.0 && p.z > -39.0) << "hole at " << x << "," << y;
                continue;
            }
            ++covered;
            ASSERT_TRUE(hits) << x << "," << y;
            // Vertices are snapped to 1/256 pixel, which moves the plane a little: allow the world
            // distance of 1/64 pixel here (|dp/dpixel| from the next row), plus float rounding 1e-4 relative.
            const double footprint = glm::length(hit(x + 0.5, y + 1.5, unused) - p);
            const double tol = 1e-4 * glm::length(p) + 2e-3 + footprint / 64.0;
            EXPECT_NEAR(got.x, p.x, tol) << x << "," << y;
            EXPECT_NEAR(got.z, p.z, tol) << x << "," << y;
        }
    EXPECT_GT(covered, w * h / 4);
    device.takePassTimes();
}

TEST(RasterClipping, UserPlaneHalvesAQuad)
{
    clvr::Device& device = clvr::test::device();
    const int w = 37, h = 23;
    std::vector<raster::Vertex> quad;
    for (glm::vec2 p : {glm::vec2(-1, -1), glm::vec2(1, -1), glm::vec2(1, 1), glm::vec2(-1, -1), glm::vec2(1, 1), glm::vec2(-1, 1)}) {
        raster::Vertex v;
        v.position = glm::vec4(p, 0.0f, 1.0f);
        v.attributes[0] = glm::vec4(1.0f);
        quad.push_back(v);
    }
    raster::DrawState s;
    // A world plane x >= 0.25 through a view-projection that scales x by 2 and shifts by -0.5:
    // clip x = 2 X - 0.5, so the plane is clip x >= 0, window x >= 18.5 (that center is on the
    // clipped left edge, which owns it): columns 18..36.
    glm::mat4 viewProjection(1.0f);
    viewProjection[0][0] = 2.0f;
    viewProjection[3][0] = -0.5f;
    s.clipPlanes.push_back(raster::clipPlaneFromWorld(glm::vec4(1, 0, 0, -0.25f), viewProjection));
    EXPECT_NEAR(s.clipPlanes[0].x, 0.5f, 1e-6f);
    EXPECT_NEAR(s.clipPlanes[0].w, 0.0f, 1e-6f);
    raster::Framebuffer fb(device, w, h);
    fb.clearColor(device, glm::vec4(0.0f));
    const raster::DrawStats stats = raster::draw(device, fb, s, raster::Topology::Triangles, quad);
    EXPECT_EQ(stats.fragments, std::uint64_t((w - 18) * h));
    EXPECT_EQ(stats.triangles, 3u) << "one triangle is cut to a quad (2 triangles), the other to a triangle";
    const clvr::Image4f image = fb.readColor(device);
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x)
            ASSERT_EQ(image.at(x, y).r, x >= 18 ? 1.0f : 0.0f) << x << "," << y;
    device.takePassTimes();
}

TEST(RasterScissor, VisitsOnlyTheRectangleWithUnchangedValues)
{
    // A perspective-looking triangle with a varying attribute, drawn once whole and once scissored:
    // inside the rectangle the bits are the same (absolute edge functions), outside nothing is written.
    clvr::Device& device = clvr::test::device();
    const int w = 37, h = 23;
    std::vector<raster::Vertex> tri(3);
    tri[0].position = glm::vec4(-0.9f, -0.8f, 0.1f, 1.0f);
    tri[1].position = glm::vec4(1.7f, -1.2f, 0.5f, 2.0f);
    tri[2].position = glm::vec4(0.1f, 0.9f, -0.3f, 1.0f);
    for (int i = 0; i < 3; ++i)
        tri[i].attributes[0] = glm::vec4(0.1f * i, 1.0f - 0.3f * i, 0.7f, 1.0f);
    raster::DrawState s;
    s.fragment.depth.test = true;
    s.fragment.depth.func = raster::CompareFunc::Always;
    raster::Framebuffer whole(device, w, h), part(device, w, h);
    for (raster::Framebuffer* fb : {&whole, &part}) {
        fb->clearColor(device, glm::vec4(-1.0f));
        fb->clearDepth(device, 1.0f);
    }
    const raster::DrawStats all = raster::draw(device, whole, s, raster::Topology::Triangles, tri);
    s.scissor = {true, 5, 3, 20, 11};  // columns 5..24, rows 3..13
    const raster::DrawStats some = raster::draw(device, part, s, raster::Topology::Triangles, tri);
    const clvr::Image4f a = whole.readColor(device), b = part.readColor(device);
    const std::vector<float> da = whole.readDepth(device), db = part.readDepth(device);
    std::uint64_t inside = 0;
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
            const bool in = x >= 5 && x < 25 && y >= 3 && y < 14;
            const std::size_t i = static_cast<std::size_t>(y) * w + x;
            if (in) {
                inside += a.at(x, y).r >= 0.0f;
                ASSERT_EQ(std::memcmp(&a.at(x, y), &b.at(x, y), sizeof(a.at(x, y))), 0) << x << "," << y;
                ASSERT_EQ(da[i], db[i]) << x << "," << y;
            } else {
                ASSERT_EQ(b.at(x, y).r, -1.0f) << x << "," << y;
                ASSERT_EQ(db[i], 1.0f) << x << "," << y;
            }
        }
    EXPECT_GT(inside, 50u);
    EXPECT_LT(some.fragments, all.fragments);
    EXPECT_EQ(some.fragments, inside);
    s.scissor = {true, 0, 0, -1, 4};
    EXPECT_THROW(raster::draw(device, part, s, raster::Topology::Triangles, tri), clvr::InternalError);
    device.takePassTimes();
}

TEST(RasterInterpolation, PerspectiveCorrectNotAffine)
{
    clvr::Device& device = clvr::test::device();
    const int w = 61, h = 45;
    // A wall receding from z = -1 to z = -20, attribute u = 0 at the near side and 1 at the far side.
    const glm::mat4 vp = glm::perspective(glm::radians(60.0f), float(w) / h, 0.5f, 50.0f);
    const glm::vec3 p[4] = {{-1, -1, -1}, {-1, -1, -20}, {-1, 1, -20}, {-1, 1, -1}};
    const float u[4] = {0, 1, 1, 0};
    std::vector<raster::Vertex> v;
    for (int i : {0, 1, 2, 0, 2, 3}) {
        raster::Vertex x;
        x.position = vp * glm::vec4(p[i], 1.0f);
        x.attributes[0] = glm::vec4(u[i], 0, 0, 1);
        v.push_back(x);
    }
    raster::Framebuffer fb(device, w, h);
    fb.clearColor(device, glm::vec4(-1.0f));
    raster::draw(device, fb, raster::DrawState{}, raster::Topology::Triangles, v);
    const clvr::Image4f image = fb.readColor(device);
    const int y = h / 2;
    int checked = 0;
    double worstAffine = 0.0;
    for (int x = 0; x < w; ++x) {
        if (image.at(x, y).a < 0.0f)
            continue;
        // Exact u: intersect the ray through window x with the plane x = -1.
        const double tanHalf = std::tan(glm::radians(30.0)), aspect = double(w) / h;
        const auto exactU = [&](double wx) {
            const double dirX = (2.0 * wx / w - 1.0) * tanHalf * aspect;  // eye ray (dirX, ., -1)
            return (-1.0 / dirX - 1.0) / 19.0;                              // hits x = -1 at z = 1/dirX
        };
        const double exact = exactU(x + 0.5);
        // Affine: u linear in window x between the near (u 0) and far (u 1) edges' window positions.
        const auto windowX = [&](double zEye) { return (1.0 + (-1.0 / (-zEye * tanHalf * aspect))) * 0.5 * w; };
        const double affine = (x + 0.5 - windowX(-1.0)) / (windowX(-20.0) - windowX(-1.0));
        worstAffine = std::max(worstAffine, std::abs(affine - exact));
        // Snapping vertices to 1/256 pixel: allow u's change over 1/64 pixel, plus float rounding 1e-5.
        const double tol = 1e-5 + std::abs(exactU(x + 1.5) - exact) / 64.0;
        EXPECT_NEAR(image.at(x, y).r, exact, tol) << "x " << x;
        ++checked;
    }
    EXPECT_GT(checked, 5);
    EXPECT_GT(worstAffine, 0.1) << "the scene must tell perspective-correct from affine interpolation";
    device.takePassTimes();
}

TEST(RasterOrder, OverlappingBlendedTrianglesCompositeInSubmissionOrder)
{
    clvr::Device& device = clvr::test::device();
    const int w = 61, h = 45;
    Rng rng(99);
    // 200 big premultiplied triangles with "over" blending (ONE, ONE_MINUS_SRC_ALPHA), then the same reversed.
    std::vector<raster::Vertex> v;
    for (int i = 0; i < 200; ++i) {
        const glm::vec4 c(rng.uniform(0, 1), rng.uniform(0, 1), rng.uniform(0, 1), 1.0);
        const float alpha = float(rng.uniform(0.2, 0.8));
        for (int k = 0; k < 3; ++k) {
            raster::Vertex x;
            x.position = glm::vec4(rng.uniform(-1.5, 1.5), rng.uniform(-1.5, 1.5), 0.0, 1.0);
            x.attributes[0] = glm::vec4(glm::vec3(c) * alpha, alpha);
            v.push_back(x);
        }
    }
    std::vector<raster::Vertex> reversed;
    for (int i = int(v.size()) / 3 - 1; i >= 0; --i)
        reversed.insert(reversed.end(), {v[3 * i], v[3 * i + 1], v[3 * i + 2]});
    raster::DrawState s;
    s.fragment.blend.enabled = true;
    s.fragment.blend.srcRgb = s.fragment.blend.srcAlpha = raster::BlendFactor::One;
    s.fragment.blend.dstRgb = s.fragment.blend.dstAlpha = raster::BlendFactor::OneMinusSrcAlpha;
    clvr::Image4f results[2];
    int k = 0;
    for (const auto* list : {&v, &reversed}) {
        raster::Framebuffer fb(device, w, h);
        fb.clearColor(device, glm::vec4(0.0f));
        raster::draw(device, fb, s, raster::Topology::Triangles, *list);
        ref::Planes want(w, h);
        ref::draw(want, s, raster::Topology::Triangles, *list);
        results[k++] = fb.readColor(device);
        // <= 200 layers of "over" on values <= 1; each layer 2 roundings, errors damped by (1 - alpha): 1e-5.
        EXPECT_TRUE(clvr::test::imagesNear(results[k - 1], want.colorImage(), {.maxAbs = 1e-5, .meanAbs = 1e-6}));
    }
    double diff = 0.0;
    for (std::size_t i = 0; i < results[0].pixelCount(); ++i)
        diff = std::max(diff, double(glm::length(results[0].pixels()[i] - results[1].pixels()[i])));
    EXPECT_GT(diff, 0.1) << "reversing the submission order must change the blend";
    device.takePassTimes();
}

TEST(RasterDeterminism, TwoRunsAreBitIdentical)
{
    clvr::Device& device = clvr::test::device();
    Rng rng(1234);
    const std::vector<raster::Vertex> v = randomVertices(rng, 300);
    raster::Framebuffer a(device, 61, 45), b(device, 61, 45);
    for (raster::Framebuffer* fb : {&a, &b}) {
        fb->clearColor(device, glm::vec4(0.2f));
        fb->clearDepth(device, 1.0f);
        fb->clearStencil(device, 0);
        raster::draw(device, *fb, blendedDepthStencil(), raster::Topology::Triangles, v);
    }
    expectIdentical(device, a, b);
    device.takePassTimes();
}

// A draw of at least 2 x 16,384 triangles is set up in chunks on the host's threads and joined in submission
// order (raster/rasterizer.cpp, setUpDraw): the frame buffer's bits and the draw's stats must be those of the same
// triangles drawn in pieces small enough to be set up on one thread. 100,000 small triangles, overlapping
// (blending, depth and stencil see their order), a tenth of them large and crossing the near, far and side
// planes (clipped, with fan triangles that replace one); on 2 threads or more (CI has 2).
TEST(RasterSetUp, ThreadedSetUpGivesTheBitsOfTheDrawInPieces)
{
    if (clvr::threadBudget() < 2)
        GTEST_SKIP() << "one host thread: the set-up is never split";
    clvr::Device& device = clvr::test::device();
    Rng rng(2024);
    std::vector<raster::Vertex> v;
    const int triangles = 100000;
    for (int t = 0; t < triangles; ++t) {
        const bool large = rng.integer(0, 9) == 0;
        const double w = rng.uniform(0.5, 1.5);
        const glm::dvec3 centre(rng.uniform(-1.1, 1.1), rng.uniform(-1.1, 1.1), rng.uniform(-0.9, 0.9));
        for (int k = 0; k < 3; ++k) {
            const double r = large ? 1.2 : 0.06;
            raster::Vertex x;
            const glm::dvec3 p = centre + glm::dvec3(rng.uniform(-r, r), rng.uniform(-r, r), rng.uniform(-r, r));
            x.position = glm::vec4(glm::vec3(p * w), static_cast<float>(w));
            x.attributes[0] = randomVec4(rng);
            v.push_back(x);
        }
    }
    const raster::DrawState state = blendedDepthStencil();
    raster::Framebuffer whole(device, 64, 48), pieces(device, 64, 48);
    for (raster::Framebuffer* fb : {&whole, &pieces}) {
        fb->clearColor(device, glm::vec4(0.2f));
        fb->clearDepth(device, 1.0f);
        fb->clearStencil(device, 0);
    }
    raster::Rasterizer rasterizer(device);
    rasterizer.draw(whole, state, raster::Topology::Triangles, v);
    const raster::DrawStats wholeStats = rasterizer.takeStats();
    raster::DrawStats pieceStats;
    const std::size_t piece = 3 * 10000;  // vertices: 10,000 triangles, set up on one thread
    for (std::size_t first = 0; first < v.size(); first += piece) {
        const std::vector<raster::Vertex> part(v.begin() + static_cast<std::ptrdiff_t>(first),
                                               v.begin() + static_cast<std::ptrdiff_t>(std::min(first + piece, v.size())));
        rasterizer.draw(pieces, state, raster::Topology::Triangles, part);
        const raster::DrawStats d = rasterizer.takeStats();
        pieceStats.triangles += d.triangles;
        pieceStats.fragments += d.fragments;
    }
    std::printf("[ measured ] %llu triangles set up, %llu fragments\n", static_cast<unsigned long long>(wholeStats.triangles),
                static_cast<unsigned long long>(wholeStats.fragments));
    EXPECT_GT(wholeStats.triangles, static_cast<std::uint64_t>(triangles) * 8 / 10);
    EXPECT_GT(wholeStats.fragments, 64u * 48u * 10u);  // every pixel many times over: the order is seen
    EXPECT_EQ(wholeStats.triangles, pieceStats.triangles);
    EXPECT_EQ(wholeStats.fragments, pieceStats.fragments);
    expectIdentical(device, whole, pieces);
    device.takePassTimes();
}

TEST(RasterFragmentProgram, DiscardsAndReadsUniformsAndBuffers)
{
    clvr::Device& device = clvr::test::device();
    const int w = 37, h = 23;
    // Discard left of uniform[0].x; color = table[row] * uniform[1] + attribute 1.
    raster::FragmentProgram program;
    program.source = R"(
int clvr_fragment(const ClFragment* f, const ClFragmentResources* r, float4* color)
{
    if (f->window.x < r->uniforms[0].x)
        return 0;
    const float t = r->buffer[2][(int)f->window.y];
    *color = t * r->uniforms[1] + f->attr[1];
    return 1;
}
)";
    program.uniforms = {glm::vec4(12.0f, 0, 0, 0), glm::vec4(0.5f, 0.25f, 1.0f, 1.0f)};
    std::vector<float> table(h);
    for (int i = 0; i < h; ++i)
        table[i] = 0.1f * i;
    program.buffers[2] = device.upload("test table", table);
    const ref::FragmentFunction twin = [&](const ref::Fragment& f, glm::dvec4& color) {
        if (f.window.x < 12.0)
            return false;
        color = double(table[int(f.window.y)]) * glm::dvec4(program.uniforms[1]) + f.attributes[1];
        return true;
    };
    Rng rng(3);
    const std::vector<raster::Vertex> v = randomVertices(rng, 30);
    raster::DrawState s;
    s.fragment.blend.enabled = true;
    s.fragment.blend.srcRgb = s.fragment.blend.dstRgb = raster::BlendFactor::One;
    raster::Framebuffer fb(device, w, h);
    fb.clearColor(device, glm::vec4(0.0f));
    const raster::DrawStats stats = raster::draw(device, fb, s, raster::Topology::Triangles, v, program);
    ref::Planes want(w, h);
    const raster::DrawStats wantStats = ref::draw(want, s, raster::Topology::Triangles, v, twin);
    EXPECT_EQ(stats.fragments, wantStats.fragments) << "fragments are counted before the program discards";
    // <= 10 layers of additive values <= 4: 10 roundings of ulp(40) ~ 4e-6 each.
    EXPECT_TRUE(clvr::test::imagesNear(fb.readColor(device), want.colorImage(), {.maxAbs = 4e-5, .meanAbs = 4e-6}));
    const clvr::Image4f image = fb.readColor(device);
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < 12; ++x)
            ASSERT_EQ(image.at(x, y), glm::vec4(0.0f)) << "not discarded at " << x << "," << y;
    device.takePassTimes();
}

TEST(RasterFragmentProgram, SamplesATextureThroughTextureH)
{
    clvr::Device& device = clvr::test::device();
    const int w = 40, h = 24;  // even sizes: a texel boundary at a pixel center would need 4 (x + 0.5) / w integral
    // A 4x4 NEAREST texture holding its texel index; texture coordinates run 0..1 across the screen
    // (v = 0 at the top row), so pixel (x, y) reads texel (floor(4 (x + 0.5) / w), floor(4 (y + 0.5) / h)).
    // Every pixel center is half a pixel from a texel boundary, so float rounding cannot move a lookup.
    std::vector<float> texels(16);
    for (int i = 0; i < 16; ++i)
        texels[i] = float(i);
    raster::TextureDesc desc;
    desc.width = desc.height = 4;
    desc.filter = raster::Filter::Nearest;
    raster::Texture texture(device, desc, texels);
    const ClTexture t = texture.toCl();
    raster::FragmentProgram program;
    program.source = R"(
int clvr_fragment(const ClFragment* f, const ClFragmentResources* r, float4* color)
{
    ClTexture t;
    t.width = (uint)r->uniforms[0].x;
    t.height = (uint)r->uniforms[0].y;
    t.depth = (uint)r->uniforms[0].z;
    t.channels = (uint)r->uniforms[0].w;
    t.filter = (uint)r->uniforms[1].x;
    t.wrap = (uint)r->uniforms[1].y;
    t.pad0 = t.pad1 = 0u;
    t.border = (float4)(0.0f);
    *color = clvr_tex2d(r->buffer[0], t, f->attr[1].xy);
    return 1;
}
)";
    program.uniforms = {glm::vec4(t.width, t.height, t.depth, t.channels), glm::vec4(t.filter, t.wrap, 0, 0)};
    program.buffers[0] = texture.buffer();
    std::vector<raster::Vertex> quad;
    for (glm::vec2 p : {glm::vec2(-1, -1), glm::vec2(1, -1), glm::vec2(1, 1), glm::vec2(-1, -1), glm::vec2(1, 1), glm::vec2(-1, 1)}) {
        raster::Vertex v;
        v.position = glm::vec4(p, 0.0f, 1.0f);
        v.attributes[1] = glm::vec4((p.x + 1) / 2, (1 - p.y) / 2, 0, 0);
        quad.push_back(v);
    }
    raster::Framebuffer fb(device, w, h);
    fb.clearColor(device, glm::vec4(-1.0f));
    raster::draw(device, fb, raster::DrawState{}, raster::Topology::Triangles, quad, program);
    const clvr::Image4f image = fb.readColor(device);
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
            const int i = int(4 * (y + 0.5) / h) * 4 + int(4 * (x + 0.5) / w);
            ASSERT_EQ(image.at(x, y), glm::vec4(float(i))) << x << "," << y;
        }
    device.takePassTimes();
}

// A fragment program whose color is uniform 0 plus attribute 0 times uniform 1: draws that differ only
// in uniforms are different passes, and a wrong uniform base shows in the color.
raster::FragmentProgram uniformProgram(Rng& rng)
{
    raster::FragmentProgram p;
    p.source = R"(
int clvr_fragment(const ClFragment* f, const ClFragmentResources* r, float4* color)
{
    *color = r->uniforms[0] + f->attr[0] * r->uniforms[1];
    return 1;
}
)";
    p.uniforms = {randomVec4(rng, -0.5, 0.5), randomVec4(rng, 0.5, 1.5)};
    return p;
}

struct RandomDraw {
    raster::DrawState state;
    raster::Topology topology;
    std::vector<raster::Vertex> vertices;
    raster::FragmentProgram program;
};

// Random draws as RasterConformance makes them, plus scissors, a second fragment program with
// per-draw uniforms, and runs of draws that repeat the previous state (one pass in a batch).
std::vector<RandomDraw> randomDraws(Rng& rng, int count, int width, int height)
{
    std::vector<RandomDraw> draws;
    const raster::FragmentProgram textured = uniformProgram(rng);
    for (int d = 0; d < count; ++d) {
        RandomDraw r;
        if (!draws.empty() && rng.integer(0, 2) == 0) {  // same state and program as the previous draw
            r.state = draws.back().state;
            r.program = draws.back().program;
        } else {
            r.state.fragment = randomState(rng);
            for (int p = rng.integer(0, 2); p > 0; --p)
                r.state.clipPlanes.push_back(glm::vec4(rng.uniform(-1, 1), rng.uniform(-1, 1), rng.uniform(-1, 1), rng.uniform(-0.3, 0.3)));
            if (rng.integer(0, 2) == 0)
                r.state.viewport = {rng.integer(-8, 8), rng.integer(-8, 8), rng.integer(10, width), rng.integer(10, height),
                                    float(rng.uniform(0, 0.3)), float(rng.uniform(0.6, 1.0))};
            if (rng.integer(0, 3) == 0)
                r.state.scissor = {true, rng.integer(-4, width / 2), rng.integer(-4, height / 2), rng.integer(0, width),
                                   rng.integer(0, height)};
            if (rng.integer(0, 1) == 0) {
                r.program = textured;
                r.program.uniforms[1] = randomVec4(rng, 0.5, 1.5);
            }
        }
        r.topology = static_cast<raster::Topology>(rng.integer(0, 2));
        r.vertices = randomVertices(rng, rng.integer(3, 30));
        draws.push_back(std::move(r));
    }
    return draws;
}

TEST(RasterBatch, SameBitsAsTheDrawsOneByOneAndMatchesReference)
{
    clvr::Device& device = clvr::test::device();
    Rng rng(77);
    const int sizes[][2] = {{37, 23}, {61, 45}};
    std::size_t passes = 0;
    for (int round = 0; round < 6; ++round) {
        SCOPED_TRACE("round " + std::to_string(round));
        const int width = sizes[round % 2][0], height = sizes[round % 2][1];
        const Scene scene = randomScene(rng, width, height);
        const std::vector<RandomDraw> draws = randomDraws(rng, 24, width, height);
        raster::Framebuffer single(device, width, height), batched(device, width, height);
        load(device, single, scene);
        load(device, batched, scene);
        raster::DrawStats one;
        for (const RandomDraw& d : draws) {
            const raster::DrawStats s = raster::draw(device, single, d.state, d.topology, d.vertices, d.program);
            one.triangles += s.triangles;
            one.fragments += s.fragments;
        }
        device.takePassTimes();  // from here on, only the batch's launches
        raster::Rasterizer rasterizer(device);
        raster::DrawBatch batch(rasterizer, batched);
        for (const RandomDraw& d : draws)
            batch.add(d.state, d.topology, d.vertices, d.program);
        EXPECT_EQ(batch.pendingDraws(), draws.size());
        batch.flush();
        EXPECT_EQ(batch.pendingDraws(), 0u);
        expectIdentical(device, single, batched);
        const raster::DrawStats all = rasterizer.takeStats();
        EXPECT_EQ(all.triangles, one.triangles);
        EXPECT_EQ(all.fragments, one.fragments);
        EXPECT_GT(all.fragments, 0u);
        const raster::DrawStats none = rasterizer.takeStats();
        EXPECT_EQ(none.triangles + none.fragments, 0u) << "takeStats() starts counting again";
        for (const auto& pass : device.takePassTimes())
            passes += pass.name == "raster: fragments";

        // The CPU reference, draw by draw, with RasterConformance's tolerances and tie rule.
        ref::Planes want = load(scene);
        TieFinder ties(std::size_t(width) * height);
        for (const RandomDraw& d : draws) {
            markTies(ties, want, d.state, d.topology, d.vertices);
            // The reference has no scissor test; a pixel outside it changes nothing, as a discarded fragment.
            const raster::Scissor& sc = d.state.scissor;
            const bool programmed = !d.program.source.empty();
            const glm::dvec4 u0 = programmed ? glm::dvec4(d.program.uniforms[0]) : glm::dvec4(0.0);
            const glm::dvec4 u1 = programmed ? glm::dvec4(d.program.uniforms[1]) : glm::dvec4(1.0);
            ref::draw(want, d.state, d.topology, d.vertices, [&](const ref::Fragment& f, glm::dvec4& color) {
                const double x = f.window.x, y = f.window.y;
                if (sc.test && !(x >= sc.x && x < sc.x + sc.width && y >= sc.y && y < sc.y + sc.height))
                    return false;
                color = programmed ? u0 + f.attributes[0] * u1 : f.attributes[0];
                return true;
            });
        }
        EXPECT_TRUE(planesNear(batched, device, want, ties.ties));
    }
    // Runs of equal state share a pass, state changes start one: fewer launches than draws, more than rounds.
    EXPECT_LT(passes, 6u * 24u);
    EXPECT_GT(passes, 6u * 2u);
}

// A full-screen quad drawn four times in one batch, each with other state: the result is only right if
// every state applies to its own draw, in order.
// The work-item shape (tiles and items, raster/rasterizer.h) decides only speed: a CPU's whole-tile items,
// a GPU's one-pixel items, and odd shapes on frame buffers that are no multiple of them give the same
// bits and counts, as one draw at a time and as one batch.
TEST(RasterShape, EveryShapeGivesTheSameBits)
{
    clvr::Device& device = clvr::test::device();
    const raster::RasterShape shapes[] = {
        {16, 16, 16, 16}, {16, 16, 1, 1}, {8, 8, 8, 8}, {16, 8, 4, 2}, {1, 1, 1, 1}, {4, 16, 4, 4}, {16, 2, 16, 1}};
    Rng rng(313);
    for (const auto& [width, height] : {std::pair{37, 23}, std::pair{61, 45}}) {
        const Scene scene = randomScene(rng, width, height);
        const std::vector<RandomDraw> draws = randomDraws(rng, 20, width, height);
        raster::Framebuffer first(device, width, height);  // the CPU shape, the one to agree with
        load(device, first, scene);
        raster::Rasterizer cpu(device, shapes[0]);
        for (const RandomDraw& d : draws)
            cpu.draw(first, d.state, d.topology, d.vertices, d.program);
        const raster::DrawStats firstStats = cpu.takeStats();
        EXPECT_GT(firstStats.fragments, 0u);
        for (const raster::RasterShape& shape : shapes) {
            SCOPED_TRACE(std::to_string(width) + "x" + std::to_string(height) + ", tiles " + std::to_string(shape.tileW) +
                         "x" + std::to_string(shape.tileH) + ", items " + std::to_string(shape.itemW) + "x" +
                         std::to_string(shape.itemH));
            raster::Rasterizer rasterizer(device, shape);
            EXPECT_EQ(rasterizer.shape().itemW, shape.itemW);
            raster::Framebuffer one(device, width, height), batched(device, width, height);
            load(device, one, scene);
            load(device, batched, scene);
            for (const RandomDraw& d : draws)
                rasterizer.draw(one, d.state, d.topology, d.vertices, d.program);
            const raster::DrawStats oneStats = rasterizer.takeStats();
            {
                raster::DrawBatch batch(rasterizer, batched);
                for (const RandomDraw& d : draws)
                    batch.add(d.state, d.topology, d.vertices, d.program);
                batch.flush();
            }
            const raster::DrawStats batchStats = rasterizer.takeStats();
            expectIdentical(device, one, batched);
            EXPECT_EQ(batchStats.fragments, oneStats.fragments);
            expectIdentical(device, first, one);
            EXPECT_EQ(oneStats.triangles, firstStats.triangles);
            EXPECT_EQ(oneStats.fragments, firstStats.fragments);
        }
    }
    EXPECT_THROW(raster::Rasterizer(device, raster::RasterShape{32, 32, 32, 32}), clvr::InternalError);
    EXPECT_THROW(raster::Rasterizer(device, raster::RasterShape{16, 16, 3, 3}), clvr::InternalError);
    EXPECT_THROW(raster::Rasterizer(device, raster::RasterShape{8, 8, 16, 16}), clvr::InternalError);
    device.takePassTimes();
}

// Tile lists of many triangles that each cover whole items, against the exact sum: the CPU shape (an
// item is a 16x16 tile, its pixels in private arrays for the whole list), one pixel per item, lists cut
// into launches of 7 entries, and the device's own shape. Found on Mesa's rusticl (llvmpipe), which stops
// a work-item's loops after 65,535 iterations: items with long lists lost every pixel but their first
// (docs/devices.md).
TEST(RasterShape, LongListsOfFullTileTrianglesGiveTheExactSum)
{
    clvr::Device& device = clvr::test::device();
    const raster::RasterShape shapes[] = {{16, 16, 16, 16}, {16, 16, 1, 1}, {16, 16, 16, 16, 7}, {8, 8, 1, 1, 7},
                                          {16, 16, 1, 1, 1000}, raster::RasterShape::forDevice(device)};
    const bool capped = device.loopIterationCap() != 0;
    // 40 x 24: tiles cut by the frame buffer's edge. 12,000 quads: 24,000 triangles per tile list, over the
    // cap even for 1x1 items (about 4 iterations per triangle).
    const int w = 40, h = 24;
    for (const int quads : {2, 12000}) {
        std::vector<raster::Vertex> vertices;
        for (int q = 0; q < quads; ++q) {
            const auto a = windowVertex(-3.0, -2.0, w, h), b = windowVertex(w + 5.0, -1.0, w, h);
            const auto c = windowVertex(w + 2.0, h + 4.0, w, h), d = windowVertex(-1.0, h + 3.0, w, h);
            vertices.insert(vertices.end(), {a, b, c, a, c, d});
        }
        for (const raster::RasterShape& shape : shapes) {
            if (quads > 100 && shape.listChunk == 7)
                continue;  // 3,400 launches: the short lists test the cutting
            if (quads > 100 && capped && shape.listChunk == 0)
                continue;  // not a shape this device gets: a whole list would run past its cap
            SCOPED_TRACE(std::to_string(quads) + " quads, items " + std::to_string(shape.itemW) + "x" +
                         std::to_string(shape.itemH) + ", list chunk " + std::to_string(shape.listChunk));
            raster::Framebuffer fb(device, w, h);
            fb.clearColor(device, glm::vec4(0.0f));
            raster::Rasterizer rasterizer(device, shape);
            rasterizer.draw(fb, additiveOnes(), raster::Topology::Triangles, vertices);
            EXPECT_EQ(rasterizer.takeStats().fragments, std::uint64_t(quads) * w * h);
            const clvr::Image4f image = fb.readColor(device);
            int wrong = 0;
            for (int y = 0; y < h; ++y)
                for (int x = 0; x < w; ++x)
                    wrong += image.at(x, y).r != float(quads) || image.at(x, y).a != float(quads);
            EXPECT_EQ(wrong, 0) << "pixels without the sum of " << quads << " ones, e.g. (1, 0): " << image.at(1, 0).r;
        }
    }
    device.takePassTimes();
}

// FragmentProgram::attributes: the attributes a program reads are interpolated exactly as with all four,
// the ones past the count read as zero, and a count out of range is an internal error.
TEST(RasterFragmentProgram, AttributeCountKeepsTheReadOnesAndZeroesTheRest)
{
    clvr::Device& device = clvr::test::device();
    const int width = 41, height = 29;
    Rng rng(29);
    const Scene scene = randomScene(rng, width, height);
    const std::vector<raster::Vertex> v = randomVertices(rng, 60);
    raster::DrawState state = blendedDepthStencil();
    const auto program = [](int attributes) {
        raster::FragmentProgram p;
        p.source = R"(
int clvr_fragment(const ClFragment* f, const ClFragmentResources* r, float4* color)
{
    (void)r;
    *color = f->attr[0] + 2.0f * f->attr[1] + (f->attr[2] != 0.0f ? 4.0f : 0.0f) + (f->attr[3] != 0.0f ? 8.0f : 0.0f);
    return 1;
}
)";
        p.attributes = attributes;
        return p;
    };
    const raster::FragmentProgram two = program(2), four = program(4);
    raster::Framebuffer withTwo(device, width, height), withFour(device, width, height);
    load(device, withTwo, scene);
    load(device, withFour, scene);
    raster::draw(device, withTwo, state, raster::Topology::Triangles, v, two);
    // With all four attributes but attributes 2 and 3 zero at every vertex, the program reads what it
    // reads with two.
    std::vector<raster::Vertex> zeroed = v;
    for (raster::Vertex& x : zeroed)
        x.attributes[2] = x.attributes[3] = glm::vec4(0.0f);
    raster::draw(device, withFour, state, raster::Topology::Triangles, zeroed, four);
    expectIdentical(device, withTwo, withFour);
    // And differently from four live attributes, so the comparison above could fail.
    raster::Framebuffer live(device, width, height);
    load(device, live, scene);
    raster::draw(device, live, state, raster::Topology::Triangles, v, four);
    EXPECT_FALSE(bytes(live.readColor(device)) == bytes(withTwo.readColor(device)));

    raster::Framebuffer fb(device, 8, 8);
    EXPECT_THROW(raster::draw(device, fb, state, raster::Topology::Triangles, v, program(5)), clvr::InternalError);
    EXPECT_THROW(raster::draw(device, fb, state, raster::Topology::Triangles, v, program(-1)), clvr::InternalError);
    device.takePassTimes();
}

TEST(RasterBatch, StateChangesTakeEffectInOrder)
{
    clvr::Device& device = clvr::test::device();
    const int w = 29, h = 17;
    auto quad = [&](glm::vec4 color, float z) {
        std::vector<raster::Vertex> v;
        for (glm::vec2 p : {glm::vec2(-1, -1), glm::vec2(1, -1), glm::vec2(1, 1), glm::vec2(-1, -1), glm::vec2(1, 1), glm::vec2(-1, 1)}) {
            raster::Vertex x;
            x.position = glm::vec4(p, z, 1.0f);
            x.attributes[0] = color;
            v.push_back(x);
        }
        return v;
    };
    raster::DrawState replace;                    // 1: color := (0.5, 0, 0, 1), depth := 0.5, stencil := 1 on the left
    replace.fragment.depth.test = true;
    replace.fragment.depth.func = raster::CompareFunc::Always;
    replace.fragment.stencil.test = true;
    replace.fragment.stencil.ref = 1;
    replace.fragment.stencil.dppass = raster::StencilOp::Replace;
    replace.scissor = {true, 0, 0, 10, h};
    raster::DrawState additive = additiveOnes();  // 2: + (0.25, 0.125, 0, 0) where stencil == 1
    additive.fragment.stencil.test = true;
    additive.fragment.stencil.func = raster::CompareFunc::Equal;
    additive.fragment.stencil.ref = 1;
    raster::DrawState greenOnly;                  // 3: only green := 1, only in front of depth 0.5
    greenOnly.fragment.colorMask = {false, true, false, false};
    greenOnly.fragment.depth.test = true;
    greenOnly.fragment.depth.func = raster::CompareFunc::Less;
    raster::FragmentProgram blue;                 // 4: another program: blue := uniform, left of column 5
    blue.source = R"(
int clvr_fragment(const ClFragment* f, const ClFragmentResources* r, float4* color)
{
    *color = (float4)(0.0f, 0.0f, r->uniforms[0].z, 0.0f);
    return f->window.x < 5.0f;
}
)";
    blue.uniforms = {glm::vec4(0.0f, 0.0f, 0.75f, 0.0f)};
    raster::DrawState maxBlend;
    maxBlend.fragment.blend.enabled = true;
    maxBlend.fragment.blend.rgbEquation = maxBlend.fragment.blend.alphaEquation = raster::BlendEquation::Max;

    raster::Framebuffer fb(device, w, h);
    fb.clearColor(device, glm::vec4(0.0f));
    fb.clearDepth(device, 1.0f);
    fb.clearStencil(device, 0);
    raster::Rasterizer rasterizer(device);
    raster::DrawBatch batch(rasterizer, fb);
    batch.add(replace, raster::Topology::Triangles, quad({0.5f, 0.0f, 0.0f, 1.0f}, 0.0f));
    batch.add(additive, raster::Topology::Triangles, quad({0.25f, 0.125f, 0.0f, 0.0f}, 0.0f));
    batch.add(greenOnly, raster::Topology::Triangles, quad({9.0f, 1.0f, 9.0f, 9.0f}, -0.5f));
    batch.add(maxBlend, raster::Topology::Triangles, quad({}, 0.0f), blue);
    batch.flush();
    const clvr::Image4f image = fb.readColor(device);
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
            const bool left = x < 10;
            const glm::vec4 want(left ? 0.75f : 0.0f, left ? 1.0f : 1.0f, x < 5 ? 0.75f : 0.0f, left ? 1.0f : 0.0f);
            ASSERT_EQ(image.at(x, y), want) << x << "," << y;
        }
    const raster::DrawStats stats = rasterizer.takeStats();
    EXPECT_EQ(stats.triangles, 8u);
    EXPECT_EQ(stats.fragments, std::uint64_t(10 * h + 3 * w * h)) << "covered pixels, before any test or discard";
    device.takePassTimes();
}

TEST(RasterRasterizer, BuildsEachFragmentProgramOnceAndRebuildsAChangedOne)
{
    clvr::Device& device = clvr::test::device();
    raster::Framebuffer fb(device, 16, 16);
    std::vector<raster::Vertex> tri = {windowVertex(0, 0, 16, 16), windowVertex(64, 0, 16, 16), windowVertex(0, 64, 16, 16)};
    raster::FragmentProgram program;
    program.source = "int clvr_fragment(const ClFragment* f, const ClFragmentResources* r, float4* color)\n"
                     "{ *color = (float4)(1.0f, 0.0f, 0.0f, 1.0f); return 1; }\n";
    raster::Rasterizer rasterizer(device);
    rasterizer.draw(fb, raster::DrawState{}, raster::Topology::Triangles, tri, program);
    ASSERT_TRUE(program.compiled);
    const auto* first = program.compiled.get();
    const raster::FragmentProgram copy = program;
    rasterizer.draw(fb, raster::DrawState{}, raster::Topology::Triangles, tri, copy);
    EXPECT_EQ(program.compiled.get(), first);
    EXPECT_EQ(copy.compiled.get(), first) << "a copy shares the built kernel";
    EXPECT_EQ(fb.readColor(device).at(3, 3), glm::vec4(1.0f, 0.0f, 0.0f, 1.0f));

    program.source = "int clvr_fragment(const ClFragment* f, const ClFragmentResources* r, float4* color)\n"
                     "{ *color = (float4)(0.0f, 1.0f, 0.0f, 1.0f); return 1; } /* green */\n";
    rasterizer.draw(fb, raster::DrawState{}, raster::Topology::Triangles, tri, program);
    EXPECT_NE(program.compiled.get(), first);
    EXPECT_EQ(fb.readColor(device).at(3, 3), glm::vec4(0.0f, 1.0f, 0.0f, 1.0f)) << "a source of another length is rebuilt";
    device.takePassTimes();
}

TEST(RasterRasterizer, StateOutOfRangeIsAnInternalError)
{
    clvr::Device& device = clvr::test::device();
    raster::Framebuffer fb(device, 8, 8);
    const std::vector<raster::Vertex> tri = {windowVertex(0, 0, 8, 8), windowVertex(8, 0, 8, 8), windowVertex(0, 8, 8, 8)};
    raster::Rasterizer rasterizer(device);
    raster::DrawState planes;
    planes.clipPlanes.assign(raster::kMaxClipPlanes + 1, glm::vec4(0, 0, 0, 1));
    EXPECT_THROW(rasterizer.draw(fb, planes, raster::Topology::Triangles, tri), clvr::InternalError);
    raster::FragmentProgram uniforms;
    uniforms.uniforms.resize(raster::kMaxUniforms + 1);
    EXPECT_THROW(rasterizer.draw(fb, raster::DrawState{}, raster::Topology::Triangles, tri, uniforms), clvr::InternalError);
    raster::DrawState empty;
    empty.viewport.width = 0;
    EXPECT_THROW(rasterizer.draw(fb, empty, raster::Topology::Triangles, tri), clvr::InternalError);
    raster::DrawBatch batch(rasterizer, fb);
    EXPECT_THROW(batch.add(empty, raster::Topology::Triangles, tri), clvr::InternalError);
    EXPECT_THROW(raster::assembleTriangles(static_cast<raster::Topology>(7), 3), clvr::InternalError);
    EXPECT_EQ(rasterizer.takeStats().triangles, 0u) << "nothing was drawn";
    device.takePassTimes();
}

// Speed, not correctness (DESIGN.md: speed is measured by clvr bench): run with
// --gtest_also_run_disabled_tests to print the time of 1024 large blended triangles on 512x512.
TEST(RasterSpeed, DISABLED_BlendedLargeTriangles512)
{
    clvr::Device& device = clvr::test::device();
    Rng rng(8);
    std::vector<raster::Vertex> v;
    for (int i = 0; i < 512; ++i) {  // 512 screen-filling quads = 1024 triangles, like slice3d's slices
        const float z = float(rng.uniform(-0.9, 0.9));
        const glm::vec4 c(0.01f, 0.02f, 0.03f, 0.04f);
        for (glm::vec2 p : {glm::vec2(-1, -1), glm::vec2(1, -1), glm::vec2(1, 1), glm::vec2(-1, -1), glm::vec2(1, 1), glm::vec2(-1, 1)}) {
            raster::Vertex x;
            x.position = glm::vec4(p * 1.05f, z, 1.0f);
            x.attributes[0] = c;
            v.push_back(x);
        }
    }
    raster::DrawState s;
    s.fragment.blend.enabled = true;
    s.fragment.blend.dstRgb = s.fragment.blend.dstAlpha = raster::BlendFactor::OneMinusSrcAlpha;
    raster::Framebuffer fb(device, 512, 512);
    fb.clearColor(device, glm::vec4(0.0f));
    raster::draw(device, fb, s, raster::Topology::Triangles, v);  // compile
    device.takePassTimes();
    for (int run = 0; run < 3; ++run) {
        const auto t0 = std::chrono::steady_clock::now();
        const raster::DrawStats stats = raster::draw(device, fb, s, raster::Topology::Triangles, v);
        const auto times = device.takePassTimes();
        const double ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
        std::printf("draw: %.1f ms total, %s %.1f ms; %llu triangles, %llu fragments; %s\n", ms, times.back().name.c_str(),
                    times.back().ms, (unsigned long long)stats.triangles, (unsigned long long)stats.fragments,
                    device.description().c_str());
    }
}

}  // namespace
