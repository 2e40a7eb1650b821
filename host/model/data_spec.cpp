// host/model/data_spec.cpp — parsing and checking of the scene's "volume" and "mesh" objects into
// VolumeSpec and MeshSpec: forms, keys, types and file extensions; nothing is read from disk.
#include "host/model/data_spec.h"

#include "host/runtime/errors.h"
#include "host/runtime/file_io.h"

#include <nlohmann/json.hpp>

#include <algorithm>
#include <array>
#include <cctype>
#include <climits>
#include <cmath>
#include <cstddef>
#include <initializer_list>
#include <string_view>
#include <utility>

namespace clvr {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;

// `s` quoted, unprintable characters as '?', cut after `limit` characters.
std::string shown(std::string_view s, std::size_t limit)
{
    std::string out = "\"";
    for (std::size_t i = 0; i < s.size() && i < limit; ++i)
        out += std::isprint(static_cast<unsigned char>(s[i])) ? s[i] : '?';
    if (s.size() > limit)
        out += "...";
    return out + "\"";
}

fs::path resolve(const fs::path& baseDir, const std::string& file)
{
    const fs::path p(file);
    return p.is_absolute() ? p : baseDir / p;
}

// ---------------------------------------------------------------------------------------------------
// "volume"

[[noreturn]] void badVolumeKey(const std::string& key, const std::string& what)
{
    throw InputError("volume: \"" + key + "\" " + what);
}

glm::dvec3 volumeVec3(const json& spec, const std::string& key)
{
    const json& v = spec.at(key);
    if (!v.is_array() || v.size() != 3 || !std::all_of(v.begin(), v.end(), [](const auto& x) { return x.is_number(); }))
        badVolumeKey(key, "must be an array of 3 numbers");
    return {v[0].get<double>(), v[1].get<double>(), v[2].get<double>()};
}

glm::ivec3 jsonDims(const json& spec)
{
    if (!spec.contains("dims"))
        badVolumeKey("dims", "is missing");
    const json& v = spec.at("dims");
    if (!v.is_array() || v.size() != 3 ||
        !std::all_of(v.begin(), v.end(), [](const auto& x) { return x.is_number_integer(); }))
        badVolumeKey("dims", "must be an array of 3 integers");
    glm::ivec3 d;
    for (int a = 0; a < 3; ++a) {
        const long long n = v[static_cast<std::size_t>(a)].get<long long>();
        if (n < 1 || n > INT_MAX)
            badVolumeKey("dims", "[" + std::to_string(a) + "] is " + std::to_string(n) + ", must be a positive int");
        d[a] = static_cast<int>(n);
    }
    return d;
}

std::string jsonString(const json& spec, const std::string& key)
{
    const json& v = spec.at(key);
    if (!v.is_string())
        badVolumeKey(key, "must be a string");
    return v.get<std::string>();
}

void checkKeys(const json& spec, std::initializer_list<const char*> allowed, const std::string& form)
{
    for (auto it = spec.begin(); it != spec.end(); ++it) {
        if (std::none_of(allowed.begin(), allowed.end(), [&](const char* k) { return it.key() == k; })) {
            std::string list;
            for (const char* k : allowed)
                list += (list.empty() ? "" : ", ") + std::string(k);
            throw InputError("volume: unknown key \"" + it.key() + "\" for " + form + " (allowed: " + list + ")");
        }
    }
}

ScalarType parseRawType(const json& spec)
{
    if (!spec.contains("type"))
        badVolumeKey("type", "is missing (uint8, int8, int16, uint16, int32, uint32, float32 or float64)");
    const std::string type = jsonString(spec, "type");
    static const std::array<std::pair<const char*, ScalarType>, 8> kTypes{{
        {"uint8", ScalarType::UInt8},   {"int8", ScalarType::Int8},     {"int16", ScalarType::Int16},
        {"uint16", ScalarType::UInt16}, {"int32", ScalarType::Int32},   {"uint32", ScalarType::UInt32},
        {"float32", ScalarType::Float32}, {"float64", ScalarType::Float64},
    }};
    const auto it = std::find_if(kTypes.begin(), kTypes.end(), [&](const auto& p) { return type == p.first; });
    if (it == kTypes.end())
        badVolumeKey("type", "is " + shown(type, 60) + " (uint8, int8, int16, uint16, int32, uint32, float32 or float64)");
    return it->second;
}

RawLayout parseRawLayout(const json& spec)
{
    checkKeys(spec, {"file", "dims", "type", "endian", "spacing", "origin", "header_bytes"}, "a raw file");
    RawLayout layout;
    layout.dims = jsonDims(spec);
    layout.type = parseRawType(spec);
    const bool multiByte = layout.type != ScalarType::UInt8 && layout.type != ScalarType::Int8;
    if (spec.contains("endian")) {
        const std::string e = jsonString(spec, "endian");
        if (e != "little" && e != "big")
            badVolumeKey("endian", "is " + shown(e, 60) + ", must be little or big");
        layout.endian = e == "big" ? Endian::Big : Endian::Little;
    } else if (multiByte) {
        badVolumeKey("endian", "is missing (little or big)");
    }
    if (spec.contains("spacing"))
        layout.spacing = volumeVec3(spec, "spacing");
    if (spec.contains("origin"))
        layout.origin = volumeVec3(spec, "origin");
    if (spec.contains("header_bytes")) {
        const json& hb = spec.at("header_bytes");
        if (!hb.is_number_integer() || hb.get<long long>() < 0)
            badVolumeKey("header_bytes", "must be a non-negative integer");
        layout.headerBytes = hb.get<std::uint64_t>();
    }
    return layout;
}

// ---------------------------------------------------------------------------------------------------
// "mesh"

std::string meshFileScalar(const json& spec)
{
    if (!spec.contains("scalar"))
        return "";
    const json& s = spec["scalar"];
    if (s.is_string())
        return s.get<std::string>();
    if (s.is_number_integer() && s.get<std::int64_t>() >= 0)
        return std::to_string(s.get<std::int64_t>());
    throw InputError("scene: mesh.scalar must be a name (string) or an attribute index (non-negative integer)");
}

// {"surface": ..., "quality": Q, "max_volume": V, "scalar": generator or volume file}
MeshSpec parseSurfaceSpec(const json& spec, const fs::path& baseDir)
{
    for (auto it = spec.begin(); it != spec.end(); ++it)
        if (it.key() != "surface" && it.key() != "quality" && it.key() != "max_volume" && it.key() != "scalar")
            throw InputError("scene: mesh." + it.key() +
                             " is not a key of a surface mesh (surface, quality, max_volume, scalar)");
    if (!spec["surface"].is_string())
        throw InputError("scene: mesh.surface must be a file name (string)");
    MeshSpec m;
    m.kind = MeshSpec::Kind::Surface;
    const auto positive = [&](const char* key, double& out) {
        if (!spec.contains(key))
            return;
        const json& v = spec[key];
        if (!v.is_number() || !(v.get<double>() > 0.0) || !std::isfinite(v.get<double>()))
            throw InputError(std::string("scene: mesh.") + key + " must be a positive number, got " + v.dump());
        out = v.get<double>();
    };
    positive("quality", m.quality);
    positive("max_volume", m.maxVolume);
    m.scalar = "sphere";
    if (spec.contains("scalar")) {
        if (!spec["scalar"].is_string())
            throw InputError("scene: mesh.scalar must be a generator name or a volume file (string) for a surface");
        m.scalar = spec["scalar"].get<std::string>();
        const std::string ext = asciiLower(fs::path(m.scalar).extension().string());
        if (ext == ".nrrd" || ext == ".nhdr")
            m.scalar = resolve(baseDir, m.scalar).string();
    }
    m.surface = resolve(baseDir, spec["surface"].get<std::string>());
    return m;
}

}  // namespace

VolumeSpec parseVolumeSpec(const json& spec, const fs::path& baseDir)
{
    if (!spec.is_object())
        throw InputError("volume: must be an object with \"file\" or \"generator\"");
    const bool hasFile = spec.contains("file"), hasGenerator = spec.contains("generator");
    if (hasFile == hasGenerator)
        throw InputError(std::string("volume: needs exactly one of \"file\" and \"generator\"") +
                         (hasFile ? ", has both" : ", has neither"));
    VolumeSpec v;
    if (hasGenerator) {
        checkKeys(spec, {"generator", "dims"}, "a generator");
        v.kind = VolumeSpec::Kind::Generator;
        v.generator = jsonString(spec, "generator");
        v.dims = jsonDims(spec);
        return v;
    }
    const fs::path file = jsonString(spec, "file");
    v.file = file.is_absolute() ? file : baseDir / file;
    const std::string ext = asciiLower(file.extension().string());
    const bool vtkImage = ext == ".vti" || ext == ".pvti" || ext == ".mhd" || ext == ".mha";
    const bool selfDescribing = ext == ".nrrd" || ext == ".nhdr" || ext == ".vtk" || ext == ".npy" || vtkImage;
    if (!selfDescribing && (spec.contains("dims") || ext == ".raw")) {
        v.kind = VolumeSpec::Kind::Raw;
        v.raw = parseRawLayout(spec);
        return v;
    }
    if (ext == ".npy") {  // an array without geometry: spacing and origin from the scene
        checkKeys(spec, {"file", "spacing", "origin"}, "a .npy file");
        v.kind = VolumeSpec::Kind::Npy;
        if (spec.contains("spacing"))
            v.raw.spacing = volumeVec3(spec, "spacing");
        if (spec.contains("origin"))
            v.raw.origin = volumeVec3(spec, "origin");
        for (int a = 0; a < 3; ++a)
            if (!(v.raw.spacing[a] > 0.0) || !std::isfinite(v.raw.spacing[a]) || !std::isfinite(v.raw.origin[a]))
                badVolumeKey("spacing", "must be finite and > 0, with a finite origin");
        return v;
    }
    if (vtkImage) {
        checkKeys(spec, {"file", "scalar"}, "a " + ext + " file");
        v.kind = VolumeSpec::Kind::VtkImage;
        if (spec.contains("scalar"))
            v.scalar = jsonString(spec, "scalar");
        return v;
    }
    checkKeys(spec, {"file"}, ext.empty() ? "a file" : "a " + ext + " file");
    if (ext == ".nrrd" || ext == ".nhdr")
        v.kind = VolumeSpec::Kind::Nrrd;
    else if (ext == ".vtk")
        v.kind = VolumeSpec::Kind::Vtk;
    else
        throw InputError(v.file.string() + ": unknown volume format " + shown(ext, 60) +
                         " (.nrrd, .nhdr, .vtk, .vti, .pvti, .mhd, .mha, .npy, or .raw / any file with \"dims\")");
    return v;
}

MeshSpec parseMeshSpec(const json& spec, const fs::path& baseDir)
{
    if (!spec.is_object())
        throw InputError("scene: \"mesh\" must be an object such as {\"file\": \"x.vtk\"}");
    if (spec.contains("surface"))
        return parseSurfaceSpec(spec, baseDir);
    if (spec.contains("generator")) {
        // {"generator": "automaton", "cells": N, "grid": G}: a mesh made in code (host/io/generators.h).
        for (auto it = spec.begin(); it != spec.end(); ++it)
            if (it.key() != "generator" && it.key() != "cells" && it.key() != "grid")
                throw InputError("scene: mesh." + it.key() + " is not a key of a generated mesh (generator, cells, grid)");
        MeshSpec m;
        m.kind = MeshSpec::Kind::Generator;
        if (!spec["generator"].is_string() || spec["generator"].get<std::string>() != "automaton")
            throw InputError("scene: mesh.generator must be \"automaton\", got " + shown(spec["generator"].dump(), 40));
        m.generator = "automaton";
        const auto integer = [&](const char* key, int lo, int hi, int& out) {
            if (!spec.contains(key))
                return;
            const json& v = spec[key];
            if (!v.is_number_integer() || v.get<std::int64_t>() < lo || v.get<std::int64_t>() > hi)
                throw InputError(std::string("scene: mesh.") + key + " must be an integer in [" + std::to_string(lo) +
                                 ", " + std::to_string(hi) + "], got " + shown(v.dump(), 40));
            out = static_cast<int>(v.get<std::int64_t>());
        };
        integer("cells", 1, 1 << 24, m.cells);
        integer("grid", 1, 1024, m.grid);
        return m;
    }
    for (auto it = spec.begin(); it != spec.end(); ++it)
        if (it.key() != "file" && it.key() != "q_file" && it.key() != "scalar")
            throw InputError("scene: mesh." + it.key() + " is not a mesh key (file, q_file, scalar, or surface)");
    if (!spec.contains("file") || !spec["file"].is_string())
        throw InputError("scene: mesh.file must be a file name (string)");
    MeshSpec m;
    m.scalar = meshFileScalar(spec);
    m.file = resolve(baseDir, spec["file"].get<std::string>());
    if (spec.contains("q_file")) {
        if (!spec["q_file"].is_string())
            throw InputError("scene: mesh.q_file must be a file name (string)");
        m.kind = MeshSpec::Kind::Plot3d;
        m.qFile = resolve(baseDir, spec["q_file"].get<std::string>());
        if (m.scalar.empty())
            m.scalar = "density";
        return m;
    }
    m.kind = MeshSpec::Kind::File;
    const std::string ext = asciiLower(m.file.extension().string());
    if (ext == ".bin" || ext == ".xyz" || ext == ".x")
        throw InputError("scene: mesh.file " + m.file.string() + " looks like a PLOT3D grid: mesh.q_file is missing");
    if (ext != ".node" && ext != ".ele" && ext != ".vtk" && ext != ".off" && ext != ".vtu" && ext != ".pvtu")
        throw InputError(m.file.string() + ": unknown mesh format " + shown(ext, 40) +
                         " (.node, .ele, .vtk, .vtu, .pvtu, .off, or PLOT3D with q_file)");
    return m;
}

}  // namespace clvr
