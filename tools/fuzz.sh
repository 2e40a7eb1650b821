#!/usr/bin/env bash
# tools/fuzz.sh — builds the libFuzzer targets (build-fuzz/, -DCLVR_FUZZ=ON, clang) and fuzzes each one in
# turn on a copy of its seed corpus (plus fuzz/regressions/<target>), then prints per target the executions,
# exec/s, coverage and what was found. Fails on any crash, leak, timeout or out-of-memory.
#   tools/fuzz.sh [seconds-per-target] [target ...]     (default 60 s, every target; docs/robustness.md)
# Environment: JOBS (parallel build jobs, default: number of cores), FUZZ_WORK (where the corpus copies,
# logs and crash artifacts go, default build-fuzz/fuzz-run), FUZZ_RUNS (also stop a target after this many
# executions, libFuzzer's -runs; default: time only). Run it with `nice -n 19` on a shared machine.
set -euo pipefail
cd "$(dirname "$0")/.."
seconds="${1:-60}"
shift || true
jobs="${JOBS:-$(nproc)}"
work="${FUZZ_WORK:-build-fuzz/fuzz-run}"

compilers=()  # only on the first configure: a changed compiler makes CMake drop the whole cache, CLVR_FUZZ too
[ -f build-fuzz/CMakeCache.txt ] || compilers=(-DCMAKE_C_COMPILER=clang -DCMAKE_CXX_COMPILER=clang++)
cmake -S . -B build-fuzz -DCLVR_FUZZ=ON "${compilers[@]}" >/dev/null
cmake --build build-fuzz -j "$jobs"

targets=("$@")
if ((${#targets[@]} == 0)); then  # every fuzz/<target>.cpp
    for f in fuzz/*.cpp; do
        targets+=("$(basename "$f" .cpp)")
    done
fi

# VTK's own leaks (fuzz/lsan.supp names each); clvr's are still reported.
export LSAN_OPTIONS="suppressions=$PWD/fuzz/lsan.supp:print_suppressions=0${LSAN_OPTIONS:+:$LSAN_OPTIONS}"
failed=()
printf '%-18s %12s %8s %6s %6s %6s  %s\n' target executions exec/s cov ft corpus result
for t in "${targets[@]}"; do
    dir="$work/$t"
    rm -rf "$dir"
    mkdir -p "$dir"
    cp -r "fuzz/corpus/$t" "$dir/corpus"
    inputs=("$dir/corpus")
    [ -d "fuzz/regressions/$t" ] && inputs+=("fuzz/regressions/$t")
    dict=()
    [ -f "fuzz/$t.dict" ] && dict=(-dict="fuzz/$t.dict")
    runs=()
    [ -n "${FUZZ_RUNS:-}" ] && runs=(-runs="$FUZZ_RUNS")
    rc=0
    "build-fuzz/fuzz/fuzz_$t" -rss_limit_mb=2048 -malloc_limit_mb=2048 -max_len=4096 -timeout=10 \
        -max_total_time="$seconds" "${runs[@]}" -print_final_stats=1 -artifact_prefix="$dir/" "${dict[@]}" "${inputs[@]}" \
        >"$dir/log" 2>&1 || rc=$?
    stat() { sed -n "s/^stat::$1: *//p" "$dir/log" | tail -1; }
    done_line=$(grep -E '^#[0-9]+[[:space:]]+(DONE|pulse|NEW|REDUCE|INITED)' "$dir/log" | tail -1)
    cov=$(sed -n 's/.* cov: \([0-9]*\).*/\1/p' <<<"$done_line")
    ft=$(sed -n 's/.* ft: \([0-9]*\).*/\1/p' <<<"$done_line")
    corpus=$(sed -n 's/.* corp: \([0-9]*\).*/\1/p' <<<"$done_line")
    result=ok
    if ((rc != 0)); then
        result="FAILED (exit $rc): $(grep -m1 -E '^==[0-9]+==ERROR|^SUMMARY|ERROR: libFuzzer|runtime error' "$dir/log" || true)"
        result+=" artifact: $(ls "$dir"/{crash,leak,timeout,oom,slow-unit}-* 2>/dev/null | head -1 || true) log: $dir/log"
        failed+=("$t")
    fi
    printf '%-18s %12s %8s %6s %6s %6s  %s\n' "$t" "$(stat number_of_executed_units)" \
        "$(stat average_exec_per_sec)" "${cov:-?}" "${ft:-?}" "${corpus:-?}" "$result"
done
if ((${#failed[@]})); then
    echo "fuzz: failed: ${failed[*]}" >&2
    exit 1
fi
