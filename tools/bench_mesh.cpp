// tools/bench_mesh.cpp — the tetrahedral-mesh side of `clvr bench`: figures from a frame's stats, the
// TetGen mesh cache and the peer's files (tools/bench_mesh.h).
#include "tools/bench_mesh.h"

#include "host/runtime/errors.h"
#include "host/io/mesh_io.h"

#include <cstdio>
#include <fstream>
#include <iterator>
#include <sstream>
#include <unistd.h>

namespace clvr::tools {

namespace fs = std::filesystem;

namespace {

// FNV-1a, 64 bit: a cache name, not a security boundary.
void fnv1a(std::uint64_t& h, const std::string& bytes)
{
    for (const unsigned char c : bytes) {
        h ^= c;
        h *= 0x100000001b3ull;
    }
}

std::string readBytes(const fs::path& path)
{
    std::ifstream in(path, std::ios::binary);
    if (!in)
        throw InputError(path.string() + ": cannot read (mesh cache key)");
    return std::string(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
}

std::uint64_t count(const nlohmann::json& extra, const char* key)
{
    if (!extra.contains(key) || !extra[key].is_number())
        throw InputError(std::string("frame stats have no numeric \"") + key + "\" (not a mesh technique?)");
    return extra[key].get<std::uint64_t>();
}

}  // namespace

MeshFigures meshFigures(const nlohmann::json& extra, double frameMs)
{
    if (!(frameMs > 0.0))
        throw InputError("frame time must be positive, got " + std::to_string(frameMs) + " ms");
    if (!extra.contains("bytes_per_tet") || !extra["bytes_per_tet"].is_number())
        throw InputError("frame stats have no numeric \"bytes_per_tet\" (not a mesh technique?)");
    MeshFigures f;
    f.tets = count(extra, "tets_rendered");
    const char* unit = extra.contains("steps")            ? "steps"
                       : extra.contains("cells_drawn")      ? "cells_drawn"
                       : extra.contains("raster_fragments") ? "raster_fragments"
                                                            : "steps";
    f.steps = count(extra, unit);
    f.frameMs = frameMs;
    f.fps = 1000.0 / frameMs;
    f.tetsPerS = static_cast<double>(f.tets) * f.fps;
    f.stepsPerS = static_cast<double>(f.steps) / (frameMs * 1e-3);
    f.bytesPerTet = extra["bytes_per_tet"].get<double>();
    return f;
}

std::uint64_t meshCacheKey(const MeshSpec& spec)
{
    char options[96];
    std::snprintf(options, sizeof options, "quality %.17g max_volume %.17g ", spec.quality, spec.maxVolume);
    std::uint64_t h = 0xcbf29ce484222325ull;
    fnv1a(h, spec.surface.string() + "\n" + options + spec.scalar);
    fnv1a(h, readBytes(spec.surface));
    std::error_code ec;
    if (fs::is_regular_file(spec.scalar, ec))  // a volume the scalar is sampled from (resolved by parseMeshSpec)
        fnv1a(h, readBytes(spec.scalar));
    return h;
}

fs::path defaultMeshCacheDir()
{
    std::error_code ec;
    const fs::path exe = fs::read_symlink("/proc/self/exe", ec);
    return ec ? fs::path("bench-data") : exe.parent_path() / "bench-data";
}

TetMesh loadBenchMesh(const Scene& scene, const std::string& name, const fs::path& cacheDir,
                      const std::function<void(const std::string&)>& progress)
{
    if (!scene.mesh)
        throw InternalError("loadBenchMesh: the scene has no mesh");
    const MeshSpec& spec = *scene.mesh;
    if (spec.kind != MeshSpec::Kind::Surface)
        return loadMesh(spec);

    char hex[17];
    std::snprintf(hex, sizeof hex, "%016llx", static_cast<unsigned long long>(meshCacheKey(spec)));
    const fs::path base = cacheDir / (name + "-" + hex);
    const fs::path node = base.string() + ".node";
    std::error_code ec;
    if (fs::exists(node, ec)) {
        TetMesh mesh = readTetgen(base);
        checkMesh(mesh);
        return mesh;
    }

    progress("meshing " + spec.surface.string() + " with TetGen (quality " + std::to_string(spec.quality) +
             ", max_volume " + std::to_string(spec.maxVolume) + ", scalar " + spec.scalar +
             "); kept as " + base.string() + ".{node,ele,neigh} for the next run");
    TetMesh mesh = loadMesh(spec);
    fs::create_directories(cacheDir);
    // Written under a temporary name and renamed, the .node last: a cache entry whose .node exists is whole.
    const fs::path temp = base.string() + ".tmp" + std::to_string(::getpid());
    writeTetgen(mesh, temp);
    for (const char* ext : {".neigh", ".ele", ".node"}) {
        fs::rename(temp.string() + ext, base.string() + ext, ec);
        if (ec)
            throw InputError(base.string() + ext + ": cannot rename the mesh cache file into place: " + ec.message());
    }
    return mesh;
}

nlohmann::json cameraJson(const Camera& camera)
{
    nlohmann::json c = {{"position", {camera.position.x, camera.position.y, camera.position.z}},
                        {"focal_point", {camera.focalPoint.x, camera.focalPoint.y, camera.focalPoint.z}},
                        {"view_up", {camera.viewUp.x, camera.viewUp.y, camera.viewUp.z}}};
    if (camera.parallel) {
        c["projection"] = "parallel";
        c["parallel_scale"] = camera.parallelScale;
    } else {
        c["view_angle"] = camera.viewAngle;
    }
    return c;
}

void writePeerMeshScene(const Scene& scene, const TetMesh& mesh, const Camera& camera, const fs::path& meshPath,
                        const fs::path& scenePath)
{
    writeVtkUnstructured(mesh, meshPath, true, "scalars");
    nlohmann::json points = nlohmann::json::array();
    for (const ControlPoint& p : scene.transferFunction.points())
        points.push_back({p.s, p.color.r, p.color.g, p.color.b, p.tau});
    nlohmann::json peer = {
        {"technique", scene.technique},
        {"mesh", {{"file", fs::absolute(meshPath).string()}, {"scalar", "scalars"}}},
        {"camera", cameraJson(camera)},
        {"image",
         {{"width", scene.image.width},
          {"height", scene.image.height},
          {"background", {scene.image.background.r, scene.image.background.g, scene.image.background.b}}}},
        {"transfer_function", {{"points", points}}},
        {"options", scene.options}};
    std::ofstream out(scenePath);
    out << peer.dump(2) << '\n';
    if (!out)
        throw InputError(scenePath.string() + ": cannot write the peer's scene");
}

}  // namespace clvr::tools
