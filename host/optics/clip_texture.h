// host/optics/clip_texture.h — clipping with a second "stencil" texture (seeds/003_e49ee09fcdafadac.txt,
// "Clipping with arbitrary clipping geometry": a second texture decides which samples are drawn, and
// the clip volume is moved by adapting its texture coordinates). The texture is a voxel mask read from
// a volume file, or an analytic sphere, box or cylinder made into a signed-distance texture. slice3d
// samples it per sample (fused kernel) or per fragment (raster path) and draws only where it says
// inside (or outside, inverse). For the CPU reference: the exact ray/shape intervals, and the
// texture's own inside/outside crossings along a ray found finely. docs/slice3d.md, "Clip textures".
#pragma once

#include "host/model/camera.h"
#include "raster/texture.h"

#include <glm/glm.hpp>
#include <nlohmann/json_fwd.hpp>

#include <filesystem>
#include <string>
#include <vector>

namespace clvr {

// What a scene's options.clip_texture asks for, validated but not yet built:
//   {"shape": "sphere", "center": [x,y,z], "radius": r}
//   {"shape": "box", "min": [x,y,z], "max": [x,y,z]}
//   {"shape": "cylinder", "center": [x,y,z], "axis": [x,y,z], "radius": r, "height": h}
//   {"mask": "m.nrrd"}  (or a volume object as the scene's "volume": {"file": "m.raw", "dims": ...})
// plus "resolution" (shapes), "inverse", "offset" and "matrix" (the placement, below). World units.
struct ClipTextureSpec {
    enum class Shape { Sphere, Box, Cylinder, Mask };
    Shape shape = Shape::Sphere;
    std::string maskFile;              // Shape::Mask: the volume spec's file, for messages
    std::string maskSpec;              // Shape::Mask: the volume spec as JSON text (loadVolume reads it)
    glm::dvec3 center{0.0}, axis{0.0, 0.0, 1.0};
    glm::dvec3 min{-0.5}, max{0.5};
    double radius = 0.5, height = 1.0;
    int resolution = 64;  // shapes: texels along the texture box's longest axis
    bool inverse = false;  // false: draw the samples inside; true: those outside
    // Placement: the clip region drawn is { pivot + offset + matrix (q - pivot) : q in the region },
    // pivot = the texture box's center. Only the texture coordinates change with it.
    glm::dvec3 offset{0.0};
    glm::dmat3 matrix{1.0};
};

// Parses `spec`; `key` ("options.clip_texture") prefixes every InputError, which names the bad key.
ClipTextureSpec parseClipTextureSpec(const nlohmann::json& spec, const std::string& key);

// The stencil texture: one channel, linear filtering, negative inside. Texel (i, j, k) lies at the
// world position origin + (i, j, k) * spacing (grid-point convention, as a Volume); the region the
// texture can call inside is the box of texel centers, origin .. origin + (dims - 1) * spacing.
struct ClipTexture {
    std::string source;  // mask file or shape name, for messages and stats
    raster::TextureDesc desc;
    std::vector<float> texels;  // shapes: signed distance in world units; masks: 0.5 - value
    glm::dvec3 origin{0.0}, spacing{1.0};
    glm::dvec3 pivot{0.0};  // center of the box of texel centers
    glm::ivec3 dims() const { return {desc.width, desc.height, desc.depth}; }
};

// Makes the texture (shapes) or reads the mask (relative to baseDir; InputError for a missing or bad
// file, NaN values included, naming it).
ClipTexture makeClipTexture(const ClipTextureSpec& spec, const std::filesystem::path& baseDir);

// The `--stats` extras of a renderer with a clip texture (slice3d, stack2d): clip_texture (its source),
// clip_texture_dims, clip_texture_inverse.
void addClipTextureStats(nlohmann::json& extra, const ClipTexture& texture, const ClipTextureSpec& spec);

// World position -> normalized texture coordinates (GL's: texel i centered at (i + 0.5) / n) for the
// texture placed by offset and matrix; affine, acting on (p, 1).
glm::dmat4 clipTextureCoordinates(const ClipTexture& texture, const glm::dvec3& offset, const glm::dmat3& matrix);

// The shape's exact signed distance at p (world units, negative inside), before the placement.
double shapeSignedDistance(const ClipTextureSpec& spec, const glm::dvec3& p);

// Reference: the sub-intervals of [t0, t1] along `ray` whose points the placed shape holds (inverse:
// does not hold), exact in double (sphere and cylinder by their quadratics, box and caps by slabs).
std::vector<glm::dvec2> shapeClipIntervals(const ClipTextureSpec& spec, const Ray& ray, double t0, double t1);

// Whether the texture says inside at world point p (placed by `coordinates`): within the box of texel
// centers and the trilinear texel value < 0, in double.
bool insideClipTexture(const ClipTexture& texture, const glm::dmat4& coordinates, const glm::dvec3& p);

// Reference for any clip texture: the sub-intervals of [t0, t1] where insideClipTexture holds (inverse:
// does not), its changes found by stepping `step` world units and bisecting each change to 1e-12 of the
// chord. Features thinner than `step` along the ray can be missed; tests use a step of 1/16 texel.
std::vector<glm::dvec2> textureClipIntervals(const ClipTexture& texture, const glm::dmat4& coordinates, bool inverse,
                                             const Ray& ray, double t0, double t1, double step);

}  // namespace clvr
