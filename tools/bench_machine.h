// tools/bench_machine.h — what every benchmark report says about the machine and the moment: the CPU
// model, the load average (the machine is shared, so every report says how busy it was) and the UTC time.
// Shared by tools/bench.cpp and tools/bench_raster.cpp.
#pragma once

#include <ctime>
#include <fstream>
#include <string>

namespace clvr::tools {

inline std::string cpuModel()
{
    std::ifstream in("/proc/cpuinfo");
    for (std::string line; std::getline(in, line);)
        if (line.rfind("model name", 0) == 0) {
            const auto colon = line.find(':');
            return colon == std::string::npos ? line : line.substr(colon + 2);
        }
    return "unknown";
}

// /proc/loadavg's first three fields.
inline std::string loadAverage()
{
    std::ifstream in("/proc/loadavg");
    std::string a, b, c;
    in >> a >> b >> c;
    return in ? a + " " + b + " " + c : "unknown";
}

// "2026-12-02T06:19:02Z"
inline std::string utcNow()
{
    const std::time_t t = std::time(nullptr);
    std::tm tm{};
    gmtime_r(&t, &tm);
    char buf[32];
    std::strftime(buf, sizeof buf, "%Y-%m-%dT%H:%M:%SZ", &tm);
    return buf;
}

}  // namespace clvr::tools
