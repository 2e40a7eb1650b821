// fuzz/transfer_function.cpp — libFuzzer target: the scene's "transfer_function" (the input is its JSON
// value, parsed inside a minimal scene), then the TransferFunction it builds evaluated at every control
// point, between neighbours and beyond the ends: whatever validates must give finite r, g, b in [0, 1]
// and tau >= 0 (an interpolation that overflows into NaN is a bug, as a crash is).
#include "fuzz/fuzz_input.h"
#include "host/model/scene.h"
#include "host/runtime/errors.h"

#include <cmath>
#include <cstdio>
#include <cstdlib>

namespace {

void checkValue(const clvr::TransferFunction& tf, double s)
{
    const glm::dvec4 v = tf(s);
    bool ok = std::isfinite(v.w) && v.w >= 0.0;
    for (int c = 0; c < 3; ++c)
        ok = ok && std::isfinite(v[c]) && v[c] >= 0.0 && v[c] <= 1.0;
    if (!ok) {
        std::fprintf(stderr, "transfer function at s = %.17g is (%g, %g, %g, %g)\n", s, v.x, v.y, v.z, v.w);
        std::abort();
    }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size)
{
    const std::string scene = R"({"volume": {"generator": "marschner-lobb", "dims": [2, 2, 2]}, "transfer_function": )" +
                              std::string(clvr::fuzz::asText(data, size)) + "}";
    clvr::TransferFunction tf;
    try {
        tf = clvr::parseScene(scene, "scene", clvr::fuzz::workDir()).transferFunction;
    } catch (const clvr::InputError&) {
        return 0;  // a clear error for bad input: what the parser promises
    }
    const auto& points = tf.points();
    for (std::size_t i = 0; i < points.size(); ++i) {
        checkValue(tf, points[i].s);
        for (double f : {0.25, 0.5, 0.75})  // written so that no difference of two s can overflow
            if (i + 1 < points.size())
                checkValue(tf, (1.0 - f) * points[i].s + f * points[i + 1].s);
    }
    checkValue(tf, std::nextafter(tf.sMin(), -INFINITY));
    checkValue(tf, std::nextafter(tf.sMax(), INFINITY));
    return 0;
}
