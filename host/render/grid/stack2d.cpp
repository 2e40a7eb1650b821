// host/render/grid/stack2d.cpp — options, stack choice, slice planning and the rendering of the stack2d
// technique: pass by pass, one raster::draw of all quads of the chosen stack, back to front, with
// kernels/stack2d.cl as fragment program, then the background pass of slice3d; or fused, the same
// planes stepped through per pixel by kernels/stack2d.cl's stack2d_fused.
#include "host/render/grid/stack2d.h"

#include "host/render/grid/slice3d.h"  // buildBrickGrid, emptyBricks, emptySpaceRadii: slice3d's bricks

#include "host/render/scaffold.h"
#include "host/runtime/embedded_kernels.h"
#include "host/runtime/errors.h"
#include "host/render/camera_args.h"
#include "host/render/fragment_uniforms.h"
#include "host/render/options_util.h"
#include "host/optics/gradient_volume.h"
#include "host/optics/reflectance_map.h"
#include "host/render/transfer_function_upload.h"
#include "kernels/stack2d_params.h"
#include "raster/framebuffer.h"
#include "raster/rasterizer.h"
#include "raster/texture.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <optional>

namespace clvr {

static_assert(sizeof(ClStack2dIsoFinishParams) == 32, "also probed on the device by tests/layout_test.cpp");
static_assert(sizeof(ClStack2dFusedParams) == 384, "also probed on the device by tests/layout_test.cpp");

namespace {

cl_float4 cl4(float x, float y, float z, float w)
{
    return cl_float4{{x, y, z, w}};
}

// The most intermediate slices per stack interval; 64 already samples far finer than the data.
constexpr int kMaxIntermediate = 64;
constexpr int kMaxSlicesPerPolygon = 64;
constexpr const char* kAxisNames[3] = {"x", "y", "z"};

// The stack along `axis`: slice i (grid index i on that axis) is a 2D texture over the other two
// axes (b, c) = ((axis + 1) % 3, (axis + 2) % 3) ordered as x < y < z, i.e. (y, z), (x, z), (x, y);
// the first of them runs fastest. Slices follow one another in one buffer.
struct StackShape {
    int b = 0, c = 0;  // texture width along axis b, height along axis c
};
StackShape stackShape(int axis)
{
    const int p = (axis + 1) % 3, q = (axis + 2) % 3;
    return {std::min(p, q), std::max(p, q)};
}

// The texels of that stack from `channels` floats per grid point (x fastest, then y, then z).
std::vector<float> stackTexels(const float* points, const glm::ivec3& n, int channels, int axis)
{
    const StackShape s = stackShape(axis);
    std::vector<float> texels(static_cast<std::size_t>(n.x) * n.y * n.z * channels);
    float* out = texels.data();
    glm::ivec3 g;
    for (g[axis] = 0; g[axis] < n[axis]; ++g[axis])
        for (g[s.c] = 0; g[s.c] < n[s.c]; ++g[s.c])
            for (g[s.b] = 0; g[s.b] < n[s.b]; ++g[s.b]) {
                const float* p = points + ((static_cast<std::size_t>(g.z) * n.y + g.y) * n.x + g.x) * channels;
                out = std::copy(p, p + channels, out);
            }
    return texels;
}

class Stack2dRenderer final : public Renderer {
public:
    Stack2dRenderer(Device& device, const Scene& scene, const Volume& volume);
    Image4f render(FrameStats& stats) override;
    std::uint64_t residentBytes() const override { return residentBytes_; }
    void setTransferFunction(const TransferFunction& tf) override;
    bool setCamera(const Scene& scene) override;
    void setClipPlacement(const glm::dvec3& offset, const glm::dmat3& matrix);

private:
    void setClipCoordinateUniforms();
    void setView(const Scene& scene);
    void setUpFused(const Volume& volume);
    void setEmptySpace();
    std::uint64_t renderFused(std::uint64_t& steppedOver);
    raster::DrawStats drawQuads();

    Device& device_;
    Stack2dOptions options_;
    Camera camera_;
    ImageSpec image_;
    glm::ivec3 dims_;
    glm::dvec3 origin_, spacing_, lo_, hi_;
    Lighting lighting_;
    // Iso-surface mode (scene "iso"): the alpha test on the value keeps the slice fragments inside the
    // surface, the front-most one stays.
    struct Iso {
        double value = 0.0;
        bool gradientShading = true;  // "shading": "gradient"; "none": flat surface color
        glm::dvec3 light{0.0};        // towards the light; default: the headlight, -forward (setView)
        double ambient = 0.1, diffuse = 0.9;
        glm::dvec3 color{1.0};        // the transfer function's color at the value, or white
        double dataMin = 0.0, dataMax = 1.0;
    };
    std::optional<Iso> iso_;
    int axis_ = 2;
    std::vector<StackSlice> slices_;
    SliceGroups grouped_;  // slices_per_polygon > 1 only
    cl::Buffer sliceTable_;  // buffer[3]: the slice table (slices_per_polygon > 1), then the clip texels
    std::uint64_t sliceTableBytes_ = 0;
    // Clip texture: the texture and world -> clip-texture coordinates.
    std::optional<ClipTexture> clipTexture_;
    glm::dmat4 clipCoordinates_{1.0};
    std::vector<raster::Texture> stacks_;  // x, y, z: all three stay resident, as on the paper's boards
    TransferFunctionUpload tf_;
    TransferFunction tfHost_;  // which bricks are empty depends on it
    cl::Buffer map_;
    std::uint64_t residentBytes_ = 0;
    std::unique_ptr<raster::Framebuffer> framebuffer_;
    raster::FragmentProgram fragmentProgram_;
    ClStack2dUniforms uniforms_{};  // fragmentProgram_.uniforms, by field
    OverBackground overBackground_;
    cl::Kernel isoFinish_;
    // The fused path: its kernel, samples per pixel (planes met in the box, and of them stepped over), and
    // the empty-space radii of the bricks of the drawn stack's grid (kernels/empty_space.h), kept with the
    // bricks' min-max for a new transfer function; volumeBricks_: the same bricks in the volume's axis order,
    // renamed into brickGrid_ for each stack drawn.
    cl::Kernel fused_;
    bool packet_ = false;  // fused_ is stack2d_fused_packet
    cl::Buffer fusedSamples_, fusedSkipped_, space_, noMap_;
    BrickGrid volumeBricks_, brickGrid_;
    std::uint64_t emptyBrickCount_ = 0;
};

Stack2dRenderer::Stack2dRenderer(Device& device, const Scene& scene, const Volume& volume)
    : device_(device), options_(parseStack2dOptions(scene.options)), image_(scene.image), lighting_(scene.lighting),
      overBackground_(device)
{
    checkGridVolume(volume, "stack2d");
    dims_ = volume.dims;
    origin_ = volume.origin;
    spacing_ = volume.spacing;
    lo_ = volume.boundsMin();
    hi_ = volume.boundsMax();
    if (scene.iso) {
        Iso iso;
        iso.value = scene.iso->value;
        if (scene.iso->shading == IsoSpec::Shading::Gradientless)
            throw InputError("iso.shading: stack2d knows \"gradient\" and \"none\", got \"gradientless\"");
        iso.gradientShading = scene.iso->shading == IsoSpec::Shading::Gradient;
        iso.ambient = scene.iso->ambient;
        iso.diffuse = scene.iso->diffuse;
        if (!scene.transferFunction.points().empty())
            iso.color = glm::dvec3(scene.transferFunction(iso.value));
        const glm::dvec2 range = volume.range();
        iso.dataMin = static_cast<float>(range.x);
        iso.dataMax = static_cast<float>(range.y);
        iso_ = iso;
    }
    if (options_.clipTexture) {
        clipTexture_ = makeClipTexture(*options_.clipTexture, scene.baseDir);
        clipCoordinates_ =
            clipTextureCoordinates(*clipTexture_, options_.clipTexture->offset, options_.clipTexture->matrix);
    }

    // Unshaded: the values (1 channel). Shaded or iso-surface: (gradient, value) per texel, the paper's
    // RGBA slices with the gradient in RGB, so that one bilinear fetch (and the lerp) interpolates both.
    const bool gradients = lighting_.shaded() || iso_;
    const int channels = gradients ? 4 : 1;
    std::vector<glm::vec4> rgba;
    if (gradients)
        rgba = sobelGradientVolume(volume);
    std::vector<float> scratch;
    const float* points = gradients ? &rgba[0].x : volume.floats(scratch).data();
    for (int a = 0; a < 3; ++a) {
        const StackShape s = stackShape(a);
        raster::TextureDesc desc;
        desc.width = dims_[s.b];
        desc.height = dims_[s.c];
        desc.depth = dims_[a];
        desc.channels = channels;
        desc.filter = raster::Filter::Linear;
        desc.wrap = raster::Wrap::ClampToEdge;
        stacks_.emplace_back(device_, desc, stackTexels(points, dims_, channels, a));
        residentBytes_ += stacks_.back().bytes();
    }
    setTransferFunction(scene.transferFunction);

    framebuffer_ = std::make_unique<raster::Framebuffer>(device_, image_.width, image_.height);
    const std::string_view source = embeddedKernelSource("stack2d.cl");
    fragmentProgram_.source = "#define CLVR_STACK2D_FRAGMENT 1\n" +
                              std::string(clipTexture_ ? "#define CLVR_STACK2D_CLIP_TEXTURE 1\n" : "") + std::string(source);
    fragmentProgram_.attributes = clipTexture_ ? 3 : 2;  // texture coordinates, slab, clip-texture coordinates
    // The uniforms that do not depend on the view (setView sets the others); fields of a mode that is off stay 0.
    ClStack2dUniforms& u = uniforms_;
    u.frame = cl4(image_.width, image_.height, static_cast<float>(scene.transferFunction.points().size()), 0.0f);
    u.shading = cl4(options_.reflectanceMapSize, lighting_.shaded() ? 1.0f : 0.0f, 0.0f, 0.0f);
    if (iso_) {
        u.iso = cl4(static_cast<float>(iso_->dataMin), 1.0f, static_cast<float>(iso_->ambient),
                    static_cast<float>(iso_->diffuse));
        u.surface = toCl4(iso_->color, iso_->gradientShading ? 1.0 : 0.0);
        isoFinish_ = device_.kernel("stack2d.cl", "stack2d_iso_finish");
    }
    if (options_.slicesPerPolygon > 1) {
        const double alphaRef =
            iso_ ? std::clamp((iso_->value - iso_->dataMin) / (iso_->dataMax > iso_->dataMin ? iso_->dataMax - iso_->dataMin : 1.0),
                              0.0, 1.0)
                 : 0.0;
        u.alpha_ref = cl4(static_cast<float>(alphaRef), 0.0f, 0.0f, 0.0f);
    }
    if (clipTexture_) {
        const glm::ivec3 n = clipTexture_->dims();
        u.clip_tex = cl4(n.x, n.y, n.z, options_.clipTexture->inverse ? 1.0f : 0.0f);
        setClipCoordinateUniforms();  // u.clip_row
    }
    fragmentProgram_.buffers[1] = tf_.buffer();
    if (options_.path == Stack2dOptions::Path::Fused)
        setUpFused(volume);
    setView(scene);
}

// Everything that follows the view, for the constructor and setCamera: the camera and the headlight, the stack
// drawn (the axis most parallel to the view) and its slices, the reflectance map (one view direction for the
// image, -forward, as in planes and blend), the uniforms and slice table of the draws, and the fused path's
// bricks of the drawn stack's grid.
void Stack2dRenderer::setView(const Scene& scene)
{
    camera_ = frameCamera(scene, lo_, hi_);
    if (iso_)
        iso_->light = scene.iso->lightFor(camera_);
    axis_ = stackAxis(camera_);
    slices_ = planStack(camera_, origin_, spacing_, dims_, axis_, options_.intermediate);
    if (lighting_.shaded()) {
        const ReflectanceMap map = buildReflectanceMap(lighting_, -camera_.forward(), options_.reflectanceMapSize);
        if (!map_())
            residentBytes_ += map.entries.size() * sizeof(glm::vec4);
        map_ = device_.upload("stack2d reflectance map", map.entries);
    }
    fragmentProgram_.buffers[0] = stacks_[axis_].buffer();
    fragmentProgram_.buffers[2] = map_;
    const StackShape s = stackShape(axis_);
    ClStack2dUniforms& u = uniforms_;
    u.camera = toClCamera(camera_, image_.width, image_.height);
    u.axis = cl4(0.0f, 0.0f, 0.0f, 0.0f);
    u.axis.s[axis_] = 1.0f;
    u.slice_tex = cl4(dims_[s.b], dims_[s.c], stacks_[axis_].desc().channels, 0.0f);
    u.to_eye = toCl4(-camera_.forward());
    if (iso_) {
        const double range = iso_->dataMax > iso_->dataMin ? iso_->dataMax - iso_->dataMin : 1.0;
        u.light = cl4(static_cast<float>(iso_->light.x), static_cast<float>(iso_->light.y),
                      static_cast<float>(iso_->light.z), static_cast<float>(1.0 / range));
    }
    // buffer[3]: the slice table (several slices per polygon), then the clip texels (four buffers in
    // all, and the reflectance map takes the third): one upload, the texels at a float offset.
    std::vector<glm::vec4> table;
    if (options_.slicesPerPolygon > 1) {
        grouped_ = groupStackSlices(slices_, camera_, origin_, spacing_, axis_, options_.slicesPerPolygon);
        for (const StackSlice& slice : grouped_.slices)
            table.emplace_back(static_cast<float>(origin_[axis_] + slice.position * spacing_[axis_]),
                               static_cast<float>(slice.lower), slice.weight, static_cast<float>(slice.thickness));
        u.axis_b = cl4(0.0f, 0.0f, 0.0f, 0.0f);
        u.axis_c = cl4(0.0f, 0.0f, 0.0f, 0.0f);
        u.axis_b.s[s.b] = 1.0f;
        u.axis_c.s[s.c] = 1.0f;
        u.box = cl4(lo_[s.b], lo_[s.c], hi_[s.b], hi_[s.c]);
        u.uv_box = cl4(0.5f / dims_[s.b], 0.5f / dims_[s.c], (dims_[s.b] - 0.5f) / dims_[s.b],
                       (dims_[s.c] - 0.5f) / dims_[s.c]);  // as the quads' corners
    }
    residentBytes_ -= sliceTableBytes_;
    sliceTableBytes_ = 0;
    if (clipTexture_) {
        std::vector<float> packed(reinterpret_cast<const float*>(table.data()),
                                  reinterpret_cast<const float*>(table.data() + table.size()));
        packed.insert(packed.end(), clipTexture_->texels.begin(), clipTexture_->texels.end());
        sliceTable_ = device_.upload("stack2d slice table and clip texture", packed);
        sliceTableBytes_ = packed.size() * sizeof(float);
        fragmentProgram_.buffers[3] = sliceTable_;
        u.clip_offset = cl4(static_cast<float>(table.size() * 4), 0.0f, 0.0f, 0.0f);
    } else if (!table.empty()) {
        sliceTable_ = device_.upload("stack2d slice table", table);
        sliceTableBytes_ = table.size() * sizeof(glm::vec4);
        fragmentProgram_.buffers[3] = sliceTable_;
    }
    residentBytes_ += sliceTableBytes_;
    fragmentProgram_.uniforms = fragmentUniforms(u);
    if (options_.path == Stack2dOptions::Path::Fused) {
        // The drawn stack's grid is the volume with its axes renamed (b, c, axis): so are its bricks, which
        // slice3d's grid cuts the same way along every axis.
        const int stackAxes[3] = {s.b, s.c, axis_};
        const glm::ivec3 n = volumeBricks_.dims;
        brickGrid_.dims = glm::ivec3(n[s.b], n[s.c], n[axis_]);
        brickGrid_.minMax.resize(volumeBricks_.minMax.size());
        glm::ivec3 v, g;
        for (g.z = 0; g.z < brickGrid_.dims.z; ++g.z)
            for (g.y = 0; g.y < brickGrid_.dims.y; ++g.y)
                for (g.x = 0; g.x < brickGrid_.dims.x; ++g.x) {
                    for (int r = 0; r < 3; ++r)
                        v[stackAxes[r]] = g[r];
                    brickGrid_.minMax[(static_cast<std::size_t>(g.z) * brickGrid_.dims.y + g.y) * brickGrid_.dims.x + g.x] =
                        volumeBricks_.minMax[(static_cast<std::size_t>(v.z) * n.y + v.y) * n.x + v.x];
                }
        setEmptySpace();
    }
}

bool Stack2dRenderer::setCamera(const Scene& scene)
{
    if (!sameImageSize(scene.image, image_))
        return false;  // the frame buffer and the per-pixel counts would change
    image_ = scene.image;
    setView(scene);
    return true;
}

// The fused path's kernel and buffers, and the bricks (slice3d's) of the volume, which setView renames into
// the drawn stack's.
void Stack2dRenderer::setUpFused(const Volume& volume)
{
    volumeBricks_ = buildBrickGrid(volume);
    space_ = device_.buffer("stack2d empty-space radii", volumeBricks_.minMax.size(), CL_MEM_READ_ONLY);
    residentBytes_ += volumeBricks_.minMax.size();
    if (!lighting_.shaded())  // the kernel takes a reflectance map argument in every mode
        noMap_ = device_.upload("stack2d no reflectance map", std::vector<glm::vec4>(1));
    // Ray packets (kernels/stack2d.cl stack2d_fused_packet, the same bits): plain direct volume rendering
    // without a clip texture; shading, iso-surfaces and clip textures keep one pixel per work-item.
    packet_ = packetsOnDevice(options_.packets, device_) && !clipTexture_ && !iso_ && !lighting_.shaded();
    fused_ = device_.kernel("stack2d.cl", packet_ ? "stack2d_fused_packet" : "stack2d_fused", {},
                            clipTexture_ ? "-DCLVR_STACK2D_CLIP_TEXTURE=1" : "");
    const std::size_t pixels = framebuffer_->pixelCount();
    fusedSamples_ = device_.buffer("stack2d fused samples per pixel", pixels * sizeof(cl_uint), CL_MEM_WRITE_ONLY);
    fusedSkipped_ = device_.buffer("stack2d fused skipped samples per pixel", pixels * sizeof(cl_uint), CL_MEM_WRITE_ONLY);
}

// The fused path's empty bricks of the drawn stack, and their radii on the device: empty where tau is 0 over the
// brick's values (direct volume rendering) or where they all lie below the iso-value by more than float rounding
// in the trilinear interpolation could make up.
void Stack2dRenderer::setEmptySpace()
{
    std::vector<cl_uchar> empty;
    if (iso_) {
        const double margin = 1e-5 * std::max({std::abs(iso_->dataMin), std::abs(iso_->dataMax), std::abs(iso_->value)});
        empty.resize(brickGrid_.minMax.size());
        for (std::size_t b = 0; b < empty.size(); ++b)
            empty[b] = static_cast<double>(brickGrid_.minMax[b].y) + margin < iso_->value ? 1 : 0;
    } else {
        empty = emptyBricks(brickGrid_, tfHost_);
    }
    emptyBrickCount_ = static_cast<std::uint64_t>(std::count(empty.begin(), empty.end(), cl_uchar(1)));
    const std::vector<cl_uchar> radii = emptySpaceRadii(brickGrid_.dims, empty);
    device_.queue().enqueueWriteBuffer(space_, CL_TRUE, 0, radii.size(), radii.data());
}

// The uniforms' clip_row: the rows of world -> clip-texture coordinates (the several-slices path maps
// the ray's hit points with them; the one-slice path's vertices carry the mapped points, made per frame).
void Stack2dRenderer::setClipCoordinateUniforms()
{
    for (int r = 0; r < 3; ++r)
        uniforms_.clip_row[r] =
            cl4(static_cast<float>(clipCoordinates_[0][r]), static_cast<float>(clipCoordinates_[1][r]),
                static_cast<float>(clipCoordinates_[2][r]), static_cast<float>(clipCoordinates_[3][r]));
    fragmentProgram_.uniforms = fragmentUniforms(uniforms_);
}

void Stack2dRenderer::setClipPlacement(const glm::dvec3& offset, const glm::dmat3& matrix)
{
    if (!clipTexture_)
        throw InputError("stack2d: no clip texture to move (options.clip_texture is not given)");
    if (!(std::abs(glm::determinant(matrix)) > 0.0))
        throw InputError("stack2d: the clip texture's matrix must be invertible");
    options_.clipTexture->offset = offset;
    options_.clipTexture->matrix = matrix;
    clipCoordinates_ = clipTextureCoordinates(*clipTexture_, offset, matrix);
    setClipCoordinateUniforms();
}

void Stack2dRenderer::setTransferFunction(const TransferFunction& tf)
{
    tfHost_ = tf;
    tf_.replace(device_, "stack2d transfer function", tf, residentBytes_);
    fragmentProgram_.buffers[1] = tf_.buffer();
    if (fragmentProgram_.uniforms.empty())  // during construction, which sets them itself
        return;
    uniforms_.frame.s[2] = static_cast<float>(tf.points().size());
    if (iso_ && !tf.points().empty()) {  // the surface color
        iso_->color = glm::dvec3(tf(iso_->value));
        uniforms_.surface = toCl4(iso_->color, uniforms_.surface.s[3]);
    }
    fragmentProgram_.uniforms = fragmentUniforms(uniforms_);
    if (options_.path == Stack2dOptions::Path::Fused && !iso_)
        setEmptySpace();  // which bricks are empty depends on the transfer function
}

Image4f Stack2dRenderer::render(FrameStats& stats)
{
    const FrameClock clock;
    const bool fused = options_.path == Stack2dOptions::Path::Fused;
    std::uint64_t samples = 0, steppedOver = 0;
    raster::DrawStats drawStats;
    if (fused) {
        samples = renderFused(steppedOver);
    } else {
        drawStats = drawQuads();
        // One sample per fragment of a quad; with several slices per polygon at most `count` per fragment
        // (fewer where the enlarged quad covers pixels outside some of its slices): an upper bound.
        samples = drawStats.fragments;
        if (options_.slicesPerPolygon > 1)
            samples = static_cast<std::uint64_t>(static_cast<double>(drawStats.fragments) * grouped_.slices.size() /
                                                 std::max<std::size_t>(grouped_.groups.size(), 1));
    }
    Image4f image = framebuffer_->readColor(device_);
    finishFrame(device_, clock, stats);
    stats.samples = samples;
    stats.extra["path"] = fused ? "fused" : "raster";
    stats.extra["axis"] = kAxisNames[axis_];
    stats.extra["slices"] = slices_.size();
    stats.extra["intermediate"] = options_.intermediate;
    stats.extra["slices_per_polygon"] = options_.slicesPerPolygon;
    stats.extra["shaded"] = lighting_.shaded();
    stats.extra["iso"] = iso_.has_value();
    stats.extra["reflectance_map_size"] = options_.reflectanceMapSize;
    stats.extra["voxels"] = static_cast<std::uint64_t>(dims_.x) * dims_.y * dims_.z;
    stats.extra["resident_bytes"] = residentBytes_;
    if (fused) {
        stats.extra["empty_space_skipping"] = options_.emptySpaceSkipping && emptyBrickCount_ > 0;
        stats.extra["packets"] = packet_;
        stats.extra["empty_bricks"] = emptyBrickCount_;
        stats.extra["skipped"] = steppedOver;
        stats.extra["early_termination"] = options_.earlyTermination;
    } else {
        stats.extra["polygons"] = options_.slicesPerPolygon > 1 ? grouped_.groups.size() : slices_.size();
        stats.extra["fragments"] = drawStats.fragments;
        stats.extra["triangles"] = drawStats.triangles;
    }
    if (clipTexture_)
        addClipTextureStats(stats.extra, *clipTexture_, *options_.clipTexture);
    return image;
}

// The fused path: stack2d_fused leaves the finished image (over the background) in the frame buffer's
// color. Returns the samples (planes met in the box), with those stepped over in `steppedOver`.
std::uint64_t Stack2dRenderer::renderFused(std::uint64_t& steppedOver)
{
    const StackShape s = stackShape(axis_);
    ClStack2dFusedParams p{};
    p.camera = toClCamera(camera_, image_.width, image_.height);
    const int stackAxes[3] = {s.b, s.c, axis_};
    for (int r = 0; r < 3; ++r) {  // q_r = (p[a] - origin[a]) / spacing[a] for a = stackAxes[r]
        const int a = stackAxes[r];
        p.to_stack[r].s[a] = static_cast<float>(1.0 / spacing_[a]);
        p.to_stack[r].s[3] = static_cast<float>(-origin_[a] / spacing_[a]);
    }
    p.to_eye = uniforms_.to_eye;
    p.background = toCl4(glm::dvec3(image_.background), 0.0);
    p.iso = uniforms_.iso;
    p.surface = uniforms_.surface;
    p.light = uniforms_.light;
    p.dims = cl_int4{{dims_[s.b], dims_[s.c], dims_[axis_], 0}};
    const bool skip = options_.emptySpaceSkipping && emptyBrickCount_ > 0;
    p.bricks = cl_int4{{brickGrid_.dims.x, brickGrid_.dims.y, brickGrid_.dims.z, skip ? 1 : 0}};
    p.width = image_.width;
    p.height = image_.height;
    p.tf_count = static_cast<cl_int>(uniforms_.frame.s[2]);
    p.planes = static_cast<cl_int>(slices_.size());
    p.plane_step = static_cast<float>(1.0 / (options_.intermediate + 1));
    p.ert_alpha = options_.earlyTermination < 1.0 ? static_cast<float>(options_.earlyTermination) : 2.0f;
    if (iso_) {
        // The draws' alpha test GEQUAL the mapped iso-value (NEVER above the data).
        const double range = iso_->dataMax > iso_->dataMin ? iso_->dataMax - iso_->dataMin : 1.0;
        p.alpha_ref = iso_->value > iso_->dataMax
                          ? std::numeric_limits<float>::infinity()
                          : static_cast<float>(std::clamp((iso_->value - iso_->dataMin) / range, 0.0, 1.0));
    }
    p.mode = iso_ ? 2 : (lighting_.shaded() ? 1 : 0);
    p.map_n = options_.reflectanceMapSize;
    if (clipTexture_) {
        for (int r = 0; r < 3; ++r)
            p.clip_row[r] = uniforms_.clip_row[r];
        const glm::ivec3 n = clipTexture_->dims();
        p.clip_tex.width = static_cast<cl_uint>(n.x);
        p.clip_tex.height = static_cast<cl_uint>(n.y);
        p.clip_tex.depth = static_cast<cl_uint>(n.z);
        p.clip_tex.channels = 1;
        p.clip_tex.filter = CLVR_FILTER_LINEAR;
        p.clip_tex.wrap = CLVR_WRAP_CLAMP_TO_EDGE;
        p.clip_inverse = options_.clipTexture->inverse ? 1 : 0;
    }
    int a = 0;
    fused_.setArg(a++, framebuffer_->color());
    fused_.setArg(a++, fusedSamples_);
    fused_.setArg(a++, fusedSkipped_);
    fused_.setArg(a++, stacks_[axis_].buffer());
    fused_.setArg(a++, tf_.buffer());
    fused_.setArg(a++, map_() ? map_ : noMap_);
    fused_.setArg(a++, space_);
    if (clipTexture_)
        fused_.setArg(a++, sliceTable_);  // one slice per quad: the table is empty, the texels start at 0
    fused_.setArg(a++, p);
    device_.launch("stack2d: fused planes", fused_, rowWorkItems(image_.width, packet_), image_.height);
    const std::size_t pixels = framebuffer_->pixelCount();
    std::uint64_t samples = 0;
    steppedOver = 0;
    for (const cl_uint n : device_.download<cl_uint>(fusedSamples_, pixels))
        samples += n;
    for (const cl_uint n : device_.download<cl_uint>(fusedSkipped_, pixels))
        steppedOver += n;
    return samples;
}

// The raster path: every quad of the drawn stack in one raster::draw, then the background (or the iso-surface's
// last pass); the image is left in the frame buffer's color.
raster::DrawStats Stack2dRenderer::drawQuads()
{
    // Near and far planes around the box's eye-depth range; depth is not tested, so only the near
    // plane matters: it removes what lies behind the camera (perspective) or in front of its image
    // plane (parallel: depth 0, as the reference integral counts the ray from there).
    double dMin = std::numeric_limits<double>::infinity(), dMax = -dMin;
    for (int c = 0; c < 8; ++c) {
        const glm::dvec3 corner((c & 1) ? hi_.x : lo_.x, (c & 2) ? hi_.y : lo_.y, (c & 4) ? hi_.z : lo_.z);
        const double d = glm::dot(camera_.forward(), corner - camera_.position);
        dMin = std::min(dMin, d);
        dMax = std::max(dMax, d);
    }
    const double nearZ = camera_.parallel ? 0.0 : (dMin > 0.0 ? 0.5 * dMin : 1e-4 * std::max(dMax, 1e-30));
    const double farZ = 2.0 * std::max(dMax, 0.0) + 1.0;
    const glm::dmat4 viewProjection =
        camera_.projectionMatrix(image_.width, image_.height, nearZ, farZ) * camera_.viewMatrix();
    const StackShape s = stackShape(axis_);
    // Quad corners in the (b, c) plane and their texture coordinates: grid point i of n is texel i,
    // centered at (i + 0.5) / n, so the box [0, n - 1] maps to [0.5 / n, (n - 0.5) / n].
    const glm::dvec2 uvLo(0.5 / dims_[s.b], 0.5 / dims_[s.c]);
    const glm::dvec2 uvHi((dims_[s.b] - 0.5) / dims_[s.b], (dims_[s.c] - 0.5) / dims_[s.c]);
    std::vector<raster::Vertex> vertices;
    auto quad = [&](double axisWorld, glm::dvec2 rectLo, glm::dvec2 rectHi, float lower, float weight,
                    glm::vec4 attribute1) {
        for (const auto& [cb, cc] : std::array<std::pair<int, int>, 6>{{{0, 0}, {1, 0}, {1, 1}, {0, 0}, {1, 1}, {0, 1}}}) {
            glm::dvec3 p;
            p[axis_] = axisWorld;
            p[s.b] = cb ? rectHi.x : rectLo.x;
            p[s.c] = cc ? rectHi.y : rectLo.y;
            // Texture coordinates linear in (b, c): the box corners get uvLo and uvHi exactly.
            glm::dvec2 uv;
            for (int k = 0; k < 2; ++k) {
                const int a = k == 0 ? s.b : s.c;
                const double extent = hi_[a] - lo_[a];
                uv[k] = extent > 0.0 ? uvLo[k] + (p[a] - lo_[a]) / extent * (uvHi[k] - uvLo[k]) : uvLo[k];
                if (p[a] == hi_[a])
                    uv[k] = uvHi[k];
            }
            raster::Vertex v;
            v.position = glm::vec4(viewProjection * glm::dvec4(p, 1.0));
            v.attributes[0] = glm::vec4(static_cast<float>(uv.x), static_cast<float>(uv.y), lower, weight);
            v.attributes[1] = attribute1;
            if (clipTexture_)  // the second texture's coordinates of the slice point (one slice per quad)
                v.attributes[2] = glm::vec4(glm::vec3(clipCoordinates_ * glm::dvec4(p, 1.0)), 1.0f);
            vertices.push_back(v);
        }
    };
    const glm::dvec2 boxLo(lo_[s.b], lo_[s.c]), boxHi(hi_[s.b], hi_[s.c]);
    if (options_.slicesPerPolygon == 1) {
        vertices.reserve(slices_.size() * 6);
        for (const StackSlice& slice : slices_)
            quad(origin_[axis_] + slice.position * spacing_[axis_], boxLo, boxHi, static_cast<float>(slice.lower),
                 slice.weight, glm::vec4(static_cast<float>(slice.thickness), 0.0f, 0.0f, 0.0f));
    } else {
        // One quad per group, in the plane of its front-most slice, covering the box's cross-section
        // of every slice of the group as seen from the camera: the bounding rectangle of their
        // corners projected onto that plane along the rays (through the camera, or along forward).
        vertices.reserve(grouped_.groups.size() * 6);
        for (const auto& [first, count] : grouped_.groups) {
            const double drawn = origin_[axis_] + grouped_.slices[first + count - 1].position * spacing_[axis_];
            glm::dvec2 rectLo(std::numeric_limits<double>::infinity()), rectHi(-std::numeric_limits<double>::infinity());
            for (int j = first; j < first + count; ++j) {
                const double x = origin_[axis_] + grouped_.slices[j].position * spacing_[axis_];
                for (int corner = 0; corner < 4; ++corner) {
                    glm::dvec3 p;
                    p[axis_] = x;
                    p[s.b] = (corner & 1) ? hi_[s.b] : lo_[s.b];
                    p[s.c] = (corner & 2) ? hi_[s.c] : lo_[s.c];
                    const glm::dvec3 q = camera_.parallel
                                             ? p + camera_.forward() * ((drawn - x) / camera_.forward()[axis_])
                                             : camera_.position + (p - camera_.position) *
                                                                      ((drawn - camera_.position[axis_]) / (x - camera_.position[axis_]));
                    rectLo = glm::min(rectLo, glm::dvec2(q[s.b], q[s.c]));
                    rectHi = glm::max(rectHi, glm::dvec2(q[s.b], q[s.c]));
                }
            }
            // Widen by a hair so that pixels whose rays graze a box edge are covered; the fragment
            // program tests each slice against the box itself.
            const glm::dvec2 pad = 1e-6 * (rectHi - rectLo) + 1e-12;
            quad(drawn, rectLo - pad, rectHi + pad, 0.0f, 0.0f,
                 glm::vec4(0.0f, static_cast<float>(first), static_cast<float>(count), 0.0f));
        }
    }
    raster::DrawState state;
    if (!iso_) {
        state.fragment.blend = raster::premultipliedOver();
    } else {
        // Alpha test on the value mapped to [0, 1] as the fragment program maps it: GEQUAL the mapped
        // iso-value (an iso-value above the data passes nothing); the stencil marks covered pixels.
        const double range = iso_->dataMax > iso_->dataMin ? iso_->dataMax - iso_->dataMin : 1.0;
        state.fragment.alpha.test = true;
        state.fragment.alpha.func = iso_->value > iso_->dataMax ? raster::CompareFunc::Never : raster::CompareFunc::GEqual;
        state.fragment.alpha.ref = static_cast<float>(std::clamp((iso_->value - iso_->dataMin) / range, 0.0, 1.0));
        state.fragment.stencil.test = true;
        state.fragment.stencil.func = raster::CompareFunc::Always;
        state.fragment.stencil.ref = 1;
        state.fragment.stencil.dppass = raster::StencilOp::Replace;
        framebuffer_->clearStencil(device_, 0);
    }
    framebuffer_->clearColor(device_, glm::vec4(0.0f));
    const raster::DrawStats drawStats =
        raster::draw(device_, *framebuffer_, state, raster::Topology::Triangles, vertices, fragmentProgram_);
    const std::size_t pixels = framebuffer_->pixelCount();
    const cl_float4 background{{static_cast<float>(image_.background.r), static_cast<float>(image_.background.g),
                                static_cast<float>(image_.background.b), 0.0f}};
    if (iso_) {
        ClStack2dIsoFinishParams finish{};
        finish.background = background;
        finish.count = static_cast<cl_int>(pixels);
        isoFinish_.setArg(0, framebuffer_->color());
        isoFinish_.setArg(1, framebuffer_->stencil());
        isoFinish_.setArg(2, finish);
        device_.launch("stack2d: iso-surface over background", isoFinish_, pixels);
    } else {
        overBackground_.run(framebuffer_->color(), pixels, image_.background, "stack2d: over background");
    }
    return drawStats;
}

}  // namespace

TechniqueInfo stack2dTechnique()
{
    TechniqueInfo t;
    t.name = "stack2d";
    t.data = DataKind::Volume;
    t.description = "object-aligned 2D texture stacks, the one most facing the view (docs/stack2d.md)";
    t.options = {
        {"intermediate", 0, "", "slices interpolated between two neighbouring stack slices"},
        reflectanceMapSizeInfo(),
        {"slices_per_polygon", 1, "", "stack slices one quad stands for (seeds/003's multi-texture speed-up; raster path)"},
        clipTextureInfo(),
        {"path", "fused", "", "\"fused\" (each pixel steps through the planes in one kernel) or \"raster\" (the quads "
                              "through the raster stage); slices_per_polygon > 1 takes \"raster\""},
        {"empty_space_skipping", true, "", "fused path: step over bricks where nothing can show (same image)"},
        earlyTerminationInfo(1.0),
        packetsInfo(),
    };
    t.makeForVolume = makeStack2dRenderer;
    return t;
}

Stack2dOptions parseStack2dOptions(const nlohmann::json& options)
{
    static const TechniqueInfo& info = technique("stack2d");
    Stack2dOptions o;
    forEachOption(options, info, [&](const std::string& key, const nlohmann::json& value) {
        if (key == "intermediate")
            o.intermediate = integerOption(key, value, 0, kMaxIntermediate);
        else if (key == "reflectance_map_size")
            o.reflectanceMapSize = reflectanceMapSizeOption(value);
        else if (key == "slices_per_polygon")
            o.slicesPerPolygon = integerOption(key, value, 1, kMaxSlicesPerPolygon);
        else if (key == "clip_texture")
            o.clipTexture = parseClipTextureSpec(value, "options.clip_texture");
        else if (key == "path")
            o.path = choiceOption(key, value, {"fused", "raster"}) == 0 ? Stack2dOptions::Path::Fused
                                                                       : Stack2dOptions::Path::Raster;
        else if (key == "empty_space_skipping")
            o.emptySpaceSkipping = booleanOption(key, value);
        else if (key == "packets")
            o.packets = packetsOption(key, value);
        else if (key == "early_termination")
            o.earlyTermination = earlyTerminationOption(value);
        else
            unparsedOption(info, key);
    });
    // Several slices per polygon is the raster path's speed-up (one quad for several planes).
    if (o.slicesPerPolygon > 1) {
        if (options.contains("path") && o.path == Stack2dOptions::Path::Fused)
            badOption("path", "\"fused\" does not work with slices_per_polygon > 1 (the raster path's quads do it): "
                              "give \"path\": \"raster\" or leave path out");
        o.path = Stack2dOptions::Path::Raster;
    }
    if (o.earlyTermination < 1.0 && o.path == Stack2dOptions::Path::Raster)
        badOption("early_termination", "is only available on the fused path (the blending stage cannot stop a pixel)");
    return o;
}

int stackAxis(const Camera& camera)
{
    const glm::dvec3 f = glm::abs(camera.forward());
    int axis = 0;
    for (int a = 1; a < 3; ++a)
        if (f[a] > f[axis])
            axis = a;
    return axis;
}

std::vector<StackSlice> planStack(const Camera& camera, const glm::dvec3& origin, const glm::dvec3& spacing,
                                  const glm::ivec3& dims, int axis, int intermediate)
{
    const int perCell = intermediate + 1;
    const int count = (dims[axis] - 1) * perCell + 1;
    std::vector<StackSlice> slices(count);
    for (int j = 0; j < count; ++j) {
        StackSlice& s = slices[j];
        s.lower = j / perCell;
        s.weight = static_cast<float>(j % perCell) / static_cast<float>(perCell);
        s.position = s.lower + static_cast<double>(j % perCell) / perCell;
        s.thickness = spacing[axis] / perCell * (j == 0 || j == count - 1 ? 0.5 : 1.0);
    }
    // Back to front. Perspective: the rays that meet a plane come from the camera, so along every
    // ray the planes follow in increasing distance |camera - plane| along the axis (planes on the
    // other side of the camera are behind it and clipped away). Parallel: depth along forward.
    const double forwardAxis = camera.forward()[axis];
    auto farness = [&](const StackSlice& s) {
        const double x = origin[axis] + s.position * spacing[axis];
        return camera.parallel ? forwardAxis * x : std::abs(x - camera.position[axis]);
    };
    std::stable_sort(slices.begin(), slices.end(),
                     [&](const StackSlice& a, const StackSlice& b) { return farness(a) > farness(b); });
    return slices;
}

SliceGroups groupStackSlices(const std::vector<StackSlice>& drawOrder, const Camera& camera, const glm::dvec3& origin,
                             const glm::dvec3& spacing, int axis, int perPolygon)
{
    SliceGroups out;
    std::vector<StackSlice> sides[2];
    for (const StackSlice& slice : drawOrder) {
        const double x = origin[axis] + slice.position * spacing[axis];
        if (camera.parallel)
            sides[0].push_back(slice);
        else if (x != camera.position[axis])
            sides[x > camera.position[axis] ? 0 : 1].push_back(slice);
    }
    for (const std::vector<StackSlice>& side : sides)
        for (std::size_t first = 0; first < side.size(); first += perPolygon) {
            const std::size_t count = std::min<std::size_t>(perPolygon, side.size() - first);
            out.groups.emplace_back(static_cast<int>(out.slices.size()), static_cast<int>(count));
            out.slices.insert(out.slices.end(), side.begin() + first, side.begin() + first + count);
        }
    return out;
}

std::unique_ptr<Renderer> makeStack2dRenderer(Device& device, const Scene& scene, const Volume& volume)
{
    return std::make_unique<Stack2dRenderer>(device, scene, volume);
}

void setStack2dClipPlacement(Renderer& renderer, const glm::dvec3& offset, const glm::dmat3& matrix)
{
    auto* stack2d = dynamic_cast<Stack2dRenderer*>(&renderer);
    if (!stack2d)
        throw InternalError("setStack2dClipPlacement: the renderer is not stack2d");
    stack2d->setClipPlacement(offset, matrix);
}

}  // namespace clvr
