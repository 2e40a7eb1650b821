// fuzz/npy.cpp — libFuzzer target: readNpy (numpy .npy, versions 1-3, every dtype clvr takes).
#include "fuzz/fuzz_input.h"
#include "host/io/volume_io.h"
#include "host/runtime/errors.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size)
{
    const auto path = clvr::fuzz::writeFile("volume.npy", clvr::fuzz::asText(data, size));
    try {
        clvr::readNpy(path);
    } catch (const clvr::InputError&) {
        // a clear error for bad input: what the reader promises
    }
    return 0;
}
