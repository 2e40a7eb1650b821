// host/runtime/file_io.h — file checks shared by the data readers: each failure is one InputError naming the file.
#pragma once

#include <cstdint>
#include <filesystem>
#include <string>

namespace clvr {

// The size of the regular file at `path`; InputError "<path>: no such file", "... is a directory, not a
// file" or "... cannot read (...)".
std::uint64_t fileSize(const std::filesystem::path& path);

// `s` with ASCII letters in lower case (file extensions, names and keywords compare case-blind).
std::string asciiLower(std::string s);

}  // namespace clvr
