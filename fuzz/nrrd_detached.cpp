// fuzz/nrrd_detached.cpp — libFuzzer target: readNrrd on a detached header. The input is
// "<header>" kSplitMarker "<data>": volume.nhdr and, beside it, the file "data" that the seeds' header
// names ("data file: data"); every encoding (raw, ascii, gzip) and the byte and line skips.
#include "fuzz/fuzz_input.h"
#include "host/io/volume_io.h"
#include "host/runtime/errors.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size)
{
    const auto parts = clvr::fuzz::splitInput(clvr::fuzz::asText(data, size), 2);
    const auto header = clvr::fuzz::writeFile("volume.nhdr", parts[0]);
    if (parts.size() == 2)
        clvr::fuzz::writeFile("data", parts[1]);
    else
        clvr::fuzz::removeFile("data");
    try {
        clvr::readNrrd(header);
    } catch (const clvr::InputError&) {
        // a clear error for bad input: what the reader promises
    }
    return 0;
}
