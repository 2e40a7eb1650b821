// host/render/grid/planes.cpp — options, set-up (RGBA volume, reflectance map, transfer function on the device)
// and the one launch of the planes technique (kernels/planes.cl: planes_render).
#include "host/render/grid/planes.h"

#include "host/render/scaffold.h"
#include "host/runtime/errors.h"
#include "host/render/camera_args.h"
#include "host/render/options_util.h"
#include "host/optics/gradient_volume.h"
#include "host/optics/reflectance_map.h"
#include "host/render/transfer_function_upload.h"
#include "kernels/planes_params.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <numeric>

namespace clvr {
namespace {

constexpr double kMaxSamplesPerRay = 1 << 20;

class PlanesRenderer final : public Renderer {
public:
    PlanesRenderer(Device& device, const Scene& scene, const Volume& volume);
    Image4f render(FrameStats& stats) override;
    std::uint64_t residentBytes() const override { return residentBytes_; }
    void setTransferFunction(const TransferFunction& tf) override;
    bool setCamera(const Scene& scene) override;  // the camera and the reflectance map (it faces the eye)

private:
    Device& device_;
    PlanesOptions options_;
    Camera camera_;
    ImageSpec image_;
    glm::ivec3 dims_;
    glm::dvec3 origin_, spacing_, lo_, hi_;  // the full grid's origin and box (a part's are inside them)
    GridPart part_;        // where the volume sits in the full grid (sort-last; else the whole)
    bool isPart_ = false;  // a part of a larger grid: no early ray termination
    Lighting lighting_;
    glm::dvec3 toEye_;
    TransferFunctionUpload tf_;
    double gradientMs_ = 0.0, mapMs_ = 0.0;
    std::uint64_t uploadReflectanceMap();
    cl::Buffer volume_, map_;
    cl::Buffer out_, samples_, skipped_, terminated_;
    cl::Kernel kernel_;
    std::uint64_t residentBytes_ = 0;
};

PlanesRenderer::PlanesRenderer(Device& device, const Scene& scene, const Volume& volume)
    : device_(device), options_(parsePlanesOptions(scene.options)), image_(scene.image),
      lighting_(scene.lighting)
{
    checkGridVolume(volume, "planes");
    dims_ = volume.dims;
    spacing_ = volume.spacing;
    // A part of a larger grid (sort-last) casts the full grid's rays with the full grid's samples and
    // keeps the ones it owns; its ghost layer (TechniqueInfo::sortLastGhost) gives the Sobel gradients
    // at its own points their neighbours, so every owned sample is the whole volume's, bit for bit.
    part_ = volume.gridPart();
    isPart_ = volume.part.has_value();
    origin_ = part_.fullOrigin;
    lo_ = part_.fullBoundsMin();
    hi_ = part_.fullBoundsMax(spacing_);
    camera_ = frameCamera(scene, lo_, hi_);
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

    residentBytes_ += uploadReflectanceMap();

    setTransferFunction(scene.transferFunction);

    const std::size_t pixels = static_cast<std::size_t>(image_.width) * image_.height;
    kernel_ = device_.kernel("planes.cl", "planes_render");
    out_ = device_.buffer("planes image", pixels * sizeof(cl_float4), CL_MEM_WRITE_ONLY);
    samples_ = device_.buffer("planes sample counts", pixels * sizeof(cl_uint), CL_MEM_WRITE_ONLY);
    skipped_ = device_.buffer("planes skipped sample counts", pixels * sizeof(cl_uint), CL_MEM_WRITE_ONLY);
    terminated_ = device_.buffer("planes terminated-ray flags", pixels, CL_MEM_WRITE_ONLY);
}

// The reflectance map, for these lights and this view direction (rebuilt with either); its bytes.
std::uint64_t PlanesRenderer::uploadReflectanceMap()
{
    const auto t0 = std::chrono::steady_clock::now();
    const ReflectanceMap map = buildReflectanceMap(lighting_, toEye_, options_.reflectanceMapSize);
    mapMs_ = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
    map_ = device_.upload("planes reflectance map", map.entries);
    return map.entries.size() * sizeof(glm::vec4);
}

bool PlanesRenderer::setCamera(const Scene& scene)
{
    if (!sameImageSize(scene.image, image_))
        return false;  // the image-sized buffers would change
    image_ = scene.image;
    camera_ = frameCamera(scene, lo_, hi_);
    toEye_ = -camera_.forward();
    lighting_ = scene.lighting;
    uploadReflectanceMap();  // the same size: resident bytes unchanged
    return true;
}

void PlanesRenderer::setTransferFunction(const TransferFunction& tf)
{
    // Classification happens per sample on the device: only the control points change.
    tf_.replace(device_, "planes transfer function", tf, residentBytes_);
}

Image4f PlanesRenderer::render(FrameStats& stats)
{
    const FrameClock clock;
    ClPlanesParams params{};
    params.camera = toClCamera(camera_, image_.width, image_.height);
    params.dims = cl_int4{{dims_.x, dims_.y, dims_.z, 0}};
    setGridPartParams(params, part_, dims_);
    params.full_dims = cl_int4{{part_.fullDims.x, part_.fullDims.y, part_.fullDims.z, 0}};
    params.grid_origin = toCl4(origin_);
    params.inv_spacing = toCl4(1.0 / spacing_);
    params.box_lo = toCl4(lo_);
    params.box_hi = toCl4(hi_);
    params.to_eye = toCl4(toEye_);
    params.background = toCl4(image_.background);
    params.width = image_.width;
    params.height = image_.height;
    params.tf_count = tf_.count();
    params.map_n = options_.reflectanceMapSize;
    params.shade_on = lighting_.shaded() ? 1 : 0;
    params.step = static_cast<cl_float>(options_.sampleSpacing);
    // A part cannot see the opacity in front of it: it never stops early (docs/cluster.md).
    params.ert_alpha = isPart_ ? 2.0f : static_cast<cl_float>(options_.earlyTermination);
    params.threshold = static_cast<cl_float>(options_.opacityThreshold);
    int a = 0;
    kernel_.setArg(a++, out_);
    kernel_.setArg(a++, samples_);
    kernel_.setArg(a++, skipped_);
    kernel_.setArg(a++, terminated_);
    kernel_.setArg(a++, volume_);
    kernel_.setArg(a++, tf_.buffer());
    kernel_.setArg(a++, map_);
    kernel_.setArg(a++, params);
    device_.launch("planes: cast, shade, composite", kernel_, image_.width, image_.height);

    const std::size_t pixels = static_cast<std::size_t>(image_.width) * image_.height;
    Image4f image = readImage(device_, out_, image_.width, image_.height);
    stats.samples = sumCounts(device_, samples_, pixels);
    const std::uint64_t below = sumCounts(device_, skipped_, pixels);
    const std::vector<cl_uchar> stopped = device_.download<cl_uchar>(terminated_, pixels);
    finishFrame(device_, clock, stats);
    stats.extra["samples_shaded"] = stats.samples - below;
    stats.extra["samples_below_threshold"] = below;
    stats.extra["rays_terminated"] = std::accumulate(stopped.begin(), stopped.end(), std::uint64_t(0));
    stats.extra["sample_spacing"] = options_.sampleSpacing;
    stats.extra["early_termination"] = isPart_ ? 1.0 : options_.earlyTermination;
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

TechniqueInfo planesTechnique()
{
    TechniqueInfo t;
    t.name = "planes";
    t.data = DataKind::Volume;
    t.description = "shaded ray casting through gradient planes, seeds/004 (docs/planes.md)";
    t.options = {
        {"sample_spacing", nullptr, "half the smallest grid spacing",
         "world units between samples along each ray (a ray caster: along the ray, not the view axis)"},
        earlyTerminationInfo(0.99),
        opacityThresholdInfo(),
        reflectanceMapSizeInfo(),
    };
    t.sortLast = true;  // sort-last parts with one ghost layer, without early ray termination
    t.sortLastGhost = 1;
    t.makeForVolume = makePlanesRenderer;
    return t;
}

PlanesOptions parsePlanesOptions(const nlohmann::json& options)
{
    static const TechniqueInfo& info = technique("planes");
    PlanesOptions o;
    forEachOption(options, info, [&](const std::string& key, const nlohmann::json& value) {
        if (key == "sample_spacing")
            o.sampleSpacing = numberOption(key, value, [](double x) { return x > 0.0; }, "a positive number (world units)");
        else if (key == "early_termination")
            o.earlyTermination = earlyTerminationOption(value);
        else if (key == "opacity_threshold")
            o.opacityThreshold = opacityThresholdOption(value);
        else if (key == "reflectance_map_size")
            o.reflectanceMapSize = reflectanceMapSizeOption(value);
        else
            unparsedOption(info, key);
    });
    return o;
}

std::unique_ptr<Renderer> makePlanesRenderer(Device& device, const Scene& scene, const Volume& volume)
{
    return std::make_unique<PlanesRenderer>(device, scene, volume);
}

}  // namespace clvr
