// host/optics/preintegration_table.cpp — the full pre-integration table from the exact segment integral.
#include "host/optics/preintegration_table.h"

#include "host/runtime/parallel.h"
#include "host/optics/segment_integral.h"

#include <algorithm>
#include <atomic>
#include <cmath>

namespace clvr {

static_assert(sizeof(glm::vec4) == 16, "the table is uploaded as OpenCL float4");

PreintegrationTable buildPreintegrationTable(const TransferFunction& tf, double sLo, double sHi, double lMax,
                                             int scalarSamples, int lengthSamples, int threads)
{
    PreintegrationTable table;
    table.scalarSamples = scalarSamples;
    table.lengthSamples = lengthSamples;
    table.sLo = sLo;
    table.sHi = sHi;
    table.lMax = lMax;
    const std::size_t ns = static_cast<std::size_t>(scalarSamples);
    table.values.resize(ns * ns * static_cast<std::size_t>(lengthSamples));
    std::atomic<int> nextSlice{0};
    auto worker = [&] {
        // One segment from λ = 0 to l: integrateSegments cuts it at the control points between s_f and
        // s_b and integrates every piece in closed form, the reference that tests judge renderers by.
        std::vector<TetSegment> segment(1);
        for (int k; (k = nextSlice.fetch_add(1)) < lengthSamples;) {
            const double l = table.length(k);
            for (int j = 0; j < scalarSamples; ++j)
                for (int i = 0; i < scalarSamples; ++i) {
                    segment[0] = TetSegment{0, 0.0, l, table.scalar(i), table.scalar(j)};
                    // l = 0 is an empty segment: nothing emitted, nothing absorbed.
                    const glm::dvec4 v = l > 0.0 ? integrateSegments(segment, tf) : glm::dvec4(0.0);
                    table.values[(k * ns + j) * ns + i] = glm::vec4(v);
                }
        }
    };
    runOnThreads(threads, lengthSamples, worker);
    return table;
}

glm::vec4 PreintegrationTable::lookup(float sFront, float sBack, float l) const
{
    // Keep in step with harc_full_lookup in kernels/harc.cl.
    const float ns1 = static_cast<float>(scalarSamples - 1), nl1 = static_cast<float>(lengthSamples - 1);
    const float sScale = ns1 / static_cast<float>(sHi - sLo), lScale = nl1 / static_cast<float>(lMax);
    const float x = std::clamp((sFront - static_cast<float>(sLo)) * sScale, 0.0f, ns1);
    const float y = std::clamp((sBack - static_cast<float>(sLo)) * sScale, 0.0f, ns1);
    const float z = std::clamp(l * lScale, 0.0f, nl1);
    const int i = std::min(static_cast<int>(x), scalarSamples - 2);
    const int j = std::min(static_cast<int>(y), scalarSamples - 2);
    const int k = std::min(static_cast<int>(z), lengthSamples - 2);
    const float fx = x - static_cast<float>(i), fy = y - static_cast<float>(j), fz = z - static_cast<float>(k);
    const std::size_t ns = static_cast<std::size_t>(scalarSamples);
    auto at = [&](int di, int dj, int dk) { return values[((k + dk) * ns + (j + dj)) * ns + (i + di)]; };
    auto lerp = [](const glm::vec4& a, const glm::vec4& b, float t) { return a + t * (b - a); };
    const glm::vec4 c0 = lerp(lerp(at(0, 0, 0), at(1, 0, 0), fx), lerp(at(0, 1, 0), at(1, 1, 0), fx), fy);
    const glm::vec4 c1 = lerp(lerp(at(0, 0, 1), at(1, 0, 1), fx), lerp(at(0, 1, 1), at(1, 1, 1), fx), fy);
    return lerp(c0, c1, fz);
}

}  // namespace clvr
