// tests/support/test_util.h — what every suite shares: the test device, image comparison with stated
// tolerances (NaN never passes, failure images written), seeded randomness, data paths.
#pragma once

#include "host/model/camera.h"
#include "host/model/scene.h"
#include "host/model/transfer_function.h"
#include "host/model/volume.h"
#include "host/reference/image_error.h"
#include "host/render/renderer.h"
#include "host/runtime/device.h"
#include "host/model/image.h"
#include "host/model/scene.h"

#include <gtest/gtest.h>

#include <cstdint>
#include <filesystem>
#include <functional>
#include <memory>
#include <string>
#include <vector>

namespace clvr::test {

// CLVR_DEVICE, else the first CPU device (PoCL); opened once per process.
Device& device();

// The transfer function of DESIGN.md's example scene on s in [0,1]: black and clear at 0, orange at 0.5
// (tau 4 per world unit), white at 1 with extinction `tauAtOne` (8 in DESIGN.md).
TransferFunction designTransferFunction(double tauAtOne = 8.0);

// One frame of `scene` on `volume` from a new renderer on the test device; `stats`, when not null, gets
// the frame's FrameStats.
Image4f renderScene(const Scene& scene, const Volume& volume, FrameStats* stats = nullptr);

// The CPU reference integral of `scene` on `volume` (host/reference/reference_integral.h, default tolerance),
// its statistics printed as "[ measured ] reference: ..."; a test failure when a ray did not converge.
Image4d referenceImage(const Scene& scene, const Volume& volume);

// ../shared/data/<relative>, and the repository's own data/<relative>.
std::string sharedData(const std::string& relative);
std::string repoData(const std::string& relative);

struct Tolerance {
    double maxAbs = 0.0;   // per channel, every pixel
    double meanAbs = 0.0;  // per channel, averaged over the image
};

// Per channel max and mean absolute error (host/reference/image_error.h).
using clvr::ImageError;
using clvr::imageError;

// Ray packets' promise: `scene` with "packets": true renders the bits of the same scene with "packets": false,
// with equal stats under `keys` (the samples too), and each frame reports which kernel ran. `render` makes a
// renderer for the scene and renders one frame into its stats. Returns the one-pixel frame's stats.
FrameStats expectPacketsEqualPixels(Scene scene, const std::function<Image4f(const Scene&, FrameStats&)>& render,
                                    const std::vector<std::string>& keys, const std::string& label);

// Renderer::setCamera's promise: a renderer made by `make` for `scene` at cameras[0] (one frame rendered there
// first, so whatever it leaves behind is exercised) and pointed at each further camera renders the bits a new
// renderer renders there; a wider image it refuses. `label` names the case in failures.
void expectSetCameraEqualsNewRenderer(Scene scene, const std::function<std::unique_ptr<Renderer>(const Scene&)>& make,
                                      const std::vector<Camera>& cameras, const std::string& label);
// The same for a volume technique (makeRenderer).
void expectSetCameraEqualsNewRenderer(Scene scene, const Volume& volume, const std::vector<Camera>& cameras,
                                      const std::string& label);

// Early termination's promise, pixel by pixel: `early`, rendered stopping each ray at opacity `threshold`, differs
// from `full` by at most 1 - threshold in every channel; where `full` passes the threshold by 0.05 it reaches the
// threshold and stays at or below `full`'s opacity; where `full` stays below it, the same bits. Returns the pixels
// that stopped short of `full`'s opacity (by more than 1e-3).
int expectEarlyTermination(const Image4f& full, const Image4f& early, double threshold);

// Success when `a` and `b` have the same size and the same bits (memcmp), else the first differing pixel:
// for kernels that must agree exactly (ray packets against one pixel per work-item).
testing::AssertionResult sameBits(const Image4f& a, const Image4f& b);

// Per channel max and mean absolute error against `expected`; fails on NaN or size mismatch.
// On failure writes test_output/<suite>.<test>/{actual,expected,diff}.exr and says so.
testing::AssertionResult imagesNear(const Image4f& actual, const Image4d& expected, Tolerance tolerance);

// True when a pixel of the 3x3 neighbourhood of (x, y) inside the width x height image is on the other
// side of `covered` than (x, y): a silhouette pixel of the coverage, where a surface renderer and its
// reference may disagree on whether the pixel's ray hits.
bool atSilhouette(const std::function<bool(int, int)>& covered, int x, int y, int width, int height);

// A fresh directory under the system temporary directory (named after the running test), removed
// with everything in it when it goes out of scope. Tests write malformed files here, never in the repo.
class TempDir {
public:
    TempDir();
    ~TempDir();
    TempDir(const TempDir&) = delete;
    TempDir& operator=(const TempDir&) = delete;
    std::filesystem::path operator/(const std::string& name) const { return path_ / name; }
    const std::filesystem::path& path() const { return path_; }

private:
    std::filesystem::path path_;
};

// Whole-file binary write (asserting success) and read.
void writeFile(const std::filesystem::path& path, const std::string& bytes);
std::string readFile(const std::filesystem::path& path);

// The call throws InputError with one line that contains every piece (the readers' promise for bad input).
testing::AssertionResult throwsInputError(const std::function<void()>& call, std::vector<std::string> pieces);

// `data` deflated with gzip (not zlib) framing, as NRRD's gzip encoding writes it.
std::string gzip(const std::string& data);

// A small deterministic generator (splitmix64): the same numbers on every standard library.
class Rng {
public:
    explicit Rng(std::uint64_t seed) : state_(seed) {}
    std::uint64_t next();
    double uniform(double lo = 0.0, double hi = 1.0);  // [lo, hi)
    int integer(int lo, int hi);                       // [lo, hi]

private:
    std::uint64_t state_;
};

// The two cameras of tests/slice3d_test.cpp that most regular-grid tests share, looking at the origin
// (a volume in [-1, 1]^3): perspective from (1.2, 1.6, 3.7), 28 degrees off the z axis, with this view
// angle; parallel from (3.5, 1.0, 1.9), z up, 32 degrees off the x axis, with this parallel scale.
inline Camera obliquePerspectiveCamera(double viewAngle)
{
    Camera c;
    c.position = {1.2, 1.6, 3.7};
    c.viewAngle = viewAngle;
    return c;
}

inline Camera obliqueParallelCamera(double parallelScale)
{
    Camera c;
    c.position = {3.5, 1.0, 1.9};
    c.viewUp = {0.0, 0.0, 1.0};
    c.parallel = true;
    c.parallelScale = parallelScale;
    return c;
}

// An "iso" with its light given (normalized, as parseScene does) and gradient shading unless told.
inline IsoSpec isoSpec(double value, const glm::dvec3& light, double ambient, double diffuse,
                       IsoSpec::Shading shading = IsoSpec::Shading::Gradient)
{
    IsoSpec iso;
    iso.value = value;
    iso.shading = shading;
    iso.light = glm::normalize(light);
    iso.ambient = ambient;
    iso.diffuse = diffuse;
    return iso;
}

// "iso.shading" by its scene name ("gradient", "gradientless", "none").
inline IsoSpec::Shading shadingNamed(const std::string& name)
{
    for (IsoSpec::Shading s : {IsoSpec::Shading::Gradient, IsoSpec::Shading::Gradientless, IsoSpec::Shading::None})
        if (name == shadingName(s))
            return s;
    ADD_FAILURE() << "no shading named " << name;
    return IsoSpec::Shading::Gradient;
}

// The lights and material the shaded planes, blend and stack2d tests share: a white light from
// (0.4, 0.6, 1), a dim blue one from (-1, -0.2, 0.3); ka 0.15, kd 0.7, ks 0.3, shininess 10.
inline Lighting twoLightLighting()
{
    Lighting l;
    l.lights = {{glm::normalize(glm::dvec3(0.4, 0.6, 1.0)), glm::dvec3(1.0)},
                {glm::normalize(glm::dvec3(-1.0, -0.2, 0.3)), glm::dvec3(0.3, 0.3, 0.5)}};
    l.material = {0.15, 0.7, 0.3, 10.0};
    return l;
}

}  // namespace clvr::test
