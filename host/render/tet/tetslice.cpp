// host/render/tet/tetslice.cpp — options, active cell lists and the tetslice renderer: per slice two
// face draws through the raster stage (raster/rasterizer.h), the accumulation buffer between them, and
// kernels/tetslice.cl's composite pass.
#include "host/render/tet/tetslice.h"

#include "host/render/tet/cell_faces.h"
#include "host/render/tet/harc.h"

#include "host/render/camera_args.h"
#include "host/render/options_util.h"
#include "host/render/scaffold.h"
#include "host/render/slice_plan.h"
#include "host/render/transfer_function_upload.h"
#include "host/runtime/errors.h"
#include "kernels/tetslice_params.h"
#include "raster/framebuffer.h"
#include "raster/pixel_transfer.h"
#include "raster/rasterizer.h"

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <limits>
#include <string>

namespace clvr {

static_assert(sizeof(ClTetsliceCompositeParams) == 112, "also probed on the device by tests/layout_test.cpp");

// ---- active cell lists --------------------------------------------------------------------------------

namespace {

// CSR of `key[c]` (a slice, or -1 for none) over slices 0 .. count-1: cells with key k in
// cells[begin[k] .. begin[k+1]), in cell order.
void bucketBySlice(const std::vector<int>& key, int count, std::vector<std::uint32_t>& begin,
                   std::vector<std::uint32_t>& cells)
{
    begin.assign(static_cast<std::size_t>(count) + 1, 0);
    for (int k : key)
        if (k >= 0)
            ++begin[static_cast<std::size_t>(k) + 1];
    for (int k = 0; k < count; ++k)
        begin[k + 1] += begin[k];
    cells.resize(begin[count]);
    std::vector<std::uint32_t> cursor(begin.begin(), begin.end() - 1);
    for (std::size_t c = 0; c < key.size(); ++c)
        if (key[c] >= 0)
            cells[cursor[key[c]]++] = static_cast<std::uint32_t>(c);
}

}  // namespace

ActiveCellLists::ActiveCellLists(const std::vector<double>& zMin, const std::vector<double>& zMax, double depthMin,
                                 double deltaS, int count)
    : count_(count), k_(count)
{
    // Slice k is at depthMin + (k + 0.5) deltaS; cell c is cut by the slices k with zMin <= depth(k) <= zMax.
    std::vector<int> first(zMin.size(), -1), last(zMin.size(), -1);
    for (std::size_t c = 0; c < zMin.size(); ++c) {
        const double lo = std::ceil((zMin[c] - depthMin) / deltaS - 0.5);
        const double hi = std::floor((zMax[c] - depthMin) / deltaS - 0.5);
        const double k0 = std::max(lo, 0.0), k1 = std::min(hi, static_cast<double>(count - 1));
        if (!(k0 <= k1))
            continue;  // between two slices, or outside the slab (NaN-safe: false for NaN)
        first[c] = static_cast<int>(k0);
        last[c] = static_cast<int>(k1);
        ++listed_;
    }
    // Back to front, a cell starts at its farthest slice and ends after its nearest.
    bucketBySlice(last, count, startBegin_, startAt_);
    bucketBySlice(first, count, endBegin_, endAt_);
    place_.assign(zMin.size(), 0);
}

const std::vector<std::uint32_t>& ActiveCellLists::next()
{
    if (k_ <= 0)
        throw InternalError("ActiveCellLists::next called more than count times");
    // Cells whose nearest slice was the previous one leave (swap with the last, O(1) each).
    if (pendingEnd_) {
        for (std::uint32_t i = endBegin_[k_]; i < endBegin_[k_ + 1]; ++i) {
            const std::uint32_t cell = endAt_[i];
            const std::uint32_t at = place_[cell];
            active_[at] = active_.back();
            place_[active_[at]] = at;
            active_.pop_back();
        }
    }
    --k_;
    for (std::uint32_t i = startBegin_[k_]; i < startBegin_[k_ + 1]; ++i) {
        place_[startAt_[i]] = static_cast<std::uint32_t>(active_.size());
        active_.push_back(startAt_[i]);
    }
    pendingEnd_ = true;
    return active_;
}

// ---- the renderer -------------------------------------------------------------------------------------

namespace {


class TetsliceRenderer final : public Renderer {
public:
    TetsliceRenderer(Device& device, const Scene& scene, const TetMesh& mesh);
    Image4f render(FrameStats& stats) override;
    std::uint64_t residentBytes() const override { return residentBytes_; }
    void setTransferFunction(const TransferFunction& tf) override
    {
        tf_.replace(device_, "tetslice transfer function", tf, residentBytes_);
    }
    // Every frame plans its slices and draws them from camera_: a new view is a new camera.
    bool setCamera(const Scene& scene) override
    {
        if (!sameImageSize(scene.image, image_))
            return false;  // the frame buffer and the image would change
        image_ = scene.image;
        camera_ = frameCamera(scene, meshLo_, meshHi_).relativeTo(shift_);
        return true;
    }

private:
    Device& device_;
    TetsliceOptions options_;
    Camera camera_;  // relative to shift_
    ImageSpec image_;
    glm::dvec3 shift_{0.0}, lo_{0.0}, hi_{0.0};  // lo_, hi_: the mesh box, shifted
    glm::dvec3 meshLo_{0.0}, meshHi_{0.0};       // the mesh box in world coordinates, which frames the camera
    CellFaces cells_;
    std::vector<float> scalars_;
    MeshCounts counts_;
    TransferFunctionUpload tf_;
    raster::Rasterizer rasterizer_;
    raster::Framebuffer fb_;
    cl::Buffer image_buffer_;
    cl::Kernel composite_;
    OverBackground overBackground_;
    std::uint64_t residentBytes_ = 0;
};

TetsliceRenderer::TetsliceRenderer(Device& device, const Scene& scene, const TetMesh& mesh)
    : device_(device), options_(parseTetsliceOptions(scene.options)), image_(scene.image),
      shift_(0.5 * (mesh.boundsMin() + mesh.boundsMax())), cells_(mesh, shift_, "tetslice"), rasterizer_(device),
      fb_(device, scene.image.width, scene.image.height, true), overBackground_(device)
{
    const glm::dvec3 lo = mesh.boundsMin(), hi = mesh.boundsMax();
    lo_ = lo - shift_;
    hi_ = hi - shift_;
    meshLo_ = lo;
    meshHi_ = hi;
    camera_ = frameCamera(scene, lo, hi).relativeTo(shift_);
    counts_ = MeshCounts::of(mesh);

    scalars_.assign(mesh.scalars.begin(), mesh.scalars.end());

    tf_.upload(device_, "tetslice transfer function", scene.transferFunction);
    const std::size_t pixels = static_cast<std::size_t>(image_.width) * image_.height;
    image_buffer_ = device_.buffer("tetslice image", pixels * sizeof(cl_float4));
    composite_ = device_.kernel("tetslice.cl", "tetslice_composite");
    // Resident for the data: the transfer function. The mesh stays on the host; each slice's faces are
    // uploaded by the raster stage.
    residentBytes_ = tf_.bytes();
}

Image4f TetsliceRenderer::render(FrameStats& stats)
{
    const FrameClock clock;
    const SlicePlan plan = planSlices(camera_, lo_, hi_, options_.slices, options_.sliceSpacing);
    const std::size_t pixels = static_cast<std::size_t>(image_.width) * image_.height;
    device_.queue().enqueueFillBuffer(image_buffer_, cl_float4{{0.0f, 0.0f, 0.0f, 0.0f}}, 0,
                                      pixels * sizeof(cl_float4));

    // Per point: eye depth, clip position, vertex color (scalar, -, -, normalized eye depth t). The
    // alpha test compares t with the slice's t (GL clamps the reference to [0, 1]): t = 0 at the slab's
    // front, 1 at its back.
    auto t0 = std::chrono::steady_clock::now();
    const glm::dvec3 forward = camera_.forward();
    const double tScale = plan.depthMax > plan.depthMin ? 1.0 / (plan.depthMax - plan.depthMin) : 1.0;
    const double nearZ = plan.count ? 0.5 * plan.depth(0) : 1.0;
    const double farZ = 2.0 * plan.depthMax + 1.0;
    const glm::dmat4 viewProjection =
        camera_.projectionMatrix(image_.width, image_.height, nearZ, farZ) * camera_.viewMatrix();
    const std::vector<glm::dvec3>& points = cells_.points();
    std::vector<double> z(points.size());
    std::vector<raster::Vertex> pointVertex(points.size());
    for (std::size_t p = 0; p < points.size(); ++p) {
        z[p] = glm::dot(points[p] - camera_.position, forward);
        pointVertex[p].position = glm::vec4(viewProjection * glm::dvec4(points[p], 1.0));
        pointVertex[p].attributes[0] =
            glm::vec4(scalars_[p], 0.0f, 0.0f, static_cast<float>((z[p] - plan.depthMin) * tScale));
    }
    // Per cell: its eye-depth range, and which faces face away from the eye (drawn in the back-face pass)
    // or towards it (front-face pass).
    const std::size_t cells = cells_.cellCount();
    const std::vector<std::uint8_t> backMask = cells_.backFacing(camera_);
    std::vector<double> zMin(cells), zMax(cells);
    for (std::size_t c = 0; c < cells; ++c) {
        double lo = std::numeric_limits<double>::infinity(), hi = -lo;
        for (const std::uint32_t p : cells_.faces()[c]) {
            lo = std::min(lo, z[p]);
            hi = std::max(hi, z[p]);
        }
        zMin[c] = lo;
        zMax[c] = hi;
    }
    ActiveCellLists lists(zMin, zMax, plan.depthMin, plan.deltaS > 0.0 ? plan.deltaS : 1.0, plan.count);
    const double setUpMs = msSince(t0);

    // The two draws' state (GL: glAlphaFunc, glDepthFunc, glStencilFunc/Op; the color buffer is float).
    raster::DrawState back;
    back.fragment.alpha.test = true;
    back.fragment.alpha.func = raster::CompareFunc::GEqual;
    back.fragment.depth.test = true;
    back.fragment.depth.func = raster::CompareFunc::Less;
    back.fragment.stencil.test = true;
    back.fragment.stencil.func = raster::CompareFunc::Always;
    back.fragment.stencil.ref = 1;
    back.fragment.stencil.dppass = raster::StencilOp::Replace;  // set where the alpha and depth tests pass
    raster::DrawState front;
    front.fragment.alpha.test = true;
    front.fragment.alpha.func = raster::CompareFunc::LEqual;
    front.fragment.depth.test = true;
    front.fragment.depth.func = raster::CompareFunc::Greater;  // the farthest front face at or before d
    front.fragment.stencil.test = true;
    front.fragment.stencil.func = raster::CompareFunc::Equal;  // only where a back face was found
    front.fragment.stencil.ref = 1;
    front.fragment.stencil.writeMask = 0;

    ClTetsliceCompositeParams params{};
    params.camera = toClCamera(camera_, image_.width, image_.height);
    params.width = image_.width;
    params.height = image_.height;
    params.tf_count = tf_.count();
    params.delta_s = static_cast<float>(plan.deltaS);
    const glm::vec4 clear(0.0f, kNoFace, kNoFace, 0.0f);

    std::vector<raster::Vertex> backFaces, frontFaces;
    std::vector<std::uint32_t> cellsPerSlice(static_cast<std::size_t>(plan.count), 0);
    std::uint64_t cellsDrawn = 0;
    double buildMs = 0.0;
    for (int n = 0; n < plan.count; ++n) {
        const std::vector<std::uint32_t>& active = lists.next();
        const int k = lists.slice();
        cellsPerSlice[k] = static_cast<std::uint32_t>(active.size());
        cellsDrawn += active.size();
        if (active.empty())
            continue;
        t0 = std::chrono::steady_clock::now();
        backFaces.clear();
        frontFaces.clear();
        // Vertex colors (scalar, id low 12 bits, id high 12 bits, t); ids are exact in float.
        cells_.appendFaces(active, backMask, true, pointVertex, 1u, backFaces);
        cells_.appendFaces(active, backMask, false, pointVertex, 1u, frontFaces);
        buildMs += msSince(t0);
        const float d = static_cast<float>((plan.depth(k) - plan.depthMin) * tScale);
        back.fragment.alpha.ref = d;
        front.fragment.alpha.ref = d;

        fb_.clearColor(device_, clear);
        fb_.clearDepth(device_, 1.0f);
        fb_.clearStencil(device_, 0);
        rasterizer_.draw(fb_, back, raster::Topology::Triangles, backFaces);
        raster::accumulate(device_, fb_, raster::AccumOp::Load, 1.0f);  // the back faces' image, kept
        fb_.clearColor(device_, clear);
        fb_.clearDepth(device_, 0.0f);
        rasterizer_.draw(fb_, front, raster::Topology::Triangles, frontFaces);

        params.depth = d;
        int a = 0;
        composite_.setArg(a++, image_buffer_);
        composite_.setArg(a++, fb_.color());
        composite_.setArg(a++, fb_.accum());
        composite_.setArg(a++, tf_.buffer());
        composite_.setArg(a++, params);
        device_.launch("tetslice: composite", composite_, image_.width, image_.height);
    }

    overBackground_.run(image_buffer_, pixels, image_.background, "tetslice: over background");
    Image4f image = readImage(device_, image_buffer_, image_.width, image_.height);
    const raster::DrawStats drawn = rasterizer_.takeStats();

    std::vector<PassTime> hostPasses = {{"tetslice: eye depths, facing, active cell lists (host)", setUpMs},
                                        {"tetslice: face vertices of the active cells (host)", buildMs}};
    const std::size_t hostCount = hostPasses.size();
    finishFrame(device_, clock, stats, std::move(hostPasses));
    stats.extra["launches"] = mergePassesByName(stats.passes) - hostCount;  // per pass name: its launches summed
    counts_.report(stats);
    stats.extra["resident_bytes"] = residentBytes_;
    // The mesh stays on the host; each slice's faces go to the device through the raster stage.
    stats.extra["bytes_per_tet"] = static_cast<double>(residentBytes_) / static_cast<double>(cells);
    stats.extra["path"] = "raster";
    stats.extra["slices"] = plan.count;
    stats.extra["slice_spacing"] = plan.deltaS;
    stats.extra["cells_listed"] = lists.cellsListed();
    stats.extra["cells_drawn"] = cellsDrawn;
    stats.extra["cells_per_slice"] = cellsPerSlice;  // slice 0 = nearest
    stats.extra["raster_triangles"] = drawn.triangles;
    stats.extra["raster_fragments"] = drawn.fragments;
    return image;
}

}  // namespace

TechniqueInfo tetsliceTechnique()
{
    TechniqueInfo t;
    t.name = "tetslice";
    t.data = DataKind::Mesh;
    t.description = "direct slicing of tetrahedral grids through cell faces, seeds/000 §4.2 (docs/tetslice.md)";
    t.options = {slicesInfo(), sliceSpacingInfo(),
                 {"path", "fused", "", "\"fused\" (each ray walks the cells and samples the slices in them) or "
                                       "\"raster\" (the face draws per slice through the raster stage)"},
                 packetsInfo()};
    t.makeForMesh = makeTetsliceRenderer;
    return t;
}

TetsliceOptions parseTetsliceOptions(const nlohmann::json& options)
{
    static const TechniqueInfo& info = technique("tetslice");
    checkSlicesOrSpacing(options);
    TetsliceOptions o;
    forEachOption(options, info, [&](const std::string& key, const nlohmann::json& value) {
        if (key == "slices")
            o.slices = slicesOption(value);
        else if (key == "slice_spacing")
            o.sliceSpacing = sliceSpacingOption(value);
        else if (key == "path")
            o.path = choiceOption(key, value, {"fused", "raster"}) == 0 ? TetsliceOptions::Path::Fused
                                                                       : TetsliceOptions::Path::Raster;
        else if (key == "packets")
            o.packets = packetsOption(key, value);
        else
            unparsedOption(info, key);
    });
    return o;
}

namespace {

// The slices the raster path plans for the scene's view of the mesh box [lo, hi] (its camera frame: the same eye
// depths).
SlicePlan fusedPlan(const Scene& scene, const glm::dvec3& lo, const glm::dvec3& hi, const TetsliceOptions& options)
{
    const glm::dvec3 shift = 0.5 * (lo + hi);
    return planSlices(frameCamera(scene, lo, hi).relativeTo(shift), lo - shift, hi - shift, options.slices,
                      options.sliceSpacing);
}

// The walk sampling the cells' field at those slices.
HarcOptions walkOptions(const SlicePlan& plan, const std::optional<bool>& packets)
{
    HarcOptions harc;
    harc.packets = packets;
    harc.integration = HarcOptions::Integration::Slices;
    harc.sliceDepth0 = plan.count ? plan.depth(0) : 0.0;
    harc.sliceSpacing = plan.deltaS > 0.0 ? plan.deltaS : 1.0;
    harc.sliceCount = plan.count;
    return harc;
}

// The fused path: harc's renderer walking the cells with HARC_INTEGRATION_SLICES at the slices the raster path
// plans (the same camera frame and mesh box, so the same eye depths), its stats named as tetslice's.
class TetsliceFusedRenderer final : public Renderer {
public:
    TetsliceFusedRenderer(Device& device, const Scene& scene, const TetMesh& mesh)
        : options_(parseTetsliceOptions(scene.options)), lo_(mesh.boundsMin()), hi_(mesh.boundsMax())
    {
        plan_ = fusedPlan(scene, lo_, hi_, options_);
        walk_ = makeHarcRenderer(device, scene, mesh, buildTopology(mesh), walkOptions(plan_, options_.packets));
    }
    Image4f render(FrameStats& stats) override
    {
        Image4f image = walk_->render(stats);
        stats.samples = stats.extra["pieces"].get<std::uint64_t>();  // slices taken inside cells
        stats.extra["path"] = "fused";  // and "packets" from the walk
        stats.extra["slices"] = plan_.count;
        stats.extra["slice_spacing"] = plan_.deltaS;
        return image;
    }
    std::uint64_t residentBytes() const override { return walk_->residentBytes(); }
    void setTransferFunction(const TransferFunction& tf) override { walk_->setTransferFunction(tf); }
    bool setCamera(const Scene& scene) override
    {
        const SlicePlan plan = fusedPlan(scene, lo_, hi_, options_);
        if (!harcSetView(*walk_, scene, walkOptions(plan, options_.packets)))
            return false;
        plan_ = plan;
        return true;
    }

private:
    TetsliceOptions options_;
    glm::dvec3 lo_, hi_;  // the mesh box
    SlicePlan plan_;
    std::unique_ptr<Renderer> walk_;
};

}  // namespace

HarcOptions tetsliceWalkOptions(const Scene& scene, const TetMesh& mesh, const TetsliceOptions& options)
{
    return walkOptions(fusedPlan(scene, mesh.boundsMin(), mesh.boundsMax(), options), options.packets);
}

std::unique_ptr<Renderer> makeTetsliceRenderer(Device& device, const Scene& scene, const TetMesh& mesh)
{
    if (parseTetsliceOptions(scene.options).path == TetsliceOptions::Path::Fused)
        return std::make_unique<TetsliceFusedRenderer>(device, scene, mesh);
    return std::make_unique<TetsliceRenderer>(device, scene, mesh);
}

}  // namespace clvr
