// host/cluster/bricks.h — one process renders a volume too large for one device allocation as sort-last
// ranks render theirs (issue 37 goal 5, docs/cluster.md): the volume cut into k-d parts
// (host/cluster/partition.h), each part's renderer on the same device, their images composited "over" in
// the view's visibility order (compositeOver) and the background added last — the image of one renderer
// on the whole volume, as the N-rank image is. No MPI.
#pragma once

#include "host/model/scene.h"
#include "host/model/volume.h"
#include "host/render/renderer.h"
#include "host/runtime/device.h"
#include "host/runtime/errors.h"

#include <memory>

namespace clvr {

// Whether `error` (from setting up a renderer) says that something did not fit the device.
bool isOutOfDeviceMemory(const DeviceError& error);

// A renderer of `volume` in bricks: the technique must render a part (TechniqueInfo::sortLast). Tries 2,
// 4, 8, ... bricks until every brick's renderer fits the device (each buffer within its largest
// allocation); DeviceError "out of device memory: ..." naming the volume when even bricks of one cell per
// axis do not fit (the grid cannot be cut further). The bricks stay on the device across frames; FrameStats::extra["volume_parts"]
// says how many there are. The volume must outlive the renderer (the bricks are cut from it).
std::unique_ptr<Renderer> makeBrickedRenderer(Device& device, const Scene& scene, const Volume& volume);

}  // namespace clvr
