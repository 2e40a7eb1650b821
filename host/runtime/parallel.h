// host/runtime/parallel.h — the process-wide thread budget and running one worker function on several host
// threads (CPU references, harc's face sort, the ceiling loop, the renderers' per-frame host loops).
#pragma once

#include <algorithm>
#include <atomic>
#include <cstddef>
#include <cstdint>
#include <functional>
#include <string>

namespace clvr {

// The most host threads any parallel loop of the library uses: setThreadBudget's value, else one per
// hardware thread. Process-wide, like the CPU itself; read by runOnThreads.
int threadBudget();

// Sets the budget (>= 1, else InputError). clvr sets it from --threads or $CLVR_THREADS before any
// OpenCL call, together with passThreadBudgetToPocl().
void setThreadBudget(int threads);

// A thread count as the user wrote it (`what` names where: "--threads", "CLVR_THREADS"): a whole
// number in 1..4096, else InputError "<what>: ...".
int parseThreadCount(const std::string& text, const std::string& what);

// Sets PoCL's CPU compute-unit count (POCL_MAX_PTHREAD_COUNT, read by PoCL 3.1, and POCL_CPU_MAX_CU_NUM,
// its later name; read once when PoCL's platform initialises) to threadBudget(), unless the environment
// already has either; returns whether it did. Only effective before the first OpenCL call of the process.
// docs/cli.md says what was measured.
bool passThreadBudgetToPocl();

// The number of threads runOnThreads(threads, maxUseful, ...) runs its worker on.
int threadsToUse(int threads, int maxUseful);

// Runs `worker` on `threads` threads (<= 0: the thread budget), at most the budget, at most
// `maxUseful` of them and at least one, the calling thread included; returns when all have returned.
// Workers share their work through their own means (an atomic row counter, say). Returns the number
// of threads it used.
int runOnThreads(int threads, int maxUseful, const std::function<void()>& worker);

// Loops over n items in chunks of `chunk` taken from a shared counter (the per-frame host loops over points,
// cells, faces and cubes): hostChunkThreads is the threads worth it for n items (the thread budget, one per chunk
// at most), and forHostChunks runs work(begin, end) for every chunk on that many; begin / chunk numbers the
// chunk, for loops that keep their outputs in order.
inline constexpr std::size_t kHostChunk = 8192;
inline int hostChunkThreads(std::size_t n, std::size_t chunk = kHostChunk)
{
    return threadsToUse(0, static_cast<int>(n / chunk + 1));
}
template <typename Work>
void forHostChunks(int threads, std::size_t n, const Work& work, std::size_t chunk = kHostChunk)
{
    std::atomic<std::size_t> next{0};
    runOnThreads(threads, threads, [&] {
        for (std::size_t begin; (begin = next.fetch_add(chunk)) < n;)
            work(begin, std::min(begin + chunk, n));
    });
}

// A reusable barrier for a fixed number of threads that yields a short while before it sleeps, for
// phases of a hundred microseconds or so (projtet's sort waves), where std::barrier's futex wake-up
// costs about as much as the phase itself (measured: docs/projtet.md).
class PhaseBarrier {
public:
    explicit PhaseBarrier(int threads) : threads_(threads) {}
    // Returns once all `threads` threads have called it for this phase.
    void arriveAndWait();

private:
    const int threads_;
    std::atomic<int> arrived_{0};
    std::atomic<std::uint32_t> phase_{0};
};

}  // namespace clvr
