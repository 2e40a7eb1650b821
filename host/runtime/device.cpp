// host/runtime/device.cpp — device choice, program build and cache, named launches, checked buffers.
#include "host/runtime/device.h"

#include "host/runtime/embedded_kernels.h"
#include "host/runtime/errors.h"
#include "host/runtime/file_io.h"

#include <algorithm>
#include <array>
#include <cctype>
#include <chrono>
#include <cstdlib>
#include <cstring>

namespace clvr {
namespace {

std::string typeName(cl_device_type type)
{
    if (type & CL_DEVICE_TYPE_GPU)
        return "GPU";
    if (type & CL_DEVICE_TYPE_CPU)
        return "CPU";
    if (type & CL_DEVICE_TYPE_ACCELERATOR)
        return "accelerator";
    return "other";
}

struct Found {
    DeviceListing listing;
    cl::Device device;
};

std::vector<Found> enumerate()
{
    std::vector<cl::Platform> platforms;
    // The ICD loader returns CL_PLATFORM_NOT_FOUND_KHR (-1001) when no platform is installed.
    cl_uint count = 0;
    if (clGetPlatformIDs(0, nullptr, &count) != CL_SUCCESS || count == 0)
        return {};
    cl::Platform::get(&platforms);
    std::vector<Found> found;
    for (const cl::Platform& platform : platforms) {
        std::vector<cl::Device> devices;
        try {
            platform.getDevices(CL_DEVICE_TYPE_ALL, &devices);
        } catch (const cl::Error&) {  // CL_DEVICE_NOT_FOUND: a platform without devices
            continue;
        }
        for (const cl::Device& d : devices) {
            DeviceListing l;
            l.index = static_cast<int>(found.size());
            l.platform = platform.getInfo<CL_PLATFORM_NAME>();
            l.name = d.getInfo<CL_DEVICE_NAME>();
            l.version = d.getInfo<CL_DEVICE_VERSION>();
            l.type = typeName(d.getInfo<CL_DEVICE_TYPE>());
            l.computeUnits = d.getInfo<CL_DEVICE_MAX_COMPUTE_UNITS>();
            l.globalMemBytes = d.getInfo<CL_DEVICE_GLOBAL_MEM_SIZE>();
            l.maxAllocBytes = d.getInfo<CL_DEVICE_MAX_MEM_ALLOC_SIZE>();
            l.hostUnifiedMemory = d.getInfo<CL_DEVICE_HOST_UNIFIED_MEMORY>() == CL_TRUE;
            l.baseAddressAlignment = d.getInfo<CL_DEVICE_MEM_BASE_ADDR_ALIGN>() / 8;  // bits to bytes
            // Strip the trailing NULs some drivers leave in info strings.
            for (std::string* s : {&l.platform, &l.name, &l.version})
                s->erase(std::find(s->begin(), s->end(), '\0'), s->end());
            found.push_back({l, d});
        }
    }
    return found;
}

const Found& pick(const std::vector<Found>& found, const std::string& spec)
{
    if (found.empty())
        throw DeviceError("no OpenCL device found (is an ICD such as pocl-opencl-icd installed?)");
    std::string rule = spec;
    std::string source = "--device";
    if (rule.empty()) {
        if (const char* env = std::getenv("CLVR_DEVICE"); env && *env) {
            rule = env;
            source = "CLVR_DEVICE";
        }
    }
    if (rule.empty()) {
        for (const Found& f : found)
            if (f.listing.type == "CPU")
                return f;
        return found.front();
    }
    if (std::all_of(rule.begin(), rule.end(), [](unsigned char c) { return std::isdigit(c); })) {
        // At most 9 digits: no overflow, and no machine has a billion devices.
        const unsigned long index = rule.size() <= 9 ? std::stoul(rule) : ~0ul;
        if (index >= found.size())
            throw DeviceError(source + " " + rule + ": " +
                              (found.size() == 1 ? std::string("there is only 1 OpenCL device")
                                                 : "there are only " + std::to_string(found.size()) + " OpenCL devices") +
                              ", numbered from 0 (see clvr info)");
        return found[index];
    }
    // A device type: the first device of that type.
    const std::string lower = asciiLower(rule);
    if (lower == "cpu" || lower == "gpu" || lower == "accelerator") {
        for (const Found& f : found)
            if (asciiLower(f.listing.type) == lower)
                return f;
        throw DeviceError(source + " " + rule + ": no OpenCL device of type " + lower + " (see clvr info)");
    }
    for (const Found& f : found)
        if (asciiLower(f.listing.name).find(asciiLower(rule)) != std::string::npos ||
            asciiLower(f.listing.platform).find(asciiLower(rule)) != std::string::npos)
            return f;
    throw DeviceError(source + " \"" + rule + "\" matches no OpenCL device (see clvr info)");
}

// $CLVR_INJECT_FAULT, a testing aid (docs/robustness.md): "build" makes every program build fail in the
// compiler (an #error appended to the source), "launch:N" makes the N-th kernel launch fail as a driver's
// CL_OUT_OF_RESOURCES would. Unset or empty: no fault.
FaultInjection faultFromEnvironment()
{
    const char* env = std::getenv("CLVR_INJECT_FAULT");
    if (!env || !*env)
        return {};
    const std::string text(env);
    FaultInjection fault;
    if (text == "build") {
        fault.build = true;
        return fault;
    }
    const std::string prefix = "launch:";
    if (text.rfind(prefix, 0) == 0 && text.size() > prefix.size() && text.size() <= prefix.size() + 9 &&
        std::all_of(text.begin() + prefix.size(), text.end(), [](unsigned char c) { return std::isdigit(c); })) {
        fault.launch = std::stoull(text.substr(prefix.size()));
        if (fault.launch > 0)
            return fault;
    }
    throw InputError("CLVR_INJECT_FAULT \"" + text + "\": want \"build\" or \"launch:N\" with N >= 1");
}

// $CLVR_DEVICE_MEMORY_LIMIT: bytes with an optional K, M or G suffix (powers of 1024); 0 when unset.
cl_ulong memoryLimitFromEnvironment()
{
    const char* env = std::getenv("CLVR_DEVICE_MEMORY_LIMIT");
    if (!env || !*env)
        return 0;
    const std::string text(env);
    std::size_t used = 0;
    unsigned long long value = 0;
    try {
        value = std::stoull(text, &used);
    } catch (const std::exception&) {
        used = 0;
    }
    unsigned shift = 0;
    if (used > 0 && used + 1 == text.size()) {
        switch (std::toupper(static_cast<unsigned char>(text.back()))) {
        case 'K': shift = 10; break;
        case 'M': shift = 20; break;
        case 'G': shift = 30; break;
        default: used = 0;
        }
        if (used)
            used = text.size();
    }
    if (used != text.size() || value == 0 || value > (~0ull >> shift))
        throw InputError("CLVR_DEVICE_MEMORY_LIMIT \"" + text + "\": want a positive byte count like 512M or 2G");
    return static_cast<cl_ulong>(value) << shift;
}

std::string mib(cl_ulong bytes)
{
    return std::to_string((bytes + (1u << 20) - 1) >> 20) + " MiB";
}

}  // namespace

std::vector<DeviceListing> listDevices()
{
    std::vector<DeviceListing> out;
    for (const Found& f : enumerate())
        out.push_back(f.listing);
    return out;
}

DeviceListing chooseDevice(const std::string& spec)
{
    return pick(enumerate(), spec).listing;
}

Device::Device(const std::string& spec)
{
    const std::vector<Found> found = enumerate();
    const Found& chosen = pick(found, spec);
    listing_ = chosen.listing;
    // A user-set cap on device memory (shared GPUs on a cluster node; tests of the out-of-memory path).
    if (const cl_ulong limit = memoryLimitFromEnvironment()) {
        listing_.globalMemBytes = std::min(listing_.globalMemBytes, limit);
        listing_.maxAllocBytes = std::min(listing_.maxAllocBytes, limit);
    }
    fault_ = faultFromEnvironment();
    device_ = chosen.device;
    context_ = cl::Context(device_);
    queue_ = cl::CommandQueue(context_, device_, CL_QUEUE_PROFILING_ENABLE);
}

std::string Device::description() const
{
    return listing_.name + " (" + listing_.version + "), " + std::to_string(listing_.computeUnits) +
           " compute units";
}

cl::Program Device::program(std::string_view label, std::string_view source, std::string_view options)
{
    auto key = std::make_tuple(std::string(label), std::string(source), std::string(options));
    if (auto it = programs_.find(key); it != programs_.end())
        return it->second;

    cl::Program program(context_, fault_.build ? std::string(source) + "\n#error CLVR_INJECT_FAULT=build\n"
                                                : std::string(source));
    const auto start = std::chrono::steady_clock::now();
    cl_int status = CL_SUCCESS;
    try {
        status = program.build({device_}, std::string(options).c_str());
    } catch (const cl::Error& e) {
        status = e.err();
    }
    compileMs_ += std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
    std::string log;
    try {
        log = program.getBuildInfo<CL_PROGRAM_BUILD_LOG>(device_);
        log.erase(std::find(log.begin(), log.end(), '\0'), log.end());
    } catch (const cl::Error&) {
    }
    log = mapSourcePositions(source, log);
    if (status != CL_SUCCESS) {
        throw BuildError("building " + std::string(label) + " for \"" + listing_.name + "\" (" + listing_.version +
                             ") with \"" + std::string(options) + "\" failed: " + clErrorName(status),
                         log.empty() ? "(the compiler left no log)" : log);
    }
    if (log.find_first_not_of(" \t\r\n") != std::string::npos)
        warnings_.push_back(std::string(label) + ": " + log);
    programs_.emplace(std::move(key), program);
    return program;
}

cl::Kernel Device::kernel(std::string_view file, std::string_view kernelName, std::string_view fragmentProgram,
                          std::string_view extraOptions)
{
    const auto& kernels = embeddedKernels();
    const auto it = std::find_if(kernels.begin(), kernels.end(), [&](const EmbeddedKernel& k) { return k.name == file; });
    if (it == kernels.end())
        throw DeviceError("no embedded kernel file kernels/" + std::string(file));
    // The fragment program goes after the file, so it can use everything the file includes;
    // the file declares the functions the fragment program must define.
    std::string source(it->source);
    if (!fragmentProgram.empty()) {
        source += "\n#line 1 \"fragment program\"\n";
        source += fragmentProgram;
        source += '\n';
    }
    std::string options(kBuildOptions);
    if (!extraOptions.empty())
        options += " " + std::string(extraOptions);
    cl::Program prog = program("kernels/" + std::string(file), source, options);
    try {
        return cl::Kernel(prog, std::string(kernelName).c_str());
    } catch (const cl::Error& e) {
        throw DeviceError("kernels/" + std::string(file) + " has no kernel \"" + std::string(kernelName) +
                          "\": " + clErrorName(e.err()));
    }
}

void Device::enqueue(std::string name, const cl::Kernel& kernel, const cl::NDRange& global, const cl::NDRange& local)
{
    if (fault_.launch && ++launches_ == fault_.launch)
        throw DeviceError("launching \"" + name + "\" failed: CL_OUT_OF_RESOURCES (injected by CLVR_INJECT_FAULT=launch:" +
                          std::to_string(fault_.launch) + ")");
    cl::Event event;
    try {
        queue_.enqueueNDRangeKernel(kernel, cl::NullRange, global, local, nullptr, &event);
    } catch (const cl::Error& e) {
        if (e.err() == CL_MEM_OBJECT_ALLOCATION_FAILURE || e.err() == CL_OUT_OF_RESOURCES ||
            e.err() == CL_OUT_OF_HOST_MEMORY)
            throw DeviceError("out of device memory running \"" + name + "\" on " + listing_.name + ": " +
                              clErrorName(e.err()));
        throw DeviceError("launching \"" + name + "\" failed: " + clErrorName(e.err()));
    }
    pending_.emplace_back(std::move(name), std::move(event));
}

void Device::launch(std::string name, const cl::Kernel& kernel, std::size_t count)
{
    const std::size_t padded = std::max<std::size_t>(64, (count + 63) / 64 * 64);
    enqueue(std::move(name), kernel, cl::NDRange(padded));
}

void Device::launch(std::string name, const cl::Kernel& kernel, std::size_t width, std::size_t height)
{
    const std::size_t w = std::max<std::size_t>(8, (width + 7) / 8 * 8);
    const std::size_t h = std::max<std::size_t>(8, (height + 7) / 8 * 8);
    enqueue(std::move(name), kernel, cl::NDRange(w, h));
}

void Device::launch(std::string name, const cl::Kernel& kernel, std::size_t width, std::size_t height,
                    std::size_t groupWidth, std::size_t groupHeight)
{
    const std::size_t w = std::max<std::size_t>(1, (width + groupWidth - 1) / groupWidth) * groupWidth;
    const std::size_t h = std::max<std::size_t>(1, (height + groupHeight - 1) / groupHeight) * groupHeight;
    const auto itemSizes = device_.getInfo<CL_DEVICE_MAX_WORK_ITEM_SIZES>();
    const std::size_t kernelLimit = kernel.getWorkGroupInfo<CL_KERNEL_WORK_GROUP_SIZE>(device_);
    const bool fits = groupWidth * groupHeight <= kernelLimit && itemSizes.size() >= 2 &&
                      groupWidth <= itemSizes[0] && groupHeight <= itemSizes[1];
    enqueue(std::move(name), kernel, cl::NDRange(w, h), fits ? cl::NDRange(groupWidth, groupHeight) : cl::NullRange);
}

std::uint64_t Device::loopIterationCap()
{
    if (!loopIterationCap_) {
        constexpr cl_uint kIterations = 1u << 24;
        cl::Kernel k = kernel("util.cl", "loop_iterations");
        cl::Buffer out = upload("loop probe result", std::vector<cl_uint>{0u}, CL_MEM_READ_WRITE);
        cl::Buffer ones = upload("loop probe ones", std::vector<cl_uint>(16, 1u));
        k.setArg(0, out);
        k.setArg(1, ones);
        k.setArg(2, kIterations);
        cl::Event event;
        queue_.enqueueNDRangeKernel(k, cl::NullRange, cl::NDRange(1), cl::NullRange, nullptr, &event);
        const cl_uint ran = download<cl_uint>(out, 1).front();
        loopIterationCap_ = ran == kIterations ? 0 : ran;
    }
    return *loopIterationCap_;
}

std::vector<PassTime> Device::takePassTimes()
{
    queue_.finish();
    std::vector<PassTime> out;
    out.reserve(pending_.size());
    for (auto& [name, event] : pending_) {
        const cl_ulong start = event.getProfilingInfo<CL_PROFILING_COMMAND_START>();
        const cl_ulong end = event.getProfilingInfo<CL_PROFILING_COMMAND_END>();
        out.push_back({name, static_cast<double>(end - start) * 1e-6});
    }
    pending_.clear();
    return out;
}

namespace {

// Device::deviceBytes(): `bytes` counted in now and out when OpenCL releases the buffer.
// `owner` (may be null) is kept alive until then. False when OpenCL refused the callback (the buffer is then
// not counted, and `owner` not kept).
template <typename Count>
bool countBuffer(const cl::Buffer& buffer, std::uint64_t bytes, const std::shared_ptr<Count>& count,
                 std::shared_ptr<const void> owner = nullptr)
{
    struct Release {
        std::shared_ptr<Count> count;
        std::uint64_t bytes;
        std::shared_ptr<const void> owner;
    };
    const std::uint64_t live = count->live.fetch_add(bytes) + bytes;
    std::uint64_t peak = count->peak.load();
    while (live > peak && !count->peak.compare_exchange_weak(peak, live)) {
    }
    auto* release = new Release{count, bytes, std::move(owner)};
    const cl_int err = clSetMemObjectDestructorCallback(
        buffer(),
        [](cl_mem, void* data) {
            auto* r = static_cast<Release*>(data);
            r->count->live.fetch_sub(r->bytes);
            delete r;
        },
        release);
    if (err != CL_SUCCESS) {  // not counted out then: forget it now rather than leak the record
        count->live.fetch_sub(bytes);
        delete release;
        return false;
    }
    return true;
}

}  // namespace

cl::Buffer Device::buffer(std::string_view what, std::size_t bytes, cl_mem_flags flags, const void* host)
{
    if (bytes > listing_.maxAllocBytes || bytes > listing_.globalMemBytes)
        throw DeviceError("out of device memory: " + std::string(what) + " needs " + mib(bytes) + ", " +
                          listing_.name + " allows " + mib(listing_.maxAllocBytes) + " per buffer and has " +
                          mib(listing_.globalMemBytes));
    // Zero-sized buffers are invalid in OpenCL: allocate at least 4 bytes. CL_MEM_COPY_HOST_PTR then
    // reads the whole allocation, so a shorter host block is copied into a zero-padded one first.
    constexpr std::size_t kMinBytes = 4;
    std::array<unsigned char, kMinBytes> padded{};
    if ((flags & CL_MEM_COPY_HOST_PTR) != 0 && bytes < kMinBytes) {
        if (bytes > 0)
            std::memcpy(padded.data(), host, bytes);
        host = padded.data();
    }
    try {
        cl::Buffer buffer(context_, flags, std::max(bytes, kMinBytes), const_cast<void*>(host));
        countBuffer(buffer, std::max(bytes, kMinBytes), memory_);
        return buffer;
    } catch (const cl::Error& e) {
        const bool noMemory = e.err() == CL_MEM_OBJECT_ALLOCATION_FAILURE || e.err() == CL_OUT_OF_RESOURCES ||
                              e.err() == CL_OUT_OF_HOST_MEMORY || e.err() == CL_INVALID_BUFFER_SIZE;
        throw DeviceError(std::string(noMemory ? "out of device memory: " : "") + "allocating " + mib(bytes) +
                          " for " + std::string(what) + " on " + listing_.name + " failed: " + clErrorName(e.err()));
    }
}

cl::Buffer Device::readOnlyOver(std::string_view what, std::size_t bytes, const void* host,
                                std::shared_ptr<const void> owner, bool* inPlace)
{
    const std::size_t align = listing_.baseAddressAlignment;
    const bool shareable = listing_.hostUnifiedMemory && owner && host && bytes > 0 && align > 0 &&
                           reinterpret_cast<std::uintptr_t>(host) % align == 0 && bytes <= listing_.maxAllocBytes &&
                           bytes <= listing_.globalMemBytes;
    if (inPlace)
        *inPlace = false;
    if (shareable) {
        cl_int err = CL_SUCCESS;
        cl_mem mem = clCreateBuffer(context_(), CL_MEM_READ_ONLY | CL_MEM_USE_HOST_PTR, bytes, const_cast<void*>(host),
                                    &err);
        if (err == CL_SUCCESS) {
            cl::Buffer buffer(mem);  // takes the reference
            if (countBuffer(buffer, bytes, memory_, std::move(owner))) {
                if (inPlace)
                    *inPlace = true;
                return buffer;
            }
            // No callback to keep `owner` alive: copy instead (the fallback below).
        }
    }
    return buffer(what, bytes, CL_MEM_READ_ONLY | CL_MEM_COPY_HOST_PTR, host);
}

}  // namespace clvr
