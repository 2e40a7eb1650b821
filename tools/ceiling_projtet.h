// tools/ceiling_projtet.h — the speed ceiling for projtet: its frame's projection and draw (host/render/tet/projtet.h:
// the cells' points projected, and per cell in visibility order every pixel its silhouette covers, each running
// kernels/projtet.cl's fragment — the pixel's own ray against the cell's four planes, the segment (s_f, s_b, l)
// integrated by kernels/segment_integral.h's pieces — blended ONE, ONE_MINUS_SRC_ALPHA, then the background) as
// a plain C++ loop on std::threads. Coverage is each cell's pixel box (projtetCellBoxes, the fused path's), the
// exact ray–cell test deciding (what the fragment program decides inside the grown silhouette the raster stage
// draws). The threads own interleaved blocks
// of rows and each walks every cell in the same order, so each pixel's segments blend in that order. The cells are
// sorted once, by the renderer's VisibilitySorter (a host pass clvr times on its own). Not part of the library;
// tests/bench_test.cpp checks its image and its segments against clvr's projtet.
#pragma once

#include "host/model/camera.h"
#include "host/model/image.h"
#include "host/model/mesh.h"
#include "host/model/scene.h"
#include "host/model/transfer_function.h"
#include "host/render/tet/projtet.h"
#include "kernels/ray.h"
#include "tools/ceiling_segment.h"

#include <glm/glm.hpp>

#include <cstdint>
#include <vector>

namespace clvr::tools {

struct ProjtetCeilingResult {
    Image4f image;                  // I + (1 - A) background, alpha = A
    std::uint64_t pixelsTested = 0;  // pixels of the cells' boxes whose ray was tested against the cell
    std::uint64_t segments = 0;     // of them, rays that meet the cell (l > 0): the segments integrated
};

class ProjtetCeiling {
public:
    // The mesh as projtet renders it (checkMesh()'d, with its topology), the camera it uses (Session::camera), the
    // image size and background, and projtet's options (the visibility order).
    ProjtetCeiling(const TetMesh& mesh, const TetTopology& topology, const TransferFunction& tf, const Camera& camera,
                   const ImageSpec& image, const ProjtetOptions& options);
    // One frame with `threads` threads (<= 0: the thread budget).
    ProjtetCeilingResult render(int threads = 0) const;

private:
    int width_, height_;
    glm::vec3 background_;
    Camera camera_;
    ClCamera rayCamera_{};              // the fragments' camera, relative to the mesh's box centre (as projtet's)
    std::vector<glm::dvec3> points_;
    std::vector<glm::uvec4> tets_;
    std::vector<std::uint32_t> order_;  // back to front
    std::vector<glm::vec4> cells_;      // packHarcTets: 5 per tetrahedron, in the mesh's order
    CeilingSegments segments_;
};

}  // namespace clvr::tools
