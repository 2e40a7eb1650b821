// host/io/tetgen_mesher.cpp — TetGen as a library: the surface is read by clvr (host/io/surface_io.h: what
// tetgenio's printing readers would load) into a tetgenio, tetrahedralized with "p" always on and "Q"
// (TetGen's own quiet switch), and the output copied into a TetMesh. Nothing is printed.
#include "host/io/tetgen_mesher.h"

#include "host/runtime/errors.h"
#include "host/runtime/file_io.h"
#include "host/io/generators.h"
#include "host/io/surface_io.h"
#include "host/io/volume_io.h"

#include <tetgen.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <sstream>
#include <vector>

namespace clvr {

namespace fs = std::filesystem;

namespace {

// Copies `plc` into `io` as tetgenio::load_off / load_stl / load_poly would have filled it; the arrays are
// allocated with new[], which tetgenio's destructor frees.
void toTetgenio(const Plc& plc, tetgenio& io)
{
    io.firstnumber = plc.firstNumber;
    io.numberofpoints = static_cast<int>(plc.points.size());
    io.pointlist = new REAL[3 * plc.points.size()];
    for (std::size_t i = 0; i < plc.points.size(); ++i)
        for (int a = 0; a < 3; ++a)
            io.pointlist[3 * i + a] = plc.points[i][a];
    if (!plc.pointMarkers.empty()) {
        io.pointmarkerlist = new int[plc.pointMarkers.size()];
        std::copy(plc.pointMarkers.begin(), plc.pointMarkers.end(), io.pointmarkerlist);
    }
    io.numberoffacets = static_cast<int>(plc.facets.size());
    io.facetlist = new tetgenio::facet[plc.facets.size()];
    if (plc.facetMarkers)
        io.facetmarkerlist = new int[plc.facets.size()];
    for (std::size_t f = 0; f < plc.facets.size(); ++f) {
        const PlcFacet& in = plc.facets[f];
        tetgenio::facet& out = io.facetlist[f];
        tetgenio::init(&out);
        out.numberofpolygons = static_cast<int>(in.polygons.size());
        out.polygonlist = new tetgenio::polygon[in.polygons.size()];
        for (std::size_t p = 0; p < in.polygons.size(); ++p) {
            tetgenio::polygon& poly = out.polygonlist[p];
            tetgenio::init(&poly);
            poly.numberofvertices = static_cast<int>(in.polygons[p].size());
            poly.vertexlist = new int[in.polygons[p].size()];
            std::copy(in.polygons[p].begin(), in.polygons[p].end(), poly.vertexlist);
        }
        if (!in.holes.empty()) {
            out.numberofholes = static_cast<int>(in.holes.size());
            out.holelist = new REAL[3 * in.holes.size()];
            for (std::size_t h = 0; h < in.holes.size(); ++h)
                for (int a = 0; a < 3; ++a)
                    out.holelist[3 * h + a] = in.holes[h][a];
        }
        if (plc.facetMarkers)
            io.facetmarkerlist[f] = in.marker;
    }
    if (!plc.holes.empty()) {
        io.numberofholes = static_cast<int>(plc.holes.size());
        io.holelist = new REAL[3 * plc.holes.size()];
        for (std::size_t h = 0; h < plc.holes.size(); ++h)
            for (int a = 0; a < 3; ++a)
                io.holelist[3 * h + a] = plc.holes[h][a];
    }
    if (!plc.regions.empty()) {
        io.numberofregions = static_cast<int>(plc.regions.size());
        io.regionlist = new REAL[5 * plc.regions.size()];
        for (std::size_t r = 0; r < plc.regions.size(); ++r) {
            const PlcRegion& region = plc.regions[r];
            REAL* out = io.regionlist + 5 * r;
            out[0] = region.point.x, out[1] = region.point.y, out[2] = region.point.z;
            out[3] = region.attribute, out[4] = region.maxVolume;
        }
    }
}

// tetgenio's calls take a writable char*.
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

namespace {

// The generator a mesh scalar names (host/io/generators.h), or nullptr when it names none.
double (*scalarGenerator(const std::string& scalar))(const glm::dvec3&)
{
    const std::string name = asciiLower(scalar);
    return name == "marschner-lobb" ? marschnerLobb
           : name == "sphere"       ? sphereField
           : name == "blobs"        ? blobsField
           : name == "kernel"       ? kernelField
                                    : nullptr;
}

// InputError unless `scalar` names a generator or a .nrrd/.nhdr volume (checked before TetGen runs).
void checkScalar(const std::string& scalar)
{
    const std::string ext = asciiLower(fs::path(scalar).extension().string());
    if (!scalarGenerator(scalar) && ext != ".nrrd" && ext != ".nhdr")
        throw InputError("mesh scalar " + scalar +
                         ": neither a generator (marschner-lobb, sphere, blobs, kernel) nor a .nrrd/.nhdr volume");
}

}  // namespace

void assignScalar(TetMesh& mesh, const std::string& scalar)
{
    mesh.scalars.resize(mesh.points.size());
    if (double (*f)(const glm::dvec3&) = scalarGenerator(scalar)) {
        for (std::size_t i = 0; i < mesh.points.size(); ++i)
            mesh.scalars[i] = f(mesh.points[i]);
        return;
    }
    checkScalar(scalar);
    const Volume volume = readNrrd(scalar);
    const glm::dvec3 lo = volume.boundsMin(), hi = volume.boundsMax();
    std::size_t inside = 0;
    for (std::size_t i = 0; i < mesh.points.size(); ++i) {
        const glm::dvec3& p = mesh.points[i];
        inside += glm::all(glm::greaterThanEqual(p, lo)) && glm::all(glm::lessThanEqual(p, hi)) ? 1 : 0;
        mesh.scalars[i] = volume.sample(glm::clamp(p, lo, hi)).value_or(0.0);
    }
    // Clamping suits a surface that pokes out a little; one entirely outside would only repeat the
    // volume's border values: say so instead of rendering a constant.
    if (inside == 0)
        throw InputError("mesh scalar " + scalar + ": no point of the mesh lies inside the volume's bounds (" +
                         std::to_string(lo.x) + ", " + std::to_string(lo.y) + ", " + std::to_string(lo.z) + ") .. (" +
                         std::to_string(hi.x) + ", " + std::to_string(hi.y) + ", " + std::to_string(hi.z) +
                         "): move or scale the surface into the volume");
}

TetMesh meshSurface(const fs::path& surface, const MesherOptions& options)
{
    if (!fs::is_regular_file(surface))
        throw InputError(surface.string() + ": no such file");
    if (!(options.quality >= 0.0) || !(options.maxVolume >= 0.0))
        throw InputError(surface.string() + ": --quality and --max-volume must be positive");
    checkScalar(options.scalar);
    const std::string ext = asciiLower(surface.extension().string());
    if (ext != ".poly" && ext != ".smesh" && ext != ".off" && ext != ".stl")
        throw InputError(surface.string() + ": unknown surface format \"" + ext + "\" (.poly, .smesh, .off, .stl)");
    const Plc plc = readPlc(surface);
    if (plc.points.empty() || plc.facets.empty())
        throw InputError(surface.string() + ": no surface in it (no points or no facets)");
    tetgenio in, out;
    toTetgenio(plc, in);

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
    checkSurface(plc, surface, ext == ".off" || ext == ".stl");

    // A surface that intersects itself crashes TetGen's mesher (a segfault inside tetrahedralize, not an
    // error code). TetGen's own check ("d": detect intersecting facets, no meshing) reports such facets
    // without crashing: refuse the surface when it finds any.
    {
        tetgenio check;
        auto detect = cString("pdQz");
        try {
            tetrahedralize(detect.data(), &in, &check);
        } catch (int code) {
            throw InputError(surface.string() + ": TetGen failed checking the surface: " + tetgenError(code));
        }
        if (check.numberoftrifaces > 0)
            throw InputError(surface.string() + ": the surface intersects itself (" + std::to_string(check.numberoftrifaces) +
                             " facets cross others): TetGen needs a closed surface without self-intersections");
    }
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
