// host/render/grid/cubefan.cpp — options, the exp-opacity texture and the cubefan renderer: per frame the
// octree's selection (back to front), every cube projected as its class's triangles (cube_fans.h) and
// drawn in that order through the raster stage in batches, kernels/cubefan.cl's fragment program per
// fragment, then slice3d's pass over the background.
#include "host/render/grid/cubefan.h"

#include "host/render/camera_args.h"
#include "host/render/fragment_uniforms.h"
#include "host/render/grid/cube_fans.h"
#include "host/render/grid/cube_octree.h"
#include "host/render/grid/slice3d.h"  // emptySpaceRadii
#include "host/render/options_util.h"
#include "host/render/scaffold.h"
#include "host/render/tile_lists.h"
#include "host/render/transfer_function_upload.h"
#include "host/runtime/embedded_kernels.h"
#include "host/runtime/errors.h"
#include "host/runtime/parallel.h"
#include "kernels/cubefan_params.h"
#include "raster/framebuffer.h"
#include "raster/rasterizer.h"

#include <algorithm>
#include <array>
#include <chrono>
#include <future>
#include <optional>
#include <cmath>
#include <string>

namespace clvr {

static_assert(sizeof(ClCubefanUniforms) == 112, "float4s only: the fragment program reads it from its uniforms");
static_assert(sizeof(ClCubefanFusedParams) == 192, "also probed on the device by tests/layout_test.cpp");

const char* pathName(CubefanOptions::Path path)
{
    switch (path) {
    case CubefanOptions::Path::Fused:
        return "fused";
    case CubefanOptions::Path::Raster:
        return "raster";
    case CubefanOptions::Path::Tiles:
        return "tiles";
    }
    return "fused";
}

const char* opacityName(CubefanOptions::Opacity opacity)
{
    switch (opacity) {
    case CubefanOptions::Opacity::Texture: return "texture";
    case CubefanOptions::Opacity::Exp: return "exp";
    case CubefanOptions::Opacity::Linear: return "linear";
    }
    return "?";
}

std::vector<float> expOpacityTexels(int size, double k)
{
    std::vector<float> texels(static_cast<std::size_t>(size) * size);
    const double step = 1.0 / (size - 1);
    for (int j = 0; j < size; ++j)
        for (int i = 0; i < size; ++i)
            texels[static_cast<std::size_t>(j) * size + i] = static_cast<float>(-std::expm1(-k * (i * step) * (j * step)));
    return texels;
}

double maxExtinction(const TransferFunction& tf)
{
    double m = 0.0;
    for (const auto& p : tf.points())
        m = std::max(m, p.tau);
    return m;
}

CubefanWalkGrid buildCubefanWalkGrid(const cubefan::CubeOctree& octree, const glm::ivec3& dims, double tolerance,
                                     const TransferFunction& tf, cubefan::SelectionStats* stats)
{
    CubefanWalkGrid walk;
    walk.grid = octree.selectGrid(tolerance, tf, stats);
    const glm::ivec3 bricks = (dims + 3) / 4;
    std::vector<cl_uchar> empty(walk.grid.level.size() / 64);
    for (std::size_t b = 0; b < empty.size(); ++b) {
        const std::uint8_t* code = walk.grid.level.data() + 64 * b;
        empty[b] = std::all_of(code, code + 64, [](std::uint8_t c) { return (c & cubefan::CubeOctree::kTransparent) != 0; });
    }
    walk.space = emptySpaceRadii(bricks, empty);
    walk.emptyBricks = static_cast<std::uint64_t>(std::count(empty.begin(), empty.end(), cl_uchar(1)));
    glm::ivec3 lo, hi;  // the bricks with a voxel that adds color
    filledBricks(bricks, empty, lo, hi);
    walk.filledLo = glm::min(lo * 4, dims);
    walk.filledHi = glm::min((hi + 1) * 4, dims);
    return walk;
}

namespace {

// Vertices per draw: 2^19 raster::Vertex are 40 MiB on the host, about 14,000 cubes of 12 triangles.
constexpr std::size_t kBatchVertices = std::size_t(1) << 19;

std::string programSource(const char* define)
{
    return std::string("#define ") + define + " 1\n" + std::string(embeddedKernelSource("cubefan.cl"));
}

using cubefan::cornerOf;

// The six faces as corner quadruples (v = x + 2y + 4z), in cyclic order; face f is 0 -x, 1 +x, ... 5 +z.
constexpr int kFaceCorners[6][4] = {{0, 2, 6, 4}, {1, 3, 7, 5}, {0, 1, 5, 4}, {2, 3, 7, 6}, {0, 1, 3, 2}, {4, 5, 7, 6}};

// What projecting a run of cubes needs, shared read-only by the worker thread.
struct ProjectionContext {
    cubefan::CubeView view;
    glm::dvec3 eye, forward;
    bool parallel;
    CubefanOptions options;
    glm::dvec3 shift;
    double lMax, nearZ;
    const TransferFunction* tf;
};

// Vertices for one fragment program, in the cubes' order.
struct VertexRun {
    bool box = false;  // the back-face program (CLVR_CUBEFAN_BOX), else the fans'
    std::vector<raster::Vertex> vertices;
};

// One chunk of cubes projected: its runs (the vectors are kept and reused, runCount of them in use) and counts.
struct ProjectedChunk {
    std::vector<VertexRun> runs;
    std::size_t runCount = 0;
    std::uint64_t culled = 0, nearCubes = 0, boxCubes = 0, triangles = 0;
    std::array<std::uint64_t, 4> byKind{};
    double ms = 0.0;
    void add(const ProjectedChunk& c)
    {
        culled += c.culled;
        nearCubes += c.nearCubes;
        boxCubes += c.boxCubes;
        triangles += c.triangles;
        for (int k = 0; k < 4; ++k)
            byKind[k] += c.byKind[k];
    }
};

// The vertices of cubes [begin, end): culled when wholly behind the near plane or beside the view; at the
// near plane (or with exact thickness) the back faces in clip space with the box as attributes; else the
// class's fans with the thickness (or, linear opacity, the opacity) at every vertex.
void projectCubes(const ProjectionContext& c, const cubefan::Cube* begin, const cubefan::Cube* end, ProjectedChunk& out)
{
    out.runCount = 0;
    out.culled = out.nearCubes = out.boxCubes = out.triangles = 0;
    out.byKind = {};
    auto run = [&](bool box) -> std::vector<raster::Vertex>& {
        if (out.runCount == 0 || out.runs[out.runCount - 1].box != box) {
            if (out.runs.size() == out.runCount)
                out.runs.emplace_back();
            out.runs[out.runCount].box = box;
            out.runs[out.runCount].vertices.clear();
            ++out.runCount;
        }
        return out.runs[out.runCount - 1].vertices;
    };
    const bool linear = c.options.opacity == CubefanOptions::Opacity::Linear;
    for (const cubefan::Cube* cube = begin; cube != end; ++cube) {
        std::array<glm::dvec4, 8> clip;
        std::array<glm::dvec2, 8> ndc;
        int behind = 0, out4[4] = {0, 0, 0, 0};
        for (int v = 0; v < 8; ++v) {
            const glm::dvec3 p = cornerOf(cube->lo, cube->hi, v);
            clip[v] = c.view.viewProjection * glm::dvec4(p, 1.0);
            behind += glm::dot(p - c.eye, c.forward) <= c.nearZ ? 1 : 0;
            out4[0] += clip[v].x > clip[v].w;
            out4[1] += clip[v].x < -clip[v].w;
            out4[2] += clip[v].y > clip[v].w;
            out4[3] += clip[v].y < -clip[v].w;
        }
        if (behind == 8 || (behind == 0 && (out4[0] == 8 || out4[1] == 8 || out4[2] == 8 || out4[3] == 8))) {
            ++out.culled;  // wholly behind the near plane, or beside the view
            continue;
        }
        cubefan::ProjectedCube projected;
        if (behind == 0 && !c.options.exactThickness) {
            for (int v = 0; v < 8; ++v)  // float, as the raster stage takes them: neighbours share the bits
                ndc[v] = glm::dvec2(glm::vec2(static_cast<float>(clip[v].x / clip[v].w), static_cast<float>(clip[v].y / clip[v].w)));
            projected = cubefan::projectCube(c.view, cube->lo, cube->hi, ndc);
        }
        if (projected.triangleCount == 0) {
            // At the near plane (or holding the eye), or exact thickness: its back faces in clip space, the
            // chord per fragment. Every ray through the cube in front of the eye leaves it by one back face.
            out.nearCubes += behind > 0 ? 1 : 0;
            ++out.boxCubes;
            std::vector<raster::Vertex>& vertices = run(true);
            raster::Vertex vertex;
            vertex.attributes[0] = glm::vec4(0.0f, cube->value, 0.0f, 0.0f);
            vertex.attributes[1] = glm::vec4(glm::vec3(cube->lo - c.shift), 0.0f);
            vertex.attributes[2] = glm::vec4(glm::vec3(cube->hi - c.shift), 0.0f);
            for (int f = 0; f < 6; ++f) {
                const int axis = f / 2;
                const double normal = (f & 1) ? 1.0 : -1.0;  // outward along the axis
                const double plane = (f & 1) ? cube->hi[axis] : cube->lo[axis];
                const double towardsEye = c.parallel ? -c.forward[axis] * normal : (c.eye[axis] - plane) * normal;
                if (towardsEye > 0.0)
                    continue;  // a front face
                const int* q = kFaceCorners[f];
                for (const int k : {q[0], q[1], q[2], q[0], q[2], q[3]}) {
                    vertex.position = glm::vec4(clip[k]);
                    vertices.push_back(vertex);
                }
                out.triangles += 2;
            }
            continue;
        }
        ++out.byKind[static_cast<int>(projected.kind)];
        std::vector<raster::Vertex>& vertices = run(false);
        const double tau = linear ? (*c.tf)(cube->value).a : 0.0;
        std::array<glm::vec4, 10> position, attribute;
        for (int i = 0; i < projected.vertexCount; ++i) {
            position[i] = glm::vec4(static_cast<float>(projected.ndc[i].x), static_cast<float>(projected.ndc[i].y), 0.0f, 1.0f);
            const double l = projected.thickness[i];
            attribute[i] = glm::vec4(static_cast<float>(linear ? -std::expm1(-tau * l) : l / c.lMax), cube->value, 0.0f, 0.0f);
        }
        raster::Vertex vertex;
        for (int k = 0; k < projected.triangleCount; ++k)
            for (const int i : projected.triangles[k]) {
                vertex.position = position[i];
                vertex.attributes[0] = attribute[i];
                vertices.push_back(vertex);
            }
        out.triangles += projected.triangleCount;
    }
}

class CubefanRenderer final : public Renderer {
public:
    CubefanRenderer(Device& device, const Scene& scene, const Volume& volume);
    Image4f render(FrameStats& stats) override
    {
        using Path = CubefanOptions::Path;
        Image4f image = options_.path == Path::Fused   ? renderFused(stats)
                        : options_.path == Path::Tiles ? renderTiles(stats)
                                                       : renderRaster(stats);
        stats.extra["path"] = pathName(options_.path);
        stats.extra["error"] = options_.error;
        stats.extra["hierarchy_ms"] = hierarchyMs_;
        stats.extra["hierarchy_levels"] = octree_->levels();
        stats.extra["resident_bytes"] = residentBytes_;
        return image;
    }
    std::uint64_t residentBytes() const override { return residentBytes_; }
    void setTransferFunction(const TransferFunction& tf) override
    {
        tfHost_ = tf;
        tf_.replace(device_, "cubefan transfer function", tf, residentBytes_);
        textureK_ = -1.0;  // tau_max may have changed
        gridCurrent_ = false;  // which cubes are transparent may have changed
    }
    // Both paths work from camera_ every frame (the raster path selects and projects per frame; the fused path's
    // selection grid does not depend on the view): a new view is a new camera.
    bool setCamera(const Scene& scene) override
    {
        if (!sameImageSize(scene.image, image_))
            return false;  // the frame buffer and the per-pixel counts would change
        image_ = scene.image;
        camera_ = frameCamera(scene, volumeLo_, volumeHi_);
        return true;
    }

private:
    Image4f renderRaster(FrameStats& stats);
    Image4f renderFused(FrameStats& stats);
    Image4f renderTiles(FrameStats& stats);
    // The fused and tile paths' kernel parameters for the current camera (the walk adds its filled box).
    ClCubefanFusedParams kernelParams() const
    {
        ClCubefanFusedParams p{};
        p.camera = toClCamera(camera_, image_.width, image_.height, shift_);
        p.field_lo = toCl4(lo_ - shift_, 0.0);
        p.inv_spacing = toCl4(1.0 / spacing_, 0.0);
        p.background = toCl4(glm::dvec3(image_.background), 0.0);
        p.dims = cl_int4{{dims_.x, dims_.y, dims_.z, 0}};
        p.width = image_.width;
        p.height = image_.height;
        p.tf_count = static_cast<cl_int>(tf_.count());
        p.ert_alpha = options_.earlyTermination < 1.0 ? static_cast<float>(options_.earlyTermination) : 2.0f;
        return p;
    }
    // What the fused and tile paths report of their selection (built this frame in selectionMs, else 0) and chords.
    void reportSelection(FrameStats& stats, double selectionMs, std::uint64_t crossed) const
    {
        stats.samples = crossed;
        stats.extra["selection_ms"] = selectionMs;
        stats.extra["selection_grid_ms"] = gridMs_;
        stats.extra["selection_visited"] = gridStats_.visited;
        stats.extra["packets"] = packet_;
        stats.extra["cubes"] = gridStats_.selected;
        stats.extra["cubes_transparent"] = gridStats_.transparent;
        stats.extra["cubes_crossed"] = crossed;
    }
    void updateTexture(double k);
    double updateSelectionGrid();
    double updateSelectionTree();

    Device& device_;
    CubefanOptions options_;
    Camera camera_;
    ImageSpec image_;
    glm::dvec3 shift_{0.0}, lo_{0.0}, hi_{0.0};  // the cube field's box
    glm::dvec3 volumeLo_{0.0}, volumeHi_{0.0};     // the volume's bounds, which frame the camera
    TransferFunction tfHost_;
    TransferFunctionUpload tf_;
    std::unique_ptr<cubefan::CubeOctree> octree_;
    double hierarchyMs_ = 0.0;
    cl::Buffer texture_;
    std::uint64_t textureBytes_ = 0;
    double textureK_ = -1.0;  // the k of the texture on the device; < 0: none yet
    double textureMs_ = 0.0;
    raster::Rasterizer rasterizer_;
    raster::Framebuffer fb_;
    raster::FragmentProgram fan_, box_;
    std::optional<OverBackground> overBackground_;  // the raster path's last pass (the fused kernel adds the background)
    std::array<ProjectedChunk, 2> chunks_;  // the chunk being drawn and the next; kept: pages touched once
    // The fused path: the selection as a grid over the voxels (level and value per voxel, on the device),
    // current for options_.error and tfHost_ when gridCurrent_, and the kernel's per-pixel counts.
    glm::ivec3 dims_{0};
    glm::dvec3 spacing_{1.0};
    cl::Kernel fused_;
    bool packet_ = false;  // fused_ is cubefan_fused_packet
    cl::Buffer gridLevel_, gridValue_, gridSpace_, fusedSteps_, fusedSkipped_;
    bool gridCurrent_ = false;  // the selection grid, or on the tile path the selection tree and its cubes
    // The tile path: the selection as a tree (the order per view), its cubes on the device (3 float4 each: low
    // corner and value, high corner, in the selection grid's coordinates; color and extinction) and their boxes, the
    // frame's order and tile lists.
    cubefan::CubeOctree::SelectionTree tree_;
    cl::Buffer tileCubes_, tileBoxesOut_;
    std::uint64_t tileCubeBytes_ = 0;
    cl::Kernel cubeColors_, cubeBoxes_;
    std::vector<std::uint32_t> order_;
    StagingBuffer tileStart_, tileItems_;
    cubefan::SelectionStats gridStats_;
    std::uint64_t gridEmptyBricks_ = 0;  // bricks of 4^3 voxels with nothing to add
    double gridMs_ = 0.0;                // the last build of the grid (selection, empty space, upload)
    glm::ivec3 filledLo_{0}, filledHi_{0};  // voxels [lo, hi) hold every cube that adds color
    std::uint64_t residentBytes_ = 0;
};

CubefanRenderer::CubefanRenderer(Device& device, const Scene& scene, const Volume& volume)
    : device_(device), options_(parseCubefanOptions(scene.options)), image_(scene.image),
      tfHost_(scene.transferFunction), rasterizer_(device), fb_(device, scene.image.width, scene.image.height)
{
    checkGridVolume(volume, "cubefan");
    if (volume.part)
        throw InputError(volume.source + ": cubefan renders whole volumes only (no sort-last parts)");
    volumeLo_ = volume.boundsMin();
    volumeHi_ = volume.boundsMax();
    camera_ = frameCamera(scene, volumeLo_, volumeHi_);
    cubefan::cubeFieldBounds(volume, lo_, hi_);
    shift_ = 0.5 * (lo_ + hi_);
    // The octree holds mean, min and max per cube of every level (8/7 of the voxels): 12 bytes a voxel
    // and a seventh more, beside the volume's own 4.
    const std::uint64_t voxels = volume.voxelCount();
    checkHostMemory(volume.source + ": cubefan's octree", voxels * 12 + voxels * 12 / 7 + voxels * 4);
    const auto t0 = std::chrono::steady_clock::now();
    octree_ = std::make_unique<cubefan::CubeOctree>(volume);
    hierarchyMs_ = msSince(t0);
    tf_.upload(device_, "cubefan transfer function", tfHost_);
    residentBytes_ = tf_.bytes();
    dims_ = volume.dims;
    spacing_ = volume.spacing;
    if (options_.path == CubefanOptions::Path::Fused) {
        // The selection grid: a level byte and a float value per voxel, on the host while it is built.
        // Bricks of 4^3 (cube_octree.h): the dims rounded up to multiples of 4.
        const glm::u64vec3 padded = glm::u64vec3((volume.dims + 3) / 4) * std::uint64_t(4);
        const std::uint64_t entries = padded.x * padded.y * padded.z;
        checkHostMemory(volume.source + ": cubefan's selection grid", entries * 5);
        gridLevel_ = device_.buffer("cubefan selection grid (levels)", entries, CL_MEM_READ_ONLY);
        gridValue_ = device_.buffer("cubefan selection grid (values)", entries * sizeof(float), CL_MEM_READ_ONLY);
        gridSpace_ = device_.buffer("cubefan selection grid (empty space)", entries / 64, CL_MEM_READ_ONLY);
        residentBytes_ += entries * 5 + entries / 64;
        const std::size_t pixels = static_cast<std::size_t>(image_.width) * image_.height;
        fusedSteps_ = device_.buffer("cubefan cubes crossed per pixel", pixels * sizeof(cl_uint), CL_MEM_WRITE_ONLY);
        fusedSkipped_ = device_.buffer("cubefan cubes stepped over per pixel", pixels * sizeof(cl_uint), CL_MEM_WRITE_ONLY);
        // Ray packets (docs/cubefan.md): the same walk on 8 pixels at once, its entries indexed in 32 bits.
        packet_ = packetsOnDevice(options_.packets, device_) && entries <= 0xffffffffu;
        fused_ = device_.kernel("cubefan.cl", packet_ ? "cubefan_fused_packet" : "cubefan_fused");
        return;
    }
    if (options_.path == CubefanOptions::Path::Tiles) {
        if (image_.width > kTileImageMax || image_.height > kTileImageMax)
            throw InputError("cubefan: \"path\": \"tiles\" takes images of at most " + std::to_string(kTileImageMax) +
                             " pixels a side, got " + std::to_string(image_.width) + "x" + std::to_string(image_.height));
        const std::size_t pixels = static_cast<std::size_t>(image_.width) * image_.height;
        fusedSteps_ = device_.buffer("cubefan chords per pixel", pixels * sizeof(cl_uint), CL_MEM_WRITE_ONLY);
        residentBytes_ += pixels * sizeof(cl_uint);
        packet_ = packetsOnDevice(options_.packets, device_);  // a tile per work-item, its rows as vectors
        fused_ = device_.kernel("cubefan.cl", packet_ ? "cubefan_tiles_packet" : "cubefan_tiles");
        cubeColors_ = device_.kernel("cubefan.cl", "cubefan_cube_colors");
        cubeBoxes_ = device_.kernel("cubefan.cl", "cubefan_cube_boxes");
        return;
    }
    overBackground_.emplace(device_);
    fan_.source = programSource("CLVR_CUBEFAN_FAN");
    fan_.attributes = 1;  // (l / l_max or alpha, value)
    box_.source = programSource("CLVR_CUBEFAN_BOX");
    box_.attributes = 3;  // (0, value), lo, hi
}

void CubefanRenderer::updateTexture(double k)
{
    if (k == textureK_)
        return;
    const auto t0 = std::chrono::steady_clock::now();
    const std::vector<float> texels = expOpacityTexels(options_.textureSize, k);
    residentBytes_ -= textureBytes_;
    texture_ = device_.upload("cubefan exp-opacity texture", texels);
    textureBytes_ = texels.size() * sizeof(float);
    residentBytes_ += textureBytes_;
    textureK_ = k;
    textureMs_ = msSince(t0);
}

// Builds the selection grid for the current tolerance and transfer function and uploads it; returns its
// milliseconds (0 when it was current).
double CubefanRenderer::updateSelectionGrid()
{
    if (gridCurrent_)
        return 0.0;
    const auto t0 = std::chrono::steady_clock::now();
    const CubefanWalkGrid walk = buildCubefanWalkGrid(*octree_, dims_, options_.error, tfHost_, &gridStats_);
    const cubefan::CubeOctree::SelectionGrid& grid = walk.grid;
    const std::vector<std::uint8_t>& space = walk.space;
    gridEmptyBricks_ = walk.emptyBricks;
    filledLo_ = walk.filledLo;
    filledHi_ = walk.filledHi;
    device_.queue().enqueueWriteBuffer(gridLevel_, CL_FALSE, 0, grid.level.size(), grid.level.data());
    device_.queue().enqueueWriteBuffer(gridSpace_, CL_FALSE, 0, space.size(), space.data());
    device_.queue().enqueueWriteBuffer(gridValue_, CL_TRUE, 0, grid.value.size() * sizeof(float), grid.value.data());
    gridCurrent_ = true;
    gridMs_ = msSince(t0);
    return gridMs_;
}

// The fused path: cubefan_fused walks every pixel's ray through the selected cubes (kernels/cubefan.cl).
Image4f CubefanRenderer::renderFused(FrameStats& stats)
{
    const FrameClock clock;
    const double gridMs = updateSelectionGrid();
    ClCubefanFusedParams p = kernelParams();
    p.filled_lo = cl_int4{{filledLo_.x, filledLo_.y, filledLo_.z, 0}};
    p.filled_hi = cl_int4{{filledHi_.x, filledHi_.y, filledHi_.z, 0}};
    int a = 0;
    fused_.setArg(a++, fb_.color());
    fused_.setArg(a++, fusedSteps_);
    fused_.setArg(a++, fusedSkipped_);
    fused_.setArg(a++, gridLevel_);
    fused_.setArg(a++, gridValue_);
    fused_.setArg(a++, gridSpace_);
    fused_.setArg(a++, tf_.buffer());
    fused_.setArg(a++, p);
    device_.launch("cubefan: fused cube walk", fused_, rowWorkItems(image_.width, packet_), image_.height);
    const std::size_t pixels = static_cast<std::size_t>(image_.width) * image_.height;
    std::uint64_t crossed = 0, steppedOver = 0;
    for (const cl_uint n : device_.download<cl_uint>(fusedSteps_, pixels))
        crossed += n;
    for (const cl_uint n : device_.download<cl_uint>(fusedSkipped_, pixels))
        steppedOver += n;
    Image4f image = readImage(device_, fb_.color(), image_.width, image_.height);
    std::vector<PassTime> hostPasses;
    if (gridMs > 0.0)
        hostPasses.push_back({"cubefan: selection grid (host, when the tolerance or transfer function changes)", gridMs});
    finishFrame(device_, clock, stats, std::move(hostPasses));
    reportSelection(stats, gridMs, crossed);
    stats.extra["cubes_stepped_over"] = steppedOver;
    stats.extra["empty_bricks"] = gridEmptyBricks_;
    stats.extra["early_termination"] = options_.earlyTermination;
    return image;
}

// Builds the tile path's selection tree for the current tolerance and transfer function, uploads its cubes and has
// their colors computed; returns its milliseconds (0 when it was current).
double CubefanRenderer::updateSelectionTree()
{
    if (gridCurrent_)
        return 0.0;
    const auto t0 = std::chrono::steady_clock::now();
    tree_ = octree_->selectTree(options_.error, tfHost_, &gridStats_);
    const std::size_t n = tree_.cubes.size();
    if (n >= (std::size_t(1) << 30))  // the kernels index 3 float4 per cube in 32 bits
        throw InputError("cubefan: \"path\": \"tiles\" takes fewer than 2^30 cubes, the selection has " +
                         std::to_string(n) + "; use \"path\": \"fused\" or a larger error");
    checkHostMemory("cubefan's tile path (" + std::to_string(n) + " cubes)", n * 3 * sizeof(cl_float4));
    std::vector<cl_float4> cubes(3 * n);
    for (std::size_t i = 0; i < n; ++i) {
        const cubefan::Cube& c = tree_.cubes[i];
        const glm::ivec3 lo = c.index * (1 << c.level), hi = glm::min(lo + (1 << c.level), dims_);
        cubes[3 * i] = cl_float4{{static_cast<float>(lo.x), static_cast<float>(lo.y), static_cast<float>(lo.z), c.value}};
        cubes[3 * i + 1] = cl_float4{{static_cast<float>(hi.x), static_cast<float>(hi.y), static_cast<float>(hi.z), 0.0f}};
    }
    residentBytes_ -= tileCubeBytes_;
    tileCubes_ = device_.upload("cubefan tile path cubes", cubes.empty() ? std::vector<cl_float4>(3) : cubes,
                                CL_MEM_READ_WRITE);
    tileBoxesOut_ = device_.buffer("cubefan tile path cube boxes", std::max<std::size_t>(n, 1) * sizeof(cl_short4));
    tileCubeBytes_ = std::max<std::size_t>(3 * n, 3) * sizeof(cl_float4) + std::max<std::size_t>(n, 1) * sizeof(cl_short4);
    residentBytes_ += tileCubeBytes_;
    if (n > 0) {  // each cube's color (the transfer function on the device, as the walk evaluates it)
        int a = 0;
        cubeColors_.setArg(a++, tileCubes_);
        cubeColors_.setArg(a++, tf_.buffer());
        cubeColors_.setArg(a++, static_cast<cl_int>(tf_.count()));
        cubeColors_.setArg(a++, static_cast<cl_uint>(n));
        device_.launch("cubefan: cube colors", cubeColors_, n);
    }
    gridCurrent_ = true;
    gridMs_ = msSince(t0);
    return gridMs_;
}

// The tile path: the selection as a tree (when the tolerance or transfer function changed), its cubes ordered front to
// back for the eye, boxed and binned to tiles on the host's threads, then cubefan_tiles (or its packets) over the image.
Image4f CubefanRenderer::renderTiles(FrameStats& stats)
{
    const FrameClock clock;
    std::vector<PassTime> hostPasses;
    const double selectionMs = updateSelectionTree();
    if (selectionMs > 0.0)
        hostPasses.push_back({"cubefan: selection tree (host, when the tolerance or transfer function changes)", selectionMs});
    const int width = image_.width, height = image_.height;
    const ClCubefanFusedParams p = kernelParams();
    // The cubes' boxes on the device while the host orders the cubes for the eye; then the boxes read back and the
    // cubes binned to tiles in that order.
    const std::size_t n = tree_.cubes.size();
    const auto t1 = std::chrono::steady_clock::now();
    if (n > 0) {
        int a = 0;
        cubeBoxes_.setArg(a++, tileCubes_);
        cubeBoxes_.setArg(a++, tileBoxesOut_);
        cubeBoxes_.setArg(a++, p);
        cubeBoxes_.setArg(a++, static_cast<cl_uint>(n));
        device_.launch("cubefan: cube boxes", cubeBoxes_, (n + 7) / 8);  // 8 cubes per work-item
        device_.queue().flush();
    }
    tree_.frontToBack(camera_.position, camera_.forward(), camera_.parallel, order_);
    std::vector<PixelBox> boxes(n);
    if (n > 0)
        device_.queue().enqueueReadBuffer(tileBoxesOut_, CL_TRUE, 0, n * sizeof(PixelBox), boxes.data());
    const TileLists lists = binToTiles(boxes, order_, width, height, kCubefanTileW, kCubefanTileH,
                                       "cubefan: \"path\": \"tiles\"", "use \"path\": \"fused\" or a smaller image");
    static_assert(sizeof(PixelBox) == sizeof(cl_short4));
    tileStart_.write(device_, "cubefan tile starts", lists.start.data(), lists.start.size() * sizeof(cl_uint), residentBytes_);
    tileItems_.write(device_, "cubefan tile cubes", lists.items.data(), lists.items.size() * sizeof(cl_uint), residentBytes_);
    hostPasses.push_back({"cubefan: order and tile lists (host, beside the cube boxes)", msSince(t1)});

    int a = 0;
    fused_.setArg(a++, fb_.color());
    fused_.setArg(a++, fusedSteps_);
    fused_.setArg(a++, tileStart_.buffer());
    fused_.setArg(a++, tileItems_.buffer());
    fused_.setArg(a++, tileBoxesOut_);
    fused_.setArg(a++, tileCubes_);
    fused_.setArg(a++, p);
    fused_.setArg(a++, static_cast<cl_int>(lists.tilesX));
    if (packet_)  // a work-item per tile
        device_.launch("cubefan: tiles", fused_, static_cast<std::size_t>(lists.tilesX),
                       static_cast<std::size_t>(lists.tilesY), 1, 1);
    else
        device_.launch("cubefan: tiles", fused_, static_cast<std::size_t>(width), static_cast<std::size_t>(height),
                       kCubefanTileW, kCubefanTileH);
    const std::uint64_t crossed = sumCounts(device_, fusedSteps_, static_cast<std::size_t>(width) * height);
    Image4f image = readImage(device_, fb_.color(), width, height);
    finishFrame(device_, clock, stats, std::move(hostPasses));
    reportSelection(stats, selectionMs, crossed);
    stats.extra["tile_entries"] = lists.items.size();
    stats.extra["tile_size"] = {kCubefanTileW, kCubefanTileH};
    stats.extra["early_termination"] = options_.earlyTermination;
    return image;
}

// The raster path: the selected cubes projected as fans (or back faces) through the raster stage.
Image4f CubefanRenderer::renderRaster(FrameStats& stats)
{
    const FrameClock clock;
    const glm::dvec3 eye = camera_.position, forward = camera_.forward();

    // Selection (§6): the cubes within the tolerance, back to front, transparent ones skipped.
    auto t0 = std::chrono::steady_clock::now();
    cubefan::SelectionStats selection;
    const std::vector<cubefan::Cube> cubes =
        octree_->select(options_.error, tfHost_, eye, forward, camera_.parallel, &selection);
    const double selectionMs = msSince(t0);

    // The texture's axes: u = l / l_max over the selected cubes' longest chord, v = tau / tau_max.
    const double lMax = std::max(selection.largestDiagonal, 1e-30);
    const double tauMax = std::max(maxExtinction(tfHost_), 1e-30);
    textureMs_ = 0.0;
    if (options_.opacity == CubefanOptions::Opacity::Texture && !options_.exactThickness)
        updateTexture(lMax * tauMax);

    // The projection: eye depth of the field's box sets the clip planes; a cube with a corner at or
    // behind the near plane is drawn as its back faces in clip space (the raster stage clips them).
    double depthMax = 0.0;
    for (int v = 0; v < 8; ++v)
        depthMax = std::max(depthMax, glm::dot(cornerOf(lo_, hi_, v) - eye, forward));
    const double nearZ = 1e-4 * depthMax + 1e-9;
    const double farZ = 2.0 * depthMax + 1.0;
    cubefan::CubeView view;
    view.viewProjection = camera_.projectionMatrix(image_.width, image_.height, nearZ, farZ) * camera_.viewMatrix();
    view.eye = eye;
    view.forward = forward;
    view.parallel = camera_.parallel;

    raster::DrawState state;
    state.fragment.blend = raster::premultipliedOver();  // back to front: dst = src + (1 - src.alpha) dst
    ClCubefanUniforms uniforms{};
    uniforms.camera = toClCamera(camera_, image_.width, image_.height, shift_);
    const int mode = options_.opacity == CubefanOptions::Opacity::Texture ? CUBEFAN_OPACITY_TEXTURE
                     : options_.opacity == CubefanOptions::Opacity::Exp   ? CUBEFAN_OPACITY_EXP
                                                                          : CUBEFAN_OPACITY_LINEAR;
    uniforms.counts = cl_float4{{static_cast<float>(image_.width), static_cast<float>(image_.height),
                                 static_cast<float>(tf_.count()), static_cast<float>(mode)}};
    uniforms.scale = cl_float4{{static_cast<float>(lMax), static_cast<float>(tauMax),
                                static_cast<float>(options_.textureSize), 0.0f}};
    for (raster::FragmentProgram* p : {&fan_, &box_}) {
        p->uniforms = fragmentUniforms(uniforms);
        p->buffers[1] = tf_.buffer();
        p->buffers[2] = texture_;
    }
    fb_.clearColor(device_, glm::vec4(0.0f));

    // Projection in chunks on a worker thread, one chunk ahead of the drawing (the raster stage's set-up
    // and binning, on this thread): chunk k + 1 is projected while chunk k is drawn. Each chunk is runs of
    // vertices for one program (fans, or back faces), in the cubes' order.
    ProjectionContext context{view, eye, forward, camera_.parallel, options_, shift_, lMax, nearZ, &tfHost_};
    const std::size_t chunkCubes = kBatchVertices / 36;  // a class-1 to -3 cube has at most 36 vertices
    const std::size_t chunkCount = (cubes.size() + chunkCubes - 1) / chunkCubes;
    auto project = [&](std::size_t k) {
        const auto p0 = std::chrono::steady_clock::now();
        const std::size_t begin = k * chunkCubes, end = std::min(cubes.size(), begin + chunkCubes);
        projectCubes(context, cubes.data() + begin, cubes.data() + end, chunks_[k % 2]);
        chunks_[k % 2].ms = msSince(p0);
    };
    const bool threaded = threadBudget() >= 2 && chunkCount > 1;
    double drawMs = 0.0, projectMs = 0.0;
    ProjectedChunk total;
    t0 = std::chrono::steady_clock::now();
    std::future<void> next;
    if (chunkCount > 0)
        next = std::async(threaded ? std::launch::async : std::launch::deferred, project, std::size_t(0));
    for (std::size_t k = 0; k < chunkCount; ++k) {
        next.get();
        if (k + 1 < chunkCount)
            next = std::async(threaded ? std::launch::async : std::launch::deferred, project, k + 1);
        ProjectedChunk& chunk = chunks_[k % 2];
        const auto d0 = std::chrono::steady_clock::now();
        for (std::size_t r = 0; r < chunk.runCount; ++r)
            rasterizer_.draw(fb_, state, raster::Topology::Triangles, chunk.runs[r].vertices,
                             chunk.runs[r].box ? box_ : fan_);
        drawMs += msSince(d0);
        projectMs += chunk.ms;
        total.add(chunk);
    }
    const double loopMs = msSince(t0);

    const std::size_t pixels = static_cast<std::size_t>(image_.width) * image_.height;
    overBackground_->run(fb_.color(), pixels, image_.background, "cubefan: over background");
    Image4f image = readImage(device_, fb_.color(), image_.width, image_.height);
    const raster::DrawStats drawn = rasterizer_.takeStats();

    std::vector<PassTime> hostPasses = {{"cubefan: selection (host)", selectionMs},
                                        {"cubefan: classification and projection (host)", projectMs},
                                        {"cubefan: raster set-up and binning (host)", drawMs}};
    stats.extra["projection_threaded"] = threaded;
    stats.extra["projection_and_drawing_ms"] = loopMs;  // the two above overlapped
    if (textureMs_ > 0.0)
        hostPasses.push_back({"cubefan: exp-opacity texture (host)", textureMs_});
    finishFrame(device_, clock, stats, std::move(hostPasses));
    stats.extra["opacity"] = options_.exactThickness ? "exp" : opacityName(options_.opacity);
    stats.extra["thickness"] = options_.exactThickness ? "exact" : "interpolated";
    stats.extra["cubes_as_back_faces"] = total.boxCubes;
    stats.extra["selection_ms"] = selectionMs;
    stats.extra["selection_visited"] = selection.visited;
    stats.extra["cubes"] = selection.selected;
    stats.extra["cubes_transparent"] = selection.transparent;
    stats.extra["cubes_culled"] = total.culled;
    stats.extra["cubes_near_plane"] = total.nearCubes;
    stats.extra["cubes_class1"] = total.byKind[0];
    stats.extra["cubes_class2"] = total.byKind[1];
    stats.extra["cubes_class3a"] = total.byKind[2];
    stats.extra["cubes_class3b"] = total.byKind[3];
    stats.extra["triangles"] = total.triangles;
    stats.extra["projection_ms"] = projectMs;
    stats.extra["l_max"] = lMax;
    stats.extra["tau_max"] = tauMax;
    if (options_.opacity == CubefanOptions::Opacity::Texture && !options_.exactThickness)
        stats.extra["texture"] = std::to_string(options_.textureSize) + "x" + std::to_string(options_.textureSize);
    stats.extra["raster_triangles"] = drawn.triangles;
    stats.extra["raster_fragments"] = drawn.fragments;
    return image;
}

}  // namespace

TechniqueInfo cubefanTechnique()
{
    TechniqueInfo t;
    t.name = "cubefan";
    t.data = DataKind::Volume;
    t.description = "octree cubes projected as triangle fans with an exp-opacity texture (Schussman-Max, docs/cubefan.md)";
    t.options = {
        {"error", 0.0, "", "error tolerance, a fraction of the data range: cubes merge while every voxel is within it"},
        {"opacity", "texture", "",
         "\"texture\" (the exp-opacity texture of the interpolated thickness), \"exp\" (the exponential per "
         "fragment) or \"linear\" (per-vertex opacity interpolated, Shirley-Tuchman)"},
        {"texture_size", 512, "", "texels per axis of the exp-opacity texture"},
        {"thickness", "interpolated", "",
         "\"interpolated\" (at the fans' vertices, across each triangle: seeds/002 §7) or \"exact\" (each "
         "fragment's own chord through its cube, drawn as back faces)"},
        {"path", "fused", "",
         "\"fused\" (each pixel's ray walks the selected cubes in one kernel, every chord exact), \"tiles\" (the "
         "cubes in the octree's visibility order binned to 8x4-pixel tiles, each tile's rays meeting its cubes in one "
         "kernel, every chord exact; the default where error > 0) or \"raster\" (the paper's triangle fans through "
         "the raster stage); opacity, texture_size or thickness other than their defaults take \"raster\""},
        earlyTerminationInfo(1.0),
        packetsInfo(),
    };
    t.makeForVolume = [](Device& device, const Scene& scene, const Volume& volume) -> std::unique_ptr<Renderer> {
        return makeCubefanRenderer(device, scene, volume);
    };
    return t;
}

CubefanOptions parseCubefanOptions(const nlohmann::json& options)
{
    static const TechniqueInfo& info = technique("cubefan");
    CubefanOptions o;
    forEachOption(options, info, [&](const std::string& key, const nlohmann::json& value) {
        if (key == "error") {
            o.error = numberOption(key, value, [](double x) { return x >= 0.0 && x <= 1.0; }, "a number in [0, 1]");
        } else if (key == "opacity") {
            const std::string s = value.is_string() ? value.get<std::string>() : "";
            if (s == "texture")
                o.opacity = CubefanOptions::Opacity::Texture;
            else if (s == "exp")
                o.opacity = CubefanOptions::Opacity::Exp;
            else if (s == "linear")
                o.opacity = CubefanOptions::Opacity::Linear;
            else
                badOption(key, "must be \"texture\", \"exp\" or \"linear\", got " + value.dump());
        } else if (key == "thickness") {
            const std::string s = value.is_string() ? value.get<std::string>() : "";
            if (s != "interpolated" && s != "exact")
                badOption(key, "must be \"interpolated\" or \"exact\", got " + value.dump());
            o.exactThickness = s == "exact";
        } else if (key == "texture_size") {
            o.textureSize = integerOption(key, value, 2, 4096);
        } else if (key == "path") {
            const CubefanOptions::Path paths[] = {CubefanOptions::Path::Fused, CubefanOptions::Path::Raster,
                                                  CubefanOptions::Path::Tiles};
            o.path = paths[choiceOption(key, value, {"fused", "raster", "tiles"})];
        } else if (key == "early_termination") {
            o.earlyTermination = earlyTerminationOption(value);
        } else if (key == "packets") {
            o.packets = packetsOption(key, value);
        } else {
            unparsedOption(info, key);
        }
    });
    // The fans' options describe the raster path: one away from its default takes it, unless the scene asks
    // for fused (the listed defaults change nothing).
    const CubefanOptions defaults;
    const std::pair<const char*, bool> fans[] = {{"opacity", o.opacity != defaults.opacity},
                                                 {"texture_size", o.textureSize != defaults.textureSize},
                                                 {"thickness", o.exactThickness != defaults.exactThickness}};
    for (const auto& [key, changed] : fans) {
        if (!changed)
            continue;
        if (options.contains("path") && o.path != CubefanOptions::Path::Raster)
            badOption(key, std::string("describes the raster path's triangle fans; the ") + pathName(o.path) +
                               " path computes every chord exactly: give \"path\": \"raster\" or leave path out");
        o.path = CubefanOptions::Path::Raster;
    }
    // Without a path: the tile path where cubes merge (error > 0), the walk for the full-resolution field, where the
    // tile path's per-frame order and lists of every voxel's cube cost more (BENCHMARKS.md run CT1).
    if (!options.contains("path") && o.path == CubefanOptions::Path::Fused && o.error > 0.0)
        o.path = CubefanOptions::Path::Tiles;
    if (o.earlyTermination < 1.0 && o.path == CubefanOptions::Path::Raster)
        badOption("early_termination",
                  "is only available on the fused and tile paths (the blending stage cannot stop a pixel)");
    return o;
}

std::unique_ptr<Renderer> makeCubefanRenderer(Device& device, const Scene& scene, const Volume& volume)
{
    return std::make_unique<CubefanRenderer>(device, scene, volume);
}

}  // namespace clvr
