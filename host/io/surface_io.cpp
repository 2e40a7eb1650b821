// host/io/surface_io.cpp — readPlc: TetGen's surface formats read without tetgenio's printing readers.
// Each reader fills the Plc as the matching tetgenio::load_* does (TetGen 1.5), so the mesh is the same.
#include "host/io/surface_io.h"

#include "host/runtime/errors.h"
#include "host/runtime/file_io.h"

#include <algorithm>
#include <sstream>
#include <map>
#include <limits>
#include <array>
#include <cctype>
#include <cerrno>
#include <climits>
#include <cmath>
#include <cstdlib>
#include <fstream>
#include <string>

namespace clvr {

namespace fs = std::filesystem;

namespace {

// The file's lines, as TetGen's readline gives them: text after '#' dropped, blank lines skipped, then
// split into numbers at spaces, tabs and commas. take() gives the next line's words; more() the next
// words of an entry that runs on over several lines (a long polygon).
class Lines {
public:
    explicit Lines(const fs::path& path) : path_(path.string())
    {
        std::ifstream in(path);
        if (!in)
            throw InputError(path_ + ": cannot open");
        std::string text;
        for (int number = 1; std::getline(in, text); ++number) {
            text = text.substr(0, text.find('#'));
            std::replace_if(text.begin(), text.end(), [](char c) { return c == ',' || c == '\t' || c == '\r'; }, ' ');
            Line line{number, {}};
            for (std::size_t i = 0; i < text.size();) {
                const std::size_t start = text.find_first_not_of(' ', i);
                if (start == std::string::npos)
                    break;
                const std::size_t end = std::min(text.find(' ', start), text.size());
                line.words.push_back(text.substr(start, end - start));
                i = end;
            }
            if (!line.words.empty())
                lines_.push_back(std::move(line));
        }
    }

    bool done() const { return next_ >= lines_.size(); }
    std::vector<std::string> take(const std::string& what)
    {
        if (done())
            throw InputError(path_ + ": ends before " + what);
        current_ = lines_[next_].number;
        return lines_[next_++].words;
    }
    std::vector<std::string> more(const std::string& what) { return take(what); }

    // "<path>:<line>: " for the line taken last.
    std::string at() const { return path_ + ":" + std::to_string(current_) + ": "; }

    double real(const std::string& word, const std::string& what) const
    {
        char* end = nullptr;
        errno = 0;
        const double v = std::strtod(word.c_str(), &end);
        if (end == word.c_str() || *end != '\0' || !std::isfinite(v))
            throw InputError(at() + what + ": \"" + word + "\" is not a finite number");
        return v;
    }
    int integer(const std::string& word, const std::string& what) const
    {
        char* end = nullptr;
        errno = 0;
        const long v = std::strtol(word.c_str(), &end, 10);
        if (end == word.c_str() || *end != '\0' || errno == ERANGE || v < INT_MIN || v > INT_MAX)
            throw InputError(at() + what + ": \"" + word + "\" is not a whole number");
        return static_cast<int>(v);
    }
    int count(const std::string& word, const std::string& what) const
    {
        const int n = integer(word, what);
        if (n < 0)
            throw InputError(at() + what + " must not be negative, got " + word);
        return n;
    }

private:
    struct Line {
        int number;
        std::vector<std::string> words;
    };
    std::string path_;
    std::vector<Line> lines_;
    std::size_t next_ = 0;
    int current_ = 0;
};

glm::dvec3 point(const Lines& lines, const std::vector<std::string>& words, std::size_t first, const std::string& what)
{
    if (words.size() < first + 3)
        throw InputError(lines.at() + what + " needs three coordinates");
    return {lines.real(words[first], what), lines.real(words[first + 1], what), lines.real(words[first + 2], what)};
}

// "<n> <c1> ... <cn>" starting at words[first], running on over further lines if needed.
std::vector<int> polygon(Lines& lines, std::vector<std::string> words, std::size_t first, std::size_t* usedOut = nullptr)
{
    const int n = lines.count(words.at(first), "polygon corner count");
    if (n < 1)
        throw InputError(lines.at() + "a polygon needs at least one corner");
    std::vector<int> corners;
    std::size_t i = first + 1;
    while (static_cast<int>(corners.size()) < n) {
        if (i >= words.size()) {
            words = lines.more("the corners of a polygon");
            i = 0;
        }
        corners.push_back(lines.integer(words[i++], "polygon corner"));
    }
    if (usedOut)
        *usedOut = i;
    return corners;
}

void checkCorners(const Plc& plc, const Lines& lines, const std::vector<int>& corners)
{
    const int last = plc.firstNumber + static_cast<int>(plc.points.size()) - 1;
    for (int c : corners)
        if (c < plc.firstNumber || c > last)
            throw InputError(lines.at() + "polygon corner " + std::to_string(c) + " names no point (points are " +
                             std::to_string(plc.firstNumber) + ".." + std::to_string(last) + ")");
}

// .off (tetgenio::load_off): "OFF" (counts on its line or the next), points, then one polygon per face.
Plc readOff(const fs::path& path)
{
    Lines lines(path);
    std::vector<std::string> header = lines.take("the OFF header");
    const auto off = std::find_if(header.begin(), header.end(),
                                  [](const std::string& w) { return w.find("OFF") != std::string::npos; });
    if (off == header.end())
        throw InputError(lines.at() + "no \"OFF\" header");
    std::vector<std::string> counts(off + 1, header.end());
    if (counts.empty())
        counts = lines.take("the OFF counts");
    if (counts.size() < 3)
        throw InputError(lines.at() + "want \"<points> <faces> <edges>\" after OFF");
    const int nPoints = lines.count(counts[0], "point count"), nFaces = lines.count(counts[1], "face count");
    if (nPoints == 0)
        throw InputError(lines.at() + "the point count is 0");
    Plc plc;
    for (int i = 0; i < nPoints; ++i)
        plc.points.push_back(point(lines, lines.take("point " + std::to_string(i)), 0, "point"));
    int smallest = INT_MAX, largest = 0;
    for (int f = 0; f < nFaces; ++f) {
        PlcFacet facet;
        facet.polygons.push_back(polygon(lines, lines.take("face " + std::to_string(f)), 0));
        for (int c : facet.polygons.back()) {
            if (c < 0 || c > nPoints)  // numbered from 0 or from 1: either way in 0..nPoints
                throw InputError(lines.at() + "polygon corner " + std::to_string(c) + " names no point (" +
                                 std::to_string(nPoints) + " points)");
            smallest = std::min(smallest, c);
            largest = std::max(largest, c);
        }
        plc.facets.push_back(std::move(facet));
    }
    if (nFaces > 0 && smallest != 0 && smallest != 1)
        throw InputError(path.string() + ": the smallest point index is " + std::to_string(smallest) +
                         ", neither 0 nor 1");
    plc.firstNumber = nFaces > 0 ? smallest : 0;
    if (largest >= plc.firstNumber + nPoints)
        throw InputError(path.string() + ": point index " + std::to_string(largest) + " names no point (" +
                         std::to_string(nPoints) + " points, numbered from " + std::to_string(plc.firstNumber) + ")");
    return plc;
}

// ASCII .stl (tetgenio::load_stl): after "solid", every "vertex x y z" is a new point; each three make a
// triangle; numbered from 1. Keywords are matched as load_stl does, anywhere in the line.
Plc readAsciiStl(const fs::path& path)
{
    std::ifstream in(path);
    if (!in)
        throw InputError(path.string() + ": cannot open");
    Plc plc;
    plc.firstNumber = 1;
    bool solid = false;
    std::string text;
    for (int number = 1; std::getline(in, text); ++number) {
        text = text.substr(0, text.find('#'));
        if (!solid) {
            solid = text.find("solid") != std::string::npos;
            continue;
        }
        if (text.find("endsolid") != std::string::npos) {
            solid = false;
            continue;
        }
        const std::size_t v = text.find("vertex");
        if (v == std::string::npos)
            continue;
        const std::string where = path.string() + ":" + std::to_string(number) + ": ";
        const char* p = text.c_str() + v + 6;
        glm::dvec3 corner;
        for (int axis = 0; axis < 3; ++axis) {
            char* end = nullptr;
            corner[axis] = std::strtod(p, &end);
            if (end == p || !std::isfinite(corner[axis]))
                throw InputError(where + "a vertex needs three finite coordinates");
            p = end;
        }
        plc.points.push_back(corner);
    }
    if (plc.points.empty() || plc.points.size() % 3 != 0)
        throw InputError(path.string() + ": " + std::to_string(plc.points.size()) +
                         " vertices, not a positive multiple of 3 (is it an ASCII STL starting \"solid\"?)");
    for (int i = 0; i < static_cast<int>(plc.points.size()); i += 3) {
        PlcFacet facet;
        facet.polygons.push_back({i + 1, i + 2, i + 3});
        plc.facets.push_back(std::move(facet));
    }
    return plc;
}

// A .node section: "<n> <dim> <attributes> <markers>" then "<index> x y z [attributes] [marker]".
void readNodes(Lines& lines, Plc& plc, int n, const std::vector<std::string>& header)
{
    if (header.size() >= 2 && lines.integer(header[1], "dimension") != 3)
        throw InputError(lines.at() + "the dimension must be 3, got " + header[1]);
    const int attributes = header.size() >= 3 ? lines.count(header[2], "attribute count") : 0;
    const bool markers = header.size() >= 4 && lines.integer(header[3], "boundary marker flag") != 0;
    for (int i = 0; i < n; ++i) {
        const std::vector<std::string> words = lines.take("point " + std::to_string(i));
        const int index = lines.integer(words[0], "point index");
        if (i == 0)
            plc.firstNumber = index;
        plc.points.push_back(point(lines, words, 1, "point"));
        if (markers) {
            const std::size_t at = 4 + static_cast<std::size_t>(attributes);
            plc.pointMarkers.push_back(words.size() > at ? lines.integer(words[at], "point marker") : 0);
        }
    }
    if (plc.firstNumber != 0 && plc.firstNumber != 1)
        throw InputError(lines.at() + "the first point is numbered " + std::to_string(plc.firstNumber) +
                         ", neither 0 nor 1");
}

// .poly or .smesh (tetgenio::load_poly): points (or the .node beside it), facets, volume holes, regions.
Plc readPoly(const fs::path& path, bool smesh)
{
    Lines lines(path);
    Plc plc;
    const std::vector<std::string> header = lines.take("the point section");
    const int nPoints = lines.count(header[0], "point count");
    if (nPoints > 0) {
        readNodes(lines, plc, nPoints, header);
    } else {
        fs::path nodePath = path;
        nodePath.replace_extension(".node");
        if (!fs::is_regular_file(nodePath))
            throw InputError(path.string() + ": has no points and " + nodePath.string() + " does not exist");
        Lines nodes(nodePath);
        const std::vector<std::string> nodeHeader = nodes.take("the point section");
        readNodes(nodes, plc, nodes.count(nodeHeader[0], "point count"), nodeHeader);
    }
    if (plc.points.empty())
        throw InputError(path.string() + ": no points");

    const std::vector<std::string> facetHeader = lines.take("the facet section");
    const int nFacets = lines.count(facetHeader[0], "facet count");
    plc.facetMarkers = facetHeader.size() >= 2 && lines.integer(facetHeader[1], "facet marker flag") != 0;
    for (int f = 0; f < nFacets; ++f) {
        PlcFacet facet;
        const std::vector<std::string> words = lines.take("facet " + std::to_string(f));
        if (smesh) {  // "<n> <c1> ... <cn> [marker]"
            std::size_t used = 0;
            facet.polygons.push_back(polygon(lines, words, 0, &used));
            if (plc.facetMarkers && used < words.size())
                facet.marker = lines.integer(words[used], "facet marker");
        } else {  // "<polygons> [holes] [marker]", then the polygons, then the holes
            const int nPolygons = lines.count(words[0], "polygon count");
            const int nHoles = words.size() >= 2 ? lines.count(words[1], "facet hole count") : 0;
            if (plc.facetMarkers && words.size() >= 3)
                facet.marker = lines.integer(words[2], "facet marker");
            for (int p = 0; p < nPolygons; ++p)
                facet.polygons.push_back(polygon(lines, lines.take("a polygon of facet " + std::to_string(f)), 0));
            for (int h = 0; h < nHoles; ++h)
                facet.holes.push_back(point(lines, lines.take("a hole of facet " + std::to_string(f)), 1, "facet hole"));
        }
        for (const std::vector<int>& p : facet.polygons)
            checkCorners(plc, lines, p);
        plc.facets.push_back(std::move(facet));
    }

    if (lines.done())
        return plc;
    const int nHoles = lines.count(lines.take("the hole section")[0], "hole count");
    for (int h = 0; h < nHoles; ++h)
        plc.holes.push_back(point(lines, lines.take("hole " + std::to_string(h)), 1, "hole"));
    if (lines.done())
        return plc;
    const int nRegions = lines.count(lines.take("the region section")[0], "region count");
    for (int r = 0; r < nRegions; ++r) {
        const std::vector<std::string> words = lines.take("region " + std::to_string(r));
        PlcRegion region;
        region.point = point(lines, words, 1, "region");
        if (words.size() >= 5)
            region.attribute = lines.real(words[4], "region attribute");
        if (words.size() >= 6)
            region.maxVolume = lines.real(words[5], "region volume bound");
        plc.regions.push_back(region);
    }
    return plc;
}

}  // namespace

Plc readPlc(const fs::path& path)
{
    if (!fs::is_regular_file(path))
        throw InputError(path.string() + ": no such file");
    const std::string ext = asciiLower(path.extension().string());
    if (ext == ".off")
        return readOff(path);
    if (ext == ".stl")
        return readAsciiStl(path);
    if (ext == ".poly" || ext == ".smesh")
        return readPoly(path, ext == ".smesh");
    throw InputError(path.string() + ": unknown surface format \"" + ext + "\" (.poly, .smesh, .off, .stl)");
}

std::vector<std::uint32_t> mergeIdenticalPoints(const std::vector<glm::dvec3>& points, std::vector<glm::dvec3>& merged)
{
    std::map<std::array<double, 3>, std::uint32_t> first;
    std::vector<std::uint32_t> remap(points.size());
    merged.clear();
    for (std::size_t i = 0; i < points.size(); ++i) {
        const glm::dvec3& p = points[i];
        const auto [it, added] = first.try_emplace({p.x, p.y, p.z}, static_cast<std::uint32_t>(merged.size()));
        if (added)
            merged.push_back(p);
        remap[i] = it->second;
    }
    return remap;
}

void checkSurface(const Plc& plc, const std::filesystem::path& path, bool closedManifold)
{
    std::vector<glm::dvec3> points;
    const std::vector<std::uint32_t> remap = mergeIdenticalPoints(plc.points, points);
    glm::dvec3 lo(std::numeric_limits<double>::max()), hi(-std::numeric_limits<double>::max());
    for (const glm::dvec3& p : points) {
        lo = glm::min(lo, p);
        hi = glm::max(hi, p);
    }
    const double extent = glm::length(hi - lo);
    const auto pointOf = [&](int number, std::size_t facet) {
        const long index = static_cast<long>(number) - plc.firstNumber;
        if (index < 0 || index >= static_cast<long>(plc.points.size()))
            throw InputError(path.string() + ": facet " + std::to_string(facet) + " uses point " + std::to_string(number) +
                             ", which does not exist");
        return remap[static_cast<std::size_t>(index)];
    };
    std::map<std::pair<std::uint32_t, std::uint32_t>, int> uses;  // undirected edge -> polygons bordering it
    for (std::size_t f = 0; f < plc.facets.size(); ++f)
        for (const std::vector<int>& polygon : plc.facets[f].polygons) {
            if (polygon.size() < 3)
                continue;  // a segment or point constraint inside a .poly facet
            // Newell's normal: twice the polygon's vector area, zero for a collinear or repeated polygon.
            glm::dvec3 area(0.0);
            for (std::size_t k = 0; k < polygon.size(); ++k) {
                const std::uint32_t a = pointOf(polygon[k], f), b = pointOf(polygon[(k + 1) % polygon.size()], f);
                area += glm::cross(points[a], points[b]);
                if (a != b)
                    ++uses[{std::min(a, b), std::max(a, b)}];
            }
            if (!(glm::length(area) > 1e-12 * extent * extent)) {
                std::string numbers;
                for (int n : polygon) {
                    numbers += ' ';
                    numbers += std::to_string(n);
                }
                throw InputError(path.string() + ": facet " + std::to_string(f) + " (points" + numbers +
                                 ") has zero area: TetGen needs a surface without degenerate facets");
            }
        }
    if (!closedManifold)
        return;
    for (const auto& [edge, n] : uses)
        if (n != 2) {
            const glm::dvec3 &a = points[edge.first], &b = points[edge.second];
            std::ostringstream s;
            s << path.string() << ": the edge (" << a.x << ", " << a.y << ", " << a.z << ") - (" << b.x << ", " << b.y
              << ", " << b.z << ") borders " << n << (n == 1 ? " facet: the surface is open (a hole)" : " facets: the surface is not a manifold")
              << "; TetGen needs a closed surface in which every edge borders two facets";
            throw InputError(s.str());
        }
}

}  // namespace clvr
