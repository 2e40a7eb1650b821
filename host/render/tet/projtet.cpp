// host/render/tet/projtet.cpp — options, the visibility sort (MPVONC or centre distance), the
// Shirley-Tuchman classification and the projtet renderer: one draw of every cell's projected triangles
// in visibility order through the raster stage, kernels/projtet.cl's fragment program per fragment.
#include "host/render/tet/projtet.h"

#include "host/optics/psi_table.h"
#include "host/render/camera_args.h"
#include "host/render/fragment_uniforms.h"
#include "host/render/options_util.h"
#include "host/render/scaffold.h"
#include "host/render/tet/harc.h"
#include "host/render/transfer_function_upload.h"
#include "host/runtime/embedded_kernels.h"
#include "host/runtime/errors.h"
#include "kernels/projtet_params.h"
#include "kernels/slice3d_params.h"  // ClSlice3dOverBackgroundParams: the last pass is slice3d's
#include "raster/framebuffer.h"
#include "raster/rasterizer.h"

#include <algorithm>
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
    centres_.resize(cells);
    for (std::uint32_t t = 0; t < cells; ++t) {
        glm::dvec3 c(0.0);
        for (int i = 0; i < 4; ++i)
            c += mesh.points[mesh.tets[t][i]];
        centres_[t] = 0.25 * c;
        for (std::uint32_t f = 0; f < 4; ++f) {
            const std::int32_t n = topology.neighbor[t][f];
            if (n <= static_cast<std::int32_t>(t))
                continue;  // the boundary, or the pair was taken from n
            const std::array<glm::dvec3, 3> p = outwardFace(mesh, t, f);
            const glm::dvec3 normal = glm::cross(p[1] - p[0], p[2] - p[0]);
            const std::int32_t index = static_cast<std::int32_t>(faces_.size());
            faces_.push_back({t, static_cast<std::uint32_t>(n), normal, glm::dot(normal, p[0])});
            faceOf_[t][f] = index;
            for (int g = 0; g < 4; ++g)
                if (topology.neighbor[n][g] == static_cast<std::int32_t>(t) && faceOf_[n][g] < 0) {
                    faceOf_[n][g] = index;
                    break;
                }
        }
    }
}

VisibilitySorter::Result VisibilitySorter::sort(const Camera& camera, ProjtetOptions::Order order) const
{
    const std::size_t cells = centres_.size();
    const glm::dvec3 eye = camera.position, forward = camera.forward();
    // Larger key = farther from the eye.
    std::vector<double> key(cells);
    for (std::size_t c = 0; c < cells; ++c)
        key[c] = camera.parallel ? glm::dot(centres_[c], forward) : glm::dot(centres_[c] - eye, centres_[c] - eye);
    Result result;
    result.order.reserve(cells);
    std::vector<std::uint32_t> byKey;
    auto farthestFirst = [&] {
        byKey.resize(cells);
        for (std::uint32_t c = 0; c < cells; ++c)
            byKey[c] = c;
        std::stable_sort(byKey.begin(), byKey.end(), [&](std::uint32_t a, std::uint32_t b) { return key[a] > key[b]; });
    };
    if (order == ProjtetOptions::Order::Centroid) {
        farthestFirst();
        result.order = std::move(byKey);
        return result;
    }

    // later[f]: 1 if faces_[f].b is drawn after a (a is behind it), 2 if a after b, 0 no constraint
    // (the eye in the face's plane).
    std::vector<std::uint8_t> later(faces_.size());
    std::vector<std::uint32_t> pending(cells, 0);  // cells behind c not yet emitted
    for (std::size_t f = 0; f < faces_.size(); ++f) {
        const InnerFace& face = faces_[f];
        // > 0: the eye (or, parallel, the direction towards it) is on b's side of the face, outside a.
        const double side = camera.parallel ? -glm::dot(face.normal, forward) : glm::dot(face.normal, eye) - face.offset;
        if (side > 0.0) {
            later[f] = 1;
            ++pending[face.b];
        } else if (side < 0.0) {
            later[f] = 2;
            ++pending[face.a];
        }
    }
    std::vector<std::uint8_t> emitted(cells, 0);
    std::priority_queue<std::pair<double, std::uint32_t>> ready;  // farthest first
    for (std::uint32_t c = 0; c < cells; ++c)
        if (pending[c] == 0)
            ready.push({key[c], c});
    auto emit = [&](std::uint32_t c) {
        emitted[c] = 1;
        result.order.push_back(c);
        for (const std::int32_t f : faceOf_[c]) {
            if (f < 0)
                continue;
            const InnerFace& face = faces_[f];
            const bool cIsA = face.a == c;
            if (later[f] != (cIsA ? 1 : 2))
                continue;  // c is not the one behind
            const std::uint32_t next = cIsA ? face.b : face.a;
            if (!emitted[next] && --pending[next] == 0)
                ready.push({key[next], next});
        }
    };
    std::size_t cursor = 0;
    while (result.order.size() < cells) {
        if (ready.empty()) {
            // A cycle: the farthest cell left goes next.
            if (byKey.empty())
                farthestFirst();
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

std::string fragmentSource()
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

private:
    Device& device_;
    ProjtetOptions options_;
    Camera camera_;  // world coordinates (the host's sort and projection are in double)
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
    cl::Kernel finish_;
    std::vector<raster::Vertex> vertices_;  // the frame's triangles, 3 vertices each
    std::uint64_t residentBytes_ = 0;
};

ProjtetRenderer::ProjtetRenderer(Device& device, const Scene& scene, const TetMesh& mesh, const TetTopology& topology)
    : device_(device), options_(parseProjtetOptions(scene.options)), image_(scene.image),
      shift_(0.5 * (mesh.boundsMin() + mesh.boundsMax())), points_(mesh.points), tets_(mesh.tets.begin(), mesh.tets.end()),
      sorter_(mesh, topology), rasterizer_(device), fb_(device, scene.image.width, scene.image.height)
{
    if (mesh.tets.empty())
        throw InputError(mesh.source + ": projtet needs a mesh with at least one tetrahedron");
    if (mesh.tets.size() >= (std::size_t(1) << 24))
        throw InputError(mesh.source + ": projtet takes fewer than 2^24 tetrahedra (ids in two 12-bit halves)");
    camera_ = frameCamera(scene, mesh.boundsMin(), mesh.boundsMax());
    counts_ = MeshCounts::of(mesh);
    const std::vector<cl_float4> cells = packHarcTets(mesh, topology, shift_);
    cells_ = device_.upload("projtet tetrahedra (harc's 80 bytes each)", cells);
    tf_.upload(device_, "projtet transfer function", scene.transferFunction);
    const PsiTable& psi = psiTable();
    psi_ = device_.upload("projtet psi table", psi.values);
    residentBytes_ = cells.size() * sizeof(cl_float4) + tf_.bytes() + psi.values.size() * sizeof(float);
    program_.source = fragmentSource();
    program_.attributes = 1;  // the cell id
    program_.buffers[0] = cells_;
    program_.buffers[2] = psi_;
    finish_ = device_.kernel("slice3d.cl", "slice3d_over_background");
}

Image4f ProjtetRenderer::render(FrameStats& stats)
{
    const FrameClock clock;
    auto t0 = std::chrono::steady_clock::now();
    const VisibilitySorter::Result sorted = sorter_.sort(camera_, options_.order);
    const double sortMs = msSince(t0);

    // Projection: every point to normalized device coordinates (double, then float as the raster stage
    // gets them, so neighbouring cells share their silhouette edges bit for bit). A cell with a point at
    // or behind the near plane is drawn as its back faces in clip space instead (the raster stage clips):
    // every ray that meets such a cell in front of the eye leaves it through a back face in front of the
    // eye, also when the eye is inside the cell (which has no front face).
    t0 = std::chrono::steady_clock::now();
    const glm::dvec3 forward = camera_.forward();
    double depthMax = 0.0;
    for (const glm::dvec3& p : points_)
        depthMax = std::max(depthMax, glm::dot(p - camera_.position, forward));
    const double nearZ = 1e-4 * depthMax + 1e-9;
    const double farZ = 2.0 * depthMax + 1.0;
    const glm::dmat4 viewProjection =
        camera_.projectionMatrix(image_.width, image_.height, nearZ, farZ) * camera_.viewMatrix();
    std::vector<glm::vec4> clip(points_.size());
    std::vector<glm::dvec2> ndc(points_.size());
    std::vector<std::uint8_t> inFront(points_.size());
    for (std::size_t p = 0; p < points_.size(); ++p) {
        const glm::dvec4 c = viewProjection * glm::dvec4(points_[p], 1.0);
        clip[p] = glm::vec4(c);
        inFront[p] = camera_.parallel || c.w > nearZ;
        ndc[p] = glm::dvec2(glm::vec2(static_cast<float>(c.x / c.w), static_cast<float>(c.y / c.w)));
    }
    const glm::dvec2 pixelScale(0.5 * image_.width, 0.5 * image_.height);  // NDC to pixels
    std::vector<raster::Vertex>& vertices = vertices_;  // kept: its pages are touched once, not every frame
    vertices.clear();
    std::uint64_t class1 = 0, class2 = 0, degenerate = 0, nearCells = 0;
    for (const std::uint32_t t : sorted.order) {
        const glm::uvec4 tet = tets_[t];
        const glm::vec4 id(static_cast<float>(t & 4095u), static_cast<float>(t >> 12), 0.0f, 0.0f);
        auto vertex = [&](const glm::vec4& position) {
            raster::Vertex v;
            v.position = position;
            v.attributes[0] = id;
            vertices.push_back(v);
        };
        if (!(inFront[tet[0]] && inFront[tet[1]] && inFront[tet[2]] && inFront[tet[3]])) {
            ++nearCells;
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
            continue;
        }
        const std::array<glm::dvec2, 4> q = {ndc[tet[0]], ndc[tet[1]], ndc[tet[2]], ndc[tet[3]]};
        const ProjectedTet pt = classifyProjection(q);
        if (pt.kind == ProjectedTet::Kind::Degenerate) {
            ++degenerate;
            continue;
        }
        (pt.kind == ProjectedTet::Kind::Class1 ? class1 : class2)++;
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
    }
    const double projectMs = msSince(t0);

    // Back to front, premultiplied: dst = src + (1 - src.alpha) dst (GL_ONE, GL_ONE_MINUS_SRC_ALPHA).
    raster::DrawState state;
    state.fragment.blend.enabled = true;
    state.fragment.blend.srcRgb = raster::BlendFactor::One;
    state.fragment.blend.dstRgb = raster::BlendFactor::OneMinusSrcAlpha;
    state.fragment.blend.srcAlpha = raster::BlendFactor::One;
    state.fragment.blend.dstAlpha = raster::BlendFactor::OneMinusSrcAlpha;
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
    ClSlice3dOverBackgroundParams finish{};
    finish.background = toCl4(image_.background);
    finish.count = static_cast<cl_int>(pixels);
    finish_.setArg(0, fb_.color());
    finish_.setArg(1, finish);
    device_.launch("projtet: over background", finish_, pixels);
    Image4f image = readImage(device_, fb_.color(), image_.width, image_.height);
    const raster::DrawStats drawn = rasterizer_.takeStats();

    std::vector<PassTime> hostPasses = {{"projtet: visibility sort (host)", sortMs},
                                        {"projtet: projection and classification (host)", projectMs},
                                        {"projtet: raster set-up and binning (host)", setUpMs}};
    finishFrame(device_, clock, stats, std::move(hostPasses));
    counts_.report(stats);
    stats.extra["resident_bytes"] = residentBytes_;
    stats.extra["bytes_per_tet"] = static_cast<double>(residentBytes_) / static_cast<double>(tets_.size());
    stats.extra["order"] = options_.order == ProjtetOptions::Order::Mpvonc ? "mpvonc" : "centroid";
    stats.extra["order_cycles_broken"] = sorted.cyclesBroken;
    stats.extra["sort_ms"] = sortMs;
    stats.extra["projection_ms"] = projectMs;
    stats.extra["cells_class1"] = class1;
    stats.extra["cells_class2"] = class2;
    stats.extra["cells_degenerate_projection"] = degenerate;
    stats.extra["cells_near_plane"] = nearCells;
    stats.extra["raster_triangles"] = drawn.triangles;
    stats.extra["raster_fragments"] = drawn.fragments;
    stats.extra["psi_table"] = std::to_string(psiTable().size) + "x" + std::to_string(psiTable().size);
    return image;
}

}  // namespace

TechniqueInfo projtetTechnique()
{
    TechniqueInfo t;
    t.name = "projtet";
    t.data = DataKind::Mesh;
    t.description = "cell projection (Shirley-Tuchman) in visibility order with partial pre-integration (docs/projtet.md)";
    t.options = {
        {"order", "mpvonc", "", "visibility order: \"mpvonc\" (adjacency, Williams 1992) or \"centroid\" (centre distance)"},
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
            if (s == "mpvonc")
                o.order = ProjtetOptions::Order::Mpvonc;
            else if (s == "centroid")
                o.order = ProjtetOptions::Order::Centroid;
            else
                badOption(key, "must be \"mpvonc\" or \"centroid\", got " + value.dump());
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
