// fuzz/scene.cpp — libFuzzer target: loadScene as `clvr render SCENE --set ... --unset ...` calls it.
// The input is the scene JSON, optionally followed by kSplitMarker and the command line's values, one
// per line: "-PATH" is `--unset PATH`, any other line `--set PATH=VALUE`.
#include "fuzz/fuzz_input.h"
#include "host/model/scene.h"
#include "host/runtime/errors.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size)
{
    const auto parts = clvr::fuzz::splitInput(clvr::fuzz::asText(data, size), 2);
    std::vector<std::string> overrides, unsets;
    for (std::string_view rest = parts.size() > 1 ? parts[1] : ""; !rest.empty();) {
        const std::string_view line = rest.substr(0, rest.find('\n'));
        rest.remove_prefix(std::min(rest.size(), line.size() + 1));
        if (!line.empty() && line[0] == '-')
            unsets.emplace_back(line.substr(1));
        else
            overrides.emplace_back(line);
    }
    const auto path = clvr::fuzz::writeFile("scene.json", parts[0]);
    try {
        clvr::loadScene(path, overrides, unsets);
    } catch (const clvr::InputError&) {
        // a clear error for bad input: what the parser promises
    }
    return 0;
}
