// host/io/mesh_io.cpp — TetGen, VTK legacy unstructured grid, .off tetrahedral and PLOT3D readers, the TetGen
// and VTK writers, and the scene's "mesh" object. Files are read whole (after their size is measured);
// every count from a header is compared with what the file can hold before anything is allocated.
#include "host/io/mesh_io.h"

#include "host/io/cell_split.h"
#include "host/io/generators.h"
#include "host/io/vtk_xml_io.h"

#include "host/runtime/errors.h"
#include "host/runtime/file_io.h"
#include "host/io/tetgen_mesher.h"

#include <nlohmann/json.hpp>

#include <algorithm>
#include <array>
#include <bit>
#include <cctype>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <limits>
#include <optional>
#include <sstream>

namespace clvr {

namespace fs = std::filesystem;

namespace {

// Largest counts any reader accepts: uint32 point indices, int32 tetrahedron ids (TetTopology).
constexpr std::uint64_t kMaxPoints = std::numeric_limits<std::uint32_t>::max();
constexpr std::uint64_t kMaxTets = std::numeric_limits<std::int32_t>::max();

// ---------------------------------------------------------------------------------------------------
// Small helpers.

std::string shown(std::string_view s)
{
    std::string out = "\"";
    for (std::size_t i = 0; i < s.size() && i < 40; ++i)
        out += std::isprint(static_cast<unsigned char>(s[i])) ? s[i] : '?';
    if (s.size() > 40)
        out += "...";
    return out + "\"";
}

std::optional<long long> parseInteger(std::string_view s)
{
    if (!s.empty() && s[0] == '+')
        s.remove_prefix(1);
    long long v = 0;
    const auto [end, ec] = std::from_chars(s.data(), s.data() + s.size(), v);
    if (s.empty() || ec != std::errc() || end != s.data() + s.size())
        return std::nullopt;
    return v;
}

// What strtod accepts (nan, inf, exponents), but the whole token must be a number.
std::optional<double> parseDouble(std::string_view s)
{
    if (!s.empty() && s[0] == '+')
        s.remove_prefix(1);
    double v = 0;
    const auto [end, ec] = std::from_chars(s.data(), s.data() + s.size(), v);
    if (s.empty() || end != s.data() + s.size())
        return std::nullopt;
    if (ec == std::errc::result_out_of_range)  // denormals and overflow: strtod's answer
        return std::strtod(std::string(s).c_str(), nullptr);
    if (ec != std::errc())
        return std::nullopt;
    return v;
}

std::string readWhole(const fs::path& path)
{
    const std::uint64_t size = fileSize(path);
    std::ifstream in(path, std::ios::binary);
    if (!in)
        throw InputError(path.string() + ": cannot open for reading");
    std::string data(size, '\0');
    in.read(data.data(), static_cast<std::streamsize>(size));
    if (static_cast<std::uint64_t>(in.gcount()) != size)
        throw InputError(path.string() + ": read error");
    return data;
}

// A count from a header, checked against a bound derived from the file's size.
std::uint64_t checkedCount(const std::string& where, const std::string& what, long long value, std::uint64_t limit,
                           std::uint64_t fileBound)
{
    if (value < 0)
        throw InputError(where + ": " + what + " count " + std::to_string(value) + " is negative");
    const auto v = static_cast<std::uint64_t>(value);
    if (v > limit)
        throw InputError(where + ": " + what + " count " + std::to_string(v) + " exceeds the limit " +
                         std::to_string(limit));
    if (v > fileBound)
        throw InputError(where + ": " + what + " count " + std::to_string(v) +
                         " is more than the file can hold (truncated or a wrong count)");
    return v;
}

// ---------------------------------------------------------------------------------------------------
// Line-oriented text: comments (#) stripped, blank lines skipped, line numbers kept for messages.

class TextLines {
public:
    TextLines(const fs::path& path) : path_(path), data_(readWhole(path)) {}

    std::uint64_t size() const { return data_.size(); }

    // The next non-blank line's tokens; false at the end of the file.
    bool next(std::vector<std::string_view>& tokens)
    {
        tokens.clear();
        while (pos_ < data_.size()) {
            std::size_t end = data_.find('\n', pos_);
            if (end == std::string::npos)
                end = data_.size();
            std::string_view line(data_.data() + pos_, end - pos_);
            pos_ = end + 1;
            ++line_;
            if (const std::size_t hash = line.find('#'); hash != std::string_view::npos)
                line = line.substr(0, hash);
            std::size_t i = 0;
            while (i < line.size()) {
                while (i < line.size() && std::isspace(static_cast<unsigned char>(line[i])))
                    ++i;
                std::size_t j = i;
                while (j < line.size() && !std::isspace(static_cast<unsigned char>(line[j])))
                    ++j;
                if (j > i)
                    tokens.push_back(line.substr(i, j - i));
                i = j;
            }
            if (!tokens.empty())
                return true;
        }
        return false;
    }

    // "file line N" for messages about the line last returned.
    std::string where() const { return path_.string() + " line " + std::to_string(line_); }
    std::string file() const { return path_.string(); }

    long long integer(std::string_view token, const std::string& what) const
    {
        const auto v = parseInteger(token);
        if (!v)
            throw InputError(where() + ": " + what + " " + shown(token) + " is not an integer");
        return *v;
    }
    double real(std::string_view token, const std::string& what) const
    {
        const auto v = parseDouble(token);
        if (!v)
            throw InputError(where() + ": " + what + " " + shown(token) + " is not a number");
        return *v;
    }

private:
    fs::path path_;
    std::string data_;
    std::size_t pos_ = 0;
    std::size_t line_ = 0;
};

// A 0-based attribute index from the scene's "scalar" (empty: 0).
std::size_t attributeIndex(const std::string& file, const std::string& scalar)
{
    if (scalar.empty())
        return 0;
    const auto v = parseInteger(scalar);
    if (!v || *v < 0)
        throw InputError(file + ": scalar " + shown(scalar) + " must be a 0-based attribute index for this format");
    return static_cast<std::size_t>(*v);
}

// ---------------------------------------------------------------------------------------------------
// VTK legacy.

struct VtkType {
    std::size_t size;
    enum Kind { Signed, Unsigned, Float } kind;
};

std::optional<VtkType> vtkType(const std::string& name)
{
    const std::string n = asciiLower(name);
    if (n == "unsigned_char")
        return VtkType{1, VtkType::Unsigned};
    if (n == "char")
        return VtkType{1, VtkType::Signed};
    if (n == "unsigned_short")
        return VtkType{2, VtkType::Unsigned};
    if (n == "short")
        return VtkType{2, VtkType::Signed};
    if (n == "unsigned_int")
        return VtkType{4, VtkType::Unsigned};
    if (n == "int")
        return VtkType{4, VtkType::Signed};
    if (n == "unsigned_long" || n == "vtktypeuint64")
        return VtkType{8, VtkType::Unsigned};
    if (n == "long" || n == "vtktypeint64" || n == "vtkidtype")
        return VtkType{8, VtkType::Signed};
    if (n == "float")
        return VtkType{4, VtkType::Float};
    if (n == "double")
        return VtkType{8, VtkType::Float};
    return std::nullopt;
}

double decodeBig(const unsigned char* p, const VtkType& t)
{
    unsigned char b[8];
    for (std::size_t i = 0; i < t.size; ++i)
        b[i] = p[t.size - 1 - i];  // big-endian to little-endian (x86, ARM)
    if constexpr (std::endian::native == std::endian::big)
        std::memcpy(b, p, t.size);
    switch (t.size) {
    case 1: return t.kind == VtkType::Signed ? double(std::int8_t(b[0])) : double(b[0]);
    case 2: {
        std::uint16_t u;
        std::memcpy(&u, b, 2);
        return t.kind == VtkType::Signed ? double(std::int16_t(u)) : double(u);
    }
    case 4: {
        if (t.kind == VtkType::Float) {
            float f;
            std::memcpy(&f, b, 4);
            return f;
        }
        std::uint32_t u;
        std::memcpy(&u, b, 4);
        return t.kind == VtkType::Signed ? double(std::int32_t(u)) : double(u);
    }
    default: {
        if (t.kind == VtkType::Float) {
            double d;
            std::memcpy(&d, b, 8);
            return d;
        }
        std::uint64_t u;
        std::memcpy(&u, b, 8);
        return t.kind == VtkType::Signed ? double(std::int64_t(u)) : double(u);
    }
    }
}

class VtkReader {
public:
    VtkReader(const fs::path& path) : path_(path), data_(readWhole(path)) {}

    std::string file() const { return path_.string(); }

    // The source position as "file line N" (lines counted up to the current position).
    std::string where() const
    {
        const auto line = std::count(data_.begin(), data_.begin() + static_cast<std::ptrdiff_t>(std::min(pos_, data_.size())), '\n');
        return path_.string() + " line " + std::to_string(line + 1);
    }

    // One raw line (the header's first three lines), without its line break.
    std::string rawLine()
    {
        if (pos_ >= data_.size())
            throw InputError(file() + ": ends inside the header");
        std::size_t end = data_.find('\n', pos_);
        if (end == std::string::npos)
            end = data_.size();
        std::string line = data_.substr(pos_, end - pos_);
        if (!line.empty() && line.back() == '\r')
            line.pop_back();
        pos_ = end + 1;
        return line;
    }

    // The next non-blank line's tokens (keywords and their arguments); empty at the end of the file.
    // Leaves the position at the start of the following line, where binary data begins.
    std::vector<std::string> headerLine()
    {
        while (pos_ < data_.size() && std::isspace(static_cast<unsigned char>(data_[pos_])))
            ++pos_;
        std::vector<std::string> tokens;
        if (pos_ >= data_.size())
            return tokens;
        std::size_t end = data_.find('\n', pos_);
        if (end == std::string::npos)
            end = data_.size();
        std::size_t i = pos_;
        while (i < end) {
            while (i < end && std::isspace(static_cast<unsigned char>(data_[i])))
                ++i;
            std::size_t j = i;
            while (j < end && !std::isspace(static_cast<unsigned char>(data_[j])))
                ++j;
            if (j > i)
                tokens.emplace_back(data_.substr(i, j - i));
            i = j;
        }
        pos_ = std::min(end + 1, data_.size());
        return tokens;
    }

    long long integer(const std::string& token, const std::string& what) const
    {
        const auto v = parseInteger(token);
        if (!v)
            throw InputError(where() + ": " + what + " " + shown(token) + " is not an integer");
        return *v;
    }

    // Lines up to and including the next blank one (or the end of the file).
    void skipBlock()
    {
        while (pos_ < data_.size()) {
            const std::string line = rawLine();
            if (std::all_of(line.begin(), line.end(), [](char c) { return std::isspace(static_cast<unsigned char>(c)); }))
                return;
        }
    }

    VtkType type(const std::string& name) const
    {
        if (asciiLower(name) == "bit")
            throw InputError(where() + ": data type bit is not supported");
        const auto t = vtkType(name);
        if (!t)
            throw InputError(where() + ": unknown data type " + shown(name));
        return *t;
    }

    // A bound on how many values of `type` can remain in the file (for counts before allocation).
    std::uint64_t valuesLeft(const VtkType& t) const
    {
        const std::uint64_t left = data_.size() - std::min(pos_, data_.size());
        return binary ? left / t.size : left / 2 + 1;  // ASCII: at least one digit and a separator each
    }

    // `count` values of `type` at the current position; to `out` unless it is null (skipped).
    void values(const VtkType& t, std::uint64_t count, const std::string& what, std::vector<double>* out)
    {
        if (count > valuesLeft(t))
            throw InputError(where() + ": " + what + " needs " + std::to_string(count) + " values, the file is truncated");
        if (out)
            out->resize(count);
        if (binary) {
            const auto* p = reinterpret_cast<const unsigned char*>(data_.data() + pos_);
            if (out)
                for (std::uint64_t i = 0; i < count; ++i)
                    (*out)[i] = decodeBig(p + i * t.size, t);
            pos_ += count * t.size;
            return;
        }
        for (std::uint64_t i = 0; i < count; ++i) {
            while (pos_ < data_.size() && std::isspace(static_cast<unsigned char>(data_[pos_])))
                ++pos_;
            std::size_t j = pos_;
            while (j < data_.size() && !std::isspace(static_cast<unsigned char>(data_[j])))
                ++j;
            if (j == pos_)
                throw InputError(where() + ": " + what + " ends after " + std::to_string(i) + " of " +
                                 std::to_string(count) + " values (truncated)");
            const std::string_view tok(data_.data() + pos_, j - pos_);
            const auto v = parseDouble(tok);
            if (!v)
                throw InputError(where() + ": " + what + " value " + shown(tok) + " is not a number");
            if (out)
                (*out)[i] = *v;
            pos_ = j;
        }
    }

    bool binary = false;

private:
    fs::path path_;
    std::string data_;
    std::size_t pos_ = 0;
};

// Exact integer from a double holding a file's index value.
std::int64_t asIndex(double v)
{
    return (v >= -9.0e18 && v <= 9.0e18 && v == std::floor(v)) ? static_cast<std::int64_t>(v) : -1;
}

}  // namespace

// ---------------------------------------------------------------------------------------------------

TetMesh readVtkUnstructured(const fs::path& path, const std::string& scalar)
{
    VtkReader in(path);
    const std::string first = in.rawLine();
    if (first.rfind("# vtk DataFile Version", 0) != 0)
        throw InputError(in.file() + ": not a VTK legacy file (the first line is " + shown(first) +
                         ", expected \"# vtk DataFile Version x.y\")");
    int major = 0;
    std::sscanf(first.c_str() + 22, "%d", &major);
    in.rawLine();  // title
    std::string mode = in.rawLine();
    while (!mode.empty() && std::isspace(static_cast<unsigned char>(mode.back())))
        mode.pop_back();
    if (asciiLower(mode) == "binary")
        in.binary = true;
    else if (asciiLower(mode) != "ascii")
        throw InputError(in.file() + ": the third line must be ASCII or BINARY, not " + shown(mode));
    auto line = in.headerLine();
    if (line.size() < 2 || asciiLower(line[0]) != "dataset")
        throw InputError(in.where() + ": expected DATASET UNSTRUCTURED_GRID");
    if (asciiLower(line[1]) != "unstructured_grid")
        throw InputError(in.where() + ": DATASET " + line[1] + " is not an unstructured grid (UNSTRUCTURED_GRID)");

    TetMesh mesh;
    mesh.source = path.string();
    std::vector<double> coords, cells, offsets, types;
    bool haveCells = false, haveTypes = false;
    std::uint64_t nPoints = 0, nCells = 0;
    enum class Section { Dataset, Points, Cells } section = Section::Dataset;
    std::uint64_t sectionCount = 0;
    std::vector<std::pair<std::string, std::vector<double>>> pointArrays;  // one-component point arrays

    auto argCount = [&](const std::vector<std::string>& l, std::size_t n) {
        if (l.size() < n)
            throw InputError(in.where() + ": " + l[0] + " needs " + std::to_string(n - 1) + " arguments");
    };
    auto dataArray = [&](const std::string& name, std::uint64_t comps, std::uint64_t tuples, const VtkType& t,
                         const std::string& what) {
        if (comps > 0 && tuples > in.valuesLeft(t) / comps)
            throw InputError(in.where() + ": " + what + " needs " + std::to_string(tuples) + "x" + std::to_string(comps) +
                             " values, the file is truncated");
        const bool keep = section == Section::Points && comps == 1 && tuples == nPoints;
        std::vector<double> v;
        in.values(t, comps * tuples, what, keep ? &v : nullptr);
        if (keep)
            pointArrays.emplace_back(name, std::move(v));
    };

    while (!(line = in.headerLine()).empty()) {
        const std::string key = asciiLower(line[0]);
        if (key == "points") {
            argCount(line, 3);
            const VtkType t = in.type(line[2]);
            nPoints = checkedCount(in.where(), "POINTS", in.integer(line[1], "POINTS count"), kMaxPoints,
                                   in.valuesLeft(t) / 3);
            in.values(t, 3 * nPoints, "POINTS", &coords);
        } else if (key == "cells") {
            argCount(line, 3);
            const long long a = in.integer(line[1], "CELLS count"), b = in.integer(line[2], "CELLS size");
            if (major >= 5) {  // 5.x: OFFSETS and CONNECTIVITY arrays
                auto sub = in.headerLine();
                if (sub.size() < 2 || asciiLower(sub[0]) != "offsets")
                    throw InputError(in.where() + ": expected OFFSETS after CELLS (file version 5)");
                VtkType t = in.type(sub[1]);
                const std::uint64_t no = checkedCount(in.where(), "OFFSETS", a, kMaxTets + 1, in.valuesLeft(t));
                in.values(t, no, "OFFSETS", &offsets);
                sub = in.headerLine();
                if (sub.size() < 2 || asciiLower(sub[0]) != "connectivity")
                    throw InputError(in.where() + ": expected CONNECTIVITY after OFFSETS");
                t = in.type(sub[1]);
                const std::uint64_t nc = checkedCount(in.where(), "CONNECTIVITY", b, 16 * kMaxTets, in.valuesLeft(t));
                in.values(t, nc, "CONNECTIVITY", &cells);
                nCells = no == 0 ? 0 : no - 1;
            } else {
                const VtkType t{4, VtkType::Signed};
                nCells = checkedCount(in.where(), "CELLS", a, kMaxTets, in.valuesLeft(t));
                const std::uint64_t size = checkedCount(in.where(), "CELLS size", b, 16 * kMaxTets, in.valuesLeft(t));
                in.values(t, size, "CELLS", &cells);
                // Offsets from the size-prefixed list.
                offsets.resize(nCells + 1);
                std::uint64_t at = 0;
                for (std::uint64_t c = 0; c < nCells; ++c) {
                    if (at >= cells.size())
                        throw InputError(in.file() + ": CELLS list ends at cell " + std::to_string(c) + " of " +
                                         std::to_string(nCells) + " (the size " + std::to_string(size) + " is wrong)");
                    const std::int64_t k = asIndex(cells[at]);
                    if (k < 0 || static_cast<std::uint64_t>(k) > cells.size() - at - 1)
                        throw InputError(in.file() + ": cell " + std::to_string(c) + " has " + numberText(cells[at]) +
                                         " points, more than the CELLS list holds");
                    offsets[c] = static_cast<double>(at + 1);
                    at += 1 + static_cast<std::uint64_t>(k);
                }
                if (at != cells.size())
                    throw InputError(in.file() + ": CELLS size " + std::to_string(size) + " does not match its " +
                                     std::to_string(nCells) + " cells (" + std::to_string(at) + " values)");
                offsets[nCells] = static_cast<double>(at + 1);  // sentinel: cell c is offsets[c] .. offsets[c+1]-1
                // Cells hold their count at offsets[c]-1, so cell c's points are [offsets[c], offsets[c] + k).
            }
            haveCells = true;
        } else if (key == "cell_types") {
            argCount(line, 2);
            const VtkType t{4, VtkType::Signed};
            const std::uint64_t n = checkedCount(in.where(), "CELL_TYPES", in.integer(line[1], "CELL_TYPES count"),
                                                 kMaxTets, in.valuesLeft(t));
            in.values(t, n, "CELL_TYPES", &types);
            haveTypes = true;
        } else if (key == "point_data" || key == "cell_data") {
            argCount(line, 2);
            sectionCount = checkedCount(in.where(), line[0], in.integer(line[1], line[0] + " count"), 16 * kMaxTets,
                                        std::numeric_limits<std::uint64_t>::max());
            section = key == "point_data" ? Section::Points : Section::Cells;
            if (section == Section::Points && sectionCount != nPoints)
                throw InputError(in.where() + ": POINT_DATA " + std::to_string(sectionCount) + " differs from POINTS " +
                                 std::to_string(nPoints));
        } else if (key == "field") {
            argCount(line, 3);
            const long long arrays = in.integer(line[2], "FIELD array count");
            if (arrays < 0 || arrays > 100000)
                throw InputError(in.where() + ": FIELD array count " + line[2] + " is out of range");
            for (long long a = 0; a < arrays; ++a) {
                auto arr = in.headerLine();
                if (arr.empty())
                    throw InputError(in.file() + ": FIELD " + line[1] + " ends after " + std::to_string(a) + " of " +
                                     std::to_string(arrays) + " arrays (truncated)");
                if (asciiLower(arr[0]) == "null_array")
                    continue;
                if (arr.size() < 4)
                    throw InputError(in.where() + ": FIELD array line needs: name components tuples type");
                const long long comps = in.integer(arr[1], "components"), tuples = in.integer(arr[2], "tuples");
                if (comps < 0 || tuples < 0)
                    throw InputError(in.where() + ": negative FIELD array size");
                dataArray(arr[0], static_cast<std::uint64_t>(comps), static_cast<std::uint64_t>(tuples), in.type(arr[3]),
                          "FIELD array " + arr[0]);
            }
        } else if (key == "scalars") {
            argCount(line, 3);
            const VtkType t = in.type(line[2]);
            const long long comps = line.size() > 3 ? in.integer(line[3], "SCALARS components") : 1;
            if (comps < 1 || comps > 4)
                throw InputError(in.where() + ": SCALARS components " + std::to_string(comps) + " must be 1 to 4");
            auto lut = in.headerLine();
            if (lut.empty() || asciiLower(lut[0]) != "lookup_table")
                throw InputError(in.where() + ": expected LOOKUP_TABLE after SCALARS " + line[1]);
            dataArray(line[1], static_cast<std::uint64_t>(comps), sectionCount, t, "SCALARS " + line[1]);
        } else if (key == "lookup_table") {
            argCount(line, 3);
            const long long n = in.integer(line[2], "LOOKUP_TABLE size");
            if (n < 0)
                throw InputError(in.where() + ": negative LOOKUP_TABLE size");
            const VtkType t = in.binary ? VtkType{1, VtkType::Unsigned} : VtkType{4, VtkType::Float};
            const Section saved = section;
            section = Section::Cells;  // never a point scalar
            dataArray(line[1], 4, static_cast<std::uint64_t>(n), t, "LOOKUP_TABLE " + line[1]);
            section = saved;
        } else if (key == "color_scalars") {
            argCount(line, 3);
            const long long n = in.integer(line[2], "COLOR_SCALARS components");
            if (n < 1 || n > 4)
                throw InputError(in.where() + ": COLOR_SCALARS components must be 1 to 4");
            const VtkType t = in.binary ? VtkType{1, VtkType::Unsigned} : VtkType{4, VtkType::Float};
            const Section saved = section;
            section = Section::Cells;
            dataArray(line[1], static_cast<std::uint64_t>(n), sectionCount, t, "COLOR_SCALARS " + line[1]);
            section = saved;
        } else if (key == "vectors" || key == "normals" || key == "tensors" || key == "tensors6") {
            argCount(line, 3);
            const std::uint64_t comps = key == "tensors" ? 9 : key == "tensors6" ? 6 : 3;
            dataArray(line[1], comps, sectionCount, in.type(line[2]), line[0] + " " + line[1]);
        } else if (key == "texture_coordinates") {
            argCount(line, 4);
            const long long dim = in.integer(line[2], "TEXTURE_COORDINATES dimension");
            if (dim < 1 || dim > 3)
                throw InputError(in.where() + ": TEXTURE_COORDINATES dimension must be 1 to 3");
            dataArray(line[1], static_cast<std::uint64_t>(dim), sectionCount, in.type(line[3]), line[0] + " " + line[1]);
        } else if (key == "global_ids" || key == "pedigree_ids") {
            argCount(line, 3);
            dataArray(line[1], 1, sectionCount, in.type(line[2]), line[0] + " " + line[1]);
        } else if (key == "metadata") {
            // VTK 9's METADATA block (COMPONENT_NAMES, INFORMATION) ends with a blank line: skip it.
            in.skipBlock();
        } else {
            throw InputError(in.where() + ": unknown keyword " + shown(line[0]) +
                             " in an UNSTRUCTURED_GRID (expected POINTS, CELLS, CELL_TYPES, POINT_DATA, ...)");
        }
    }

    if (coords.empty() && nPoints == 0)
        throw InputError(in.file() + ": no POINTS");
    if (!haveCells)
        throw InputError(in.file() + ": no CELLS");
    if (!haveTypes)
        throw InputError(in.file() + ": no CELL_TYPES");
    if (types.size() != nCells)
        throw InputError(in.file() + ": CELL_TYPES has " + std::to_string(types.size()) + " cells, CELLS " +
                         std::to_string(nCells));

    mesh.points.resize(nPoints);
    for (std::uint64_t i = 0; i < nPoints; ++i)
        mesh.points[i] = glm::dvec3(coords[3 * i], coords[3 * i + 1], coords[3 * i + 2]);

    // Cells: point ids [begin, end) of cell c in `cells`.
    const bool v5 = major >= 5;
    for (std::uint64_t c = 0; c < nCells; ++c) {
        const std::int64_t begin = asIndex(offsets[c]), end = v5 ? asIndex(offsets[c + 1]) : -1;
        std::uint64_t b = 0, k = 0;
        if (v5) {
            if (begin < 0 || end < begin || static_cast<std::uint64_t>(end) > cells.size())
                throw InputError(in.file() + ": cell " + std::to_string(c) + " has offsets out of range");
            b = static_cast<std::uint64_t>(begin);
            k = static_cast<std::uint64_t>(end - begin);
        } else {
            b = static_cast<std::uint64_t>(begin);
            k = static_cast<std::uint64_t>(asIndex(cells[b - 1]));
        }
        const std::int64_t type = asIndex(types[c]);
        const std::uint64_t need = type == 10 ? 4 : type == 12 ? 8 : type == 13 ? 6 : 0;
        if (need == 0)
            throw InputError(in.file() + ": cell " + std::to_string(c) + " has type " + numberText(types[c]) +
                             ", only tetra (10), hexahedron (12) and wedge (13) are supported");
        if (k != need)
            throw InputError(in.file() + ": cell " + std::to_string(c) + " of type " + std::to_string(type) + " has " +
                             std::to_string(k) + " points, not " + std::to_string(need));
        std::array<std::uint32_t, 8> v{};
        for (std::uint64_t i = 0; i < k; ++i) {
            const std::int64_t id = asIndex(cells[b + i]);
            if (id < 0 || static_cast<std::uint64_t>(id) >= nPoints)
                throw InputError(in.file() + ": cell " + std::to_string(c) + " has point index " + numberText(cells[b + i]) +
                                 ", out of range (the mesh has " + std::to_string(nPoints) + " points)");
            v[i] = static_cast<std::uint32_t>(id);
        }
        if (type == 10)
            mesh.tets.emplace_back(v[0], v[1], v[2], v[3]);
        else if (type == 12)
            splitHex(v, mesh.tets);
        else
            splitWedge({v[0], v[1], v[2], v[3], v[4], v[5]}, mesh.tets);
    }
    mesh.tetsRead = mesh.tets.size();

    // The point scalar: by name, else the first one-component point array.
    if (pointArrays.empty())
        throw InputError(in.file() + ": no one-component point array (SCALARS or FIELD in POINT_DATA) for the scalar");
    const std::pair<std::string, std::vector<double>>* chosen = &pointArrays.front();
    if (!scalar.empty()) {
        chosen = nullptr;
        std::string names;
        for (const auto& a : pointArrays) {
            names += (names.empty() ? "" : ", ") + a.first;
            if (a.first == scalar && !chosen)
                chosen = &a;
        }
        if (!chosen)
            throw InputError(in.file() + ": no point array named " + shown(scalar) + " (it has " + names + ")");
    }
    mesh.scalars = chosen->second;
    return mesh;
}

// ---------------------------------------------------------------------------------------------------

TetMesh readTetgen(const fs::path& path, const std::string& scalar)
{
    fs::path base = path;
    const std::string ext = asciiLower(path.extension().string());
    if (ext == ".node" || ext == ".ele")
        base.replace_extension();
    const fs::path nodePath = base.string() + ".node", elePath = base.string() + ".ele";

    TetMesh mesh;
    mesh.source = elePath.string();
    std::vector<std::string_view> tok;

    TextLines node(nodePath);
    if (!node.next(tok))
        throw InputError(node.file() + ": empty file");
    const std::uint64_t n = checkedCount(node.where(), "point", node.integer(tok[0], "point count"), kMaxPoints,
                                         node.size() / 8 + 1);
    const long long dim = tok.size() > 1 ? node.integer(tok[1], "dimension") : 3;
    const long long attrs = tok.size() > 2 ? node.integer(tok[2], "attribute count") : 0;
    const long long markers = tok.size() > 3 ? node.integer(tok[3], "boundary marker flag") : 0;
    if (dim != 3)
        throw InputError(node.where() + ": dimension " + std::to_string(dim) + ", only 3 is supported");
    if (attrs < 0 || attrs > 1000 || markers < 0 || markers > 1)
        throw InputError(node.where() + ": attribute count or boundary marker flag out of range");
    const std::size_t attr = attributeIndex(node.file(), scalar);
    if (attrs == 0)
        throw InputError(node.file() + ": no node attributes (the first attribute is the scalar)");
    if (attr >= static_cast<std::size_t>(attrs))
        throw InputError(node.file() + ": scalar attribute " + std::to_string(attr) + " out of range (the file has " +
                         std::to_string(attrs) + ")");
    mesh.points.resize(n);
    mesh.scalars.resize(n);
    long long firstNumber = 0;
    for (std::uint64_t i = 0; i < n; ++i) {
        if (!node.next(tok))
            throw InputError(node.file() + ": ends after " + std::to_string(i) + " of " + std::to_string(n) +
                             " points (truncated or a wrong count)");
        if (tok.size() < 4 + static_cast<std::size_t>(attrs))
            throw InputError(node.where() + ": a point line needs a number, x y z and " + std::to_string(attrs) +
                             " attributes");
        const long long number = node.integer(tok[0], "point number");
        if (i == 0) {
            if (number != 0 && number != 1)
                throw InputError(node.where() + ": the first point is numbered " + std::to_string(number) +
                                 ", expected 0 or 1");
            firstNumber = number;
        } else if (number != firstNumber + static_cast<long long>(i)) {
            throw InputError(node.where() + ": point number " + std::to_string(number) + ", expected " +
                             std::to_string(firstNumber + static_cast<long long>(i)) + " (points must be numbered in order)");
        }
        mesh.points[i] = glm::dvec3(node.real(tok[1], "x"), node.real(tok[2], "y"), node.real(tok[3], "z"));
        mesh.scalars[i] = node.real(tok[4 + attr], "attribute");
    }

    TextLines ele(elePath);
    if (!ele.next(tok))
        throw InputError(ele.file() + ": empty file");
    const std::uint64_t nt = checkedCount(ele.where(), "tetrahedron", ele.integer(tok[0], "tetrahedron count"), kMaxTets,
                                          ele.size() / 10 + 1);
    const long long per = tok.size() > 1 ? ele.integer(tok[1], "nodes per tetrahedron") : 4;
    if (per != 4 && per != 10)
        throw InputError(ele.where() + ": " + std::to_string(per) + " nodes per tetrahedron, expected 4 or 10");
    mesh.tets.resize(nt);
    for (std::uint64_t t = 0; t < nt; ++t) {
        if (!ele.next(tok))
            throw InputError(ele.file() + ": ends after " + std::to_string(t) + " of " + std::to_string(nt) +
                             " tetrahedra (truncated or a wrong count)");
        if (tok.size() < 1 + static_cast<std::size_t>(per))
            throw InputError(ele.where() + ": a tetrahedron line needs a number and " + std::to_string(per) + " points");
        glm::uvec4 c;
        for (int k = 0; k < 4; ++k) {
            const long long number = ele.integer(tok[1 + k], "point index");  // compared before subtracting: no overflow
            if (number < firstNumber || static_cast<std::uint64_t>(number - firstNumber) >= n)
                throw InputError(ele.where() + ": tetrahedron " + std::to_string(t) + " has point index " +
                                 std::to_string(number) + ", out of range (points are numbered " +
                                 std::to_string(firstNumber) + " to " + std::to_string(firstNumber + static_cast<long long>(n) - 1) + ")");
            c[k] = static_cast<std::uint32_t>(number - firstNumber);
        }
        mesh.tets[t] = c;
    }
    mesh.tetsRead = nt;

    // x.neigh (TetGen -n): `ntets 4`, then `number n0 n1 n2 n3`, neighbor i across the face opposite
    // point i, -1 on the boundary, numbered like the points. Used instead of matching faces when present.
    const fs::path neighPath = base.string() + ".neigh";
    std::error_code ec;
    if (!fs::exists(neighPath, ec))
        return mesh;
    TextLines neigh(neighPath);
    if (!neigh.next(tok))
        throw InputError(neigh.file() + ": empty file");
    const long long count = neigh.integer(tok[0], "tetrahedron count");
    if (count != static_cast<long long>(nt))
        throw InputError(neigh.where() + ": " + std::to_string(count) + " tetrahedra, " + ele.file() + " has " +
                         std::to_string(nt));
    mesh.neighbors.resize(nt);
    for (std::uint64_t t = 0; t < nt; ++t) {
        if (!neigh.next(tok))
            throw InputError(neigh.file() + ": ends after " + std::to_string(t) + " of " + std::to_string(nt) +
                             " tetrahedra (truncated or a wrong count)");
        if (tok.size() < 5)
            throw InputError(neigh.where() + ": a neighbor line needs a number and 4 neighbors");
        for (int k = 0; k < 4; ++k) {
            const long long id = neigh.integer(tok[1 + k], "neighbor");
            if (id == -1) {
                mesh.neighbors[t][k] = -1;
                continue;
            }
            if (id < firstNumber || static_cast<std::uint64_t>(id - firstNumber) >= nt)
                throw InputError(neigh.where() + ": neighbor " + std::to_string(id) + " out of range (tetrahedra are numbered " +
                                 std::to_string(firstNumber) + " to " + std::to_string(firstNumber + static_cast<long long>(nt) - 1) +
                                 ", -1 for none)");
            mesh.neighbors[t][k] = static_cast<std::int32_t>(id - firstNumber);
        }
    }
    return mesh;
}

// ---------------------------------------------------------------------------------------------------

TetMesh readOffTet(const fs::path& path, const std::string& scalar)
{
    TextLines in(path);
    TetMesh mesh;
    mesh.source = path.string();
    std::vector<std::string_view> tok;
    if (!in.next(tok))
        throw InputError(in.file() + ": empty file");
    if (asciiLower(std::string(tok[0])) == "off" || asciiLower(std::string(tok[0])) == "toff") {
        tok.erase(tok.begin());
        if (tok.empty() && !in.next(tok))
            throw InputError(in.file() + ": no counts after OFF");
    }
    if (tok.size() < 2)
        throw InputError(in.where() + ": expected the counts \"npoints ntets\"");
    const std::uint64_t n = checkedCount(in.where(), "point", in.integer(tok[0], "point count"), kMaxPoints, in.size() / 6 + 1);
    const std::uint64_t nt =
        checkedCount(in.where(), "tetrahedron", in.integer(tok[1], "tetrahedron count"), kMaxTets, in.size() / 8 + 1);
    const std::size_t attr = attributeIndex(in.file(), scalar);
    mesh.points.resize(n);
    mesh.scalars.resize(n);
    for (std::uint64_t i = 0; i < n; ++i) {
        if (!in.next(tok))
            throw InputError(in.file() + ": ends after " + std::to_string(i) + " of " + std::to_string(n) +
                             " points (truncated or a wrong count)");
        if (tok.size() < 4 + attr)
            throw InputError(in.where() + ": a point line needs x y z and the scalar (value " + std::to_string(attr) +
                             " after z)");
        mesh.points[i] = glm::dvec3(in.real(tok[0], "x"), in.real(tok[1], "y"), in.real(tok[2], "z"));
        mesh.scalars[i] = in.real(tok[3 + attr], "scalar");
    }
    mesh.tets.resize(nt);
    for (std::uint64_t t = 0; t < nt; ++t) {
        if (!in.next(tok))
            throw InputError(in.file() + ": ends after " + std::to_string(t) + " of " + std::to_string(nt) +
                             " tetrahedra (truncated or a wrong count)");
        std::size_t first = 0;
        if (tok.size() == 5 && tok[0] == "4")
            first = 1;
        else if (tok.size() != 4)
            throw InputError(in.where() + ": a cell line is \"a b c d\" or \"4 a b c d\" (" + std::to_string(tok.size()) +
                             " values)");
        glm::uvec4 c;
        for (int k = 0; k < 4; ++k) {
            const long long id = in.integer(tok[first + k], "point index");
            if (id < 0 || static_cast<std::uint64_t>(id) >= n)
                throw InputError(in.where() + ": tetrahedron " + std::to_string(t) + " has point index " +
                                 std::to_string(id) + ", out of range (the mesh has " + std::to_string(n) + " points)");
            c[k] = static_cast<std::uint32_t>(id);
        }
        mesh.tets[t] = c;
    }
    mesh.tetsRead = nt;
    return mesh;
}

// ---------------------------------------------------------------------------------------------------

namespace {

std::int32_t bigInt(const std::string& d, std::size_t at)
{
    return static_cast<std::int32_t>(decodeBig(reinterpret_cast<const unsigned char*>(d.data() + at), {4, VtkType::Signed}));
}
float bigFloat(const std::string& d, std::size_t at)
{
    return static_cast<float>(decodeBig(reinterpret_cast<const unsigned char*>(d.data() + at), {4, VtkType::Float}));
}

// The 3-int header of a PLOT3D file: dimensions, each positive, product bounded.
glm::u64vec3 plot3dDims(const std::string& d, const fs::path& path)
{
    if (d.size() < 12)
        throw InputError(path.string() + ": " + std::to_string(d.size()) + " bytes, too short for a PLOT3D header");
    const std::int32_t nx = bigInt(d, 0), ny = bigInt(d, 4), nz = bigInt(d, 8);
    if (nx < 2 || ny < 2 || nz < 2)
        throw InputError(path.string() + ": PLOT3D dimensions " + std::to_string(nx) + "x" + std::to_string(ny) + "x" +
                         std::to_string(nz) + " (big-endian, single grid) must each be at least 2");
    const std::uint64_t count = std::uint64_t(nx) * std::uint64_t(ny) * std::uint64_t(nz);
    if (count > kMaxPoints)
        throw InputError(path.string() + ": PLOT3D grid of " + std::to_string(count) + " points is too large");
    return {std::uint64_t(nx), std::uint64_t(ny), std::uint64_t(nz)};
}

}  // namespace

TetMesh readPlot3d(const fs::path& xyzPath, const fs::path& qPath, const std::string& scalarName)
{
    const std::string which = scalarName.empty() ? "density" : asciiLower(scalarName);
    if (which != "density" && which != "momentum" && which != "energy" && which != "pressure")
        throw InputError(qPath.string() + ": PLOT3D scalar " + shown(scalarName) +
                         " is not one of density, momentum, energy, pressure");
    const std::string xyz = readWhole(xyzPath);
    const glm::u64vec3 dims = plot3dDims(xyz, xyzPath);
    const std::uint64_t n = dims.x * dims.y * dims.z;
    if (xyz.size() < 12 + 12 * n)
        throw InputError(xyzPath.string() + ": " + std::to_string(xyz.size()) + " bytes, a " + std::to_string(dims.x) +
                         "x" + std::to_string(dims.y) + "x" + std::to_string(dims.z) + " grid needs " +
                         std::to_string(12 + 12 * n) + " (truncated)");
    const std::string q = readWhole(qPath);
    const glm::u64vec3 qd = plot3dDims(q, qPath);
    if (qd != dims)
        throw InputError(qPath.string() + ": dimensions " + std::to_string(qd.x) + "x" + std::to_string(qd.y) + "x" +
                         std::to_string(qd.z) + " differ from the grid's in " + xyzPath.string());
    if (q.size() < 12 + 16 + 20 * n)
        throw InputError(qPath.string() + ": " + std::to_string(q.size()) + " bytes, the solution needs " +
                         std::to_string(12 + 16 + 20 * n) + " (truncated)");

    TetMesh mesh;
    mesh.source = xyzPath.string();
    mesh.points.resize(n);
    mesh.scalars.resize(n);
    for (std::uint64_t i = 0; i < n; ++i)
        mesh.points[i] = glm::dvec3(bigFloat(xyz, 12 + 4 * i), bigFloat(xyz, 12 + 4 * (n + i)), bigFloat(xyz, 12 + 4 * (2 * n + i)));
    const std::size_t q0 = 12 + 16;
    for (std::uint64_t i = 0; i < n; ++i) {
        const double rho = bigFloat(q, q0 + 4 * i);
        const glm::dvec3 m(bigFloat(q, q0 + 4 * (n + i)), bigFloat(q, q0 + 4 * (2 * n + i)), bigFloat(q, q0 + 4 * (3 * n + i)));
        const double e = bigFloat(q, q0 + 4 * (4 * n + i));
        double s = rho;
        if (which == "momentum")
            s = glm::length(m);
        else if (which == "energy")
            s = e;
        else if (which == "pressure")
            s = (1.4 - 1.0) * (e - 0.5 * glm::dot(m, m) / rho);
        mesh.scalars[i] = s;
    }

    const std::uint64_t cells = (dims.x - 1) * (dims.y - 1) * (dims.z - 1);
    if (6 * cells > kMaxTets)
        throw InputError(xyzPath.string() + ": " + std::to_string(6 * cells) + " tetrahedra, the limit is 2^31 - 1");
    mesh.tets.reserve(6 * cells);
    const auto id = [&](std::uint64_t i, std::uint64_t j, std::uint64_t k) {
        return static_cast<std::uint32_t>(i + dims.x * (j + dims.y * k));
    };
    for (std::uint64_t k = 0; k + 1 < dims.z; ++k)
        for (std::uint64_t j = 0; j + 1 < dims.y; ++j)
            for (std::uint64_t i = 0; i + 1 < dims.x; ++i)
                splitHex({id(i, j, k), id(i + 1, j, k), id(i + 1, j + 1, k), id(i, j + 1, k), id(i, j, k + 1),
                          id(i + 1, j, k + 1), id(i + 1, j + 1, k + 1), id(i, j + 1, k + 1)},
                         mesh.tets);
    mesh.tetsRead = mesh.tets.size();
    return mesh;
}

// ---------------------------------------------------------------------------------------------------

void writeTetgen(const TetMesh& mesh, const fs::path& base)
{
    const fs::path nodePath = base.string() + ".node", elePath = base.string() + ".ele";
    {
        std::ofstream out(nodePath);
        if (!out)
            throw InputError(nodePath.string() + ": cannot open for writing");
        out.precision(17);
        out << mesh.points.size() << " 3 1 0\n";
        for (std::size_t i = 0; i < mesh.points.size(); ++i)
            out << i << ' ' << mesh.points[i].x << ' ' << mesh.points[i].y << ' ' << mesh.points[i].z << ' '
                << (i < mesh.scalars.size() ? mesh.scalars[i] : 0.0) << '\n';
        out << "# written by clvr\n";
        if (!out)
            throw InputError(nodePath.string() + ": write error");
    }
    std::ofstream out(elePath);
    if (!out)
        throw InputError(elePath.string() + ": cannot open for writing");
    out << mesh.tets.size() << " 4 0\n";
    for (std::size_t t = 0; t < mesh.tets.size(); ++t)
        out << t << ' ' << mesh.tets[t][0] << ' ' << mesh.tets[t][1] << ' ' << mesh.tets[t][2] << ' ' << mesh.tets[t][3]
            << '\n';
    out << "# written by clvr\n";
    if (!out)
        throw InputError(elePath.string() + ": write error");
    // The adjacency, so that readers (clvr render) need not match faces again.
    const TetTopology topology = buildTopology(mesh);
    const fs::path neighPath = base.string() + ".neigh";
    std::ofstream neigh(neighPath);
    if (!neigh)
        throw InputError(neighPath.string() + ": cannot open for writing");
    neigh << mesh.tets.size() << " 4\n";
    for (std::size_t t = 0; t < mesh.tets.size(); ++t) {
        const auto& a = topology.neighbor[t];
        neigh << t << ' ' << a[0] << ' ' << a[1] << ' ' << a[2] << ' ' << a[3] << '\n';
    }
    neigh << "# written by clvr\n";
    if (!neigh)
        throw InputError(neighPath.string() + ": write error");
}

void writeVtkUnstructured(const TetMesh& mesh, const fs::path& path, bool binary, const std::string& scalarName)
{
    std::ofstream out(path, std::ios::binary);
    if (!out)
        throw InputError(path.string() + ": cannot open for writing");
    out.precision(17);
    const auto put = [&](auto v) {
        char b[sizeof(v)];
        std::memcpy(b, &v, sizeof(v));
        if constexpr (std::endian::native == std::endian::little)
            std::reverse(b, b + sizeof(v));
        out.write(b, sizeof(v));
    };
    out << "# vtk DataFile Version 3.0\nclvr tetrahedral mesh\n" << (binary ? "BINARY" : "ASCII")
        << "\nDATASET UNSTRUCTURED_GRID\nPOINTS " << mesh.points.size() << " double\n";
    for (const glm::dvec3& p : mesh.points) {
        if (binary) {
            put(p.x);
            put(p.y);
            put(p.z);
        } else {
            out << p.x << ' ' << p.y << ' ' << p.z << '\n';
        }
    }
    out << "\nCELLS " << mesh.tets.size() << ' ' << 5 * mesh.tets.size() << '\n';
    for (const glm::uvec4& t : mesh.tets) {
        if (binary) {
            put(std::int32_t(4));
            for (int k = 0; k < 4; ++k)
                put(static_cast<std::int32_t>(t[k]));
        } else {
            out << "4 " << t[0] << ' ' << t[1] << ' ' << t[2] << ' ' << t[3] << '\n';
        }
    }
    out << "\nCELL_TYPES " << mesh.tets.size() << '\n';
    for (std::size_t t = 0; t < mesh.tets.size(); ++t) {
        if (binary)
            put(std::int32_t(10));
        else
            out << "10\n";
    }
    out << "\nPOINT_DATA " << mesh.points.size() << "\nSCALARS " << scalarName << " double 1\nLOOKUP_TABLE default\n";
    for (double s : mesh.scalars) {
        if (binary)
            put(s);
        else
            out << s << '\n';
    }
    out << '\n';
    if (!out)
        throw InputError(path.string() + ": write error");
}

// ---------------------------------------------------------------------------------------------------

namespace {

}  // namespace

namespace {

// The mesh as read, before checkMesh: by the file's extension, which parseMeshSpec has checked.
TetMesh readMeshFile(const MeshSpec& spec)
{
    const std::string ext = asciiLower(spec.file.extension().string());
    if (ext == ".node" || ext == ".ele")
        return readTetgen(spec.file, spec.scalar);
    if (ext == ".vtk")
        return readVtkUnstructured(spec.file, spec.scalar);
    if (ext == ".off")
        return readOffTet(spec.file, spec.scalar);
    if (ext == ".vtu" || ext == ".pvtu")
        return readVtkXmlUnstructured(spec.file, spec.scalar);
    throw InternalError("loadMesh: mesh file " + spec.file.string() + " has an extension parseMeshSpec rejects");
}

}  // namespace

TetMesh loadMesh(const MeshSpec& spec)
{
    if (spec.kind == MeshSpec::Kind::Surface) {
        MesherOptions options;
        options.quality = spec.quality;
        options.maxVolume = spec.maxVolume;
        options.scalar = spec.scalar;
        return meshSurface(spec.surface, options);  // checked by meshSurface
    }
    TetMesh mesh = spec.kind == MeshSpec::Kind::Generator ? automatonMesh(spec.cells, spec.grid)
                   : spec.kind == MeshSpec::Kind::Plot3d  ? readPlot3d(spec.file, spec.qFile, spec.scalar)
                                                          : readMeshFile(spec);
    checkMesh(mesh);
    if (mesh.tets.empty())
        throw InputError(mesh.source + ": no tetrahedra left (" + std::to_string(mesh.tetsRead) + " read, " +
                         std::to_string(mesh.tetsDegenerate) + " of zero volume)");
    return mesh;
}

TetMesh loadMesh(const nlohmann::json& spec, const fs::path& baseDir)
{
    return loadMesh(parseMeshSpec(spec, baseDir));
}

}  // namespace clvr
