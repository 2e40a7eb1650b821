// host/io/generators.h — procedural regular volumes with known values: analytic ground truth for tests
// and the scenes that need no data file. Every generator samples a function on [-1,1]^3: grid point
// (i,j,k) sits at -1 + 2*(i,j,k)/(n-1), so origin is (-1,-1,-1) and spacing 2/(n-1) per axis.
#pragma once

#include "host/model/mesh.h"
#include "host/model/volume.h"

#include <glm/glm.hpp>

#include <string>

namespace clvr {

// "marschner-lobb", "sphere", "blobs" or "atmosphere" sampled on a dims grid over [-1,1]^3.
// Throws InputError for an unknown name, a dimension < 2, or more than 2^34 grid points.
Volume generateVolume(const std::string& name, glm::ivec3 dims);

// Marschner and Lobb 1994, "An evaluation of reconstruction filters for volume rendering", Eq. 1-2:
//   rho(x,y,z) = (1 - sin(pi z/2) + alpha (1 + rho_r(sqrt(x^2+y^2)))) / (2 (1 + alpha)),
//   rho_r(r) = cos(2 pi f_M cos(pi r/2)),  f_M = 6, alpha = 0.25.
// p in [-1,1]^3; values in [0,1].
double marschnerLobb(const glm::dvec3& p);

// "sphere": 1 - |p| clamped to [0,1]: 1 at the center, 0 on and outside the unit sphere; iso-surfaces
// are spheres of radius 1 - value.
double sphereField(const glm::dvec3& p);

// "blobs": min(1, sum over four fixed Gaussians a_k exp(-|p - c_k|^2 / (2 sigma_k^2))), amplitudes a_k
// 1, 0.75, 0.5 and 0.25; values in [0,1]. Centers and widths are in generators.cpp and docs/data-formats.md.
double blobsField(const glm::dvec3& p);

// "kernel": the "glowing kernel" of seeds/000's finite-element example, for the L-block part
// (data/surfaces/l-block.poly, in [-1,1]^2 x [-1,0]): 0.1 + 0.9 exp(-|p - c|^2 / (2 0.3^2)) with c =
// (-0.5, -0.5, -0.5), the center of the L's corner cube; values in (0.1, 1].
double kernelField(const glm::dvec3& p);

// "automaton" mesh (seeds/000 §5, the binary cellular automaton): `cells` distinct cubes of a grid x grid x
// grid lattice over [-1,1]^3, picked by a fixed-seed shuffle, each split into 12 tetrahedra that share
// its center (two per face), with no vertex shared between cubes: 9 points per cube, value 1 at the
// center and 0 at the 8 corners. InputError unless 1 <= cells <= grid^3 and 1 <= grid <= 1024.
TetMesh automatonMesh(int cells, int grid);

// "atmosphere": a field meant as (phi, theta, r) data for the spherical technique (host/render/grid/spherical.h):
// with (u, v, w) = (p + 1) / 2, phi = 2 pi u, theta = pi v, a cloud layer around w = 0.55 (Gaussian, width
// 0.22) times latitude bands that meander with longitude:
//   exp(-((w - 0.55) / 0.22)^2) * (1 + cos(6 theta + 1.2 sin(theta) cos(3 phi))) / 2, in [0,1].
// Periodic in phi (u = 0 and u = 1 agree) and independent of phi at the poles (sin(theta) = 0).
double atmosphereField(const glm::dvec3& p);

}  // namespace clvr
