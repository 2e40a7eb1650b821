// host/runtime/parallel.h — running one worker function on several host threads (CPU references, ceiling loop).
#pragma once

#include <functional>

namespace clvr {

// Runs `worker` on `threads` threads (<= 0: one per hardware thread), at most `maxUseful` of them and at
// least one, the calling thread included; returns when all have returned. Workers share their work
// through their own means (an atomic row counter, say).
void runOnThreads(int threads, int maxUseful, const std::function<void()>& worker);

}  // namespace clvr
