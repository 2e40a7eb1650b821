// host/runtime/file_io.cpp — file checks shared by the data readers.
#include "host/runtime/file_io.h"

#include "host/runtime/errors.h"

#include <cctype>

namespace clvr {

std::uint64_t fileSize(const std::filesystem::path& path)
{
    namespace fs = std::filesystem;
    std::error_code ec;
    const fs::file_status st = fs::status(path, ec);
    if (ec || !fs::exists(st))
        throw InputError(path.string() + ": no such file");
    if (fs::is_directory(st))
        throw InputError(path.string() + ": is a directory, not a file");
    const std::uintmax_t size = fs::file_size(path, ec);
    if (ec)
        throw InputError(path.string() + ": cannot read (" + ec.message() + ")");
    return size;
}

std::string asciiLower(std::string s)
{
    for (char& c : s)
        c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
    return s;
}

}  // namespace clvr
