// host/render/tet/tetiso.cpp — options, interval bit-streams, vertex gradients and the tetiso renderer:
// four face draws through the raster stage (weights: back, front; shading: back, front) and
// kernels/tetiso.cl's per-pixel passes.
#include "host/render/tet/tetiso.h"

#include "host/render/camera_args.h"
#include "host/render/fragment_uniforms.h"
#include "host/render/options_util.h"
#include "host/render/scaffold.h"
#include "host/render/tet/cell_faces.h"
#include "host/render/tet/harc.h"
#include "host/runtime/embedded_kernels.h"
#include "host/runtime/errors.h"
#include "kernels/tetiso_params.h"
#include "raster/framebuffer.h"
#include "raster/pixel_transfer.h"
#include "raster/rasterizer.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <string>

namespace clvr {

static_assert(sizeof(ClTetisoParams) == 32, "also probed on the device by tests/layout_test.cpp");
static_assert(sizeof(ClTetisoUniforms) == 16);

// ---- interval bit-streams ---------------------------------------------------------------------------

IntervalBitStreams::IntervalBitStreams(const std::vector<double>& cellMin, const std::vector<double>& cellMax,
                                       double lo, double hi, int intervals)
    : cells_(cellMin.size()), lo_(lo), hi_(hi > lo ? hi : lo + 1.0)
{
    if (intervals < 1)
        throw InternalError("IntervalBitStreams: " + std::to_string(intervals) + " intervals");
    streams_.resize(static_cast<std::size_t>(intervals));
    const std::size_t bytes = (cells_ + 7) / 8;
    std::vector<std::uint8_t> bits(bytes);
    const double width = (hi_ - lo_) / intervals;
    for (int i = 0; i < intervals; ++i) {
        // Interval i is [a, b]; a cell's bit is set unless all its values are below a or all above b.
        const double a = lo_ + i * width, b = i + 1 == intervals ? hi_ : lo_ + (i + 1) * width;
        std::fill(bits.begin(), bits.end(), std::uint8_t{0});
        for (std::size_t c = 0; c < cells_; ++c)
            if (!(cellMax[c] < a) && !(cellMin[c] > b))
                bits[c / 8] |= static_cast<std::uint8_t>(1u << (c % 8));
        Stream& s = streams_[static_cast<std::size_t>(i)];
        std::size_t at = 0;
        while (at < bytes) {
            std::size_t zeros = 0;
            while (at < bytes && bits[at] == 0) {
                ++zeros;
                ++at;
            }
            std::size_t literals = 0;
            while (at < bytes && bits[at] != 0) {
                s.bytes.push_back(bits[at]);
                ++literals;
                ++at;
            }
            if (literals)  // trailing zero bytes need no run: the stream simply ends
                s.runs.push_back({static_cast<std::uint32_t>(zeros), static_cast<std::uint32_t>(literals)});
        }
    }
}

int IntervalBitStreams::intervalOf(double value) const
{
    const int n = intervals();
    const double x = (value - lo_) / (hi_ - lo_) * n;
    if (!(x > 0.0))
        return 0;
    return std::min(static_cast<int>(x), n - 1);
}

std::vector<std::uint32_t> IntervalBitStreams::cells(int interval) const
{
    std::vector<std::uint32_t> out;
    const Stream& s = streams_.at(static_cast<std::size_t>(interval));
    std::size_t byte = 0, literal = 0;
    for (const Run& r : s.runs) {
        byte += r.zeroBytes;
        for (std::uint32_t k = 0; k < r.literals; ++k, ++byte, ++literal)
            for (unsigned bit = 0; bit < 8; ++bit)
                if ((s.bytes[literal] >> bit) & 1u)
                    out.push_back(static_cast<std::uint32_t>(8 * byte + bit));
    }
    return out;
}

std::uint64_t IntervalBitStreams::encodedBytes() const
{
    std::uint64_t n = 0;
    for (const Stream& s : streams_)
        n += s.runs.size() * sizeof(Run) + s.bytes.size();
    return n;
}

int IntervalBitStreams::emptyIntervals() const
{
    int n = 0;
    for (const Stream& s : streams_)
        n += s.runs.empty() ? 1 : 0;
    return n;
}

// ---- vertex gradients -------------------------------------------------------------------------------

std::vector<glm::dvec3> averagedVertexGradients(const TetMesh& mesh)
{
    std::vector<glm::dvec3> sum(mesh.points.size(), glm::dvec3(0.0));
    std::vector<int> count(mesh.points.size(), 0);
    for (const glm::uvec4& t : mesh.tets) {
        // s(x) = s0 + g . (x - p0): g solves [p1-p0; p2-p0; p3-p0] g = (s1-s0, s2-s0, s3-s0).
        const glm::dvec3 p0 = mesh.points[t[0]];
        const glm::dmat3 m = glm::transpose(glm::dmat3(mesh.points[t[1]] - p0, mesh.points[t[2]] - p0, mesh.points[t[3]] - p0));
        const double det = glm::determinant(m);
        if (!(std::abs(det) > 0.0))
            continue;
        const double s0 = mesh.scalars[t[0]];
        const glm::dvec3 ds(mesh.scalars[t[1]] - s0, mesh.scalars[t[2]] - s0, mesh.scalars[t[3]] - s0);
        const glm::dvec3 g = glm::inverse(m) * ds;
        for (int k = 0; k < 4; ++k) {
            sum[t[k]] += g;
            ++count[t[k]];
        }
    }
    for (std::size_t p = 0; p < sum.size(); ++p)
        if (count[p])
            sum[p] /= count[p];
    return sum;
}

// ---- the renderer -----------------------------------------------------------------------------------

namespace {


// The scene's iso-surface, checked for tetiso: present, shaded with gradients or not at all.
IsoSpec checkedIso(const Scene& scene)
{
    if (!scene.iso)
        throw InputError("iso: technique tetiso needs \"iso\": {\"value\": ...}, and the scene has none");
    if (scene.iso->shading == IsoSpec::Shading::Gradientless)
        throw InputError("iso.shading: tetiso shades with vertex gradients: \"gradient\" or \"none\", got \"gradientless\"");
    return *scene.iso;
}

// Per point the shading normal -gradient / |gradient| of the averaged cell gradients (0 where it is 0).
std::vector<glm::dvec3> vertexNormals(const TetMesh& mesh)
{
    std::vector<glm::dvec3> normals = averagedVertexGradients(mesh);
    for (glm::dvec3& n : normals) {
        const double length = glm::length(n);
        n = length > 0.0 ? -n / length : glm::dvec3(0.0);
    }
    return normals;
}

std::string tetisoFragmentSource()
{
    return "#define CLVR_TETISO_FRAGMENT 1\n" + std::string(embeddedKernelSource("tetiso.cl"));
}

class Tetiso final : public TetisoRenderer {
public:
    Tetiso(Device& device, const Scene& scene, const TetMesh& mesh);
    Image4f render(FrameStats& stats) override;
    std::uint64_t residentBytes() const override { return 0; }  // everything is drawn from the host
    void setTransferFunction(const TransferFunction& tf) override { color_ = surfaceColor(tf); }
    std::vector<double> hitDepth() override;
    // Every frame draws from camera_ (and lights from it): a new view is a new camera.
    bool setCamera(const Scene& scene) override
    {
        if (!sameImageSize(scene.image, image_))
            return false;  // the frame buffer and the per-pixel buffers would change
        image_ = scene.image;
        camera_ = frameCamera(scene, meshLo_, meshHi_).relativeTo(shift_);
        return true;
    }

private:
    glm::dvec3 surfaceColor(const TransferFunction& tf) const
    {
        return tf.points().empty() ? glm::dvec3(1.0) : glm::dvec3(tf(iso_.value));
    }

    Device& device_;
    TetisoOptions options_;
    IsoSpec iso_;
    glm::dvec3 color_{1.0};
    Camera camera_;  // relative to shift_
    ImageSpec image_;
    glm::dvec3 shift_{0.0};
    glm::dvec3 meshLo_{0.0}, meshHi_{0.0};  // the mesh box in world coordinates, which frames the camera
    CellFaces cells_;
    std::vector<float> scalars_;            // normalized to [0, 1] over the mesh's range
    std::vector<glm::dvec3> normals_;       // -gradient / |gradient| per point (0 where the gradient is 0)
    double sLo_ = 0.0, sScale_ = 1.0;       // normalized = (s - sLo_) * sScale_
    float isoNormalized_ = 0.0f;
    std::vector<std::uint32_t> drawn_;      // the cells whose value range holds the iso-value
    std::uint64_t candidates_ = 0;          // the cells of its interval's bit-stream
    std::uint64_t streamBytes_ = 0;
    int emptyIntervals_ = 0;
    MeshCounts counts_;
    raster::Rasterizer rasterizer_;
    raster::Framebuffer fb_;
    // Per direction of the crossing (0 upwards, 1 downwards): the kept back-face image, the cell-id test
    // of the front-face draws against it, and the weights found.
    cl::Buffer kept_[2], weights_[2];
    raster::FragmentProgram frontProgram_[2];
    cl::Buffer chosen_, image_buffer_;
    cl::Kernel weightsKernel_, nearer_, add_, finish_;
    double hitZLo_ = 0.0, hitTScale_ = 1.0;  // the last frame's normalization of the depth channel t
};

Tetiso::Tetiso(Device& device, const Scene& scene, const TetMesh& mesh)
    : device_(device), options_(parseTetisoOptions(scene.options)), image_(scene.image),
      shift_(0.5 * (mesh.boundsMin() + mesh.boundsMax())), cells_(mesh, shift_, "tetiso"), rasterizer_(device),
      fb_(device, scene.image.width, scene.image.height, true)
{
    iso_ = checkedIso(scene);
    color_ = surfaceColor(scene.transferFunction);
    meshLo_ = mesh.boundsMin();
    meshHi_ = mesh.boundsMax();
    camera_ = frameCamera(scene, meshLo_, meshHi_).relativeTo(shift_);
    counts_ = MeshCounts::of(mesh);

    // All scalar values scaled to [0, 1] (§4.3; GL clamps the alpha-test reference to [0, 1]).
    const glm::dvec2 range = mesh.scalarRange();
    sLo_ = range.x;
    sScale_ = range.y > range.x ? 1.0 / (range.y - range.x) : 1.0;
    scalars_.resize(mesh.scalars.size());
    for (std::size_t p = 0; p < scalars_.size(); ++p)
        scalars_[p] = static_cast<float>((mesh.scalars[p] - sLo_) * sScale_);
    isoNormalized_ = static_cast<float>(std::clamp((iso_.value - sLo_) * sScale_, 0.0, 1.0));

    normals_ = vertexNormals(mesh);

    // The iso-value's interval, then the exact range test of each of its cells.
    std::vector<double> cellMin(mesh.tets.size()), cellMax(mesh.tets.size());
    for (std::size_t c = 0; c < mesh.tets.size(); ++c) {
        double a = std::numeric_limits<double>::infinity(), b = -a;
        for (int k = 0; k < 4; ++k) {
            a = std::min(a, mesh.scalars[mesh.tets[c][k]]);
            b = std::max(b, mesh.scalars[mesh.tets[c][k]]);
        }
        cellMin[c] = a;
        cellMax[c] = b;
    }
    const IntervalBitStreams streams(cellMin, cellMax, range.x, range.y, options_.intervals);
    streamBytes_ = streams.encodedBytes();
    emptyIntervals_ = streams.emptyIntervals();
    const std::vector<std::uint32_t> candidates = streams.cells(streams.intervalOf(iso_.value));
    candidates_ = candidates.size();
    for (const std::uint32_t c : candidates)
        if (cellMin[c] <= iso_.value && iso_.value <= cellMax[c])
            drawn_.push_back(c);

    const std::size_t pixels = static_cast<std::size_t>(image_.width) * image_.height;
    ClTetisoUniforms uniforms{};
    uniforms.size = cl_float4{{static_cast<float>(image_.width), static_cast<float>(image_.height), 0.0f, 0.0f}};
    for (int dir = 0; dir < 2; ++dir) {
        kept_[dir] = device_.buffer(dir ? "tetiso kept back faces (downwards)" : "tetiso kept back faces (upwards)",
                                    pixels * sizeof(cl_float4));
        weights_[dir] = device_.buffer(dir ? "tetiso weights (downwards)" : "tetiso weights (upwards)",
                                       pixels * sizeof(cl_float4));
        frontProgram_[dir].source = tetisoFragmentSource();
        frontProgram_[dir].attributes = 2;  // the color, the cell id
        frontProgram_[dir].buffers[0] = kept_[dir];
        frontProgram_[dir].uniforms = fragmentUniforms(uniforms);
    }
    chosen_ = device_.buffer("tetiso chosen crossing", pixels * sizeof(cl_float4));
    image_buffer_ = device_.buffer("tetiso image", pixels * sizeof(cl_float4));
    weightsKernel_ = device_.kernel("tetiso.cl", "tetiso_weights");
    nearer_ = device_.kernel("tetiso.cl", "tetiso_nearer");
    add_ = device_.kernel("tetiso.cl", "tetiso_add");
    finish_ = device_.kernel("tetiso.cl", "tetiso_finish");
}

Image4f Tetiso::render(FrameStats& stats)
{
    const FrameClock clock;
    auto t0 = std::chrono::steady_clock::now();
    const std::size_t pixels = static_cast<std::size_t>(image_.width) * image_.height;
    const std::vector<glm::dvec3>& points = cells_.points();
    const glm::dvec3 forward = camera_.forward();

    // Eye depths: normalized over the points' range for the depth channel t; near and far around it.
    std::vector<double> z(points.size());
    double zLo = std::numeric_limits<double>::infinity(), zHi = -zLo;
    for (std::size_t p = 0; p < points.size(); ++p) {
        z[p] = glm::dot(points[p] - camera_.position, forward);
        zLo = std::min(zLo, z[p]);
        zHi = std::max(zHi, z[p]);
    }
    const double margin = 0.01 * (zHi - zLo) + 1e-9;
    const double farZ = std::max(zHi + margin, 1e-6);
    const double nearZ = std::max(zLo - margin, farZ * 1e-5);
    const double tScale = zHi > zLo ? 1.0 / (zHi - zLo) : 1.0;
    const glm::dmat4 viewProjection =
        camera_.projectionMatrix(image_.width, image_.height, nearZ, farZ) * camera_.viewMatrix();

    // Vertex colors: (t, -, -, s) for the weights, (shade, s) for the shading (Gouraud: the light at
    // the vertices, interpolated; clamped per pixel at the end).
    const glm::dvec3 light = iso_.lightFor(camera_);
    std::vector<raster::Vertex> weightVertex(points.size()), shadeVertex(points.size());
    for (std::size_t p = 0; p < points.size(); ++p) {
        const glm::vec4 clip(viewProjection * glm::dvec4(points[p], 1.0));
        const float s = scalars_[p];
        const glm::dvec3 shade = iso_.shading == IsoSpec::Shading::None
                                     ? color_
                                     : color_ * (iso_.ambient + iso_.diffuse * glm::dot(light, normals_[p]));
        weightVertex[p].position = shadeVertex[p].position = clip;
        weightVertex[p].attributes[0] = glm::vec4(static_cast<float>((z[p] - zLo) * tScale), 0.0f, 0.0f, s);
        shadeVertex[p].attributes[0] = glm::vec4(glm::vec3(shade), s);
    }
    const std::vector<std::uint8_t> backMask = cells_.backFacing(camera_);
    std::vector<raster::Vertex> weightBack, weightFront, shadeBack, shadeFront;
    cells_.appendFaces(drawn_, backMask, true, weightVertex, 1u, weightBack);
    cells_.appendFaces(drawn_, backMask, false, weightVertex, 3u, weightFront);  // ids in the color and attr[1]
    cells_.appendFaces(drawn_, backMask, true, shadeVertex, 0u, shadeBack);
    cells_.appendFaces(drawn_, backMask, false, shadeVertex, 2u, shadeFront);
    const double setUpMs = msSince(t0);

    // Per direction: the nearest back face past the surface (alpha = s > iso upwards, < iso downwards),
    // the stencil set there; then that cell's front face on the other side (alpha <= iso, >= iso).
    raster::DrawState back[2], front[2];
    for (int dir = 0; dir < 2; ++dir) {
        raster::FragmentState& b = back[dir].fragment;
        b.alpha = {true, dir ? raster::CompareFunc::Less : raster::CompareFunc::Greater, isoNormalized_};
        b.depth.test = true;
        b.depth.func = raster::CompareFunc::Less;
        b.stencil.test = true;
        b.stencil.func = raster::CompareFunc::Always;
        b.stencil.ref = 1;
        b.stencil.dppass = raster::StencilOp::Replace;
        raster::FragmentState& f = front[dir].fragment;
        f.alpha = {true, dir ? raster::CompareFunc::GEqual : raster::CompareFunc::LEqual, isoNormalized_};
        f.stencil.test = true;
        f.stencil.func = raster::CompareFunc::Equal;
        f.stencil.ref = 1;
        f.stencil.writeMask = 0;
    }

    ClTetisoParams params{};
    params.background = toCl4(image_.background);
    params.count = static_cast<cl_int>(pixels);
    params.equal = options_.weights == TetisoOptions::Weights::Equal ? 1 : 0;
    params.iso = isoNormalized_;
    const glm::vec4 noFace(0.0f, kNoFace, kNoFace, 0.0f);
    const auto launch = [&](cl::Kernel& k, const char* name, std::initializer_list<const cl::Buffer*> buffers) {
        int a = 0;
        for (const cl::Buffer* b : buffers)
            k.setArg(a++, *b);
        k.setArg(a, params);
        device_.launch(name, k, pixels);
    };

    // a. Interpolation weights, for the crossings upwards and downwards; the nearer is the first crossing.
    for (int dir = 0; dir < 2; ++dir) {
        fb_.clearColor(device_, noFace);
        fb_.clearDepth(device_, 1.0f);
        fb_.clearStencil(device_, 0);
        rasterizer_.draw(fb_, back[dir], raster::Topology::Triangles, weightBack);
        device_.queue().enqueueCopyBuffer(fb_.color(), kept_[dir], 0, 0, pixels * sizeof(cl_float4));  // glCopyPixels
        fb_.clearColor(device_, noFace);
        rasterizer_.draw(fb_, front[dir], raster::Topology::Triangles, weightFront, frontProgram_[dir]);
        launch(weightsKernel_, "tetiso: weights", {&weights_[dir], &fb_.color(), &kept_[dir]});
    }
    launch(nearer_, "tetiso: nearer crossing", {&chosen_, &weights_[0], &weights_[1]});
    // b. and c. The shaded faces, modulated by the weights and summed in the accumulation buffer.
    fb_.clearAccum(device_, glm::vec4(0.0f));
    for (int dir = 0; dir < 2; ++dir) {
        fb_.clearColor(device_, glm::vec4(0.0f));
        fb_.clearDepth(device_, 1.0f);
        fb_.clearStencil(device_, 0);
        rasterizer_.draw(fb_, back[dir], raster::Topology::Triangles, shadeBack);
        params.pass = dir + 2;
        launch(add_, "tetiso: accumulate q * back shade", {&fb_.accum(), &fb_.color(), &chosen_});
        fb_.clearColor(device_, glm::vec4(0.0f));
        rasterizer_.draw(fb_, front[dir], raster::Topology::Triangles, shadeFront, frontProgram_[dir]);
        params.pass = dir;
        launch(add_, "tetiso: accumulate (1 - q) * front shade", {&fb_.accum(), &fb_.color(), &chosen_});
    }
    launch(finish_, "tetiso: accumulation buffer over background", {&image_buffer_, &fb_.accum()});

    Image4f image = readImage(device_, image_buffer_, image_.width, image_.height);
    hitZLo_ = zLo;
    hitTScale_ = tScale;
    std::uint64_t hits = 0;  // alpha is the coverage: q + (1 - q) where a surface was found, else 0
    for (const glm::vec4& c : image.pixels())
        hits += c.a > 0.0f ? 1 : 0;
    const raster::DrawStats drawn = rasterizer_.takeStats();

    std::vector<PassTime> hostPasses = {{"tetiso: vertex colors, facing, face lists (host)", setUpMs}};
    const std::size_t hostCount = hostPasses.size();
    finishFrame(device_, clock, stats, std::move(hostPasses));
    stats.extra["launches"] = mergePassesByName(stats.passes) - hostCount;  // per pass name: its launches summed
    counts_.report(stats);
    stats.extra["path"] = "raster";
    stats.extra["iso_value"] = iso_.value;
    stats.extra["weights"] = options_.weights == TetisoOptions::Weights::Equal ? "equal" : "interpolated";
    stats.extra["intervals"] = options_.intervals;
    stats.extra["intervals_empty"] = emptyIntervals_;
    stats.extra["bitstream_bytes"] = streamBytes_;
    stats.extra["bitstream_bytes_per_tet"] = static_cast<double>(streamBytes_) / static_cast<double>(cells_.cellCount());
    stats.extra["cells_in_interval"] = candidates_;
    stats.extra["cells_drawn"] = drawn_.size();
    stats.extra["pixels_hit"] = hits;
    stats.extra["raster_triangles"] = drawn.triangles;
    stats.extra["raster_fragments"] = drawn.fragments;
    stats.extra["resident_bytes"] = 0;
    stats.extra["bytes_per_tet"] = 0.0;  // the mesh stays on the host; the faces are drawn from there
    return image;
}

std::vector<double> Tetiso::hitDepth()
{
    const std::size_t pixels = static_cast<std::size_t>(image_.width) * image_.height;
    const std::vector<cl_float4> w = device_.download<cl_float4>(chosen_, pixels);
    std::vector<double> z(pixels, std::numeric_limits<double>::infinity());
    for (std::size_t i = 0; i < pixels; ++i)
        if (w[i].s[2] != 0.0f)
            z[i] = hitZLo_ + static_cast<double>(w[i].s[1]) / hitTScale_;
    return z;
}

// The fused path: harc's renderer walking the cells with Integration::Iso — the first crossing of each ray,
// shaded from the same vertex normals, light and weights as the face draws —, its stats named as tetiso's.
class TetisoFused final : public TetisoRenderer {
public:
    TetisoFused(Device& device, const Scene& scene, const TetMesh& mesh)
        : iso_(checkedIso(scene)), lo_(mesh.boundsMin()), hi_(mesh.boundsMax())
    {
        weights_ = parseTetisoOptions(scene.options).weights == TetisoOptions::Weights::Equal ? "equal" : "interpolated";
        walk_ = makeHarcRenderer(device, scene, mesh, buildTopology(mesh), tetisoWalkOptions(scene, mesh));
    }
    Image4f render(FrameStats& stats) override
    {
        Image4f image = walk_->render(stats);
        stats.samples = 0;
        stats.extra["path"] = "fused";
        stats.extra["pixels_hit"] = stats.extra["pieces"];  // the walk's count of rays that found a crossing
        stats.extra["iso_value"] = iso_.value;
        stats.extra["weights"] = weights_;
        return image;
    }
    std::uint64_t residentBytes() const override { return walk_->residentBytes(); }
    void setTransferFunction(const TransferFunction& tf) override { walk_->setTransferFunction(tf); }
    std::vector<double> hitDepth() override { return harcIsoHitDepth(*walk_); }
    // The walk takes the new camera and the light that follows it (IsoSpec::lightFor).
    bool setCamera(const Scene& scene) override
    {
        HarcOptions view;
        view.iso.light = iso_.lightFor(frameCamera(scene, lo_, hi_));
        return harcSetView(*walk_, scene, view);
    }

private:
    IsoSpec iso_;
    glm::dvec3 lo_, hi_;  // the mesh box, which frames the camera
    std::unique_ptr<Renderer> walk_;
    std::string weights_;
};

}  // namespace

HarcOptions tetisoWalkOptions(const Scene& scene, const TetMesh& mesh)
{
    const IsoSpec iso = checkedIso(scene);
    const TetisoOptions options = parseTetisoOptions(scene.options);
    HarcOptions harc;
    harc.integration = HarcOptions::Integration::Iso;
    harc.iso.value = iso.value;
    harc.iso.normals = vertexNormals(mesh);
    harc.iso.light = iso.lightFor(frameCamera(scene, mesh.boundsMin(), mesh.boundsMax()));
    harc.iso.ambient = iso.ambient;
    harc.iso.diffuse = iso.diffuse;
    harc.iso.shaded = iso.shading != IsoSpec::Shading::None;
    harc.iso.equalWeights = options.weights == TetisoOptions::Weights::Equal;
    harc.packets = options.packets;
    return harc;
}

TechniqueInfo tetisoTechnique()
{
    TechniqueInfo t;
    t.name = "tetiso";
    t.data = DataKind::Mesh;
    t.description = "shaded iso-surfaces of tetrahedral grids from cell faces with interpolation weights, seeds/000 §4.1 (docs/tetiso.md)";
    t.options = {
        {"weights", "interpolated", "", "\"interpolated\" (Figure 8's weights) or \"equal\" (front and back faces blended equally, Figure 9 left)"},
        {"intervals", 64, "", "interval bit-streams over the value range, 1..4096 (which cells an iso-value draws; raster path)"},
        {"path", "fused", "", "\"fused\" (harc's cell walk stops at each ray's first crossing) or \"raster\" (the face "
                              "draws and per-pixel passes of seeds/000 §4.1)"},
        packetsInfo(),
    };
    t.makeForMesh = [](Device& device, const Scene& scene, const TetMesh& mesh) -> std::unique_ptr<Renderer> {
        return makeTetisoRenderer(device, scene, mesh);
    };
    return t;
}

TetisoOptions parseTetisoOptions(const nlohmann::json& options)
{
    static const TechniqueInfo& info = technique("tetiso");
    TetisoOptions o;
    forEachOption(options, info, [&](const std::string& key, const nlohmann::json& value) {
        if (key == "weights") {
            const std::string s = value.is_string() ? value.get<std::string>() : "";
            if (s == "interpolated")
                o.weights = TetisoOptions::Weights::Interpolated;
            else if (s == "equal")
                o.weights = TetisoOptions::Weights::Equal;
            else
                badOption(key, "must be \"interpolated\" or \"equal\", got " + value.dump());
        } else if (key == "intervals") {
            o.intervals = integerOption(key, value, 1, 4096);
        } else if (key == "path") {
            o.path = choiceOption(key, value, {"fused", "raster"}) == 0 ? TetisoOptions::Path::Fused
                                                                       : TetisoOptions::Path::Raster;
        } else if (key == "packets") {
            o.packets = packetsOption(key, value);
        } else {
            unparsedOption(info, key);
        }
    });
    return o;
}

std::unique_ptr<TetisoRenderer> makeTetisoRenderer(Device& device, const Scene& scene, const TetMesh& mesh)
{
    if (parseTetisoOptions(scene.options).path == TetisoOptions::Path::Fused)
        return std::make_unique<TetisoFused>(device, scene, mesh);
    return std::make_unique<Tetiso>(device, scene, mesh);
}

}  // namespace clvr
