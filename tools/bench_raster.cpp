// tools/bench_raster.cpp — `clvr bench --suite raster` (docs/raster.md, "Speed"; BENCHMARKS.md).
// 100,000 triangles of 1–20 pixels (fixed seed, splitmix64) on a 512x512 frame buffer, blended
// SRC_ALPHA, ONE_MINUS_SRC_ALPHA (order dependent), default fragment program, drawn as one draw, as
// 1,000 draws of 100 and (with the raster stage's batches) as one batch of those 1,000 draws. A frame is
// host set-up + binning + the fragment launches until the queue is idle; median of 7 after one warm-up.
// "host cpu" is the CPU time of the calling thread during a frame (set-up, binning, enqueueing).
// The file also compiles against the raster stage before batches (raster::draw only), so that one
// script can run the same suite on main's code and on this one (BENCHMARKS.md says how).
#include "tools/bench_raster.h"

#include "tools/bench_machine.h"

#include "host/render/scaffold.h"
#include "host/runtime/device.h"
#include "raster/framebuffer.h"
#include "raster/rasterizer.h"

#include <nlohmann/json.hpp>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <ctime>
#include <time.h>
#include <filesystem>
#include <fstream>
#include <functional>
#include <iomanip>
#include <iostream>
#include <sstream>
#include <vector>

#ifndef CLVR_RASTER_BATCHES
#define CLVR_RASTER_BATCHES 0
#endif

namespace clvr::tools {
namespace {

using Clock = std::chrono::steady_clock;
constexpr int kSize = 512, kTriangles = 100000, kDraws = 1000, kFrames = 7;

// CPU time of the calling thread: the host part of a frame, which other processes on a shared machine
// delay but do not lengthen (the launch's wall time they do).
double threadCpuMs()
{
    timespec t{};
    clock_gettime(CLOCK_THREAD_CPUTIME_ID, &t);
    return 1e3 * static_cast<double>(t.tv_sec) + 1e-6 * static_cast<double>(t.tv_nsec);
}

// Triangles of area 1..20 pixels: an equilateral triangle of that area, rotated and stretched by k and
// 1/k (k in 0.5..2, area kept), centered anywhere on the frame buffer; depth and color random.
std::vector<raster::Vertex> smallTriangles()
{
    std::uint64_t state = 0x243f6a8885a308d3ull;
    auto uniform = [&state] {  // splitmix64 -> [0, 1)
        std::uint64_t z = (state += 0x9e3779b97f4a7c15ull);
        z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ull;
        z = (z ^ (z >> 27)) * 0x94d049bb133111ebull;
        return static_cast<double>((z ^ (z >> 31)) >> 11) / 9007199254740992.0;
    };
    std::vector<raster::Vertex> vertices;
    vertices.reserve(3 * kTriangles);
    for (int t = 0; t < kTriangles; ++t) {
        const double area = 1.0 + 19.0 * uniform();
        const double side = std::sqrt(4.0 * area / std::sqrt(3.0));
        const double angle = 6.283185307179586 * uniform();
        const double k = std::exp2(2.0 * uniform() - 1.0);
        const double cx = kSize * uniform(), cy = kSize * uniform();
        const glm::vec4 color(uniform(), uniform(), uniform(), 0.2 + 0.6 * uniform());
        const float z = static_cast<float>(1.8 * uniform() - 0.9);
        for (int v = 0; v < 3; ++v) {  // unit-circumradius equilateral, scaled to `side`, stretched, rotated
            const double a = 6.283185307179586 * v / 3.0;
            const double x = k * side / std::sqrt(3.0) * std::cos(a), y = side / std::sqrt(3.0) / k * std::sin(a);
            const double px = cx + std::cos(angle) * x - std::sin(angle) * y;
            const double py = cy + std::sin(angle) * x + std::cos(angle) * y;
            raster::Vertex vertex;
            vertex.position = glm::vec4(static_cast<float>(2.0 * px / kSize - 1.0),
                                        static_cast<float>(1.0 - 2.0 * py / kSize), z, 1.0f);
            vertex.attributes[0] = color;
            vertices.push_back(vertex);
        }
    }
    return vertices;
}

raster::DrawState blendedState()
{
    raster::DrawState s;
    s.fragment.blend.enabled = true;
    s.fragment.blend.srcRgb = s.fragment.blend.srcAlpha = raster::BlendFactor::SrcAlpha;
    s.fragment.blend.dstRgb = s.fragment.blend.dstAlpha = raster::BlendFactor::OneMinusSrcAlpha;
    return s;
}

// FNV-1a over the color plane's bytes: equal hashes across forms (and binaries) mean equal bits.
std::string colorHash(Device& device, raster::Framebuffer& fb)
{
    const Image4f image = fb.readColor(device);
    std::uint64_t h = 0xcbf29ce484222325ull;
    const auto* bytes = reinterpret_cast<const unsigned char*>(image.pixels().data());
    for (std::size_t i = 0; i < image.pixels().size() * sizeof(image.pixels()[0]); ++i)
        h = (h ^ bytes[i]) * 0x100000001b3ull;
    std::ostringstream out;
    out << std::hex << std::setw(16) << std::setfill('0') << h;
    return out.str();
}

struct Form {
    std::string name;  // "one draw", ...
    std::string api;   // what it calls
    int draws = 1;
    // Draws the whole frame; returns {triangles, fragments} as the raster stage reports them.
    std::function<std::pair<std::uint64_t, std::uint64_t>()> frame;
};

nlohmann::json runForm(Device& device, raster::Framebuffer& fb, const Form& form)
{
    std::vector<double> ms, deviceMs, hostCpuMs;
    std::pair<std::uint64_t, std::uint64_t> counts;
    for (int i = 0; i <= kFrames; ++i) {  // frame 0 warms up (kernel build, buffers)
        fb.clearColor(device, glm::vec4(0.0f));
        device.takePassTimes();
        const auto t0 = Clock::now();
        const double cpu0 = threadCpuMs();
        counts = form.frame();
        const double cpuMs = threadCpuMs() - cpu0;  // waits for the device (takeStats) cost next to nothing
        device.queue().finish();
        const double frameMs = msSince(t0);
        double launchMs = 0.0;
        for (const PassTime& p : device.takePassTimes())
            launchMs += p.ms;
        if (i > 0) {
            ms.push_back(frameMs);
            deviceMs.push_back(launchMs);
            hostCpuMs.push_back(cpuMs);
        }
    }
    auto median = [](std::vector<double> v) {
        std::sort(v.begin(), v.end());
        return v[v.size() / 2];
    };
    const double frameMs = median(ms);
    return {{"form", form.name},
            {"api", form.api},
            {"draws", form.draws},
            {"triangles", counts.first},
            {"fragments", counts.second},
            {"frame_ms", frameMs},
            {"frame_ms_min", *std::min_element(ms.begin(), ms.end())},
            {"frame_ms_max", *std::max_element(ms.begin(), ms.end())},
            {"launch_ms", median(deviceMs)},
            {"host_cpu_ms", median(hostCpuMs)},
            {"triangles_per_s", counts.first / (frameMs * 1e-3)},
            {"color_hash", colorHash(device, fb)}};
}

struct Input {
    std::vector<raster::Vertex> all;                 // every triangle, in order
    std::vector<std::vector<raster::Vertex>> parts;  // the same, kDraws parts of equal size
    raster::DrawState state = blendedState();
};

#if CLVR_RASTER_BATCHES
std::vector<Form> forms(Device& device, raster::Framebuffer& fb, const Input& in, raster::Rasterizer& rasterizer)
#else
std::vector<Form> forms(Device& device, raster::Framebuffer& fb, const Input& in)
#endif
{
    const auto& all = in.all;
    const auto& parts = in.parts;
    const auto& state = in.state;
    using Counts = std::pair<std::uint64_t, std::uint64_t>;
    std::vector<Form> out;
    out.push_back({"one draw", "raster::draw", 1, [&] {
                       const raster::DrawStats s = raster::draw(device, fb, state, raster::Topology::Triangles, all);
                       return Counts{s.triangles, s.fragments};
                   }});
    out.push_back({"1000 draws", "raster::draw", kDraws, [&] {
                       Counts c{0, 0};
                       for (const auto& part : parts) {
                           const raster::DrawStats s = raster::draw(device, fb, state, raster::Topology::Triangles, part);
                           c.first += s.triangles;
                           c.second += s.fragments;
                       }
                       return c;
                   }});
#if CLVR_RASTER_BATCHES
    // One Rasterizer for all frames, as a renderer keeps one: programs, buffers and counters persist.
    out.push_back({"one draw", "Rasterizer::draw", 1, [&] {
                       rasterizer.draw(fb, state, raster::Topology::Triangles, all);
                       const raster::DrawStats s = rasterizer.takeStats();
                       return Counts{s.triangles, s.fragments};
                   }});
    out.push_back({"1000 draws", "Rasterizer::draw", kDraws, [&] {
                       for (const auto& part : parts)
                           rasterizer.draw(fb, state, raster::Topology::Triangles, part);
                       const raster::DrawStats s = rasterizer.takeStats();
                       return Counts{s.triangles, s.fragments};
                   }});
    out.push_back({"1000 draws, one batch", "DrawBatch", kDraws, [&] {
                       raster::DrawBatch batch(rasterizer, fb);
                       for (const auto& part : parts)
                           batch.add(state, raster::Topology::Triangles, part);
                       batch.flush();
                       const raster::DrawStats s = rasterizer.takeStats();
                       return Counts{s.triangles, s.fragments};
                   }});
#endif
    return out;
}

}  // namespace

int benchRaster(const BenchOptions& options)
{
    Device device(options.deviceSpec);
    Input in;
    in.all = smallTriangles();
    in.parts.resize(kDraws);
    const std::size_t per = in.all.size() / kDraws;
    for (int d = 0; d < kDraws; ++d)
        in.parts[d].assign(in.all.begin() + d * per, in.all.begin() + (d + 1) * per);
    raster::Framebuffer fb(device, kSize, kSize);
#if CLVR_RASTER_BATCHES
    raster::Rasterizer rasterizer(device);
    const std::vector<Form> all = forms(device, fb, in, rasterizer);
#else
    const std::vector<Form> all = forms(device, fb, in);
#endif

    nlohmann::json report;
    report["machine"] = {{"device", device.description()}, {"date", utcNow()}, {"load_average_start", loadAverage()}};
    report["scene"] = {{"width", kSize}, {"height", kSize}, {"triangles", kTriangles}, {"triangle_pixels", "1..20"},
                       {"blend", "SRC_ALPHA, ONE_MINUS_SRC_ALPHA"}, {"frames", kFrames},
                       {"batches", CLVR_RASTER_BATCHES != 0}};
    std::cout << "raster suite: " << device.description() << ", " << utcNow() << ", load average " << loadAverage()
              << "\n" << kTriangles << " triangles of 1-20 pixels, " << kSize << "x" << kSize
              << ", blended; median of " << kFrames << " frames\n";
    std::cout << std::left << std::setw(24) << "form" << std::setw(18) << "api" << std::right << std::setw(11)
              << "frame ms" << std::setw(11) << "launch ms" << std::setw(11) << "host cpu" << std::setw(13) << "M tri/s" << std::setw(12)
              << "fragments" << "  color hash\n";
    for (const Form& form : all) {
        const nlohmann::json r = runForm(device, fb, form);
        report["forms"].push_back(r);
        std::cout << std::left << std::setw(24) << form.name << std::setw(18) << form.api << std::right << std::fixed
                  << std::setprecision(1) << std::setw(11) << r["frame_ms"].get<double>() << std::setw(11)
                  << r["launch_ms"].get<double>() << std::setw(11) << r["host_cpu_ms"].get<double>() << std::setprecision(2) << std::setw(13)
                  << r["triangles_per_s"].get<double>() * 1e-6 << std::setw(12) << r["fragments"].get<std::uint64_t>()
                  << "  " << r["color_hash"].get<std::string>() << '\n';
    }
    report["machine"]["load_average_end"] = loadAverage();
    const std::filesystem::path out = options.outJson;
    if (out.has_parent_path())
        std::filesystem::create_directories(out.parent_path());
    std::ofstream(out) << report.dump(2) << '\n';
    std::cout << "wrote " << out.string() << '\n';
    return 0;
}

}  // namespace clvr::tools
