// fuzz/vtk_points.cpp — libFuzzer target: readVtkStructuredPoints (VTK legacy STRUCTURED_POINTS, ASCII
// and big-endian BINARY).
#include "fuzz/fuzz_input.h"
#include "host/io/volume_io.h"
#include "host/runtime/errors.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size)
{
    const auto path = clvr::fuzz::writeFile("volume.vtk", clvr::fuzz::asText(data, size));
    try {
        clvr::readVtkStructuredPoints(path);
    } catch (const clvr::InputError&) {
        // a clear error for bad input: what the reader promises
    }
    return 0;
}
