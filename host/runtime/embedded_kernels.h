// host/runtime/embedded_kernels.h — the kernels/*.cl sources compiled into the binary at build time
// (tools/embed_kernels.cmake), with their quoted includes inlined between #line markers.
#pragma once

#include <string>
#include <string_view>
#include <vector>

namespace clvr {

struct EmbeddedKernel {
    std::string_view name;    // "slice3d.cl"
    std::string_view source;  // starts with #line 1 "kernels/slice3d.cl"
};

const std::vector<EmbeddedKernel>& embeddedKernels();

// The source of kernels/<name> (e.g. "slice3d.cl"), for fragment programs built from a kernel file;
// InternalError when this build has no such file (host/runtime/kernel_sources.cpp).
std::string_view embeddedKernelSource(std::string_view name);

// `log` with each position a compiler gave as a line of the whole submitted source, such as NVIDIA's
// "<kernel>:4:12" (its compiler ignores #line), rewritten as the file and line that `source`'s #line
// markers say, "kernels/broken.cl:3:12". Positions already named by file (PoCL, Mesa) are left alone.
std::string mapSourcePositions(std::string_view source, std::string_view log);

}  // namespace clvr
