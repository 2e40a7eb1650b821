// host/render/tet/harc.cpp — options, the 80-byte device layout, per-pixel boundary entry lists and the
// harc renderer (kernels/harc.cl: harc_render).
#include "host/render/tet/harc.h"

#include "host/render/scaffold.h"
#include "host/runtime/errors.h"
#include "host/render/camera_args.h"
#include "host/render/options_util.h"
#include "host/runtime/parallel.h"
#include "host/optics/preintegration_table.h"
#include "host/optics/psi_table.h"
#include "host/render/tet/harc_entry.h"
#include "host/render/transfer_function_upload.h"
#include "kernels/harc_params.h"

#include <algorithm>
#include <array>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstring>
#include <limits>
#include <mutex>
#include <string>

namespace clvr {
namespace {

// The iso-surface's color (Integration::Iso): the transfer function's at the value, white without one.
glm::dvec3 isoColorOf(const TransferFunction& tf, double value)
{
    return tf.points().empty() ? glm::dvec3(1.0) : glm::dvec3(tf(value));
}

class HarcRenderer final : public Renderer {
public:
    HarcRenderer(Device& device, const Scene& scene, const TetMesh& mesh, const TetTopology& topology,
                 const HarcOptions& options);
    Image4f render(FrameStats& stats) override;
    std::uint64_t residentBytes() const override { return residentBytes_; }
    void setTransferFunction(const TransferFunction& tf) override;
    // The entry lists, the eye's cell and the walk's camera follow the camera every frame anyway: only the
    // framed camera changes here (the mesh, its topology and the tables stay on the device).
    bool setCamera(const Scene& scene) override;
    // setCamera with the view-dependent options of tetslice's and tetiso's fused paths (harcSetView).
    bool setView(const Scene& scene, const HarcOptions& view)
    {
        if (!setCamera(scene))
            return false;
        options_.sliceDepth0 = view.sliceDepth0;
        options_.sliceSpacing = view.sliceSpacing;
        options_.sliceCount = view.sliceCount;
        options_.iso.light = view.iso.light;
        return true;
    }
    // Integration::Iso: the last frame's hits as eye depths (harcIsoHitDepth).
    std::vector<double> isoHitDepth() const;

private:
    void buildFullTable(const TransferFunction& tf);


    Device& device_;
    HarcOptions options_;
    Camera camera_;
    ImageSpec image_;
    TetMesh mesh_;          // copies: the renderer outlives the caller's mesh
    TetTopology topology_;
    std::vector<std::uint32_t> slot_;  // each tetrahedron's place on the device (harcCellOrder; empty: its own)
    glm::dvec3 shift_{0.0};
    glm::dvec3 lo_{0.0}, hi_{0.0};  // the mesh's bounds, which frame the camera (harcBounds)
    std::optional<MeshPart> part_;  // the box to integrate in, for a part of a larger mesh
    TransferFunctionUpload tf_;
    std::uint64_t maxSteps_ = 0;
    cl::Buffer tets_, psi_, out_, stats_;
    cl::Buffer isoNormals_;              // Integration::Iso: 3 float4 per cell (else one dummy)
    std::vector<float> isoHitLambda_;    // Integration::Iso: the last frame's hit per pixel (+inf: none)
    glm::dvec3 isoColor_{1.0};           // Integration::Iso: the transfer function's color at the iso-value
    cl::Kernel kernel_;
    bool packet_ = false;  // kernel_ is harc_render_packet
    std::unique_ptr<HarcRasterEntries> rasterEntries_;  // options_.entry == Raster
    std::uint64_t residentBytes_ = 0;
    MeshCounts counts_;
    // Full pre-integration (options_.integration == Full): the table on the device, its s range (the
    // hull of the transfer function's and the mesh's), its l range and the last build's time.
    cl::Buffer full_;
    glm::dvec2 meshScalarRange_{0.0};
    double fullLMax_ = 1.0;
    double fullSLo_ = 0.0, fullSHi_ = 1.0;
    double fullBuildMs_ = 0.0;
    std::uint64_t fullBytes_ = 0;
};

HarcRenderer::HarcRenderer(Device& device, const Scene& scene, const TetMesh& mesh, const TetTopology& topology,
                           const HarcOptions& options)
    : device_(device), options_(options), image_(scene.image), mesh_(mesh),
      topology_(topology)
{
    if (mesh.tets.empty())
        throw InputError(mesh.source + ": harc needs a mesh with at least one tetrahedron");
    if (mesh.tets.size() >= (std::size_t(1) << 29))
        throw InputError(mesh.source + ": harc takes fewer than 2^29 tetrahedra (tet * 4 + face in 31 bits)");
    if (topology.neighbor.size() != mesh.tets.size())  // makeMeshRenderer builds it from this mesh
        throw InternalError(mesh.source + ": topology does not match the mesh");
    // A part of a larger mesh (sort-last) computes in the full mesh's frame and integrates only inside
    // its box (host/model/mesh.h's MeshPart), so that the parts' images composite to the full one.
    harcBounds(mesh, lo_, hi_);
    shift_ = 0.5 * (lo_ + hi_);
    camera_ = frameCamera(scene, lo_, hi_);
    part_ = mesh.part;

    counts_ = MeshCounts::of(mesh);
    maxSteps_ = harcMaxSteps(options_, counts_.rendered);

    if (!options_.meshCellOrder)
        slot_ = harcCellOrder(mesh, topology);
    const std::vector<cl_float4> tets = packHarcTets(mesh, topology, shift_, slot_);
    tets_ = device_.upload("harc tetrahedra (80 bytes each)", tets);
    tf_.upload(device_, "harc transfer function", scene.transferFunction);
    const PsiTable& psi = psiTable();
    psi_ = device_.upload("harc psi table", psi.values);
    residentBytes_ = tets.size() * sizeof(cl_float4) + tf_.bytes() + psi.values.size() * sizeof(float);
    meshScalarRange_ = mesh.scalarRange();
    fullLMax_ = longestTetEdge(mesh);
    if (!(fullLMax_ > 0.0))
        fullLMax_ = 1.0;  // every cell flat: no segment has a length, any l range will do
    if (options_.integration == HarcOptions::Integration::Full) {
        buildFullTable(scene.transferFunction);
        residentBytes_ += fullBytes_;
    } else {
        full_ = device_.buffer("harc full table (unused)", sizeof(cl_float4));  // no zero-size buffers
    }

    if (options_.integration == HarcOptions::Integration::Iso) {
        isoColor_ = isoColorOf(scene.transferFunction, options_.iso.value);
        // Per cell the x, y and z of its four vertex normals, in the order of its barycentric planes.
        if (options_.iso.normals.size() != mesh.points.size())
            throw InternalError(mesh.source + ": harc iso needs one normal per point");
        std::vector<cl_float4> normals(mesh.tets.size() * 3);
        for (std::size_t t = 0; t < mesh.tets.size(); ++t)
            for (int axis = 0; axis < 3; ++axis)
                for (int v = 0; v < 4; ++v)
                    normals[3 * harcCellPlace(t, slot_) + axis].s[v] =
                        static_cast<float>(options_.iso.normals[mesh.tets[t][v]][axis]);
        isoNormals_ = device_.upload("harc iso vertex normals (48 bytes per tet)", normals);
        residentBytes_ += normals.size() * sizeof(cl_float4);
    } else {
        isoNormals_ = device_.buffer("harc iso normals (unused)", sizeof(cl_float4));  // no zero-size buffers
    }

    const std::size_t pixels = static_cast<std::size_t>(image_.width) * image_.height;
    out_ = device_.buffer("harc image", pixels * sizeof(cl_float4), CL_MEM_WRITE_ONLY);
    stats_ = device_.buffer("harc ray counts", pixels * 3 * sizeof(cl_uint), CL_MEM_WRITE_ONLY);
    // Ray packets (docs/harc.md): a whole mesh (not a sort-last part), 8 pixels' walks per work-item.
    packet_ = packetsOnDevice(options_.packets, device_) && !part_;
    kernel_ = device_.kernel("harc.cl", packet_ ? "harc_render_packet" : "harc_render");
    if (options_.entry == HarcOptions::Entry::Raster)
        rasterEntries_ = std::make_unique<HarcRasterEntries>(device_, mesh, topology, shift_, tets_, image_.width,
                                                             image_.height, options_.maxLayers, slot_);
}

// The table over s in the hull of the transfer function's range and the mesh's: a segment whose s
// leaves the transfer function's range still has to cross into it at the right λ, which clamping s to
// that range would move. l runs to the longest tetrahedron edge, the longest segment any ray can have.
void HarcRenderer::buildFullTable(const TransferFunction& tf)
{
    const auto start = std::chrono::steady_clock::now();
    fullSLo_ = std::min(tf.sMin(), meshScalarRange_.x);
    fullSHi_ = std::max(tf.sMax(), meshScalarRange_.y);
    const PreintegrationTable table = buildPreintegrationTable(tf, fullSLo_, fullSHi_, fullLMax_,
                                                               options_.fullScalarSamples, options_.fullLengthSamples);
    full_ = device_.upload("harc full pre-integration table", table.values);
    fullBytes_ = table.bytes();
    fullBuildMs_ = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
}

bool HarcRenderer::setCamera(const Scene& scene)
{
    if (!sameImageSize(scene.image, image_))
        return false;  // the image-sized buffers (and the raster entry's frame buffers) would change
    image_ = scene.image;
    camera_ = frameCamera(scene, lo_, hi_);
    return true;
}

void HarcRenderer::setTransferFunction(const TransferFunction& tf)
{
    // Full pre-integration has to rebuild its whole table (same size, so residentBytes_ keeps it): the
    // cost that partial pre-integration avoids (seeds/001 §1).
    if (options_.integration == HarcOptions::Integration::Full)
        buildFullTable(tf);

    // Partial pre-integration needs no table that depends on the transfer function: only the packed
    // control points change (the ψ table is the same for every transfer function).
    isoColor_ = isoColorOf(tf, options_.iso.value);
    tf_.replace(device_, "harc transfer function", tf, residentBytes_);
}

Image4f HarcRenderer::render(FrameStats& stats)
{
    const FrameClock clock;
    // Entry points: the boundary front faces' crossings per pixel, sorted by depth, every frame.
    // The raster's lists come with the cells' places on the device (slot_); the host's are sorted in the mesh's
    // numbering (ties by code) and mapped after, so that the order of the cells changes no list.
    HarcRasterEntryStats peel;
    HarcEntryLists lists = rasterEntries_ ? rasterEntries_->build(camera_, peel)
                                          : buildHarcEntryLists(mesh_, topology_, camera_, image_.width, image_.height);
    if (!rasterEntries_ && !slot_.empty())
        for (cl_int2& entry : lists.entries)
            entry.s[1] = harcDeviceCode(entry.s[1], slot_);
    // A perspective eye inside the mesh: every ray starts in the cell holding the eye, before any crossing.
    // The search is linear in the cells (40 ms on the 1.16 M-cell torus), so it runs only for an eye in the mesh's
    // box (for a part, the whole mesh's), widened by far more than locatePoint's tolerance (1e-12 of a cell's volume)
    // can reach past a face.
    const glm::dvec3 margin = 1e-9 * (hi_ - lo_) + 1e-300;
    const bool eyeInBox = glm::all(glm::greaterThanEqual(camera_.position, lo_ - margin)) &&
                          glm::all(glm::lessThanEqual(camera_.position, hi_ + margin));
    const std::int64_t eyeTet = camera_.parallel || !eyeInBox ? -1 : locatePoint(mesh_, camera_.position);
    if (eyeTet >= 0)
        prependEyeEntry(lists, harcCellPlace(static_cast<std::size_t>(eyeTet), slot_));
    const double entryMs = clock.ms();
    const cl::Buffer offsets = device_.upload("harc entry offsets", lists.offsets);
    std::vector<cl_int2> entries = lists.entries;
    if (entries.empty())
        entries.push_back(cl_int2{{0, 0}});  // no zero-size buffers
    const cl::Buffer entryBuffer = device_.upload("harc entry crossings", entries);

    const float ert = options_.earlyTermination < 1.0 ? static_cast<float>(options_.earlyTermination) : 2.0f;
    const cl_uint maxSteps = static_cast<cl_uint>(std::min<std::uint64_t>(maxSteps_, 0xffffffffu));
    const cl_int integration = options_.integration == HarcOptions::Integration::Average ? 1
                               : options_.integration == HarcOptions::Integration::Full  ? 2
                               : options_.integration == HarcOptions::Integration::Slices ? 3
                               : options_.integration == HarcOptions::Integration::Iso    ? 4
                                                                                          : 0;
    // The table's sample spacing as PreintegrationTable::lookup computes it (float), so host and device
    // interpolate alike.
    const int ns = options_.fullScalarSamples, nl = options_.fullLengthSamples;
    ClHarcParams params{};
    params.camera = toClCamera(camera_, image_.width, image_.height, shift_);
    params.background = toCl4(image_.background);
    params.full_params = cl_float4{{static_cast<float>(fullSLo_),
                                    static_cast<float>(ns - 1) / static_cast<float>(fullSHi_ - fullSLo_),
                                    static_cast<float>(nl - 1) / static_cast<float>(fullLMax_), 0.0f}};
    params.width = image_.width;
    params.height = image_.height;
    params.tf_count = tf_.count();
    params.psi_n = static_cast<cl_int>(psiTable().size);
    params.max_steps = maxSteps;
    params.integration = integration;  // HARC_INTEGRATION_* of kernels/harc.cl
    params.ert_alpha = ert;
    params.full_ns = ns;
    params.full_nl = nl;
    params.slices = cl_float4{{static_cast<float>(options_.sliceDepth0), static_cast<float>(options_.sliceSpacing),
                               static_cast<float>(options_.sliceCount), 0.0f}};
    if (options_.integration == HarcOptions::Integration::Iso) {
        const HarcOptions::HarcIso& iso = options_.iso;
        const int flags = (iso.shaded ? HARC_ISO_SHADED : 0) | (iso.equalWeights ? HARC_ISO_EQUAL_WEIGHTS : 0);
        params.iso = cl_float4{{static_cast<float>(iso.value), static_cast<float>(iso.ambient),
                                static_cast<float>(iso.diffuse), static_cast<float>(flags)}};
        params.iso_light = toCl4(iso.light);
        params.iso_color = toCl4(isoColor_);
    }
    if (part_) {
        params.clip_box = 1;
        params.box_lo = toCl4(part_->lo - shift_);
        params.box_hi = toCl4(part_->hi - shift_);
    }
    int a = 0;
    kernel_.setArg(a++, out_);
    kernel_.setArg(a++, stats_);
    kernel_.setArg(a++, tets_);
    kernel_.setArg(a++, offsets);
    kernel_.setArg(a++, entryBuffer);
    kernel_.setArg(a++, tf_.buffer());
    kernel_.setArg(a++, psi_);
    kernel_.setArg(a++, full_);
    kernel_.setArg(a++, isoNormals_);
    kernel_.setArg(a++, params);
    device_.launch(kHarcWalkPass, kernel_, rowWorkItems(image_.width, packet_), image_.height);

    const std::size_t pixels = static_cast<std::size_t>(image_.width) * image_.height;
    Image4f image = readImage(device_, out_, image_.width, image_.height);
    const std::vector<cl_uint> counts = device_.download<cl_uint>(stats_, pixels * 3);
    std::uint64_t steps = 0, bounded = 0, pieces = 0;
    const bool iso = options_.integration == HarcOptions::Integration::Iso;
    if (iso)
        isoHitLambda_.resize(pixels);
    for (std::size_t p = 0; p < pixels; ++p) {
        steps += counts[3 * p];
        bounded += counts[3 * p + 1];
        if (iso) {  // the hit's λ as float bits: pieces counts the hits
            std::memcpy(&isoHitLambda_[p], &counts[3 * p + 2], sizeof(float));
            pieces += std::isfinite(isoHitLambda_[p]) ? 1 : 0;
        } else {
            pieces += counts[3 * p + 2];
        }
    }
    // The host's entry stage first (with raster entries the peeling draws' own device passes are among
    // the device's; this is the whole entry stage, draws, read-backs and the host's compaction included).
    std::vector<PassTime> hostPasses;
    if (rasterEntries_) {
        hostPasses.push_back({"harc: entry lists (raster, all layers)", entryMs});
        hostPasses.push_back({"harc: entry lists (raster) host compaction", peel.compactMs});
    } else {
        hostPasses.push_back({"harc: entry lists (host)", entryMs});
    }
    finishFrame(device_, clock, stats, std::move(hostPasses));
    counts_.report(stats);
    stats.extra["bytes_per_tet"] = static_cast<double>(residentBytes_) / static_cast<double>(counts_.rendered);
    stats.extra["tet_layout_bytes"] = kHarcBytesPerTet;
    stats.extra["resident_bytes"] = residentBytes_;
    stats.extra["psi_table"] = std::to_string(psiTable().size) + "x" + std::to_string(psiTable().size);
    stats.extra["steps"] = steps;
    stats.extra["pieces"] = pieces;
    stats.extra["rays_step_bound"] = bounded;
    stats.extra["max_steps"] = maxSteps_;
    stats.extra["boundary_faces"] = topology_.boundary.size();
    stats.extra["entry_crossings"] = lists.entries.size();
    switch (options_.integration) {
    case HarcOptions::Integration::Partial: stats.extra["integration"] = "partial"; break;
    case HarcOptions::Integration::Average: stats.extra["integration"] = "average"; break;
    case HarcOptions::Integration::Slices: stats.extra["integration"] = "slices"; break;
    case HarcOptions::Integration::Iso: stats.extra["integration"] = "iso"; break;
    case HarcOptions::Integration::Full:
        stats.extra["integration"] = "full";
        stats.extra["full_table"] = std::to_string(ns) + "x" + std::to_string(ns) + "x" + std::to_string(nl);
        stats.extra["full_table_bytes"] = fullBytes_;
        stats.extra["full_table_build_ms"] = fullBuildMs_;  // the last build: construction or TF change
        stats.extra["full_table_l_max"] = fullLMax_;
        stats.extra["full_table_s_range"] = {fullSLo_, fullSHi_};
        break;
    }
    stats.extra["early_termination"] = options_.earlyTermination;
    stats.extra["packets"] = packet_;
    stats.extra["entry"] = rasterEntries_ ? "raster" : "host";
    stats.extra["eye_tet"] = eyeTet;
    stats.extra["entry_ms"] = entryMs;
    if (rasterEntries_) {
        stats.extra["entry_layers"] = peel.layers;
        stats.extra["max_layers"] = options_.maxLayers;
        stats.extra["rays_layer_bound"] = peel.pixelsAtBound;  // lists cut at max_layers
        stats.extra["entry_triangles"] = peel.triangles;
        stats.extra["entry_fragments"] = peel.fragments;
    }
    return image;
}

std::vector<double> HarcRenderer::isoHitDepth() const
{
    // λ is the distance along the unit ray from its origin (kernels/ray.h's clvr_ray_unit, as Camera::ray).
    std::vector<double> z(isoHitLambda_.size(), std::numeric_limits<double>::infinity());
    const glm::dvec3 forward = camera_.forward();
    for (int y = 0; y < image_.height; ++y)
        for (int x = 0; x < image_.width; ++x) {
            const std::size_t p = static_cast<std::size_t>(y) * image_.width + x;
            if (p >= isoHitLambda_.size() || !std::isfinite(isoHitLambda_[p]))
                continue;
            const Ray ray = camera_.ray(x, y, image_.width, image_.height);
            z[p] = glm::dot(ray.origin + static_cast<double>(isoHitLambda_[p]) * ray.direction - camera_.position, forward);
        }
    return z;
}

}  // namespace

std::vector<double> harcIsoHitDepth(const Renderer& renderer)
{
    const auto* harc = dynamic_cast<const HarcRenderer*>(&renderer);
    if (!harc)
        throw InternalError("harcIsoHitDepth: not a harc renderer");
    return harc->isoHitDepth();
}

bool harcSetView(Renderer& renderer, const Scene& scene, const HarcOptions& view)
{
    auto* harc = dynamic_cast<HarcRenderer*>(&renderer);
    if (!harc)
        throw InternalError("harcSetView: not a harc renderer");
    return harc->setView(scene, view);
}

TechniqueInfo harcTechnique()
{
    TechniqueInfo t;
    t.name = "harc";
    t.data = DataKind::Mesh;
    t.description = "tetrahedral ray casting with partial pre-integration, seeds/001 (docs/harc.md)";
    t.sortLast = true;
    t.options = {
        {"integration", "partial", "", "\"partial\" (Eq. 2-4), \"average\" (mean color per segment) or \"full\" (3D table)"},
        {"full_table", nullptr, "[64, 64], with integration full only", "[NS, NL]: the full table's samples of s_f, s_b and of l"},
        {"max_steps", nullptr, "4 cbrt(tets) + 10000", "traversal steps per ray before it is stopped and counted"},
        earlyTerminationInfo(1.0),
        packetsInfo(),
        {"entry", "host", "", "entry faces per pixel: \"host\" (exact ray/face tests) or \"raster\" (depth peeling)"},
        {"max_layers", 64, "", "raster entry: depth-peeling layers per frame, 1..255"},
    };
    t.makeForMesh = [](Device& device, const Scene& scene, const TetMesh& mesh) -> std::unique_ptr<Renderer> {
        return makeHarcRenderer(device, scene, mesh, buildTopology(mesh));
    };
    return t;
}

HarcOptions parseHarcOptions(const nlohmann::json& options)
{
    static const TechniqueInfo& info = technique("harc");
    HarcOptions o;
    forEachOption(options, info, [&](const std::string& key, const nlohmann::json& value) {
        if (key == "integration") {
            const std::string s = value.is_string() ? value.get<std::string>() : "";
            if (s == "partial")
                o.integration = HarcOptions::Integration::Partial;
            else if (s == "average")
                o.integration = HarcOptions::Integration::Average;
            else if (s == "full")
                o.integration = HarcOptions::Integration::Full;
            else
                badOption(key, "must be \"partial\", \"average\" or \"full\", got " + value.dump());
        } else if (key == "full_table") {
            const bool pair = value.is_array() && value.size() == 2;
            for (std::size_t i = 0; pair && i < 2; ++i)
                if (!value[i].is_number_integer() || value[i].get<long long>() < 2 || value[i].get<long long>() > 512)
                    badOption(key, "must be [NS, NL], integers in [2, 512], got " + value.dump());
            if (!pair)
                badOption(key, "must be [NS, NL] (samples of s_f and s_b, samples of l), got " + value.dump());
            o.fullScalarSamples = value[0].get<int>();
            o.fullLengthSamples = value[1].get<int>();
            const std::uint64_t bytes = std::uint64_t(o.fullScalarSamples) * o.fullScalarSamples *
                                        o.fullLengthSamples * sizeof(cl_float4);
            if (bytes > kMaxFullTableBytes)
                badOption(key, value.dump() + " is a table of " + std::to_string(bytes >> 20) +
                                   " MiB (NS x NS x NL x 16 bytes); at most " +
                                   std::to_string(kMaxFullTableBytes >> 20) + " MiB");
        } else if (key == "entry") {
            const std::string s = value.is_string() ? value.get<std::string>() : "";
            if (s == "raster")
                o.entry = HarcOptions::Entry::Raster;
            else if (s == "host")
                o.entry = HarcOptions::Entry::Host;
            else
                badOption(key, "must be \"raster\" or \"host\", got " + value.dump());
        } else if (key == "max_layers") {
            if (!value.is_number_integer() || value.get<long long>() < 1 || value.get<long long>() > 255)
                badOption(key, "must be an integer in [1, 255], got " + value.dump());
            o.maxLayers = value.get<int>();
        } else if (key == "max_steps") {
            if (!value.is_number_integer() || value.get<long long>() < 1 || value.get<long long>() > 0xffffffffll)
                badOption(key, "must be an integer in [1, 4294967295], got " + value.dump());
            o.maxSteps = value.get<std::uint64_t>();
        } else if (key == "packets") {
            o.packets = packetsOption(key, value);
        } else if (key == "early_termination") {
            o.earlyTermination = earlyTerminationOption(value);
        } else {
            unparsedOption(info, key);
        }
    });
    if (options.contains("full_table") && o.integration != HarcOptions::Integration::Full)
        badOption("full_table", "applies only to \"integration\": \"full\"");
    return o;
}

double longestTetEdge(const TetMesh& mesh)
{
    double longest2 = 0.0;
    for (const glm::uvec4& t : mesh.tets)
        for (int a = 0; a < 4; ++a)
            for (int b = a + 1; b < 4; ++b) {
                const glm::dvec3 e = mesh.points[t[a]] - mesh.points[t[b]];
                longest2 = std::max(longest2, glm::dot(e, e));
            }
    return std::sqrt(longest2);
}

void harcBounds(const TetMesh& mesh, glm::dvec3& lo, glm::dvec3& hi)
{
    if (mesh.part) {
        lo = mesh.part->fullLo;
        hi = mesh.part->fullHi;
        return;
    }
    lo = glm::dvec3(std::numeric_limits<double>::infinity());
    hi = -lo;
    for (const glm::uvec4& t : mesh.tets)
        for (int k = 0; k < 4; ++k) {
            lo = glm::min(lo, mesh.points[t[k]]);
            hi = glm::max(hi, mesh.points[t[k]]);
        }
}

std::uint64_t harcMaxSteps(const HarcOptions& options, std::uint64_t tets)
{
    if (options.maxSteps)
        return options.maxSteps;
    return static_cast<std::uint64_t>(4.0 * std::cbrt(static_cast<double>(tets))) + 10000;
}

double harcNeighbourDistance(const TetTopology& topology, const std::vector<std::uint32_t>& slot)
{
    double sum = 0.0;
    std::size_t pairs = 0;
    for (std::size_t t = 0; t < topology.neighbor.size(); ++t)
        for (const std::int32_t n : topology.neighbor[t])
            if (n >= 0) {
                sum += std::log2(1.0 + std::abs(static_cast<double>(harcCellPlace(t, slot)) -
                                                 static_cast<double>(harcCellPlace(static_cast<std::size_t>(n), slot))));
                ++pairs;
            }
    return pairs ? sum / static_cast<double>(pairs) : 0.0;
}

std::vector<std::uint32_t> harcCellOrder(const TetMesh& mesh, const TetTopology& topology)
{
    const std::size_t count = mesh.tets.size();
    glm::dvec3 lo(INFINITY), hi(-INFINITY);
    std::vector<glm::dvec3> centroid(count);
    for (std::size_t t = 0; t < count; ++t) {
        const glm::uvec4 v = mesh.tets[t];
        centroid[t] = 0.25 * (mesh.points[v[0]] + mesh.points[v[1]] + mesh.points[v[2]] + mesh.points[v[3]]);
        lo = glm::min(lo, centroid[t]);
        hi = glm::max(hi, centroid[t]);
    }
    // 10 bits per axis on the centroids' box, interleaved z y x from the top bit down.
    const auto spread = [](std::uint32_t v) {
        std::uint64_t x = v & 0x3ff;
        x = (x | (x << 16)) & 0x030000ff;
        x = (x | (x << 8)) & 0x0300f00f;
        x = (x | (x << 4)) & 0x030c30c3;
        x = (x | (x << 2)) & 0x09249249;
        return x;
    };
    const glm::dvec3 extent = glm::max(hi - lo, glm::dvec3(1e-300));
    std::vector<std::pair<std::uint64_t, std::uint32_t>> keys(count);
    for (std::size_t t = 0; t < count; ++t) {
        const glm::dvec3 q = glm::clamp((centroid[t] - lo) / extent * 1024.0, glm::dvec3(0.0), glm::dvec3(1023.0));
        keys[t] = {spread(static_cast<std::uint32_t>(q.x)) | spread(static_cast<std::uint32_t>(q.y)) << 1 |
                       spread(static_cast<std::uint32_t>(q.z)) << 2,
                   static_cast<std::uint32_t>(t)};
    }
    std::sort(keys.begin(), keys.end());
    std::vector<std::uint32_t> slot(count);
    for (std::size_t i = 0; i < count; ++i)
        slot[keys[i].second] = static_cast<std::uint32_t>(i);
    if (harcNeighbourDistance(topology, slot) < harcNeighbourDistance(topology))
        return slot;
    return {};  // the mesh's own order is the nearer
}

std::vector<cl_float4> packHarcTets(const TetMesh& mesh, const TetTopology& topology, const glm::dvec3& shift,
                                    const std::vector<std::uint32_t>& slot)
{
    std::vector<cl_float4> out(mesh.tets.size() * 5);
    for (std::size_t t = 0; t < mesh.tets.size(); ++t) {
        const glm::uvec4 v = mesh.tets[t];
        const glm::dvec3 x0 = mesh.points[v[0]] - shift;
        // Barycentric coordinates: (b1, b2, b3) = M^-1 (x - x0), M = [x1 - x0, x2 - x0, x3 - x0]; b0 = 1 - Σ.
        const glm::dmat3 m(mesh.points[v[1]] - shift - x0, mesh.points[v[2]] - shift - x0,
                           mesh.points[v[3]] - shift - x0);
        const glm::dmat3 inv = glm::inverse(m);
        glm::dvec3 h[4];
        double k[4];
        for (int i = 1; i < 4; ++i) {
            h[i] = glm::dvec3(inv[0][i - 1], inv[1][i - 1], inv[2][i - 1]);  // row i-1 of M^-1
            k[i] = -glm::dot(h[i], x0);
        }
        h[0] = -(h[1] + h[2] + h[3]);
        k[0] = 1.0 - (k[1] + k[2] + k[3]);
        glm::dvec3 g(0.0);
        double g0 = 0.0;
        for (int i = 0; i < 4; ++i) {  // s(x) = Σ s_i b_i(x): Eq. 6's gradient and scalar term
            g += mesh.scalars[v[i]] * h[i];
            g0 += mesh.scalars[v[i]] * k[i];
        }
        cl_float4* o = &out[5 * static_cast<std::size_t>(harcCellPlace(t, slot))];
        for (int i = 0; i < 3; ++i)
            o[i] = toCl4(h[i], k[i]);
        o[3] = toCl4(g, g0);
        // Across face i: the neighbor n and the face of n that is this face, as n * 4 + face (the walk
        // needs both and this saves it a second, dependent load per step), or -1 on the boundary.
        cl_int adj[4];
        for (int i = 0; i < 4; ++i) {
            const std::int32_t n = topology.neighbor[t][i];
            adj[i] = -1;
            if (n >= 0)
                for (int j = 0; j < 4; ++j)
                    if (topology.neighbor[n][j] == static_cast<std::int32_t>(t))
                        adj[i] = static_cast<cl_int>(harcCellPlace(static_cast<std::size_t>(n), slot) * 4 + j);
        }
        std::memcpy(&o[4], adj, sizeof adj);
    }
    return out;
}

HarcEntryLists buildHarcEntryLists(const TetMesh& mesh, const TetTopology& topology, const Camera& camera,
                                   int width, int height)
{
    // A boundary face that faces the eye, its pixel box and its entry code, and Möller–Trumbore's quantities for a
    // ray e + λ d as affine functions of what varies from pixel to pixel, `vary` − anchor: the direction d from one
    // eye (anchor 0), or the origin e along one direction (parallel; anchor p0). With e1 = p1 − p0, e2 = p2 − p0,
    // n = e1 × e2 and t = e − p0: det = d · (e2 × e1) = −d · n, det·u = t · (d × e2) = d · (e2 × t),
    // det·v = d · (t × e1) = t · (e1 × d), det·λ = e2 · (t × e1) = t · n.
    struct FrontFace {
        glm::dvec3 anchor;
        std::array<glm::dvec3, 4> w;  // det, det·u, det·v, det·λ: dot(vary − anchor, w[i]) + w0[i]
        std::array<double, 4> w0;
        int x0, x1, y0, y1;
        std::int32_t code;
    };
    struct Hit {
        std::uint32_t pixel;  // in its band
        float lambda;
        std::int32_t code;
    };
    const glm::dvec3 f = camera.forward(), r = camera.right(), u = camera.up();
    const PixelRays rays(camera, width, height);
    const double fullHeight = camera.fullHeight(height), firstRow = camera.bandY0;  // a band of rows (sort-first)
    const double aspect = static_cast<double>(width) / fullHeight;
    const double scale = camera.parallel ? camera.parallelScale : std::tan(glm::radians(camera.viewAngle) * 0.5);
    HarcEntryLists lists;
    const std::size_t pixels = static_cast<std::size_t>(width) * height;
    lists.offsets.assign(pixels + 1, 0);
    if (pixels == 0)
        return lists;

    // 1. The front faces and their pixel boxes, in chunks over the host's threads, each thread's in its own list.
    constexpr std::size_t kChunk = 256;
    const std::size_t faceCount = topology.boundary.size();
    std::vector<std::vector<FrontFace>> threadFaces;
    std::mutex merge;
    std::atomic<std::size_t> nextChunk{0};
    runOnThreads(0, static_cast<int>((faceCount + kChunk - 1) / kChunk), [&] {
        std::vector<FrontFace> local;
        for (std::size_t begin; (begin = nextChunk.fetch_add(kChunk)) < faceCount;) {
            const std::size_t end = std::min(begin + kChunk, faceCount);
            for (std::size_t i = begin; i < end; ++i) {
                const TetTopology::BoundaryFace& bf = topology.boundary[i];
                const std::array<glm::dvec3, 3> p = outwardFace(mesh, bf.tet, bf.face);
                const glm::dvec3 normal = glm::cross(p[1] - p[0], p[2] - p[0]);
                // A face turned away from the eye is a back face for every ray that meets its plane ahead
                // (t dot(n, d) = dot(n, p0 - eye) for the hit at e + t d, t >= 0), and for a parallel camera
                // dot(n, d) = dot(n, forward) for every ray: the per-pixel test below would reject each pixel.
                if (camera.parallel ? !(glm::dot(normal, f) < 0.0) : glm::dot(normal, p[0] - camera.position) > 0.0)
                    continue;
                // Pixel bounding box of the face (whole image if a corner is at or behind the eye plane).
                double x0 = 0.0, x1 = width - 1.0, y0 = 0.0, y1 = height - 1.0;
                bool clipped = false;
                double minX = 1e300, maxX = -1e300, minY = 1e300, maxY = -1e300;
                for (const glm::dvec3& q : p) {
                    const glm::dvec3 rel = q - camera.position;
                    double sx = glm::dot(rel, r), sy = glm::dot(rel, u);
                    if (!camera.parallel) {
                        const double z = glm::dot(rel, f);
                        if (!(z > 1e-12)) {
                            clipped = true;
                            break;
                        }
                        sx /= z;
                        sy /= z;
                    }
                    const double px = (sx / (scale * aspect) + 1.0) * 0.5 * width - 0.5;
                    const double py = (1.0 - sy / scale) * 0.5 * fullHeight - 0.5 - firstRow;
                    minX = std::min(minX, px);
                    maxX = std::max(maxX, px);
                    minY = std::min(minY, py);
                    maxY = std::max(maxY, py);
                }
                if (!clipped) {
                    // The pixel centres (x, y) in the projected box, widened by far more than the projection's
                    // rounding and the test's edge margin (1e-7 of a barycentric coordinate) can move a hit.
                    const double pad = 0.01 + 1e-6 * std::max(maxX - minX, maxY - minY);
                    x0 = std::max(x0, std::ceil(minX - pad));
                    x1 = std::min(x1, std::floor(maxX + pad));
                    y0 = std::max(y0, std::ceil(minY - pad));
                    y1 = std::min(y1, std::floor(maxY + pad));
                }
                if (x0 > x1 || y0 > y1)
                    continue;
                FrontFace face{};
                const glm::dvec3 e1 = p[1] - p[0], e2 = p[2] - p[0];
                if (camera.parallel) {  // v = e: t = v − p0; d = forward
                    face.anchor = p[0];
                    face.w = {glm::dvec3(0.0), glm::cross(f, e2), glm::cross(e1, f), normal};
                    face.w0 = {-glm::dot(f, normal), 0.0, 0.0, 0.0};
                } else {  // v = d: t = eye − p0 for every ray
                    const glm::dvec3 t = camera.position - p[0], q = glm::cross(t, e1);
                    face.anchor = glm::dvec3(0.0);
                    face.w = {-normal, glm::cross(e2, t), q, glm::dvec3(0.0)};
                    face.w0 = {0.0, 0.0, 0.0, glm::dot(e2, q)};
                }
                face.x0 = static_cast<int>(x0), face.x1 = static_cast<int>(x1);
                face.y0 = static_cast<int>(y0), face.y1 = static_cast<int>(y1);
                face.code = static_cast<std::int32_t>(bf.tet * 4 + bf.face);
                local.push_back(face);
            }
        }
        const std::lock_guard<std::mutex> lock(merge);
        threadFaces.push_back(std::move(local));
    });

    // 2. The faces binned by bands of kBandRows rows (a face in every band its box reaches), and each band's
    // columns: the hull of its faces' boxes.
    constexpr int kBandRows = 8;
    const int bands = (height + kBandRows - 1) / kBandRows;
    std::vector<std::uint32_t> binStart(static_cast<std::size_t>(bands) + 1, 0);
    std::vector<int> bandX0(static_cast<std::size_t>(bands), width), bandX1(static_cast<std::size_t>(bands), -1);
    std::vector<std::uint64_t> bandTests(static_cast<std::size_t>(bands), 0);  // ray/face tests in the band
    for (const std::vector<FrontFace>& list : threadFaces)
        for (const FrontFace& face : list)
            for (int b = face.y0 / kBandRows; b <= face.y1 / kBandRows; ++b) {
                ++binStart[static_cast<std::size_t>(b) + 1];
                bandX0[b] = std::min(bandX0[b], face.x0);
                bandX1[b] = std::max(bandX1[b], face.x1);
                const int rows = std::min(face.y1, b * kBandRows + kBandRows - 1) - std::max(face.y0, b * kBandRows) + 1;
                bandTests[b] += static_cast<std::uint64_t>(face.x1 - face.x0 + 1) * static_cast<std::uint64_t>(rows);
            }
    for (int b = 0; b < bands; ++b)
        binStart[b + 1] += binStart[b];
    std::vector<const FrontFace*> bin(binStart[bands]);
    {
        std::vector<std::uint32_t> fill(binStart.begin(), binStart.end() - 1);
        for (const std::vector<FrontFace>& list : threadFaces)
            for (const FrontFace& face : list)
                for (int b = face.y0 / kBandRows; b <= face.y1 / kBandRows; ++b)
                    bin[fill[b]++] = &face;
    }

    // 3. Each band on its own over the host's threads: its faces' crossings with its pixels' rays, each pixel's
    // sorted by λ, then face (the same lists whichever thread found what); each band's pixel counts go into
    // offsets, its entries into its own vector until the offsets are summed.
    std::vector<std::vector<cl_int2>> bandEntries(static_cast<std::size_t>(bands));
    std::atomic<int> nextBand{0};
    runOnThreads(0, bands, [&] {
        std::vector<Hit> hits, sorted;
        std::vector<std::uint32_t> start;
        std::vector<Ray> bandRays;
        for (int band; (band = nextBand.fetch_add(1)) < bands;) {
            const int rowLo = band * kBandRows, rowHi = std::min(rowLo + kBandRows, height) - 1;
            const std::size_t firstPixel = static_cast<std::size_t>(rowLo) * width;
            const std::size_t bandPixels = static_cast<std::size_t>(rowHi - rowLo + 1) * width;
            // Where the band's pixels are tested against more faces than it has pixels (the automaton: about 10
            // each), the rays of its columns once each; else each test its ray.
            const int x0 = bandX0[band], columns = std::max(bandX1[band] - x0 + 1, 0);
            const bool table = bandTests[band] > static_cast<std::uint64_t>(columns) * (rowHi - rowLo + 1);
            bandRays.resize(table ? static_cast<std::size_t>(columns) * kBandRows : 0);
            if (table)
                for (int y = rowLo; y <= rowHi; ++y)
                    for (int x = x0; x < x0 + columns; ++x)
                        bandRays[static_cast<std::size_t>(y - rowLo) * columns + (x - x0)] = rays.at(x, y);
            hits.clear();
            for (std::uint32_t k = binStart[band]; k < binStart[band + 1]; ++k) {
                const FrontFace& face = *bin[k];
                for (int y = std::max(face.y0, rowLo); y <= std::min(face.y1, rowHi); ++y)
                    for (int x = face.x0; x <= face.x1; ++x) {
                        const Ray ray =
                            table ? bandRays[static_cast<std::size_t>(y - rowLo) * columns + (x - x0)] : rays.at(x, y);
                        const glm::dvec3 vary = (camera.parallel ? ray.origin : ray.direction) - face.anchor;
                        // Möller–Trumbore without its divisions: det > 0 where the ray enters through the face (a
                        // back face or edge-on: det <= 0), and the barycentric coordinates u, v and 1 − u − v each
                        // >= −1e-7, a small margin so that no ray slips between two faces that share an edge (a
                        // duplicate is skipped by the walk).
                        const double det = glm::dot(vary, face.w[0]) + face.w0[0];
                        if (!(det > 0.0))
                            continue;
                        constexpr double kMargin = 1e-7;
                        const double du = glm::dot(vary, face.w[1]), dv = glm::dot(vary, face.w[2]);
                        if (du < -kMargin * det || dv < -kMargin * det || du + dv > (1.0 + kMargin) * det)
                            continue;
                        const double lambda = (glm::dot(vary, face.w[3]) + face.w0[3]) / det;
                        if (!(lambda >= 0.0))
                            continue;
                        hits.push_back({static_cast<std::uint32_t>(static_cast<std::size_t>(y) * width + x - firstPixel),
                                        static_cast<float>(lambda), face.code});
                    }
            }
            // per pixel of the band: count, place, sort
            start.assign(bandPixels + 1, 0);
            for (const Hit& h : hits)
                ++start[h.pixel + 1];
            for (std::size_t q = 0; q < bandPixels; ++q) {
                lists.offsets[firstPixel + q + 1] = start[q + 1];  // the count, summed below
                start[q + 1] += start[q];
            }
            sorted.resize(hits.size());
            for (const Hit& h : hits)
                sorted[start[h.pixel]++] = h;  // start[q] ends at pixel q's end
            std::vector<cl_int2>& out = bandEntries[static_cast<std::size_t>(band)];
            out.resize(sorted.size());
            for (std::size_t q = 0, b = 0; q < bandPixels; ++q) {
                const std::size_t e = start[q];
                std::sort(sorted.begin() + static_cast<std::ptrdiff_t>(b), sorted.begin() + static_cast<std::ptrdiff_t>(e),
                          [](const Hit& a, const Hit& c) { return a.lambda != c.lambda ? a.lambda < c.lambda : a.code < c.code; });
                for (; b < e; ++b) {
                    cl_int bits;
                    std::memcpy(&bits, &sorted[b].lambda, sizeof bits);
                    out[b] = cl_int2{{bits, sorted[b].code}};
                }
            }
        }
    });

    // 4. The offsets summed, the bands' entries in place.
    for (std::size_t q = 0; q < pixels; ++q)
        lists.offsets[q + 1] += lists.offsets[q];
    lists.entries.resize(lists.offsets[pixels]);
    for (int band = 0; band < bands; ++band) {
        const std::vector<cl_int2>& e = bandEntries[static_cast<std::size_t>(band)];
        std::copy(e.begin(), e.end(),
                  lists.entries.begin() + lists.offsets[static_cast<std::size_t>(band) * kBandRows * width]);
    }
    return lists;
}

std::int64_t locatePoint(const TetMesh& mesh, const glm::dvec3& p)
{
    for (std::size_t t = 0; t < mesh.tets.size(); ++t) {
        const glm::uvec4 v = mesh.tets[t];
        const glm::dvec3 a = mesh.points[v.x], b = mesh.points[v.y], c = mesh.points[v.z], d = mesh.points[v.w];
        const double whole = signedVolume6(a, b, c, d);
        if (!(whole > 0.0))
            continue;
        // Barycentric coordinates as signed sub-volumes; a point on a face or edge belongs to each cell there.
        const double tol = -1e-12 * whole;
        if (signedVolume6(p, b, c, d) >= tol && signedVolume6(a, p, c, d) >= tol && signedVolume6(a, b, p, d) >= tol &&
            signedVolume6(a, b, c, p) >= tol)
            return static_cast<std::int64_t>(t);
    }
    return -1;
}

void prependEyeEntry(HarcEntryLists& lists, std::uint32_t tet)
{
    const std::size_t pixels = lists.offsets.size() - 1;
    std::vector<cl_int2> entries;
    entries.reserve(lists.entries.size() + pixels);
    const cl_int start = -1 - static_cast<cl_int>(tet);  // λ = 0 (bits 0), no entry face
    for (std::size_t p = 0; p < pixels; ++p) {
        const cl_uint first = lists.offsets[p], last = lists.offsets[p + 1];
        lists.offsets[p] = static_cast<cl_uint>(entries.size());
        entries.push_back(cl_int2{{0, start}});
        entries.insert(entries.end(), lists.entries.begin() + first, lists.entries.begin() + last);
    }
    lists.offsets[pixels] = static_cast<cl_uint>(entries.size());
    lists.entries = std::move(entries);
}

std::unique_ptr<Renderer> makeHarcRenderer(Device& device, const Scene& scene, const TetMesh& mesh,
                                           const TetTopology& topology)
{
    return std::make_unique<HarcRenderer>(device, scene, mesh, topology, parseHarcOptions(scene.options));
}

std::unique_ptr<Renderer> makeHarcRenderer(Device& device, const Scene& scene, const TetMesh& mesh,
                                           const TetTopology& topology, const HarcOptions& options)
{
    return std::make_unique<HarcRenderer>(device, scene, mesh, topology, options);
}

}  // namespace clvr
