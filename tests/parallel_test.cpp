// tests/parallel_test.cpp — the thread budget of host/runtime/parallel.h: runOnThreads keeps to it, results do not
// depend on it, and bad values are InputErrors.
#include "host/runtime/parallel.h"

#include "host/runtime/errors.h"
#include "host/io/generators.h"
#include "host/optics/gradient_volume.h"

#include <gtest/gtest.h>

#include <atomic>
#include <cstring>
#include <mutex>
#include <set>
#include <thread>

namespace clvr {
namespace {

// Restores the process-wide budget when a test ends, pass or fail.
class BudgetGuard {
public:
    BudgetGuard() : saved_(threadBudget()) {}
    ~BudgetGuard() { setThreadBudget(saved_); }

private:
    int saved_;
};

TEST(ThreadBudget, OneMakesRunOnThreadsUseOneThreadWithIdenticalResults)
{
    const BudgetGuard guard;
    const Volume volume = generateVolume("marschner-lobb", {24, 20, 18});

    setThreadBudget(2);
    const std::vector<glm::vec4> two = sobelGradientVolume(volume);
    setThreadBudget(1);
    EXPECT_EQ(threadBudget(), 1);
    std::mutex m;
    std::set<std::thread::id> ids;
    const int used = runOnThreads(8, 100, [&] {
        const std::lock_guard lock(m);
        ids.insert(std::this_thread::get_id());
    });
    EXPECT_EQ(used, 1);
    EXPECT_EQ(ids.size(), 1u);
    EXPECT_EQ(ids.count(std::this_thread::get_id()), 1u);  // the calling thread itself
    const std::vector<glm::vec4> one = sobelGradientVolume(volume);
    ASSERT_EQ(one.size(), two.size());
    EXPECT_EQ(std::memcmp(one.data(), two.data(), one.size() * sizeof(glm::vec4)), 0);

    setThreadBudget(3);
    ids.clear();
    EXPECT_EQ(runOnThreads(0, 100, [&] {
        const std::lock_guard lock(m);
        ids.insert(std::this_thread::get_id());
    }), 3);
    EXPECT_EQ(ids.size(), 3u);
    EXPECT_EQ(runOnThreads(8, 2, [] {}), 2);  // maxUseful still bounds it
}

// Every thread sees every other thread's work of a phase after the barrier and none of the next
// phase's before it; more threads than cores (the yields, then the sleeps) included.
TEST(PhaseBarrier, SeparatesPhasesOnMoreThreadsThanCores)
{
    const BudgetGuard guard;
    setThreadBudget(5);
    constexpr int threads = 5, phases = 500;
    PhaseBarrier barrier(threads);
    std::atomic<int> done{0}, wrong{0};
    EXPECT_EQ(runOnThreads(threads, threads, [&] {
        for (int p = 0; p < phases; ++p) {
            done.fetch_add(1, std::memory_order_relaxed);
            barrier.arriveAndWait();
            if (done.load(std::memory_order_relaxed) != threads * (p + 1))
                wrong.fetch_add(1);
            barrier.arriveAndWait();
        }
    }), threads);
    EXPECT_EQ(done.load(), threads * phases);
    EXPECT_EQ(wrong.load(), 0);
    EXPECT_EQ(threadsToUse(0, 100), 5);
    EXPECT_EQ(threadsToUse(8, 3), 3);
    EXPECT_EQ(threadsToUse(8, 0), 1);
}

TEST(ThreadBudget, BadValuesAreInputErrors)
{
    const BudgetGuard guard;
    EXPECT_EQ(parseThreadCount("4", "--threads"), 4);
    for (const char* bad : {"", "0", "-1", "two", "1.5", "4 ", "99999"})
        EXPECT_THROW(parseThreadCount(bad, "--threads"), InputError) << '"' << bad << '"';
    EXPECT_THROW(setThreadBudget(0), InputError);
    try {
        parseThreadCount("x", "CLVR_THREADS");
        FAIL();
    } catch (const InputError& e) {
        EXPECT_EQ(std::string(e.what()).rfind("CLVR_THREADS: ", 0), 0u) << e.what();
    }
}

}  // namespace
}  // namespace clvr
