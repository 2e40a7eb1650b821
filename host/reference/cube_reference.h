// host/reference/cube_reference.h — the exact integral of the piecewise-constant cube field of seeds/002
// (Schussman & Max 2001, §6): every grid point owns the cube of one grid spacing centred on it, with the
// point's value throughout. Per pixel, the camera ray walks the cubes it crosses (a 3D DDA, in double),
// and each crossing of length l adds opacity 1 - exp(-tau l) and color C (1 - exp(-tau l)), composited
// front to back: the integral of DESIGN.md's optical model for that field, with no quadrature. The judge
// of the cubefan technique (host/render/grid/cubefan.h); not a renderer.
#pragma once

#include "host/model/camera.h"
#include "host/model/image.h"
#include "host/model/scene.h"
#include "host/model/transfer_function.h"
#include "host/model/volume.h"

namespace clvr {

// Integrates every pixel of an image.width x image.height image (row 0 at the top); the result pixel is
// rgb = I + (1 - A) background, a = A. Only the ray part in front of the camera counts (t >= 0, as
// referenceIntegral). Rows are spread over `threads` host threads (<= 0: the thread budget).
Image4d cubeFieldIntegral(const Volume& volume, const TransferFunction& tf, const Camera& camera,
                          const ImageSpec& image, int threads = 2);

}  // namespace clvr
