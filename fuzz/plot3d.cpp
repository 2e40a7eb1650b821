// fuzz/plot3d.cpp — libFuzzer target: readPlot3d. The first byte picks the scalar (mod 4: density,
// momentum, energy, pressure); the rest is "<grid .xyz>" kSplitMarker "<solution .q>". Then checkMesh
// and buildTopology as loadMesh and the renderers apply them.
#include "fuzz/fuzz_input.h"
#include "host/io/mesh_io.h"
#include "host/runtime/errors.h"

#include <array>

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size)
{
    static const std::array<const char*, 4> kScalars{"density", "momentum", "energy", "pressure"};
    if (size < 1)
        return 0;
    const auto parts = clvr::fuzz::splitInput(clvr::fuzz::asText(data + 1, size - 1), 2);
    const auto xyz = clvr::fuzz::writeFile("grid.xyz", parts[0]);
    const auto q = clvr::fuzz::writeFile("grid.q", parts.size() > 1 ? parts[1] : "");
    try {
        clvr::TetMesh mesh = clvr::readPlot3d(xyz, q, kScalars[data[0] % 4]);
        clvr::checkMesh(mesh);
        clvr::buildTopology(mesh);
    } catch (const clvr::InputError&) {
        // a clear error for bad input: what the reader promises
    }
    return 0;
}
