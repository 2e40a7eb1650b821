// host/render/options_util.h — small pieces every renderer shares: the walk over the scene's "options"
// checked against the technique's registry entry (host/render/renderer.h), the InputError for a bad one
// ("options.KEY: what"), the checks of integer and number options, the options several techniques
// share (one name, one meaning, one check, one line of help), and a host vector as a cl_float4.
#pragma once

#include "host/model/volume.h"
#include "host/runtime/device.h"
#include "host/runtime/errors.h"
#include "host/render/renderer.h"

#include <CL/opencl.hpp>
#include <glm/glm.hpp>
#include <nlohmann/json.hpp>

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <initializer_list>
#include <optional>
#include <string>

namespace clvr {

[[noreturn]] inline void badOption(const std::string& key, const std::string& what)
{
    throw InputError("options." + key + ": " + what);
}

// Calls visit(key, value) for every key of a scene's "options" (none when it is null); InputError
// "options: must be an object" for anything else, and "options.KEY: unknown option for T (known: ...)"
// for a key the technique's registry entry does not list, so a technique accepts only what
// `clvr techniques` shows. A listed key that `visit` does not handle must call unparsedOption.
template <class Visit>
void forEachOption(const nlohmann::json& options, const TechniqueInfo& info, Visit visit)
{
    if (options.is_null())
        return;
    if (!options.is_object())
        throw InputError("options: must be an object");
    for (const auto& [key, value] : options.items()) {
        if (!info.option(key))
            badOption(key, "unknown option for " + info.name + " (known: " + info.optionList() + ")");
        visit(key, value);
    }
}

// A listed option the parser has no branch for: the registry and the parser disagree.
[[noreturn]] inline void unparsedOption(const TechniqueInfo& info, const std::string& key)
{
    throw InternalError("options." + key + " is listed for " + info.name + " but its parser does not read it");
}

// The value of integer option `key` in [lo, hi]; else "options.KEY: must be an integer in [lo, hi], got V".
inline int integerOption(const std::string& key, const nlohmann::json& value, long long lo, long long hi)
{
    if (!value.is_number_integer() || value.get<long long>() < lo || value.get<long long>() > hi)
        badOption(key, "must be an integer in [" + std::to_string(lo) + ", " + std::to_string(hi) + "], got " + value.dump());
    return static_cast<int>(value.get<long long>());
}

// The index in `names` of string option `key`; else "options.KEY: must be "a", "b" or "c", got V".
inline int choiceOption(const std::string& key, const nlohmann::json& value, std::initializer_list<const char*> names)
{
    const std::string s = value.is_string() ? value.get<std::string>() : "";
    std::string list;
    int i = 0;
    for (const char* name : names) {
        if (s == name)
            return i;
        list += std::string(i == 0 ? "" : (i + 1 == static_cast<int>(names.size()) ? " or " : ", ")) + '"' + name + '"';
        ++i;
    }
    badOption(key, "must be " + list + ", got " + value.dump());
}

// The value of boolean option `key`; else "options.KEY: must be true or false, got V".
inline bool booleanOption(const std::string& key, const nlohmann::json& value)
{
    if (!value.is_boolean())
        badOption(key, "must be true or false, got " + value.dump());
    return value.get<bool>();
}

// The value of number option `key` when it is finite and ok(value); else "options.KEY: must be WHAT, got V".
inline double numberOption(const std::string& key, const nlohmann::json& value, bool (*ok)(double), const std::string& what)
{
    if (!value.is_number() || !std::isfinite(value.get<double>()) || !ok(value.get<double>()))
        badOption(key, "must be " + what + ", got " + value.dump());
    return value.get<double>();
}

// The options that mean the same in every technique that has them: the check and the registry entry.
constexpr int kMaxSlices = 65536;
constexpr int kMaxReflectanceMapSize = 1024;  // 6 * 1024^2 entries * 16 bytes = 96 MiB

// "slices": view-aligned slices across the volume box's eye-depth range.
inline int slicesOption(const nlohmann::json& value) { return integerOption("slices", value, 1, kMaxSlices); }

// "slice_spacing": world units between slices along the view direction (instead of slices).
inline double sliceSpacingOption(const nlohmann::json& value)
{
    return numberOption("slice_spacing", value, [](double x) { return x > 0.0; }, "a positive number (world units)");
}

// InputError when both slices and slice_spacing are given.
inline void checkSlicesOrSpacing(const nlohmann::json& options)
{
    if (options.is_object() && options.contains("slices") && options.contains("slice_spacing"))
        badOption("slice_spacing", "give either slices or slice_spacing, not both");
}

// "early_termination": stop a ray (front to back) once its accumulated opacity A >= this; 1 = off.
inline double earlyTerminationOption(const nlohmann::json& value)
{
    return numberOption("early_termination", value, [](double x) { return x > 0.0 && x <= 1.0; },
                        "an opacity in (0, 1] (1 = off)");
}

// "opacity_threshold": samples with alpha <= this are neither shaded nor composited.
inline double opacityThresholdOption(const nlohmann::json& value)
{
    return numberOption("opacity_threshold", value, [](double x) { return x >= 0.0 && x < 1.0; },
                        "an opacity in [0, 1) (0 = skip only transparent samples)");
}

// "reflectance_map_size": n of the shaded techniques' reflectance map, 6 n^2 shades.
inline int reflectanceMapSizeOption(const nlohmann::json& value)
{
    return integerOption("reflectance_map_size", value, 1, kMaxReflectanceMapSize);
}

// Their registry entries, each with the default of the technique that lists it.
inline OptionInfo slicesInfo(int slices = 256)
{
    return {"slices", slices, "", "view-aligned slices across the data's eye-depth range"};
}
inline OptionInfo sliceSpacingInfo()
{
    return {"slice_spacing", nullptr, "from slices", "world units between slices along the view direction (not with slices)"};
}
inline OptionInfo earlyTerminationInfo(double opacity)
{
    return {"early_termination", opacity, "", "stop a ray once its opacity reaches this, in (0, 1]; 1 = off"};
}
inline OptionInfo opacityThresholdInfo()
{
    return {"opacity_threshold", 0.0, "", "samples with alpha <= this, in [0, 1), are neither shaded nor composited"};
}
inline OptionInfo reflectanceMapSizeInfo()
{
    return {"reflectance_map_size", 128, "", "n of the reflectance map of shaded rendering (\"lights\"): 6 n^2 shades"};
}
inline OptionInfo packetsInfo()
{
    return {"packets", nullptr, "true on CPU devices without a loop-iteration cap (PoCL), false on others",
            "fused path: 8 neighbouring pixels per work-item as vector lanes (the same image) where the technique's "
            "mode has them (docs/scene-format.md), or false: one pixel per work-item"};
}
// Ray packets (slice3d's, stack2d's and spherical's "packets"): pixels per work-item, the lanes of
// kernels/packet.h (CLVR_LANES); work-item x renders pixels kPacketLanes x .. kPacketLanes x + kPacketLanes - 1
// of its row.
constexpr int kPacketLanes = 8;

// "packets" left out (or null): packets on CPU devices, where PoCL turns the lanes into SIMD and they took
// slice3d's kernel from 141-155 to 51-52 ms (run PK1); one pixel per work-item elsewhere: on an NVIDIA H200
// the packet kernel took 2.7-4.2x the one-pixel kernel's time (0.86 against 0.31 ms, run GPU2); and on a CPU
// device that caps a work-item's loop iterations (Mesa's llvmpipe, Device::loopIterationCap), which vectorizes
// work-items itself: there projtet's packets, a tile's list per work-item, ran past the cap and dropped 1 % of
// bluntfin's pixels, and took 6x the one-pixel kernel's time (docs/devices.md).
inline bool packetsByDefault(const std::string& deviceType, std::uint64_t loopIterationCap)
{
    return deviceType == "CPU" && loopIterationCap == 0;
}
inline bool packetsOnDevice(const std::optional<bool>& packets, Device& device)
{
    if (packets)
        return *packets;
    const std::string& type = device.listing().type;
    return packetsByDefault(type, type == "CPU" ? device.loopIterationCap() : 0);  // the loop probe runs on CPUs only
}
// "packets": true or false, or null for the device's default.
inline std::optional<bool> packetsOption(const std::string& key, const nlohmann::json& value)
{
    return value.is_null() ? std::nullopt : std::optional<bool>(booleanOption(key, value));
}
// Work-items across a row of `width` pixels: one per pixel, or one per kPacketLanes with packets.
inline std::size_t rowWorkItems(int width, bool packets)
{
    const auto w = static_cast<std::size_t>(width);
    return packets ? (w + kPacketLanes - 1) / kPacketLanes : w;
}
inline OptionInfo clipTextureInfo()
{
    return {"clip_texture", nullptr, "none", "clip by a second texture (file or generator; docs/slice3d.md, Clip textures)"};
}

inline cl_float4 toCl4(const glm::dvec3& v, double w = 0.0)
{
    return {{static_cast<float>(v.x), static_cast<float>(v.y), static_cast<float>(v.z), static_cast<float>(w)}};
}

// The sort-last fields every grid kernel's parameters carry (part_offset, own_lo, own_hi: the part's point
// 0 in the full grid and the full grid coordinates it samples; kernels/volume_sampling.h clvr_grid_owned)
// for `part` of a volume of `dims` points.
template <class Params>
void setGridPartParams(Params& params, const GridPart& part, const glm::ivec3& dims)
{
    const glm::vec3 lo = part.ownLo(), hi = part.ownHi(dims);
    params.part_offset = cl_int4{{part.offset.x, part.offset.y, part.offset.z, 0}};
    params.own_lo = cl_float4{{lo.x, lo.y, lo.z, 0.0f}};
    params.own_hi = cl_float4{{hi.x, hi.y, hi.z, 0.0f}};
}

}  // namespace clvr
