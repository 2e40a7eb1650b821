#!/bin/sh
# tools/bench_raster_compare.sh — `clvr bench --suite raster` before and after in one run (BENCHMARKS.md,
# "Raster stage"). Exports BEFORE (a commit whose raster stage has only raster::draw, e.g. main before
# issue 9's raster part), overlays tools/bench_raster.{h,cpp} and the two-line hooks of this tree, builds
# its `clvr` in $WORK/before, then runs that binary and AFTER_BIN back to back on the same PoCL cache.
# usage: tools/bench_raster_compare.sh BEFORE_COMMIT [AFTER_BIN=build/clvr] [WORK=build/raster-compare]
set -eu
before=$1
after_bin=${2:-build/clvr}
work=${3:-build/raster-compare}
repo=$(cd "$(dirname "$0")/.." && pwd)
mkdir -p "$work/src"
work=$(cd "$work" && pwd)
git -C "$repo" archive "$before" | tar -x -C "$work/src"
cp "$repo/tools/bench_raster.h" "$repo/tools/bench_raster.cpp" "$repo/tools/bench_machine.h" "$work/src/tools/"
# The hooks: `--suite raster` in tools/commands.cpp and its dispatch in tools/bench.cpp.
grep -q bench_raster.h "$work/src/tools/bench.cpp" || sed -i \
  -e 's|#include "tools/bench_mesh.h"|#include "tools/bench_mesh.h"\n#include "tools/bench_raster.h"|' \
  -e '/^int bench(const BenchOptions& options)$/{n;s|^{$|{\n    if (options.suite == "raster" \&\& options.scenes.empty())\n        return benchRaster(options);|}' \
  "$work/src/tools/bench.cpp"
sed -i 's|"regular", "all"})|"regular", "all", "raster"})|' "$work/src/tools/commands.cpp"
cmake -S "$work/src" -B "$work/before" -DCMAKE_BUILD_TYPE=Release > "$work/cmake.log"
cmake --build "$work/before" -j2 --target clvr > "$work/build.log"
export POCL_CACHE_DIR="${POCL_CACHE_DIR:-$work/pocl-cache}"
"$work/before/clvr" bench --suite raster -o "$work/before.json"
"$after_bin" bench --suite raster -o "$work/after.json"
