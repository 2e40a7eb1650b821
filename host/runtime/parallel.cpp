// host/runtime/parallel.cpp — runOnThreads.
#include "host/runtime/parallel.h"

#include <algorithm>
#include <thread>
#include <vector>

namespace clvr {

void runOnThreads(int threads, int maxUseful, const std::function<void()>& worker)
{
    if (threads <= 0)
        threads = static_cast<int>(std::thread::hardware_concurrency());
    threads = std::clamp(threads, 1, std::max(1, maxUseful));
    std::vector<std::thread> pool;
    for (int i = 1; i < threads; ++i)
        pool.emplace_back(worker);
    worker();
    for (std::thread& t : pool)
        t.join();
}

}  // namespace clvr
