// tests/support/test_util.cpp — shared test device, image metrics, failure images, RNG.
#include "tests/support/test_util.h"

#include "host/io/image_io.h"
#include "host/runtime/errors.h"
#include "host/reference/reference_integral.h"

#include <zlib.h>

#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <memory>
#include <sstream>
#include <unistd.h>

namespace clvr::test {

TransferFunction designTransferFunction(double tauAtOne)
{
    return TransferFunction({{0.0, {0, 0, 0}, 0.0}, {0.5, {1, 0.5, 0}, 4.0}, {1.0, {1, 1, 1}, tauAtOne}});
}

Image4f renderScene(const Scene& scene, const Volume& volume, FrameStats* stats)
{
    auto renderer = makeRenderer(device(), scene, volume);
    FrameStats frame;
    Image4f image = renderer->render(frame);
    if (stats)
        *stats = frame;
    return image;
}

Image4d referenceImage(const Scene& scene, const Volume& volume)
{
    ReferenceStats stats;
    ReferenceOptions options;
    options.stats = &stats;
    Image4d image = referenceIntegral(volume, scene.transferFunction, *scene.camera, scene.image, options);
    std::printf("[ measured ] reference: %llu rays, %llu samples, up to %d segments per ray, last change %.2g, "
                "%llu rays not converged\n",
                static_cast<unsigned long long>(stats.rays), static_cast<unsigned long long>(stats.samples),
                stats.maxSegments, stats.maxResidual, static_cast<unsigned long long>(stats.raysNotConverged));
    EXPECT_EQ(stats.raysNotConverged, 0u);
    return image;
}

Device& device()
{
    static std::unique_ptr<Device> instance = std::make_unique<Device>("");
    return *instance;
}

// Appended step by step: `std::string(DIR) + "/" + relative` makes GCC 12 at -O1 warn of a memcpy out of
// bounds inside operator+ (-Warray-bounds, a false positive of its string inlining).
std::string sharedData(const std::string& relative)
{
    std::string path = CLVR_SHARED_DATA_DIR;
    path += '/';
    path += relative;
    return path;
}

std::string repoData(const std::string& relative)
{
    std::string path = CLVR_SOURCE_DIR;
    path += "/data/";
    path += relative;
    return path;
}

FrameStats expectPacketsEqualPixels(Scene scene, const std::function<Image4f(const Scene&, FrameStats&)>& render,
                                    const std::vector<std::string>& keys, const std::string& label)
{
    scene.options["packets"] = true;
    Scene pixels = scene;
    pixels.options["packets"] = false;
    FrameStats ps, qs;
    const Image4f p = render(scene, ps);
    const Image4f q = render(pixels, qs);
    EXPECT_TRUE(sameBits(p, q)) << label;
    EXPECT_TRUE(ps.extra["packets"].get<bool>()) << label;
    EXPECT_FALSE(qs.extra["packets"].get<bool>()) << label;
    EXPECT_EQ(ps.samples, qs.samples) << label;
    for (const std::string& key : keys)
        EXPECT_EQ(ps.extra[key], qs.extra[key]) << label << ": " << key;
    return qs;
}

void expectSetCameraEqualsNewRenderer(Scene scene, const std::function<std::unique_ptr<Renderer>(const Scene&)>& make,
                                      const std::vector<Camera>& cameras, const std::string& label)
{
    ASSERT_FALSE(cameras.empty());
    scene.camera = cameras[0];
    std::unique_ptr<Renderer> moved = make(scene);
    FrameStats stats;
    moved->render(stats);
    for (std::size_t c = 1; c < cameras.size(); ++c) {
        scene.camera = cameras[c];
        ASSERT_TRUE(moved->setCamera(scene)) << label;
        const Image4f a = moved->render(stats);
        FrameStats fresh;
        EXPECT_TRUE(sameBits(a, make(scene)->render(fresh))) << label << " camera " << c;
    }
    Scene wider = scene;
    wider.image.width += 1;
    EXPECT_FALSE(moved->setCamera(wider)) << label;
}

void expectSetCameraEqualsNewRenderer(Scene scene, const Volume& volume, const std::vector<Camera>& cameras,
                                      const std::string& label)
{
    expectSetCameraEqualsNewRenderer(
        std::move(scene), [&](const Scene& s) { return makeRenderer(device(), s, volume); }, cameras, label);
}

int expectEarlyTermination(const Image4f& full, const Image4f& early, double threshold)
{
    EXPECT_EQ(full.width(), early.width());
    EXPECT_EQ(full.height(), early.height());
    int stopped = 0;
    for (int y = 0; y < full.height() && y < early.height(); ++y)
        for (int x = 0; x < full.width() && x < early.width(); ++x) {
            const glm::vec4 a = full.at(x, y), b = early.at(x, y);
            for (int k = 0; k < 4; ++k)
                EXPECT_LE(std::abs(a[k] - b[k]), 1.0 - threshold + 1e-5) << x << "," << y;
            if (a.a > threshold + 0.05) {
                EXPECT_GE(b.a, threshold - 1e-6) << x << "," << y;
                EXPECT_LE(b.a, a.a) << x << "," << y;
                stopped += b.a < a.a - 1e-3 ? 1 : 0;  // what lay behind the stop was left out
            } else if (a.a < threshold - 1e-3) {
                EXPECT_EQ(a, b) << x << "," << y;  // never stopped: the same bits
            }
        }
    return stopped;
}

testing::AssertionResult sameBits(const Image4f& a, const Image4f& b)
{
    if (a.width() != b.width() || a.height() != b.height())
        return testing::AssertionFailure() << "sizes differ: " << a.width() << "x" << a.height() << " against " << b.width()
                                           << "x" << b.height();
    for (std::size_t i = 0; i < a.pixelCount(); ++i)
        if (std::memcmp(&a.pixels()[i], &b.pixels()[i], sizeof(glm::vec4)) != 0) {
            const glm::vec4 u = a.pixels()[i], v = b.pixels()[i];
            return testing::AssertionFailure() << "pixel (" << i % a.width() << ", " << i / a.width() << ") differs: (" << u.r
                                               << ", " << u.g << ", " << u.b << ", " << u.a << ") against (" << v.r << ", "
                                               << v.g << ", " << v.b << ", " << v.a << ")";
        }
    return testing::AssertionSuccess();
}

testing::AssertionResult imagesNear(const Image4f& actual, const Image4d& expected, Tolerance tolerance)
{
    if (actual.width() != expected.width() || actual.height() != expected.height())
        return testing::AssertionFailure() << "size " << actual.width() << "x" << actual.height() << ", want "
                                           << expected.width() << "x" << expected.height();
    const ImageError e = imageError(actual, expected);
    std::ostringstream msg;
    bool ok = e.nanCount == 0;
    static const char* kChannel = "rgba";
    for (int c = 0; c < 4; ++c) {
        const bool channelOk = e.maxAbs[c] <= tolerance.maxAbs && e.meanAbs[c] <= tolerance.meanAbs;
        ok = ok && channelOk;
        if (!channelOk) {
            // Locate the worst pixel of this channel.
            double worst = -1.0;
            int wx = 0, wy = 0;
            std::size_t over = 0;
            for (int y = 0; y < actual.height(); ++y)
                for (int x = 0; x < actual.width(); ++x) {
                    const double d = std::abs(double(actual.at(x, y)[c]) - expected.at(x, y)[c]);
                    if (d > tolerance.maxAbs)
                        ++over;
                    if (d > worst) {
                        worst = d;
                        wx = x;
                        wy = y;
                    }
                }
            msg << "color." << kChannel[c] << ": max |diff| " << e.maxAbs[c] << " at (" << wx << ", " << wy
                << "): got " << actual.at(wx, wy)[c] << ", want " << expected.at(wx, wy)[c] << "; mean "
                << e.meanAbs[c] << "; " << over << " of " << actual.pixelCount() << " pixels over "
                << tolerance.maxAbs << " (mean limit " << tolerance.meanAbs << ")\n";
        }
    }
    if (ok)
        return testing::AssertionSuccess();
    msg << "NaN " << e.nanCount << "\n";
    const testing::TestInfo* info = testing::UnitTest::GetInstance()->current_test_info();
    const std::string dir = std::string("test_output/") + (info ? std::string(info->test_suite_name()) + "." + info->name() : "unknown");
    std::filesystem::create_directories(dir);
    Image4f expectedF(expected.width(), expected.height()), diff(expected.width(), expected.height());
    for (std::size_t i = 0; i < expected.pixelCount(); ++i) {
        expectedF.pixels()[i] = glm::vec4(expected.pixels()[i]);
        diff.pixels()[i] = glm::abs(actual.pixels()[i] - expectedF.pixels()[i]);
        diff.pixels()[i].a = 1.0f;
    }
    writeImage(dir + "/actual.exr", actual);
    writeImage(dir + "/expected.exr", expectedF);
    writeImage(dir + "/diff.exr", diff);
    msg << "wrote " << dir << "/{actual,expected,diff}.exr";
    return testing::AssertionFailure() << msg.str();
}

TempDir::TempDir()
{
    static int counter = 0;
    const testing::TestInfo* info = testing::UnitTest::GetInstance()->current_test_info();
    path_ = std::filesystem::temp_directory_path() /
            ("clvr-test-" + std::to_string(::getpid()) + "-" + std::to_string(counter++) + "-" +
             (info ? std::string(info->name()) : std::string("x")));
    std::filesystem::create_directories(path_);
}

TempDir::~TempDir()
{
    std::error_code ec;
    std::filesystem::remove_all(path_, ec);
}

void writeFile(const std::filesystem::path& path, const std::string& bytes)
{
    std::ofstream out(path, std::ios::binary);
    out.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
    ASSERT_TRUE(out.good()) << path;
}

std::string readFile(const std::filesystem::path& path)
{
    std::ifstream in(path, std::ios::binary);
    std::ostringstream s;
    s << in.rdbuf();
    return s.str();
}

std::string gzip(const std::string& data)
{
    z_stream z{};
    EXPECT_EQ(deflateInit2(&z, 6, Z_DEFLATED, 16 + MAX_WBITS, 8, Z_DEFAULT_STRATEGY), Z_OK);
    std::string out(deflateBound(&z, data.size()) + 64, '\0');
    z.next_in = reinterpret_cast<Bytef*>(const_cast<char*>(data.data()));
    z.avail_in = static_cast<uInt>(data.size());
    z.next_out = reinterpret_cast<Bytef*>(out.data());
    z.avail_out = static_cast<uInt>(out.size());
    EXPECT_EQ(deflate(&z, Z_FINISH), Z_STREAM_END);
    out.resize(z.total_out);
    deflateEnd(&z);
    return out;
}

testing::AssertionResult throwsInputError(const std::function<void()>& call, std::vector<std::string> pieces)
{
    try {
        call();
    } catch (const clvr::InputError& e) {
        const std::string what = e.what();
        if (what.find('\n') != std::string::npos)
            return testing::AssertionFailure() << "message has more than one line: " << what;
        for (const std::string& p : pieces)
            if (what.find(p) == std::string::npos)
                return testing::AssertionFailure() << "message lacks \"" << p << "\": " << what;
        return testing::AssertionSuccess() << what;
    } catch (const std::exception& e) {
        return testing::AssertionFailure() << "threw something other than InputError: " << e.what();
    }
    return testing::AssertionFailure() << "did not throw";
}

std::uint64_t Rng::next()
{
    std::uint64_t z = (state_ += 0x9e3779b97f4a7c15ull);
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ull;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebull;
    return z ^ (z >> 31);
}

double Rng::uniform(double lo, double hi)
{
    return lo + (hi - lo) * (static_cast<double>(next() >> 11) * 0x1.0p-53);
}

int Rng::integer(int lo, int hi)
{
    return lo + static_cast<int>(next() % static_cast<std::uint64_t>(hi - lo + 1));
}

bool atSilhouette(const std::function<bool(int, int)>& covered, int x, int y, int width, int height)
{
    for (int dy = -1; dy <= 1; ++dy)
        for (int dx = -1; dx <= 1; ++dx) {
            const int xx = x + dx, yy = y + dy;
            if (xx >= 0 && yy >= 0 && xx < width && yy < height && covered(xx, yy) != covered(x, y))
                return true;
        }
    return false;
}

}  // namespace clvr::test
