// host/io/tetgen_mesher.cpp — TetGen as a library: the surface is loaded with tetgenio's own readers,
// tetrahedralized with "p" always on, and the output copied into a TetMesh.
#include "host/io/tetgen_mesher.h"

#include "host/runtime/errors.h"
#include "host/runtime/file_io.h"
#include "host/io/generators.h"
#include "host/io/volume_io.h"

#include <tetgen.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <memory>
#include <sstream>
#include <vector>

namespace clvr {

namespace fs = std::filesystem;

namespace {

std::string lower(std::string s)
{
    for (char& c : s)
        c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
    return s;
}

// tetgenio's readers take a writable char*.
std::vector<char> cString(const std::string& s)
{
    std::vector<char> v(s.begin(), s.end());
    v.push_back('\0');
    return v;
}

// TetGen's exit codes (terminatetetgen) in words.
std::string tetgenError(int code)
{
    switch (code) {
    case 1: return "out of memory";
    case 2: return "internal error";
    case 3: return "a self-intersection in the surface";
    case 4: return "a very small input feature size (points or facets too close)";
    case 5: return "two very close input facets";
    case 10: return "a problem with the input data";
    default: return "error code " + std::to_string(code);
    }
}

}  // namespace

std::string tetgenSwitches(const MesherOptions& options)
{
    std::ostringstream s;
    s.precision(17);
    s << "pQz";
    if (options.quality > 0.0)
        s << 'q' << options.quality;
    if (options.maxVolume > 0.0)
        s << 'a' << options.maxVolume;
    return s.str();
}

void assignScalar(TetMesh& mesh, const std::string& scalar)
{
    mesh.scalars.resize(mesh.points.size());
    const std::string name = lower(scalar);
    if (name == "marschner-lobb" || name == "sphere" || name == "blobs") {
        double (*f)(const glm::dvec3&) = name == "sphere" ? sphereField : name == "blobs" ? blobsField : marschnerLobb;
        for (std::size_t i = 0; i < mesh.points.size(); ++i)
            mesh.scalars[i] = f(mesh.points[i]);
        return;
    }
    const std::string ext = lower(fs::path(scalar).extension().string());
    if (ext != ".nrrd" && ext != ".nhdr")
        throw InputError("mesh scalar " + scalar +
                         ": neither a generator (marschner-lobb, sphere, blobs) nor a .nrrd/.nhdr volume");
    const Volume volume = readNrrd(scalar);
    const glm::dvec3 lo = volume.boundsMin(), hi = volume.boundsMax();
    for (std::size_t i = 0; i < mesh.points.size(); ++i)
        mesh.scalars[i] = volume.sample(glm::clamp(mesh.points[i], lo, hi)).value_or(0.0);
}

TetMesh meshSurface(const fs::path& surface, const MesherOptions& options)
{
    if (!fs::is_regular_file(surface))
        throw InputError(surface.string() + ": no such file");
    if (!(options.quality >= 0.0) || !(options.maxVolume >= 0.0))
        throw InputError(surface.string() + ": --quality and --max-volume must be positive");
    {
        const std::string s = lower(options.scalar), e = lower(fs::path(options.scalar).extension().string());
        if (s != "marschner-lobb" && s != "sphere" && s != "blobs" && e != ".nrrd" && e != ".nhdr")
            throw InputError("mesh scalar " + options.scalar +
                             ": neither a generator (marschner-lobb, sphere, blobs) nor a .nrrd/.nhdr volume");
    }
    const std::string ext = lower(surface.extension().string());
    tetgenio in, out;
    bool loaded = false;
    auto quiet = std::make_unique<QuietStdout>();  // TetGen's readers print "Opening FILE."
    if (ext == ".poly" || ext == ".smesh") {
        fs::path base = surface;
        base.replace_extension();
        auto name = cString(base.string());
        loaded = in.load_plc(name.data(), static_cast<int>(tetgenbehavior::POLY));
    } else if (ext == ".off") {
        auto name = cString(surface.string());
        loaded = in.load_off(name.data());
    } else if (ext == ".stl") {
        auto name = cString(surface.string());
        loaded = in.load_stl(name.data());
    } else {
        throw InputError(surface.string() + ": unknown surface format \"" + ext + "\" (.poly, .smesh, .off, .stl)");
    }
    quiet.reset();
    if (!loaded || in.numberofpoints == 0 || in.numberoffacets == 0)
        throw InputError(surface.string() + ": TetGen could not read a surface from it");

    // TetGen asserts (aborts) on flat input: refuse it here.
    glm::dvec3 lo(in.pointlist[0], in.pointlist[1], in.pointlist[2]), hi = lo;
    for (int i = 0; i < in.numberofpoints; ++i) {
        const glm::dvec3 p(in.pointlist[3 * i], in.pointlist[3 * i + 1], in.pointlist[3 * i + 2]);
        if (!std::isfinite(p.x) || !std::isfinite(p.y) || !std::isfinite(p.z))
            throw InputError(surface.string() + ": point " + std::to_string(i) + " is not finite");
        lo = glm::min(lo, p);
        hi = glm::max(hi, p);
    }
    if (!(hi.x > lo.x && hi.y > lo.y && hi.z > lo.z))
        throw InputError(surface.string() + ": the surface is flat (its bounding box has zero extent), not closed");

    auto switches = cString(tetgenSwitches(options));
    try {
        tetrahedralize(switches.data(), &in, &out);
    } catch (int code) {
        throw InputError(surface.string() + ": TetGen failed: " + tetgenError(code));
    }
    if (out.numberoftetrahedra <= 0 || out.numberofpoints <= 0)
        throw InputError(surface.string() + ": TetGen made no tetrahedra (is the surface closed?)");

    TetMesh mesh;
    mesh.source = surface.string();
    mesh.points.resize(static_cast<std::size_t>(out.numberofpoints));
    for (std::size_t i = 0; i < mesh.points.size(); ++i)
        mesh.points[i] = glm::dvec3(out.pointlist[3 * i], out.pointlist[3 * i + 1], out.pointlist[3 * i + 2]);
    const int corners = out.numberofcorners > 0 ? out.numberofcorners : 4;
    mesh.tets.resize(static_cast<std::size_t>(out.numberoftetrahedra));
    // The 'z' switch numbers the output from 0 whatever the input's firstnumber; out.firstnumber still
    // carries the input's (1 for an STL, whose load_stl numbers from 1), so it is not used here.
    for (std::size_t t = 0; t < mesh.tets.size(); ++t)
        for (int k = 0; k < 4; ++k)
            mesh.tets[t][k] = static_cast<std::uint32_t>(out.tetrahedronlist[t * corners + k]);
    mesh.tetsRead = mesh.tets.size();
    assignScalar(mesh, options.scalar);
    checkMesh(mesh);
    return mesh;
}

}  // namespace clvr
