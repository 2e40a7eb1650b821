// host/runtime/parallel.cpp — the thread budget and runOnThreads.
#include "host/runtime/parallel.h"

#include "host/runtime/errors.h"

#include <algorithm>
#include <atomic>
#include <cstdlib>
#include <thread>
#include <vector>

namespace clvr {
namespace {

constexpr int kMaxThreads = 4096;
std::atomic<int> budget{0};  // 0: not set, one per hardware thread

}  // namespace

int threadBudget()
{
    const int set = budget.load(std::memory_order_relaxed);
    return set > 0 ? set : static_cast<int>(std::max(1u, std::thread::hardware_concurrency()));
}

void setThreadBudget(int threads)
{
    if (threads < 1 || threads > kMaxThreads)
        throw InputError("thread budget must be in 1.." + std::to_string(kMaxThreads) + ", got " +
                         std::to_string(threads));
    budget.store(threads, std::memory_order_relaxed);
}

int parseThreadCount(const std::string& text, const std::string& what)
{
    const std::string bad = what + ": want a whole number of threads in 1.." + std::to_string(kMaxThreads) +
                            ", got \"" + text + "\"";
    if (text.empty() || text.size() > 4 || !std::all_of(text.begin(), text.end(), [](unsigned char c) {
            return c >= '0' && c <= '9';
        }))
        throw InputError(bad);
    const int n = std::stoi(text);
    if (n < 1 || n > kMaxThreads)
        throw InputError(bad);
    return n;
}

bool passThreadBudgetToPocl()
{
    // PoCL 3.1's pthread device reads POCL_MAX_PTHREAD_COUNT (measured: Debian 12's PoCL ignores
    // POCL_CPU_MAX_CU_NUM); later PoCL versions read POCL_CPU_MAX_CU_NUM. Either one set by the user wins.
    if (std::getenv("POCL_CPU_MAX_CU_NUM") || std::getenv("POCL_MAX_PTHREAD_COUNT"))
        return false;
    const std::string n = std::to_string(threadBudget());
    return ::setenv("POCL_CPU_MAX_CU_NUM", n.c_str(), 0) == 0 && ::setenv("POCL_MAX_PTHREAD_COUNT", n.c_str(), 0) == 0;
}

int threadsToUse(int threads, int maxUseful)
{
    const int limit = threadBudget();
    threads = threads <= 0 ? limit : std::min(threads, limit);
    return std::clamp(threads, 1, std::max(1, maxUseful));
}

int runOnThreads(int threads, int maxUseful, const std::function<void()>& worker)
{
    threads = threadsToUse(threads, maxUseful);
    std::vector<std::thread> pool;
    for (int i = 1; i < threads; ++i)
        pool.emplace_back(worker);
    worker();
    for (std::thread& t : pool)
        t.join();
    return threads;
}

void PhaseBarrier::arriveAndWait()
{
    const std::uint32_t phase = phase_.load(std::memory_order_acquire);
    if (arrived_.fetch_add(1, std::memory_order_acq_rel) + 1 == threads_) {
        arrived_.store(0, std::memory_order_relaxed);  // before the phase moves on: the next arrivals see 0
        phase_.fetch_add(1, std::memory_order_release);
        phase_.notify_all();
        return;
    }
    // Yielding keeps the wait short when the other threads are about to arrive and gives the core away
    // when the machine has more threads than cores; after that, sleep.
    constexpr int yields = 256;
    for (int i = 0; i < yields; ++i) {
        if (phase_.load(std::memory_order_acquire) != phase)
            return;
        std::this_thread::yield();
    }
    while (phase_.load(std::memory_order_acquire) == phase)
        phase_.wait(phase, std::memory_order_acquire);
}

}  // namespace clvr
