// fuzz/raw.cpp — libFuzzer target: readRaw with a layout taken from the input's first 11 bytes; the
// rest is the file. Bytes 0-5: dims x, y, z as little-endian int16 (zero, negative and large sizes
// reach the checks); 6: sample type (mod 8); 7: bit 0 big-endian, bits 1-7 header bytes;
// 8-10: spacing per axis as int8 / 4 (zero and negative too).
#include "fuzz/fuzz_input.h"
#include "host/io/volume_io.h"
#include "host/runtime/errors.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size)
{
    constexpr std::size_t kLayoutBytes = 11;
    if (size < kLayoutBytes)
        return 0;
    clvr::RawLayout layout;
    for (int a = 0; a < 3; ++a)
        layout.dims[a] = static_cast<std::int16_t>(data[2 * a] | data[2 * a + 1] << 8);
    layout.type = static_cast<clvr::ScalarType>(data[6] % 8);
    layout.endian = data[7] & 1 ? clvr::Endian::Big : clvr::Endian::Little;
    layout.headerBytes = data[7] >> 1;
    for (int a = 0; a < 3; ++a)
        layout.spacing[a] = static_cast<std::int8_t>(data[8 + a]) / 4.0;
    const auto path = clvr::fuzz::writeFile("volume.raw", clvr::fuzz::asText(data + kLayoutBytes, size - kLayoutBytes));
    try {
        clvr::readRaw(path, layout);
    } catch (const clvr::InputError&) {
        // a clear error for bad input: what the reader promises
    }
    return 0;
}
