// host/runtime/kernel_sources.cpp — one embedded kernel's source by file name.
#include "host/runtime/embedded_kernels.h"

#include "host/runtime/errors.h"

#include <string>

namespace clvr {

std::string_view embeddedKernelSource(std::string_view name)
{
    for (const EmbeddedKernel& k : embeddedKernels())
        if (k.name == name)
            return k.source;
    throw InternalError("kernels/" + std::string(name) + " is not embedded in this build");
}

}  // namespace clvr
