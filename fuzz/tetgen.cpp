// fuzz/tetgen.cpp — libFuzzer target: readTetgen. The input is "<.node>" kSplitMarker "<.ele>", and
// optionally kSplitMarker "<.neigh>"; then checkMesh and buildTopology (which checks the .neigh).
#include "fuzz/fuzz_input.h"
#include "host/io/mesh_io.h"
#include "host/runtime/errors.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size)
{
    const auto parts = clvr::fuzz::splitInput(clvr::fuzz::asText(data, size), 3);
    const auto node = clvr::fuzz::writeFile("mesh.node", parts[0]);
    clvr::fuzz::writeFile("mesh.ele", parts.size() > 1 ? parts[1] : "");
    if (parts.size() > 2)
        clvr::fuzz::writeFile("mesh.neigh", parts[2]);
    else
        clvr::fuzz::removeFile("mesh.neigh");
    try {
        clvr::TetMesh mesh = clvr::readTetgen(node);
        clvr::checkMesh(mesh);
        clvr::buildTopology(mesh);
    } catch (const clvr::InputError&) {
        // a clear error for bad input: what the reader promises
    }
    return 0;
}
