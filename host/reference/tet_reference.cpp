// host/reference/tet_reference.cpp — the exact emission-absorption integral on linear tetrahedra: rays clipped
// against each tetrahedron's 4 face planes (candidates from a uniform grid of bounding boxes), segments
// cut at transfer-function control points, each linear piece integrated in closed form (Eq. 2-4 of
// seeds/001_cd12fd6b76f9cf96.txt; derivation and numerical care in docs/tet-reference.md).
#include "host/reference/tet_reference.h"

#include "host/optics/segment_integral.h"

#include "host/runtime/parallel.h"

#include <algorithm>
#include <array>
#include <atomic>
#include <cmath>
#include <limits>
#include <mutex>

namespace clvr {
// ---- geometry ---------------------------------------------------------------------------------------

TetAccel::TetAccel(const TetMesh& mesh)
{
    const auto& P = mesh.points;
    if (mesh.tets.empty() || P.empty())
        return;
    lo_ = glm::dvec3(std::numeric_limits<double>::infinity());
    hi_ = -lo_;
    for (const glm::uvec4& t : mesh.tets)
        for (int i = 0; i < 4; ++i) {
            lo_ = glm::min(lo_, P[t[i]]);
            hi_ = glm::max(hi_, P[t[i]]);
        }
    const glm::dvec3 ext = hi_ - lo_;
    const double extent = std::max({ext.x, ext.y, ext.z});
    const double minVolume6 = 1e-12 * extent * extent * extent;  // checkMesh's zero-volume threshold

    tets_.reserve(mesh.tets.size());
    meshIndex_.reserve(mesh.tets.size());
    // Canonical order of a face's points: by position (then index), so that two tetrahedra sharing a
    // face, even through duplicated points at a seam, compute the same plane bit for bit.
    auto before = [&](std::uint32_t i, std::uint32_t j) {
        const glm::dvec3 &p = P[i], &q = P[j];
        if (p.x != q.x) return p.x < q.x;
        if (p.y != q.y) return p.y < q.y;
        if (p.z != q.z) return p.z < q.z;
        return i < j;
    };
    for (std::size_t t = 0; t < mesh.tets.size(); ++t) {
        const glm::uvec4 v = mesh.tets[t];
        const double volume6 = glm::dot(P[v[1]] - P[v[0]], glm::cross(P[v[2]] - P[v[0]], P[v[3]] - P[v[0]]));
        if (!(std::fabs(volume6) > minVolume6)) {
            ++skipped_;
            continue;
        }
        Tet tet{};
        for (int i = 0; i < 4; ++i) {
            std::array<std::uint32_t, 3> f;
            for (int j = 0, k = 0; j < 4; ++j)
                if (j != i)
                    f[k++] = v[j];
            std::sort(f.begin(), f.end(), before);
            glm::dvec3 n = glm::cross(P[f[1]] - P[f[0]], P[f[2]] - P[f[0]]);
            double w = -glm::dot(n, P[f[0]]);
            double h = glm::dot(n, P[v[i]]) + w;
            if (h > 0.0) {  // make the inside negative (exact: a sign flip)
                n = -n;
                w = -w;
                h = -h;
                tet.flipped |= 1u << i;
            }
            tet.plane[i] = glm::dvec4(n, w);
            tet.height[i] = h;
            tet.scalar[i] = mesh.scalars[v[i]];
        }
        tets_.push_back(tet);
        meshIndex_.push_back(static_cast<std::uint32_t>(t));
    }

    // Uniform grid, about one cell per tetrahedron, cells as cubic as the box allows.
    const double n = static_cast<double>(std::max<std::size_t>(tets_.size(), 1));
    const glm::dvec3 e = glm::max(ext, glm::dvec3(extent * 1e-6 + 1e-300));
    const double cell = std::cbrt(e.x * e.y * e.z / n);
    dims_ = glm::clamp(glm::ivec3(glm::ceil(e / cell)), glm::ivec3(1), glm::ivec3(256));
    hi_ = lo_ + e;
    cellSize_ = e / glm::dvec3(dims_);
    const glm::dvec3 pad = cellSize_ * 1e-6;  // boxes a hair larger: no tet lost to DDA rounding
    auto cellRange = [&](const Tet&, std::size_t t, glm::ivec3& c0, glm::ivec3& c1) {
        const glm::uvec4 v = mesh.tets[meshIndex_[t]];
        glm::dvec3 bmin = P[v[0]], bmax = P[v[0]];
        for (int i = 1; i < 4; ++i) {
            bmin = glm::min(bmin, P[v[i]]);
            bmax = glm::max(bmax, P[v[i]]);
        }
        c0 = glm::clamp(glm::ivec3(glm::floor((bmin - pad - lo_) / cellSize_)), glm::ivec3(0), dims_ - 1);
        c1 = glm::clamp(glm::ivec3(glm::floor((bmax + pad - lo_) / cellSize_)), glm::ivec3(0), dims_ - 1);
    };
    const std::size_t cells = static_cast<std::size_t>(dims_.x) * dims_.y * dims_.z;
    cellStart_.assign(cells + 1, 0);
    auto cellIndex = [&](int x, int y, int z) { return (static_cast<std::size_t>(z) * dims_.y + y) * dims_.x + x; };
    for (int pass = 0; pass < 2; ++pass) {
        std::vector<std::uint32_t> fill;
        if (pass == 1) {
            for (std::size_t c = 0; c < cells; ++c)
                cellStart_[c + 1] += cellStart_[c];
            cellTets_.resize(cellStart_[cells]);
            fill.assign(cellStart_.begin(), cellStart_.end() - 1);
        }
        for (std::size_t t = 0; t < tets_.size(); ++t) {
            glm::ivec3 c0, c1;
            cellRange(tets_[t], t, c0, c1);
            for (int z = c0.z; z <= c1.z; ++z)
                for (int y = c0.y; y <= c1.y; ++y)
                    for (int x = c0.x; x <= c1.x; ++x) {
                        if (pass == 0)
                            ++cellStart_[cellIndex(x, y, z) + 1];
                        else
                            cellTets_[fill[cellIndex(x, y, z)]++] = static_cast<std::uint32_t>(t);
                    }
        }
    }
}

namespace {

// [t0, t1] (t0 >= 0) of the ray inside the box [lo, hi]; false if it misses.
bool clipToBox(const Ray& ray, glm::dvec3 lo, glm::dvec3 hi, double& t0, double& t1)
{
    t0 = 0.0;
    t1 = std::numeric_limits<double>::infinity();
    for (int a = 0; a < 3; ++a) {
        if (ray.direction[a] == 0.0) {
            if (ray.origin[a] < lo[a] || ray.origin[a] > hi[a])
                return false;
            continue;
        }
        double ta = (lo[a] - ray.origin[a]) / ray.direction[a], tb = (hi[a] - ray.origin[a]) / ray.direction[a];
        if (ta > tb)
            std::swap(ta, tb);
        t0 = std::max(t0, ta);
        t1 = std::min(t1, tb);
    }
    return t1 >= t0;
}

}  // namespace

std::vector<TetSegment> traceRay(const TetAccel& accel, const Ray& ray)
{
    std::vector<TetSegment> out;
    if (accel.tets_.empty())
        return out;
    const glm::dvec3 margin = accel.cellSize_ * 1e-6;
    double t0, t1;
    if (!clipToBox(ray, accel.lo_ - margin, accel.hi_ + margin, t0, t1))
        return out;

    // Candidates: every tetrahedron listed in a grid cell the ray passes (3D DDA, Amanatides & Woo).
    std::vector<std::uint32_t> candidates;
    const glm::ivec3 dims = accel.dims_;
    const glm::dvec3 start = ray.origin + t0 * ray.direction;
    glm::ivec3 c = glm::clamp(glm::ivec3(glm::floor((start - accel.lo_) / accel.cellSize_)), glm::ivec3(0), dims - 1);
    glm::ivec3 step;
    glm::dvec3 tNext, tDelta;
    for (int a = 0; a < 3; ++a) {
        const double d = ray.direction[a];
        if (d > 0.0) {
            step[a] = 1;
            tNext[a] = (accel.lo_[a] + (c[a] + 1) * accel.cellSize_[a] - ray.origin[a]) / d;
            tDelta[a] = accel.cellSize_[a] / d;
        } else if (d < 0.0) {
            step[a] = -1;
            tNext[a] = (accel.lo_[a] + c[a] * accel.cellSize_[a] - ray.origin[a]) / d;
            tDelta[a] = -accel.cellSize_[a] / d;
        } else {
            step[a] = 0;
            tNext[a] = std::numeric_limits<double>::infinity();
            tDelta[a] = std::numeric_limits<double>::infinity();
        }
    }
    for (;;) {
        const std::size_t cell = (static_cast<std::size_t>(c.z) * dims.y + c.y) * dims.x + c.x;
        candidates.insert(candidates.end(), accel.cellTets_.begin() + accel.cellStart_[cell],
                          accel.cellTets_.begin() + accel.cellStart_[cell + 1]);
        const int a = (tNext.x <= tNext.y && tNext.x <= tNext.z) ? 0 : (tNext.y <= tNext.z ? 1 : 2);
        if (tNext[a] > t1)
            break;
        c[a] += step[a];
        if (c[a] < 0 || c[a] >= dims[a])
            break;
        tNext[a] += tDelta[a];
    }
    std::sort(candidates.begin(), candidates.end());
    candidates.erase(std::unique(candidates.begin(), candidates.end()), candidates.end());

    // Clip the ray against the 4 face planes: n.(o + λ d) + w <= 0 on every face.
    for (const std::uint32_t t : candidates) {
        const TetAccel::Tet& tet = accel.tets_[t];
        double lamIn = 0.0, lamOut = std::numeric_limits<double>::infinity();
        double v[4], den[4];
        bool miss = false;
        for (int i = 0; i < 4 && !miss; ++i) {
            const glm::dvec3 n(tet.plane[i]);
            v[i] = glm::dot(n, ray.origin) + tet.plane[i].w;
            den[i] = glm::dot(n, ray.direction);
            if (den[i] > 0.0)
                lamOut = std::min(lamOut, -v[i] / den[i]);
            else if (den[i] < 0.0)
                lamIn = std::max(lamIn, -v[i] / den[i]);
            else if (v[i] > 0.0 || (v[i] == 0.0 && (tet.flipped >> i & 1u)))
                miss = true;  // parallel: outside; in the shared plane only the unflipped side counts
        }
        if (miss || !(lamOut > lamIn))
            continue;
        // Barycentric coordinates are linear in λ: b_i(λ) = (v_i + λ den_i) / height_i.
        double sIn = 0.0, sOut = 0.0;
        for (int i = 0; i < 4; ++i) {
            sIn += (v[i] + lamIn * den[i]) / tet.height[i] * tet.scalar[i];
            sOut += (v[i] + lamOut * den[i]) / tet.height[i] * tet.scalar[i];
        }
        out.push_back({accel.meshIndex_[t], lamIn, lamOut, sIn, sOut});
    }
    std::sort(out.begin(), out.end(), [](const TetSegment& p, const TetSegment& q) {
        if (p.lambdaIn != q.lambdaIn) return p.lambdaIn < q.lambdaIn;
        if (p.lambdaOut != q.lambdaOut) return p.lambdaOut < q.lambdaOut;
        return p.tet < q.tet;
    });
    return out;
}

// ---- integration ------------------------------------------------------------------------------------


Image4d tetReferenceIntegral(const TetAccel& accel, const TransferFunction& tf, const Camera& camera,
                             const ImageSpec& image, const TetReferenceOptions& options)
{
    Image4d out(image.width, image.height);
    std::atomic<int> nextRow{0};
    std::mutex statsMutex;
    TetReferenceStats total;
    auto worker = [&] {
        TetReferenceStats local;
        for (int y; (y = nextRow.fetch_add(1)) < image.height;) {
            for (int x = 0; x < image.width; ++x) {
                const std::vector<TetSegment> segments = traceRay(accel, camera.ray(x, y, image.width, image.height));
                const glm::dvec4 v = integrateSegments(segments, tf, &local.pieces);
                local.rays += segments.empty() ? 0 : 1;
                local.segments += segments.size();
                local.maxSegmentsPerRay = std::max(local.maxSegmentsPerRay, static_cast<int>(segments.size()));
                // Final pixel of DESIGN.md: I + (1 - A) * background, alpha = A.
                out.at(x, y) = glm::dvec4(glm::dvec3(v) + (1.0 - v.a) * image.background, v.a);
            }
        }
        std::lock_guard lock(statsMutex);
        total.rays += local.rays;
        total.segments += local.segments;
        total.pieces += local.pieces;
        total.maxSegmentsPerRay = std::max(total.maxSegmentsPerRay, local.maxSegmentsPerRay);
    };
    runOnThreads(options.threads, image.height, worker);
    if (options.stats)
        *options.stats = total;
    return out;
}

Image4d tetReferenceIntegral(const TetMesh& mesh, const TransferFunction& tf, const Camera& camera,
                             const ImageSpec& image, const TetReferenceOptions& options)
{
    return tetReferenceIntegral(TetAccel(mesh), tf, camera, image, options);
}

}  // namespace clvr
