// host/optics/clip_mesh.h — closed triangle meshes that clip a volume (§2.1 of seeds/000_354856c7f65dc3f9.txt):
// read from .off/ASCII .stl (TetGen's tetgenio readers, as host/io/tetgen_mesher.cpp), binary .stl or .obj,
// or generated (box, sphere, cylinder); checked closed and oriented outward; and, for the CPU reference, the parts of a
// ray inside the mesh by ray parity in double. slice3d draws them into the stencil buffer
// (docs/slice3d.md, "Clipping with closed meshes").
#pragma once

#include "host/model/camera.h"

#include <glm/glm.hpp>
#include <nlohmann/json_fwd.hpp>

#include <array>
#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

namespace clvr {

// A closed, consistently oriented triangle surface: every triangle is counter-clockwise seen from
// outside (its normal (b - a) x (c - a) points out), so from any viewpoint the faces facing the eye
// are where a ray enters and the back faces where it leaves.
struct ClipMesh {
    std::string source;  // file name or generator, for messages
    std::vector<glm::dvec3> points;
    std::vector<std::array<std::uint32_t, 3>> triangles;
};

// What a scene's "mesh" (inside options.clip) asks for, validated but not yet loaded:
//   "x.off"                                   (a file, relative to the scene)
//   {"file": "x.obj", "scale": s|[sx,sy,sz], "translate": [x,y,z]}     p' = p * scale + translate
//   {"generator": "box", "min": [x,y,z], "max": [x,y,z]}
//   {"generator": "sphere", "center": [x,y,z], "radius": r, "segments": n}
//   {"generator": "cylinder", "center": [x,y,z], "axis": [x,y,z], "radius": r, "height": h, "segments": n}
struct ClipMeshSpec {
    std::string file;       // non-empty: a surface file (.off, .stl, .obj)
    std::string generator;  // else "box", "sphere" or "cylinder"
    glm::dvec3 scale{1.0}, translate{0.0};
    glm::dvec3 min{-0.5}, max{0.5};
    glm::dvec3 center{0.0}, axis{0.0, 0.0, 1.0};
    double radius = 0.5, height = 1.0;
    int segments = 32;
};

// Parses `spec`; `key` ("options.clip.mesh") prefixes every InputError, which names the bad key.
ClipMeshSpec parseClipMeshSpec(const nlohmann::json& spec, const std::string& key);

// Reads or generates the mesh (relative files from baseDir), applies the placement and closes it
// (closeClipMesh). InputError for a missing, unreadable or open surface, naming the file.
ClipMesh loadClipMesh(const ClipMeshSpec& spec, const std::filesystem::path& baseDir);

// A triangle surface as the file holds it (polygons fanned into triangles), not yet checked.
// .off and ASCII .stl through tetgenio (load_off / load_stl); binary .stl (which tetgenio does not
// read) and .obj ("v x y z", "f a b c ..." with a, a/t, a/t/n or a//n, 1-based or negative; other
// statements ignored) by clvr.
ClipMesh readSurface(const std::filesystem::path& path);

// Generated surfaces, counter-clockwise seen from outside. The sphere is a UV sphere of `segments`
// meridians and segments / 2 rings (vertices on the sphere, so it lies inside it); the cylinder has
// `segments` sides and flat caps, its axis through `center` along `axis`, `height` long.
ClipMesh boxMesh(const glm::dvec3& lo, const glm::dvec3& hi);
ClipMesh sphereMesh(const glm::dvec3& center, double radius, int segments);
ClipMesh cylinderMesh(const glm::dvec3& center, const glm::dvec3& axis, double radius, double height, int segments);

// Makes `mesh` a ClipMesh: merges points with identical coordinates (STL repeats them per triangle),
// drops triangles that use a point twice, and checks that the surface is closed and consistently
// oriented — every edge a-b is used as often from a to b as from b to a — else InputError naming an
// edge. Reverses every triangle when the enclosed (signed) volume is negative; InputError when it is 0.
// Self-intersections are not detected (they make "inside" ambiguous).
void closeClipMesh(ClipMesh& mesh);

// Signed volume enclosed by the triangles (positive when they face outward).
double signedVolume(const ClipMesh& mesh);

// The parameters t of every crossing of the line origin + t * direction with the surface, sorted.
// Watertight in double: each triangle is tested with edge functions of its points projected along the
// line (Woop, Benthin and Wald 2013), which are computed so that two triangles sharing an edge get
// exactly opposite values; a line through an edge or a point is counted once by a top-left tie rule.
std::vector<double> rayCrossings(const ClipMesh& mesh, const Ray& ray);

// The sub-intervals of [t0, t1] along `ray` whose points are inside the mesh (inverse: outside),
// in increasing order: a point is inside when the ray beyond it crosses the surface an odd number of
// times (ray parity, from rayCrossings).
std::vector<glm::dvec2> clipIntervals(const ClipMesh& mesh, const Ray& ray, double t0, double t1, bool inverse);

// Whether p is inside (ray parity along a fixed, irrational-looking direction). Tests use it.
bool insideClipMesh(const ClipMesh& mesh, const glm::dvec3& p);

}  // namespace clvr
