// host/render/tet/harc_entry.h — HARC's entry points through the raster stage, as seeds/001 starts its
// rays: "the propagation of the ray is started by rasterizing the front faces on the mesh's boundary"
// (§3), and for non-convex meshes the further entries by depth peeling (§4, Everitt 2001). Each
// layer is one raster::draw of the boundary faces, no culling (the fragment program keeps the faces the ray enters through, by their plane), depth test LESS, with a
// fragment program (kernels/harc_entry.cl) that writes the face and its ray parameter λ and discards
// fragments at or before the previous layer's λ at that pixel. The layers, in order, are the per-pixel
// sorted lists that kernels/harc.cl walks (HarcEntryLists, compacted on the host).
#pragma once

#include "host/model/camera.h"
#include "host/runtime/device.h"
#include "host/model/mesh.h"
#include "host/render/tet/harc.h"
#include "raster/framebuffer.h"
#include "raster/rasterizer.h"

#include <glm/glm.hpp>

#include <cstdint>
#include <memory>
#include <vector>

namespace clvr {

struct HarcRasterEntryStats {
    int layers = 0;                  // draws that added at least one entry
    bool layerBound = false;         // stopped at maxLayers with entries still coming
    std::uint64_t pixelsAtBound = 0; // pixels whose list was cut at maxLayers (their rays may miss cells)
    std::uint64_t triangles = 0;     // rasterized (after culling), all layers
    std::uint64_t fragments = 0;     // covered pixels before the tests, all layers
    double rasterMs = 0.0;           // raster::draw calls, wall clock
    double compactMs = 0.0;          // read-back and CSR compaction on the host
};

class HarcRasterEntries {
public:
    // Boundary faces of `mesh` (as `topology` lists them), outward-wound, relative to `shift` (the
    // renderer's origin); `tets` is packHarcTets(mesh, topology, shift) on the device (the fragment
    // program takes λ from the entry face's plane). A frame buffer of width x height on `device`;
    // at most maxLayers (1..255) peeling layers per frame.
    // `slot`: where packHarcTets placed each tetrahedron (harcCellOrder, harcCellPlace); the lists' codes are
    // those places (harcDeviceCode).
    HarcRasterEntries(Device& device, const TetMesh& mesh, const TetTopology& topology, const glm::dvec3& shift,
                      const cl::Buffer& tets, int width, int height, int maxLayers,
                      const std::vector<std::uint32_t>& slot = {});

    // The per-pixel sorted crossings with boundary front faces for `camera` (world coordinates),
    // λ >= the near plane. Same layout as buildHarcEntryLists.
    HarcEntryLists build(const Camera& camera, HarcRasterEntryStats& stats);

private:
    Device& device_;
    int width_, height_, maxLayers_;
    glm::dvec3 shift_;
    std::vector<glm::vec3> corners_;   // 3 per boundary face, counter-clockwise seen from outside
    std::vector<std::int32_t> codes_;  // tet * 4 + face per boundary face
    glm::dvec3 boundsCenter_{0.0};     // of the boundary points, shifted
    double boundsRadius_ = 0.0;
    std::unique_ptr<raster::Framebuffer> framebuffer_;
    cl::Buffer previous_;              // λ of the last layer per pixel (the peel threshold)
    raster::FragmentProgram program_;
};

}  // namespace clvr
