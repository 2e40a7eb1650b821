// fuzz/fuzz_input.h — what the libFuzzer targets share: the readers take paths, so each input is written
// to files in a folder of this process's own; inputs that stand for several files (header and data,
// .node and .ele, grid and solution) are cut at kSplitMarker.
#pragma once

#include <unistd.h>

#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <string>
#include <string_view>
#include <vector>

namespace clvr::fuzz {

// Separates the files of one input; the seeds and the dictionaries hold it.
inline constexpr std::string_view kSplitMarker = "\n--8<--\n";

// /dev/shm/clvr-fuzz-<pid> (else under $TMPDIR or /tmp): one folder per process, so parallel runs (-jobs,
// -fork) do not share files. In memory where possible: ext4 writes a truncated and rewritten file to
// the disk at once (auto_da_alloc), which made every run 10 times slower. Removed at a normal exit.
inline const std::filesystem::path& workDir()
{
    struct Dir {
        std::filesystem::path path = (std::filesystem::is_directory("/dev/shm") ? std::filesystem::path("/dev/shm")
                                                                                 : std::filesystem::temp_directory_path()) /
                                     ("clvr-fuzz-" + std::to_string(::getpid()));
        Dir() { std::filesystem::create_directories(path); }
        ~Dir()
        {
            std::error_code ec;
            std::filesystem::remove_all(path, ec);
        }
    };
    static const Dir dir;
    return dir.path;
}

inline std::string_view asText(const std::uint8_t* data, std::size_t size)
{
    return {reinterpret_cast<const char*>(data), size};
}

// workDir()/name holding exactly `bytes`.
inline std::filesystem::path writeFile(const std::string& name, std::string_view bytes)
{
    const std::filesystem::path path = workDir() / name;
    std::ofstream out(path, std::ios::binary | std::ios::trunc);
    out.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
    return path;
}

// workDir()/name removed (an optional file the last input wrote must not outlive it).
inline std::filesystem::path removeFile(const std::string& name)
{
    const std::filesystem::path path = workDir() / name;
    std::error_code ec;
    std::filesystem::remove(path, ec);
    return path;
}

// `input` cut at the first `maxParts - 1` markers: 1 to maxParts pieces, the last keeping any later marker.
inline std::vector<std::string_view> splitInput(std::string_view input, std::size_t maxParts)
{
    std::vector<std::string_view> parts;
    while (parts.size() + 1 < maxParts) {
        const std::size_t at = input.find(kSplitMarker);
        if (at == std::string_view::npos)
            break;
        parts.push_back(input.substr(0, at));
        input.remove_prefix(at + kSplitMarker.size());
    }
    parts.push_back(input);
    return parts;
}

}  // namespace clvr::fuzz
