// host/render/grid/blend.cpp — options, set-up and the one launch of the blend technique
// (kernels/blend.cl: blend_render).
#include "host/render/grid/blend.h"

#include "host/render/scaffold.h"
#include "host/runtime/errors.h"
#include "host/render/camera_args.h"
#include "host/render/options_util.h"
#include "host/optics/gradient_volume.h"
#include "host/optics/reflectance_map.h"
#include "host/render/slice_plan.h"
#include "host/render/transfer_function_upload.h"
#include "kernels/blend_params.h"

#include <cmath>

namespace clvr {
namespace {


class BlendRenderer final : public Renderer {
public:
    BlendRenderer(Device& device, const Scene& scene, const Volume& volume);
    Image4f render(FrameStats& stats) override;
    std::uint64_t residentBytes() const override { return residentBytes_; }
    void setTransferFunction(const TransferFunction& tf) override;
    bool setCamera(const Scene& scene) override;  // the camera, the slices and the reflectance map

private:
    std::uint64_t uploadReflectanceMap();

    Device& device_;
    BlendOptions options_;
    Camera camera_;
    ImageSpec image_;
    glm::ivec3 dims_;
    glm::dvec3 origin_, spacing_;  // the full grid's origin (a part's point 0 is inside it)
    glm::dvec3 lo_{0.0}, hi_{0.0};  // the full grid's box, which frames the camera and bounds the slices
    GridPart part_;                // where the volume sits in the full grid (sort-last; else the whole)
    Lighting lighting_;
    SlicePlan plan_;
    TransferFunctionUpload tf_;
    cl::Buffer volume_, map_, out_, samples_, skipped_;
    cl::Kernel kernel_;
    std::uint64_t residentBytes_ = 0;
};

BlendRenderer::BlendRenderer(Device& device, const Scene& scene, const Volume& volume)
    : device_(device), options_(parseBlendOptions(scene.options)), image_(scene.image), lighting_(scene.lighting)
{
    checkGridVolume(volume, "blend");
    dims_ = volume.dims;
    spacing_ = volume.spacing;
    // A part of a larger grid (sort-last) takes the full grid's slices and keeps the samples it owns;
    // its ghost layer gives the Sobel gradients at its own points their neighbours (planes.cpp).
    part_ = volume.gridPart();
    origin_ = part_.fullOrigin;
    lo_ = part_.fullBoundsMin();
    hi_ = part_.fullBoundsMax(spacing_);
    camera_ = frameCamera(scene, lo_, hi_);
    // the same slab planning as slice3d
    plan_ = planSlices(camera_, lo_, hi_, options_.slices, options_.sliceSpacing);

    const std::vector<glm::vec4> rgba = sobelGradientVolume(volume);
    volume_ = device_.upload("blend RGBA volume (gradient, value; float32)", rgba);
    residentBytes_ = rgba.size() * sizeof(glm::vec4) + uploadReflectanceMap();
    setTransferFunction(scene.transferFunction);

    const std::size_t pixels = static_cast<std::size_t>(image_.width) * image_.height;
    kernel_ = device_.kernel("blend.cl", "blend_render");
    out_ = device_.buffer("blend image", pixels * sizeof(cl_float4), CL_MEM_WRITE_ONLY);
    samples_ = device_.buffer("blend sample counts", pixels * sizeof(cl_uint), CL_MEM_WRITE_ONLY);
    skipped_ = device_.buffer("blend skipped sample counts", pixels * sizeof(cl_uint), CL_MEM_WRITE_ONLY);
}

bool BlendRenderer::setCamera(const Scene& scene)
{
    if (!sameImageSize(scene.image, image_))
        return false;  // the image-sized buffers would change
    image_ = scene.image;
    camera_ = frameCamera(scene, lo_, hi_);
    plan_ = planSlices(camera_, lo_, hi_, options_.slices, options_.sliceSpacing);
    lighting_ = scene.lighting;
    uploadReflectanceMap();  // the same size: resident bytes unchanged
    return true;
}

// The reflectance map, for these lights and this view direction; its bytes.
std::uint64_t BlendRenderer::uploadReflectanceMap()
{
    const ReflectanceMap map = buildReflectanceMap(lighting_, -camera_.forward(), options_.reflectanceMapSize);
    map_ = device_.upload("blend reflectance map", map.entries);
    return map.entries.size() * sizeof(glm::vec4);
}

void BlendRenderer::setTransferFunction(const TransferFunction& tf)
{
    tf_.replace(device_, "blend transfer function", tf, residentBytes_);
}

Image4f BlendRenderer::render(FrameStats& stats)
{
    const FrameClock clock;
    ClBlendParams params{};
    params.camera = toClCamera(camera_, image_.width, image_.height);
    params.dims = cl_int4{{dims_.x, dims_.y, dims_.z, 0}};
    setGridPartParams(params, part_, dims_);
    params.grid_origin = toCl4(origin_);
    params.inv_spacing = toCl4(1.0 / spacing_);
    params.to_eye = toCl4(-camera_.forward());
    params.background = toCl4(image_.background);
    params.width = image_.width;
    params.height = image_.height;
    params.tf_count = tf_.count();
    params.map_n = options_.reflectanceMapSize;
    params.shade_on = lighting_.shaded() ? 1 : 0;
    params.depth0 = static_cast<cl_float>(plan_.depthMin);
    params.delta_s = static_cast<cl_float>(plan_.deltaS);
    params.slice_count = plan_.count;
    params.threshold = static_cast<cl_float>(options_.opacityThreshold);
    int a = 0;
    kernel_.setArg(a++, out_);
    kernel_.setArg(a++, samples_);
    kernel_.setArg(a++, skipped_);
    kernel_.setArg(a++, volume_);
    kernel_.setArg(a++, tf_.buffer());
    kernel_.setArg(a++, map_);
    kernel_.setArg(a++, params);
    device_.launch("blend: shade slices, blend back to front", kernel_, image_.width, image_.height);

    const std::size_t pixels = static_cast<std::size_t>(image_.width) * image_.height;
    Image4f image = readImage(device_, out_, image_.width, image_.height);
    stats.samples = sumCounts(device_, samples_, pixels);
    const std::uint64_t below = sumCounts(device_, skipped_, pixels);
    finishFrame(device_, clock, stats);
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

TechniqueInfo blendTechnique()
{
    TechniqueInfo t;
    t.name = "blend";
    t.data = DataKind::Volume;
    t.description = "shaded slices blended back to front in one kernel, seeds/004 (docs/planes.md)";
    t.options = {slicesInfo(), sliceSpacingInfo(), opacityThresholdInfo(), reflectanceMapSizeInfo()};
    t.sortLast = true;  // sort-last parts with one ghost layer (planes.cpp)
    t.sortLastGhost = 1;
    t.makeForVolume = makeBlendRenderer;
    return t;
}

BlendOptions parseBlendOptions(const nlohmann::json& options)
{
    static const TechniqueInfo& info = technique("blend");
    BlendOptions o;
    forEachOption(options, info, [&](const std::string& key, const nlohmann::json& value) {
        if (key == "slices")
            o.slices = slicesOption(value);
        else if (key == "slice_spacing")
            o.sliceSpacing = sliceSpacingOption(value);
        else if (key == "opacity_threshold")
            o.opacityThreshold = opacityThresholdOption(value);
        else if (key == "reflectance_map_size")
            o.reflectanceMapSize = reflectanceMapSizeOption(value);
        else
            unparsedOption(info, key);
    });
    checkSlicesOrSpacing(options);
    return o;
}

std::unique_ptr<Renderer> makeBlendRenderer(Device& device, const Scene& scene, const Volume& volume)
{
    return std::make_unique<BlendRenderer>(device, scene, volume);
}

}  // namespace clvr
