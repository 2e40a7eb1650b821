// host/reference/iso_reference.h — the CPU reference for iso-surface techniques (iso3d, docs/iso3d.md): the exact
// first hit of a pixel ray with the iso-surface of the trilinear field, in double, and its diffuse shade.
// Used by tests to judge iso3d; not a renderer.
#pragma once

#include "host/model/camera.h"
#include "host/model/image.h"
#include "host/render/grid/iso3d.h"
#include "host/model/scene.h"
#include "host/model/volume.h"

#include <optional>
#include <vector>

namespace clvr {

// The smallest t >= 0 where the trilinear field on ray.origin + t ray.direction (inside the volume's
// bounds; outside is empty) is >= iso: the entry into the box if the value there already is, else the
// first crossing. Exact up to double rounding: the ray is cut at every grid plane it crosses, on each
// piece the field is one cell's trilinear function, a cubic in t (its coefficients multiplied out), split
// at the cubic's turning points into monotone parts, which are searched in order for the first one that
// reaches iso and bisected to convergence. nullopt when the field stays below iso.
std::optional<double> firstIsoHit(const Volume& volume, const Ray& ray, double iso);

struct IsoReference {
    std::vector<double> eyeDepth;  // per pixel, row 0 at the top: eye depth of the hit, +infinity if none
    Image4d image;                 // shaded as iso3d shades, I + (1 - A) background
};

// Per pixel center (Camera::ray): firstIsoHit, its eye depth (t * dot(direction, forward)) and
// - Gradient: clamp(c (I_a + k_d <L, N>), 0, 1) per channel (the clamp of a fixed-point frame buffer),
//   N = -g/|g| with g the Sobel gradient (host/optics/gradient_volume.h) interpolated trilinearly at the hit;
// - None: the surface color c;
// alpha 1; the background with alpha 0 where there is no hit.
IsoReference isoReference(const Volume& volume, const Camera& camera, const ImageSpec& image, const IsoSurface& iso);

}  // namespace clvr
