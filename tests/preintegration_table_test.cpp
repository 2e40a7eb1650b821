// tests/preintegration_table_test.cpp — the full pre-integration table (host/optics/preintegration_table.h):
// entries at the grid points are the exact segment integral of host/reference/tet_reference.h rounded to float,
// independent closed forms where there is one, bits independent of the thread count, and trilinear
// lookups between grid points within a stated (measured) tolerance that shrinks with the resolution.
#include "host/optics/preintegration_table.h"

#include "host/reference/tet_reference.h"
#include "tests/support/mesh_fixtures.h"
#include "tests/support/test_util.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <cstring>

namespace clvr {
namespace {

// Five control points with τ up to 6 per unit and color kinks: segments of length up to lMax = 1.5
// reach optical depths near 9, α close to 1.
TransferFunction rampTf() { return test::rampTransferFunction(); }

glm::dvec4 exactSegment(const TransferFunction& tf, double sF, double sB, double l)
{
    return integrateSegments({TetSegment{0, 0.0, l, sF, sB}}, tf);
}

TEST(PreintegrationTable, GridPointsAreTheExactIntegral)
{
    const TransferFunction tf = rampTf();
    // s beyond the transfer function's range on both sides (where the end values hold), odd sizes.
    const PreintegrationTable table = buildPreintegrationTable(tf, -0.2, 1.1, 1.5, 11, 7);
    ASSERT_EQ(table.values.size(), 11u * 11u * 7u);
    EXPECT_EQ(table.bytes(), 11u * 11u * 7u * 16u);
    int checked = 0;
    for (int k = 0; k < 7; ++k)
        for (int j = 0; j < 11; ++j)
            for (int i = 0; i < 11; ++i) {
                const glm::vec4 entry = table.values[(k * 11 + j) * 11 + i];
                const glm::vec4 want(exactSegment(tf, table.scalar(i), table.scalar(j), table.length(k)));
                ASSERT_EQ(entry, want) << "entry (" << i << ", " << j << ", " << k << ")";
                // A lookup at a grid point returns that entry up to float rounding of its coordinates.
                const glm::vec4 looked = table.lookup(static_cast<float>(table.scalar(i)),
                                                      static_cast<float>(table.scalar(j)),
                                                      static_cast<float>(table.length(k)));
                for (int c = 0; c < 4; ++c)
                    ASSERT_NEAR(looked[c], entry[c], 1e-5) << "lookup at (" << i << ", " << j << ", " << k << ")";
                ++checked;
            }
    EXPECT_EQ(checked, 11 * 11 * 7);
}

TEST(PreintegrationTable, ConstantScalarAndEmptySegmentsMatchClosedForms)
{
    const TransferFunction tf = rampTf();
    const PreintegrationTable table = buildPreintegrationTable(tf, 0.0, 1.0, 2.0, 5, 9);
    for (int k = 0; k < 9; ++k)
        for (int i = 0; i < 5; ++i) {
            // s_f = s_b: constant C and τ, α = 1 - exp(-τ l), color C α (DESIGN.md's optical model).
            const glm::dvec4 v = tf(table.scalar(i));
            const double alpha = 1.0 - std::exp(-v.w * table.length(k));
            const glm::vec4 entry = table.values[(k * 5 + i) * 5 + i];
            // float rounding of values <= 1: 1 ulp is 6e-8; the closed form of tet_reference a few 1e-16.
            for (int c = 0; c < 3; ++c)
                EXPECT_NEAR(entry[c], v[c] * alpha, 2e-7) << i << ", " << k;
            EXPECT_NEAR(entry.a, alpha, 2e-7) << i << ", " << k;
        }
    for (int j = 0; j < 5; ++j)
        for (int i = 0; i < 5; ++i)
            EXPECT_EQ(table.values[j * 5 + i], glm::vec4(0.0f)) << "l = 0 emits and absorbs nothing";
}

TEST(PreintegrationTable, SameBitsOnAnyThreadCount)
{
    const TransferFunction tf = rampTf();
    const PreintegrationTable one = buildPreintegrationTable(tf, 0.0, 1.0, 1.5, 16, 12, 1);
    const PreintegrationTable three = buildPreintegrationTable(tf, 0.0, 1.0, 1.5, 16, 12, 3);
    ASSERT_EQ(one.values.size(), three.values.size());
    EXPECT_EQ(std::memcmp(one.values.data(), three.values.data(), one.bytes()), 0);
}

// Max absolute error over channels of trilinear lookups at random points against the exact integral.
double maxLookupError(const PreintegrationTable& table, const TransferFunction& tf, int samples)
{
    test::Rng rng(7);
    double worst = 0.0;
    for (int n = 0; n < samples; ++n) {
        // Float coordinates first, so that lookup and reference see the same segment.
        const float sF = static_cast<float>(rng.uniform(0.0, 1.0)), sB = static_cast<float>(rng.uniform(0.0, 1.0));
        const float l = static_cast<float>(rng.uniform(0.0, table.lMax));
        const glm::dvec4 want = exactSegment(tf, sF, sB, l);
        const glm::vec4 got = table.lookup(sF, sB, l);
        for (int c = 0; c < 4; ++c)
            worst = std::max(worst, std::abs(static_cast<double>(got[c]) - want[c]));
    }
    return worst;
}

TEST(PreintegrationTable, BetweenGridPointsWithinStatedTolerance)
{
    const TransferFunction tf = rampTf();
    const PreintegrationTable coarse = buildPreintegrationTable(tf, 0.0, 1.0, 1.5, 16, 16);
    const PreintegrationTable fine = buildPreintegrationTable(tf, 0.0, 1.0, 1.5, 64, 64);
    const double coarseError = maxLookupError(coarse, tf, 4000), fineError = maxLookupError(fine, tf, 4000);
    std::printf("trilinear lookup, max |error| over 4000 random segments: 16x16x16 %.3g, 64x64x64 %.3g\n",
                coarseError, fineError);
    // Measured 0.0254 and 0.141; bounds a little above. Large for a table: segments up to 1.5 long with
    // τ up to 6 reach α near 1 within a few l samples, and trilinear error is O(h) across the kinks of
    // the integral at control points, O(h²) elsewhere, so 4x the samples cut it more than 4x.
    EXPECT_LT(fineError, 0.03);
    EXPECT_LT(coarseError, 0.16);
    EXPECT_LT(fineError * 4.0, coarseError);
}

}  // namespace
}  // namespace clvr
