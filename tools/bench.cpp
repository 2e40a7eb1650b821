// tools/bench.cpp — `clvr bench` (DESIGN.md, "How results are judged": speed and peers), over
// clvr::Session (host/session.h) on one device shared by every scene. Steady-state frames with the data
// already on the device, compilation reported apart, median of several frames;
// the ceiling loops (tools/ceiling.h for slice3d, tools/ceiling_harc.h for harc) and VTK (tools/peer_vtk.py,
// tools/peer_vtk_unstructured.py for meshes) on the same scene in the same run.
#include "tools/bench.h"

#include "host/render/tet/tetiso.h"
#include "host/render/tet/tetslice.h"

#include "host/reference/image_error.h"
#include "host/reference/reference_integral.h"

#include "host/runtime/device.h"
#include "host/runtime/errors.h"
#include "host/io/image_io.h"
#include "host/model/mesh.h"
#include "host/render/renderer.h"
#include "host/runtime/parallel.h"
#include "host/model/scene.h"
#include "host/session.h"
#include "host/io/volume_io.h"
#include "host/render/scaffold.h"
#include "tools/bench_machine.h"
#include "tools/bench_mesh.h"
#include "tools/bench_raster.h"
#include "tools/ceiling.h"
#include "tools/ceiling_harc.h"
#include "tools/ceiling_cubefan.h"
#include "tools/ceiling_iso3d.h"
#include "tools/ceiling_projtet.h"
#include "tools/ceiling_spherical.h"
#include "tools/ceiling_stack2d.h"

#if __has_include("raster/rasterizer.h")
#include "raster/rasterizer.h"
#define CLVR_BENCH_RASTER 1
#else
#define CLVR_BENCH_RASTER 0
#endif

#include <nlohmann/json.hpp>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <ctime>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <iostream>
#include <map>
#include <sstream>
#include <thread>
#include <unistd.h>

namespace clvr::tools {
namespace {

namespace fs = std::filesystem;
using Clock = std::chrono::steady_clock;

struct Spread {
    double median = 0.0, min = 0.0, max = 0.0;
};

Spread spread(std::vector<double> v)
{
    if (v.empty())
        return {};
    std::sort(v.begin(), v.end());
    const std::size_t n = v.size();
    const double median = n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
    return {median, v.front(), v.back()};
}

// A file of the repository (data/scenes/bench/..., tools/peer_vtk.py): looked up from the current
// folder, then from the executable's folder and its parents (a build folder inside the repository).
// Per-channel absolute difference over R, G, B (VTK's PNG has no alpha).
struct ImageDiff {
    double mean = 0.0, max = 0.0;
};
ImageDiff imageDiff(const Image4f& a, const Image4f& b)
{
    if (a.width() != b.width() || a.height() != b.height())
        throw InputError("images to compare differ in size: " + std::to_string(a.width()) + "x" +
                         std::to_string(a.height()) + " and " + std::to_string(b.width()) + "x" +
                         std::to_string(b.height()));
    ImageDiff d;
    for (std::size_t i = 0; i < a.pixelCount(); ++i)
        for (int c = 0; c < 3; ++c) {
            const double e = std::abs(static_cast<double>(a.pixels()[i][c]) - b.pixels()[i][c]);
            d.mean += e;
            d.max = std::max(d.max, e);
        }
    d.mean /= 3.0 * std::max<std::size_t>(a.pixelCount(), 1);
    return d;
}

std::string fixed(double v, int digits)
{
    std::ostringstream s;
    s << std::fixed << std::setprecision(digits) << v;
    return s.str();
}

std::string si(double v)  // 1.23e+08 -> "123.0 M"
{
    const char* unit[] = {"", " k", " M", " G", " T"};
    int u = 0;
    while (std::abs(v) >= 1000.0 && u < 4) {
        v /= 1000.0;
        ++u;
    }
    return fixed(v, 1) + unit[u];
}

// Image error against the reference integral, as the tests measure it (host/reference/image_error.h): the
// mean and the max of the worst channel, over R, G, B and, when withAlpha, A.
nlohmann::json referenceError(const Image4f& image, const Image4d& want, bool withAlpha)
{
    if (image.width() != want.width() || image.height() != want.height())
        throw InputError("bench --reference: image and reference differ in size");
    const ImageError e = imageError(image, want);
    const int channels = withAlpha ? 4 : 3;
    double mean = 0.0, max = 0.0;
    for (int c = 0; c < channels; ++c) {
        mean = std::max(mean, e.meanAbs[c]);
        max = std::max(max, e.maxAbs[c]);
    }
    return {{"mean", mean}, {"max", max}, {"channels", withAlpha ? "rgba" : "rgb"}};
}

// The reference integral of a scene (host/reference/reference_integral.h; tolerance 1e-4: its own error
// is about a third of that, well below the errors it judges), kept per (volume, camera, transfer
// function, image) so that a suite of slice counts and integrations computes it once.
const Image4d& referenceImage(std::map<std::string, Image4d>& cache, const Scene& scene, const Volume& volume,
                              const Camera& camera, double& ms)
{
    std::uint64_t hash = 1469598103934665603ull;  // FNV-1a over the values' bits: the volume's identity
    std::vector<float> scratch;
    for (const float v : volume.floats(scratch)) {
        std::uint32_t bits;
        std::memcpy(&bits, &v, sizeof bits);
        hash = (hash ^ bits) * 1099511628211ull;
    }
    nlohmann::json key = {{"volume", {volume.dims.x, volume.dims.y, volume.dims.z, volume.origin.x, volume.origin.y,
                                      volume.origin.z, volume.spacing.x, volume.spacing.y, volume.spacing.z, hash}},
                          {"camera", {camera.position.x, camera.position.y, camera.position.z, camera.focalPoint.x,
                                      camera.focalPoint.y, camera.focalPoint.z, camera.viewUp.x, camera.viewUp.y,
                                      camera.viewUp.z, camera.viewAngle, camera.parallel, camera.parallelScale}},
                          {"image", {scene.image.width, scene.image.height, scene.image.background.x,
                                     scene.image.background.y, scene.image.background.z}},
                          {"tf", nlohmann::json::array()}};
    for (const ControlPoint& p : scene.transferFunction.points())
        key["tf"].push_back({p.s, p.color.r, p.color.g, p.color.b, p.tau});
    const std::string k = key.dump();
    ms = 0.0;
    if (auto it = cache.find(k); it != cache.end())
        return it->second;
    const auto t0 = Clock::now();
    ReferenceOptions options;
    options.tolerance = 1e-4;
    options.threads = 0;  // the thread budget
    Image4d image = referenceIntegral(volume, scene.transferFunction, camera, scene.image, options);
    ms = msSince(t0);
    return cache.emplace(k, std::move(image)).first->second;
}

// The plain C++ ceiling loop on the same scene, where there is one: slice3d's fused path (per-sample
// classification or pre-integrated slabs, a clip mesh or none; not a clip texture; the raster path counts
// fragments, not samples), stack2d's fused direct volume rendering (unshaded, no clip texture), spherical's fused
// path, cubefan's fused path, iso3d's fused path (unbricked) and raster path (bricked or not; gradient or no
// shading, no interior pass). Its frames are interleaved with clvr's (see bench()), so that both
// see the same load on a shared machine.
std::unique_ptr<VolumeCeiling> makeCeiling(const Scene& scene, const Volume& volume, const Camera& camera)
{
    if (scene.technique == slice3dTechnique().name) {
        CeilingScene cs;
        cs.camera = camera;
        cs.width = scene.image.width;
        cs.height = scene.image.height;
        cs.background = scene.image.background;
        cs.options = parseSlice3dOptions(scene.options);
        if (cs.options.path != Slice3dOptions::Path::Fused || cs.options.clipTexture)
            return nullptr;
        if (cs.options.clip)
            cs.clipMesh = loadClipMesh(cs.options.clip->mesh, scene.baseDir);
        return std::make_unique<Ceiling>(volume, scene.transferFunction, cs);
    }
    if (scene.technique == stack2dTechnique().name) {
        const Stack2dOptions options = parseStack2dOptions(scene.options);
        if (!stack2dCeilingFits(scene, options))
            return nullptr;
        return std::make_unique<Stack2dCeiling>(volume, scene.transferFunction, camera, scene.image, options);
    }
    if (scene.technique == sphericalTechnique().name) {
        const SphericalOptions options = parseSphericalOptions(scene.options);
        if (options.path != SphericalOptions::Path::Fused)
            return nullptr;
        return std::make_unique<SphericalCeiling>(volume, scene.transferFunction, camera, scene.image, options);
    }
    if (scene.technique == iso3dTechnique().name && scene.iso) {
        const Iso3dOptions options = parseIso3dOptions(scene.options);
        if (!iso3dCeilingFits(options, *scene.iso))
            return nullptr;
        return std::make_unique<Iso3dCeiling>(volume, scene, camera, options);
    }
    if (scene.technique == cubefanTechnique().name) {
        const CubefanOptions options = parseCubefanOptions(scene.options);
        if (options.path != CubefanOptions::Path::Fused)
            return nullptr;
        return std::make_unique<CubefanCeiling>(volume, scene.transferFunction, camera, scene.image, options);
    }
    return nullptr;
}

// What every ceiling report holds: the loop's threads and frame times (median, min, max, all), its image written
// beside clvr's and how far the two are apart.
nlohmann::json ceilingFrames(int threads, const std::vector<double>& ms, const Image4f& ceilingImage,
                             const Image4f& clvrImage, const fs::path& imagePath)
{
    const Spread s = spread(ms);
    writeImage(imagePath.string(), ceilingImage);
    const ImageDiff d = imageDiff(clvrImage, ceilingImage);
    return {{"threads", threads},
            {"frame_ms", s.median},
            {"frame_ms_min", s.min},
            {"frame_ms_max", s.max},
            {"frame_ms_all", ms},
            {"image", imagePath.string()},
            {"image_diff_vs_clvr", {{"mean", d.mean}, {"max", d.max}}}};
}

nlohmann::json ceilingReport(const VolumeCeiling& ceiling, int threads, const CeilingResult& result,
                             const std::vector<double>& ms, const Image4f& clvrImage, double clvrSamplesPerS,
                             const fs::path& imagePath)
{
    nlohmann::json r = ceilingFrames(threads, ms, result.image, clvrImage, imagePath);
    const double samplesPerS = result.samples / (r["frame_ms"].get<double>() * 1e-3);
    r.update({{"samples", result.samples},
              {"samples_per_s", samplesPerS},
              {"clvr_ratio", clvrSamplesPerS / samplesPerS}});
    r.update(ceiling.describe());
    return r;
}

// tools/peer_vtk.py under xvfb-run on the same scene; its figures, and its image against clvr's PNG.
nlohmann::json runPeer(const fs::path& scenePath, int frames, double sampleDistance, const fs::path& clvrPng,
                       const fs::path& outPrefix)
{
    const fs::path script = repoFile("tools/peer_vtk.py");
    const fs::path png = outPrefix.string() + ".vtk.png", json = outPrefix.string() + ".vtk.json";
    std::error_code ec;
    fs::remove(json, ec);
    std::ostringstream cmd;
    cmd << "xvfb-run -a /usr/bin/python3 '" << script.string() << "' '" << scenePath.string() << "' --frames "
        << frames << " --sample-distance " << std::setprecision(17) << sampleDistance << " --out-png '"
        << png.string() << "' --out-json '" << json.string() << "'";
    std::cout << "peer: " << cmd.str() << '\n' << std::flush;
    const int rc = std::system(cmd.str().c_str());
    std::ifstream in(json);
    if (rc != 0 || !in)
        return {{"error", "tools/peer_vtk.py failed (status " + std::to_string(rc) + "); command: " + cmd.str()}};
    nlohmann::json peer = nlohmann::json::parse(in);
    const ImageDiff d = imageDiff(readImage(clvrPng.string()), readImage(png.string()));
    peer["image"] = png.string();
    peer["image_diff_vs_clvr"] = {{"mean", d.mean}, {"max", d.max}};
    return peer;
}

// tools/peer_vtk_unstructured.py under xvfb-run on the scene clvr bench wrote for it (the mesh clvr
// loaded, as .vtk, and the camera it used); its figures, and its image against clvr's PNG.
nlohmann::json runMeshPeer(const fs::path& peerScene, int frames, const fs::path& clvrPng, const fs::path& outPrefix)
{
    const fs::path script = repoFile("tools/peer_vtk_unstructured.py");
    const fs::path png = outPrefix.string() + ".vtk.png", json = outPrefix.string() + ".vtk.json";
    std::error_code ec;
    fs::remove(json, ec);
    std::ostringstream cmd;
    cmd << "xvfb-run -a /usr/bin/python3 '" << script.string() << "' '" << peerScene.string() << "' --frames "
        << frames << " --out-png '" << png.string() << "' --out-json '" << json.string() << "'";
    std::cout << "  peer: " << cmd.str() << '\n' << std::flush;
    const int rc = std::system(cmd.str().c_str());
    std::ifstream in(json);
    if (rc != 0 || !in)
        return {{"error", "tools/peer_vtk_unstructured.py failed (status " + std::to_string(rc) + "); command: " +
                              cmd.str()}};
    nlohmann::json peer = nlohmann::json::parse(in);
    const ImageDiff d = imageDiff(readImage(clvrPng.string()), readImage(png.string()));
    peer["image"] = png.string();
    peer["image_diff_vs_clvr"] = {{"mean", d.mean}, {"max", d.max}};
    peer["image_diff_vs_clvr_8bit"] = {{"mean", 255.0 * d.mean}, {"max", 255.0 * d.max}};
    return peer;
}

// One tetrahedral-mesh scene: load (or TetGen, cached), set-up, a first frame, steady frames; the
// figures of seeds/001 Tables 2-3 (tools/bench_mesh.h); with --peer, VTK on the same tetrahedra.
nlohmann::json benchMeshScene(Device& device, const fs::path& scenePath, const Scene& sceneIn,
                              const BenchOptions& options, int frames, const fs::path& prefix)
{
    const std::string name = scenePath.stem().string();
    const Scene& scene = sceneIn;
    std::cout << name << " (" << scene.technique << ", " << scene.image.width << "x" << scene.image.height << ", "
              << scene.transferFunction.points().size() - 1 << " transfer-function segments)\n" << std::flush;
    const fs::path cacheDir = options.meshCache.empty() ? defaultMeshCacheDir() : fs::path(options.meshCache);
    SceneData data;
    const auto t0 = Clock::now();
    data.mesh = loadBenchMesh(scene, name, cacheDir, [](const std::string& line) {
        std::cout << "  " << line << '\n' << std::flush;
    });
    data.loadMs = msSince(t0);
    const double loadMs = data.loadMs;

    // As clvr render: a camera fitted to the whole mesh when the scene has none; the peer gets the same.
    const double compile0 = device.compileMs();
    Session session(device, scene, std::move(data), scenePath.string());
    const TetMesh& mesh = session.data().mesh;
    const Renderer* renderer = &session.renderer();
    const double setupMs = session.setupMs();
    const double firstFrameMs = session.render().wallMs;
    const double compileMs = device.compileMs() - compile0;

    // harc's ceiling loop (tools/ceiling_harc.h) walks the same entry lists and cells; its frames alternate
    // with clvr's, set beside the kernel's own pass (kHarcWalkPass), whose host entry stage it does not repeat.
    // tetslice's and tetiso's fused paths are harc's walk sampling slices or stopping at the first crossing: the
    // same loop with the options they hand harc.
    const bool isHarc = scene.technique == harcTechnique().name;
    const bool isFusedTetslice = scene.technique == tetsliceTechnique().name &&
                                 parseTetsliceOptions(scene.options).path == TetsliceOptions::Path::Fused;
    const bool isFusedTetiso = scene.technique == tetisoTechnique().name &&
                               parseTetisoOptions(scene.options).path == TetisoOptions::Path::Fused;
    const HarcOptions harcOptions = isHarc            ? parseHarcOptions(scene.options)
                                    : isFusedTetslice ? tetsliceWalkOptions(scene, mesh, parseTetsliceOptions(scene.options))
                                    : isFusedTetiso   ? tetisoWalkOptions(scene, mesh)
                                                      : HarcOptions{};
    std::unique_ptr<HarcCeiling> ceiling;
    if ((isHarc || isFusedTetslice || isFusedTetiso) && harcCeilingFits(mesh))
        ceiling = std::make_unique<HarcCeiling>(mesh, buildTopology(mesh), scene.transferFunction, session.camera(),
                                                scene.image, harcOptions);
    const int threads = threadBudget();
    HarcCeilingResult ceilingResult;
    if (ceiling)
        ceilingResult = ceiling->render(threads);  // warms its caches
    // projtet's ceiling loop (tools/ceiling_projtet.h): the projection and the draw, set beside the renderer's
    // passes that do that work (kProjtetDrawPasses: the raster path's or the fused path's), not its visibility sort.
    std::unique_ptr<ProjtetCeiling> projtetCeiling;
    ProjtetCeilingResult projtetResult;
    if (scene.technique == projtetTechnique().name) {
        projtetCeiling = std::make_unique<ProjtetCeiling>(mesh, buildTopology(mesh), scene.transferFunction,
                                                          session.camera(), scene.image, parseProjtetOptions(scene.options));
        projtetResult = projtetCeiling->render(threads);
    }
    static const char* const kProjtetDrawPasses[] = {"projtet: projection and classification (host)",
                                                     "projtet: raster set-up and binning (host)", "raster: fragments",
                                                     "projtet: cell boxes and tile lists (host)", "projtet: fused"};
    std::vector<double> drawMs;

    std::vector<double> ms, statsMs, walkMs, ceilingMs;
    FrameStats stats;
    Image4f image;
    for (int i = 0; i < frames; ++i) {
        Frame frame = session.render();
        ms.push_back(frame.wallMs);
        statsMs.push_back(frame.stats.frameMs);
        double draw = 0.0;
        for (const PassTime& p : frame.stats.passes) {
            if (p.name == kHarcWalkPass)
                walkMs.push_back(p.ms);
            for (const char* pass : kProjtetDrawPasses)
                draw += p.name == pass ? p.ms : 0.0;
        }
        drawMs.push_back(draw);
        stats = std::move(frame.stats);
        image = std::move(frame.image);
        if (ceiling) {
            const auto c0 = Clock::now();
            ceilingResult = ceiling->render(threads);
            ceilingMs.push_back(msSince(c0));
        }
        if (projtetCeiling) {
            const auto c0 = Clock::now();
            projtetResult = projtetCeiling->render(threads);
            ceilingMs.push_back(msSince(c0));
        }
    }
    const Spread s = spread(ms);
    const MeshFigures f = meshFigures(stats.extra, s.median);
    const fs::path clvrPng = prefix.string() + ".clvr.png";
    writeImage(clvrPng.string(), image);

    nlohmann::json r = {{"scene", scenePath.string()},
                        {"name", name},
                        {"technique", scene.technique},
                        {"kind", "mesh"},
                        {"width", scene.image.width},
                        {"height", scene.image.height},
                        {"mesh_source", mesh.source},
                        {"points", mesh.points.size()},
                        {"tf_control_points", scene.transferFunction.points().size()},
                        {"tf_segments", scene.transferFunction.points().size() - 1},
                        {"camera", cameraJson(session.camera())},
                        {"load_average", loadAverage()},
                        {"load_ms", loadMs},
                        {"setup_ms", setupMs},
                        {"compile_ms", compileMs},
                        {"first_frame_ms", firstFrameMs},
                        {"frame_ms", s.median},
                        {"frame_ms_min", s.min},
                        {"frame_ms_max", s.max},
                        {"frame_ms_all", ms},
                        {"frame_ms_renderer", spread(statsMs).median},
                        {"fps", f.fps},
                        {"tets", f.tets},
                        {"tets_per_s", f.tetsPerS},
                        {"steps", f.steps},
                        {"steps_per_s", f.stepsPerS},
                        {"bytes_per_tet", f.bytesPerTet},
                        {"resident_bytes", renderer->residentBytes()},
                        {"integration", stats.extra.value("integration", std::string("-"))},
                        {"image", clvrPng.string()},
                        {"extra", stats.extra}};
    r["passes"] = nlohmann::json::array();
    for (const PassTime& p : stats.passes)
        r["passes"].push_back({{"name", p.name}, {"ms", p.ms}});

    std::cout << "  mesh         " << mesh.source << ": " << mesh.points.size() << " points, " << f.tets
              << " tetrahedra, loaded in " << fixed(loadMs, 0) << " ms\n"
              << "  frame        " << fixed(s.median, 1) << " ms median (min " << fixed(s.min, 1) << ", max "
              << fixed(s.max, 1) << ", " << frames << " frames), " << fixed(f.fps, 2) << " frames/s ("
              << r["integration"].get<std::string>() << " integration)\n"
              << "  throughput   " << si(f.tetsPerS) << " tet/s, " << si(f.stepsPerS) << " steps/s ("
              << si(static_cast<double>(f.steps)) << " steps per frame)\n"
              << "  first frame  " << fixed(firstFrameMs, 1) << " ms, after set-up " << fixed(setupMs, 1)
              << " ms; kernel compile " << fixed(compileMs, 1) << " ms of the two\n"
              << "  resident     " << fixed(f.bytesPerTet, 1) << " bytes/tet ("
              << si(static_cast<double>(renderer->residentBytes())) << "B)\n"
              << "  passes      ";
    for (const PassTime& p : stats.passes)
        std::cout << ' ' << p.name << ' ' << fixed(p.ms, 1) << " ms;";
    std::cout << " (last frame)\n" << std::flush;

    if (ceiling && !walkMs.empty()) {
        nlohmann::json& c = r["ceiling"] =
            ceilingFrames(threads, ceilingMs, ceilingResult.image, image, prefix.string() + ".ceiling.png");
        const double loopMs = c["frame_ms"].get<double>(), walk = spread(walkMs).median;
        const double walkStepsPerS = static_cast<double>(f.steps) / (walk * 1e-3);
        const double ceilingStepsPerS = static_cast<double>(ceilingResult.steps) / (loopMs * 1e-3);
        c.update({{"steps", ceilingResult.steps},
                  {"pieces", ceilingResult.pieces},
                  {"steps_per_s", ceilingStepsPerS},
                  {"clvr_walk_ms", walk},
                  {"clvr_walk_ms_all", walkMs},
                  {"clvr_walk_steps_per_s", walkStepsPerS},
                  {"clvr_ratio", walkStepsPerS / ceilingStepsPerS}});
        std::cout << "  ceiling      walk " << fixed(loopMs, 1) << " ms, " << si(ceilingStepsPerS) << " steps/s ("
                  << threads << " threads, interleaved with clvr's); clvr's walk pass " << fixed(walk, 1) << " ms, "
                  << si(walkStepsPerS) << " steps/s: " << fixed(100.0 * walkStepsPerS / ceilingStepsPerS, 1)
                  << "% of it; steps " << ceilingResult.steps << " vs " << f.steps << ", image |diff| max "
                  << fixed(c["image_diff_vs_clvr"]["max"].get<double>(), 4) << ", mean "
                  << fixed(c["image_diff_vs_clvr"]["mean"].get<double>(), 5) << '\n'
                  << std::flush;
    }

    if (projtetCeiling) {
        nlohmann::json& c = r["ceiling"] =
            ceilingFrames(threads, ceilingMs, projtetResult.image, image, prefix.string() + ".ceiling.png");
        const double loopMs = c["frame_ms"].get<double>(), draw = spread(drawMs).median;
        c.update({{"pixels_tested", projtetResult.pixelsTested},
                  {"segments", projtetResult.segments},
                  {"clvr_draw_ms", draw},
                  {"clvr_draw_ms_all", drawMs},
                  {"clvr_ratio", loopMs / draw}});
        std::cout << "  ceiling      projection and draw " << fixed(loopMs, 1) << " ms (" << threads
                  << " threads, interleaved with clvr's; " << si(static_cast<double>(projtetResult.segments))
                  << " segments of " << si(static_cast<double>(projtetResult.pixelsTested))
                  << " pixels tested); clvr's projection and draw " << fixed(draw, 1) << " ms: "
                  << fixed(100.0 * loopMs / draw, 1) << "% of its speed; image |diff| max "
                  << fixed(c["image_diff_vs_clvr"]["max"].get<double>(), 4) << ", mean "
                  << fixed(c["image_diff_vs_clvr"]["mean"].get<double>(), 5) << '\n'
                  << std::flush;
    }

    if (options.peer) {
        const fs::path peerScene = prefix.string() + ".peer.json", peerMesh = prefix.string() + ".mesh.vtk";
        writePeerMeshScene(session.scene(), mesh, session.camera(), peerMesh, peerScene);
        nlohmann::json peer = runMeshPeer(peerScene, options.peerFrames > 0 ? options.peerFrames : frames, clvrPng,
                                          prefix);
        if (peer.contains("frame_ms")) {
            peer["clvr_speedup"] = peer["frame_ms"].get<double>() / s.median;
            peer["tets_per_s"] = static_cast<double>(f.tets) * 1000.0 / peer["frame_ms"].get<double>();
            std::cout << "  VTK          " << fixed(peer["frame_ms"].get<double>(), 1) << " ms ("
                      << peer.value("mapper", std::string("?")) << ", " << si(peer["tets_per_s"].get<double>())
                      << " tet/s); clvr " << fixed(peer["clvr_speedup"].get<double>(), 2)
                      << "x faster; image |diff| (8-bit levels) mean "
                      << fixed(peer["image_diff_vs_clvr_8bit"]["mean"].get<double>(), 2) << ", max "
                      << fixed(peer["image_diff_vs_clvr_8bit"]["max"].get<double>(), 0) << '\n';
        } else {
            std::cout << "  VTK          " << peer.value("error", std::string("failed")) << '\n';
        }
        r["peer"] = peer;
    }
    std::cout << '\n';
    return r;
}

// The cubefan scenes as seeds/002's Figure 9 (and the paper's own rows, GeForce 2, 256x256x110), with the
// image error against the group's first scene, and the other scenes of the run (slice3d) beside.
void printCubefanTable(const nlohmann::json& scenes)
{
    bool any = false;
    for (const nlohmann::json& r : scenes)
        any = any || r["technique"] == "cubefan";
    if (!any)
        return;
    std::ostringstream table;
    table << std::left << std::setw(26) << "scene" << std::right << std::setw(7) << "error" << std::setw(10) << "cubes"
          << std::setw(11) << "triangles" << std::setw(11) << "select ms" << std::setw(11) << "render ms"
          << std::setw(10) << "frame ms" << std::setw(13) << "|diff| mean" << std::setw(12) << "|diff| max" << '\n';
    for (const nlohmann::json& r : scenes) {
        if (r.value("kind", std::string()) == "mesh")
            continue;
        const nlohmann::json& e = r["extra"];
        const bool cubefan = r["technique"] == "cubefan";
        const double selection = cubefan ? e["selection_ms"].get<double>() : 0.0;
        table << std::left << std::setw(26) << r["name"].get<std::string>() << std::right << std::setw(7)
              << (cubefan ? fixed(100.0 * e["error"].get<double>(), 0) + " %" : std::string("-")) << std::setw(10)
              << (cubefan ? si(e["cubes"].get<double>()) : std::string("-")) << std::setw(11)
              << (cubefan && e.contains("triangles") ? si(e["triangles"].get<double>()) : std::string("-")) << std::setw(11)
              << (cubefan ? fixed(selection, 1) : std::string("-")) << std::setw(11)
              << fixed(r["frame_ms"].get<double>() - selection, 1) << std::setw(10) << fixed(r["frame_ms"].get<double>(), 1);
        if (r.contains("image_diff_vs_group_first"))
            table << std::setw(13) << fixed(r["image_diff_vs_group_first"]["mean"].get<double>(), 5) << std::setw(12)
                  << fixed(r["image_diff_vs_group_first"]["max"].get<double>(), 4);
        else
            table << std::setw(13) << "(first)";
        table << '\n';
    }
    table << std::left << std::setw(26) << "paper (GeForce 2) 0 %" << std::right << std::setw(7) << "0 %" << std::setw(10)
          << "5.20 M" << std::setw(11) << "-" << std::setw(11) << "850" << std::setw(11) << "37500" << '\n'
          << std::left << std::setw(26) << "paper (GeForce 2) 18 %" << std::right << std::setw(7) << "18 %"
          << std::setw(10) << "0.19 M" << std::setw(11) << "2.3 M" << std::setw(11) << "36" << std::setw(11) << "950" << '\n'
          << std::left << std::setw(26) << "paper (GeForce 2) 48 %" << std::right << std::setw(7) << "48 %"
          << std::setw(10) << "15.8 K" << std::setw(11) << "0.19 M" << std::setw(11) << "1.9" << std::setw(11) << "70" << '\n';
    std::cout << "cubefan (seeds/002 Figure 9; render ms = frame - selection, as the paper times it)\n" << table.str() << '\n';
}

// The mesh scenes side by side: the columns of seeds/001 Tables 2-3, and VTK's when it ran.
void printMeshTable(const nlohmann::json& scenes)
{
    std::ostringstream table;
    table << std::left << std::setw(22) << "mesh scene" << std::right << std::setw(9) << "tets" << std::setw(10)
          << "ms/frame" << std::setw(8) << "fps" << std::setw(10) << "tet/s" << std::setw(11) << "steps/s"
          << std::setw(10) << "bytes/tet" << std::setw(10) << "first ms" << std::setw(10) << "setup ms"
          << std::setw(10) << "VTK ms" << std::setw(8) << "x VTK" << "  integration" << '\n';
    int rows = 0;
    for (const nlohmann::json& r : scenes) {
        if (r.value("kind", std::string()) != "mesh")
            continue;
        ++rows;
        const bool peer = r.contains("peer") && r["peer"].contains("frame_ms");
        table << std::left << std::setw(22) << r["name"].get<std::string>() << std::right << std::setw(9)
              << r["tets"].get<std::uint64_t>() << std::setw(10) << fixed(r["frame_ms"].get<double>(), 1)
              << std::setw(8) << fixed(r["fps"].get<double>(), 2) << std::setw(10)
              << si(r["tets_per_s"].get<double>()) << std::setw(11) << si(r["steps_per_s"].get<double>())
              << std::setw(10) << fixed(r["bytes_per_tet"].get<double>(), 1) << std::setw(10)
              << fixed(r["first_frame_ms"].get<double>(), 0) << std::setw(10) << fixed(r["setup_ms"].get<double>(), 0)
              << std::setw(10) << (peer ? fixed(r["peer"]["frame_ms"].get<double>(), 0) : std::string("-"))
              << std::setw(8) << (peer ? fixed(r["peer"]["clvr_speedup"].get<double>(), 2) : std::string("-")) << "  "
              << r["integration"].get<std::string>() << '\n';
    }
    if (rows > 0)
        std::cout << table.str() << '\n';
}

#if CLVR_BENCH_RASTER
// raster::draw on a 512x512 frame buffer: 1000 random triangles (fixed seed, splitmix64), blended
// with SRC_ALPHA, ONE_MINUS_SRC_ALPHA, default fragment program; first draw apart, median of 5.
nlohmann::json rasterBench(Device& device)
{
    constexpr int kSize = 512, kTriangles = 1000, kDraws = 5;
    std::uint64_t state = 0x9e3779b97f4a7c15ull;
    auto uniform = [&state] {  // splitmix64 -> [0, 1)
        std::uint64_t z = (state += 0x9e3779b97f4a7c15ull);
        z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ull;
        z = (z ^ (z >> 27)) * 0x94d049bb133111ebull;
        return static_cast<float>((z ^ (z >> 31)) >> 40) / static_cast<float>(1 << 24);
    };
    std::vector<raster::Vertex> vertices;
    for (int t = 0; t < kTriangles; ++t) {
        const glm::vec2 center(uniform() * 2.0f - 1.0f, uniform() * 2.0f - 1.0f);
        const float radius = 0.05f + 0.25f * uniform();  // NDC units
        const glm::vec4 color(uniform(), uniform(), uniform(), 0.2f + 0.6f * uniform());
        for (int v = 0; v < 3; ++v) {
            const float angle = 6.2831853f * (v / 3.0f + 0.2f * uniform());
            raster::Vertex vertex;
            vertex.position = glm::vec4(center + radius * glm::vec2(std::cos(angle), std::sin(angle)),
                                        uniform() * 2.0f - 1.0f, 1.0f);
            vertex.attributes[0] = color;
            vertices.push_back(vertex);
        }
    }
    raster::DrawState drawState;
    drawState.fragment.blend.enabled = true;
    drawState.fragment.blend.srcRgb = drawState.fragment.blend.srcAlpha = raster::BlendFactor::SrcAlpha;
    drawState.fragment.blend.dstRgb = drawState.fragment.blend.dstAlpha = raster::BlendFactor::OneMinusSrcAlpha;
    raster::Framebuffer fb(device, kSize, kSize);
    fb.clearColor(device, glm::vec4(0.0f));
    const double compile0 = device.compileMs();
    auto t0 = Clock::now();
    raster::DrawStats stats = raster::draw(device, fb, drawState, raster::Topology::Triangles, vertices);
    const double firstMs = msSince(t0);
    const double compileMs = device.compileMs() - compile0;
    std::vector<double> ms;
    for (int i = 0; i < kDraws; ++i) {
        t0 = Clock::now();
        stats = raster::draw(device, fb, drawState, raster::Topology::Triangles, vertices);
        device.queue().finish();
        ms.push_back(msSince(t0));
    }
    device.takePassTimes();
    const Spread s = spread(ms);
    return {{"width", kSize},
            {"height", kSize},
            {"triangles", stats.triangles},
            {"fragments", stats.fragments},
            {"first_draw_ms", firstMs},
            {"compile_ms", compileMs},
            {"draw_ms", s.median},
            {"draw_ms_min", s.min},
            {"draw_ms_max", s.max},
            {"triangles_per_s", stats.triangles / (s.median * 1e-3)},
            {"fragments_per_s", stats.fragments / (s.median * 1e-3)}};
}
#endif

}  // namespace

std::filesystem::path repoFile(const std::filesystem::path& relative)
{
    if (fs::exists(relative))
        return relative;
    std::error_code ec;
    fs::path dir = fs::read_symlink("/proc/self/exe", ec).parent_path();
    for (int up = 0; !ec && up < 4 && !dir.empty(); ++up, dir = dir.parent_path())
        if (fs::exists(dir / relative))
            return dir / relative;
    throw InputError(relative.string() + ": not found in the current folder or above the clvr executable "
                     "(run clvr bench from the repository root, or name the scene files)");
}

int bench(const BenchOptions& options)
{
    if (options.suite == "raster" && options.scenes.empty())
        return benchRaster(options);
    if (options.suite == "cluster")
        return benchCluster(options);
    std::vector<fs::path> scenes(options.scenes.begin(), options.scenes.end());
    if (scenes.empty())
        for (const std::string& name : benchSuiteScenes(options.suite))
            scenes.push_back(repoFile(fs::path("data/scenes/bench") / name));
    const int frames = std::max(options.frames, 5);
    const fs::path outJson = options.outJson;
    const fs::path outDir = outJson.has_parent_path() ? outJson.parent_path() : fs::path(".");
    fs::create_directories(outDir);

    Device device(options.deviceSpec);
    nlohmann::json report;
    const char* poclCache = std::getenv("POCL_CACHE_DIR");
    report["machine"] = {{"device", device.description()},
                         {"device_name", device.listing().name},
                         {"device_version", device.listing().version},
                         {"platform", device.listing().platform},
                         {"platform_version",
                          cl::Platform(device.device().getInfo<CL_DEVICE_PLATFORM>()).getInfo<CL_PLATFORM_VERSION>()},
                         {"device_compute_units", device.listing().computeUnits},
                         {"cpu", cpuModel()},
                         {"cores", std::thread::hardware_concurrency()},
                         {"thread_budget", threadBudget()},
                         {"date", utcNow()},
                         {"load_average_start", loadAverage()},
                         {"pocl_cache_dir", poclCache ? poclCache : "default (~/.cache/pocl)"}};
    report["frames"] = frames;
    report["overrides"] = options.overrides;
    report["scenes"] = nlohmann::json::array();
    bool anyVolume = false;  // the raster-stage figures go with the regular-grid scenes
    // Suites that trade image quality for speed (cubefan): the first scene of a group (its name up to the
    // last '-') is the group's full-quality image, and every later one is compared with it.
    std::map<std::string, std::pair<std::string, Image4f>> groupFirst;
    std::map<std::string, Image4d> references;  // --reference, by scene content
    std::cout << "clvr bench on " << device.description() << "\nplatform "
              << report["machine"]["platform_version"].get<std::string>() << "\nCPU " << cpuModel() << ", "
              << std::thread::hardware_concurrency() << " cores, " << utcNow() << ", load average "
              << loadAverage() << "\n\n";

    for (const fs::path& scenePath : scenes) {
        const std::string name = scenePath.stem().string();
        const fs::path prefix = outDir / ("bench." + name);
        const Scene scene = loadScene(scenePath, options.overrides, options.unsets);
        if (scene.mesh) {
            report["scenes"].push_back(benchMeshScene(device, scenePath, scene, options, frames, prefix));
            continue;
        }
        anyVolume = true;
        const double compile0 = device.compileMs();
        Session session(device, scene, loadSceneData(scene), scenePath.string());
        const Volume& volume = session.data().volume;
        const Camera& camera = session.camera();
        const Renderer* renderer = &session.renderer();
        const double setupMs = session.setupMs();
        const double firstFrameMs = session.render().wallMs;
        const double compileMs = device.compileMs() - compile0;

        // The ceiling's first frame warms its caches; then clvr and ceiling frames alternate.
        const std::unique_ptr<VolumeCeiling> ceiling = makeCeiling(scene, volume, camera);
        const int threads = threadBudget();
        CeilingResult ceilingResult;
        if (ceiling)
            ceilingResult = ceiling->render(threads);

        std::vector<double> ms, statsMs, ceilingMs;
        FrameStats stats;
        Image4f image;
        for (int i = 0; i < frames; ++i) {
            Frame frame = session.render();
            ms.push_back(frame.wallMs);
            statsMs.push_back(frame.stats.frameMs);
            stats = std::move(frame.stats);
            image = std::move(frame.image);
            if (ceiling) {
                const auto t0 = Clock::now();
                ceilingResult = ceiling->render(threads);
                ceilingMs.push_back(msSince(t0));
            }
        }
        const Spread s = spread(ms);
        const double samplesPerS = stats.samples / (s.median * 1e-3);
        const std::uint64_t resident = renderer->residentBytes();
        const fs::path clvrPng = prefix.string() + ".clvr.png";
        writeImage(clvrPng.string(), image);

        nlohmann::json r = {
            {"scene", scenePath.string()},
            {"name", name},
            {"technique", scene.technique},
            {"width", scene.image.width},
            {"height", scene.image.height},
            {"dims", {volume.dims.x, volume.dims.y, volume.dims.z}},
            {"voxels", volume.voxelCount()},
            {"setup_ms", setupMs},
            {"compile_ms", compileMs},
            {"first_frame_ms", firstFrameMs},
            {"frame_ms", s.median},
            {"frame_ms_min", s.min},
            {"frame_ms_max", s.max},
            {"frame_ms_all", ms},
            {"frame_ms_renderer", spread(statsMs).median},
            {"fps", 1000.0 / s.median},
            {"samples", stats.samples},
            {"samples_per_s", samplesPerS},
            {"resident_bytes", resident},
            {"bytes_per_voxel", static_cast<double>(resident) / volume.voxelCount()},
            {"image", clvrPng.string()},
            {"extra", stats.extra}};
        r["passes"] = nlohmann::json::array();
        for (const PassTime& p : stats.passes)
            r["passes"].push_back({{"name", p.name}, {"ms", p.ms}});

        std::cout << name << " (" << scene.technique << ", " << volume.dims.x << "x" << volume.dims.y << "x"
                  << volume.dims.z << ", " << scene.image.width << "x" << scene.image.height << ")\n"
                  << "  frame        " << fixed(s.median, 1) << " ms median (min " << fixed(s.min, 1) << ", max "
                  << fixed(s.max, 1) << ", " << frames << " frames), " << fixed(1000.0 / s.median, 2) << " frames/s\n"
                  << "  samples      " << si(static_cast<double>(stats.samples)) << " per frame, "
                  << si(samplesPerS) << " samples/s\n"
                  << "  first frame  " << fixed(firstFrameMs, 1) << " ms, after set-up " << fixed(setupMs, 1)
                  << " ms; kernel compile " << fixed(compileMs, 1) << " ms of the two\n"
                  << "  resident     " << fixed(static_cast<double>(resident) / volume.voxelCount(), 2)
                  << " bytes/voxel (" << si(static_cast<double>(resident)) << "B)\n"
                  << std::flush;

        if (ceiling) {
            r["ceiling"] = ceilingReport(*ceiling, threads, ceilingResult, ceilingMs, image, samplesPerS,
                                         prefix.string() + ".ceiling.png");
            nlohmann::json& c = r["ceiling"];
            // The frame times side by side too: where the loop counts other samples than clvr (iso3d's raster
            // path: the fragments up to each hit), that is the figure to read.
            c["clvr_time_ratio"] = c["frame_ms"].get<double>() / s.median;
            std::cout << "  ceiling      " << fixed(c["frame_ms"].get<double>(), 1) << " ms, "
                      << si(c["samples_per_s"].get<double>()) << " samples/s (" << c["threads"].get<int>()
                      << " threads, interleaved with clvr's); clvr at " << fixed(100.0 * c["clvr_ratio"].get<double>(), 1)
                      << "% of it per sample, " << fixed(100.0 * c["clvr_time_ratio"].get<double>(), 1)
                      << "% of its speed by frame time; image |diff| max " << fixed(c["image_diff_vs_clvr"]["max"].get<double>(), 4)
                      << ", mean " << fixed(c["image_diff_vs_clvr"]["mean"].get<double>(), 5) << '\n'
                      << std::flush;
        }
        if (options.peer) {
            // VTK samples at clvr's slice spacing (slice3d reports it; other techniques: slice3d's default plan).
            const double sampleDistance =
                stats.extra.contains("slice_spacing")
                    ? stats.extra["slice_spacing"].get<double>()
                    : planSlices(camera, volume.boundsMin(), volume.boundsMax(), Slice3dOptions{}).deltaS;
            nlohmann::json peer = runPeer(scenePath, options.peerFrames > 0 ? options.peerFrames : frames,
                                          sampleDistance, clvrPng, prefix);
            if (peer.contains("frame_ms")) {
                peer["clvr_speedup"] = peer["frame_ms"].get<double>() / s.median;
                std::cout << "  VTK          " << fixed(peer["frame_ms"].get<double>(), 1) << " ms ("
                          << peer.value("mapper", std::string("?")) << "); clvr "
                          << fixed(peer["clvr_speedup"].get<double>(), 2) << "x faster; image |diff| mean "
                          << fixed(peer["image_diff_vs_clvr"]["mean"].get<double>(), 4) << ", max "
                          << fixed(peer["image_diff_vs_clvr"]["max"].get<double>(), 4) << '\n';
            } else {
                std::cout << "  VTK          " << peer.value("error", std::string("failed")) << '\n';
            }
            r["peer"] = peer;
        }
        if (options.reference && scene.technique == slice3dTechnique().name) {
            double referenceMs = 0.0;
            const Image4d& want = referenceImage(references, scene, volume, camera, referenceMs);
            r["error_vs_reference"] = referenceError(image, want, true);
            r["error_vs_reference_png"] = referenceError(readImage(clvrPng.string()), want, false);
            r["reference_ms"] = referenceMs;
            std::cout << "  reference    |image - exact integral| mean " << std::scientific << std::setprecision(2)
                      << r["error_vs_reference"]["mean"].get<double>() << ", max "
                      << r["error_vs_reference"]["max"].get<double>() << " (8-bit PNG: mean "
                      << r["error_vs_reference_png"]["mean"].get<double>() << ")" << std::defaultfloat;
            if (r.contains("peer") && r["peer"].contains("image")) {
                r["peer"]["error_vs_reference_png"] =
                    referenceError(readImage(r["peer"]["image"].get<std::string>()), want, false);
                std::cout << "; VTK's PNG: mean " << std::scientific << std::setprecision(2)
                          << r["peer"]["error_vs_reference_png"]["mean"].get<double>() << std::defaultfloat;
            }
            std::cout << (referenceMs > 0.0 ? "; computed in " + fixed(referenceMs / 1000.0, 1) + " s" : "") << '\n';
        }
        const std::string group = name.substr(0, name.rfind('-'));
        if (auto it = groupFirst.find(group); it == groupFirst.end()) {
            groupFirst.emplace(group, std::make_pair(name, image));
        } else {
            const ImageDiff d = imageDiff(image, it->second.second);
            r["image_diff_vs_group_first"] = {{"first", it->second.first}, {"mean", d.mean}, {"max", d.max}};
            std::cout << "  vs " << it->second.first << "  image |diff| mean " << fixed(d.mean, 5) << ", max "
                      << fixed(d.max, 4) << '\n';
        }
        if (scene.technique == "cubefan") {
            // seeds/002 Figure 9: rendering time excludes the selection, as the paper's does.
            const nlohmann::json& e = stats.extra;
            std::cout << "  figure 9     error " << fixed(100.0 * e["error"].get<double>(), 0) << " %: "
                      << si(e["cubes"].get<double>()) << " cubes, "
                      << (e.contains("triangles") ? si(e["triangles"].get<double>()) + " triangles"
                                                  : si(e["cubes_crossed"].get<double>()) + " cube chords (" +
                                                        e["path"].get<std::string>() + ")")
                      << ", selection " << fixed(e["selection_ms"].get<double>(), 1) << " ms, rendering "
                      << fixed(s.median - e["selection_ms"].get<double>(), 1) << " ms; hierarchy built in "
                      << fixed(e["hierarchy_ms"].get<double>(), 0) << " ms";
            if (e.contains("selection_grid_ms"))  // the fused and tile paths select when the tolerance or TF changes
                std::cout << ", selection " << (e["path"] == "tiles" ? "tree" : "grid") << " in "
                          << fixed(e["selection_grid_ms"].get<double>(), 0) << " ms";
            std::cout << '\n';
        }
        std::cout << '\n';
        report["scenes"].push_back(r);
    }

#if CLVR_BENCH_RASTER
    if (!anyVolume) {
        report["raster"] = {{"skipped", "tetrahedral-mesh scenes only"}};
    } else {
        report["raster"] = rasterBench(device);
        const nlohmann::json& r = report["raster"];
        std::cout << "raster (raster::draw, 512x512, 1000 random blended triangles)\n"
                  << "  draw         " << fixed(r["draw_ms"].get<double>(), 2) << " ms median (first "
                  << fixed(r["first_draw_ms"].get<double>(), 1) << " ms, compile "
                  << fixed(r["compile_ms"].get<double>(), 1) << " ms)\n"
                  << "  throughput   " << si(r["triangles_per_s"].get<double>()) << " triangles/s, "
                  << si(r["fragments_per_s"].get<double>()) << " fragments/s (" << r["fragments"].get<std::uint64_t>()
                  << " fragments per draw)\n\n";
    }
#else
    report["raster"] = {{"skipped", "raster/rasterizer.h not wired into clvr bench yet"}};
#endif

    printMeshTable(report["scenes"]);
    printCubefanTable(report["scenes"]);
    report["machine"]["load_average_end"] = loadAverage();
    std::ofstream out(outJson);
    if (!out)
        throw InputError(outJson.string() + ": cannot write");
    out << report.dump(2) << '\n';
    if (!out)
        throw InputError(outJson.string() + ": write failed");
    std::cout << "wrote " << outJson.string() << '\n';
    return 0;
}

}  // namespace clvr::tools
