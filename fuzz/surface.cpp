// fuzz/surface.cpp — libFuzzer target: readPlc and checkSurface (what clvr checks before TetGen runs),
// the surfaces TetGen meshes. The first byte picks the
// format by extension (mod 4: .off, .stl, .poly, .smesh; .stl is ASCII STL, the only STL clvr reads),
// the rest is the file.
#include "fuzz/fuzz_input.h"
#include "host/io/surface_io.h"
#include "host/runtime/errors.h"

#include <array>

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size)
{
    static const std::array<const char*, 4> kNames{"surface.off", "surface.stl", "surface.poly", "surface.smesh"};
    if (size < 1)
        return 0;
    const auto path = clvr::fuzz::writeFile(kNames[data[0] % 4], clvr::fuzz::asText(data + 1, size - 1));
    try {
        const clvr::Plc plc = clvr::readPlc(path);
        clvr::checkSurface(plc, path, data[0] % 4 < 2);  // strict for .off and .stl, as meshSurface
    } catch (const clvr::InputError&) {
        // a clear error for bad input: what the reader promises
    }
    return 0;
}
