// host/render/grid/planes.h — the Planes method of seeds/004_35d3c76e603b55b1.txt (§3.1): resample-then-shade
// ray casting. The volume goes to the device once as an RGBA volume (Sobel gradient and value,
// host/optics/gradient_volume.h, float32: 16 bytes per grid point); each pixel's ray takes samples at a fixed
// spacing, interpolates value and gradient, classifies, shades through the reflectance map
// (host/optics/reflectance_map.h) and composites front to back with early ray termination and skipping of
// low-opacity samples. Parallel and perspective cameras. docs/planes.md.
#pragma once

#include "host/render/renderer.h"

#include <nlohmann/json.hpp>

namespace clvr {

struct PlanesOptions {
    double sampleSpacing = 0.0;      // world units between samples along a ray; 0: half the smallest grid spacing
    double earlyTermination = 0.99;  // stop a ray once its opacity A >= this; 1.0 = off
    double opacityThreshold = 0.0;   // skip (neither shade nor composite) samples with alpha <= this
    int reflectanceMapSize = 128;    // n: the map holds 6 n^2 shades
};

// Reads the scene's "options" for planes (sample_spacing, early_termination, opacity_threshold,
// reflectance_map_size). Throws InputError naming the key ("options.sample_spacing: ...") for unknown
// keys, wrong types and values out of range.
PlanesOptions parsePlanesOptions(const nlohmann::json& options);

// Renderer for "planes". Shaded when the scene has "lights" (sceneLighting), else unshaded (then it
// approximates the same integral as slice3d). The reflectance map is built at creation from the lights and
// the camera's view direction. Throws InputError for bad options, a volume over 2^32 - 1 grid points or
// rays that would need over 2^20 samples, and DeviceError when the volume does not fit on the device.
std::unique_ptr<Renderer> makePlanesRenderer(Device& device, const Scene& scene, const Volume& volume);

}  // namespace clvr
