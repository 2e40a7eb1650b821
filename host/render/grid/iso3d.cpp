// host/render/grid/iso3d.cpp — options, "iso" parsing, the encoded normal volume, the paper's color matrix,
// and the passes of the iso3d technique: slices through raster::draw with kernels/iso3d.cl as fragment
// program under the alpha and depth tests, the color-matrix copy, and kernels/iso3d.cl: iso3d_finish.
#include "host/render/grid/iso3d.h"

#include "host/render/grid/slice3d.h"  // buildBrickGrid, emptySpaceRadii: slice3d's bricks

#include "host/render/camera_args.h"
#include "host/render/scaffold.h"
#include "host/runtime/embedded_kernels.h"
#include "host/runtime/errors.h"
#include "host/render/options_util.h"
#include "host/optics/gradient_volume.h"
#include "host/render/fragment_uniforms.h"
#include "host/render/slice_plan.h"  // planSlices, slicePolygon: the same slices as slice3d
#include "kernels/iso3d_params.h"
#include "raster/framebuffer.h"
#include "raster/pixel_transfer.h"
#include "raster/rasterizer.h"
#include "raster/texture.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>

namespace clvr {

static_assert(sizeof(ClIso3dFinishParams) == 48, "also probed on the device by tests/layout_test.cpp");
static_assert(sizeof(ClIso3dFusedParams) == 240, "also probed on the device by tests/layout_test.cpp");

namespace {

// Figure 7: how far behind the box entry (in slices) the depth buffer is put. The first slice inside the box
// lies within one slice of the entry; 1.5 keeps it in front on faces seen obliquely by a perspective camera.
constexpr double kEntryDepthSlices = 1.5;

class Iso3dRendererImpl final : public Iso3dRenderer {
public:
    Iso3dRendererImpl(Device& device, const Scene& scene, const Volume& volume);
    Image4f render(FrameStats& stats) override;
    std::uint64_t residentBytes() const override { return residentBytes_; }
    void setTransferFunction(const TransferFunction& tf) override;
    std::vector<double> hitDepth() override;
    double sliceSpacing() const override { return plan_.deltaS; }
    // The volumes, bricks and programs do not depend on the view: a new camera plans its slices again, and
    // the headlight (IsoSpec::lightFor) follows it, with gradientless shading's shift along the light.
    bool setCamera(const Scene& scene) override
    {
        if (!sameImageSize(scene.image, image_))
            return false;  // the frame buffer and the per-pixel buffers would change
        image_ = scene.image;
        camera_ = frameCamera(scene, lo_, hi_);
        iso_.light = isoSurface(scene, camera_).light;  // the color stays: setTransferFunction may have set it
        plan_ = planSlices(camera_, lo_, hi_, options_.slices, options_.sliceSpacing);
        setTextureShift();
        return true;
    }

private:
    Device& device_;
    Iso3dOptions options_;
    IsoSurface iso_;
    Camera camera_;
    ImageSpec image_;
    glm::dvec3 lo_, hi_;
    SlicePlan plan_;
    double nearZ_ = 0.0, farZ_ = 0.0;  // of the projection the slices were drawn with
    float alphaRef_ = 0.0f;            // the iso-value in alpha's [0,1] (see the constructor)
    cl::Buffer volume_;
    std::uint64_t residentBytes_ = 0;
    std::unique_ptr<raster::Framebuffer> framebuffer_;
    raster::FragmentProgram fragmentProgram_;
    ClIso3dUniforms fragmentUniforms_{};
    cl::Kernel finish_;
    cl::Kernel fused_;             // options_.path == Fused: iso3d_fused ...
    cl::Buffer fusedSamples_;      // ... its samples per pixel
    cl::Buffer values_;            // ... the scalar volume it tests the value on (the RGBA volume's alpha)
    cl::Buffer space_;             // ... and its empty-space radii per brick (kernels/empty_space.h)
    glm::ivec3 brickDims_{0};
    std::uint64_t emptyBrickCount_ = 0;
    // Gradientless shading: the scalar volume as a 3D texture (texel centers at the grid points) and
    // the shift Delta L in texture coordinates.
    std::unique_ptr<raster::Texture> scalarTexture_;
    double gradientlessStep_ = 0.0, gradientlessScale_ = 0.0;
    glm::vec4 textureShift_{0.0f};
    // Bricking (§3.1): with more than one brick, brickData_ holds each brick's part of the RGBA volume on
    // the host (index x + counts.x (y + counts.y z)), uploaded in turn into the one device buffer volume_.
    glm::dvec3 origin_{0.0}, spacing_{1.0};
    glm::ivec3 dims_{0};
    MemoryBricks bricks_;
    std::vector<std::vector<glm::vec4>> brickData_;

    // Gradientless shading's Delta L along the light, in texture coordinates (textureShift_).
    void setTextureShift()
    {
        if (iso_.shading == IsoSurface::Shading::Gradientless)
            textureShift_ = glm::vec4(glm::vec3(gradientlessStep_ * iso_.light / (spacing_ * glm::dvec3(dims_))), 0.0f);
    }
    raster::DrawStats drawSlices(const glm::dmat4& viewProjection, FrameStats& stats);
    raster::DrawStats drawFused();
    raster::DrawStats drawBricks(const raster::DrawState& state, const std::vector<raster::Vertex>& vertices,
                                 const std::vector<std::size_t>& sliceFirst, const glm::dmat4& viewProjection,
                                 FrameStats& stats);
};

Iso3dRendererImpl::Iso3dRendererImpl(Device& device, const Scene& scene, const Volume& volume)
    : device_(device), options_(parseIso3dOptions(scene.options)), image_(scene.image)
{
    if (!scene.iso)
        throw InputError("iso: technique iso3d needs \"iso\": {\"value\": ...}, and the scene has none");
    checkGridVolume(volume, "iso3d");
    lo_ = volume.boundsMin();
    hi_ = volume.boundsMax();
    camera_ = frameCamera(scene, lo_, hi_);
    iso_ = isoSurface(scene, camera_);
    plan_ = planSlices(camera_, lo_, hi_, options_.slices, options_.sliceSpacing);

    origin_ = volume.origin;
    spacing_ = volume.spacing;
    dims_ = volume.dims;
    const bool gradientless = iso_.shading == IsoSurface::Shading::Gradientless;
    // Every byte of texture per grid point: the RGBA volume, and gradientless shading's scalar texture.
    const std::uint64_t bytesPerPoint = sizeof(glm::vec4) + (gradientless ? sizeof(float) : 0);
    bricks_ = iso3dBrickGrid(volume.dims, options_, bytesPerPoint);
    const std::string brickKey = options_.bricks.x > 0 ? "bricks" : "brick_budget";
    const std::string brickGrid = std::to_string(bricks_.counts.x) + "x" + std::to_string(bricks_.counts.y) + "x" +
                                  std::to_string(bricks_.counts.z);
    if (bricks_.count() > 1 && gradientless)
        badOption(brickKey, "gives " + brickGrid + " bricks, and bricking works with iso.shading \"gradient\" or "
                            "\"none\" only (gradientless shading's shifted lookup X(p0 + Delta L) leaves the brick)");
    if (bricks_.count() > 1 && options_.interior)
        badOption(brickKey, "gives " + brickGrid + " bricks, and bricking does not work with options.interior "
                            "(Figure 7's passes use the stencil themselves)");

    const std::vector<glm::vec4> rgba = encodedNormalVolume(volume);
    if (bricks_.count() == 1) {
        volume_ = device_.upload("iso3d RGBA volume (normal, value; float32)", rgba);
        residentBytes_ = rgba.size() * sizeof(glm::vec4);
    } else {
        // Each brick's grid points cut out of the globally computed RGBA volume (so its normals at the
        // brick faces are the unbricked ones), and one device buffer as large as the largest brick.
        for (int bz = 0; bz < bricks_.counts.z; ++bz)
            for (int by = 0; by < bricks_.counts.y; ++by)
                for (int bx = 0; bx < bricks_.counts.x; ++bx)
                    brickData_.push_back(brickPoints(rgba, volume.dims, bricks_, glm::ivec3(bx, by, bz)));
        residentBytes_ = bricks_.maxBytes();
        volume_ = device_.buffer("iso3d brick (RGBA: normal, value; float32)", residentBytes_, CL_MEM_READ_ONLY);
    }

    // GL clamps the alpha reference to [0,1], as the paper's 8-bit textures hold values in [0,1]:
    // the value range, widened to hold the iso-value (so that an iso-value above every value keeps
    // nothing), is mapped onto [0,1]. Both sides use the same float operations (value - lo) * scale,
    // monotonic in the value, so value >= iso implies alpha >= reference.
    const glm::dvec2 range = volume.range();
    const float valueLo = static_cast<float>(std::min(range.x, iso_.value));
    const float valueHi = static_cast<float>(std::max(range.y, iso_.value));
    const float scale = valueHi > valueLo ? 1.0f / (valueHi - valueLo) : 1.0f;
    alphaRef_ = (static_cast<float>(iso_.value) - valueLo) * scale;

    framebuffer_ = std::make_unique<raster::Framebuffer>(device_, image_.width, image_.height);
    finish_ = device_.kernel("iso3d.cl", "iso3d_finish");
    if (options_.path == Iso3dOptions::Path::Fused) {
        std::vector<float> scratch;
        values_ = device_.upload("iso3d scalar volume (fused path's alpha test; float32)", volume.floats(scratch));
        residentBytes_ += volume.voxelCount() * sizeof(float);
        // Empty-space skipping: slice3d's bricks whose values all lie below the iso-value.
        const std::vector<std::uint8_t> space = iso3dEmptySpace(volume, iso_.value, brickDims_, emptyBrickCount_);
        space_ = device_.upload("iso3d empty-space radii", space);
        residentBytes_ += space.size();
        fused_ = device_.kernel("iso3d.cl", "iso3d_fused");
        fusedSamples_ = device_.buffer("iso3d fused samples per pixel", framebuffer_->pixelCount() * sizeof(cl_uint),
                                       CL_MEM_WRITE_ONLY);
    }
    const std::string_view source = embeddedKernelSource("iso3d.cl");
    fragmentProgram_.source = "#define CLVR_ISO3D_FRAGMENT 1\n" + std::string(source);
    fragmentProgram_.attributes = 1;  // the world position
    fragmentProgram_.buffers[0] = volume_;
    if (options_.interior && gradientless)
        badOption("interior", "works with \"gradient\" or \"none\" shading (the gradientless difference would need its "
                              "sign turned per pixel), and iso.shading is \"gradientless\"");
    const cl_float4 dims{{static_cast<float>(volume.dims.x), static_cast<float>(volume.dims.y),
                          static_cast<float>(volume.dims.z), 0.0f}};
    fragmentUniforms_.grid_origin = toCl4(volume.origin);
    fragmentUniforms_.inv_spacing = toCl4(1.0 / volume.spacing);
    fragmentUniforms_.dims = dims;
    fragmentUniforms_.value_map = cl_float4{{valueLo, scale, gradientless ? 1.0f : 0.0f, 0.0f}};
    fragmentUniforms_.brick_lo = cl_float4{{0.0f, 0.0f, 0.0f, 0.0f}};  // the brick's first grid point ...
    fragmentUniforms_.brick_end = dims;                               // ... the end of its box ...
    fragmentUniforms_.brick_dims = dims;                              // ... its dims: unbricked, all
    fragmentProgram_.uniforms = fragmentUniforms(fragmentUniforms_);
    if (gradientless) {
        raster::TextureDesc desc;
        desc.width = volume.dims.x;
        desc.height = volume.dims.y;
        desc.depth = volume.dims.z;
        desc.channels = 1;
        desc.filter = raster::Filter::Linear;
        desc.wrap = raster::Wrap::ClampToEdge;
        std::vector<float> scratch;
        scalarTexture_ = std::make_unique<raster::Texture>(device_, desc, volume.floats(scratch));
        residentBytes_ += scalarTexture_->bytes();
        gradientlessStep_ = options_.gradientlessStep > 0.0
                                ? options_.gradientlessStep
                                : std::min({volume.spacing.x, volume.spacing.y, volume.spacing.z});
        // X(p0) - X(p0 + Delta L) ~ Delta |grad X| <L, N>: the paper's condition is |grad X| = 1 (then
        // k = 1 / Delta); clvr divides by the median gradient length at the surface instead, unless given.
        gradientlessScale_ = options_.gradientlessScale > 0.0
                                 ? options_.gradientlessScale
                                 : 1.0 / (gradientlessStep_ * medianGradientAtIso(volume, iso_.value));
        // Delta L in world units -> grid units (/ spacing) -> texture coordinates (/ n).
        setTextureShift();
    }
}

void Iso3dRendererImpl::setTransferFunction(const TransferFunction& tf)
{
    // Only the surface color depends on it (the color at the iso-value).
    iso_.color = tf.points().empty() ? glm::dvec3(1.0) : glm::dvec3(tf(iso_.value));
}

Image4f Iso3dRendererImpl::render(FrameStats& stats)
{
    const FrameClock clock;
    // The projection of the slice draws (and of the fused path's window depths).
    nearZ_ = 0.5 * plan_.depth(0);
    farZ_ = 2.0 * plan_.depthMax + 1.0;
    const glm::dmat4 viewProjection =
        camera_.projectionMatrix(image_.width, image_.height, nearZ_, farZ_) * camera_.viewMatrix();
    // Uploads per frame: none unbricked (the volume stays resident between frames); drawBricks counts its own.
    stats.extra["brick_uploads"] = 0;
    stats.extra["brick_upload_bytes"] = 0;
    stats.extra["brick_upload_ms"] = 0.0;
    const raster::DrawStats drawStats =
        options_.path == Iso3dOptions::Path::Fused ? drawFused() : drawSlices(viewProjection, stats);

    const bool shaded = iso_.shading != IsoSurface::Shading::None;
    if (iso_.shading == IsoSurface::Shading::Gradient) {
        // Gradient shading (§3): the frame buffer copied onto itself through the color matrix with the
        // reflectivity as scale and the ambient term as bias, giving c (k_d <L, N> + I_a) in RGB.
        raster::applyPixelTransfer(device_, *framebuffer_, isoShadingTransfer(iso_));
    } else if (shaded) {
        // Gradientless shading (§3): the frame buffer holds the surface points' texture coordinates;
        // read back and drawn twice through the pixel texture: X(p0), then X(p0 + Delta L) (the shift as
        // the pixel bias) subtracted from it by blending. X(p0) - X(p0 + Delta L) ~ -Delta dX/dL =
        // Delta |grad X| <L, N>; times k = 1 / (Delta |grad|~) it is <L, N> where |grad X| = |grad|~
        // (docs/iso3d.md: off by the factor |grad X| / |grad|~ elsewhere, the paper's condition).
        const Image4f positions = framebuffer_->readColor(device_);
        raster::drawPixels(device_, *framebuffer_, positions, {0, 0}, raster::PixelTransfer{},
                           raster::DrawPixelsBlend::Replace, scalarTexture_.get());
        raster::PixelTransfer shift;
        shift.bias = textureShift_;
        raster::drawPixels(device_, *framebuffer_, positions, {0, 0}, shift, raster::DrawPixelsBlend::ReverseSubtract,
                           scalarTexture_.get());
        raster::PixelTransfer light;
        light.scale = glm::vec4(glm::vec3(iso_.diffuse * gradientlessScale_ * iso_.color), 1.0f);
        light.bias = glm::vec4(glm::vec3(iso_.ambient * iso_.color), 0.0f);
        raster::applyPixelTransfer(device_, *framebuffer_, light);
    }
    const std::size_t pixels = framebuffer_->pixelCount();
    ClIso3dFinishParams finish{};
    finish.surface = toCl4(iso_.color, 1.0);
    finish.background = toCl4(image_.background, 0.0);
    finish.n = static_cast<cl_uint>(pixels);
    finish.shaded = shaded ? 1 : 0;
    finish_.setArg(0, framebuffer_->color());
    finish_.setArg(1, framebuffer_->depth());
    finish_.setArg(2, finish);
    device_.launch("iso3d: finish", finish_, pixels);
    Image4f image = framebuffer_->readColor(device_);

    finishFrame(device_, clock, stats);
    stats.samples = drawStats.fragments;
    stats.extra["slices"] = plan_.count;
    stats.extra["slice_spacing"] = plan_.deltaS;
    stats.extra["triangles"] = drawStats.triangles;
    stats.extra["iso_value"] = iso_.value;
    stats.extra["shading"] = shadingName(iso_.shading);
    stats.extra["resident_bytes"] = residentBytes_;
    stats.extra["interior"] = options_.interior;
    stats.extra["path"] = options_.path == Iso3dOptions::Path::Fused ? "fused" : "raster";
    if (options_.path == Iso3dOptions::Path::Fused) {
        stats.extra["empty_space_skipping"] = options_.emptySpaceSkipping && emptyBrickCount_ > 0;
        stats.extra["empty_bricks"] = emptyBrickCount_;
    }
    stats.extra["bricks"] = bricks_.count();
    stats.extra["brick_grid"] = {bricks_.counts.x, bricks_.counts.y, bricks_.counts.z};
    stats.extra["brick_bytes"] = bricks_.maxBytes();
    return image;
}

// The raster path: the slice polygons drawn under the alpha and depth tests (bricked, or Figure 7's passes).
raster::DrawStats Iso3dRendererImpl::drawSlices(const glm::dmat4& viewProjection, FrameStats& stats)
{
    // The slice polygons, nearest first, fanned into one triangle list; as slice3d's raster path.
    const glm::dvec3 forward = camera_.forward();
    std::vector<raster::Vertex> vertices;
    vertices.reserve(static_cast<std::size_t>(plan_.count) * 12);
    std::vector<std::size_t> sliceFirst;  // slice k's triangles: vertices[sliceFirst[k] .. sliceFirst[k + 1])
    sliceFirst.reserve(static_cast<std::size_t>(plan_.count) + 1);
    for (int k = 0; k < plan_.count; ++k) {
        sliceFirst.push_back(vertices.size());
        const double offset = glm::dot(forward, camera_.position) + plan_.depth(k);
        const std::vector<glm::dvec3> polygon = slicePolygon(lo_, hi_, forward, offset);
        auto vertex = [&](const glm::dvec3& p) {
            raster::Vertex v;
            v.position = glm::vec4(viewProjection * glm::dvec4(p, 1.0));
            v.attributes[0] = glm::vec4(glm::vec3(p), 1.0f);
            return v;
        };
        for (std::size_t j = 1; j + 1 < polygon.size(); ++j) {
            vertices.push_back(vertex(polygon[0]));
            vertices.push_back(vertex(polygon[j]));
            vertices.push_back(vertex(polygon[j + 1]));
        }
    }
    sliceFirst.push_back(vertices.size());
    // §3: "pixel values are only drawn if they pass the z-buffer test and if the alpha value is larger
    // than or equal to the selected iso-value". Front to back with LESS, the first slice that passes
    // the alpha test at a pixel locks it; back to front would give the same image with more writes.
    raster::DrawState state;
    state.fragment.alpha.test = true;
    state.fragment.alpha.func = raster::CompareFunc::GEqual;
    state.fragment.alpha.ref = alphaRef_;
    state.fragment.depth.test = true;
    state.fragment.depth.func = raster::CompareFunc::Less;
    state.fragment.depth.write = true;
    framebuffer_->clearColor(device_, glm::vec4(0.0f));
    framebuffer_->clearDepth(device_, 1.0f);
    raster::DrawStats drawStats;
    if (vertices.empty()) {
        // the box is behind the camera: nothing to draw
    } else if (bricks_.count() > 1) {
        drawStats = drawBricks(state, vertices, sliceFirst, viewProjection, stats);
    } else if (!options_.interior) {
        drawStats = raster::draw(device_, *framebuffer_, state, raster::Topology::Triangles, vertices, fragmentProgram_);
    } else {
        // Figure 7 (§3): 1. the depth buffer right behind the first intersection with the box: its 12
        // triangles moved back by kEntryDepthSlices slices along forward, nearest kept, no color.
        raster::DrawState box;
        box.fragment.colorMask = {false, false, false, false};
        box.fragment.depth.test = true;
        box.fragment.depth.func = raster::CompareFunc::Less;
        const glm::dvec3 shift = kEntryDepthSlices * plan_.deltaS * forward;
        std::vector<raster::Vertex> boxVertices;
        auto corner = [&](int c) {
            return glm::dvec3((c & 1) ? hi_.x : lo_.x, (c & 2) ? hi_.y : lo_.y, (c & 4) ? hi_.z : lo_.z) + shift;
        };
        for (int axis = 0; axis < 3; ++axis)
            for (int side = 0; side < 2; ++side) {
                // The face's 4 corners: bit `axis` fixed to `side`, the other two bits in a cycle.
                const int a = 1 << ((axis + 1) % 3), b = 1 << ((axis + 2) % 3), base = side ? (1 << axis) : 0;
                const int quad[4] = {base, base | a, base | a | b, base | b};
                for (int t : {0, 1, 2, 0, 2, 3}) {
                    raster::Vertex v;
                    v.position = glm::vec4(viewProjection * glm::dvec4(corner(quad[t]), 1.0));
                    boxVertices.push_back(v);
                }
            }
        framebuffer_->clearStencil(device_, 0);
        raster::draw(device_, *framebuffer_, box, raster::Topology::Triangles, boxVertices);
        // 2. Samples at or above iso in front of it fail the depth test (GREATER): there the stencil is set.
        raster::DrawState mark = state;
        mark.fragment.colorMask = {false, false, false, false};
        mark.fragment.depth.func = raster::CompareFunc::Greater;
        mark.fragment.depth.write = false;
        mark.fragment.stencil.test = true;
        mark.fragment.stencil.func = raster::CompareFunc::Always;
        mark.fragment.stencil.ref = 1;
        mark.fragment.stencil.dpfail = raster::StencilOp::Replace;
        raster::draw(device_, *framebuffer_, mark, raster::Topology::Triangles, vertices, fragmentProgram_);
        // 3. The usual alpha test where the stencil is unchanged ...
        framebuffer_->clearDepth(device_, 1.0f);
        raster::DrawState exterior = state;
        exterior.fragment.stencil.test = true;
        exterior.fragment.stencil.func = raster::CompareFunc::Equal;
        exterior.fragment.stencil.ref = 0;
        drawStats = raster::draw(device_, *framebuffer_, exterior, raster::Topology::Triangles, vertices, fragmentProgram_);
        // 4. ... and reversed (LESS: the first sample below iso) where it is set; the fragment program
        // turns the normal round there (it points into the material, away from this viewer).
        raster::DrawState interior = exterior;
        interior.fragment.alpha.func = raster::CompareFunc::Less;
        interior.fragment.stencil.ref = 1;
        raster::FragmentProgram flipped = fragmentProgram_;
        ClIso3dUniforms flip = fragmentUniforms_;
        flip.value_map.s[3] = 1.0f;
        flipped.uniforms = fragmentUniforms(flip);
        const raster::DrawStats d =
            raster::draw(device_, *framebuffer_, interior, raster::Topology::Triangles, vertices, flipped);
        drawStats.fragments += d.fragments;
        drawStats.triangles += d.triangles;
    }

    return drawStats;
}

// The fused path: kernels/iso3d.cl's iso3d_fused leaves in the frame buffer what drawSlices would (color and
// depth; the stencil is unused), one work-item per pixel. Its `fragments` are the samples taken.
raster::DrawStats Iso3dRendererImpl::drawFused()
{
    ClIso3dFusedParams p{};
    p.camera = toClCamera(camera_, image_.width, image_.height);
    p.grid = fragmentUniforms_;
    p.slices = cl_float4{{static_cast<float>(plan_.depth(0)), static_cast<float>(plan_.deltaS), static_cast<float>(nearZ_),
                          static_cast<float>(farZ_)}};
    p.width = image_.width;
    p.height = image_.height;
    p.slice_count = plan_.count;
    p.alpha_ref = alphaRef_;
    const bool skip = options_.emptySpaceSkipping && emptyBrickCount_ > 0;
    p.bricks = cl_int4{{brickDims_.x, brickDims_.y, brickDims_.z, skip ? 1 : 0}};
    fused_.setArg(0, framebuffer_->color());
    fused_.setArg(1, framebuffer_->depth());
    fused_.setArg(2, fusedSamples_);
    fused_.setArg(3, volume_);
    fused_.setArg(4, values_);
    fused_.setArg(5, space_);
    fused_.setArg(6, p);
    device_.launch("iso3d: fused slices", fused_, image_.width, image_.height);
    raster::DrawStats d;
    for (const cl_uint n : device_.download<cl_uint>(fusedSamples_, framebuffer_->pixelCount()))
        d.fragments += n;
    return d;
}

raster::DrawStats Iso3dRendererImpl::drawBricks(const raster::DrawState& unbricked,
                                                const std::vector<raster::Vertex>& vertices,
                                                const std::vector<std::size_t>& sliceFirst,
                                                const glm::dmat4& viewProjection, FrameStats& stats)
{
    // §3.1: "Each brick is rendered separately from front to back starting with the one nearest to the
    // image plane. Since the stencil buffer is immediately locked whenever a hit with the surface occurs,
    // once a value has been set correctly it will never be changed." A fragment that passes the alpha test
    // (and the depth test) sets the stencil to 1; the stencil test (NOTEQUAL 1) rejects every later
    // fragment there, of this brick or of the bricks behind it.
    raster::DrawState state = unbricked;
    state.fragment.stencil.test = true;
    state.fragment.stencil.func = raster::CompareFunc::NotEqual;
    state.fragment.stencil.ref = 1;
    state.fragment.stencil.dppass = raster::StencilOp::Replace;
    framebuffer_->clearStencil(device_, 0);

    raster::DrawStats total;
    std::uint64_t uploads = 0, uploadBytes = 0;
    double uploadMs = 0.0;
    raster::FragmentProgram program = fragmentProgram_;
    ClIso3dUniforms brick = fragmentUniforms_;
    for (const BrickDraw& draw : brickDraws(bricks_, camera_, origin_, spacing_, plan_, viewProjection, image_.width,
                                            image_.height)) {
        const glm::ivec3 b = draw.brick, lo = bricks_.lo(b), hi = bricks_.hi(b), n = bricks_.dims(b);
        const int kLo = draw.kLo, kHi = draw.kHi;
        if (sliceFirst[kLo] == sliceFirst[kHi + 1])
            continue;
        state.scissor = {};
        if (draw.scissor)
            state.scissor = {true, draw.x0, draw.y0, draw.x1 - draw.x0, draw.y1 - draw.y0};

        const std::vector<glm::vec4>& data = brickData_[static_cast<std::size_t>(b.x + bricks_.counts.x * (b.y + bricks_.counts.y * b.z))];
        const auto t0 = std::chrono::steady_clock::now();
        device_.queue().enqueueWriteBuffer(volume_, CL_TRUE, 0, data.size() * sizeof(glm::vec4), data.data());
        uploadMs += std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
        ++uploads;
        uploadBytes += data.size() * sizeof(glm::vec4);

        // Upper ends of the brick's half-open box in grid units; the last slab of an axis keeps its far face.
        const glm::vec4 end(hi.x == dims_.x - 1 ? dims_.x : hi.x, hi.y == dims_.y - 1 ? dims_.y : hi.y,
                            hi.z == dims_.z - 1 ? dims_.z : hi.z, 0.0f);
        brick.brick_lo = cl_float4{{static_cast<float>(lo.x), static_cast<float>(lo.y), static_cast<float>(lo.z), 0.0f}};
        brick.brick_end = cl_float4{{end.x, end.y, end.z, end.w}};
        brick.brick_dims = cl_float4{{static_cast<float>(n.x), static_cast<float>(n.y), static_cast<float>(n.z), 0.0f}};
        program.uniforms = fragmentUniforms(brick);
        const std::vector<raster::Vertex> part(vertices.begin() + static_cast<std::ptrdiff_t>(sliceFirst[kLo]),
                                               vertices.begin() + static_cast<std::ptrdiff_t>(sliceFirst[kHi + 1]));
        const raster::DrawStats d =
            raster::draw(device_, *framebuffer_, state, raster::Topology::Triangles, part, program);
        total.fragments += d.fragments;
        total.triangles += d.triangles;
    }
    stats.extra["brick_uploads"] = uploads;
    stats.extra["brick_upload_bytes"] = uploadBytes;
    stats.extra["brick_upload_ms"] = uploadMs;
    return total;
}

std::vector<double> Iso3dRendererImpl::hitDepth()
{
    // Window depth d back to eye depth z for the projection of the last frame (glm's, NDC z in [-1,1],
    // d = (ndc + 1) / 2): perspective ndc = (f + n)/(f - n) - 2fn/((f - n) z); parallel ndc = (2z - f - n)/(f - n).
    const std::vector<float> depth = framebuffer_->readDepth(device_);
    std::vector<double> z(depth.size(), std::numeric_limits<double>::infinity());
    const double n = nearZ_, f = farZ_;
    for (std::size_t i = 0; i < depth.size(); ++i) {
        if (!(depth[i] < 1.0f))
            continue;
        const double ndc = 2.0 * depth[i] - 1.0;
        z[i] = camera_.parallel ? 0.5 * (ndc * (f - n) + f + n) : 2.0 * f * n / ((f + n) - ndc * (f - n));
    }
    return z;
}

}  // namespace

TechniqueInfo iso3dTechnique()
{
    TechniqueInfo t;
    t.name = "iso3d";
    t.data = DataKind::Volume;
    t.description = "shaded iso-surfaces by the alpha test on view-aligned slices, seeds/000 (docs/iso3d.md)";
    t.options = {
        slicesInfo(),
        sliceSpacingInfo(),
        {"gradientless_step", nullptr, "the smallest grid spacing", "gradientless shading: Delta, world units towards the light"},
        {"gradientless_scale", nullptr, "1 / (Delta median |grad| at iso)", "gradientless shading: k, per data unit"},
        {"path", "fused", "", "\"fused\" (each pixel steps through the slices in one kernel) or \"raster\" (slice draws); "
                              "interior and bricks take \"raster\""},
        {"empty_space_skipping", true, "", "fused path: step over bricks whose values all lie below the iso-value (same image)"},
        {"interior", false, "", "Figure 7: show the interior surface where the box entry is already inside"},
        {"brick_budget", nullptr, "unbricked", "at most this many bytes of brick textures on the device"},
        {"bricks", nullptr, "unbricked", "[nx, ny, nz]: exactly this brick grid (not with brick_budget)"},
    };
    t.makeForVolume = [](Device& device, const Scene& scene, const Volume& volume) -> std::unique_ptr<Renderer> {
        return makeIso3dRenderer(device, scene, volume);
    };
    return t;
}

Iso3dOptions parseIso3dOptions(const nlohmann::json& options)
{
    static const TechniqueInfo& info = technique("iso3d");
    Iso3dOptions o;
    forEachOption(options, info, [&](const std::string& key, const nlohmann::json& value) {
        if (key == "slices") {
            o.slices = slicesOption(value);
        } else if (key == "slice_spacing") {
            o.sliceSpacing = sliceSpacingOption(value);
        } else if (key == "gradientless_step") {
            if (!value.is_number() || !(value.get<double>() > 0.0) || !std::isfinite(value.get<double>()))
                badOption(key, "must be a positive number (world units), got " + value.dump());
            o.gradientlessStep = value.get<double>();
        } else if (key == "gradientless_scale") {
            if (!value.is_number() || !(value.get<double>() > 0.0) || !std::isfinite(value.get<double>()))
                badOption(key, "must be a positive number (per data unit), got " + value.dump());
            o.gradientlessScale = value.get<double>();
        } else if (key == "brick_budget") {
            if (!value.is_number_integer() || value.get<long long>() < 1)
                badOption(key, "must be a positive integer (bytes of brick textures on the device), got " + value.dump());
            o.brickBudget = value.get<std::uint64_t>();
        } else if (key == "bricks") {
            if (!value.is_array() || value.size() != 3)
                badOption(key, "must be [nx, ny, nz], bricks per axis, got " + value.dump());
            for (int a = 0; a < 3; ++a) {
                if (!value[a].is_number_integer() || value[a].get<long long>() < 1 || value[a].get<long long>() > 65536)
                    badOption(key, "must be [nx, ny, nz], integers in [1, 65536], got " + value.dump());
                o.bricks[a] = value[a].get<int>();
            }
        } else if (key == "path") {
            o.path = choiceOption(key, value, {"fused", "raster"}) == 0 ? Iso3dOptions::Path::Fused
                                                                          : Iso3dOptions::Path::Raster;
        } else if (key == "empty_space_skipping") {
            o.emptySpaceSkipping = booleanOption(key, value);
        } else if (key == "interior") {
            o.interior = booleanOption(key, value);
        } else {
            unparsedOption(info, key);
        }
    });
    checkSlicesOrSpacing(options);
    if (options.contains("brick_budget") && options.contains("bricks"))
        badOption("bricks", "give either brick_budget or bricks, not both");
    // Bricks (one texture upload per brick between draws) and Figure 7's stencil passes are raster-stage work.
    for (const char* key : {"interior", "brick_budget", "bricks"}) {
        if (!options.contains(key) || (std::string(key) == "interior" && !o.interior))
            continue;
        if (options.contains("path") && o.path == Iso3dOptions::Path::Fused)
            badOption("path", std::string("\"fused\" does not work with ") + key +
                                  " (the raster path's passes do it): give \"path\": \"raster\" or leave path out");
        o.path = Iso3dOptions::Path::Raster;
    }
    return o;
}

IsoSurface isoSurface(const Scene& scene, const Camera& camera)
{
    if (!scene.iso)
        throw InputError("iso: technique iso3d needs \"iso\": {\"value\": ...}, and the scene has none");
    const IsoSpec& spec = *scene.iso;
    IsoSurface iso;
    iso.value = spec.value;
    iso.shading = spec.shading;
    iso.light = spec.lightFor(camera);
    iso.ambient = spec.ambient;
    iso.diffuse = spec.diffuse;
    if (!scene.transferFunction.points().empty())
        iso.color = glm::dvec3(scene.transferFunction(iso.value));
    return iso;
}

std::vector<std::uint8_t> iso3dEmptySpace(const Volume& volume, double iso, glm::ivec3& brickDims,
                                          std::uint64_t& emptyBricks)
{
    const glm::dvec2 range = volume.range();
    const BrickGrid grid = buildBrickGrid(volume);
    const double margin = 1e-5 * std::max({std::abs(range.x), std::abs(range.y), std::abs(iso)});
    std::vector<cl_uchar> empty(grid.minMax.size());
    for (std::size_t b = 0; b < empty.size(); ++b)
        empty[b] = static_cast<double>(grid.minMax[b].y) + margin < iso ? 1 : 0;
    emptyBricks = static_cast<std::uint64_t>(std::count(empty.begin(), empty.end(), cl_uchar(1)));
    brickDims = grid.dims;
    return emptySpaceRadii(grid.dims, empty);
}

std::vector<glm::vec4> encodedNormalVolume(const Volume& volume)
{
    std::vector<glm::vec4> rgba = sobelGradientVolume(volume);
    for (glm::vec4& p : rgba) {
        const glm::dvec3 g(p);
        const double length = glm::length(g);
        const glm::dvec3 n = length > 0.0 ? -g / length : glm::dvec3(0.0);
        p = glm::vec4(glm::vec3(0.5 * n + 0.5), p.w);
    }
    return rgba;
}

double medianGradientAtIso(const Volume& volume, double iso)
{
    const std::vector<glm::vec4> gradients = sobelGradientVolume(volume);
    const glm::ivec3 n = volume.dims;
    std::vector<float> lengths;
    for (int k = 0; k < n.z; ++k)
        for (int j = 0; j < n.y; ++j)
            for (int i = 0; i < n.x; ++i) {
                const double f = volume.at(i, j, k) - iso;
                const bool crossing = (i + 1 < n.x && f * (volume.at(i + 1, j, k) - iso) <= 0.0) ||
                                      (j + 1 < n.y && f * (volume.at(i, j + 1, k) - iso) <= 0.0) ||
                                      (k + 1 < n.z && f * (volume.at(i, j, k + 1) - iso) <= 0.0);
                if (crossing)
                    lengths.push_back(glm::length(glm::vec3(gradients[(static_cast<std::size_t>(k) * n.y + j) * n.x + i])));
            }
    if (lengths.empty())
        return 1.0;
    std::nth_element(lengths.begin(), lengths.begin() + static_cast<std::ptrdiff_t>(lengths.size() / 2), lengths.end());
    const double median = lengths[lengths.size() / 2];
    return median > 0.0 ? median : 1.0;
}

glm::dmat4 isoColorMatrix(const glm::dvec3& light, const glm::dmat3& rotation)
{
    // glm is column-major: m[c][r]. The paper's three factors, right to left.
    glm::dmat4 decode(2.0);  // 2c - 1 on rgb, alpha kept
    decode[3] = glm::dvec4(-1.0, -1.0, -1.0, 1.0);
    const glm::dmat4 rot(rotation);
    glm::dmat4 lightRows(0.0);  // rows 0..2 = (L_x, L_y, L_z, 0), row 3 = (0, 0, 0, 1)
    for (int c = 0; c < 3; ++c)
        for (int r = 0; r < 3; ++r)
            lightRows[c][r] = light[c];
    lightRows[3][3] = 1.0;
    return lightRows * rot * decode;
}

raster::PixelTransfer isoShadingTransfer(const IsoSurface& iso, const glm::dmat3& rotation)
{
    glm::dmat4 matrix = isoColorMatrix(iso.light, rotation);
    matrix[3] = glm::dvec4(0.0, 0.0, 0.0, 1.0);  // the alpha column: no -1 there, alpha passes
    const double decodeBias = glm::dot(iso.light, rotation * glm::dvec3(1.0));  // <L, M_rot (1, 1, 1)>
    raster::PixelTransfer xf;
    xf.colorMatrix = glm::mat4(matrix);
    xf.scale = glm::vec4(glm::vec3(iso.diffuse * iso.color), 1.0f);
    xf.bias = glm::vec4(glm::vec3(iso.color * (iso.ambient - iso.diffuse * decodeBias)), 0.0f);
    return xf;
}

std::uint64_t MemoryBricks::bytes(const glm::ivec3& b) const
{
    const glm::ivec3 n = dims(b);
    return static_cast<std::uint64_t>(n.x) * n.y * n.z * bytesPerPoint;
}

std::uint64_t MemoryBricks::maxBytes() const
{
    // Slabs differ by at most one cell per axis: the largest brick takes the largest slab of each.
    glm::ivec3 n(0);
    for (int a = 0; a < 3; ++a)
        for (int s = 0; s < counts[a]; ++s)
            n[a] = std::max(n[a], starts[a][s + 1] - starts[a][s] + 1);
    return static_cast<std::uint64_t>(n.x) * n.y * n.z * bytesPerPoint;
}

MemoryBricks splitBricks(const glm::ivec3& dims, const glm::ivec3& counts, std::uint64_t bytesPerPoint)
{
    MemoryBricks grid;
    grid.counts = counts;
    grid.bytesPerPoint = bytesPerPoint;
    for (int a = 0; a < 3; ++a) {
        const int cells = dims[a] - 1;
        if (counts[a] < 1 || counts[a] > cells)
            badOption("bricks", "axis " + std::to_string(a) + " has " + std::to_string(cells) + " cells, so from 1 to " +
                                    std::to_string(cells) + " bricks, got " + std::to_string(counts[a]));
        grid.starts[a].resize(static_cast<std::size_t>(counts[a]) + 1);
        for (int s = 0; s <= counts[a]; ++s)
            grid.starts[a][s] = static_cast<int>(static_cast<long long>(s) * cells / counts[a]);
    }
    return grid;
}

MemoryBricks planBricks(const glm::ivec3& dims, std::uint64_t bytesPerPoint, std::uint64_t budget)
{
    const std::uint64_t smallest = 8 * bytesPerPoint;
    if (budget < smallest)
        badOption("brick_budget", std::to_string(budget) + " bytes is less than the smallest brick, 2x2x2 grid points x " +
                                      std::to_string(bytesPerPoint) + " bytes = " + std::to_string(smallest) + " bytes");
    glm::ivec3 counts(1);
    for (;;) {
        const MemoryBricks grid = splitBricks(dims, counts, bytesPerPoint);
        if (grid.maxBytes() <= budget)
            return grid;
        // Cut the axis whose bricks have the most grid points (of those with more than one cell left).
        int axis = -1, most = 0;
        for (int a = 0; a < 3; ++a) {
            const int cells = dims[a] - 1;
            const int points = (cells + counts[a] - 1) / counts[a] + 1;
            if (points > 2 && points > most) {
                most = points;
                axis = a;
            }
        }
        ++counts[axis];  // axis >= 0: 2x2x2 points fit the budget
    }
}

MemoryBricks iso3dBrickGrid(const glm::ivec3& dims, const Iso3dOptions& options, std::uint64_t bytesPerPoint)
{
    if (options.bricks.x > 0)
        return splitBricks(dims, options.bricks, bytesPerPoint);
    if (options.brickBudget > 0)
        return planBricks(dims, bytesPerPoint, options.brickBudget);
    return splitBricks(dims, glm::ivec3(1), bytesPerPoint);
}

std::vector<glm::vec4> brickPoints(const std::vector<glm::vec4>& points, const glm::ivec3& dims, const MemoryBricks& grid,
                                   const glm::ivec3& b)
{
    const glm::ivec3 lo = grid.lo(b), n = grid.dims(b);
    std::vector<glm::vec4> data;
    data.reserve(static_cast<std::size_t>(n.x) * n.y * n.z);
    for (int k = 0; k < n.z; ++k)
        for (int j = 0; j < n.y; ++j) {
            const std::size_t row = (static_cast<std::size_t>(lo.z + k) * dims.y + (lo.y + j)) * dims.x + lo.x;
            data.insert(data.end(), points.begin() + static_cast<std::ptrdiff_t>(row),
                        points.begin() + static_cast<std::ptrdiff_t>(row + n.x));
        }
    return data;
}

std::vector<BrickDraw> brickDraws(const MemoryBricks& grid, const Camera& camera, const glm::dvec3& origin,
                                  const glm::dvec3& spacing, const SlicePlan& plan, const glm::dmat4& viewProjection,
                                  int width, int height)
{
    const glm::dvec3 forward = camera.forward();
    std::vector<BrickDraw> draws;
    for (const glm::ivec3& b : brickOrder(grid, camera, origin, spacing)) {
        const glm::dvec3 boxLo = origin + glm::dvec3(grid.lo(b)) * spacing, boxHi = origin + glm::dvec3(grid.hi(b)) * spacing;
        // The slices that can reach the brick: its corners' eye-depth range, one slice more on each side
        // (a slice drawn for a brick it misses only costs discarded fragments; one missed would lose samples).
        double dMin = std::numeric_limits<double>::infinity(), dMax = -dMin;
        bool allInFront = true;
        glm::dvec2 wMin(std::numeric_limits<double>::infinity()), wMax(-std::numeric_limits<double>::infinity());
        for (int c = 0; c < 8; ++c) {
            const glm::dvec3 p((c & 1) ? boxHi.x : boxLo.x, (c & 2) ? boxHi.y : boxLo.y, (c & 4) ? boxHi.z : boxLo.z);
            const double d = glm::dot(forward, p - camera.position);
            dMin = std::min(dMin, d);
            dMax = std::max(dMax, d);
            const glm::dvec4 clip = viewProjection * glm::dvec4(p, 1.0);
            if (!(clip.w > 0.0)) {
                allInFront = false;
                continue;
            }
            const glm::dvec2 window((clip.x / clip.w + 1.0) * 0.5 * width, (1.0 - clip.y / clip.w) * 0.5 * height);
            wMin = glm::min(wMin, window);
            wMax = glm::max(wMax, window);
        }
        BrickDraw draw;
        draw.brick = b;
        draw.kLo = std::max(0, static_cast<int>(std::floor((dMin - plan.depthMin) / plan.deltaS - 0.5)) - 1);
        draw.kHi = std::min(plan.count - 1, static_cast<int>(std::ceil((dMax - plan.depthMin) / plan.deltaS - 0.5)) + 1);
        if (draw.kLo > draw.kHi)
            continue;
        // The scissor: the brick's projected box (the hull of its corners when all are in front of the
        // eye), one pixel wider on every side; the whole frame otherwise (the eye near or in the brick).
        if (allInFront) {
            draw.scissor = true;
            draw.x0 = std::max(0, static_cast<int>(std::floor(wMin.x)) - 1);
            draw.y0 = std::max(0, static_cast<int>(std::floor(wMin.y)) - 1);
            draw.x1 = std::min(width, static_cast<int>(std::ceil(wMax.x)) + 1);
            draw.y1 = std::min(height, static_cast<int>(std::ceil(wMax.y)) + 1);
            if (draw.x0 >= draw.x1 || draw.y0 >= draw.y1)
                continue;  // off screen
        }
        draws.push_back(draw);
    }
    return draws;
}

std::vector<glm::ivec3> brickOrder(const MemoryBricks& grid, const Camera& camera, const glm::dvec3& origin,
                                   const glm::dvec3& spacing)
{
    // Per axis, the key of slab s: perspective, |s - the eye's slab| (the eye's coordinate clamped to the
    // grid); parallel, s counted along the view direction. Along any ray from the eye each axis' key never
    // decreases and one grows at every brick change, so the sum is a visibility order.
    const glm::dvec3 forward = camera.forward();
    std::array<std::vector<int>, 3> key;
    for (int a = 0; a < 3; ++a) {
        const int n = grid.counts[a];
        key[a].resize(static_cast<std::size_t>(n));
        if (camera.parallel) {
            for (int s = 0; s < n; ++s)
                key[a][s] = forward[a] > 0.0 ? s : forward[a] < 0.0 ? n - 1 - s : 0;
        } else {
            const double g = (camera.position[a] - origin[a]) / spacing[a];  // the eye in grid units
            int eye = 0;
            while (eye + 1 < n && g >= grid.starts[a][eye + 1])
                ++eye;
            for (int s = 0; s < n; ++s)
                key[a][s] = std::abs(s - eye);
        }
    }
    std::vector<glm::ivec3> order;
    for (int z = 0; z < grid.counts.z; ++z)
        for (int y = 0; y < grid.counts.y; ++y)
            for (int x = 0; x < grid.counts.x; ++x)
                order.emplace_back(x, y, z);
    std::stable_sort(order.begin(), order.end(), [&](const glm::ivec3& p, const glm::ivec3& q) {
        return key[0][p.x] + key[1][p.y] + key[2][p.z] < key[0][q.x] + key[1][q.y] + key[2][q.z];
    });
    return order;
}

std::unique_ptr<Iso3dRenderer> makeIso3dRenderer(Device& device, const Scene& scene, const Volume& volume)
{
    return std::make_unique<Iso3dRendererImpl>(device, scene, volume);
}

}  // namespace clvr
