// fuzz/vti.cpp — libFuzzer target: readVtkImage through VTK's XML image readers. The input is a .vti,
// or a .pvti and the one piece it may name ("piece.vti"), cut at the split marker; the whole grid and a
// region of it are read. VTK's readers are not instrumented: this checks what clvr does with what they
// return (and that they return) on bad files.
#include "fuzz/fuzz_input.h"
#include "host/io/vtk_xml_io.h"
#include "host/runtime/errors.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size)
{
    const auto parts = clvr::fuzz::splitInput(clvr::fuzz::asText(data, size), 2);
    std::filesystem::path path;
    if (parts.size() == 2) {
        path = clvr::fuzz::writeFile("volume.pvti", parts[0]);
        clvr::fuzz::writeFile("piece.vti", parts[1]);
    } else {
        clvr::fuzz::removeFile("piece.vti");
        path = clvr::fuzz::writeFile("volume.vti", parts[0]);
    }
    try {
        const clvr::GridHeader h = clvr::readVtkImageHeader(path);
        clvr::readVtkImage(path);
        clvr::readVtkImage(path, "", clvr::GridRegion{glm::ivec3(0), h.dims / 2});
    } catch (const clvr::InputError&) {
        // a clear error for bad input: what the reader promises
    }
    return 0;
}
