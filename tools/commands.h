// tools/commands.h — the clvr subcommands (render, info, bench), called from main().
#pragma once

namespace clvr::tools {

// Parses the command line and runs one subcommand; returns the exit status. Throws the library's
// errors (InputError, DeviceError, BuildError) for main() to report.
int run(int argc, char** argv);

}  // namespace clvr::tools
