// host/render/grid/spherical.cpp — options, shell planning, sphere tessellation and the pass-by-pass
// rendering of the spherical technique (pixel textures on spherical domains, seeds/000 §2.2).
#include "host/render/grid/spherical.h"

#include "host/render/scaffold.h"
#include "host/runtime/errors.h"
#include "host/render/camera_args.h"
#include "host/render/options_util.h"
#include "host/render/transfer_function_upload.h"
#include "kernels/spherical_params.h"
#include "raster/framebuffer.h"
#include "raster/texture.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>

namespace clvr {

static_assert(sizeof(ClSphericalFusedParams) == 288, "also probed on the device by tests/layout_test.cpp");

namespace {

constexpr double kPi = 3.14159265358979323846;
constexpr int kMaxShells = 4096;
constexpr int kMaxSegments = 1024;  // 1024 x 512 x 2 = 1 M triangles (240 MB of vertices) per shell

double finiteNumber(const std::string& key, const nlohmann::json& value)
{
    if (!value.is_number() || !std::isfinite(value.get<double>()))
        badOption(key, "must be a finite number, got " + value.dump());
    return value.get<double>();
}

int integerIn(const std::string& key, const nlohmann::json& value, int lo, int hi)
{
    if (!value.is_number_integer() || value.get<long long>() < lo || value.get<long long>() > hi)
        badOption(key, "must be an integer in [" + std::to_string(lo) + ", " + std::to_string(hi) + "], got " +
                           value.dump());
    return static_cast<int>(value.get<long long>());
}

// A list of `n` finite numbers (or, where `alsoThree`, 3: the fourth keeps `fill`).
glm::dvec4 numbers(const std::string& key, const nlohmann::json& value, int n, bool alsoThree, double fill)
{
    const bool sizeOk = value.is_array() && (value.size() == static_cast<std::size_t>(n) || (alsoThree && value.size() == 3));
    if (!sizeOk)
        badOption(key, "must be a list of " + std::to_string(n) + (alsoThree ? " (or 3)" : "") + " numbers, got " +
                           value.dump());
    glm::dvec4 v(fill);
    for (std::size_t i = 0; i < value.size(); ++i)
        v[static_cast<int>(i)] = finiteNumber(key + "[" + std::to_string(i) + "]", value[i]);
    return v;
}

cl_float4 f4(const glm::dvec3& v, double w = 0.0)
{
    return toCl4(v, w);
}

}  // namespace

TechniqueInfo sphericalTechnique()
{
    TechniqueInfo t;
    t.name = "spherical";
    t.data = DataKind::Volume;
    t.description = "spherical shells textured through a pixel texture, seeds/004 (docs/spherical.md)";
    const nlohmann::json identity = {{1, 0, 0, 0}, {0, 1, 0, 0}, {0, 0, 1, 0}, {0, 0, 0, 1}};
    t.options = {
        {"shells", 64, "", "spheres drawn between r_min and r_max, 2..4096"},
        {"segments", 64, "", "tessellation: segments in phi, segments / 2 in theta, 4..1024"},
        {"r_min", 0.5, "", "innermost shell radius, world units"},
        {"r_max", 1.0, "", "outermost shell radius, world units (> r_min)"},
        {"center", {0, 0, 0}, "", "center of the shells, world space"},
        {"color_matrix", identity, "", "pixel transfer on (u, v, w, 1): 4 rows of 4 numbers"},
        {"scale", {1, 1, 1, 1}, "", "pixel transfer scale, after the color matrix"},
        {"bias", {0, 0, 0, 0}, "", "pixel transfer bias, after the scale"},
        {"opacity", "path", "", "a shell's opacity from \"path\" (the ray's length in its slab) or \"radial\""},
        {"path", "fused", "", "\"fused\" (each pixel meets the exact spheres in one kernel) or \"raster\" (the "
                              "tessellated shells pass by pass)"},
        earlyTerminationInfo(1.0),
        packetsInfo(),
    };
    t.makeForVolume = makeSphericalRenderer;
    return t;
}

SphericalOptions parseSphericalOptions(const nlohmann::json& options)
{
    static const TechniqueInfo& info = technique("spherical");
    SphericalOptions o;
    forEachOption(options, info, [&](const std::string& key, const nlohmann::json& value) {
        if (key == "shells") {
            o.shells = integerIn(key, value, 2, kMaxShells);
        } else if (key == "segments") {
            o.segments = integerIn(key, value, 4, kMaxSegments);
        } else if (key == "r_min") {
            o.domain.rMin = finiteNumber(key, value);
            if (o.domain.rMin < 0.0)
                badOption(key, "must be >= 0, got " + value.dump());
        } else if (key == "r_max") {
            o.domain.rMax = finiteNumber(key, value);
        } else if (key == "center") {
            o.domain.center = glm::dvec3(numbers(key, value, 3, false, 0.0));
        } else if (key == "color_matrix") {
            // Rows, as written: color_matrix[r][c] multiplies input channel c into output channel r.
            if (!value.is_array() || value.size() != 4)
                badOption(key, "must be 4 rows of 4 numbers, got " + value.dump());
            for (int r = 0; r < 4; ++r) {
                const glm::dvec4 row = numbers(key + "[" + std::to_string(r) + "]", value[r], 4, false, 0.0);
                for (int c = 0; c < 4; ++c)
                    o.transfer.colorMatrix[c][r] = static_cast<float>(row[c]);  // glm: [column][row]
            }
        } else if (key == "scale") {
            o.transfer.scale = glm::vec4(numbers(key, value, 4, true, 1.0));
        } else if (key == "bias") {
            o.transfer.bias = glm::vec4(numbers(key, value, 4, true, 0.0));
        } else if (key == "opacity") {
            const std::string mode = value.is_string() ? value.get<std::string>() : "";
            if (mode == "path")
                o.opacity = SphericalOptions::Opacity::Path;
            else if (mode == "radial")
                o.opacity = SphericalOptions::Opacity::Radial;
            else
                badOption(key, "must be \"path\" or \"radial\", got " + value.dump());
        } else if (key == "path") {
            o.path = choiceOption(key, value, {"fused", "raster"}) == 0 ? SphericalOptions::Path::Fused
                                                                       : SphericalOptions::Path::Raster;
        } else if (key == "early_termination") {
            o.earlyTermination = earlyTerminationOption(value);
        } else if (key == "packets") {
            o.packets = packetsOption(key, value);
        } else {
            unparsedOption(info, key);
        }
    });
    if (o.earlyTermination < 1.0 && o.path == SphericalOptions::Path::Raster)
        badOption("early_termination", "is only available on the fused path (the blending stage cannot stop a pixel)");
    if (!(o.domain.rMax > o.domain.rMin))
        badOption("r_max", "must be greater than r_min (" + std::to_string(o.domain.rMin) + "), got " +
                               std::to_string(o.domain.rMax));
    return o;
}

glm::dvec3 sphericalCoordinates(const SphericalDomain& domain, const glm::dvec3& x)
{
    const glm::dvec3 d = x - domain.center;
    const double r = glm::length(d);
    double u = std::atan2(d.y, d.x) / (2.0 * kPi);
    if (u < 0.0)
        u += 1.0;
    if (u >= 1.0)
        u = 0.0;
    const double v = r > 0.0 ? std::acos(std::clamp(d.z / r, -1.0, 1.0)) / kPi : 0.0;
    return {u, v, (r - domain.rMin) / (domain.rMax - domain.rMin)};
}

std::vector<Shell> planShells(const SphericalOptions& options)
{
    const double r0 = options.domain.rMin, r1 = options.domain.rMax;
    const int n = options.shells;
    const double dr = (r1 - r0) / (n - 1);
    std::vector<Shell> shells(n);
    for (int k = 0; k < n; ++k) {
        // From the index, not by accumulating dr: the last shell is exactly r_max.
        const double r = k == n - 1 ? r1 : r0 + (r1 - r0) * k / (n - 1);
        shells[k] = {r, std::max(r0, r - 0.5 * dr), std::min(r1, r + 0.5 * dr)};
    }
    return shells;
}

std::vector<raster::Vertex> sphereTriangles(const glm::dvec3& center, double radius, double w, int segments,
                                            const glm::dmat4& viewProjection)
{
    const int nPhi = segments, nTheta = std::max(2, segments / 2);
    auto vertex = [&](double u, double v) {
        const double phi = 2.0 * kPi * u, theta = kPi * v;
        const glm::dvec3 p = center + radius * glm::dvec3(std::sin(theta) * std::cos(phi),
                                                          std::sin(theta) * std::sin(phi), std::cos(theta));
        raster::Vertex vx;
        vx.position = glm::vec4(viewProjection * glm::dvec4(p, 1.0));
        vx.attributes[0] = glm::vec4(static_cast<float>(u), static_cast<float>(v), static_cast<float>(w), 1.0f);
        return vx;
    };
    std::vector<raster::Vertex> out;
    out.reserve(static_cast<std::size_t>(nPhi) * nTheta * 6);
    for (int j = 0; j < nTheta; ++j) {
        const double v0 = static_cast<double>(j) / nTheta, v1 = static_cast<double>(j + 1) / nTheta;
        for (int i = 0; i < nPhi; ++i) {
            const double u0 = static_cast<double>(i) / nPhi, u1 = i + 1 == nPhi ? 1.0 : static_cast<double>(i + 1) / nPhi;
            const double uMid = 0.5 * (u0 + u1);
            // Outward and counter-clockwise: (a, a + south, a + east) and (a + east, a + south, a + south-east).
            if (j == 0) {  // north pole: one triangle, its pole vertex at the mean u
                out.push_back(vertex(uMid, v0));
                out.push_back(vertex(u0, v1));
                out.push_back(vertex(u1, v1));
            } else if (j == nTheta - 1) {  // south pole
                out.push_back(vertex(u0, v0));
                out.push_back(vertex(uMid, v1));
                out.push_back(vertex(u1, v0));
            } else {
                out.push_back(vertex(u0, v0));
                out.push_back(vertex(u0, v1));
                out.push_back(vertex(u1, v0));
                out.push_back(vertex(u1, v0));
                out.push_back(vertex(u0, v1));
                out.push_back(vertex(u1, v1));
            }
        }
    }
    return out;
}

raster::PixelTransfer composeTextureMap(const raster::PixelTransfer& user, const glm::ivec3& dims)
{
    // t = b_t + s_t ⊙ (b_u + s_u ⊙ (M p)) = (b_t + s_t ⊙ b_u) + (s_t ⊙ s_u) ⊙ (M p)
    const glm::vec4 st((dims.x - 1.0f) / dims.x, (dims.y - 1.0f) / dims.y, (dims.z - 1.0f) / dims.z, 1.0f);
    const glm::vec4 bt(0.5f / dims.x, 0.5f / dims.y, 0.5f / dims.z, 0.0f);
    raster::PixelTransfer t = user;
    t.scale = st * user.scale;
    t.bias = bt + st * user.bias;
    return t;
}

SphericalRenderer::SphericalRenderer(Device& device, const Scene& scene, const Volume& volume)
    : device_(device), options_(parseSphericalOptions(scene.options)), imageSpec_(scene.image),
      overBackground_(device)
{
    if (scene.lighting.shaded())
        throw InputError("lights: technique spherical renders unshaded (no \"lights\")");
    if (scene.iso)
        throw InputError("iso: technique spherical renders no iso-surfaces (no \"iso\")");
    checkGridVolume(volume, "spherical");
    dims_ = volume.dims;
    frameView(scene);
    shells_ = planShells(options_);
    texturedTransfer_ = composeTextureMap(options_.transfer, dims_);
    raster::validate(texturedTransfer_);

    raster::TextureDesc desc;
    desc.width = dims_.x;
    desc.height = dims_.y;
    desc.depth = dims_.z;
    desc.channels = 1;
    desc.filter = raster::Filter::Linear;
    desc.wrap = raster::Wrap::ClampToEdge;
    std::vector<float> scratch;
    texture_ = std::make_unique<raster::Texture>(device_, desc, volume.floats(scratch));
    residentBytes_ += texture_->bytes();
    setTransferFunction(scene.transferFunction);

    coords_ = std::make_unique<raster::Framebuffer>(device_, imageSpec_.width, imageSpec_.height);
    image_ = std::make_unique<raster::Framebuffer>(device_, imageSpec_.width, imageSpec_.height);
    shellKernel_ = device_.kernel("spherical.cl", "spherical_shell");

    if (options_.path == SphericalOptions::Path::Fused) {
        const SphericalDomain& d = options_.domain;
        std::vector<glm::vec4> table;
        for (const Shell& shell : shells_)
            table.emplace_back(glm::dvec4(shell.radius, shell.rLo, shell.rHi, (shell.radius - d.rMin) / (d.rMax - d.rMin)));
        shellTable_ = device_.upload("spherical shell table", table);
        residentBytes_ += table.size() * sizeof(glm::vec4);
        // Ray packets (docs/spherical.md): the same kernel's arithmetic on 8 pixels at once.
        packet_ = packetsOnDevice(options_.packets, device_);
        fused_ = device_.kernel("spherical.cl", packet_ ? "spherical_fused_packet" : "spherical_fused");
        fusedSamples_ = device_.buffer("spherical fused samples per pixel",
                                       static_cast<std::size_t>(imageSpec_.width) * imageSpec_.height * sizeof(cl_uint),
                                       CL_MEM_WRITE_ONLY);
    }
}

// What depends on the view: the framed camera and the shells' view-projection (near and far planes around the
// outer sphere's eye-depth range, as stack2d does for its box: depth is not tested, only the near plane
// matters, it removes what lies behind the camera). Everything else is the data and the domain.
void SphericalRenderer::frameView(const Scene& scene)
{
    const SphericalDomain& d = options_.domain;
    imageSpec_ = scene.image;
    camera_ = frameCamera(scene, d.center - d.rMax, d.center + d.rMax);
    const double dc = glm::dot(camera_.forward(), d.center - camera_.position);
    const double dMin = dc - d.rMax, dMax = dc + d.rMax;
    const double nearZ = camera_.parallel ? 0.0 : (dMin > 0.0 ? 0.5 * dMin : 1e-4 * std::max(dMax, 1e-30));
    const double farZ = 2.0 * std::max(dMax, 0.0) + 1.0;
    viewProjection_ = camera_.projectionMatrix(imageSpec_.width, imageSpec_.height, nearZ, farZ) * camera_.viewMatrix();
}

bool SphericalRenderer::setCamera(const Scene& scene)
{
    if (!sameImageSize(scene.image, imageSpec_))
        return false;  // the frame buffers would change
    frameView(scene);
    return true;
}

// The fused path: spherical_fused leaves the finished image (over the background) in image()'s color.
// Returns the shell hits taken.
std::uint64_t SphericalRenderer::renderFused()
{
    ClSphericalFusedParams p{};
    p.camera = toClCamera(camera_, imageSpec_.width, imageSpec_.height);
    p.tex = texture_->toCl();
    const glm::mat4& m = texturedTransfer_.colorMatrix;  // glm is column-major: row r is (m[0][r], ..., m[3][r])
    for (int r = 0; r < 4; ++r)
        p.matrix_row[r] = cl_float4{{m[0][r], m[1][r], m[2][r], m[3][r]}};
    const glm::vec4 scale = texturedTransfer_.scale, bias = texturedTransfer_.bias;
    p.scale = cl_float4{{scale.x, scale.y, scale.z, scale.w}};
    p.bias = cl_float4{{bias.x, bias.y, bias.z, bias.w}};
    p.center = f4(options_.domain.center);
    p.background = f4(glm::dvec3(imageSpec_.background));
    p.width = imageSpec_.width;
    p.height = imageSpec_.height;
    p.tf_count = tf_.count();
    p.shells = static_cast<cl_int>(shells_.size());
    p.phi_s0 = 0.5f / dims_.x;
    p.phi_period = (dims_.x - 1.0f) / dims_.x;
    p.ert_alpha = options_.earlyTermination < 1.0 ? static_cast<float>(options_.earlyTermination) : 2.0f;
    p.radial = options_.opacity == SphericalOptions::Opacity::Radial ? 1 : 0;
    int a = 0;
    fused_.setArg(a++, image_->color());
    fused_.setArg(a++, fusedSamples_);
    fused_.setArg(a++, texture_->buffer());
    fused_.setArg(a++, tf_.buffer());
    fused_.setArg(a++, shellTable_);
    fused_.setArg(a++, p);
    device_.launch("spherical: fused shells", fused_, rowWorkItems(imageSpec_.width, packet_),
                   static_cast<std::size_t>(imageSpec_.height));
    std::uint64_t samples = 0;
    for (const cl_uint n : device_.download<cl_uint>(fusedSamples_, image_->pixelCount()))
        samples += n;
    return samples;
}

void SphericalRenderer::setTransferFunction(const TransferFunction& tf)
{
    if (tf.points().empty())
        throw InputError("transfer_function: technique spherical needs one");
    tf_.replace(device_, "spherical transfer function", tf, residentBytes_);
}

void SphericalRenderer::renderPass(std::size_t shellIndex, bool back)
{
    const Shell& shell = shells_.at(shellIndex);
    if (!(shell.radius > 0.0))
        return;  // a sphere of radius 0 covers no pixel
    const SphericalDomain& d = options_.domain;
    const double w = (shell.radius - d.rMin) / (d.rMax - d.rMin);
    const std::vector<raster::Vertex> vertices = sphereTriangles(d.center, shell.radius, w, options_.segments, viewProjection_);

    // 1. The sphere's (u, v, w, 1) into the coordinate buffer: one hemisphere by face culling (a
    //    convex surface: every ray meets its back faces once and its front faces once), coverage in
    //    the stencil.
    coords_->clearColor(device_, glm::vec4(0.0f));
    coords_->clearStencil(device_, 0);
    raster::DrawState state;
    state.fragment.cull = back ? raster::CullFace::Front : raster::CullFace::Back;
    state.fragment.stencil.test = true;
    state.fragment.stencil.func = raster::CompareFunc::Always;
    state.fragment.stencil.ref = 1;
    state.fragment.stencil.dppass = raster::StencilOp::Replace;
    const raster::DrawStats s = raster::draw(device_, *coords_, state, raster::Topology::Triangles, vertices);
    drawStats_.triangles += s.triangles;
    drawStats_.fragments += s.fragments;

    // 2. The paper's pixel transfer b + s·CM·p, with the texel-center map composed in.
    raster::applyPixelTransfer(device_, *coords_, texturedTransfer_);

    // 3. Pixel texture, classification, slab opacity, blend (kernels/spherical.cl).
    const bool radial = options_.opacity == SphericalOptions::Opacity::Radial;
    ClSphericalParams params{};
    params.camera = toClCamera(camera_, imageSpec_.width, imageSpec_.height);
    params.tex = texture_->toCl();
    // center.w: the next inner sphere's radius (-1: none), see clvr_spherical_slab_length.
    params.center = f4(d.center, shellIndex > 0 ? shells_[shellIndex - 1].radius : -1.0);
    params.slab = cl_float4{{static_cast<float>(shell.rLo), static_cast<float>(shell.rHi), back ? 1.0f : -1.0f,
                             radial ? 1.0f : 0.0f}};
    params.width = imageSpec_.width;
    params.height = imageSpec_.height;
    params.tf_count = tf_.count();
    params.phi_s0 = 0.5f / dims_.x;
    params.phi_period = (dims_.x - 1.0f) / dims_.x;
    cl::Kernel& k = shellKernel_;
    int a = 0;
    k.setArg(a++, coords_->color());
    k.setArg(a++, coords_->stencil());
    k.setArg(a++, image_->color());
    k.setArg(a++, texture_->buffer());
    k.setArg(a++, tf_.buffer());
    k.setArg(a++, params);
    device_.launch("spherical: pixel texture, classify, blend", k, static_cast<std::size_t>(imageSpec_.width),
                   static_cast<std::size_t>(imageSpec_.height));
}

Image4f SphericalRenderer::render(FrameStats& stats)
{
    const FrameClock clock;
    drawStats_ = {};
    if (options_.path == SphericalOptions::Path::Fused) {
        const std::uint64_t samples = renderFused();
        Image4f image = image_->readColor(device_);
        finishFrame(device_, clock, stats);
        stats.samples = samples;  // one texture sample per shell hit
        stats.extra["path"] = "fused";
        stats.extra["shells"] = shells_.size();
        stats.extra["opacity"] = options_.opacity == SphericalOptions::Opacity::Path ? "path" : "radial";
        stats.extra["early_termination"] = options_.earlyTermination;
        stats.extra["packets"] = packet_;
        stats.extra["voxels"] = static_cast<std::uint64_t>(dims_.x) * dims_.y * dims_.z;
        stats.extra["resident_bytes"] = residentBytes_;
        return image;
    }
    image_->clearColor(device_, glm::vec4(0.0f));
    // Back to front along every ray: the far hits of concentric spheres lie beyond all near hits
    // and grow with the radius, the near hits shrink with it. So: back hemispheres from the
    // outermost shell in, then front hemispheres from the innermost out. A camera inside a sphere
    // sees only its back faces (its front faces are behind the near plane), so the order holds.
    for (std::size_t k = shells_.size(); k-- > 0;)
        renderPass(k, true);
    for (std::size_t k = 0; k < shells_.size(); ++k)
        renderPass(k, false);
    const std::size_t pixels = image_->pixelCount();
    overBackground_.run(image_->color(), pixels, imageSpec_.background, "spherical: over background");
    Image4f image = image_->readColor(device_);
    finishFrame(device_, clock, stats);
    stats.samples = drawStats_.fragments;  // one texture sample per covered pixel of a hemisphere
    stats.extra["path"] = "raster";
    stats.extra["shells"] = shells_.size();
    stats.extra["segments"] = options_.segments;
    stats.extra["triangles"] = drawStats_.triangles;
    stats.extra["opacity"] = options_.opacity == SphericalOptions::Opacity::Path ? "path" : "radial";
    stats.extra["voxels"] = static_cast<std::uint64_t>(dims_.x) * dims_.y * dims_.z;
    stats.extra["resident_bytes"] = residentBytes_;
    return image;
}

std::unique_ptr<Renderer> makeSphericalRenderer(Device& device, const Scene& scene, const Volume& volume)
{
    return std::make_unique<SphericalRenderer>(device, scene, volume);
}

}  // namespace clvr
