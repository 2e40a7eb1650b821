// fuzz/off_tet.cpp — libFuzzer target: readOffTet (.off tetrahedral meshes), then checkMesh and
// buildTopology as loadMesh and the renderers apply them.
#include "fuzz/fuzz_input.h"
#include "host/io/mesh_io.h"
#include "host/runtime/errors.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size)
{
    const auto path = clvr::fuzz::writeFile("mesh.off", clvr::fuzz::asText(data, size));
    try {
        clvr::TetMesh mesh = clvr::readOffTet(path);
        clvr::checkMesh(mesh);
        clvr::buildTopology(mesh);
    } catch (const clvr::InputError&) {
        // a clear error for bad input: what the reader promises
    }
    return 0;
}
