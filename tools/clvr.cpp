// tools/clvr.cpp — main(): the only place that prints an error or chooses an exit code.
#include "host/runtime/errors.h"
#include "tools/commands.h"

#include <CL/opencl.hpp>

#include <iostream>
#include <new>

int main(int argc, char** argv)
{
    try {
        return clvr::tools::run(argc, argv);
    } catch (const clvr::InputError& e) {
        std::cerr << "clvr: error: " << e.what() << '\n';
        return 2;
    } catch (const clvr::BuildError& e) {
        std::cerr << "clvr: error: " << e.what() << '\n' << clvr::indent(e.log);
        return 3;
    } catch (const clvr::DeviceError& e) {
        std::cerr << "clvr: error: " << e.what() << '\n';
        return 3;
    } catch (const cl::Error& e) {  // any other OpenCL call: its name and its code
        std::cerr << "clvr: error: " << e.what() << " failed: " << clvr::clErrorName(e.err()) << '\n';
        return 3;
    } catch (const clvr::InternalError& e) {  // a bug, never the user's input: its own status
        std::cerr << "clvr: internal error: " << e.what() << '\n';
        return 4;
    } catch (const std::bad_alloc&) {
        std::cerr << "clvr: error: out of host memory\n";
        return 3;
    } catch (const std::exception& e) {
        std::cerr << "clvr: internal error: " << e.what() << '\n';
        return 4;
    }
}
