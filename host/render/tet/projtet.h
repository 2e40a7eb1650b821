// host/render/tet/projtet.h — cell projection of tetrahedral meshes in visibility order: each cell's
// projected silhouette split into 3 or 4 triangles around its thick vertex (Shirley & Tuchman 1990),
// the cells sorted back to front on the host (MPVONC over the face adjacency, Williams 1992, with
// relations between overlapping boundary faces for non-convex meshes, or the centre-distance sort),
// all drawn in that order through the raster stage (raster/rasterizer.h) with kernels/projtet.cl's
// fragment program: the exact ray segment of the fragment's own ray through its cell, integrated with
// harc's partial pre-integration (kernels/segment_integral.h), blended ONE, ONE_MINUS_SRC_ALPHA.
// docs/projtet.md.
#pragma once

#include "host/model/camera.h"
#include "host/model/mesh.h"
#include "host/render/renderer.h"
#include "host/render/tile_lists.h"

#include <glm/glm.hpp>
#include <nlohmann/json.hpp>

#include <array>
#include <cstdint>
#include <memory>
#include <optional>
#include <vector>

namespace clvr {

struct ProjtetOptions {
    // "mpvonc-boundary" (the default): topological sort of the adjacency's in-front-of relation plus
    // "behind" relations between boundary faces that overlap on screen (exact for acyclic non-convex
    // meshes); "mpvonc": the adjacency alone (exact for convex meshes); "centroid": the cells' centres
    // sorted by distance from the eye (depth along the view for parallel cameras).
    enum class Order { MpvoncBoundary, Mpvonc, Centroid };
    Order order = Order::MpvoncBoundary;
    // "fused" (the default): the cells binned to tiles of kProjtetTileW x kProjtetTileH pixels by their pixel boxes
    // (projtetCellBoxes), one work-item per pixel walking its tile's cells in visibility order with the fragment
    // program's work and the blend in one kernel (kernels/projtet.cl projtet_fused). "raster": each cell's
    // silhouette as 3 or 4 triangles drawn through the raster stage (the paper's method), the fragment program
    // integrating the pixel's segment: the same frame, the same segments in the same order.
    enum class Path { Raster, Fused };
    Path path = Path::Fused;
    // Fused path: 8 neighbouring pixels of a row per work-item, one per float8 lane (kernels/projtet.cl's
    // projtet_fused_packet; the same bits as one pixel per work-item). Unset: on CPU devices only.
    std::optional<bool> packets;
};

// The fused path's tiles: kProjtetTileW x kProjtetTileH pixels (kernels/projtet.cl PROJTET_TILE_W_LOG2, _H_LOG2);
// 8 wide, so that a packet's 8 pixels share a tile.
inline constexpr int kProjtetTileW = 8, kProjtetTileH = 4;

// A cell's box of pixel centres (x0, y0)-(x1, y1), inclusive; empty when x0 > x1 or y0 > y1. The fused path
// uploads them as short4.
using ProjtetBox = PixelBox;

// Every cell's box for `camera` on a width x height image (at most 16,384 on a side), as the fused path and
// tools/ceiling_projtet.h take them: the points projected as the raster path projects them (through float NDC),
// the box of a cell's four corners grown by the raster path's 1/16 pixel and clipped to the image. A cell with a point
// at or behind the near plane (the eye in the mesh) is boxed by its part beyond the plane — its points in front and
// its edges' crossings with the plane —, as the raster path clips its back faces there; a cell wholly nearer has an
// empty box. On the host's threads.
std::vector<ProjtetBox> projtetCellBoxes(const std::vector<glm::dvec3>& points, const std::vector<glm::uvec4>& tets,
                                         const Camera& camera, int width, int height);

// The option's value for `order` ("mpvonc-boundary", "mpvonc", "centroid").
const char* orderName(ProjtetOptions::Order order);

// Its registry entry (host/render/renderer.h).
TechniqueInfo projtetTechnique();

// Reads the scene's "options" for projtet: "order" ("mpvonc-boundary" | "mpvonc" | "centroid"), "path"
// ("fused" | "raster"), "packets" (true, false or null).
// InputError naming the key for unknown keys, wrong types and values.
ProjtetOptions parseProjtetOptions(const nlohmann::json& options);

// The view-independent part of the visibility order: per interior face its two cells and its plane
// (outward normal of `a`, offset: dot(normal, x) = offset on the face), the boundary faces (cell, points,
// outward plane) and the cells' centres.
class VisibilitySorter {
public:
    VisibilitySorter(const TetMesh& mesh, const TetTopology& topology);

    // "Cell `back` is drawn before cell `front`": both meet one ray, `back` farther along it.
    struct Behind {
        std::uint32_t back, front;
    };
    struct BoundaryStats {
        std::uint64_t exitFaces = 0, entryFaces = 0;  // boundary faces the rays leave / enter the mesh by
        std::uint64_t pairsTested = 0;                // exit x entry pairs given the exact overlap test
        std::uint64_t relations = 0;                  // of them, an entry face behind an exit face
        double ms = 0.0;                              // time of boundaryOrder()
    };
    struct Result {
        std::vector<std::uint32_t> order;  // every cell once, back to front
        std::uint64_t cyclesBroken = 0;    // cells emitted before all cells behind them (cycles)
        std::uint64_t waves = 0;           // MpvoncBoundary: the levels of the wavefront order
        int threads = 1;                   // host threads of the classification and the wavefront
        BoundaryStats boundary;            // MpvoncBoundary only
    };
    // Back to front for `camera`. Mpvonc: Kahn's topological sort of "a is behind b" across each
    // interior face (the side of the face's plane the eye is on; the view direction for parallel
    // cameras), the ready cell farthest from the eye first (exact for convex meshes; for non-convex
    // ones, where cells that share no face can still overlap, the distance priority is a heuristic).
    // MpvoncBoundary: the same relations with boundaryOrder()'s added (exact where the relation has no
    // cycle, docs/projtet.md), emitted level by level (wavefront()). When no cell is ready (a cycle), the
    // farthest cell left is emitted and counted. Centroid: the centres' distances, farthest first.
    // width x height: the image (0: unbounded), outside of which boundaryOrder() looks for no overlaps.
    // threads: host threads for the per-cell classification and the wavefront's release (0: the thread
    // budget, one per kCellsPerThread cells); the order is the same for any number of threads.
    Result sort(const Camera& camera, ProjtetOptions::Order order, int width = 0, int height = 0,
                int threads = 0) const;
    static constexpr std::size_t kCellsPerThread = 32768;

    // The relations a ray adds where it leaves the mesh and enters it again (Williams' boundary
    // extension of MPVONC): for every boundary face the ray leaves by (exit) and every boundary face it
    // enters by (entry) whose projections overlap with positive area (exact convex clipping, candidates
    // from a grid on the image plane), "entry's cell behind exit's cell" if the entry face is not in
    // front of the exit face along a ray through the overlap. Faces are clipped to the view (the
    // width x height image's window grown by 2 pixels, unbounded for 0; perspective: at a near plane
    // 1e-6 of the farthest boundary point's depth); faces seen edge-on give nothing.
    std::vector<Behind> boundaryOrder(const Camera& camera, BoundaryStats& stats, int width = 0, int height = 0) const;

private:
    // Per frame, per cell: its distance key (larger = farther), which neighbours it is behind (bit i:
    // the cell across face i is drawn after it) and how many cells behind it are not drawn yet.
    struct Relations {
        std::vector<double> key;
        std::vector<std::uint8_t> inFront;
        std::vector<std::uint32_t> pending;
    };
    // The boundary relations by back cell (CSR): front[start[c] .. start[c + 1]) are drawn after c.
    struct Extra {
        std::vector<std::uint32_t> start, front;
    };
    // The keys, and with `faces` the face relations, on `threads` threads (each cell by one thread).
    Relations classify(const Camera& camera, bool faces, int threads) const;
    // Kahn's sort by levels: each wave is every cell whose cells behind are all drawn, by cell number,
    // and releases the cells in front of it. Any order that keeps the relations gives
    // the same image: cells that share a pixel are ordered by them, directly or through others, and the
    // order of the rest touches no pixel twice. Twice as fast as one cell at a time from a heap on the
    // 1 M-tet mesh (docs/projtet.md). Each wave's release is split between result.threads threads (a
    // barrier between waves; the thread that takes a cell's count to zero lists it, each list sorted,
    // the lists merged), so the order does not depend on the threads' timing. By number rather than
    // farthest first within a wave: the same image, 35 ms less on the 1 M-tet mesh.
    void wavefront(Relations& relations, const Extra& extra, std::vector<std::uint8_t>& emitted,
                   Result& result) const;
    struct InnerFace {
        std::uint32_t a, b;
        glm::dvec3 normal;  // out of a
        double offset;
    };
    struct OuterFace {
        std::uint32_t cell;
        std::array<glm::dvec3, 3> points;
        glm::dvec3 normal;  // out of the cell
        double offset;
    };
    std::vector<InnerFace> faces_;
    std::vector<std::array<std::int32_t, 4>> faceOf_;  // per cell, its inner faces' indices (-1: none)
    std::vector<std::array<std::int32_t, 4>> adjacent_;  // per cell, the cell across each face (-1: none)
    std::vector<std::uint8_t> sideA_;  // per cell, bit i: it is faces_[faceOf_[c][i]].a
    std::vector<OuterFace> boundary_;
    std::vector<glm::dvec3> centres_;
};

// Shirley-Tuchman classes of a projected tetrahedron (2D points, any orientation): Class1 one vertex
// inside the triangle of the other three (the thick vertex: 3 triangles), Class2 the two diagonals of a
// convex quadrilateral cross (the thick vertex is their crossing: 4 triangles), Degenerate: no area.
struct ProjectedTet {
    enum class Kind { Class1, Class2, Degenerate };
    Kind kind = Kind::Degenerate;
    glm::dvec2 thick{0.0};  // the thick vertex
    int thickVertex = -1;   // Class1: which vertex; Class2: -1
    // Triangles as corner indices: 0..3 the vertices, 4 the thick vertex (Class2).
    std::array<std::array<int, 3>, 4> triangles{};
    int triangleCount = 0;
    // The silhouette's corners in cyclic order (3 for Class1, 4 for Class2): the renderer moves them
    // outwards by a fraction of a pixel (conservative coverage, docs/projtet.md).
    std::array<int, 4> outer{};
    int outerCount = 0;
};
ProjectedTet classifyProjection(const std::array<glm::dvec2, 4>& p);

// Renderer for "projtet" on a mesh that checkMesh() has normalized. InputError for bad options, an
// empty mesh or 2^24 cells or more (cell ids travel as two 12-bit halves in a float attribute).
std::unique_ptr<Renderer> makeProjtetRenderer(Device& device, const Scene& scene, const TetMesh& mesh,
                                              const TetTopology& topology);

}  // namespace clvr
