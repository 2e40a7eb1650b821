// host/io/surface_io.h — TetGen's surface input formats (.off, ASCII .stl, .poly, .smesh) read by clvr, so
// that nothing prints: tetgenio's own load_* functions print "Opening FILE." (and their syntax errors)
// on stdout, which scripts read. The result is what tetgenio's readers would hold, entry for entry, as a
// piecewise linear complex (PLC) without TetGen types; host/io/tetgen_mesher.cpp copies it into a tetgenio.
#pragma once

#include <glm/glm.hpp>

#include <cstdint>
#include <filesystem>
#include <vector>

namespace clvr {

struct PlcFacet {
    std::vector<std::vector<int>> polygons;  // point numbers, counted from Plc::firstNumber
    std::vector<glm::dvec3> holes;           // points inside the facet's holes
    int marker = 0;
};

struct PlcRegion {
    glm::dvec3 point{0.0};
    double attribute = 0.0;
    double maxVolume = -1.0;  // as TetGen's region list: < 0 none
};

struct Plc {
    int firstNumber = 0;  // 0 or 1: the number of the first point
    std::vector<glm::dvec3> points;
    std::vector<int> pointMarkers;  // empty, or one per point (.poly with boundary markers)
    std::vector<PlcFacet> facets;
    bool facetMarkers = false;       // whether the file gave facet markers
    std::vector<glm::dvec3> holes;   // volume holes
    std::vector<PlcRegion> regions;
};

// Reads the surface at `path` by its extension: .off (one polygon per face, numbered from 0 or 1 as
// the smallest index says, as load_off), ASCII .stl (one point per triangle corner, numbered from 1,
// as load_stl), .poly or .smesh (TetGen's formats; a .poly with no points reads them from the .node file
// beside it). Lines are read as TetGen does: '#' starts a comment, blank lines are skipped, numbers are
// separated by spaces, tabs or commas. InputError "<path>:<line>: ..." for anything it cannot read.
Plc readPlc(const std::filesystem::path& path);

// Points with identical coordinates merged, the first occurrence kept: `merged` gets the distinct points
// in order of first occurrence and the result maps each input point to its index there (an STL file
// repeats every corner; TetGen merges them too).
std::vector<std::uint32_t> mergeIdenticalPoints(const std::vector<glm::dvec3>& points, std::vector<glm::dvec3>& merged);

// What TetGen needs of a surface, checked before it runs (docs/meshes.md): every polygon has a nonzero
// area, and — with `closedManifold`, for the pure surface formats .off and .stl — every edge (points
// merged as above) borders exactly two polygons. InputError naming `path` and the first offending
// facet or edge. (.poly and .smesh may hold internal or dangling facets, which TetGen accepts.)
void checkSurface(const Plc& plc, const std::filesystem::path& path, bool closedManifold);

}  // namespace clvr
