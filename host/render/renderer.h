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
};

// The technique the scene names, set up on `device` for `volume`. Throws InputError for an
// unknown technique (listing the known ones) or an unknown or invalid option.
std::unique_ptr<Renderer> makeRenderer(Device& device, const Scene& scene, const Volume& volume);

// The mesh technique the scene names ("harc"), set up on `device` for `mesh` (checked by checkMesh;
// its adjacency is built here). Throws InputError as makeRenderer does.
std::unique_ptr<Renderer> makeMeshRenderer(Device& device, const Scene& scene, const TetMesh& mesh);

// Technique names makeRenderer and makeMeshRenderer know, in the order `clvr render --help` lists them.
std::vector<std::string> techniqueNames();

}  // namespace clvr
