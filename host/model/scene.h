// host/model/scene.h — a scene as DESIGN.md defines it (JSON, paths relative to the file), parsed and
// validated. Data is not loaded here: `volume` keeps its JSON for host/io/volume_io.h's loadVolume().
#pragma once

#include "host/model/camera.h"
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

struct Scene {
    std::string technique = "slice3d";
    std::filesystem::path baseDir;  // folder of the scene file: relative data paths start here
    nlohmann::json volume;          // {"file": ...} or {"generator": ...}; null when absent
    nlohmann::json mesh;            // {"file": ...}; null when absent (tetrahedral techniques)
    std::optional<Camera> camera;   // absent: fit the data bounds (see fitCamera)
    ImageSpec image;
    TransferFunction transferFunction;
    nlohmann::json options = nlohmann::json::object();  // technique options, checked by the technique
    nlohmann::json iso, lights, material;               // null when absent
};

// Parses scene JSON text; `label` (the file name) prefixes every error. `overrides` are `--set`
// arguments "path=json" applied to the JSON before validation (camera.view_angle=20,
// options.slices=64, image={"width":64,"height":64}). Throws InputError naming the key or value.
Scene parseScene(const std::string& text, const std::string& label, const std::filesystem::path& baseDir,
                 const std::vector<std::string>& overrides = {});

// Reads and parses a scene file. Throws InputError for a missing or unreadable file.
Scene loadScene(const std::filesystem::path& path, const std::vector<std::string>& overrides = {});

// The scene embedded in the binary (data/scenes/default.json's content): a generated volume.
Scene defaultScene(const std::vector<std::string>& overrides = {});

// A camera looking at the box [lo, hi] from +z (as vtkRenderer::ResetCamera): the whole box in view.
Camera fitCamera(const glm::dvec3& lo, const glm::dvec3& hi, double viewAngle = 30.0);

}  // namespace clvr
