// host/model/scene.h — a scene as DESIGN.md defines it (JSON, paths relative to the file), parsed and
// validated once: camera, image, transfer function, "iso", "lights" and "material" as typed values that
// renderers take as they are, and "volume" / "mesh" as VolumeSpec / MeshSpec (host/model/data_spec.h,
// paths resolved). Data is not loaded here: host/io's loadVolume() / loadMesh() read it. `options` stays
// JSON, checked by the technique (host/render/renderer.h's registry).
#pragma once

#include "host/model/camera.h"
#include "host/model/data_spec.h"
#include "host/model/transfer_function.h"

#include <nlohmann/json.hpp>

#include <filesystem>
#include <optional>
#include <string>
#include <vector>

namespace clvr {

struct ImageSpec {
    int width = 512;
    int height = 512;
    glm::dvec3 background{0.0};
};

// Whether two images have the same size (Renderer::setCamera takes a new view only for the size its buffers have).
inline bool sameImageSize(const ImageSpec& a, const ImageSpec& b) { return a.width == b.width && a.height == b.height; }

// The scene's "iso" (docs/scene-format.md): an iso-surface and how it is shaded.
struct IsoSpec {
    enum class Shading { Gradient, Gradientless, None };
    double value = 0.0;                   // data units
    Shading shading = Shading::Gradient;  // "gradient", "gradientless" (iso3d only) or "none"
    std::optional<glm::dvec3> light;      // unit, world space, towards the light; absent: the headlight
    double ambient = 0.1, diffuse = 0.9;  // I_a and k_d

    // The light direction a renderer uses with `camera`: "light", else the headlight -forward (from
    // the camera, so a surface facing the viewer is lit whatever the view).
    glm::dvec3 lightFor(const Camera& camera) const { return light ? *light : -camera.forward(); }
};

// "shading" as the scene writes it.
const char* shadingName(IsoSpec::Shading shading);

// One entry of the scene's "lights".
struct DirectionalLight {
    glm::dvec3 direction{0.0, 0.0, 1.0};  // unit length, world space, towards the light
    glm::dvec3 color{1.0};
};

// The scene's "material"; these defaults stand where it leaves a key out.
struct Material {
    double ambient = 0.1;
    double diffuse = 0.7;
    double specular = 0.2;
    double shininess = 20.0;
};

// "lights" and "material" together: the shading of direct volume rendering (host/optics/reflectance_map.h).
struct Lighting {
    std::vector<DirectionalLight> lights;  // empty: unshaded (the shade is 1)
    Material material;
    bool shaded() const { return !lights.empty(); }
};

struct Scene {
    std::string technique = "slice3d";
    std::filesystem::path baseDir;  // folder of the scene file: relative data paths start here
    std::optional<VolumeSpec> volume;  // "volume": a file or a generator; absent for a mesh scene
    std::optional<MeshSpec> mesh;      // "mesh" (tetrahedral techniques); absent for a volume scene
    std::optional<Camera> camera;   // absent: fit the data bounds (see fitCamera)
    ImageSpec image;
    TransferFunction transferFunction;
    nlohmann::json options = nlohmann::json::object();  // technique options, checked by the technique
    std::optional<IsoSpec> iso;  // absent: no "iso" (direct volume rendering)
    Lighting lighting;           // "lights" (none: unshaded) and "material"
    // "distribution": how `mpirun -np N clvr render` shares the work (docs/cluster.md): "sort-last",
    // "sort-first" or "frames"; empty: sort-last for one image, frames for --orbit. One process ignores it.
    std::string distribution;
};

// InputError ("WHERE: unknown distribution ...") unless `name` is sort-last, sort-first or frames.
void checkDistribution(const std::string& name, const std::string& where);

// Parses scene JSON text; `label` (the file name) prefixes every error. `unsets` are `--unset` paths
// ("camera", "options.slices") removed from the JSON first; a path that is not in the scene is an
// InputError naming it. `overrides` are `--set` arguments "path=json" applied after them, before
// validation (camera.view_angle=20, options.slices=64, image={"width":64,"height":64}). Throws
// InputError naming the key or value.
Scene parseScene(const std::string& text, const std::string& label, const std::filesystem::path& baseDir,
                 const std::vector<std::string>& overrides = {}, const std::vector<std::string>& unsets = {});

// Reads and parses a scene file. Throws InputError for a missing or unreadable file.
Scene loadScene(const std::filesystem::path& path, const std::vector<std::string>& overrides = {},
                const std::vector<std::string>& unsets = {});

// The scene embedded in the binary (data/scenes/default.json's content): a generated volume.
Scene defaultScene(const std::vector<std::string>& overrides = {}, const std::vector<std::string>& unsets = {});

// A camera looking at the box [lo, hi] from +z (as vtkRenderer::ResetCamera): the whole box in view.
Camera fitCamera(const glm::dvec3& lo, const glm::dvec3& hi, double viewAngle = 30.0);

}  // namespace clvr
