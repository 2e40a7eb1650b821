// host/runtime/device.h — the OpenCL runtime: device choice, context and queue, the program cache,
// named launches with per-pass timing, and checked buffer allocation.
#pragma once

#include <CL/opencl.hpp>

#include <atomic>
#include <cstddef>
#include <cstdint>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <tuple>
#include <vector>

namespace clvr {

// One device as `clvr info` lists it; `index` is what `--device N` takes.
struct DeviceListing {
    int index = 0;
    std::string platform;  // "Portable Computing Language"
    std::string name;      // "pthread-skylake-avx512"
    std::string version;   // "OpenCL 3.0 PoCL 3.1 ..."
    std::string type;      // "CPU", "GPU", "accelerator"
    cl_uint computeUnits = 0;
    cl_ulong globalMemBytes = 0;
    cl_ulong maxAllocBytes = 0;
    // The device's memory is the host's (CL_DEVICE_HOST_UNIFIED_MEMORY: PoCL's CPU devices, integrated GPUs), and
    // the alignment a host block must have for a buffer to use it in place (CL_DEVICE_MEM_BASE_ADDR_ALIGN, bytes).
    bool hostUnifiedMemory = false;
    std::size_t baseAddressAlignment = 0;
};

// Every device of every platform, in platform order. Empty if there is no OpenCL platform.
std::vector<DeviceListing> listDevices();

// The rule of DESIGN.md: `spec` (an index into listDevices() or a case-insensitive substring of
// the platform or device name) if not empty, else $CLVR_DEVICE, else the first CPU device, else
// the first device. Throws DeviceError when nothing matches or there is no device at all.
DeviceListing chooseDevice(const std::string& spec);

// Compiler options used for every program (STYLE.md: no fast-math, no mad-enable).
inline constexpr std::string_view kBuildOptions = "-cl-std=CL1.2";

struct PassTime {
    std::string name;  // the launch name, as --stats reports it
    double ms = 0.0;   // device time from the profiling events
};

// Faults a test can inject through $CLVR_INJECT_FAULT (device.cpp): a failing build, a failing N-th launch.
struct FaultInjection {
    bool build = false;
    std::uint64_t launch = 0;  // 1-based; 0: none
};

class Device {
public:
    // Opens the device chooseDevice(spec) names, with a profiling in-order queue. $CLVR_DEVICE_MEMORY_LIMIT
    // (bytes, or with a K/M/G suffix) caps the memory buffer() allows; InputError if it is malformed.
    explicit Device(const std::string& spec = "");

    const cl::Context& context() const { return context_; }
    const cl::Device& device() const { return device_; }
    cl::CommandQueue& queue() { return queue_; }
    const DeviceListing& listing() const { return listing_; }
    // "pthread-skylake-avx512 (OpenCL 3.0 PoCL 3.1 ...), 2 compute units"
    std::string description() const;

    // A fresh cl::Kernel (setArg on a shared one races) from the cached program built from the
    // embedded kernels/<file>, with `fragmentProgram` (OpenCL C defining functions that the
    // file declares and its kernels call) appended after it, and `extraOptions` appended to kBuildOptions. Throws BuildError with the
    // whole log when the build fails; a non-empty log on success goes to warnings().
    cl::Kernel kernel(std::string_view file, std::string_view kernelName,
                      std::string_view fragmentProgram = {}, std::string_view extraOptions = {});

    // Builds (or fetches) a program from arbitrary source; `label` names it in errors.
    cl::Program program(std::string_view label, std::string_view source, std::string_view options);

    // Milliseconds spent in clBuildProgram so far (cache hits cost nothing).
    double compileMs() const { return compileMs_; }

    // 0 when a kernel's loops run to completion; otherwise how many iterations of a 2^24-iteration loop
    // ran. Mesa's llvmpipe (rusticl) stops every loop of a work-item after 65,535 iterations counted over
    // all its loops together, silently (docs/devices.md). Asked once, by running a loop.
    std::uint64_t loopIterationCap();
    const std::vector<std::string>& warnings() const { return warnings_; }

    // Enqueues `kernel` with a name that --stats reports. A 1D count is padded up to a multiple
    // of 64 and a 2D range to multiples of 8 (PoCL has no non-uniform work-groups), so kernels
    // take their real extent as an argument and return early past it.
    void launch(std::string name, const cl::Kernel& kernel, std::size_t count);
    void launch(std::string name, const cl::Kernel& kernel, std::size_t width, std::size_t height);
    // A 2D launch in work-groups of groupWidth x groupHeight (the range padded to multiples of them).
    // The group is a speed hint: where the device or this kernel allows fewer work-items per group
    // (CL_KERNEL_WORK_GROUP_SIZE, CL_DEVICE_MAX_WORK_ITEM_SIZES), the driver picks the group instead,
    // so kernels launched this way must not depend on their group (no local memory, no barriers).
    void launch(std::string name, const cl::Kernel& kernel, std::size_t width, std::size_t height,
                std::size_t groupWidth, std::size_t groupHeight);

    // Waits for the queue, then returns and forgets the device times of launches since the last call.
    std::vector<PassTime> takePassTimes();

    // A device buffer of `bytes`, optionally initialized from `host`. Throws DeviceError naming
    // `what` if it exceeds the device's largest allocation or its global memory.
    cl::Buffer buffer(std::string_view what, std::size_t bytes, cl_mem_flags flags = CL_MEM_READ_WRITE,
                      const void* host = nullptr);

    // A read-only device buffer holding the `bytes` at `host`. Where the device's memory is the host's and
    // `host` is aligned as the device requires, the buffer is those bytes themselves (CL_MEM_USE_HOST_PTR: no
    // second copy; `owner` is kept alive until OpenCL releases the buffer, and the bytes must not change while it
    // lives); elsewhere a copy (CL_MEM_COPY_HOST_PTR). *inPlace, when given, says which. Errors as buffer().
    cl::Buffer readOnlyOver(std::string_view what, std::size_t bytes, const void* host,
                            std::shared_ptr<const void> owner, bool* inPlace = nullptr);

    // Bytes of the buffers buffer() made that are still alive (OpenCL frees a buffer when its last
    // cl::Buffer goes: a destructor callback counts it out), and the most there were at once.
    std::uint64_t deviceBytes() const { return memory_->live.load(); }
    std::uint64_t deviceBytesPeak() const { return memory_->peak.load(); }

    template <typename T>
    cl::Buffer upload(std::string_view what, const std::vector<T>& data, cl_mem_flags flags = CL_MEM_READ_ONLY)
    {
        return buffer(what, data.size() * sizeof(T), flags | CL_MEM_COPY_HOST_PTR,
                      const_cast<T*>(data.data()));
    }
    template <typename T>
    std::vector<T> download(const cl::Buffer& buffer, std::size_t count)
    {
        std::vector<T> out(count);
        if (count)
            queue_.enqueueReadBuffer(buffer, CL_TRUE, 0, count * sizeof(T), out.data());
        return out;
    }

private:
    void enqueue(std::string name, const cl::Kernel& kernel, const cl::NDRange& global,
                 const cl::NDRange& local = cl::NullRange);

    DeviceListing listing_;
    cl::Device device_;
    cl::Context context_;
    cl::CommandQueue queue_;
    std::map<std::tuple<std::string, std::string, std::string>, cl::Program> programs_;
    std::vector<std::pair<std::string, cl::Event>> pending_;
    std::vector<std::string> warnings_;
    double compileMs_ = 0.0;
    std::optional<std::uint64_t> loopIterationCap_;
    FaultInjection fault_;
    std::uint64_t launches_ = 0;
    // Shared with each buffer's destructor callback, which may run after the Device is gone.
    struct MemoryCount {
        std::atomic<std::uint64_t> live{0}, peak{0};
    };
    std::shared_ptr<MemoryCount> memory_ = std::make_shared<MemoryCount>();
};

}  // namespace clvr
