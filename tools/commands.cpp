// tools/commands.cpp — command-line parsing (CLI11) and the info subcommand.
#include "tools/commands.h"

#include "host/device.h"
#include "host/errors.h"

#include <CLI/CLI.hpp>

#include <iostream>

namespace clvr::tools {

int run(int argc, char** argv)
{
    CLI::App app{"clvr: OpenCL volume renderer"};
    app.require_subcommand(1);
    std::string deviceSpec;
    CLI::App* info = app.add_subcommand("info", "list OpenCL platforms and devices and say which one is used");
    info->add_option("--device", deviceSpec, "device index or name substring (else $CLVR_DEVICE, else first CPU)");
    try {
        app.parse(argc, argv);
    } catch (const CLI::CallForHelp& e) {
        return app.exit(e);
    } catch (const CLI::ParseError& e) {
        throw InputError(e.what());
    }
    if (*info) {
        const auto devices = listDevices();
        if (devices.empty())
            throw DeviceError("no OpenCL device found (is an ICD such as pocl-opencl-icd installed?)");
        const DeviceListing used = chooseDevice(deviceSpec);
        for (const DeviceListing& d : devices)
            std::cout << (d.index == used.index ? "* " : "  ") << d.index << ": " << d.name << " [" << d.type
                      << "] on " << d.platform << ", " << d.version << ", " << d.computeUnits << " compute units, "
                      << (d.globalMemBytes >> 20) << " MiB\n";
        std::cout << "using device " << used.index << " (" << used.name << ")\n";
        return 0;
    }
    return 0;
}

}  // namespace clvr::tools
