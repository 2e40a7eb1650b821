// host/render/grid/planes.cpp — options, set-up (RGBA volume, reflectance map, transfer function on the device)
// and the one launch of the planes technique (kernels/planes.cl: planes_render).
#include "host/render/grid/planes.h"

#include "host/runtime/errors.h"
#include "host/render/camera_args.h"
#include "host/render/options_util.h"
#include "host/optics/gradient_volume.h"
#include "host/optics/reflectance_map.h"
#include "host/render/grid/slice3d.h"  // packTransferFunction: the layout kernels/transfer_function.h reads

#include <algorithm>
#include <chrono>
#include <cmath>
#include <numeric>

namespace clvr {
namespace {

constexpr int kMaxMapSize = 1024;        // 6 * 1024^2 entries * 16 bytes = 96 MiB
constexpr double kMaxSamplesPerRay = 1 << 20;
constexpr const char* kKnownOptions = "sample_spacing, early_termination, opacity_threshold, reflectance_map_size";

class PlanesRenderer final : public Renderer {
public:
    PlanesRenderer(Device& device, const Scene& scene, const Volume& volume);
    Image4f render(FrameStats& stats) override;
    std::uint64_t residentBytes() const override { return residentBytes_; }
    void setTransferFunction(const TransferFunction& tf) override;

private:
    Device& device_;
    PlanesOptions options_;
    Camera camera_;
    ImageSpec image_;
    glm::ivec3 dims_;
    glm::dvec3 origin_, spacing_, lo_, hi_;
    Lighting lighting_;
    glm::dvec3 toEye_;
    int tfCount_ = 0;
    std::size_t tfBytes_ = 0;
    double gradientMs_ = 0.0, mapMs_ = 0.0;
    cl::Buffer volume_, tf_, map_;
    cl::Buffer out_, samples_, skipped_, terminated_;
    cl::Kernel kernel_;
    std::uint64_t residentBytes_ = 0;
};

PlanesRenderer::PlanesRenderer(Device& device, const Scene& scene, const Volume& volume)
    : device_(device), options_(parsePlanesOptions(scene.options)), image_(scene.image),
      lighting_(sceneLighting(scene))
{
    volume.validate();
    if (volume.voxelCount() > 0xffffffffull)
        throw InputError(volume.source + ": planes takes at most 2^32 - 1 grid points (32-bit voxel indices)");
    dims_ = volume.dims;
    origin_ = volume.origin;
    spacing_ = volume.spacing;
    lo_ = volume.boundsMin();
    hi_ = volume.boundsMax();
    camera_ = scene.camera ? *scene.camera : fitCamera(lo_, hi_);
    camera_.validate();
    if (image_.width < 1 || image_.height < 1)
        throw InputError("image: width and height must be >= 1");
    if (options_.sampleSpacing == 0.0)
        options_.sampleSpacing = 0.5 * std::min({spacing_.x, spacing_.y, spacing_.z});
    if (glm::length(hi_ - lo_) / options_.sampleSpacing > kMaxSamplesPerRay)
        badOption("sample_spacing", "too small for this volume: a ray through the box's diagonal would take over 2^20 samples");
    toEye_ = -camera_.forward();

    // The RGBA volume, once per volume: gradients do not depend on the view (§2.3).
    auto t0 = std::chrono::steady_clock::now();
    const std::vector<glm::vec4> rgba = sobelGradientVolume(volume);
    gradientMs_ = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
    volume_ = device_.upload("planes RGBA volume (gradient, value; float32)", rgba);
    residentBytes_ = rgba.size() * sizeof(glm::vec4);

    // The reflectance map, for these lights and this view direction (rebuilt with either).
    t0 = std::chrono::steady_clock::now();
    const ReflectanceMap map = buildReflectanceMap(lighting_, toEye_, options_.reflectanceMapSize);
    mapMs_ = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
    map_ = device_.upload("planes reflectance map", map.entries);
    residentBytes_ += map.entries.size() * sizeof(glm::vec4);

    setTransferFunction(scene.transferFunction);

    const std::size_t pixels = static_cast<std::size_t>(image_.width) * image_.height;
    kernel_ = device_.kernel("planes.cl", "planes_render");
    out_ = device_.buffer("planes image", pixels * sizeof(cl_float4), CL_MEM_WRITE_ONLY);
    samples_ = device_.buffer("planes sample counts", pixels * sizeof(cl_uint), CL_MEM_WRITE_ONLY);
    skipped_ = device_.buffer("planes skipped sample counts", pixels * sizeof(cl_uint), CL_MEM_WRITE_ONLY);
    terminated_ = device_.buffer("planes terminated-ray flags", pixels, CL_MEM_WRITE_ONLY);
}

void PlanesRenderer::setTransferFunction(const TransferFunction& tf)
{
    // Classification happens per sample on the device: only the control points change.
    const std::vector<float> packed = packTransferFunction(tf);
    residentBytes_ -= tfBytes_;
    tfBytes_ = packed.size() * sizeof(float);
    residentBytes_ += tfBytes_;
    tfCount_ = static_cast<int>(tf.points().size());
    tf_ = device_.upload("planes transfer function", packed);
}

Image4f PlanesRenderer::render(FrameStats& stats)
{
    const auto start = std::chrono::steady_clock::now();
    int a = 0;
    kernel_.setArg(a++, out_);
    kernel_.setArg(a++, samples_);
    kernel_.setArg(a++, skipped_);
    kernel_.setArg(a++, terminated_);
    kernel_.setArg(a++, static_cast<cl_int>(image_.width));
    kernel_.setArg(a++, static_cast<cl_int>(image_.height));
    kernel_.setArg(a++, volume_);
    kernel_.setArg(a++, cl_int4{{dims_.x, dims_.y, dims_.z, 0}});
    kernel_.setArg(a++, toCl4(origin_));
    kernel_.setArg(a++, toCl4(1.0 / spacing_));
    kernel_.setArg(a++, toCl4(lo_));
    kernel_.setArg(a++, toCl4(hi_));
    kernel_.setArg(a++, tf_);
    kernel_.setArg(a++, static_cast<cl_int>(tfCount_));
    kernel_.setArg(a++, map_);
    kernel_.setArg(a++, static_cast<cl_int>(options_.reflectanceMapSize));
    kernel_.setArg(a++, static_cast<cl_int>(lighting_.shaded() ? 1 : 0));
    kernel_.setArg(a++, toCl4(toEye_));
    a = setCameraArgs(kernel_, a, camera_, image_.width, image_.height);
    kernel_.setArg(a++, static_cast<cl_float>(options_.sampleSpacing));
    kernel_.setArg(a++, static_cast<cl_float>(options_.earlyTermination));
    kernel_.setArg(a++, static_cast<cl_float>(options_.opacityThreshold));
    kernel_.setArg(a++, toCl4(image_.background));
    device_.launch("planes: cast, shade, composite", kernel_, image_.width, image_.height);

    const std::size_t pixels = static_cast<std::size_t>(image_.width) * image_.height;
    Image4f image(image_.width, image_.height);
    device_.queue().enqueueReadBuffer(out_, CL_TRUE, 0, pixels * sizeof(glm::vec4), image.pixels().data());
    const std::vector<cl_uint> counts = device_.download<cl_uint>(samples_, pixels);
    const std::vector<cl_uint> skipped = device_.download<cl_uint>(skipped_, pixels);
    const std::vector<cl_uchar> stopped = device_.download<cl_uchar>(terminated_, pixels);
    stats.passes = device_.takePassTimes();
    stats.frameMs = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
    stats.samples = std::accumulate(counts.begin(), counts.end(), std::uint64_t(0));
    const std::uint64_t below = std::accumulate(skipped.begin(), skipped.end(), std::uint64_t(0));
    stats.extra["samples_shaded"] = stats.samples - below;
    stats.extra["samples_below_threshold"] = below;
    stats.extra["rays_terminated"] = std::accumulate(stopped.begin(), stopped.end(), std::uint64_t(0));
    stats.extra["sample_spacing"] = options_.sampleSpacing;
    stats.extra["early_termination"] = options_.earlyTermination;
    stats.extra["opacity_threshold"] = options_.opacityThreshold;
    stats.extra["reflectance_map_size"] = options_.reflectanceMapSize;
    stats.extra["shaded"] = lighting_.shaded();
    stats.extra["lights"] = lighting_.lights.size();
    stats.extra["gradient_ms"] = gradientMs_;
    stats.extra["reflectance_map_ms"] = mapMs_;
    stats.extra["voxels"] = static_cast<std::uint64_t>(dims_.x) * dims_.y * dims_.z;
    stats.extra["resident_bytes"] = residentBytes_;
    stats.extra["voxel_type"] = "float32 RGBA (gradient, value)";
    return image;
}

}  // namespace

PlanesOptions parsePlanesOptions(const nlohmann::json& options)
{
    PlanesOptions o;
    forEachOption(options, [&](const std::string& key, const nlohmann::json& value) {
        if (key == "sample_spacing")
            o.sampleSpacing = numberOption(key, value, [](double x) { return x > 0.0; }, "a positive number (world units)");
        else if (key == "early_termination")
            o.earlyTermination =
                numberOption(key, value, [](double x) { return x > 0.0 && x <= 1.0; }, "an opacity in (0, 1] (1 = off)");
        else if (key == "opacity_threshold")
            o.opacityThreshold = numberOption(key, value, [](double x) { return x >= 0.0 && x < 1.0; },
                                              "an opacity in [0, 1) (0 = skip only transparent samples)");
        else if (key == "reflectance_map_size")
            o.reflectanceMapSize = integerOption(key, value, 1, kMaxMapSize);
        else
            badOption(key, std::string("unknown option for planes (known: ") + kKnownOptions + ")");
    });
    return o;
}

std::unique_ptr<Renderer> makePlanesRenderer(Device& device, const Scene& scene, const Volume& volume)
{
    return std::make_unique<PlanesRenderer>(device, scene, volume);
}

}  // namespace clvr
