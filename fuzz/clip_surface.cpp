// fuzz/clip_surface.cpp — libFuzzer target: readSurface and closeClipMesh, the closed triangle surfaces
// that clip a volume (host/optics/clip_mesh.h). The first byte picks the format by extension (mod 3:
// .off, .stl — ASCII or binary, as the reader decides from the bytes — or .obj), the rest is the file.
#include "fuzz/fuzz_input.h"
#include "host/optics/clip_mesh.h"
#include "host/runtime/errors.h"

#include <array>

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size)
{
    static const std::array<const char*, 3> kNames{"clip.off", "clip.stl", "clip.obj"};
    if (size < 1)
        return 0;
    const auto path = clvr::fuzz::writeFile(kNames[data[0] % 3], clvr::fuzz::asText(data + 1, size - 1));
    try {
        clvr::ClipMesh mesh = clvr::readSurface(path);
        clvr::closeClipMesh(mesh);
    } catch (const clvr::InputError&) {
        // a clear error for bad input: what the reader promises
    }
    return 0;
}
