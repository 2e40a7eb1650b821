// fuzz/vtu.cpp — libFuzzer target: readVtkXmlUnstructured through VTK's XML unstructured-grid reader, then
// checkMesh as loadMesh applies it. VTK's reader is not instrumented: this checks what clvr does with what
// it returns on bad files (cell types, point indices, array sizes).
#include "fuzz/fuzz_input.h"
#include "host/io/vtk_xml_io.h"
#include "host/runtime/errors.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size)
{
    const auto path = clvr::fuzz::writeFile("mesh.vtu", clvr::fuzz::asText(data, size));
    try {
        clvr::TetMesh mesh = clvr::readVtkXmlUnstructured(path);
        clvr::checkMesh(mesh);
    } catch (const clvr::InputError&) {
        // a clear error for bad input: what the reader promises
    }
    return 0;
}
