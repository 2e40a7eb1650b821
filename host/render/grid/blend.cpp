// host/render/grid/blend.cpp — options, set-up and the one launch of the blend technique
// (kernels/blend.cl: blend_render).
#include "host/render/grid/blend.h"

#include "host/runtime/errors.h"
#include "host/render/camera_args.h"
#include "host/render/options_util.h"
#include "host/optics/gradient_volume.h"
#include "host/optics/reflectance_map.h"
#include "host/render/grid/slice3d.h"  // planSlices, packTransferFunction

#include <chrono>
#include <cmath>
#include <numeric>

namespace clvr {
namespace {

constexpr int kMaxSlices = 65536;
constexpr int kMaxMapSize = 1024;
constexpr const char* kKnownOptions = "slices, slice_spacing, opacity_threshold, reflectance_map_size";

class BlendRenderer final : public Renderer {
public:
    BlendRenderer(Device& device, const Scene& scene, const Volume& volume);
    Image4f render(FrameStats& stats) override;
    std::uint64_t residentBytes() const override { return residentBytes_; }
    void setTransferFunction(const TransferFunction& tf) override;

private:
    Device& device_;
    BlendOptions options_;
    Camera camera_;
    ImageSpec image_;
    glm::ivec3 dims_;
    glm::dvec3 origin_, spacing_;
    Lighting lighting_;
    SlicePlan plan_;
    int tfCount_ = 0;
    std::size_t tfBytes_ = 0;
    cl::Buffer volume_, tf_, map_, out_, samples_, skipped_;
    cl::Kernel kernel_;
    std::uint64_t residentBytes_ = 0;
};

BlendRenderer::BlendRenderer(Device& device, const Scene& scene, const Volume& volume)
    : device_(device), options_(parseBlendOptions(scene.options)), image_(scene.image), lighting_(sceneLighting(scene))
{
    volume.validate();
    if (volume.voxelCount() > 0xffffffffull)
        throw InputError(volume.source + ": blend takes at most 2^32 - 1 grid points (32-bit voxel indices)");
    dims_ = volume.dims;
    origin_ = volume.origin;
    spacing_ = volume.spacing;
    camera_ = scene.camera ? *scene.camera : fitCamera(volume.boundsMin(), volume.boundsMax());
    camera_.validate();
    if (image_.width < 1 || image_.height < 1)
        throw InputError("image: width and height must be >= 1");
    Slice3dOptions sliceOptions;  // the same slab planning as slice3d
    sliceOptions.slices = options_.slices;
    sliceOptions.sliceSpacing = options_.sliceSpacing;
    plan_ = planSlices(camera_, volume.boundsMin(), volume.boundsMax(), sliceOptions);

    const std::vector<glm::vec4> rgba = sobelGradientVolume(volume);
    volume_ = device_.upload("blend RGBA volume (gradient, value; float32)", rgba);
    const ReflectanceMap map = buildReflectanceMap(lighting_, -camera_.forward(), options_.reflectanceMapSize);
    map_ = device_.upload("blend reflectance map", map.entries);
    residentBytes_ = (rgba.size() + map.entries.size()) * sizeof(glm::vec4);
    setTransferFunction(scene.transferFunction);

    const std::size_t pixels = static_cast<std::size_t>(image_.width) * image_.height;
    kernel_ = device_.kernel("blend.cl", "blend_render");
    out_ = device_.buffer("blend image", pixels * sizeof(cl_float4), CL_MEM_WRITE_ONLY);
    samples_ = device_.buffer("blend sample counts", pixels * sizeof(cl_uint), CL_MEM_WRITE_ONLY);
    skipped_ = device_.buffer("blend skipped sample counts", pixels * sizeof(cl_uint), CL_MEM_WRITE_ONLY);
}

void BlendRenderer::setTransferFunction(const TransferFunction& tf)
{
    const std::vector<float> packed = packTransferFunction(tf);
    residentBytes_ -= tfBytes_;
    tfBytes_ = packed.size() * sizeof(float);
    residentBytes_ += tfBytes_;
    tfCount_ = static_cast<int>(tf.points().size());
    tf_ = device_.upload("blend transfer function", packed);
}

Image4f BlendRenderer::render(FrameStats& stats)
{
    const auto start = std::chrono::steady_clock::now();
    int a = 0;
    kernel_.setArg(a++, out_);
    kernel_.setArg(a++, samples_);
    kernel_.setArg(a++, skipped_);
    kernel_.setArg(a++, static_cast<cl_int>(image_.width));
    kernel_.setArg(a++, static_cast<cl_int>(image_.height));
    kernel_.setArg(a++, volume_);
    kernel_.setArg(a++, cl_int4{{dims_.x, dims_.y, dims_.z, 0}});
    kernel_.setArg(a++, toCl4(origin_));
    kernel_.setArg(a++, toCl4(1.0 / spacing_));
    kernel_.setArg(a++, tf_);
    kernel_.setArg(a++, static_cast<cl_int>(tfCount_));
    kernel_.setArg(a++, map_);
    kernel_.setArg(a++, static_cast<cl_int>(options_.reflectanceMapSize));
    kernel_.setArg(a++, static_cast<cl_int>(lighting_.shaded() ? 1 : 0));
    kernel_.setArg(a++, toCl4(-camera_.forward()));
    a = setCameraArgs(kernel_, a, camera_, image_.width, image_.height);
    kernel_.setArg(a++, static_cast<cl_float>(plan_.depthMin));
    kernel_.setArg(a++, static_cast<cl_float>(plan_.deltaS));
    kernel_.setArg(a++, static_cast<cl_int>(plan_.count));
    kernel_.setArg(a++, static_cast<cl_float>(options_.opacityThreshold));
    kernel_.setArg(a++, cl_float4{{static_cast<float>(image_.background.r), static_cast<float>(image_.background.g),
                                   static_cast<float>(image_.background.b), 0.0f}});
    device_.launch("blend: shade slices, blend back to front", kernel_, image_.width, image_.height);

    const std::size_t pixels = static_cast<std::size_t>(image_.width) * image_.height;
    Image4f image(image_.width, image_.height);
    device_.queue().enqueueReadBuffer(out_, CL_TRUE, 0, pixels * sizeof(glm::vec4), image.pixels().data());
    const std::vector<cl_uint> counts = device_.download<cl_uint>(samples_, pixels);
    const std::vector<cl_uint> skipped = device_.download<cl_uint>(skipped_, pixels);
    stats.passes = device_.takePassTimes();
    stats.frameMs = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
    stats.samples = std::accumulate(counts.begin(), counts.end(), std::uint64_t(0));
    const std::uint64_t below = std::accumulate(skipped.begin(), skipped.end(), std::uint64_t(0));
    stats.extra["samples_shaded"] = stats.samples - below;
    stats.extra["samples_below_threshold"] = below;
    stats.extra["slices"] = plan_.count;
    stats.extra["slice_spacing"] = plan_.deltaS;
    stats.extra["opacity_threshold"] = options_.opacityThreshold;
    stats.extra["reflectance_map_size"] = options_.reflectanceMapSize;
    stats.extra["shaded"] = lighting_.shaded();
    stats.extra["voxels"] = static_cast<std::uint64_t>(dims_.x) * dims_.y * dims_.z;
    stats.extra["resident_bytes"] = residentBytes_;
    return image;
}

}  // namespace

BlendOptions parseBlendOptions(const nlohmann::json& options)
{
    BlendOptions o;
    forEachOption(options, [&](const std::string& key, const nlohmann::json& value) {
        if (key == "slices")
            o.slices = integerOption(key, value, 1, kMaxSlices);
        else if (key == "slice_spacing")
            o.sliceSpacing = numberOption(key, value, [](double x) { return x > 0.0; }, "a positive number (world units)");
        else if (key == "opacity_threshold")
            o.opacityThreshold = numberOption(key, value, [](double x) { return x >= 0.0 && x < 1.0; },
                                              "an opacity in [0, 1) (0 = skip only transparent samples)");
        else if (key == "reflectance_map_size")
            o.reflectanceMapSize = integerOption(key, value, 1, kMaxMapSize);
        else
            badOption(key, std::string("unknown option for blend (known: ") + kKnownOptions + ")");
    });
    if (options.contains("slices") && options.contains("slice_spacing"))
        badOption("slice_spacing", "give either slices or slice_spacing, not both");
    return o;
}

std::unique_ptr<Renderer> makeBlendRenderer(Device& device, const Scene& scene, const Volume& volume)
{
    return std::make_unique<BlendRenderer>(device, scene, volume);
}

}  // namespace clvr
