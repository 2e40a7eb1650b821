// tests/device_test.cpp — the OpenCL host: embedded kernels with #line markers, the program cache,
// BuildError carrying the log with the real file and line, named launches, device choice; clvr_exp2.
#include "host/runtime/device.h"
#include "host/runtime/embedded_kernels.h"
#include "host/runtime/errors.h"
#include "tests/support/test_util.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <limits>
#include <memory>

namespace {

TEST(Device, EmbeddedSourcesStartWithLineMarkersAndInlineHeaders)
{
    const auto& kernels = clvr::embeddedKernels();
    const auto it = std::find_if(kernels.begin(), kernels.end(), [](const auto& k) { return k.name == "util.cl"; });
    ASSERT_NE(it, kernels.end());
    EXPECT_EQ(it->source.substr(0, 25), "#line 1 \"kernels/util.cl\"");
    // The include on line 2 is replaced by the header, then a marker back to line 3.
    EXPECT_NE(it->source.find("#line 1 \"kernels/clvr_common.h\""), std::string_view::npos);
    EXPECT_NE(it->source.find("#line 3 \"kernels/util.cl\""), std::string_view::npos);
    EXPECT_EQ(it->source.find("#include \"clvr_common.h\""), std::string_view::npos);
    // Macro line continuations and brackets survive embedding byte for byte.
    EXPECT_NE(it->source.find("#define CLVR_GUARD_1D(n) \\\n    if (get_global_id(0)"), std::string_view::npos);
}

// Device::deviceBytes counts a buffer in when it is made and out when OpenCL releases it (the last
// cl::Buffer gone); the peak keeps the most there were.
TEST(Device, CountsLiveDeviceBytesAndThePeak)
{
    clvr::Device& device = clvr::test::device();
    const std::uint64_t before = device.deviceBytes();
    {
        cl::Buffer a = device.buffer("count a", 1000);
        cl::Buffer b = device.buffer("count b", 3);  // allocated as 4 (no zero-sized buffers)
        EXPECT_EQ(device.deviceBytes(), before + 1004);
        cl::Buffer copy = a;  // the same buffer: counted once
        EXPECT_EQ(device.deviceBytes(), before + 1004);
        EXPECT_GE(device.deviceBytesPeak(), before + 1004);
    }
    device.queue().finish();
    EXPECT_EQ(device.deviceBytes(), before);
    EXPECT_GE(device.deviceBytesPeak(), before + 1004);
}

// Device::readOnlyOver: on a device whose memory is the host's (PoCL), a buffer over an aligned block is the
// block itself and keeps its owner alive after the caller drops it; an unaligned block, or a device with its own
// memory, gets a copy. Either way a kernel reads the bytes as they were.
TEST(Device, ReadOnlyOverSharesAnAlignedHostBlockAndKeepsItAlive)
{
    clvr::Device& device = clvr::test::device();
    const std::size_t n = 4096;
    std::weak_ptr<const void> watch;
    cl::Buffer buffer;
    const std::uint64_t before = device.deviceBytes();
    {
        auto block = std::shared_ptr<float>(static_cast<float*>(std::aligned_alloc(4096, n * sizeof(float))),
                                            [](float* p) { std::free(p); });
        for (std::size_t i = 0; i < n; ++i)
            block.get()[i] = static_cast<float>(i) * 0.5f;
        watch = block;
        bool inPlace = false;
        buffer = device.readOnlyOver("shared block", n * sizeof(float), block.get(), block, &inPlace);
        EXPECT_EQ(inPlace, device.listing().hostUnifiedMemory);
        EXPECT_EQ(device.deviceBytes(), before + n * sizeof(float));
    }
    EXPECT_EQ(!watch.expired(), device.listing().hostUnifiedMemory) << "the buffer holds the block where it uses it";
    const std::vector<float> back = device.download<float>(buffer, n);
    for (std::size_t i = 0; i < n; i += 97)
        ASSERT_EQ(back[i], static_cast<float>(i) * 0.5f) << i;
    buffer = cl::Buffer();
    device.queue().finish();
    EXPECT_TRUE(watch.expired()) << "released with the buffer";
    EXPECT_EQ(device.deviceBytes(), before);

    // One byte past a page-aligned address: no device's base address alignment allows it, so a copy.
    std::vector<unsigned char> bytes(8192, 7);
    const unsigned char* unaligned =
        bytes.data() + (4096 - reinterpret_cast<std::uintptr_t>(bytes.data()) % 4096) % 4096 + 1;
    auto owner = std::make_shared<int>(0);
    bool inPlace = true;
    cl::Buffer copy = device.readOnlyOver("unaligned block", 16, unaligned, owner, &inPlace);
    EXPECT_FALSE(inPlace);
    EXPECT_EQ(owner.use_count(), 1) << "a copy keeps nothing";
    EXPECT_EQ(device.download<unsigned char>(copy, 16), std::vector<unsigned char>(16, 7));
}

TEST(Device, FillKernelWritesEveryElementOfAnOddSizedBuffer)
{
    clvr::Device& device = clvr::test::device();
    const cl_uint n = 1000;  // not a multiple of 64: exercises padding and the guard
    std::vector<float> init(n + 24, -1.0f);
    cl::Buffer buffer = device.upload("test buffer", init, CL_MEM_READ_WRITE);
    cl::Kernel k = device.kernel("util.cl", "fill_float");
    k.setArg(0, buffer);
    k.setArg(1, 2.5f);
    k.setArg(2, n);
    device.launch("fill", k, n);
    const std::vector<float> out = device.download<float>(buffer, n + 24);
    for (cl_uint i = 0; i < n; ++i)
        ASSERT_EQ(out[i], 2.5f) << "element " << i;
    for (cl_uint i = n; i < n + 24; ++i)
        ASSERT_EQ(out[i], -1.0f) << "element " << i << " past the guard was written";
    const auto times = device.takePassTimes();
    ASSERT_EQ(times.size(), 1u);
    EXPECT_EQ(times[0].name, "fill");
    EXPECT_GE(times[0].ms, 0.0);
}

// kernels/clvr_common.h's clvr_exp2 (the attenuation of slice3d's samples and harc's segments) against the
// host's exp2 in double: relative error below 3e-7 on [-126, 0] (Cephes' bound is 1.7e-7), exactly 1 at
// 0, and 0 below -126 and for -infinity (2^x < 1.2e-38 there).
TEST(KernelMath, Exp2IsWithin3e7OfTheHost)
{
    clvr::Device& device = clvr::test::device();
    std::vector<float> x;
    for (int i = 0; i <= 254000; ++i)
        x.push_back(-126.0f * static_cast<float>(i) / 254000.0f);
    for (float v : {0.0f, -0.0f, -1e-30f, -1e-7f, -0.5f, -1.0f, -2.5f, -125.5f, -126.0f})
        x.push_back(v);
    const std::size_t inRange = x.size();
    for (float v : {-126.25f, -127.0f, -1000.0f, -std::numeric_limits<float>::infinity()})
        x.push_back(v);
    const cl_uint n = static_cast<cl_uint>(x.size());
    cl::Buffer in = device.upload("exp2 arguments", x);
    cl::Buffer out = device.buffer("exp2 values", x.size() * sizeof(float), CL_MEM_WRITE_ONLY);
    cl::Kernel k = device.kernel("util.cl", "exp2_values");
    k.setArg(0, out);
    k.setArg(1, in);
    k.setArg(2, n);
    device.launch("exp2", k, n);
    const std::vector<float> got = device.download<float>(out, x.size());
    double worst = 0.0;
    for (std::size_t i = 0; i < inRange; ++i) {
        const double want = std::exp2(static_cast<double>(x[i]));
        const double rel = std::abs(got[i] - want) / want;
        worst = std::max(worst, rel);
        ASSERT_LT(rel, 3e-7) << "x = " << x[i] << ": " << got[i] << " vs " << want;
    }
    std::printf("[ measured ] clvr_exp2 on [-126, 0]: max relative error %.3g\n", worst);
    EXPECT_EQ(got[inRange - 9], 1.0f);  // x = 0
    EXPECT_EQ(got[inRange - 8], 1.0f);  // x = -0
    for (std::size_t i = inRange; i < x.size(); ++i)
        EXPECT_EQ(got[i], 0.0f) << "x = " << x[i];
}

// kernels/clvr_common.h's clvr_atan2 (the longitude and polar angle of spherical's fused path) against the
// host's atan2 in double: absolute error below 5e-7 over the angles of a fine circle at radii from 1e-30 to
// 1e30, the axes and the diagonals; atan2(0, 0) = 0, atan2(0, -1) = pi, the sign of y kept.
TEST(KernelMath, Atan2IsWithin5e7OfTheHost)
{
    clvr::Device& device = clvr::test::device();
    std::vector<float> y, x;
    for (const float radius : {1e-30f, 1e-3f, 1.0f, 7.5f, 1e30f})
        for (int i = 0; i < 20000; ++i) {
            const double a = -3.141592653589793 + 2.0 * 3.141592653589793 * i / 20000.0;
            y.push_back(radius * static_cast<float>(std::sin(a)));
            x.push_back(radius * static_cast<float>(std::cos(a)));
        }
    for (const auto& [py, px] : std::vector<std::pair<float, float>>{
             {0.0f, 1.0f}, {1.0f, 0.0f}, {0.0f, -1.0f}, {-1.0f, 0.0f}, {1.0f, 1.0f}, {-1.0f, -1.0f}, {3.0f, -3.0f},
             {1e-20f, 1.0f}, {-1e-20f, -1.0f}}) {
        y.push_back(py);
        x.push_back(px);
    }
    y.push_back(0.0f);  // atan2(0, 0): 0
    x.push_back(0.0f);
    const cl_uint n = static_cast<cl_uint>(x.size());
    cl::Buffer yb = device.upload("atan2 y", y), xb = device.upload("atan2 x", x);
    cl::Buffer out = device.buffer("atan2 values", x.size() * sizeof(float), CL_MEM_WRITE_ONLY);
    cl::Kernel k = device.kernel("util.cl", "atan2_values");
    k.setArg(0, out);
    k.setArg(1, yb);
    k.setArg(2, xb);
    k.setArg(3, n);
    device.launch("atan2", k, n);
    const std::vector<float> got = device.download<float>(out, x.size());
    double worst = 0.0;
    for (std::size_t i = 0; i < x.size(); ++i) {
        const double want = std::atan2(static_cast<double>(y[i]), static_cast<double>(x[i]));
        const double e = std::abs(got[i] - want);
        worst = std::max(worst, e);
        ASSERT_LT(e, 5e-7) << "atan2(" << y[i] << ", " << x[i] << ") = " << got[i] << " vs " << want;
    }
    std::printf("[ measured ] clvr_atan2: max absolute error %.3g over %zu points\n", worst, x.size());
    EXPECT_EQ(got.back(), 0.0f);
    EXPECT_FLOAT_EQ(got[x.size() - 8], 3.14159265f);  // atan2(0, -1)
}

// A requested work-group larger than the kernel allows (CL_KERNEL_WORK_GROUP_SIZE: 4096 on PoCL, 1024 on
// rusticl, 256 to 1024 on GPUs) must not fail the launch: the group is only a hint.
TEST(Device, GroupLargerThanTheKernelAllowsStillCoversTheRange)
{
    clvr::Device& device = clvr::test::device();
    cl::Kernel k = device.kernel("util.cl", "fill2d", "kernel void fill2d(global float* x, uint w, uint h) {"
                                                      " uint i = get_global_id(0), j = get_global_id(1);"
                                                      " if (i < w && j < h) x[j * w + i] = (float)(j * w + i); }");
    const std::size_t limit = k.getWorkGroupInfo<CL_KERNEL_WORK_GROUP_SIZE>(device.device());
    const cl_uint w = 300, h = 70;
    std::vector<float> init(std::size_t(w) * h, -1.0f);
    cl::Buffer buffer = device.upload("test buffer", init, CL_MEM_READ_WRITE);
    k.setArg(0, buffer);
    k.setArg(1, w);
    k.setArg(2, h);
    const std::size_t side = 128;  // 16384 work-items per group: more than any device allows
    ASSERT_GT(side * side, limit);
    device.launch("fill2d", k, w, h, side, side);
    const std::vector<float> out = device.download<float>(buffer, init.size());
    for (std::size_t i = 0; i < out.size(); ++i)
        ASSERT_EQ(out[i], float(i)) << "element " << i;
    device.takePassTimes();
}

// The raster stage keeps a whole tile's pixels in private arrays (kernels/raster.cl, CLVR_ITEM_PIXELS):
// every element must keep its value under data-dependent indexing, whatever the array's size.
TEST(Device, LargePrivateArraysKeepEveryElement)
{
    clvr::Device& device = clvr::test::device();
    for (const int n : {16, 64, 128, 256}) {
        const std::string source = "kernel void private_array(global float4* out, global const int* order) {"
                                   " float4 c[N]; float d[N]; uint s[N];"
                                   " for (int i = 0; i < N; ++i) { c[i] = (float4)(i, -i, 2 * i, 0.5f); d[i] = 1.0f; s[i] = 0u; }"
                                   " for (int k = 0; k < N; ++k) { int l = order[k]; c[l].w += (float)l; d[l] += 1.0f; s[l] += 3u; }"
                                   " for (int i = 0; i < N; ++i) out[i] = (float4)(c[i].x, c[i].w, d[i], (float)s[i]); }";
        cl::Kernel k = device.kernel("util.cl", "private_array", source, "-DN=" + std::to_string(n));
        std::vector<cl_int> order(n);
        for (int i = 0; i < n; ++i)
            order[i] = (i * 7 + 3) % n;  // a permutation: 7 is coprime to every n here
        cl::Buffer out = device.upload("out", std::vector<cl_float4>(n), CL_MEM_READ_WRITE);
        cl::Buffer ord = device.upload("order", order, CL_MEM_READ_ONLY);
        k.setArg(0, out);
        k.setArg(1, ord);
        device.launch("private array", k, 1);
        const auto got = device.download<cl_float4>(out, n);
        for (int i = 0; i < n; ++i) {
            ASSERT_EQ(got[i].s[0], float(i)) << "N " << n << " element " << i;
            ASSERT_EQ(got[i].s[1], 0.5f + float(i)) << "N " << n << " element " << i;
            ASSERT_EQ(got[i].s[2], 2.0f) << "N " << n << " element " << i;
            ASSERT_EQ(got[i].s[3], 3.0f) << "N " << n << " element " << i;
        }
        device.takePassTimes();
    }
}

TEST(Device, UploadShorterThanTheMinimumAllocationKeepsItsBytes)
{
    // Buffers are at least 4 bytes; a 1-byte host block must be copied, not over-read (ASan
    // caught the over-read when a volume had a single empty-space brick).
    clvr::Device& device = clvr::test::device();
    for (std::size_t n = 0; n <= 5; ++n) {
        std::vector<cl_uchar> data;  // push_back: GCC 12 warns (falsely) of an overflow for n = 0 otherwise
        for (std::size_t i = 0; i < n; ++i)
            data.push_back(static_cast<cl_uchar>(200 + i));
        cl::Buffer buffer = device.upload("short block", data);
        const std::vector<cl_uchar> out = device.download<cl_uchar>(buffer, n);
        EXPECT_EQ(out, data) << n << " bytes";
    }
}

TEST(Device, ProgramCacheReturnsTheSameProgram)
{
    clvr::Device& device = clvr::test::device();
    const std::string source = "kernel void twice(global float* x) { x[get_global_id(0)] *= 2.0f; }";
    cl::Program a = device.program("cache test", source, std::string(clvr::kBuildOptions));
    const double after = device.compileMs();
    cl::Program b = device.program("cache test", source, std::string(clvr::kBuildOptions));
    EXPECT_EQ(a(), b());
    EXPECT_EQ(device.compileMs(), after) << "a cache hit must not build again";
    cl::Program c = device.program("cache test", source, std::string(clvr::kBuildOptions) + " -DX=1");
    EXPECT_NE(a(), c()) << "other options are another program";
}

TEST(Device, BuildFailureCarriesTheLogWithFileAndLine)
{
    clvr::Device& device = clvr::test::device();
    const std::string source = "#line 1 \"kernels/broken.cl\"\nkernel void broken(global float* x)\n{\n    x[0] = z;\n}\n";
    try {
        device.program("kernels/broken.cl", source, std::string(clvr::kBuildOptions));
        FAIL() << "a kernel using an undeclared identifier built";
    } catch (const clvr::BuildError& e) {
        EXPECT_NE(std::string(e.what()).find("kernels/broken.cl"), std::string::npos) << e.what();
        EXPECT_NE(std::string(e.what()).find("-cl-std=CL1.2"), std::string::npos) << e.what();
        EXPECT_NE(e.log.find("kernels/broken.cl:3"), std::string::npos) << e.log;
        EXPECT_NE(e.log.find("'z'"), std::string::npos) << e.log;
    }
}

TEST(Device, CompilerPositionsInTheWholeSourceAreMappedToFileAndLine)
{
    // NVIDIA's OpenCL compiler ignores #line and names positions "<kernel>:LINE:COLUMN" of the whole
    // submitted source (seen on an H200, driver 580.159.04); the log must still name the file and line.
    const std::string source = "#line 1 \"kernels/a.cl\"\n"  // raw 1
                               "float f(void);\n"              // raw 2 = a.cl:1
                               "#line 1 \"kernels/b.h\"\n"   // raw 3
                               "float g(void);\n"              // raw 4 = b.h:1
                               "float h(void);\n"              // raw 5 = b.h:2
                               "#line 3 \"kernels/a.cl\"\n"  // raw 6
                               "kernel void k(void)\n"         // raw 7 = a.cl:3
                               "#line 40\n"                    // raw 8: same file
                               "{ x = 1; }\n";                 // raw 9 = a.cl:40
    EXPECT_EQ(clvr::mapSourcePositions(source, "<kernel>:4:7: error: one\n<kernel>:9:3: error: two\n"),
              "kernels/b.h:1:7: error: one\nkernels/a.cl:40:3: error: two\n");
    EXPECT_EQ(clvr::mapSourcePositions(source, "<kernel>:5: warning\n<kernel>:7:1"),
              "kernels/b.h:2: warning\nkernels/a.cl:3:1");
    // Already named by file (PoCL, Mesa), beyond the source, or before any marker: unchanged.
    EXPECT_EQ(clvr::mapSourcePositions(source, "kernels/a.cl:40:3: error: x\n<kernel>:99:1: y"),
              "kernels/a.cl:40:3: error: x\n<kernel>:99:1: y");
    EXPECT_EQ(clvr::mapSourcePositions("float f;\n", "<kernel>:1:1: e"), "<kernel>:1:1: e");
    EXPECT_EQ(clvr::mapSourcePositions(source, ""), "");
}

TEST(Device, FragmentProgramIsAppendedAndCachedSeparately)
{
    clvr::Device& device = clvr::test::device();
    // util.cl declares nothing for it, so a self-contained extra kernel must work.
    cl::Kernel k = device.kernel("util.cl", "extra", "kernel void extra(global float* x) { x[0] = 7.0f; }");
    std::vector<float> v(1, 0.0f);
    cl::Buffer b = device.upload("x", v, CL_MEM_READ_WRITE);
    k.setArg(0, b);
    device.launch("extra", k, 1);
    EXPECT_EQ(device.download<float>(b, 1)[0], 7.0f);
    device.takePassTimes();
    EXPECT_THROW(device.kernel("util.cl", "extra"), clvr::DeviceError) << "without the fragment program there is no kernel 'extra'";
}

TEST(Device, ChoiceByIndexNameAndBadSpec)
{
    const auto all = clvr::listDevices();
    ASSERT_FALSE(all.empty());
    EXPECT_EQ(clvr::chooseDevice("0").name, all[0].name);
    EXPECT_EQ(clvr::chooseDevice(all[0].name.substr(0, 4)).name, all[0].name);
    EXPECT_THROW(clvr::chooseDevice("no-such-device-xyz"), clvr::DeviceError);
    EXPECT_THROW(clvr::chooseDevice("99"), clvr::DeviceError);
    EXPECT_THROW(clvr::chooseDevice("99999999999999999999999"), clvr::DeviceError);  // no overflow
    // A device type picks the first device of that type (case-insensitive), or names the type it lacks.
    for (const char* type : {"cpu", "GPU", "accelerator"}) {
        const std::string want = type == std::string("cpu") ? "CPU" : type == std::string("GPU") ? "GPU" : "accelerator";
        const auto first = std::find_if(all.begin(), all.end(), [&](const auto& d) { return d.type == want; });
        if (first != all.end()) {
            EXPECT_EQ(clvr::chooseDevice(type).name, first->name) << type;
        } else {
            try {
                clvr::chooseDevice(type);
                ADD_FAILURE() << "no error for " << type;
            } catch (const clvr::DeviceError& e) {
                EXPECT_NE(std::string(e.what()).find("no OpenCL device of type"), std::string::npos) << e.what();
            }
        }
    }
}

TEST(Device, OversizedBufferIsAClearDeviceError)
{
    clvr::Device& device = clvr::test::device();
    const std::size_t huge = static_cast<std::size_t>(device.listing().globalMemBytes) * 4;
    try {
        device.buffer("huge volume", huge);
        FAIL() << "allocating 4x the device memory succeeded";
    } catch (const clvr::DeviceError& e) {
        EXPECT_NE(std::string(e.what()).find("out of device memory"), std::string::npos) << e.what();
        EXPECT_NE(std::string(e.what()).find("huge volume"), std::string::npos) << e.what();
    }
}

TEST(Device, ErrorNamesAreSymbolic)
{
    EXPECT_EQ(clvr::clErrorName(-5), "CL_OUT_OF_RESOURCES");
    EXPECT_EQ(clvr::clErrorName(-11), "CL_BUILD_PROGRAM_FAILURE");
    EXPECT_EQ(clvr::clErrorName(-12345), "CL error -12345");
}

}  // namespace
