// host/render/renderer.h — what every technique provides: set up once (upload data, build kernels),
// then render frames. The tool and the benchmarks drive techniques only through this interface.
#pragma once

#include "host/runtime/device.h"
#include "host/model/image.h"
#include "host/model/mesh.h"
#include "host/model/scene.h"
#include "host/model/volume.h"

#include <nlohmann/json.hpp>

#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <vector>

namespace clvr {

// What one frame did, for --stats and clvr bench (DESIGN.md lists the required keys).
struct FrameStats {
    std::vector<PassTime> passes;  // device time per named launch
    double frameMs = 0.0;          // wall time of the frame, host to host
    std::uint64_t samples = 0;     // volume samples taken (regular grids)
    nlohmann::json extra = nlohmann::json::object();  // technique-specific counts
};

class Renderer {
public:
    virtual ~Renderer() = default;
    // Renders one frame of the scene given at creation: the final image I + (1 - A)*background,
    // alpha = A. Blocks until done.
    virtual Image4f render(FrameStats& stats) = 0;
    // Bytes resident on the device for the data (volume, tables), not counting the frame buffer.
    virtual std::uint64_t residentBytes() const = 0;
    // Replaces the transfer function for the following frames (an interactive editor's edit). Only what
    // depends on it is rebuilt — the packed control points, and tables derived from them — never the
    // volume or the mesh on the device. The result is the same image a new renderer would give.
    virtual void setTransferFunction(const TransferFunction& tf) = 0;
    // Points the following frames at scene.camera and scene.image (the rest of `scene` as at creation),
    // keeping what does not depend on the view — the data on the device, bricks, tables, kernels — and
    // gives the same image a new renderer would. False where the technique cannot (the default, or a
    // different image size): the caller then makes a new renderer (Session::setView does).
    virtual bool setCamera(const Scene& scene)
    {
        (void)scene;
        return false;
    }
};

// The technique registry (host/render/renderer.cpp): every technique by name, with the data it
// renders, one line about it and its options. `clvr techniques`, the factories below and the option
// parsers' "unknown option" errors all read it; no other code names a technique.
enum class DataKind { Volume, Mesh };

const char* dataKindName(DataKind kind);  // "volume" or "mesh", the scene key the technique needs

// One technique option as `clvr techniques` lists it.
struct OptionInfo {
    std::string name;
    // What leaving the option out means, as a value the option accepts (the image is then the same,
    // bit for bit; tests/renderer_test.cpp). Null where no value says it: defaultText says what happens.
    nlohmann::json defaultValue;
    std::string defaultText;  // only where defaultValue is null: "derived from slices", "none", ...
    std::string description;  // one line
};

struct TechniqueInfo {
    std::string name;
    DataKind data = DataKind::Volume;
    std::string description;  // one line
    std::vector<OptionInfo> options;
    // Renders a part of a larger data set (Volume::part, TetMesh::part) so that the parts' images
    // composited in visibility order give the whole one: sort-last cluster rendering (docs/cluster.md).
    bool sortLast = false;
    // Layers of grid points a volume part needs beyond its own (host/cluster/partition.h cutGridPart):
    // 1 for techniques whose per-point values (Sobel gradients) look at the neighbours.
    int sortLastGhost = 0;
    // The factory for the technique's data kind (the other one is empty).
    std::function<std::unique_ptr<Renderer>(Device&, const Scene&, const Volume&)> makeForVolume;
    std::function<std::unique_ptr<Renderer>(Device&, const Scene&, const TetMesh&)> makeForMesh;

    const OptionInfo* option(const std::string& key) const;
    std::string optionList() const;  // "slices, slice_spacing, ..." in registry order
};

// Every technique, in the order `clvr techniques` and error messages list them.
const std::vector<TechniqueInfo>& techniques();

// The technique named `name`; nullptr when there is none.
const TechniqueInfo* findTechnique(const std::string& name);

// The technique named `name`; InternalError when there is none (a renderer asking for its own entry).
const TechniqueInfo& technique(const std::string& name);

// The technique the scene names, set up on `device` for `volume`. Throws InputError for an
// unknown technique (listing the known ones) or an unknown or invalid option.
std::unique_ptr<Renderer> makeRenderer(Device& device, const Scene& scene, const Volume& volume);

// The mesh technique the scene names (DataKind::Mesh), set up on `device` for `mesh` (checked by checkMesh;
// its adjacency is built here). Throws InputError as makeRenderer does.
std::unique_ptr<Renderer> makeMeshRenderer(Device& device, const Scene& scene, const TetMesh& mesh);

// Technique names, in registry order.
std::vector<std::string> techniqueNames();

}  // namespace clvr
