// fuzz/nrrd.cpp — libFuzzer target: readNrrd on one .nrrd file, header and attached data (raw, ascii,
// gzip encodings; a "data file" field makes it read other files, which mostly do not exist).
#include "fuzz/fuzz_input.h"
#include "host/io/volume_io.h"
#include "host/runtime/errors.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size)
{
    const auto path = clvr::fuzz::writeFile("volume.nrrd", clvr::fuzz::asText(data, size));
    try {
        clvr::readNrrd(path);
    } catch (const clvr::InputError&) {
        // a clear error for bad input: what the reader promises
    }
    return 0;
}
