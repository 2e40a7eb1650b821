// fuzz/vtk_unstructured.cpp — libFuzzer target: readVtkUnstructured (VTK legacy UNSTRUCTURED_GRID, ASCII
// and BINARY, versions 2 to 5), then what loadMesh and the renderers do with it: checkMesh, buildTopology.
#include "fuzz/fuzz_input.h"
#include "host/io/mesh_io.h"
#include "host/runtime/errors.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size)
{
    const auto path = clvr::fuzz::writeFile("mesh.vtk", clvr::fuzz::asText(data, size));
    try {
        clvr::TetMesh mesh = clvr::readVtkUnstructured(path);
        clvr::checkMesh(mesh);
        clvr::buildTopology(mesh);
    } catch (const clvr::InputError&) {
        // a clear error for bad input: what the reader promises
    }
    return 0;
}
