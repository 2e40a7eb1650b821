// tools/ceiling_harc.h — the speed ceiling for harc: the per-ray walk of kernels/harc.cl's harc_render with
// partial pre-integration (exit face by the barycentric planes of the 80-byte layout, cross-multiplied; the
// segment split at the transfer function's control points, each piece by Eq. 2-4 with ψ from the same
// 512² table; the back end carried to the next cell; "over" front to back; re-entry at the next boundary
// crossing) as a plain C++ loop on std::threads over rows. It walks the same per-pixel entry lists
// (host/render/tet/harc.h buildHarcEntryLists, built once here: clvr times that stage as its own host pass)
// and the same packed cells, so `clvr bench` can set the ceiling's walk beside the kernel's
// ("harc: walk" pass) with the same steps and pieces. Not part of the library; tests/bench_test.cpp checks
// its image against clvr's harc and its counts against the kernel's.
#pragma once

#include "host/model/camera.h"
#include "host/model/image.h"
#include "host/model/mesh.h"
#include "host/model/scene.h"
#include "host/model/transfer_function.h"
#include "host/optics/preintegration_table.h"
#include "host/optics/psi_table.h"
#include "host/render/tet/harc.h"
#include "kernels/ray.h"
#include "tools/ceiling_segment.h"

#include <glm/glm.hpp>

#include <cstdint>
#include <optional>
#include <vector>

namespace clvr::tools {

struct HarcCeilingResult {
    Image4f image;              // I + T background, alpha = 1 - T
    std::uint64_t steps = 0;    // cells entered (harc's stats "steps")
    std::uint64_t pieces = 0;   // integrated pieces (harc's "pieces")
};

class HarcCeiling {
public:
    // The mesh as harc renders it (checkMesh()'d, with its topology), the camera it uses (Session::camera),
    // the image size and background, and harc's options (any integration — partial, full, average, tetslice's
// slices (tetsliceWalkOptions), tetiso's first crossing (tetisoWalkOptions) —, no part box: harcCeilingFits).
    HarcCeiling(const TetMesh& mesh, const TetTopology& topology, const TransferFunction& tf, const Camera& camera,
                const ImageSpec& image, const HarcOptions& options);
    // Walks every pixel with `threads` threads taking rows from a shared counter (<= 0: the thread budget).
    HarcCeilingResult render(int threads = 0) const;

private:
    struct Counts {
        std::uint64_t steps = 0, pieces = 0;
    };
    void renderRow(int y, Image4f& image, Counts& counts) const;

    int width_, height_;
    glm::vec3 background_;
    ClCamera camera_{};
    std::uint32_t maxSteps_;
    float ertAlpha_;
    std::vector<glm::vec4> tets_;       // packHarcTets: 5 per tetrahedron
    HarcEntryLists lists_;
    CeilingSegments segments_;          // the transfer function and ψ, kernels/segment_integral.h's functions
    HarcOptions::Integration integration_;
    std::optional<PreintegrationTable> full_;  // Integration::Full: the table harc builds
    bool slices_ = false;  // tetslice's fused path (Integration::Slices): the slices, not the pieces
    float sliceDepth0_ = 0.0f, sliceSpacing_ = 1.0f;
    int sliceCount_ = 0;
    bool iso_ = false;     // tetiso's fused path (Integration::Iso): the first crossing, shaded; pieces = hits
    float isoValue_ = 0.0f, isoAmbient_ = 0.0f, isoDiffuse_ = 0.0f;
    bool isoShaded_ = true, isoEqualWeights_ = false;
    glm::vec3 isoLight_{0.0f}, isoColor_{1.0f};
    std::vector<glm::vec4> isoNormals_;  // 3 per cell in harc's order: the x, y, z of its vertex normals
};

// Whether the ceiling mirrors the kernel's walk of this mesh: a whole mesh, any integration (not a sort-last part,
// whose box the kernel also cuts segments to).
bool harcCeilingFits(const TetMesh& mesh);

}  // namespace clvr::tools
