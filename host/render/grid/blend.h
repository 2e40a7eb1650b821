// host/render/grid/blend.h — the Blend method of seeds/004_35d3c76e603b55b1.txt (§3.2): resample-then-shade
// with view-aligned slices blended back to front. The same RGBA volume (host/optics/gradient_volume.h, float32)
// and reflectance map (host/optics/reflectance_map.h) as planes; slices planned as slice3d's (planSlices); no early
// ray termination (back to front cannot stop), samples at or under the opacity threshold are not shaded.
// docs/planes.md.
#pragma once

#include "host/render/renderer.h"

#include <nlohmann/json.hpp>

namespace clvr {

struct BlendOptions {
    int slices = 256;               // slices across the box's eye-depth range ...
    double sliceSpacing = 0.0;      // ... or, when > 0, this spacing in world units
    double opacityThreshold = 0.0;  // samples with alpha <= this are written clear (not shaded)
    int reflectanceMapSize = 128;   // n: 6 n^2 shades
};

// Reads the scene's "options" for blend (slices, slice_spacing, opacity_threshold,
// reflectance_map_size). Throws InputError naming the key for unknown keys, wrong types, values out of
// range, and slices given together with slice_spacing.
BlendOptions parseBlendOptions(const nlohmann::json& options);

// Renderer for "blend"; shaded when the scene has "lights". Throws as makePlanesRenderer does.
std::unique_ptr<Renderer> makeBlendRenderer(Device& device, const Scene& scene, const Volume& volume);

}  // namespace clvr
