// host/render/grid/slice3d.cpp — options, slice planning, slice polygons, and the two paths of the
// slice3d technique: the fused kernel (kernels/slice3d.cl: slice3d_fused) and the pass-by-pass
// path through raster::draw with kernels/slice3d.cl as fragment program.
#include "host/render/grid/slice3d.h"

#include "host/render/scaffold.h"
#include "host/runtime/embedded_kernels.h"
#include "host/runtime/errors.h"
#include "host/render/camera_args.h"
#include "host/render/fragment_uniforms.h"
#include "host/optics/psi_table.h"
#include "host/render/options_util.h"
#include "host/render/transfer_function_upload.h"
#include "kernels/slice3d_params.h"
#include "raster/framebuffer.h"
#include "raster/rasterizer.h"
#include "raster/texture.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>

namespace clvr {

static_assert(sizeof(ClSlice3dOverBackgroundParams) == 32, "also probed on the device by tests/layout_test.cpp");

namespace {

// The clip mesh as a triangle list for raster::draw: clip-space positions, attribute 0 the world position
// (read by the fused path's peeling, kernels/clip_layers.cl; the stencil passes draw no attributes).
std::vector<raster::Vertex> clipMeshVertices(const ClipMesh& mesh, const glm::dmat4& viewProjection)
{
    std::vector<raster::Vertex> vertices;
    vertices.reserve(mesh.triangles.size() * 3);
    for (const auto& t : mesh.triangles)
        for (std::uint32_t i : t) {
            raster::Vertex v;
            v.position = glm::vec4(viewProjection * glm::dvec4(mesh.points[i], 1.0));
            v.attributes[0] = glm::vec4(glm::vec3(mesh.points[i]), 1.0f);
            vertices.push_back(v);
        }
    return vertices;
}

class Slice3dRenderer final : public Renderer {
public:
    Slice3dRenderer(Device& device, const Scene& scene, const Volume& volume);
    Image4f render(FrameStats& stats) override;
    std::uint64_t residentBytes() const override { return residentBytes_; }
    void setTransferFunction(const TransferFunction& tf) override;
    bool setCamera(const Scene& scene) override;
    void setClipPlacement(const glm::dvec3& offset, const glm::dmat3& matrix);

private:
    Image4f renderFused(FrameStats& stats);
    Image4f renderRaster(FrameStats& stats);
    raster::DrawStats drawClipped(const std::vector<raster::Vertex>& slices, const std::vector<std::size_t>& firsts,
                                  const raster::DrawState& sliceState, const glm::dmat4& viewProjection);
    void peelClipMesh();
    void frameView(const Scene& scene);
    void setFragmentView();

    Device& device_;
    Slice3dOptions options_;
    Camera camera_;
    ImageSpec image_;
    glm::ivec3 dims_;
    glm::dvec3 origin_, spacing_, lo_, hi_;  // the full grid's origin and box (a part's are inside them)
    GridPart part_;                          // where the volume sits in the full grid (sort-last; else the whole)
    TransferFunctionUpload tf_;
    SlicePlan plan_;
    cl::Buffer volume_;
    bool volumeSharesHost_ = false;  // volume_ is the host volume's own block (Device::readOnlyOver)
    std::uint64_t residentBytes_ = 0;
    // Empty-space skipping (fused path).
    glm::ivec3 brickDims_{0};
    BrickGrid brickGrid_;  // min-max per brick, kept to classify the bricks again for a new transfer function
    cl::Buffer emptyBricks_;
    cl::Buffer psi_;  // integration "preintegrated": the ψ table of host/optics/psi_table.h
    std::uint64_t emptyBrickCount_ = 0;
    glm::ivec3 filledLo_{0}, filledHi_{-1};  // the bricks that are not empty span [filledLo_, filledHi_]
    double brickSetupMs_ = 0.0;
    std::string voxelType_ = "float32";  // on the device
    // Fused path.
    cl::Kernel fused_;
    bool packet_ = false;
    cl::Buffer out_, samples_, skipped_;
    // Pass-by-pass path.
    std::unique_ptr<raster::Framebuffer> framebuffer_;
    raster::FragmentProgram fragmentProgram_;
    ClSlice3dUniforms fragmentUniforms_{};
    raster::Rasterizer rasterizer_{device_};      // slice polygons: its stats are the frame's samples
    raster::Rasterizer clipRasterizer_{device_};  // the clip mesh's stencil passes, not counted
    std::optional<OverBackground> overBackground_;  // the raster path's last pass
    // Clipping with a closed mesh: the mesh and its farthest eye depth; on the fused path its surfaces along
    // each pixel's ray, peeled once into depth layers (kernels/clip_layers.cl), and the time that took.
    std::optional<ClipMesh> clipMesh_;
    double clipDepthMax_ = 0.0;
    cl::Buffer clipLayers_;
    int clipLayerCount_ = -1;  // -1: not peeled yet
    double clipPeelMs_ = 0.0;
    // Clip texture (both paths): the texture, its device copy, and world -> texture coordinates.
    std::optional<ClipTexture> clipTexture_;
    std::unique_ptr<raster::Texture> clipTexels_;
    glm::dmat4 clipCoordinates_{1.0};
};

Slice3dRenderer::Slice3dRenderer(Device& device, const Scene& scene, const Volume& volume)
    : device_(device), options_(parseSlice3dOptions(scene.options)), image_(scene.image)
{
    checkGridVolume(volume, "slice3d");
    dims_ = volume.dims;
    spacing_ = volume.spacing;
    // A part of a larger grid (sort-last) takes the full grid's slices and sample positions and keeps
    // the samples it owns (host/model/volume.h's GridPart): the parts' images composite to the full one.
    part_ = volume.gridPart();
    if (volume.part && options_.path != Slice3dOptions::Path::Fused)
        throw InputError("slice3d: the raster path (options.path \"raster\") does not render a part "
                         "of a volume; use --distribution sort-first or frames");
    origin_ = part_.fullOrigin;
    lo_ = part_.fullBoundsMin();
    hi_ = part_.fullBoundsMax(spacing_);
    if (options_.clip)
        clipMesh_ = loadClipMesh(options_.clip->mesh, scene.baseDir);
    frameView(scene);

    if (options_.clipTexture) {
        clipTexture_ = makeClipTexture(*options_.clipTexture, scene.baseDir);
        clipCoordinates_ =
            clipTextureCoordinates(*clipTexture_, options_.clipTexture->offset, options_.clipTexture->matrix);
    }

    // On the fused path with voxel_type auto, uint8 or uint16 when every value is an integer in that
    // range (1 or 2 bytes per grid point, converted to float exactly in the kernel); else float32, 4
    // bytes per grid point. Device::buffer throws DeviceError if too big. A volume held in its own 1- or
    // 2-byte type (Volume::voxels) goes up as it is, with no host copy: int8 and int16 too where no value
    // is negative (the same bits as uint8 and uint16). Where the device's memory is the host's, the buffer is
    // the voxels' own block (stats: volume_shares_host), so the process holds them once.
    std::string trilinearOptions;
    const bool fused = options_.path == Slice3dOptions::Path::Fused;
    auto integralUpTo = [&](float top) {
        return !volume.native() && std::all_of(volume.values.begin(), volume.values.end(), [top](float v) {
            return v >= 0.0f && v <= top && v == std::floor(v);
        });
    };
    const bool nativeUnsigned = volume.native() && volume.range().x >= 0.0;
    const std::size_t nativeSize = voxelTypeSize(volume.voxelType);
    std::vector<float> scratch;  // only where a native volume must go up as float32
    if (fused && options_.nativeVoxels && nativeUnsigned) {
        volume_ = device_.readOnlyOver(nativeSize == 1 ? "slice3d volume (uint8)" : "slice3d volume (uint16)",
                                       volume.voxels.size(), volume.voxels.data(), volume.voxels.owner(),
                                       &volumeSharesHost_);
        voxelType_ = nativeSize == 1 ? "uint8" : "uint16";
        residentBytes_ = volume.voxels.size();
        trilinearOptions = nativeSize == 1
                               ? "-DSLICE3D_VOXEL=uchar -DSLICE3D_VOXEL_BITS=8 -DSLICE3D_TRILINEAR=clvr_trilinear_uchar"
                               : "-DSLICE3D_VOXEL=ushort -DSLICE3D_VOXEL_BITS=16 -DSLICE3D_TRILINEAR=clvr_trilinear_ushort";
    } else if (volume.native()) {
        volume_ = device_.upload("slice3d volume (float32)", volume.floats(scratch));
        residentBytes_ = volume.voxelCount() * sizeof(float);
    } else if (fused && options_.nativeVoxels && integralUpTo(255.0f)) {
        std::vector<cl_uchar> v(volume.values.begin(), volume.values.end());
        volume_ = device_.upload("slice3d volume (uint8)", v);
        voxelType_ = "uint8";
        residentBytes_ = v.size();
        trilinearOptions = "-DSLICE3D_VOXEL=uchar -DSLICE3D_VOXEL_BITS=8 -DSLICE3D_TRILINEAR=clvr_trilinear_uchar";
    } else if (fused && options_.nativeVoxels && integralUpTo(65535.0f)) {
        std::vector<cl_ushort> v(volume.values.begin(), volume.values.end());
        volume_ = device_.upload("slice3d volume (uint16)", v);
        voxelType_ = "uint16";
        residentBytes_ = v.size() * sizeof(cl_ushort);
        trilinearOptions = "-DSLICE3D_VOXEL=ushort -DSLICE3D_VOXEL_BITS=16 -DSLICE3D_TRILINEAR=clvr_trilinear_ushort";
    } else {
        volume_ = device_.upload("slice3d volume (float32)", volume.values);
        residentBytes_ = volume.values.size() * sizeof(float);
    }
    tf_.upload(device_, "slice3d transfer function", scene.transferFunction);
    residentBytes_ += tf_.bytes();

    if (clipTexture_) {
        clipTexels_ = std::make_unique<raster::Texture>(device_, clipTexture_->desc, clipTexture_->texels);
        residentBytes_ += clipTexels_->bytes();
        trilinearOptions += " -DSLICE3D_CLIP_TEXTURE=1";
    }
    if (clipMesh_ && fused)
        trilinearOptions += " -DSLICE3D_CLIP_MESH=1";
    if (options_.preintegrated) {
        if (volume.part)
            throw InputError("slice3d: \"integration\": \"preintegrated\" renders the whole grid, not a part of it "
                             "(its slabs cross the parts' borders); use --distribution sort-first or frames");
        const PsiTable& psi = psiTable();
        psi_ = device_.upload("slice3d psi table", psi.values);
        residentBytes_ += psi.values.size() * sizeof(float);
        trilinearOptions += " -DSLICE3D_PREINTEGRATED=1";
    }

    const std::size_t pixels = static_cast<std::size_t>(image_.width) * image_.height;
    if (options_.path == Slice3dOptions::Path::Fused) {
        // Ray packets (docs/slice3d.md): the same kernel's arithmetic on 8 pixels at once; the pre-integrated
        // slabs keep one pixel per work-item.
        packet_ = packetsOnDevice(options_.packets, device_) && !options_.preintegrated;
        fused_ = device_.kernel("slice3d.cl", packet_ ? "slice3d_fused_packet" : "slice3d_fused", {}, trilinearOptions);
        out_ = device_.buffer("slice3d image", pixels * sizeof(cl_float4), CL_MEM_WRITE_ONLY);
        samples_ = device_.buffer("slice3d sample counts", pixels * sizeof(cl_uint), CL_MEM_WRITE_ONLY);
        skipped_ = device_.buffer("slice3d skipped sample counts", pixels * sizeof(cl_uint), CL_MEM_WRITE_ONLY);
        // The min-max grid (host) and one flag byte per brick for this transfer function (device).
        const auto t0 = std::chrono::steady_clock::now();
        brickGrid_ = buildBrickGrid(volume);
        const BrickGrid& grid = brickGrid_;
        std::vector<cl_uchar> flags = emptyBricks(grid, scene.transferFunction);
        brickSetupMs_ = msSince(t0);
        brickDims_ = grid.dims;
        emptyBrickCount_ = static_cast<std::uint64_t>(std::count(flags.begin(), flags.end(), cl_uchar(1)));
        filledBricks(grid.dims, flags, filledLo_, filledHi_);
        emptyBricks_ = device_.upload("slice3d empty-space radii", emptySpaceRadii(grid.dims, flags));
        residentBytes_ += flags.size();
        if (clipMesh_)  // the peeling draws
            framebuffer_ = std::make_unique<raster::Framebuffer>(device_, image_.width, image_.height);
    } else {
        framebuffer_ = std::make_unique<raster::Framebuffer>(device_, image_.width, image_.height);
        overBackground_.emplace(device_);
        const std::string_view source = embeddedKernelSource("slice3d.cl");
        fragmentProgram_.source = std::string("#define CLVR_SLICE3D_FRAGMENT 1\n") +
                                  (clipTexture_ ? "#define CLVR_SLICE3D_CLIP_TEXTURE 1\n" : "") + std::string(source);
        fragmentProgram_.attributes = clipTexture_ ? 2 : 1;  // world position, clip-texture coordinates
        fragmentProgram_.buffers[0] = volume_;
        fragmentProgram_.buffers[1] = tf_.buffer();
        const glm::dvec3 invSpacing = 1.0 / spacing_;
        fragmentUniforms_.grid_origin = toCl4(origin_);
        fragmentUniforms_.inv_spacing = toCl4(invSpacing);
        fragmentUniforms_.dims = cl_float4{{static_cast<float>(dims_.x), static_cast<float>(dims_.y),
                                            static_cast<float>(dims_.z), 0.0f}};
        if (clipTexture_) {  // the second texture: buffer 2, u->clip_tex, coordinates in attribute 1
            fragmentProgram_.buffers[2] = clipTexels_->buffer();
            const glm::ivec3 n = clipTexture_->dims();
            fragmentUniforms_.clip_tex = cl_float4{{static_cast<float>(n.x), static_cast<float>(n.y),
                                                    static_cast<float>(n.z), options_.clipTexture->inverse ? 1.0f : 0.0f}};
        }
        setFragmentView();
    }
}

// What depends on the view: the framed camera, the slices, the clip mesh's depth range and (on the raster path)
// the fragment program's camera and slab; the clip mesh's peeled layers are peeled again at the next frame.
void Slice3dRenderer::frameView(const Scene& scene)
{
    image_ = scene.image;
    camera_ = frameCamera(scene, lo_, hi_);
    plan_ = planSlices(camera_, lo_, hi_, options_);
    if (clipMesh_) {
        clipDepthMax_ = -std::numeric_limits<double>::infinity();
        for (const glm::dvec3& p : clipMesh_->points)
            clipDepthMax_ = std::max(clipDepthMax_, glm::dot(camera_.forward(), p - camera_.position));
        clipLayerCount_ = -1;
    }
}

void Slice3dRenderer::setFragmentView()
{
    fragmentUniforms_.camera = toClCamera(camera_, image_.width, image_.height);
    fragmentUniforms_.frame = cl_float4{{static_cast<float>(image_.width), static_cast<float>(image_.height),
                                         static_cast<float>(plan_.deltaS), static_cast<float>(tf_.count())}};
    fragmentUniforms_.slab = cl_float4{{static_cast<float>(plan_.depth(0)), 0.0f, 0.0f, 0.0f}};
    fragmentProgram_.uniforms = fragmentUniforms(fragmentUniforms_);
}

bool Slice3dRenderer::setCamera(const Scene& scene)
{
    if (!sameImageSize(scene.image, image_))
        return false;  // the image-sized buffers and frame buffer would change
    frameView(scene);
    if (options_.path == Slice3dOptions::Path::Raster)
        setFragmentView();
    return true;
}

void Slice3dRenderer::setClipPlacement(const glm::dvec3& offset, const glm::dmat3& matrix)
{
    if (!clipTexture_)
        throw InputError("slice3d: no clip texture to move (options.clip_texture is not given)");
    if (!(std::abs(glm::determinant(matrix)) > 0.0))
        throw InputError("slice3d: the clip texture's matrix must be invertible");
    options_.clipTexture->offset = offset;
    options_.clipTexture->matrix = matrix;
    clipCoordinates_ = clipTextureCoordinates(*clipTexture_, offset, matrix);
}

Image4f Slice3dRenderer::render(FrameStats& stats)
{
    const FrameClock clock;
    Image4f image = options_.path == Slice3dOptions::Path::Fused ? renderFused(stats) : renderRaster(stats);
    finishFrame(device_, clock, stats);
    stats.extra["slices"] = plan_.count;
    stats.extra["slice_spacing"] = plan_.deltaS;
    stats.extra["depth_range"] = {plan_.depthMin, plan_.depthMax};
    stats.extra["order"] = options_.order == Slice3dOptions::Order::BackToFront ? "back-to-front" : "front-to-back";
    stats.extra["path"] = options_.path == Slice3dOptions::Path::Fused ? "fused" : "raster";
    stats.extra["integration"] = options_.preintegrated ? "preintegrated" : "sample";
    stats.extra["early_termination"] = options_.earlyTermination;
    stats.extra["voxels"] = static_cast<std::uint64_t>(dims_.x) * dims_.y * dims_.z;
    stats.extra["resident_bytes"] = residentBytes_;
    stats.extra["voxel_type"] = voxelType_;
    stats.extra["volume_shares_host"] = volumeSharesHost_;
    if (clipTexture_)
        addClipTextureStats(stats.extra, *clipTexture_, *options_.clipTexture);
    return image;
}

void Slice3dRenderer::setTransferFunction(const TransferFunction& tf)
{
    tf_.replace(device_, "slice3d transfer function", tf, residentBytes_);
    if (options_.path == Slice3dOptions::Path::Fused) {
        // Which bricks are empty depends on the transfer function: classify the kept min-max grid again.
        const auto t0 = std::chrono::steady_clock::now();
        const std::vector<cl_uchar> flags = emptyBricks(brickGrid_, tf);
        const std::vector<cl_uchar> radii = emptySpaceRadii(brickGrid_.dims, flags);
        brickSetupMs_ = msSince(t0);
        emptyBrickCount_ = static_cast<std::uint64_t>(std::count(flags.begin(), flags.end(), cl_uchar(1)));
        filledBricks(brickGrid_.dims, flags, filledLo_, filledHi_);
        device_.queue().enqueueWriteBuffer(emptyBricks_, CL_TRUE, 0, radii.size(), radii.data());
    } else {
        fragmentProgram_.buffers[1] = tf_.buffer();
        fragmentUniforms_.frame.s[3] = static_cast<float>(tf_.count());
        fragmentProgram_.uniforms = fragmentUniforms(fragmentUniforms_);
    }
}

Image4f Slice3dRenderer::renderFused(FrameStats& stats)
{
    const glm::dvec3 invSpacing = 1.0 / spacing_;
    const bool frontToBack = options_.order == Slice3dOptions::Order::FrontToBack;
    // ERT threshold 1.0 means off: pass a value accumulated opacity can never reach.
    const float ert = options_.earlyTermination < 1.0 ? static_cast<float>(options_.earlyTermination) : 2.0f;
    // Off when asked, or when no brick is empty (then the loop is the plain one).
    const bool skip = options_.emptySpaceSkipping && emptyBrickCount_ > 0;
    ClSlice3dParams params{};
    params.camera = toClCamera(camera_, image_.width, image_.height);
    params.dims = cl_int4{{dims_.x, dims_.y, dims_.z, 0}};
    params.grid_origin = toCl4(origin_);
    params.inv_spacing = toCl4(invSpacing);
    params.brick_dims = cl_int4{{brickDims_.x, brickDims_.y, brickDims_.z, 0}};
    params.background = toCl4(image_.background, 0.0);
    params.width = image_.width;
    params.height = image_.height;
    params.tf_count = tf_.count();
    params.skip = skip ? 1 : 0;
    params.depth0 = static_cast<cl_float>(plan_.depth(0));
    params.delta_s = static_cast<cl_float>(plan_.deltaS);
    params.slice_count = plan_.count;
    params.front_to_back = frontToBack ? 1 : 0;
    params.ert_alpha = ert;
    setGridPartParams(params, part_, dims_);
    // The box of the bricks that are not empty (brick b covers the points [4b, 4b + 4] of this volume, at
    // part_offset in the full grid), inside the owned box: the samples the loop visits (kernels/slice3d.cl).
    const glm::vec3 partOffset(part_.offset);
    for (int a = 0; a < 3; ++a) {
        params.tight_lo.s[a] = std::max(params.own_lo.s[a], partOffset[a] + static_cast<float>(filledLo_[a] * kBrickCells));
        params.tight_hi.s[a] = std::min(params.own_hi.s[a], partOffset[a] + static_cast<float>((filledHi_[a] + 1) * kBrickCells));
    }
    // (No brick holds anything, or the box misses the owned one: tight_lo >= tight_hi on an axis, a box whose
    // chord clvr_box_chord makes empty.)
    // The whole grid's box, [0, n - 1] per axis, half open above as own_hi is (the next float above n - 1), so
    // that a ray lying in the last grid plane counts as inside, as its samples do.
    const glm::vec3 last = glm::vec3(part_.fullDims - 1);
    params.grid_hi = cl_float4{{std::nextafter(last.x, INFINITY), std::nextafter(last.y, INFINITY),
                                std::nextafter(last.z, INFINITY), 0.0f}};
    int a = 0;
    fused_.setArg(a++, out_);
    fused_.setArg(a++, samples_);
    fused_.setArg(a++, skipped_);
    fused_.setArg(a++, volume_);
    fused_.setArg(a++, tf_.buffer());
    fused_.setArg(a++, emptyBricks_);
    if (clipTexture_) {
        fused_.setArg(a++, clipTexels_->buffer());
        params.clip_tex = clipTexels_->toCl();
        for (int r = 0; r < 3; ++r)  // rows of the affine world -> texture coordinates map
            params.clip_row[r] = toCl4(glm::dvec3(clipCoordinates_[0][r], clipCoordinates_[1][r], clipCoordinates_[2][r]),
                                       clipCoordinates_[3][r]);
        params.clip_inverse = options_.clipTexture->inverse ? 1 : 0;
    }
    if (clipMesh_) {
        if (clipLayerCount_ < 0)
            peelClipMesh();  // once: the layers depend only on the camera and the mesh
        fused_.setArg(a++, clipLayers_);
        params.clip_mesh = cl_int4{{clipLayerCount_, options_.clip->inverse ? 1 : 0,
                                    options_.clip->method == Slice3dClip::Method::Naive ? 1 : 0, 0}};
    }
    if (options_.preintegrated) {
        fused_.setArg(a++, psi_);
        params.psi_n = static_cast<cl_int>(psiTable().size);
    }
    fused_.setArg(a++, params);
    device_.launch("slice3d: fused", fused_, rowWorkItems(image_.width, packet_), image_.height);

    const std::size_t pixels = static_cast<std::size_t>(image_.width) * image_.height;
    Image4f image = readImage(device_, out_, image_.width, image_.height);
    // samples: inside the box (taken + stepped over), as without skipping; the skipped ones apart.
    stats.samples = sumCounts(device_, samples_, pixels);
    const std::uint64_t skipped = sumCounts(device_, skipped_, pixels);
    stats.extra["samples_skipped"] = skipped;
    stats.extra["samples_taken"] = stats.samples - skipped;
    stats.extra["empty_space_skipping"] = skip;
    stats.extra["packets"] = packet_;
    stats.extra["bricks"] = {brickDims_.x, brickDims_.y, brickDims_.z};
    stats.extra["empty_bricks"] = emptyBrickCount_;
    stats.extra["brick_setup_ms"] = brickSetupMs_;
    if (clipMesh_) {
        stats.extra["clip_layers"] = clipLayerCount_;
        stats.extra["clip_peel_ms"] = clipPeelMs_;
    }
    return image;
}

// The fused path's clip mesh (docs/slice3d.md, "Clipping with closed meshes"): its surfaces along each
// pixel's ray as depth layers, by depth peeling — the whole mesh drawn once per layer with the depth test
// LESS, kernels/clip_layers.cl discarding every fragment at or in front of the previous layer's window
// depth at its pixel — until a draw leaves no fragment. Layer l, one float4 per pixel (eye depth of the
// (l+1)-th surface, 1 if it is front-facing; +inf where the ray has fewer surfaces), is the frame buffer's
// color after draw l. The fused kernel then asks, per sample, whether the first surface beyond it is a back
// face: the stencil passes' rule, without drawing the mesh per slice.
void Slice3dRenderer::peelClipMesh()
{
    constexpr int kMaxLayers = 64;
    const auto t0 = std::chrono::steady_clock::now();
    const std::size_t pixels = static_cast<std::size_t>(image_.width) * image_.height;
    const std::vector<raster::Vertex> mesh = clipPeelVertices(*clipMesh_, camera_, image_.width, image_.height, plan_);
    raster::FragmentProgram peel;
    peel.source = "#define CLVR_CLIP_LAYERS_FRAGMENT 1\n" + std::string(embeddedKernelSource("clip_layers.cl"));
    peel.attributes = 1;
    const glm::dvec3 eye = camera_.position, forward = camera_.forward();
    peel.uniforms = {glm::vec4(glm::vec3(eye), static_cast<float>(image_.width)), glm::vec4(glm::vec3(forward), 0.0f)};
    cl::Buffer previous = device_.upload("slice3d clip mesh: previous layer's depth", std::vector<float>(pixels, -1.0f));
    peel.buffers[0] = previous;
    raster::DrawState state;
    state.fragment.depth.test = true;
    state.fragment.depth.func = raster::CompareFunc::Less;
    state.fragment.depth.write = true;
    std::vector<cl::Buffer> layers;
    for (;;) {
        framebuffer_->clearDepth(device_, 1.0f);
        // +inf where a ray has no surface left, marked front-facing: nothing beyond a sample there makes it inside
        framebuffer_->clearColor(device_, glm::vec4(std::numeric_limits<float>::infinity(), 1.0f, 0.0f, 0.0f));
        raster::draw(device_, *framebuffer_, state, raster::Topology::Triangles, mesh, peel);
        const std::vector<float> depth = device_.download<float>(framebuffer_->depth(), pixels);
        if (std::none_of(depth.begin(), depth.end(), [](float d) { return d < 1.0f; }))
            break;  // no surface left along any ray
        if (static_cast<int>(layers.size()) == kMaxLayers)
            throw InputError("options.clip.mesh: some pixel's ray crosses the clip mesh more than " +
                             std::to_string(kMaxLayers) + " times; use \"path\": \"raster\"");
        layers.push_back(device_.buffer("slice3d clip mesh layer", pixels * sizeof(cl_float4)));
        device_.queue().enqueueCopyBuffer(framebuffer_->color(), layers.back(), 0, 0, pixels * sizeof(cl_float4));
        device_.queue().enqueueCopyBuffer(framebuffer_->depth(), previous, 0, 0, pixels * sizeof(float));
    }
    // One buffer, layer after layer (one float4 per pixel each); a mesh no ray meets still gets one layer
    // of +inf, so that the kernel has a buffer to read.
    const std::size_t bytes = std::max<std::size_t>(layers.size(), 1) * pixels * sizeof(cl_float4);
    clipLayers_ = device_.buffer("slice3d clip mesh layers", bytes);
    if (layers.empty())
        device_.queue().enqueueFillBuffer(clipLayers_, cl_float4{{std::numeric_limits<float>::infinity(), 1.0f, 0.0f, 0.0f}},
                                          0, bytes);
    for (std::size_t l = 0; l < layers.size(); ++l)
        device_.queue().enqueueCopyBuffer(layers[l], clipLayers_, 0, l * pixels * sizeof(cl_float4),
                                          pixels * sizeof(cl_float4));
    device_.queue().finish();
    clipLayerCount_ = static_cast<int>(layers.size());
    residentBytes_ += bytes;
    clipPeelMs_ = msSince(t0);
}

Image4f Slice3dRenderer::renderRaster(FrameStats& stats)
{
    const bool frontToBack = options_.order == Slice3dOptions::Order::FrontToBack;
    // Clip-space vertices of every slice polygon, fanned into a triangle list, in blending order;
    // firsts[i] is where the i-th slice drawn begins. The far plane lies beyond the box and the clip
    // mesh (its back faces must not be cut); x, y and w do not depend on it, so neither do the slices.
    const glm::dvec3 forward = camera_.forward();
    const double nearZ = 0.5 * plan_.depth(0);
    const double farZ = 2.0 * std::max(plan_.depthMax, clipMesh_ ? clipDepthMax_ : 0.0) + 1.0;
    const glm::dmat4 viewProjection =
        camera_.projectionMatrix(image_.width, image_.height, nearZ, farZ) * camera_.viewMatrix();
    std::vector<raster::Vertex> vertices;
    std::vector<std::size_t> firsts;
    vertices.reserve(static_cast<std::size_t>(plan_.count) * 12);
    for (int i = 0; i < plan_.count; ++i) {
        const int k = frontToBack ? i : plan_.count - 1 - i;
        const double offset = glm::dot(forward, camera_.position) + plan_.depth(k);
        const std::vector<glm::dvec3> polygon = slicePolygon(lo_, hi_, forward, offset);
        auto vertex = [&](const glm::dvec3& p) {
            raster::Vertex v;
            v.position = glm::vec4(viewProjection * glm::dvec4(p, 1.0));
            v.attributes[0] = glm::vec4(glm::vec3(p), 1.0f);
            if (clipTexture_)  // the second texture's coordinates: moving the clip texture changes only these
                v.attributes[1] = glm::vec4(glm::vec3(clipCoordinates_ * glm::dvec4(p, 1.0)), 1.0f);
            return v;
        };
        firsts.push_back(vertices.size());
        for (std::size_t j = 1; j + 1 < polygon.size(); ++j) {
            vertices.push_back(vertex(polygon[0]));
            vertices.push_back(vertex(polygon[j]));
            vertices.push_back(vertex(polygon[j + 1]));
        }
    }
    firsts.push_back(vertices.size());
    raster::DrawState state;
    state.fragment.blend.enabled = true;
    if (frontToBack) {  // "under": dst += (1 - dst.a) src
        state.fragment.blend.srcRgb = state.fragment.blend.srcAlpha = raster::BlendFactor::OneMinusDstAlpha;
        state.fragment.blend.dstRgb = state.fragment.blend.dstAlpha = raster::BlendFactor::One;
    } else {
        state.fragment.blend = raster::premultipliedOver();
    }
    framebuffer_->clearColor(device_, glm::vec4(0.0f));
    raster::DrawStats drawStats;
    if (clipMesh_)
        drawStats = drawClipped(vertices, firsts, state, viewProjection);
    else if (!vertices.empty()) {
        rasterizer_.draw(*framebuffer_, state, raster::Topology::Triangles, vertices, fragmentProgram_);
        drawStats = rasterizer_.takeStats();
    }
    const std::size_t pixels = framebuffer_->pixelCount();
    overBackground_->run(framebuffer_->color(), pixels, image_.background, "slice3d: over background");
    Image4f image = framebuffer_->readColor(device_);
    stats.samples = drawStats.fragments;  // fragments of slice polygons; those outside the grid are discarded
    stats.extra["triangles"] = drawStats.triangles;
    if (clipMesh_) {
        stats.extra["clip_triangles"] = clipMesh_->triangles.size();
        stats.extra["clip_method"] = options_.clip->method == Slice3dClip::Method::TwoPass ? "two-pass" : "naive";
        stats.extra["clip_inverse"] = options_.clip->inverse;
    }
    return image;
}

// §2.1 of seeds/000, one slice at a time (docs/slice3d.md, "Clipping with closed meshes"). For a
// pixel, the slice's point P is inside the closed mesh iff the first surface the ray meets beyond P
// is a back face (the ray leaves there). So, with a user clip plane at the slice plane keeping only
// what lies behind it:
//   1. back faces, depth test LESS with depth writes, stencil := 1: the stencil marks pixels with any
//      back face behind P, and the depth buffer holds the nearest one;
//   2. front faces, depth test LESS without writes, stencil := 0 where one is in front of that
//      nearest back face: the ray enters the mesh before it first leaves it, so P is outside
//      (the naive method stops after 1 and keeps these pixels, Figure 2's error);
//   3. the slice polygon where stencil == 1 (inside), or == 0 (inverse), blended as without clipping.
raster::DrawStats Slice3dRenderer::drawClipped(const std::vector<raster::Vertex>& slices,
                                               const std::vector<std::size_t>& firsts,
                                               const raster::DrawState& sliceState, const glm::dmat4& viewProjection)
{
    const bool frontToBack = options_.order == Slice3dOptions::Order::FrontToBack;
    const bool twoPass = options_.clip->method == Slice3dClip::Method::TwoPass;
    const bool inverse = options_.clip->inverse;
    const std::vector<raster::Vertex> mesh = clipMeshVertices(*clipMesh_, viewProjection);

    raster::DrawState back;  // pass 1: no color writes, only stencil (and depth for pass 2)
    back.fragment.colorMask = {false, false, false, false};
    back.fragment.cull = raster::CullFace::Front;
    back.fragment.stencil.test = true;
    back.fragment.stencil.func = raster::CompareFunc::Always;
    back.fragment.stencil.ref = 1;
    back.fragment.stencil.dppass = raster::StencilOp::Replace;
    back.fragment.depth.test = twoPass;
    back.fragment.depth.func = raster::CompareFunc::Less;
    back.fragment.depth.write = true;
    raster::DrawState front = back;  // pass 2: clear where a front face is nearer than the nearest back face
    front.fragment.cull = raster::CullFace::Back;
    front.fragment.stencil.func = raster::CompareFunc::Equal;
    front.fragment.stencil.dppass = raster::StencilOp::Zero;
    front.fragment.depth.write = false;
    raster::DrawState slice = sliceState;  // pass 3
    slice.fragment.stencil.test = true;
    slice.fragment.stencil.func = raster::CompareFunc::Equal;
    slice.fragment.stencil.ref = inverse ? 0 : 1;

    const glm::dmat4 planeToClip = glm::transpose(glm::inverse(viewProjection));
    for (int i = 0; i < plan_.count; ++i) {
        if (firsts[i] == firsts[i + 1])
            continue;  // the plane misses the box
        const int k = frontToBack ? i : plan_.count - 1 - i;
        const double offset = glm::dot(camera_.forward(), camera_.position) + plan_.depth(k);
        const std::vector<raster::Vertex> polygon(slices.begin() + static_cast<std::ptrdiff_t>(firsts[i]),
                                                  slices.begin() + static_cast<std::ptrdiff_t>(firsts[i + 1]));
        raster::DrawState sliceHere = slice;
        if (plan_.depth(k) >= clipDepthMax_) {
            // No part of the mesh lies behind this slice: every point of it is outside (the passes
            // would leave the stencil all 0), so skip them.
            if (!inverse)
                continue;
            sliceHere.fragment.stencil.test = false;
        } else {
            framebuffer_->clearStencil(device_, 0);
            if (twoPass)
                framebuffer_->clearDepth(device_, 1.0f);
            // Keep dot(forward, p) >= offset: the part of the mesh behind the slice plane. As
            // raster::clipPlaneFromWorld, but in double (offset may be large next to the box).
            back.clipPlanes = front.clipPlanes = {glm::vec4(planeToClip * glm::dvec4(camera_.forward(), -offset))};
            clipRasterizer_.draw(*framebuffer_, back, raster::Topology::Triangles, mesh);
            if (twoPass)
                clipRasterizer_.draw(*framebuffer_, front, raster::Topology::Triangles, mesh);
        }
        rasterizer_.draw(*framebuffer_, sliceHere, raster::Topology::Triangles, polygon, fragmentProgram_);
    }
    clipRasterizer_.takeStats();  // resets its counters
    return rasterizer_.takeStats();
}

}  // namespace

std::vector<raster::Vertex> clipPeelVertices(const ClipMesh& mesh, const Camera& camera, int width, int height,
                                             const SlicePlan& plan)
{
    // The raster path's projection (renderRaster): surfaces nearer than its near plane lie in front of every
    // slice, where the peel's rule never looks; the far plane lies beyond the box and the mesh.
    double depthMax = plan.depthMax;
    for (const glm::dvec3& p : mesh.points)
        depthMax = std::max(depthMax, glm::dot(camera.forward(), p - camera.position));
    const double nearZ = 0.5 * plan.depth(0), farZ = 2.0 * depthMax + 1.0;
    return clipMeshVertices(mesh, camera.projectionMatrix(width, height, nearZ, farZ) * camera.viewMatrix());
}

namespace {

// options.clip: {"mesh": ..., "inverse": false, "method": "two-pass"|"naive"}; docs/slice3d.md.
Slice3dClip parseClip(const nlohmann::json& value)
{
    if (!value.is_object())
        badOption("clip", "must be an object such as {\"mesh\": \"torus.off\"}, got " + value.dump());
    if (!value.contains("mesh"))
        badOption("clip.mesh", "is missing (a surface file, or {\"generator\": \"box\"|\"sphere\"|\"cylinder\", ...})");
    Slice3dClip clip;
    for (const auto& [key, v] : value.items()) {
        if (key == "mesh") {
            clip.mesh = parseClipMeshSpec(v, "options.clip.mesh");
        } else if (key == "inverse") {
            if (!v.is_boolean())
                badOption("clip.inverse", "must be true or false, got " + v.dump());
            clip.inverse = v.get<bool>();
        } else if (key == "method") {
            const std::string m = v.is_string() ? v.get<std::string>() : "";
            if (m == "two-pass")
                clip.method = Slice3dClip::Method::TwoPass;
            else if (m == "naive")
                clip.method = Slice3dClip::Method::Naive;
            else
                badOption("clip.method", "must be \"two-pass\" or \"naive\", got " + v.dump());
        } else {
            badOption("clip." + key, "unknown key (known: mesh, inverse, method)");
        }
    }
    return clip;
}

}  // namespace

TechniqueInfo slice3dTechnique()
{
    TechniqueInfo t;
    t.name = "slice3d";
    t.data = DataKind::Volume;
    t.description = "3D-texture slicing: view-aligned slices composited (docs/slice3d.md)";
    t.sortLast = true;  // the fused path; the raster path refuses a part
    t.options = {
        slicesInfo(),
        sliceSpacingInfo(),
        {"order", "back-to-front", "", "\"back-to-front\" (over) or \"front-to-back\" (under, with early termination)"},
        earlyTerminationInfo(1.0),
        {"path", "fused", "", "\"fused\" (all slices of a pixel in one kernel) or \"raster\" (pass by pass)"},
        {"empty_space_skipping", true, "", "fused path: step over bricks where tau is 0 (same image)"},
        {"voxel_type", "auto", "", "\"auto\" (uint8/uint16 on the device when the values fit) or \"float32\""},
        packetsInfo(),
        {"integration", "sample", "",
         "\"sample\" (alpha = 1 - exp(-tau delta) per slice sample) or \"preintegrated\" (fused path: each slab "
         "between samples integrated exactly for a linear scalar)"},
        {"clip", nullptr, "none", "clip by a closed mesh through the stencil buffer: {\"mesh\": ..., \"inverse\", \"method\"}"},
        clipTextureInfo(),
    };
    t.makeForVolume = makeSlice3dRenderer;
    return t;
}

Slice3dOptions parseSlice3dOptions(const nlohmann::json& options)
{
    static const TechniqueInfo& info = technique("slice3d");
    Slice3dOptions o;
    forEachOption(options, info, [&](const std::string& key, const nlohmann::json& value) {
        if (key == "slices") {
            o.slices = slicesOption(value);
        } else if (key == "slice_spacing") {
            o.sliceSpacing = sliceSpacingOption(value);
        } else if (key == "order") {
            const std::string s = value.is_string() ? value.get<std::string>() : "";
            if (s == "back-to-front")
                o.order = Slice3dOptions::Order::BackToFront;
            else if (s == "front-to-back")
                o.order = Slice3dOptions::Order::FrontToBack;
            else
                badOption(key, "must be \"back-to-front\" or \"front-to-back\", got " + value.dump());
        } else if (key == "early_termination") {
            o.earlyTermination = earlyTerminationOption(value);
        } else if (key == "path") {
            o.path = choiceOption(key, value, {"fused", "raster"}) == 0 ? Slice3dOptions::Path::Fused
                                                                          : Slice3dOptions::Path::Raster;
        } else if (key == "voxel_type") {
            const std::string s = value.is_string() ? value.get<std::string>() : "";
            if (s == "auto")
                o.nativeVoxels = true;
            else if (s == "float32")
                o.nativeVoxels = false;
            else
                badOption(key, "must be \"auto\" or \"float32\", got " + value.dump());
        } else if (key == "integration") {
            const std::string s = value.is_string() ? value.get<std::string>() : "";
            if (s == "sample")
                o.preintegrated = false;
            else if (s == "preintegrated")
                o.preintegrated = true;
            else
                badOption(key, "must be \"sample\" or \"preintegrated\", got " + value.dump());
        } else if (key == "empty_space_skipping") {
            o.emptySpaceSkipping = booleanOption(key, value);
        } else if (key == "packets") {
            o.packets = packetsOption(key, value);
        } else if (key == "clip") {
            o.clip = parseClip(value);
        } else if (key == "clip_texture") {
            o.clipTexture = parseClipTextureSpec(value, "options.clip_texture");
        } else {
            unparsedOption(info, key);
        }
    });
    checkSlicesOrSpacing(options);
    if (o.preintegrated && o.path == Slice3dOptions::Path::Raster)
        badOption("integration", "\"preintegrated\" is only available on the fused path (a fragment sees one "
                                 "slice, not the slab behind it)");
    if (o.preintegrated && o.clip)
        badOption("integration", "\"preintegrated\" does not combine with clip yet (a slab would be cut inside; "
                                 "docs/slice3d.md)");
    if (o.preintegrated && o.clipTexture)
        badOption("integration", "\"preintegrated\" does not combine with clip_texture yet (a slab would be cut "
                                 "inside; docs/slice3d.md)");
    if (o.preintegrated) {
        // The chain of slabs is walked from the eye (kernels/slice3d.cl); back to front would be the same integral.
        if (o.order == Slice3dOptions::Order::BackToFront && options.contains("order"))
            badOption("order", "must be \"front-to-back\" with \"integration\": \"preintegrated\" (the slabs are "
                               "composited from the eye), got \"back-to-front\"");
        o.order = Slice3dOptions::Order::FrontToBack;
    }
    if (o.earlyTermination < 1.0 && o.order != Slice3dOptions::Order::FrontToBack)
        badOption("early_termination", "needs \"order\": \"front-to-back\" (back to front cannot stop early)");
    if (o.earlyTermination < 1.0 && o.path == Slice3dOptions::Path::Raster)
        badOption("early_termination", "is only available on the fused path (the blending stage cannot stop a pixel)");
    return o;
}

SlicePlan planSlices(const Camera& camera, const glm::dvec3& lo, const glm::dvec3& hi, const Slice3dOptions& options)
{
    return planSlices(camera, lo, hi, options.slices, options.sliceSpacing);
}

BrickGrid buildBrickGrid(const Volume& volume)
{
    BrickGrid grid;
    const glm::ivec3 n = volume.dims;
    grid.dims = (n - 1 + (kBrickCells - 1)) / kBrickCells;  // cells n - 1 per axis
    grid.minMax.assign(static_cast<std::size_t>(grid.dims.x) * grid.dims.y * grid.dims.z,
                       glm::vec2(std::numeric_limits<float>::infinity(), -std::numeric_limits<float>::infinity()));
    // Per row of x: (min, max) over each brick's x range [Bb, Bb + B], then merged into every brick
    // whose y and z ranges hold the row (2 bricks where j or k is a multiple of B).
    std::vector<glm::vec2> row(grid.dims.x);
    for (int k = 0; k < n.z; ++k)
        for (int j = 0; j < n.y; ++j) {
            withVoxels(volume, [&](const auto* data, std::size_t) {  // the row in the volume's own type
                const auto* v = data + (static_cast<std::size_t>(k) * n.y + j) * n.x;
                for (int bx = 0; bx < grid.dims.x; ++bx) {
                    const int i0 = bx * kBrickCells, i1 = std::min(i0 + kBrickCells, n.x - 1);
                    const auto [mn, mx] = std::minmax_element(v + i0, v + i1 + 1);
                    row[bx] = {static_cast<float>(*mn), static_cast<float>(*mx)};
                }
            });
            const int by1 = std::min(j / kBrickCells, grid.dims.y - 1), bz1 = std::min(k / kBrickCells, grid.dims.z - 1);
            const int by0 = (j % kBrickCells == 0 && j > 0) ? j / kBrickCells - 1 : by1;
            const int bz0 = (k % kBrickCells == 0 && k > 0) ? k / kBrickCells - 1 : bz1;
            for (int bz = bz0; bz <= bz1; ++bz)
                for (int by = by0; by <= by1; ++by) {
                    glm::vec2* b = grid.minMax.data() + (static_cast<std::size_t>(bz) * grid.dims.y + by) * grid.dims.x;
                    for (int bx = 0; bx < grid.dims.x; ++bx)
                        b[bx] = {std::min(b[bx].x, row[bx].x), std::max(b[bx].y, row[bx].y)};
                }
        }
    return grid;
}

std::vector<cl_uchar> emptyBricks(const BrickGrid& grid, const TransferFunction& tf)
{
    std::vector<cl_uchar> flags(grid.minMax.size(), 0);
    for (std::size_t b = 0; b < flags.size(); ++b) {
        const glm::vec2 m = grid.minMax[b];
        // Trilinear values are convex combinations of the brick's points; in float they can stray a
        // few ulp outside [min, max]: widen by 2^-16 of the magnitude (far more than that).
        const float pad = std::ldexp(std::max(std::abs(m.x), std::abs(m.y)), -16) + 1e-30f;
        flags[b] = tauZeroOn(tf, m.x - pad, m.y + pad) ? 1 : 0;
    }
    return flags;
}

void filledBricks(const glm::ivec3& brickDims, const std::vector<cl_uchar>& empty, glm::ivec3& lo, glm::ivec3& hi)
{
    lo = brickDims;
    hi = glm::ivec3(-1);
    glm::ivec3 b;
    std::size_t i = 0;
    for (b.z = 0; b.z < brickDims.z; ++b.z)
        for (b.y = 0; b.y < brickDims.y; ++b.y)
            for (b.x = 0; b.x < brickDims.x; ++b.x, ++i)
                if (!empty[i]) {
                    lo = glm::min(lo, b);
                    hi = glm::max(hi, b);
                }
}

std::vector<cl_uchar> emptySpaceRadii(const glm::ivec3& brickDims, const std::vector<cl_uchar>& empty)
{
    // The value of an empty brick is its Chebyshev distance to the nearest brick that is not empty (r + 1: every
    // brick within r is empty), capped at 255. That distance is separable: with I = 0 for a brick that is not
    // empty and unbounded for an empty one, D(x, y, z) = min_x' max(|x - x'|, min_y' max(|y - y'|,
    // min_z' max(|z - z'|, I(x', y', z')))). One pass per axis over its lines, g(i) = min_j max(|i - j|, f(j)),
    // each searched outwards from i while the distance is below the best so far and the cap (O(n * min(D, 255))
    // per pass, where the fixed-point iteration over 27-neighbourhoods it replaces took O(n * 27 * max D)).
    constexpr int kCap = 255, kUnbounded = 1 << 20;
    const glm::ivec3 n = brickDims;
    std::vector<int> d(empty.size());
    for (std::size_t b = 0; b < empty.size(); ++b)
        d[b] = empty[b] ? kUnbounded : 0;
    const std::size_t stride[3] = {1, static_cast<std::size_t>(n.x), static_cast<std::size_t>(n.x) * n.y};
    std::vector<int> line, out;
    for (const int axis : {2, 1, 0}) {
        const int length = n[axis];
        const int u = axis == 0 ? 1 : 0, v = axis == 2 ? 1 : 2;  // the two other axes
        line.resize(length);
        out.resize(length);
        for (int a = 0; a < n[v]; ++a)
            for (int b = 0; b < n[u]; ++b) {
                const std::size_t base = a * stride[v] + b * stride[u];
                for (int i = 0; i < length; ++i)
                    line[i] = d[base + i * stride[axis]];
                for (int i = 0; i < length; ++i) {
                    int best = line[i];
                    for (int k = 1; k < best && k <= kCap && (i - k >= 0 || i + k < length); ++k) {
                        if (i - k >= 0)
                            best = std::min(best, std::max(k, line[i - k]));
                        if (i + k < length)
                            best = std::min(best, std::max(k, line[i + k]));
                    }
                    out[i] = best;
                }
                for (int i = 0; i < length; ++i)
                    d[base + i * stride[axis]] = out[i];
            }
    }
    std::vector<cl_uchar> space(empty.size());
    for (std::size_t b = 0; b < empty.size(); ++b)
        space[b] = static_cast<cl_uchar>(std::min(d[b], kCap));
    return space;
}

std::unique_ptr<Renderer> makeSlice3dRenderer(Device& device, const Scene& scene, const Volume& volume)
{
    return std::make_unique<Slice3dRenderer>(device, scene, volume);
}

void setSlice3dClipPlacement(Renderer& renderer, const glm::dvec3& offset, const glm::dmat3& matrix)
{
    auto* slice3d = dynamic_cast<Slice3dRenderer*>(&renderer);
    if (!slice3d)
        throw InternalError("setSlice3dClipPlacement: the renderer is not slice3d");
    slice3d->setClipPlacement(offset, matrix);
}

}  // namespace clvr
