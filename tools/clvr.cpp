// tools/clvr.cpp — main(): the only place that prints an error or chooses an exit code.
#include "host/runtime/errors.h"
#include "tools/commands.h"

#include <CL/opencl.hpp>

#include <iostream>
#include <new>

namespace {

// std::cerr, or a sink for the ranks of an MPI job that leave the error line to rank 0.
std::ostream& errorStream()
{
    static std::ostream sink(nullptr);
    return clvr::tools::errorsQuiet() ? sink : std::cerr;
}

}  // namespace

int main(int argc, char** argv)
{
    try {
        return clvr::tools::run(argc, argv);
    } catch (const clvr::InputError& e) {
        errorStream() << "clvr: error: " << e.what() << '\n';
        return 2;
    } catch (const clvr::BuildError& e) {
        errorStream() << "clvr: error: " << e.what() << '\n' << clvr::indent(e.log);
        return 3;
    } catch (const clvr::DeviceError& e) {
        errorStream() << "clvr: error: " << e.what() << '\n';
        return 3;
    } catch (const cl::Error& e) {  // any other OpenCL call: its name and its code
        errorStream() << "clvr: error: " << e.what() << " failed: " << clvr::clErrorName(e.err()) << '\n';
        return 3;
    } catch (const clvr::InternalError& e) {  // a bug, never the user's input: its own status
        errorStream() << "clvr: internal error: " << e.what() << '\n';
        return 4;
    } catch (const std::bad_alloc&) {
        errorStream() << "clvr: error: out of host memory\n";
        return 3;
    } catch (const std::exception& e) {
        errorStream() << "clvr: internal error: " << e.what() << '\n';
        return 4;
    }
}
