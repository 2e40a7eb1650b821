// host/runtime/embedded_kernels.h — the kernels/*.cl sources compiled into the binary at build time
// (tools/embed_kernels.cmake), with their quoted includes inlined between #line markers.
#pragma once

#include <string_view>
#include <vector>

namespace clvr {

struct EmbeddedKernel {
    std::string_view name;    // "slice3d.cl"
    std::string_view source;  // starts with #line 1 "kernels/slice3d.cl"
};

const std::vector<EmbeddedKernel>& embeddedKernels();

}  // namespace clvr
