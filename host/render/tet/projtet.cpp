// host/render/tet/projtet.cpp — options, the visibility sort (MPVONC or centre distance), the
// Shirley-Tuchman classification and the projtet renderer: one draw of every cell's projected triangles
// in visibility order through the raster stage, kernels/projtet.cl's fragment program per fragment.
#include "host/render/tet/projtet.h"

#include "host/optics/psi_table.h"
#include "host/render/camera_args.h"
#include "host/render/fragment_uniforms.h"
#include "host/render/options_util.h"
#include "host/render/scaffold.h"
#include "host/render/tile_lists.h"
#include "host/render/tet/harc.h"
#include "host/render/transfer_function_upload.h"
#include "host/runtime/embedded_kernels.h"
#include "host/runtime/errors.h"
#include "host/runtime/parallel.h"
#include "kernels/projtet_params.h"
#include "raster/framebuffer.h"
#include "raster/rasterizer.h"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <limits>
#include <queue>
#include <string>
#include <utility>

namespace clvr {

static_assert(sizeof(ClProjtetUniforms) == 96, "float4s only: the fragment program reads it from its uniforms");

// ---- the visibility sort ----------------------------------------------------------------------------

VisibilitySorter::VisibilitySorter(const TetMesh& mesh, const TetTopology& topology)
{
    const std::size_t cells = mesh.tets.size();
    faceOf_.assign(cells, {-1, -1, -1, -1});
    sideA_.assign(cells, 0);
    adjacent_ = topology.neighbor;
    centres_.resize(cells);
    for (std::uint32_t t = 0; t < cells; ++t) {
        glm::dvec3 c(0.0);
        for (int i = 0; i < 4; ++i)
            c += mesh.points[mesh.tets[t][i]];
        centres_[t] = 0.25 * c;
        for (std::uint32_t f = 0; f < 4; ++f) {
            const std::int32_t n = topology.neighbor[t][f];
            if (n < 0) {
                const std::array<glm::dvec3, 3> p = outwardFace(mesh, t, f);
                const glm::dvec3 normal = glm::cross(p[1] - p[0], p[2] - p[0]);
                boundary_.push_back({t, p, normal, glm::dot(normal, p[0])});
                continue;
            }
            if (n < static_cast<std::int32_t>(t))
                continue;  // the pair was taken from n
            const std::array<glm::dvec3, 3> p = outwardFace(mesh, t, f);
            const glm::dvec3 normal = glm::cross(p[1] - p[0], p[2] - p[0]);
            const std::int32_t index = static_cast<std::int32_t>(faces_.size());
            faces_.push_back({t, static_cast<std::uint32_t>(n), normal, glm::dot(normal, p[0])});
            faceOf_[t][f] = index;
            sideA_[t] |= static_cast<std::uint8_t>(1u << f);
            for (int g = 0; g < 4; ++g)
                if (topology.neighbor[n][g] == static_cast<std::int32_t>(t) && faceOf_[n][g] < 0) {
                    faceOf_[n][g] = index;
                    break;
                }
        }
    }
}

namespace {

// Every cell, the largest key (the farthest) first; equal keys by cell number.
std::vector<std::uint32_t> farthestFirst(const std::vector<double>& key)
{
    std::vector<std::uint32_t> cells(key.size());
    for (std::uint32_t c = 0; c < cells.size(); ++c)
        cells[c] = c;
    std::stable_sort(cells.begin(), cells.end(), [&](std::uint32_t a, std::uint32_t b) { return key[a] > key[b]; });
    return cells;
}

}  // namespace

VisibilitySorter::Result VisibilitySorter::sort(const Camera& camera, ProjtetOptions::Order order, int width,
                                                int height, int threads) const
{
    const std::size_t cells = centres_.size();
    Result result;
    result.threads = threadsToUse(threads, threads > 0 ? threads : static_cast<int>(cells / kCellsPerThread));
    Relations relations = classify(camera, order != ProjtetOptions::Order::Centroid, result.threads);
    const std::vector<double>& key = relations.key;
    result.order.reserve(cells);
    std::vector<std::uint32_t> byKey;
    if (order == ProjtetOptions::Order::Centroid) {
        result.order = farthestFirst(key);
        return result;
    }

    // The boundary relations as lists per back cell (CSR), each one more cell behind its front cell.
    std::vector<std::uint32_t>& pending = relations.pending;
    Extra extra;
    if (order == ProjtetOptions::Order::MpvoncBoundary) {
        const std::vector<Behind> behind = boundaryOrder(camera, result.boundary, width, height);
        extra.start.assign(cells + 1, 0);
        for (const Behind& r : behind)
            ++extra.start[r.back + 1];
        for (std::size_t c = 0; c < cells; ++c)
            extra.start[c + 1] += extra.start[c];
        extra.front.resize(behind.size());
        std::vector<std::uint32_t> fill(extra.start.begin(), extra.start.end() - 1);
        for (const Behind& r : behind) {
            extra.front[fill[r.back]++] = r.front;
            ++pending[r.front];
        }
    }
    std::vector<std::uint8_t> emitted(cells, 0);
    if (order == ProjtetOptions::Order::MpvoncBoundary) {
        wavefront(relations, extra, emitted, result);
        return result;
    }
    std::priority_queue<std::pair<double, std::uint32_t>> ready;  // farthest first
    for (std::uint32_t c = 0; c < cells; ++c)
        if (pending[c] == 0)
            ready.push({key[c], c});
    auto emit = [&](std::uint32_t c) {
        emitted[c] = 1;
        result.order.push_back(c);
        for (int i = 0; i < 4; ++i) {
            const std::uint32_t next = static_cast<std::uint32_t>(adjacent_[c][i]);
            if ((relations.inFront[c] >> i & 1) && !emitted[next] && --pending[next] == 0)
                ready.push({key[next], next});
        }
    };
    std::size_t cursor = 0;
    while (result.order.size() < cells) {
        if (ready.empty()) {
            // A cycle: the farthest cell left goes next.
            if (byKey.empty())
                byKey = farthestFirst(key);
            while (emitted[byKey[cursor]])
                ++cursor;
            ++result.cyclesBroken;
            emit(byKey[cursor]);
            continue;
        }
        const std::uint32_t c = ready.top().second;
        ready.pop();
        if (!emitted[c])
            emit(c);
    }
    return result;
}

VisibilitySorter::Relations VisibilitySorter::classify(const Camera& camera, bool faces, int threads) const
{
    const std::size_t cells = centres_.size();
    const glm::dvec3 eye = camera.position, forward = camera.forward();
    Relations r;
    r.key.resize(cells);
    // later[f]: 1 if faces_[f].b is drawn after a (a is behind it), 2 if a after b, 0 no constraint (the
    // eye in the face's plane). Each pass in chunks taken in turn by the threads, every entry written by
    // one thread; the cells read their faces' entries, so the two cells of a face agree.
    std::vector<std::uint8_t> later(faces ? faces_.size() : 0);
    const auto inChunks = [threads](std::size_t count, const auto& body) {
        constexpr std::size_t chunk = 16384;
        std::atomic<std::size_t> next{0};
        runOnThreads(threads, threads, [&] {
            for (std::size_t first; (first = next.fetch_add(chunk)) < count;)
                for (std::size_t k = first; k < std::min(count, first + chunk); ++k)
                    body(k);
        });
    };
    if (faces) {
        inChunks(later.size(), [&](std::size_t f) {
            const InnerFace& face = faces_[f];
            // > 0: the eye (or, parallel, the direction towards it) is on b's side of the face, outside a.
            const double side = camera.parallel ? -glm::dot(face.normal, forward) : glm::dot(face.normal, eye) - face.offset;
            later[f] = side > 0.0 ? 1 : side < 0.0 ? 2 : 0;
        });
        r.inFront.resize(cells);
        r.pending.resize(cells);
    }
    inChunks(cells, [&](std::size_t c) {
        const glm::dvec3& centre = centres_[c];
        r.key[c] = camera.parallel ? glm::dot(centre, forward) : glm::dot(centre - eye, centre - eye);
        if (!faces)
            return;
        std::uint8_t inFront = 0;
        std::uint32_t behind = 0;
        for (int i = 0; i < 4; ++i) {
            const std::int32_t f = faceOf_[c][i];
            if (f < 0 || later[f] == 0)
                continue;
            const bool cIsA = sideA_[c] >> i & 1;
            if (later[f] == (cIsA ? 1 : 2))
                inFront |= static_cast<std::uint8_t>(1u << i);  // c is behind its neighbour i
            else
                ++behind;
        }
        r.inFront[c] = inFront;
        r.pending[c] = behind;
    });
    return r;
}

void VisibilitySorter::wavefront(Relations& relations, const Extra& extra, std::vector<std::uint8_t>& emitted,
                                 Result& result) const
{
    const std::size_t cells = centres_.size();
    const std::vector<double>& key = relations.key;
    const int threads = result.threads;
    // Per thread, the cells its part of the wave released, sorted. Reserved for every cell so that no
    // worker allocates (and so throws) while the others wait at the barrier.
    std::vector<std::vector<std::uint32_t>> released(threads);
    for (std::vector<std::uint32_t>& r : released)
        r.reserve(cells);
    for (std::uint32_t c = 0; c < cells; ++c)
        if (relations.pending[c] == 0)
            released[0].push_back(c);

    std::vector<std::uint32_t> wave, byKey;
    wave.reserve(cells);
    std::size_t cursor = 0;
    bool done = false;
    // One thread between the barriers: the released cells merged into the next wave, emitted.
    const auto nextWave = [&] {
        wave.clear();
        for (const std::vector<std::uint32_t>& r : released) {
            const std::size_t middle = wave.size();
            wave.insert(wave.end(), r.begin(), r.end());
            std::inplace_merge(wave.begin(), wave.begin() + static_cast<std::ptrdiff_t>(middle), wave.end());
        }
        if (result.order.size() == cells) {
            done = true;
            return;
        }
        if (wave.empty()) {
            // A cycle: the farthest cell left goes next, alone.
            if (byKey.empty())
                byKey = farthestFirst(key);
            while (emitted[byKey[cursor]])
                ++cursor;
            ++result.cyclesBroken;
            wave.push_back(byKey[cursor]);
        }
        for (const std::uint32_t c : wave) {
            emitted[c] = 1;
            result.order.push_back(c);
        }
        ++result.waves;
    };
    // Every thread: its share of the wave releases the cells in front of it; the thread whose
    // decrement takes a cell's count of cells behind it to zero puts it in its list for the next wave.
    const auto release = [&](int part) {
        std::vector<std::uint32_t>& out = released[part];
        out.clear();
        const std::size_t first = wave.size() * part / threads, last = wave.size() * (part + 1) / threads;
        const auto drop = [&](std::uint32_t front) {
            if (!emitted[front] && std::atomic_ref<std::uint32_t>(relations.pending[front]).fetch_sub(1, std::memory_order_relaxed) == 1)
                out.push_back(front);
        };
        for (std::size_t k = first; k < last; ++k) {
            const std::uint32_t c = wave[k];
            for (int i = 0; i < 4; ++i)
                if (relations.inFront[c] >> i & 1)
                    drop(static_cast<std::uint32_t>(adjacent_[c][i]));
            if (!extra.start.empty())
                for (std::uint32_t e = extra.start[c]; e < extra.start[c + 1]; ++e)
                    drop(extra.front[e]);
        }
        std::sort(out.begin(), out.end());
    };
    if (threads == 1) {
        for (nextWave(); !done; nextWave())
            release(0);
        return;
    }
    PhaseBarrier sync(threads);
    std::atomic<int> parts{0};
    runOnThreads(threads, threads, [&] {
        const int part = parts.fetch_add(1);
        for (;;) {
            if (part == 0)
                nextWave();
            sync.arriveAndWait();
            if (done)
                break;
            release(part);
            sync.arriveAndWait();
        }
    });
}

// ---- the boundary extension ------------------------------------------------------------------------

namespace {

// A convex polygon: a boundary triangle clipped at the near plane (4 corners at most), or the overlap of
// two of them (one clipped by the other's edges: 8 at most).
template <typename P>
struct Convex {
    std::array<P, 8> p;
    int n = 0;
};

// Sutherland-Hodgman: the part of `in` where inside(x) >= 0, `inside` affine along edges.
template <typename P, typename F>
Convex<P> clipConvex(const Convex<P>& in, F inside)
{
    Convex<P> out;
    for (int i = 0; i < in.n; ++i) {
        const P& a = in.p[i];
        const P& b = in.p[(i + 1) % in.n];
        const double da = inside(a), db = inside(b);
        if (da >= 0.0 && out.n < 8)
            out.p[out.n++] = a;
        if ((da >= 0.0) != (db >= 0.0) && out.n < 8)
            out.p[out.n++] = a + (da / (da - db)) * (b - a);
    }
    return out;
}

double signedArea(const Convex<glm::dvec2>& c)
{
    double a = 0.0;
    for (int i = 0; i < c.n; ++i) {
        const glm::dvec2& p = c.p[i];
        const glm::dvec2& q = c.p[(i + 1) % c.n];
        a += p.x * q.y - p.y * q.x;
    }
    return 0.5 * a;
}

// A boundary face on the image plane (perspective: (x/z, y/z) in the camera frame; parallel: (x, y)),
// with its depth range (z, along forward) and its plane in the camera frame, dot(normal, p) = offset.
struct ScreenFace {
    std::uint32_t cell;
    Convex<glm::dvec2> shape;  // counter-clockwise
    glm::dvec2 lo, hi;
    double zMin, zMax;
    glm::dvec3 normal;
    double offset;
};

// Depth z of the face's plane on the ray through image-plane point s.
double depthAt(const ScreenFace& f, const glm::dvec2& s, bool parallel)
{
    return parallel ? (f.offset - f.normal.x * s.x - f.normal.y * s.y) / f.normal.z
                    : f.offset / glm::dot(f.normal, glm::dvec3(s, 1.0));
}

}  // namespace

std::vector<VisibilitySorter::Behind> VisibilitySorter::boundaryOrder(const Camera& camera, BoundaryStats& stats,
                                                                      int width, int height) const
{
    const auto t0 = std::chrono::steady_clock::now();
    stats = BoundaryStats{};
    const glm::dvec3 eye = camera.position, forward = camera.forward(), right = camera.right(), up = camera.up();
    const bool parallel = camera.parallel;
    auto toCamera = [&](const glm::dvec3& p) {
        const glm::dvec3 d = p - eye;
        return glm::dvec3(glm::dot(d, right), glm::dot(d, up), glm::dot(d, forward));
    };
    double depthScale = 0.0;
    for (const OuterFace& face : boundary_)
        for (const glm::dvec3& p : face.points)
            depthScale = std::max(depthScale, std::abs(glm::dot(p - eye, forward)));
    const double zNear = 1e-6 * depthScale;  // perspective: what is nearer cannot be projected
    // The view on the image plane (PixelRays: |x| <= scale * aspect, |y| <= scale), grown by 2 pixels.
    const bool windowed = width > 0 && height > 0;
    glm::dvec2 window(0.0);
    if (windowed) {
        const double full = camera.fullHeight(height);
        const double scale = parallel ? camera.parallelScale : std::tan(glm::radians(camera.viewAngle) * 0.5);
        window = scale * glm::dvec2(width / full, 1.0) + glm::dvec2(4.0 * scale / full);
    }

    // Every boundary face the rays enter or leave the mesh by, projected: in chunks on the host's threads, each
    // chunk's faces in its own lists, joined in the faces' order.
    const std::size_t faceChunks = (boundary_.size() + kHostChunk - 1) / kHostChunk;
    std::vector<std::vector<ScreenFace>> chunkExits(faceChunks), chunkEntries(faceChunks);
    forHostChunks(hostChunkThreads(boundary_.size()), boundary_.size(), [&](std::size_t begin, std::size_t end) {
        std::vector<ScreenFace>& chunkExit = chunkExits[begin / kHostChunk];
        std::vector<ScreenFace>& chunkEntry = chunkEntries[begin / kHostChunk];
        for (std::size_t faceIndex = begin; faceIndex < end; ++faceIndex) {
            const OuterFace& face = boundary_[faceIndex];
            const double side = parallel ? -glm::dot(face.normal, forward) : glm::dot(face.normal, eye) - face.offset;
            if (side == 0.0 || !std::isfinite(side))
                continue;  // seen edge-on
            Convex<glm::dvec3> solid;
            for (const glm::dvec3& p : face.points)
                solid.p[solid.n++] = toCamera(p);
            if (!parallel)
                solid = clipConvex(solid, [&](const glm::dvec3& p) { return p.z - zNear; });
            if (windowed)  // |x| <= window.x (times z, perspective), |y| <= window.y: four planes in 3D
                for (int axis = 0; axis < 2; ++axis)
                    for (const double sign : {1.0, -1.0})
                        solid = clipConvex(solid, [&](const glm::dvec3& p) {
                            return window[axis] * (parallel ? 1.0 : p.z) - sign * p[axis];
                        });
            if (solid.n < 3)
                continue;
            ScreenFace s;
            s.cell = face.cell;
            s.zMin = std::numeric_limits<double>::infinity();
            s.zMax = -s.zMin;
            for (int i = 0; i < solid.n; ++i) {
                const glm::dvec3& p = solid.p[i];
                s.shape.p[i] = parallel ? glm::dvec2(p.x, p.y) : glm::dvec2(p.x / p.z, p.y / p.z);
                s.zMin = std::min(s.zMin, p.z);
                s.zMax = std::max(s.zMax, p.z);
            }
            s.shape.n = solid.n;
            const double area = signedArea(s.shape);
            if (!(std::abs(area) > 0.0))
                continue;
            if (area < 0.0)
                std::reverse(s.shape.p.begin(), s.shape.p.begin() + s.shape.n);
            s.lo = s.hi = s.shape.p[0];
            for (int i = 1; i < s.shape.n; ++i) {
                s.lo = glm::min(s.lo, s.shape.p[i]);
                s.hi = glm::max(s.hi, s.shape.p[i]);
            }
            s.normal =
                glm::dvec3(glm::dot(face.normal, right), glm::dot(face.normal, up), glm::dot(face.normal, forward));
            s.offset = face.offset - glm::dot(face.normal, eye);
            (side < 0.0 ? chunkExit : chunkEntry).push_back(s);
        }
    });
    std::vector<ScreenFace> exits, entries;
    for (std::size_t c = 0; c < faceChunks; ++c) {
        exits.insert(exits.end(), chunkExits[c].begin(), chunkExits[c].end());
        entries.insert(entries.end(), chunkEntries[c].begin(), chunkEntries[c].end());
    }
    stats.exitFaces = exits.size();
    stats.entryFaces = entries.size();
    if (exits.empty() || entries.empty()) {
        stats.ms = msSince(t0);
        return {};
    }

    // The exit faces binned on a grid over their bounds, about one face per bin.
    glm::dvec2 lo = exits[0].lo, hi = exits[0].hi;
    for (const ScreenFace& f : exits) {
        lo = glm::min(lo, f.lo);
        hi = glm::max(hi, f.hi);
    }
    const int bins = std::clamp(static_cast<int>(std::ceil(std::sqrt(static_cast<double>(exits.size())))), 1, 2048);
    const glm::dvec2 extent = glm::max(hi - lo, glm::dvec2(1e-300));
    auto bin = [&](double x, double origin, double size) {
        const double b = std::floor((x - origin) / size * bins);
        return static_cast<int>(std::clamp(b, 0.0, static_cast<double>(bins - 1)));
    };
    std::vector<std::uint32_t> start(static_cast<std::size_t>(bins) * bins + 1, 0), members;
    auto forBins = [&](const ScreenFace& f, auto visit) {
        const int x0 = bin(f.lo.x, lo.x, extent.x), x1 = bin(f.hi.x, lo.x, extent.x);
        const int y0 = bin(f.lo.y, lo.y, extent.y), y1 = bin(f.hi.y, lo.y, extent.y);
        for (int y = y0; y <= y1; ++y)
            for (int x = x0; x <= x1; ++x)
                visit(static_cast<std::size_t>(y) * bins + x);
    };
    for (const ScreenFace& f : exits)
        forBins(f, [&](std::size_t b) { ++start[b + 1]; });
    for (std::size_t b = 0; b + 1 < start.size(); ++b)
        start[b + 1] += start[b];
    members.resize(start.back());
    {
        std::vector<std::uint32_t> fill(start.begin(), start.end() - 1);
        for (std::uint32_t i = 0; i < exits.size(); ++i)
            forBins(exits[i], [&](std::size_t b) { members[fill[b]++] = i; });
    }

    const double minArea = 1e-12 * std::max(extent.x, extent.y) * std::max(extent.x, extent.y);
    const double depthTolerance = 1e-9 * depthScale;
    // The entry faces in chunks on the host's threads, each chunk's relations in its own list, joined in order.
    constexpr std::size_t kEntryChunk = 512;
    const std::size_t entryChunks = (entries.size() + kEntryChunk - 1) / kEntryChunk;
    std::vector<std::vector<Behind>> chunkRelations(entryChunks);
    std::vector<std::uint64_t> chunkPairs(entryChunks, 0);
    const int entryThreads = hostChunkThreads(entries.size(), kEntryChunk);
    forHostChunks(entryThreads, entries.size(), [&](std::size_t begin, std::size_t end) {
        std::vector<Behind>& relations = chunkRelations[begin / kEntryChunk];
        std::uint64_t& pairsTested = chunkPairs[begin / kEntryChunk];
        for (std::size_t entryIndex = begin; entryIndex < end; ++entryIndex) {
            const ScreenFace& entry = entries[entryIndex];
            if (entry.hi.x < lo.x || entry.hi.y < lo.y || entry.lo.x > hi.x || entry.lo.y > hi.y)
                continue;
            forBins(entry, [&](std::size_t b) {
                for (std::uint32_t k = start[b]; k < start[b + 1]; ++k) {
                    const ScreenFace& exit = exits[members[k]];
                    const glm::dvec2 overlapLo = glm::max(entry.lo, exit.lo), overlapHi = glm::min(entry.hi, exit.hi);
                    if (overlapLo.x >= overlapHi.x || overlapLo.y >= overlapHi.y || exit.cell == entry.cell)
                        continue;
                    // Each pair once: in the bin of its bounds' overlap's low corner.
                    const std::size_t lowCorner = static_cast<std::size_t>(bin(overlapLo.y, lo.y, extent.y)) * bins +
                                                  static_cast<std::size_t>(bin(overlapLo.x, lo.x, extent.x));
                    if (lowCorner != b)
                        continue;
                    if (entry.zMax < exit.zMin - depthTolerance)
                        continue;  // the entry face is in front of the exit face wherever they overlap
                    ++pairsTested;
                    Convex<glm::dvec2> overlap = entry.shape;
                    for (int e = 0; e < exit.shape.n && overlap.n >= 3; ++e) {
                        const glm::dvec2 a = exit.shape.p[e], d = exit.shape.p[(e + 1) % exit.shape.n] - a;
                        const auto left = [&](const glm::dvec2& p) { return d.x * (p.y - a.y) - d.y * (p.x - a.x); };
                        overlap = clipConvex(overlap, left);
                    }
                    if (overlap.n < 3 || !(signedArea(overlap) > minArea))
                        continue;
                    glm::dvec2 inside(0.0);
                    for (int i = 0; i < overlap.n; ++i)
                        inside += overlap.p[i];
                    inside /= static_cast<double>(overlap.n);
                    // The faces cross no ray at the same point except where they coincide (two parts of the
                    // mesh that touch without sharing points): there the ray leaves one and enters the other.
                    if (entry.zMin >= exit.zMax ||
                        depthAt(entry, inside, parallel) >= depthAt(exit, inside, parallel) - depthTolerance) {
                        relations.push_back({entry.cell, exit.cell});
                    }
                }
            });
        }
    }, kEntryChunk);
    std::vector<Behind> relations;
    for (std::size_t c = 0; c < entryChunks; ++c) {
        relations.insert(relations.end(), chunkRelations[c].begin(), chunkRelations[c].end());
        stats.pairsTested += chunkPairs[c];
    }
    stats.relations = relations.size();
    stats.ms = msSince(t0);
    return relations;
}

// ---- Shirley-Tuchman classification -----------------------------------------------------------------

namespace {

double orient(const glm::dvec2& a, const glm::dvec2& b, const glm::dvec2& c)
{
    return (b.x - a.x) * (c.y - a.y) - (b.y - a.y) * (c.x - a.x);
}

}  // namespace

ProjectedTet classifyProjection(const std::array<glm::dvec2, 4>& p)
{
    ProjectedTet r;
    // Class 1: vertex i inside (or on) the triangle of the other three.
    for (int i = 0; i < 4; ++i) {
        int o[3], n = 0;
        for (int j = 0; j < 4; ++j)
            if (j != i)
                o[n++] = j;
        const double area = orient(p[o[0]], p[o[1]], p[o[2]]);
        if (area == 0.0)
            continue;
        const double s1 = orient(p[o[0]], p[o[1]], p[i]), s2 = orient(p[o[1]], p[o[2]], p[i]),
                     s3 = orient(p[o[2]], p[o[0]], p[i]);
        const bool inside = area > 0.0 ? (s1 >= 0.0 && s2 >= 0.0 && s3 >= 0.0) : (s1 <= 0.0 && s2 <= 0.0 && s3 <= 0.0);
        if (!inside)
            continue;
        r.kind = ProjectedTet::Kind::Class1;
        r.thick = p[i];
        r.thickVertex = i;
        r.triangles = {{{i, o[0], o[1]}, {i, o[1], o[2]}, {i, o[2], o[0]}, {0, 0, 0}}};
        r.triangleCount = 3;
        r.outer = {o[0], o[1], o[2], 0};
        r.outerCount = 3;
        return r;
    }
    // Class 2: the diagonals (a, b) and (c, d) of a convex quadrilateral cross at the thick vertex.
    const int pairs[3][4] = {{0, 1, 2, 3}, {0, 2, 1, 3}, {0, 3, 1, 2}};
    for (const auto& q : pairs) {
        const int a = q[0], b = q[1], c = q[2], d = q[3];
        const double o1 = orient(p[a], p[b], p[c]), o2 = orient(p[a], p[b], p[d]);
        const double o3 = orient(p[c], p[d], p[a]), o4 = orient(p[c], p[d], p[b]);
        if (!(o1 * o2 < 0.0 && o3 * o4 < 0.0))
            continue;
        r.kind = ProjectedTet::Kind::Class2;
        r.thick = p[a] + (o3 / (o3 - o4)) * (p[b] - p[a]);
        r.triangles = {{{4, a, c}, {4, c, b}, {4, b, d}, {4, d, a}}};
        r.triangleCount = 4;
        r.outer = {a, c, b, d};
        r.outerCount = 4;
        return r;
    }
    return r;  // no area: nothing to draw
}

// ---- the renderer -----------------------------------------------------------------------------------

namespace {

// Conservative coverage: each silhouette grows by this much (pixels; snapping moves corners 1/512 at
// most), its corners by at most kMaxMiterPixels.
constexpr double kGrowPixels = 1.0 / 16.0;
constexpr double kMaxMiterPixels = 1.0;

// Both paths' projection of the cells' points: the near plane in front of every cell but those at the eye (a
// 10,000th of the farthest point's eye depth), the far plane beyond the mesh.
struct CellProjection {
    CellProjection(const std::vector<glm::dvec3>& points, const Camera& camera, int width, int height)
    {
        const glm::dvec3 forward = camera.forward();
        double depthMax = 0.0;
        for (const glm::dvec3& p : points)
            depthMax = std::max(depthMax, glm::dot(p - camera.position, forward));
        nearZ = 1e-4 * depthMax + 1e-9;
        viewProjection = camera.projectionMatrix(width, height, nearZ, 2.0 * depthMax + 1.0) * camera.viewMatrix();
    }
    double nearZ;
    glm::dmat4 viewProjection;
};

std::string projtetFragmentSource()
{
    return "#define CLVR_PROJTET_FRAGMENT 1\n" + std::string(embeddedKernelSource("projtet.cl"));
}

class ProjtetRenderer final : public Renderer {
public:
    ProjtetRenderer(Device& device, const Scene& scene, const TetMesh& mesh, const TetTopology& topology);
    Image4f render(FrameStats& stats) override;
    std::uint64_t residentBytes() const override { return residentBytes_; }
    void setTransferFunction(const TransferFunction& tf) override
    {
        tf_.replace(device_, "projtet transfer function", tf, residentBytes_);
    }
    // Every frame sorts, projects and draws from camera_: a new view is a new camera.
    bool setCamera(const Scene& scene) override
    {
        if (!sameImageSize(scene.image, image_))
            return false;  // the frame buffer would change
        image_ = scene.image;
        camera_ = frameCamera(scene, meshLo_, meshHi_);
        return true;
    }

private:
    Device& device_;
    ProjtetOptions options_;
    Camera camera_;  // world coordinates (the host's sort and projection are in double)
    glm::dvec3 meshLo_{0.0}, meshHi_{0.0};  // the mesh's bounds, which frame the camera
    ImageSpec image_;
    glm::dvec3 shift_{0.0};
    std::vector<glm::dvec3> points_;
    std::vector<glm::uvec4> tets_;
    VisibilitySorter sorter_;
    MeshCounts counts_;
    TransferFunctionUpload tf_;
    cl::Buffer cells_, psi_;
    raster::Rasterizer rasterizer_;
    raster::Framebuffer fb_;
    raster::FragmentProgram program_;
    OverBackground overBackground_;
    std::vector<raster::Vertex> vertices_;  // the frame's triangles, 3 vertices each
    std::uint64_t residentBytes_ = 0;
    // The fused path: its kernel, its per-pixel outputs, and the frame's boxes and tile lists (grown as needed).
    cl::Kernel fused_;
    bool packet_ = false;  // fused_ is projtet_fused_packet
    cl::Buffer fusedOut_, fusedSegments_;
    StagingBuffer boxes_, tileStart_, tileCells_;

    // The fused path's frame after the sort (ProjtetOptions::Path::Fused).
    Image4f renderFused(const VisibilitySorter::Result& sorted, std::vector<PassTime> hostPasses,
                        const FrameClock& clock, FrameStats& stats);
    // The stats both paths report: the order and the sort, the counts, the integration.
    void reportOrder(const VisibilitySorter::Result& sorted, double boundaryMs, double sortMs, FrameStats& stats) const;
};

ProjtetRenderer::ProjtetRenderer(Device& device, const Scene& scene, const TetMesh& mesh, const TetTopology& topology)
    : device_(device), options_(parseProjtetOptions(scene.options)), image_(scene.image),
      shift_(0.5 * (mesh.boundsMin() + mesh.boundsMax())), points_(mesh.points), tets_(mesh.tets.begin(), mesh.tets.end()),
      sorter_(mesh, topology), rasterizer_(device), fb_(device, scene.image.width, scene.image.height),
      overBackground_(device)
{
    if (mesh.tets.empty())
        throw InputError(mesh.source + ": projtet needs a mesh with at least one tetrahedron");
    if (mesh.tets.size() >= (std::size_t(1) << 24))
        throw InputError(mesh.source + ": projtet takes fewer than 2^24 tetrahedra (ids in two 12-bit halves)");
    meshLo_ = mesh.boundsMin();
    meshHi_ = mesh.boundsMax();
    camera_ = frameCamera(scene, meshLo_, meshHi_);
    counts_ = MeshCounts::of(mesh);
    const std::vector<cl_float4> cells = packHarcTets(mesh, topology, shift_);
    cells_ = device_.upload("projtet tetrahedra (harc's 80 bytes each)", cells);
    tf_.upload(device_, "projtet transfer function", scene.transferFunction);
    const PsiTable& psi = psiTable();
    psi_ = device_.upload("projtet psi table", psi.values);
    residentBytes_ = cells.size() * sizeof(cl_float4) + tf_.bytes() + psi.values.size() * sizeof(float);
    program_.source = projtetFragmentSource();
    program_.attributes = 1;  // the cell id
    program_.buffers[0] = cells_;
    program_.buffers[2] = psi_;
    if (options_.path == ProjtetOptions::Path::Fused) {
        if (image_.width > kTileImageMax || image_.height > kTileImageMax)
            throw InputError("projtet: \"path\": \"fused\" takes images of at most " + std::to_string(kTileImageMax) +
                             " pixels a side, got " +
                             std::to_string(image_.width) + "x" + std::to_string(image_.height));
        packet_ = packetsOnDevice(options_.packets, device_);
        fused_ = device_.kernel("projtet.cl", packet_ ? "projtet_fused_packet" : "projtet_fused");
        const std::size_t pixels = static_cast<std::size_t>(image_.width) * image_.height;
        fusedOut_ = device_.buffer("projtet fused image", pixels * sizeof(cl_float4));
        fusedSegments_ = device_.buffer("projtet fused segments per pixel", pixels * sizeof(cl_uint));
        residentBytes_ += pixels * (sizeof(cl_float4) + sizeof(cl_uint));
    }
}

// The fused path: the cells' boxes of pixel centres (projtetCellBoxes), the cells binned to tiles of
// kProjtetTileW x kProjtetTileH pixels in visibility order (binToTiles), then kernels/projtet.cl's projtet_fused (or
// its packets) over the image.
Image4f ProjtetRenderer::renderFused(const VisibilitySorter::Result& sorted, std::vector<PassTime> hostPasses,
                                     const FrameClock& clock, FrameStats& stats)
{
    auto t0 = std::chrono::steady_clock::now();
    const int width = image_.width, height = image_.height;
    const std::vector<ProjtetBox> boxes = projtetCellBoxes(points_, tets_, camera_, width, height);
    const TileLists lists = binToTiles(boxes, sorted.order, width, height, kProjtetTileW, kProjtetTileH,
                                       "projtet: \"path\": \"fused\"", "use \"path\": \"raster\" or a smaller image");
    const int tilesX = lists.tilesX, tilesY = lists.tilesY;
    const std::uint64_t entries = lists.items.size();
    static_assert(sizeof(ProjtetBox) == sizeof(cl_short4));
    boxes_.write(device_, "projtet fused cell boxes", boxes.data(), boxes.size() * sizeof(ProjtetBox), residentBytes_);
    tileStart_.write(device_, "projtet fused tile starts", lists.start.data(), lists.start.size() * sizeof(cl_uint),
                     residentBytes_);
    tileCells_.write(device_, "projtet fused tile cells", lists.items.data(), lists.items.size() * sizeof(cl_uint),
                     residentBytes_);
    hostPasses.push_back({"projtet: cell boxes and tile lists (host)", msSince(t0)});

    ClProjtetFusedParams p{};
    p.camera = toClCamera(camera_, width, height, shift_);
    p.background = toCl4(image_.background, 0.0);
    p.size = cl_int4{{width, height, tilesX, tilesY}};
    p.counts = cl_int4{{static_cast<cl_int>(tf_.count()), static_cast<cl_int>(psiTable().size), 0, 0}};
    int a = 0;
    fused_.setArg(a++, fusedOut_);
    fused_.setArg(a++, fusedSegments_);
    fused_.setArg(a++, tileStart_.buffer());
    fused_.setArg(a++, tileCells_.buffer());
    fused_.setArg(a++, boxes_.buffer());
    fused_.setArg(a++, cells_);
    fused_.setArg(a++, tf_.buffer());
    fused_.setArg(a++, psi_);
    fused_.setArg(a++, p);
    if (packet_)  // a work-item per tile
        device_.launch("projtet: fused", fused_, static_cast<std::size_t>(tilesX), static_cast<std::size_t>(tilesY), 1, 1);
    else
        device_.launch("projtet: fused", fused_, static_cast<std::size_t>(width), static_cast<std::size_t>(height),
                       kProjtetTileW, kProjtetTileH);
    Image4f image = readImage(device_, fusedOut_, width, height);
    const std::uint64_t segments = sumCounts(device_, fusedSegments_, static_cast<std::size_t>(width) * height);

    finishFrame(device_, clock, stats, std::move(hostPasses));
    stats.extra["path"] = "fused";
    stats.extra["steps"] = segments;  // the segments integrated: rays that meet a cell
    stats.extra["tile_entries"] = entries;
    stats.extra["tile_size"] = {kProjtetTileW, kProjtetTileH};
    stats.extra["packets"] = packet_;
    return image;
}

Image4f ProjtetRenderer::render(FrameStats& stats)
{
    const FrameClock clock;
    auto t0 = std::chrono::steady_clock::now();
    const VisibilitySorter::Result sorted = sorter_.sort(camera_, options_.order, image_.width, image_.height);
    const double boundaryMs = sorted.boundary.ms;
    const double sortMs = msSince(t0) - boundaryMs;
    std::vector<PassTime> hostPasses;
    if (options_.order == ProjtetOptions::Order::MpvoncBoundary)
        hostPasses.push_back({"projtet: boundary overlaps (host)", boundaryMs});
    hostPasses.push_back({"projtet: visibility sort (host)", sortMs});
    if (options_.path == ProjtetOptions::Path::Fused) {
        Image4f image = renderFused(sorted, std::move(hostPasses), clock, stats);
        reportOrder(sorted, boundaryMs, sortMs, stats);
        return image;
    }

    // Projection: every point to normalized device coordinates (double, then float as the raster stage
    // gets them, so neighbouring cells share their silhouette edges bit for bit). A cell with a point at
    // or behind the near plane is drawn as its back faces in clip space instead (the raster stage clips):
    // every ray that meets such a cell in front of the eye leaves it through a back face in front of the
    // eye, also when the eye is inside the cell (which has no front face).
    t0 = std::chrono::steady_clock::now();
    const CellProjection projection(points_, camera_, image_.width, image_.height);
    const double nearZ = projection.nearZ;
    const glm::dmat4& viewProjection = projection.viewProjection;
    std::vector<glm::vec4> clip(points_.size());
    std::vector<glm::dvec2> ndc(points_.size());
    std::vector<std::uint8_t> inFront(points_.size());
    const std::size_t cellCount = sorted.order.size();
    // On the host's threads, in chunks of cells taken from a shared counter: the points, then each cell's
    // vertex count, then (at offsets from their prefix sum, so the triangles stay in visibility order, the same
    // vertices as one thread writes) the vertices themselves.
    const int threads = hostChunkThreads(std::max(points_.size(), cellCount));
    auto inChunks = [&](std::size_t n, const auto& work) { forHostChunks(threads, n, work); };
    inChunks(points_.size(), [&](std::size_t begin, std::size_t end) {
        for (std::size_t p = begin; p < end; ++p) {
            const glm::dvec4 c = viewProjection * glm::dvec4(points_[p], 1.0);
            clip[p] = glm::vec4(c);
            inFront[p] = camera_.parallel || c.w > nearZ;
            ndc[p] = glm::dvec2(glm::vec2(static_cast<float>(c.x / c.w), static_cast<float>(c.y / c.w)));
        }
    });
    const glm::dvec2 pixelScale(0.5 * image_.width, 0.5 * image_.height);  // NDC to pixels
    // Cell t's vertices, written to `out` when it is not null; returns their number. Counts its kind.
    struct Kinds {
        std::uint64_t class1 = 0, class2 = 0, degenerate = 0, nearCells = 0;
    };
    auto emitCell = [&](std::uint32_t t, raster::Vertex* out, Kinds& kinds) -> std::uint32_t {
        const glm::uvec4 tet = tets_[t];
        const glm::vec4 id(static_cast<float>(t & 4095u), static_cast<float>(t >> 12), 0.0f, 0.0f);
        std::uint32_t written = 0;
        auto vertex = [&](const glm::vec4& position) {
            if (out) {
                raster::Vertex& v = out[written];
                v.position = position;
                v.attributes = {};
                v.attributes[0] = id;
            }
            ++written;
        };
        if (!(inFront[tet[0]] && inFront[tet[1]] && inFront[tet[2]] && inFront[tet[3]])) {
            ++kinds.nearCells;
            for (int f = 0; f < 4; ++f) {
                int corner[3], n = 0;
                for (int i = 0; i < 4; ++i)
                    if (i != f)
                        corner[n++] = static_cast<int>(tet[i]);
                const glm::dvec3 a = points_[corner[0]], b = points_[corner[1]], c = points_[corner[2]];
                glm::dvec3 normal = glm::cross(b - a, c - a);
                if (glm::dot(normal, points_[tet[f]] - a) > 0.0)
                    normal = -normal;  // out of the cell
                if (glm::dot(normal, camera_.position - a) <= 0.0)  // faces away: a ray's exit, beyond the eye
                    for (const int k : corner)
                        vertex(clip[k]);
            }
            return written;
        }
        const std::array<glm::dvec2, 4> q = {ndc[tet[0]], ndc[tet[1]], ndc[tet[2]], ndc[tet[3]]};
        const ProjectedTet pt = classifyProjection(q);
        if (pt.kind == ProjectedTet::Kind::Degenerate) {
            ++kinds.degenerate;
            return 0;
        }
        (pt.kind == ProjectedTet::Kind::Class1 ? kinds.class1 : kinds.class2)++;
        if (!out)
            return static_cast<std::uint32_t>(3 * pt.triangleCount);
        // Conservative coverage: the silhouette's corners moved outwards by kGrowPixels (miter, capped),
        // so that no pixel centre the cell's own ray meets is lost to the raster stage's 1/256-pixel
        // snapping at a silhouette edge; the fragment's exact ray-cell intersection makes the extra
        // fragments empty (discarded), so nothing is counted twice.
        std::array<glm::dvec2, 4> corner = q;
        double signedArea = 0.0;
        for (int k = 0; k < pt.outerCount; ++k) {
            const glm::dvec2 a = q[pt.outer[k]] * pixelScale, b = q[pt.outer[(k + 1) % pt.outerCount]] * pixelScale;
            signedArea += a.x * b.y - a.y * b.x;
        }
        const double sigma = signedArea >= 0.0 ? 1.0 : -1.0;
        auto outward = [&](int from, int to) {
            const glm::dvec2 e = (q[to] - q[from]) * pixelScale;
            const double len = glm::length(e);
            return len > 0.0 ? sigma * glm::dvec2(e.y, -e.x) / len : glm::dvec2(0.0);
        };
        for (int k = 0; k < pt.outerCount; ++k) {
            const int v = pt.outer[k];
            const int prev = pt.outer[(k + pt.outerCount - 1) % pt.outerCount], next = pt.outer[(k + 1) % pt.outerCount];
            const glm::dvec2 n0 = outward(prev, v), n1 = outward(v, next);
            glm::dvec2 offset = kGrowPixels * (n0 + n1) / std::max(1.0 + glm::dot(n0, n1), 1e-3);
            const double length = glm::length(offset);
            if (length > kMaxMiterPixels)
                offset *= kMaxMiterPixels / length;
            corner[v] = q[v] + offset / pixelScale;
        }
        const glm::vec4 thick(static_cast<float>(pt.thick.x), static_cast<float>(pt.thick.y), 0.0f, 1.0f);
        for (int k = 0; k < pt.triangleCount; ++k)
            for (const int c : pt.triangles[k])
                vertex(c == 4 ? thick
                              : glm::vec4(static_cast<float>(corner[c].x), static_cast<float>(corner[c].y), 0.0f, 1.0f));
        return written;
    };
    std::vector<std::uint64_t> first(cellCount + 1, 0);  // cell i's vertices start at first[i]
    std::atomic<std::uint64_t> class1{0}, class2{0}, degenerate{0}, nearCells{0};
    inChunks(cellCount, [&](std::size_t begin, std::size_t end) {
        Kinds kinds;
        for (std::size_t i = begin; i < end; ++i)
            first[i + 1] = emitCell(sorted.order[i], nullptr, kinds);
        class1 += kinds.class1;
        class2 += kinds.class2;
        degenerate += kinds.degenerate;
        nearCells += kinds.nearCells;
    });
    for (std::size_t i = 0; i < cellCount; ++i)
        first[i + 1] += first[i];
    std::vector<raster::Vertex>& vertices = vertices_;  // kept: its pages are touched once, not every frame
    vertices.resize(first[cellCount]);
    inChunks(cellCount, [&](std::size_t begin, std::size_t end) {
        Kinds ignored;
        for (std::size_t i = begin; i < end; ++i)
            emitCell(sorted.order[i], vertices.data() + first[i], ignored);
    });
    const double projectMs = msSince(t0);

    // Back to front, premultiplied: dst = src + (1 - src.alpha) dst (GL_ONE, GL_ONE_MINUS_SRC_ALPHA).
    raster::DrawState state;
    state.fragment.blend = raster::premultipliedOver();
    ClProjtetUniforms uniforms{};
    uniforms.camera = toClCamera(camera_, image_.width, image_.height, shift_);
    uniforms.counts = cl_float4{{static_cast<float>(image_.width), static_cast<float>(image_.height),
                                 static_cast<float>(tf_.count()), static_cast<float>(psiTable().size)}};
    program_.uniforms = fragmentUniforms(uniforms);
    program_.buffers[1] = tf_.buffer();
    fb_.clearColor(device_, glm::vec4(0.0f));
    t0 = std::chrono::steady_clock::now();
    rasterizer_.draw(fb_, state, raster::Topology::Triangles, vertices, program_);
    const double setUpMs = msSince(t0);

    const std::size_t pixels = static_cast<std::size_t>(image_.width) * image_.height;
    overBackground_.run(fb_.color(), pixels, image_.background, "projtet: over background");
    Image4f image = readImage(device_, fb_.color(), image_.width, image_.height);
    const raster::DrawStats drawn = rasterizer_.takeStats();

    hostPasses.insert(hostPasses.end(), {{"projtet: projection and classification (host)", projectMs},
                                        {"projtet: raster set-up and binning (host)", setUpMs}});
    finishFrame(device_, clock, stats, std::move(hostPasses));
    reportOrder(sorted, boundaryMs, sortMs, stats);
    stats.extra["path"] = "raster";
    stats.extra["projection_ms"] = projectMs;
    stats.extra["cells_class1"] = class1.load();
    stats.extra["cells_class2"] = class2.load();
    stats.extra["cells_degenerate_projection"] = degenerate.load();
    stats.extra["cells_near_plane"] = nearCells.load();
    stats.extra["raster_triangles"] = drawn.triangles;
    stats.extra["raster_fragments"] = drawn.fragments;
    return image;
}

void ProjtetRenderer::reportOrder(const VisibilitySorter::Result& sorted, double boundaryMs, double sortMs,
                                  FrameStats& stats) const
{
    counts_.report(stats);
    stats.extra["resident_bytes"] = residentBytes_;
    stats.extra["bytes_per_tet"] = static_cast<double>(residentBytes_) / static_cast<double>(tets_.size());
    stats.extra["order"] = orderName(options_.order);
    stats.extra["order_cycles_broken"] = sorted.cyclesBroken;
    if (options_.order == ProjtetOptions::Order::MpvoncBoundary)
        stats.extra["order_waves"] = sorted.waves;
    stats.extra["sort_ms"] = sortMs;
    stats.extra["sort_threads"] = sorted.threads;
    if (options_.order == ProjtetOptions::Order::MpvoncBoundary) {
        stats.extra["boundary_ms"] = boundaryMs;
        stats.extra["boundary_exit_faces"] = sorted.boundary.exitFaces;
        stats.extra["boundary_entry_faces"] = sorted.boundary.entryFaces;
        stats.extra["boundary_pairs_tested"] = sorted.boundary.pairsTested;
        stats.extra["boundary_relations"] = sorted.boundary.relations;
    }
    stats.extra["integration"] = "partial";  // harc's partial pre-integration, per fragment
    stats.extra["psi_table"] = std::to_string(psiTable().size) + "x" + std::to_string(psiTable().size);
}

}  // namespace

std::vector<ProjtetBox> projtetCellBoxes(const std::vector<glm::dvec3>& points, const std::vector<glm::uvec4>& tets,
                                         const Camera& camera, int width, int height)
{
    // The raster path's projection: the same near plane, each point through float NDC to pixels.
    const CellProjection projection(points, camera, width, height);
    const double nearZ = projection.nearZ;
    const glm::dmat4& viewProjection = projection.viewProjection;
    std::vector<glm::dvec4> clip(points.size());
    std::vector<glm::vec2> window(points.size());  // pixel coordinates, row 0 at the top
    std::vector<std::uint8_t> inFront(points.size());
    std::vector<ProjtetBox> boxes(tets.size());
    const int threads = hostChunkThreads(std::max(points.size(), tets.size()));
    auto inChunks = [&](std::size_t n, const auto& work) { forHostChunks(threads, n, work); };
    auto toWindow = [&](const glm::dvec4& c) {
        const glm::vec2 ndc(static_cast<float>(c.x / c.w), static_cast<float>(c.y / c.w));
        return glm::vec2((ndc.x + 1.0f) * 0.5f * static_cast<float>(width),
                         (1.0f - ndc.y) * 0.5f * static_cast<float>(height));
    };
    inChunks(points.size(), [&](std::size_t begin, std::size_t end) {
        for (std::size_t p = begin; p < end; ++p) {
            clip[p] = viewProjection * glm::dvec4(points[p], 1.0);
            inFront[p] = camera.parallel || clip[p].w > nearZ;
            window[p] = toWindow(clip[p]);
        }
    });
    const auto margin = static_cast<float>(kGrowPixels);
    inChunks(tets.size(), [&](std::size_t begin, std::size_t end) {
        for (std::size_t t = begin; t < end; ++t) {
            const glm::uvec4 tet = tets[t];
            // The part of the cell beyond the near plane (the raster path clips there): its points in front and
            // where its edges cross the plane; nothing for a cell wholly nearer (behind the eye, say).
            glm::vec2 lo(std::numeric_limits<float>::infinity()), hi(-std::numeric_limits<float>::infinity());
            for (int v = 0; v < 4; ++v)
                if (inFront[tet[v]]) {
                    lo = glm::min(lo, window[tet[v]]);
                    hi = glm::max(hi, window[tet[v]]);
                }
            for (int a = 0; a < 4; ++a)
                for (int b = a + 1; b < 4; ++b)
                    if (inFront[tet[a]] != inFront[tet[b]]) {
                        const glm::dvec4 &ca = clip[tet[a]], &cb = clip[tet[b]];
                        const glm::vec2 w = toWindow(ca + (nearZ - ca.w) / (cb.w - ca.w) * (cb - ca));
                        lo = glm::min(lo, w);
                        hi = glm::max(hi, w);
                    }
            if (!(lo.x <= hi.x)) {
                boxes[t] = ProjtetBox{0, 0, -1, -1};
                continue;
            }
            // the pixel centres x + 0.5 in [lo - margin, hi + margin] that lie in the image: a first centre in
            // 0 .. last + 1, a last in -1 .. last (first > last: none)
            const auto firstCentre = [&](float v, int last) {
                const float limit = static_cast<float>(last) + 1.0f;
                return static_cast<std::int16_t>(std::clamp(std::ceil(v - margin - 0.5f), 0.0f, limit));
            };
            const auto lastCentre = [&](float v, int last) {
                const float limit = static_cast<float>(last);
                return static_cast<std::int16_t>(std::clamp(std::floor(v + margin - 0.5f), -1.0f, limit));
            };
            boxes[t] = ProjtetBox{firstCentre(lo.x, width - 1), firstCentre(lo.y, height - 1),
                                  lastCentre(hi.x, width - 1), lastCentre(hi.y, height - 1)};
        }
    });
    return boxes;
}

const char* orderName(ProjtetOptions::Order order)
{
    switch (order) {
    case ProjtetOptions::Order::MpvoncBoundary: return "mpvonc-boundary";
    case ProjtetOptions::Order::Mpvonc: return "mpvonc";
    case ProjtetOptions::Order::Centroid: return "centroid";
    }
    return "?";
}

TechniqueInfo projtetTechnique()
{
    TechniqueInfo t;
    t.name = "projtet";
    t.data = DataKind::Mesh;
    t.description = "cell projection (Shirley-Tuchman) in visibility order with partial pre-integration (docs/projtet.md)";
    t.options = {
        {"order", "mpvonc-boundary", "",
         "visibility order: \"mpvonc-boundary\" (adjacency and overlapping boundary faces, exact without cycles), "
         "\"mpvonc\" (adjacency only, Williams 1992: exact on convex meshes) or \"centroid\" (centre distance)"},
        packetsInfo(),
        {"path", "fused", "",
         "\"fused\" (cells binned to 8x4-pixel tiles, one kernel walks each pixel's cells in order) or \"raster\" "
         "(each cell's silhouette as 3-4 triangles through the raster stage, the paper's method; the same frame)"},
    };
    t.makeForMesh = [](Device& device, const Scene& scene, const TetMesh& mesh) -> std::unique_ptr<Renderer> {
        return makeProjtetRenderer(device, scene, mesh, buildTopology(mesh));
    };
    return t;
}

ProjtetOptions parseProjtetOptions(const nlohmann::json& options)
{
    static const TechniqueInfo& info = technique("projtet");
    ProjtetOptions o;
    forEachOption(options, info, [&](const std::string& key, const nlohmann::json& value) {
        if (key == "order") {
            const std::string s = value.is_string() ? value.get<std::string>() : "";
            if (s == "mpvonc-boundary")
                o.order = ProjtetOptions::Order::MpvoncBoundary;
            else if (s == "mpvonc")
                o.order = ProjtetOptions::Order::Mpvonc;
            else if (s == "centroid")
                o.order = ProjtetOptions::Order::Centroid;
            else
                badOption(key, "must be \"mpvonc-boundary\", \"mpvonc\" or \"centroid\", got " + value.dump());
        } else if (key == "packets") {
            o.packets = packetsOption(key, value);
        } else if (key == "path") {
            o.path = choiceOption(key, value, {"fused", "raster"}) == 0 ? ProjtetOptions::Path::Fused
                                                                       : ProjtetOptions::Path::Raster;
        } else {
            unparsedOption(info, key);
        }
    });
    return o;
}

std::unique_ptr<Renderer> makeProjtetRenderer(Device& device, const Scene& scene, const TetMesh& mesh,
                                              const TetTopology& topology)
{
    if (topology.neighbor.size() != mesh.tets.size())
        throw InternalError(mesh.source + ": topology does not match the mesh");
    return std::make_unique<ProjtetRenderer>(device, scene, mesh, topology);
}

}  // namespace clvr
