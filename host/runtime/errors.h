// host/runtime/errors.h — the kinds of failure the library reports. Library code throws; only tools/clvr.cpp
// prints and chooses an exit code (InputError: 2, DeviceError and BuildError: 3, InternalError: 4).
#pragma once

#include <stdexcept>
#include <string>

namespace clvr {

// Bad input: usage, scene, data file. The message names the file and what is wrong.
struct InputError : std::runtime_error {
    using runtime_error::runtime_error;
};

// No device, out of device memory, a failed OpenCL call.
struct DeviceError : std::runtime_error {
    using runtime_error::runtime_error;
};

// A kernel failed to build: the exception owns the compiler's whole log.
struct BuildError : DeviceError {
    BuildError(const std::string& what, std::string log) : DeviceError(what), log(std::move(log)) {}
    std::string log;
};

// A violated internal invariant: a bug in clvr (or in a program calling the library wrongly), never
// the user's input or the device. Callers of the library check their arguments before passing them on;
// whatever reaches a check that throws this is a programming error.
struct InternalError : std::logic_error {
    using logic_error::logic_error;
};

// The symbolic name of an OpenCL error code ("CL_OUT_OF_RESOURCES"), or "CL error N".
std::string clErrorName(int code);

// A number as a person would write it in a message: 0.5, -1, nan (std::to_string gives 0.500000).
std::string numberText(double v);

// Every line of text prefixed with four spaces (used to print build logs under the error line).
std::string indent(const std::string& text);

}  // namespace clvr
