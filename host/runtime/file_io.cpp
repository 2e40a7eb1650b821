// host/runtime/file_io.cpp — file checks shared by the data readers.
#include "host/runtime/file_io.h"

#include "host/runtime/errors.h"

#include <cstdio>
#include <fcntl.h>
#include <unistd.h>

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

QuietStdout::QuietStdout()
{
    std::fflush(stdout);
    saved_ = dup(STDOUT_FILENO);
    const int devNull = open("/dev/null", O_WRONLY | O_CLOEXEC);
    if (saved_ < 0 || devNull < 0) {  // cannot silence: leave stdout as it is
        if (devNull >= 0)
            close(devNull);
        if (saved_ >= 0)
            close(saved_);
        saved_ = -1;
        return;
    }
    dup2(devNull, STDOUT_FILENO);
    close(devNull);
}

QuietStdout::~QuietStdout()
{
    if (saved_ < 0)
        return;
    std::fflush(stdout);
    dup2(saved_, STDOUT_FILENO);
    close(saved_);
}

}  // namespace clvr
