// host/runtime/file_io.h — file checks shared by the data readers: each failure is one InputError naming the file.
#pragma once

#include <cstdint>
#include <filesystem>

namespace clvr {

// The size of the regular file at `path`; InputError "<path>: no such file", "... is a directory, not a
// file" or "... cannot read (...)".
std::uint64_t fileSize(const std::filesystem::path& path);

// Sends the process's standard output (file descriptor 1) to /dev/null while alive, and back after.
// Library readers that print progress there (TetGen's load_* print "Opening FILE.") would otherwise
// mix into clvr's own output, which scripts read. Not for use from several threads at once.
class QuietStdout {
public:
    QuietStdout();
    ~QuietStdout();
    QuietStdout(const QuietStdout&) = delete;
    QuietStdout& operator=(const QuietStdout&) = delete;

private:
    int saved_ = -1;
};

}  // namespace clvr
