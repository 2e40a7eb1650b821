// tools/bench_raster.h — `clvr bench --suite raster`: the raster stage on many small triangles
// (docs/raster.md, "Speed"): 100,000 triangles of 1–20 pixels in one draw, in 1,000 draws and, where
// the raster stage has batches, as one batch of 1,000 draws.
#pragma once

#include "tools/bench.h"

namespace clvr::tools {

// Runs the raster suite on options.deviceSpec, prints a table, writes options.outJson; returns 0.
int benchRaster(const BenchOptions& options);

}  // namespace clvr::tools
