// host/reference/tet_reference.h — the exact CPU reference of DESIGN.md's optical model on linear tetrahedral
// meshes: per pixel, the emission-absorption integral I = ∫ C(s) τ(s) exp(-∫τ) dλ (Eq. 1 of
// seeds/001_cd12fd6b76f9cf96.txt) along the camera ray through the pixel center, in double. Inside a
// tetrahedron s is linear along the ray; each segment is cut at the transfer function's control points,
// so that τ and C are linear on every piece, and each piece is integrated in closed form (Williams, Max &
// Stein 1998; Moreland & Angel 2004; seeds/001 Eq. 2-4) — no quadrature. Used by tests to judge HARC;
// not a renderer. Independent of the code it checks: no adjacency (TetTopology), no checkMesh().
#pragma once

#include "host/model/camera.h"
#include "host/model/image.h"
#include "host/model/mesh.h"
#include "host/model/scene.h"
#include "host/optics/segment_integral.h"
#include "host/model/transfer_function.h"

#include <glm/glm.hpp>

#include <cstdint>
#include <vector>

namespace clvr {

// ---- geometry ---------------------------------------------------------------------------------------

// Face planes of every tetrahedron and a uniform grid over their bounding boxes. Each face's plane is
// computed from its three points in ascending index order, so the two tetrahedra that share a face hold
// the same plane up to sign and a ray crosses it at bit-identical λ in both: no gap, no overlap.
// Zero-volume tetrahedra (|6V| <= 1e-12 * extent^3, the threshold of checkMesh) are left out.
class TetAccel {
public:
    explicit TetAccel(const TetMesh& mesh);

    struct Tet {
        glm::dvec4 plane[4];  // face i (opposite vertex i): n.x + w <= 0 inside, n not normalized
        double height[4];     // n_i . p_i + w_i (< 0): barycentric_i(x) = (n_i . x + w_i) / height_i
        double scalar[4];     // s at the 4 vertices
        std::uint32_t flipped;  // bit i: plane i is the canonical plane negated (tie-break in-plane rays)
    };

    std::size_t tetCount() const { return tets_.size(); }  // usable ones, after zero-volume tets
    std::uint64_t tetsSkipped() const { return skipped_; }  // zero volume
    glm::ivec3 gridDims() const { return dims_; }
    glm::dvec3 boundsMin() const { return lo_; }
    glm::dvec3 boundsMax() const { return hi_; }

private:
    friend std::vector<TetSegment> traceRay(const TetAccel&, const Ray&);
    std::vector<Tet> tets_;
    std::vector<std::uint32_t> meshIndex_;  // tets_[i] is mesh tet meshIndex_[i]
    std::uint64_t skipped_ = 0;
    glm::dvec3 lo_{0.0}, hi_{0.0}, cellSize_{1.0};
    glm::ivec3 dims_{1};
    std::vector<std::uint32_t> cellStart_;  // CSR: cell c holds cellTets_[cellStart_[c] .. cellStart_[c+1])
    std::vector<std::uint32_t> cellTets_;
};

// The ray's segments through the mesh, front to back: every (tet, lambda_in, lambda_out, s_in, s_out)
// with lambda_out > lambda_in and lambda >= 0 (in front of the camera), sorted by lambda_in. Gaps where
// the ray is outside a non-convex mesh are simply absent. `tet` is the index into mesh.tets.
std::vector<TetSegment> traceRay(const TetAccel& accel, const Ray& ray);

// ---- the image --------------------------------------------------------------------------------------

struct TetReferenceStats {
    std::uint64_t rays = 0;      // rays with at least one segment
    std::uint64_t segments = 0;  // ray-tet segments, all rays
    std::uint64_t pieces = 0;    // linear pieces after cutting at control points
    int maxSegmentsPerRay = 0;
};

struct TetReferenceOptions {
    int threads = 2;                      // std::thread workers over rows (<= 0: hardware_concurrency)
    TetReferenceStats* stats = nullptr;   // filled when not null
};

// Integrates every pixel of an image.width x image.height image; the pixel is rgb = I + (1 - A) *
// background, a = A (DESIGN.md). Only the ray part in front of the camera (lambda >= 0) counts.
Image4d tetReferenceIntegral(const TetMesh& mesh, const TransferFunction& tf, const Camera& camera,
                             const ImageSpec& image, const TetReferenceOptions& options = {});
// The same with an acceleration structure built once (several frames or cameras of one mesh).
Image4d tetReferenceIntegral(const TetAccel& accel, const TransferFunction& tf, const Camera& camera,
                             const ImageSpec& image, const TetReferenceOptions& options = {});

}  // namespace clvr
