// host/io/volume_io.cpp — NRRD, raw and VTK legacy STRUCTURED_POINTS readers, and the scene's "volume" object.
// Every size from a file is checked before it is used: counts are uint64 with overflow checks, files are
// measured before they are read, and gzip output is bounded before it is allocated.
#include "host/io/volume_io.h"

#include "host/runtime/errors.h"
#include "host/runtime/file_io.h"
#include "host/io/generators.h"
#include "host/io/vtk_xml_io.h"

#include <nlohmann/json.hpp>
#include <zlib.h>

#include <algorithm>
#include <array>
#include <bit>
#include <cctype>
#include <charconv>
#include <climits>
#include <cmath>
#include <cstring>
#include <fstream>
#include <functional>
#include <limits>
#include <optional>
#include <sstream>
#include <vector>

namespace clvr {

namespace fs = std::filesystem;

namespace {

// ---------------------------------------------------------------------------------------------------
// Small text helpers.

std::string trim(std::string_view s)
{
    std::size_t b = 0, e = s.size();
    while (b < e && std::isspace(static_cast<unsigned char>(s[b])))
        ++b;
    while (e > b && std::isspace(static_cast<unsigned char>(s[e - 1])))
        --e;
    return std::string(s.substr(b, e - b));
}

std::vector<std::string> splitWhitespace(std::string_view s)
{
    std::vector<std::string> out;
    std::size_t i = 0;
    while (i < s.size()) {
        while (i < s.size() && std::isspace(static_cast<unsigned char>(s[i])))
            ++i;
        std::size_t j = i;
        while (j < s.size() && !std::isspace(static_cast<unsigned char>(s[j])))
            ++j;
        if (j > i)
            out.emplace_back(s.substr(i, j - i));
        i = j;
    }
    return out;
}

// Text for messages: long or binary garbage is cut and made printable.
std::string shown(std::string_view s)
{
    std::string out = "\"";
    for (std::size_t i = 0; i < s.size() && i < 60; ++i)
        out += std::isprint(static_cast<unsigned char>(s[i])) ? s[i] : '?';
    if (s.size() > 60)
        out += "...";
    return out + "\"";
}

std::optional<long long> parseInteger(std::string_view s)
{
    long long v = 0;
    if (!s.empty() && s[0] == '+')
        s.remove_prefix(1);
    const auto [end, ec] = std::from_chars(s.data(), s.data() + s.size(), v);
    if (ec != std::errc() || end != s.data() + s.size() || s.empty())
        return std::nullopt;
    return v;
}

// Accepts what strtod accepts ("nan", "inf", exponents), but the whole token must be a number.
std::optional<double> parseDouble(const std::string& s)
{
    if (s.empty())
        return std::nullopt;
    char* end = nullptr;
    const double v = std::strtod(s.c_str(), &end);
    if (end != s.c_str() + s.size())
        return std::nullopt;
    return v;
}

std::string dimsText(const std::vector<long long>& sizes)
{
    std::string s;
    for (std::size_t a = 0; a < sizes.size(); ++a) {
        if (a)
            s += 'x';
        s += std::to_string(sizes[a]);
    }
    return s;
}

// ---------------------------------------------------------------------------------------------------
// Sizes and files.

// The grid point count, or InputError: every size must be a positive int and the product at most kMaxVoxels.
// `checkMemory`: also InputError when the volume would take more than half of the machine's memory; a
// reader that can first check the file holds the data (NRRD) passes false and checks memory after that.
std::uint64_t checkedVoxelCount(const std::string& source, const std::vector<long long>& sizes, bool checkMemory = true)
{
    std::uint64_t count = 1;
    bool overflow = false;
    for (std::size_t a = 0; a < sizes.size(); ++a) {
        if (sizes[a] <= 0)
            throw InputError(source + ": size of axis " + std::to_string(a) + " is " + std::to_string(sizes[a]) +
                             ", sizes must be positive");
        overflow = overflow || __builtin_mul_overflow(count, static_cast<std::uint64_t>(sizes[a]), &count);
    }
    bool tooLarge = overflow || count > kMaxVoxels;
    for (long long s : sizes)
        tooLarge = tooLarge || s > INT_MAX;
    if (tooLarge)
        throw InputError(source + ": " + dimsText(sizes) + " is too large (" +
                         (overflow ? std::string("the product overflows") : std::to_string(count) + " grid points") +
                         ", the limit is 2^34)");
    if (checkMemory)
        checkHostMemoryForVoxels(source, count);
    return count;
}

std::ifstream openBinary(const fs::path& path)
{
    fileSize(path);  // names a missing file or a directory before the stream hides why
    std::ifstream in(path, std::ios::binary);
    if (!in)
        throw InputError(path.string() + ": cannot open for reading");
    return in;
}

void readExactly(std::ifstream& in, const fs::path& path, std::uint64_t offset, char* dst, std::uint64_t n)
{
    in.clear();
    in.seekg(static_cast<std::streamoff>(offset));
    in.read(dst, static_cast<std::streamsize>(n));
    if (!in || static_cast<std::uint64_t>(in.gcount()) != n)
        throw InputError(path.string() + ": read error at byte " + std::to_string(offset));
}

// ---------------------------------------------------------------------------------------------------
// Sample conversion: bytes of any ScalarType and endianness to float, rejecting NaN and infinity.

template <typename T>
T loadSample(const unsigned char* p, bool swap)
{
    std::array<unsigned char, sizeof(T)> b;
    std::memcpy(b.data(), p, sizeof(T));
    if (swap)
        std::reverse(b.begin(), b.end());
    T v;
    std::memcpy(&v, b.data(), sizeof(T));
    return v;
}

template <typename T>
void convertTyped(const unsigned char* src, std::size_t count, bool swap, float* dst)
{
    for (std::size_t i = 0; i < count; ++i)
        dst[i] = static_cast<float>(loadSample<T>(src + i * sizeof(T), swap));
}

// Converts `count` samples; `first` is the index of src's first sample in the whole volume, for messages.
void convertSamples(const std::string& source, const unsigned char* src, std::size_t count, ScalarType type,
                    Endian endian, float* dst, std::uint64_t first, glm::ivec3 dims)
{
    const bool swap = scalarSize(type) > 1 && (endian == Endian::Big) != (std::endian::native == std::endian::big);
    switch (type) {
    case ScalarType::UInt8: convertTyped<std::uint8_t>(src, count, swap, dst); break;
    case ScalarType::Int8: convertTyped<std::int8_t>(src, count, swap, dst); break;
    case ScalarType::Int16: convertTyped<std::int16_t>(src, count, swap, dst); break;
    case ScalarType::UInt16: convertTyped<std::uint16_t>(src, count, swap, dst); break;
    case ScalarType::Int32: convertTyped<std::int32_t>(src, count, swap, dst); break;
    case ScalarType::UInt32: convertTyped<std::uint32_t>(src, count, swap, dst); break;
    case ScalarType::Float32: convertTyped<float>(src, count, swap, dst); break;
    case ScalarType::Float64: convertTyped<double>(src, count, swap, dst); break;
    }
    if (type == ScalarType::Float32 || type == ScalarType::Float64) {
        for (std::size_t i = 0; i < count; ++i) {
            if (std::isfinite(dst[i]))
                continue;
            const std::uint64_t n = first + i;
            const std::uint64_t nx = static_cast<std::uint64_t>(dims.x), nxy = nx * static_cast<std::uint64_t>(dims.y);
            const double original = type == ScalarType::Float32
                                        ? static_cast<double>(loadSample<float>(src + i * 4, swap))
                                        : loadSample<double>(src + i * 8, swap);
            throw InputError(source + ": value at grid point (" + std::to_string(n % nx) + "," +
                             std::to_string(n / nx % static_cast<std::uint64_t>(dims.y)) + "," +
                             std::to_string(n / nxy) + ") is " +
                             (std::isnan(original) ? "NaN" : std::isinf(original) ? "infinite"
                                                                                  : "too large for float"));
        }
    }
}

// The VoxelType a Volume keeps samples of `type` in without a float copy: the 1- and 2-byte integers.
std::optional<VoxelType> nativeVoxelType(ScalarType type)
{
    switch (type) {
    case ScalarType::UInt8: return VoxelType::UInt8;
    case ScalarType::Int8: return VoxelType::Int8;
    case ScalarType::UInt16: return VoxelType::UInt16;
    case ScalarType::Int16: return VoxelType::Int16;
    default: return std::nullopt;
    }
}

// `count` samples of `size` bytes in place from `endian` to the host's order.
void toHostOrder(unsigned char* data, std::size_t count, std::size_t size, Endian endian)
{
    if (size < 2 || (endian == Endian::Big) == (std::endian::native == std::endian::big))
        return;
    for (std::size_t i = 0; i < count; ++i)
        std::reverse(data + i * size, data + (i + 1) * size);
}

// Whole-token numbers (ASCII encodings) into floats, with the same NaN and infinity check.
void storeAsciiValue(const std::string& source, const std::string& token, std::uint64_t index, float* dst)
{
    const std::optional<double> v = parseDouble(token);
    if (!v)
        throw InputError(source + ": value " + std::to_string(index) + " is " + shown(token) + ", not a number");
    const float f = static_cast<float>(*v);
    if (!std::isfinite(f))
        throw InputError(source + ": value " + std::to_string(index) + " is " + shown(token) +
                         (std::isnan(*v) ? " (NaN)" : " (infinite or too large for float)"));
    *dst = f;
}

// ---------------------------------------------------------------------------------------------------
// gzip.

// Inflates the gzip stream in `src` (several concatenated members allowed), discards the first `skip`
// bytes of its output and writes the next `n` bytes to dst. Throws for truncated or corrupt data.
// deflate never compresses better than 1032:1: more output than that from `compressed` bytes means the
// data is truncated, and saying so before decompressing avoids allocating what a corrupt header asks for.
bool gzipCanHold(std::uint64_t compressed, std::uint64_t n)
{
    return n <= compressed * 1032 + 1024;
}

// Inflates gzip data read through `read(buffer, max) -> bytes` (0 at its end), drops the first `skip` bytes
// of the output and hands the next `n` to `sink(offset, data, length)` in order, in pieces of at most 1 MiB;
// stops once `n` bytes are out, so a reader that needs only the start of the data inflates only that.
// Several gzip members are read as one stream. InputError for corrupt or truncated data.
void gunzipTo(const std::string& source, const std::function<std::size_t(unsigned char*, std::size_t)>& read,
              std::uint64_t skip, std::uint64_t n, const std::string& sizeText,
              const std::function<void(std::uint64_t, const unsigned char*, std::size_t)>& sink)
{
    z_stream z{};
    if (inflateInit2(&z, 16 + MAX_WBITS) != Z_OK)  // 16: gzip wrapper, as NRRD writes it
        throw InputError(source + ": cannot initialise zlib");
    constexpr std::size_t kChunk = 1 << 20;
    std::vector<unsigned char> input(kChunk), output(kChunk);
    std::uint64_t skipped = 0, out = 0;
    bool inputEnded = false;
    std::string error;
    while (out < n) {
        if (z.avail_in == 0 && !inputEnded) {
            const std::size_t got = read(input.data(), input.size());
            inputEnded = got == 0;
            z.next_in = input.data();
            z.avail_in = static_cast<uInt>(got);
        }
        const std::uint64_t wanted = (skip - skipped) + (n - out);
        z.next_out = output.data();
        z.avail_out = static_cast<uInt>(std::min<std::uint64_t>(wanted, output.size()));
        const uInt before = z.avail_out;
        const int rc = inflate(&z, Z_NO_FLUSH);
        std::uint64_t produced = before - z.avail_out;
        const std::uint64_t dropped = std::min(produced, skip - skipped);
        skipped += dropped;
        produced -= dropped;
        if (produced > 0) {
            sink(out, output.data() + dropped, static_cast<std::size_t>(produced));
            out += produced;
        }
        if (rc == Z_STREAM_END) {
            if (z.avail_in == 0 && inputEnded)
                break;  // all input used; checked below
            if (inflateReset(&z) != Z_OK) {  // another gzip member follows
                error = "corrupt gzip data";
                break;
            }
            continue;
        }
        if (rc == Z_BUF_ERROR && z.avail_in == 0 && inputEnded)
            break;  // the input ended mid-stream
        if (rc != Z_OK && rc != Z_BUF_ERROR) {
            error = std::string("corrupt gzip data (") + (z.msg ? z.msg : "zlib error " + std::to_string(rc)) + ")";
            break;
        }
        if (rc == Z_BUF_ERROR && before - z.avail_out == 0 && z.avail_in != 0)
            break;  // no progress possible
    }
    inflateEnd(&z);
    if (!error.empty())
        throw InputError(source + ": " + error);
    if (out < n)
        throw InputError(source + ": gzip data is truncated (decompresses to " + std::to_string(skipped + out) +
                         " bytes, " + sizeText + (skip ? " after a byte skip of " + std::to_string(skip) : "") + ")");
}

// gunzipTo from memory into dst[0, n); first checks that src can hold n + skip bytes at deflate's best ratio.
void gunzip(const std::string& source, const std::vector<unsigned char>& src, std::uint64_t skip, unsigned char* dst,
            std::uint64_t n, const std::string& sizeText)
{
    if (!gzipCanHold(src.size(), n + skip))
        throw InputError(source + ": gzip data is truncated (" + std::to_string(src.size()) +
                         " compressed bytes cannot hold " + sizeText + ")");
    std::size_t at = 0;
    gunzipTo(
        source,
        [&](unsigned char* buffer, std::size_t max) {
            const std::size_t k = std::min(max, src.size() - at);
            std::memcpy(buffer, src.data() + at, k);
            at += k;
            return k;
        },
        skip, n, sizeText,
        [&](std::uint64_t offset, const unsigned char* data, std::size_t length) { std::memcpy(dst + offset, data, length); });
}

// ---------------------------------------------------------------------------------------------------
// NRRD.

enum class NrrdEncoding { Raw, Gzip, Ascii };

struct NrrdHeader {
    fs::path path;
    std::optional<long long> dimension;
    std::optional<std::vector<long long>> sizes;
    std::optional<ScalarType> type;
    std::optional<NrrdEncoding> encoding;
    std::optional<Endian> endian;
    std::optional<std::vector<double>> spacings;         // per axis; NaN for a non-spatial axis
    std::optional<std::vector<std::string>> directions;  // per axis: "(a,b,c)" or "none"
    std::optional<std::string> origin;
    long long byteSkip = 0;
    long long lineSkip = 0;
    std::vector<fs::path> dataFiles;  // one name or LIST; empty: data attached, or a format (below)
    // "data file: <format> <min> <max> <step>": file n is the format expanded for min + n * step, when it
    // is read. Expanding all 2^20 names a 60-byte header may ask for took seconds before anything was checked.
    std::string dataFileFormat;
    long long formatFirst = 0, formatStep = 1;
    std::uint64_t formatCount = 0;
    std::uint64_t dataOffset = 0;     // attached: first byte after the blank line
};

std::optional<ScalarType> nrrdType(const std::string& t)
{
    static const std::array<std::pair<const char*, ScalarType>, 32> kNames{{
        {"signed char", ScalarType::Int8},       {"int8", ScalarType::Int8},
        {"int8_t", ScalarType::Int8},            {"uchar", ScalarType::UInt8},
        {"unsigned char", ScalarType::UInt8},    {"uint8", ScalarType::UInt8},
        {"uint8_t", ScalarType::UInt8},          {"short", ScalarType::Int16},
        {"short int", ScalarType::Int16},        {"signed short", ScalarType::Int16},
        {"signed short int", ScalarType::Int16}, {"int16", ScalarType::Int16},
        {"int16_t", ScalarType::Int16},          {"ushort", ScalarType::UInt16},
        {"unsigned short", ScalarType::UInt16},  {"unsigned short int", ScalarType::UInt16},
        {"uint16", ScalarType::UInt16},          {"uint16_t", ScalarType::UInt16},
        {"int", ScalarType::Int32},              {"signed int", ScalarType::Int32},
        {"int32", ScalarType::Int32},            {"int32_t", ScalarType::Int32},
        {"uint", ScalarType::UInt32},            {"unsigned int", ScalarType::UInt32},
        {"uint32", ScalarType::UInt32},          {"uint32_t", ScalarType::UInt32},
        {"float", ScalarType::Float32},          {"double", ScalarType::Float64},
        {"float32", ScalarType::Float32},        {"float64", ScalarType::Float64},
        {"single", ScalarType::Float32},         {"float32_t", ScalarType::Float32},
    }};
    // Internal runs of spaces count as one ("unsigned  char").
    std::string norm;
    for (const std::string& w : splitWhitespace(asciiLower(t)))
        norm += (norm.empty() ? "" : " ") + w;
    for (const auto& [name, type] : kNames)
        if (norm == name)
            return type;
    return std::nullopt;
}

// Field names are compared in lower case with spaces removed, so "data file" and "datafile" agree.
std::string fieldKey(const std::string& name)
{
    std::string k;
    for (char c : asciiLower(name))
        if (c != ' ')
            k += c;
    return k;
}

// Expands a "data file: <format> <min> <max> <step> [<subdim>]" format for one index: only %d, %i or %u
// with optional flags and width (e.g. %03d) are accepted, and %% for a literal percent sign. The format
// comes from the file, so it never reaches printf.
std::string expandDataFileFormat(const std::string& source, const std::string& format, long long index)
{
    std::string out;
    int conversions = 0;
    for (std::size_t i = 0; i < format.size(); ++i) {
        if (format[i] != '%') {
            out += format[i];
            continue;
        }
        if (i + 1 < format.size() && format[i + 1] == '%') {
            out += '%';
            ++i;
            continue;
        }
        std::size_t j = i + 1;
        bool zeroPad = false;
        while (j < format.size() && (format[j] == '0' || format[j] == '-' || format[j] == '+' || format[j] == ' ')) {
            zeroPad = zeroPad || format[j] == '0';
            ++j;
        }
        int width = 0;
        while (j < format.size() && std::isdigit(static_cast<unsigned char>(format[j])) && width < 100)
            width = width * 10 + (format[j++] - '0');
        if (j >= format.size() || (format[j] != 'd' && format[j] != 'i' && format[j] != 'u') || ++conversions > 1)
            throw InputError(source + ": data file format " + shown(format) +
                             " is not supported (one %d, %i or %u with an optional width)");
        std::string digits = std::to_string(index < 0 ? -index : index);
        const std::size_t len = digits.size() + (index < 0 ? 1 : 0);
        if (static_cast<std::size_t>(width) > len)
            digits.insert(0, static_cast<std::size_t>(width) - len, zeroPad ? '0' : ' ');
        out += (index < 0 ? "-" : "") + digits;
        i = j;
    }
    if (conversions == 0)
        throw InputError(source + ": data file format " + shown(format) + " has no %d for the file number");
    return out;
}

NrrdHeader readNrrdHeader(const fs::path& path)
{
    const std::string source = path.string();
    std::ifstream in = openBinary(path);
    NrrdHeader h;
    h.path = path;

    // Reads one line (without \n or \r\n); false at end of file. Lines and the header are bounded so
    // that a binary file given as a header fails quickly.
    constexpr std::size_t kMaxLine = 1 << 20, kMaxHeader = 16 << 20;
    std::uint64_t consumed = 0;
    std::size_t lineLimit = 64;  // for the magic line; kMaxLine after it
    auto readLine = [&](std::string& line) {
        line.clear();
        int c;
        bool any = false;
        while ((c = in.get()) != EOF) {
            any = true;
            ++consumed;
            if (c == '\n')
                break;
            if (line.size() >= lineLimit || consumed > kMaxHeader) {
                if (lineLimit < kMaxLine)
                    break;  // a magic line is 8 characters: this is not a NRRD file, said below
                throw InputError(source + ": NRRD header line " + shown(line) + " is too long");
            }
            line += static_cast<char>(c);
        }
        if (!line.empty() && line.back() == '\r')
            line.pop_back();
        return any;
    };

    std::string line;
    if (!readLine(line) || line.size() != 8 || line.compare(0, 4, "NRRD") != 0 ||
        !std::all_of(line.begin() + 4, line.end(), [](char c) { return std::isdigit(static_cast<unsigned char>(c)); }))
        throw InputError(source + ": not a NRRD file (the first line is " + shown(line) +
                         ", expected a magic line like \"NRRD0004\")");
    lineLimit = kMaxLine;

    bool blankLineSeen = false;
    std::optional<std::string> dataFileValue;
    bool listForm = false;
    while (readLine(line)) {
        if (listForm) {  // "data file: LIST": every remaining line names one data file
            const std::string name = trim(line);
            if (!name.empty())
                h.dataFiles.push_back(name);
            continue;
        }
        if (line.empty()) {
            blankLineSeen = true;
            break;
        }
        if (line[0] == '#')
            continue;
        if (line.find(":=") != std::string::npos && line.find(":=") < line.find(": "))
            continue;  // key/value pair: free-form metadata
        const std::size_t colon = line.find(": ");
        if (colon == std::string::npos)
            throw InputError(source + ": NRRD header line " + shown(line) + " is not \"field: value\"");
        const std::string key = fieldKey(line.substr(0, colon));
        const std::string value = trim(std::string_view(line).substr(colon + 2));
        auto integer = [&](const char* what) {
            const std::optional<long long> v = parseInteger(value);
            if (!v)
                throw InputError(source + ": " + what + " " + shown(value) + " is not an integer");
            return *v;
        };
        if (key == "dimension") {
            h.dimension = integer("dimension");
        } else if (key == "sizes") {
            std::vector<long long> sizes;
            for (const std::string& t : splitWhitespace(value)) {
                const std::optional<long long> v = parseInteger(t);
                if (!v)
                    throw InputError(source + ": sizes " + shown(value) + " are not integers");
                sizes.push_back(*v);
            }
            h.sizes = sizes;
        } else if (key == "type") {
            h.type = nrrdType(value);
            if (!h.type)
                throw InputError(source + ": type " + shown(value) +
                                 " is not supported (8, 16 and 32-bit integers, float and double are)");
        } else if (key == "encoding") {
            const std::string e = asciiLower(value);
            if (e == "raw")
                h.encoding = NrrdEncoding::Raw;
            else if (e == "gzip" || e == "gz")
                h.encoding = NrrdEncoding::Gzip;
            else if (e == "ascii" || e == "text" || e == "txt")
                h.encoding = NrrdEncoding::Ascii;
            else
                throw InputError(source + ": encoding " + shown(value) +
                                 " is not supported (raw, gzip and ascii are)");
        } else if (key == "endian") {
            const std::string e = asciiLower(value);
            if (e == "little")
                h.endian = Endian::Little;
            else if (e == "big")
                h.endian = Endian::Big;
            else
                throw InputError(source + ": endian " + shown(value) + " is neither little nor big");
        } else if (key == "spacings") {
            std::vector<double> s;
            for (const std::string& t : splitWhitespace(value)) {
                const std::optional<double> v = parseDouble(t);
                if (!v)
                    throw InputError(source + ": spacings " + shown(value) + " are not numbers");
                s.push_back(*v);
            }
            h.spacings = s;
        } else if (key == "spacedirections") {
            // "(1,0,0) (0,1,0) none": a vector may hold spaces, "(1, 0, 0)", so split on parentheses.
            std::vector<std::string> dirs;
            for (std::size_t i = 0; i < value.size();) {
                if (std::isspace(static_cast<unsigned char>(value[i]))) {
                    ++i;
                    continue;
                }
                std::size_t j = i;
                if (value[i] == '(') {
                    j = value.find(')', i);
                    j = j == std::string::npos ? value.size() : j + 1;
                } else {
                    while (j < value.size() && !std::isspace(static_cast<unsigned char>(value[j])))
                        ++j;
                }
                std::string d;
                for (std::size_t k = i; k < j; ++k)
                    if (!std::isspace(static_cast<unsigned char>(value[k])))
                        d += value[k];
                dirs.push_back(d);
                i = j;
            }
            h.directions = dirs;
        } else if (key == "spaceorigin") {
            h.origin = value;
        } else if (key == "space") {
            // Any named 3D space ("left-posterior-superior", "3D-left-handed", ...); only the dimension matters.
            const std::string s = asciiLower(value);
            static const std::array<const char*, 4> kTwoOrFour{"right-anterior-superior-time", "ras-time",
                                                               "left-anterior-superior-time", "scanner-xyz-time"};
            for (const char* t : kTwoOrFour)
                if (s == t)
                    throw InputError(source + ": space " + shown(value) + " is not 3D");
        } else if (key == "spacedimension") {
            if (integer("space dimension") != 3)
                throw InputError(source + ": space dimension is " + value + ", only 3 is read");
        } else if (key == "byteskip") {
            h.byteSkip = integer("byte skip");
            if (h.byteSkip < -1)
                throw InputError(source + ": byte skip " + value + " must be -1 or at least 0");
        } else if (key == "lineskip") {
            h.lineSkip = integer("line skip");
            if (h.lineSkip < 0)
                throw InputError(source + ": line skip " + value + " must be at least 0");
        } else if (key == "datafile") {
            dataFileValue = value;
            const std::vector<std::string> words = splitWhitespace(value);
            if (!words.empty() && words[0] == "LIST") {
                if (words.size() > 2)
                    throw InputError(source + ": data file " + shown(value) + " is not \"LIST [<subdim>]\"");
                listForm = true;
            }
        }
        // Every other field (content, kinds, centers, units, labels, min/max, measurement frame, ...)
        // says nothing about layout and is ignored.
    }
    if (!blankLineSeen && !listForm && !dataFileValue)
        throw InputError(source + ": NRRD header has no data file field and no blank line before attached data");
    h.dataOffset = consumed;

    const fs::path dir = path.parent_path();
    auto relative = [&](const std::string& name) { return fs::path(name).is_absolute() ? fs::path(name) : dir / name; };
    if (listForm) {
        for (fs::path& f : h.dataFiles)
            f = relative(f.string());
        if (h.dataFiles.empty())
            throw InputError(source + ": data file LIST names no files");
    } else if (dataFileValue && *dataFileValue != "LOCAL") {
        const std::vector<std::string> words = splitWhitespace(*dataFileValue);
        if (words.size() == 1) {
            h.dataFiles.push_back(relative(words[0]));
        } else if (words.size() == 4 || words.size() == 5) {
            const auto lo = parseInteger(words[1]), hi = parseInteger(words[2]), step = parseInteger(words[3]);
            constexpr long long kMaxIndex = 1LL << 40;  // keeps the arithmetic below far from overflow
            auto inRange = [&](const std::optional<long long>& x) { return x && *x > -kMaxIndex && *x < kMaxIndex; };
            if (!inRange(lo) || !inRange(hi) || !inRange(step) || *step == 0 || (*hi - *lo) / *step < 0)
                throw InputError(source + ": data file " + shown(*dataFileValue) +
                                 " is not \"<format> <min> <max> <step> [<subdim>]\"");
            const std::uint64_t count = static_cast<std::uint64_t>((*hi - *lo) / *step) + 1;
            if (count > (1u << 20))
                throw InputError(source + ": data file " + shown(*dataFileValue) + " names too many files");
            expandDataFileFormat(source, words[0], *lo);  // the format is checked here, expanded when read
            h.dataFileFormat = words[0];
            h.formatFirst = *lo;
            h.formatStep = *step;
            h.formatCount = count;
        } else {
            throw InputError(source + ": data file " + shown(*dataFileValue) +
                             " is not one name, \"<format> <min> <max> <step> [<subdim>]\" or \"LIST\"");
        }
    }
    return h;
}

std::uint64_t dataFileCount(const NrrdHeader& h)
{
    return h.dataFiles.size() + h.formatCount;
}

// Data file f of a detached header (f < dataFileCount(h)).
fs::path dataFile(const NrrdHeader& h, std::uint64_t f)
{
    if (h.formatCount == 0)
        return h.dataFiles[f];
    const fs::path name = expandDataFileFormat(h.path.string(), h.dataFileFormat,
                                               h.formatFirst + static_cast<long long>(f) * h.formatStep);
    return name.is_absolute() ? name : h.path.parent_path() / name;
}

// Parses "(a,b,c)" with exactly three components.
std::optional<glm::dvec3> parseVector(const std::string& s)
{
    if (s.size() < 2 || s.front() != '(' || s.back() != ')')
        return std::nullopt;
    std::vector<double> v;
    std::stringstream parts(s.substr(1, s.size() - 2));
    std::string part;
    while (std::getline(parts, part, ',')) {
        const std::optional<double> d = parseDouble(trim(part));
        if (!d)
            return std::nullopt;
        v.push_back(*d);
    }
    if (v.size() != 3)
        return std::nullopt;
    return glm::dvec3(v[0], v[1], v[2]);
}

// Reads one data file's share of the samples (or the attached data) and appends them to `out`. Every size
// is checked before `out` grows, so a corrupt header cannot make it allocate more than the file can hold.
// Skips the header's line skip from `start` of `file`'s stream `in`; the position after it.
std::uint64_t skipLines(std::ifstream& in, const NrrdHeader& h, const std::string& source, std::uint64_t start)
{
    in.seekg(static_cast<std::streamoff>(start));
    for (long long l = 0; l < h.lineSkip; ++l) {
        int c;
        while ((c = in.get()) != EOF && c != '\n') {
        }
        if (c == EOF)
            throw InputError(source + ": line skip " + std::to_string(h.lineSkip) + " goes past the end of the file");
    }
    return static_cast<std::uint64_t>(static_cast<std::streamoff>(in.tellg()));
}

// "FILE: header says ..., file has N bytes after the P-byte header": a data file shorter than its samples.
InputError nrrdTooShort(const NrrdHeader& h, const std::string& source, const std::string& sizeText,
                        std::uint64_t available, std::uint64_t header)
{
    return InputError(source + ": " + sizeText + ", file has " + std::to_string(available) + " bytes" +
                      (header == 0                            ? std::string()
                       : h.byteSkip == 0 && h.lineSkip == 0 ? " after the " + std::to_string(header) + "-byte header"
                                                            : " after " + std::to_string(header) +
                                                                  " bytes of header and skips"));
}

void readNrrdData(const NrrdHeader& h, const fs::path& file, std::uint64_t start, std::uint64_t count,
                  std::vector<float>& out, glm::ivec3 dims, const std::string& sizeText)
{
    const std::string source = file.string();
    const std::uint64_t size = fileSize(file);
    const std::uint64_t first = out.size();  // index of this file's first sample, for messages
    std::ifstream in = openBinary(file);
    std::uint64_t pos = skipLines(in, h, source, start);
    const std::size_t elem = scalarSize(*h.type);
    const std::uint64_t bytes = count * elem;
    const Endian endian = h.endian.value_or(Endian::Little);
    const std::uint64_t header = pos;
    auto tooShort = [&](std::uint64_t available) { return nrrdTooShort(h, source, sizeText, available, header); };

    if (*h.encoding == NrrdEncoding::Raw) {
        if (h.byteSkip == -1) {  // the data is the last `bytes` of the file
            if (size < bytes || size - bytes < pos)
                throw tooShort(size - pos);
            pos = size - bytes;
        } else {
            pos += static_cast<std::uint64_t>(h.byteSkip);
        }
        const std::uint64_t available = size > pos ? size - pos : 0;
        if (available < bytes)
            throw tooShort(available);
        checkHostMemoryForVoxels(source, first + count);
        std::vector<unsigned char> raw(static_cast<std::size_t>(bytes));
        readExactly(in, file, pos, reinterpret_cast<char*>(raw.data()), bytes);
        out.resize(static_cast<std::size_t>(first + count));
        convertSamples(source, raw.data(), static_cast<std::size_t>(count), *h.type, endian, out.data() + first,
                       first, dims);
        return;
    }

    if (h.byteSkip == -1)
        throw InputError(source + ": byte skip -1 is only allowed with raw encoding");
    const std::uint64_t skip = static_cast<std::uint64_t>(h.byteSkip);
    // gzip and ascii: the rest of the file, whole.
    const std::uint64_t rest = size > pos ? size - pos : 0;
    if (*h.encoding == NrrdEncoding::Gzip && !gzipCanHold(rest, bytes + skip))
        throw InputError(source + ": gzip data is truncated: " + sizeText + ", and " + std::to_string(rest) +
                         " compressed bytes cannot hold that many");
    checkHostMemoryForVoxels(source, first + count);
    std::vector<unsigned char> data(static_cast<std::size_t>(rest));
    if (rest)
        readExactly(in, file, pos, reinterpret_cast<char*>(data.data()), rest);

    if (*h.encoding == NrrdEncoding::Gzip) {
        std::vector<unsigned char> raw(static_cast<std::size_t>(bytes));
        gunzip(source, data, skip, raw.data(), bytes, sizeText);
        out.resize(static_cast<std::size_t>(first + count));
        convertSamples(source, raw.data(), static_cast<std::size_t>(count), *h.type, endian, out.data() + first,
                       first, dims);
        return;
    }

    // ascii: whitespace- or comma-separated numbers; byte skip counts characters. `out` grows with the
    // values actually found.
    std::uint64_t n = 0;
    std::size_t i = static_cast<std::size_t>(std::min<std::uint64_t>(skip, data.size()));
    std::string token;
    float value = 0.0f;
    while (n < count && i < data.size()) {
        while (i < data.size() && (std::isspace(data[i]) || data[i] == ','))
            ++i;
        token.clear();
        while (i < data.size() && !std::isspace(data[i]) && data[i] != ',') {
            if (token.size() < 64)
                token += static_cast<char>(data[i]);
            else if (token.size() == 64)
                token += "...";  // a 64-character number is garbage: fail on it, do not split it
            ++i;
        }
        if (!token.empty()) {
            storeAsciiValue(source, token, first + n, &value);
            out.push_back(value);
            ++n;
        }
    }
    if (n < count)
        throw InputError(source + ": ascii data is truncated: header says " + std::to_string(count) +
                         " values, file has " + std::to_string(n));
}

// ---------------------------------------------------------------------------------------------------
// VTK legacy.

std::optional<ScalarType> vtkType(const std::string& t)
{
    const std::string s = asciiLower(t);
    if (s == "unsigned_char") return ScalarType::UInt8;
    if (s == "char" || s == "signed_char") return ScalarType::Int8;
    if (s == "short") return ScalarType::Int16;
    if (s == "unsigned_short") return ScalarType::UInt16;
    if (s == "int") return ScalarType::Int32;
    if (s == "unsigned_int") return ScalarType::UInt32;
    if (s == "float") return ScalarType::Float32;
    if (s == "double") return ScalarType::Float64;
    return std::nullopt;
}

}  // namespace

std::size_t scalarSize(ScalarType type)
{
    switch (type) {
    case ScalarType::UInt8:
    case ScalarType::Int8: return 1;
    case ScalarType::Int16:
    case ScalarType::UInt16: return 2;
    case ScalarType::Int32:
    case ScalarType::UInt32:
    case ScalarType::Float32: return 4;
    case ScalarType::Float64: return 8;
    }
    return 1;
}

namespace {

// A NRRD header's grid (dims, spacing, origin; no values) and its sample count, every field checked.
Volume nrrdGeometry(const NrrdHeader& h, std::uint64_t& count)
{
    const std::string source = h.path.string();
    if (!h.dimension)
        throw InputError(source + ": NRRD header is missing the required field \"dimension\"");
    if (!h.sizes)
        throw InputError(source + ": NRRD header is missing the required field \"sizes\"");
    if (!h.type)
        throw InputError(source + ": NRRD header is missing the required field \"type\"");
    if (!h.encoding)
        throw InputError(source + ": NRRD header is missing the required field \"encoding\"");
    const long long dim = *h.dimension;
    if (dim != 3 && dim != 4)
        throw InputError(source + ": dimension is " + std::to_string(dim) + ", only 3D volumes are read");
    if (static_cast<long long>(h.sizes->size()) != dim)
        throw InputError(source + ": sizes has " + std::to_string(h.sizes->size()) + " entries for dimension " +
                         std::to_string(dim));
    // Memory is checked once the data is known to be there (readNrrdData): a short file says so first.
    count = checkedVoxelCount(source, *h.sizes, false);
    // Dimension 4 is read only as one scalar per grid point with an explicit first axis of size 1.
    const std::size_t skipAxes = dim == 4 ? 1 : 0;
    if (dim == 4 && (*h.sizes)[0] != 1)
        throw InputError(source + ": dimension is 4 with " + std::to_string((*h.sizes)[0]) +
                         " values per grid point, only one scalar per grid point is read");
    if (scalarSize(*h.type) > 1 && *h.encoding != NrrdEncoding::Ascii && !h.endian)
        throw InputError(source + ": NRRD header is missing the required field \"endian\" (the type has " +
                         std::to_string(scalarSize(*h.type)) + " bytes)");

    Volume v;
    v.source = source;
    v.dims = glm::ivec3(static_cast<int>((*h.sizes)[skipAxes]), static_cast<int>((*h.sizes)[skipAxes + 1]),
                        static_cast<int>((*h.sizes)[skipAxes + 2]));

    if (h.spacings && h.directions)
        throw InputError(source + ": has both spacings and space directions");
    if (h.spacings) {
        if (static_cast<long long>(h.spacings->size()) != dim)
            throw InputError(source + ": spacings has " + std::to_string(h.spacings->size()) +
                             " entries for dimension " + std::to_string(dim));
        for (int a = 0; a < 3; ++a) {
            const double s = (*h.spacings)[skipAxes + static_cast<std::size_t>(a)];
            if (!(s > 0.0) || !std::isfinite(s))
                throw InputError(source + ": spacing of axis " + std::to_string(a) + " is " + numberText(s) +
                                 ", must be a positive finite number");
            v.spacing[a] = s;
        }
    }
    if (h.directions) {
        if (static_cast<long long>(h.directions->size()) != dim)
            throw InputError(source + ": space directions has " + std::to_string(h.directions->size()) +
                             " entries for dimension " + std::to_string(dim));
        if (dim == 4 && (*h.directions)[0] != "none")
            throw InputError(source + ": the first space direction of a 4D volume must be none");
        for (int a = 0; a < 3; ++a) {
            const std::string& text = (*h.directions)[skipAxes + static_cast<std::size_t>(a)];
            const std::optional<glm::dvec3> d = parseVector(text);
            if (!d)
                throw InputError(source + ": space direction " + shown(text) + " of axis " + std::to_string(a) +
                                 " is not a vector (x,y,z)");
            for (int b = 0; b < 3; ++b)
                if (b != a && (*d)[b] != 0.0)
                    throw InputError(source + ": space directions are not axis-aligned (axis " + std::to_string(a) +
                                     " is " + text + "), only axis-aligned grids are read");
            if (!((*d)[a] > 0.0) || !std::isfinite((*d)[a]))
                throw InputError(source + ": space direction of axis " + std::to_string(a) + " is " + text +
                                 ", its spacing must be a positive finite number");
            v.spacing[a] = (*d)[a];
        }
    }
    if (h.origin) {
        const std::optional<glm::dvec3> o = parseVector(*h.origin);
        if (!o || !std::isfinite(o->x) || !std::isfinite(o->y) || !std::isfinite(o->z))
            throw InputError(source + ": space origin " + shown(*h.origin) + " is not a finite vector (x,y,z)");
        v.origin = *o;
    }

    return v;
}

Volume readRawRegion(const fs::path& path, const RawLayout& layout, const GridRegion& region, bool exactSize = true);

// A region of a grid with `dims` points as runs of samples contiguous in the file (x fastest): one run per row
// of the region, or per z plane where the region spans whole rows and planes. `starts`: each run's first
// sample, in file order.
struct RegionRuns {
    std::uint64_t length = 0;
    std::vector<std::uint64_t> starts;
};

RegionRuns regionRuns(const glm::ivec3& dims, const GridRegion& region)
{
    const glm::ivec3 n = region.dims();
    const std::uint64_t nx = static_cast<std::uint64_t>(dims.x), ny = static_cast<std::uint64_t>(dims.y);
    const bool wholePlanes = n.x == dims.x && n.y == dims.y;
    RegionRuns runs;
    runs.length = wholePlanes ? nx * ny : static_cast<std::uint64_t>(n.x);
    for (int k = region.lo.z; k <= region.hi.z; ++k)
        for (int j = region.lo.y; j <= region.hi.y; j += wholePlanes ? n.y : 1)
            runs.starts.push_back((static_cast<std::uint64_t>(k) * ny + static_cast<std::uint64_t>(j)) * nx +
                                  static_cast<std::uint64_t>(region.lo.x));
    return runs;
}

// Where the samples of a NRRD with one data stream (attached, or one detached file) lie, raw or gzip: the
// layout of its samples as a raw file (raw: headerBytes is the first sample's byte after line and byte skips;
// gzip: where the compressed data starts after the line skip, its byte skip applying to the inflated data).
// nullopt for ascii and for several data files. InputError when the file is shorter than the samples (raw).
struct NrrdStream {
    fs::path file;
    RawLayout layout;
    bool gzip = false;
    std::uint64_t gzipSkip = 0;
    std::string sizeText;  // "header says 5x4x6 x 2 bytes = 240 bytes", for messages
};

std::optional<NrrdStream> nrrdStream(const NrrdHeader& h, const Volume& geometry, std::uint64_t count)
{
    if (*h.encoding == NrrdEncoding::Ascii || dataFileCount(h) > 1)
        return std::nullopt;
    NrrdStream st;
    st.file = dataFileCount(h) == 0 ? h.path : dataFile(h, 0);
    st.gzip = *h.encoding == NrrdEncoding::Gzip;
    const std::string source = st.file.string();
    const std::uint64_t size = fileSize(st.file);
    std::uint64_t pos = dataFileCount(h) == 0 ? h.dataOffset : 0;
    if (h.lineSkip > 0) {
        std::ifstream in = openBinary(st.file);
        pos = skipLines(in, h, source, pos);
    }
    const std::size_t elem = scalarSize(*h.type);
    const std::uint64_t bytes = count * elem;
    st.sizeText = "header says " + dimsText(*h.sizes) + " x " + std::to_string(elem) + " bytes = " + std::to_string(bytes) +
                  " bytes";
    st.layout.dims = geometry.dims;
    st.layout.type = *h.type;
    st.layout.endian = h.endian.value_or(Endian::Little);
    st.layout.spacing = geometry.spacing;
    st.layout.origin = geometry.origin;
    if (st.gzip) {
        if (h.byteSkip == -1)
            throw InputError(source + ": byte skip -1 is only allowed with raw encoding");
        st.gzipSkip = static_cast<std::uint64_t>(h.byteSkip);
        st.layout.headerBytes = pos;
        return st;
    }
    const std::uint64_t header = pos;
    const auto tooShort = [&](std::uint64_t available) { return nrrdTooShort(h, source, st.sizeText, available, header); };
    if (h.byteSkip == -1) {  // the data is the last `bytes` of the file
        if (size < bytes || size - bytes < pos)
            throw tooShort(size > pos ? size - pos : 0);
        pos = size - bytes;
    } else {
        pos += static_cast<std::uint64_t>(h.byteSkip);
    }
    if (size < pos || size - pos < bytes)
        throw tooShort(size > pos ? size - pos : 0);
    st.layout.headerBytes = pos;
    return st;
}

Volume readGzipRegion(const NrrdStream& st, const GridRegion& region);

// A NRRD stream's grid points `region`: by offset (raw) or inflated in order, keeping only the region (gzip).
Volume readNrrdRegion(const NrrdStream& st, const GridRegion& region)
{
    return st.gzip ? readGzipRegion(st, region) : readRawRegion(st.file, st.layout, region, false);
}

}  // namespace

Volume readNrrd(const fs::path& path)
{
    const std::string source = path.string();
    const NrrdHeader h = readNrrdHeader(path);
    std::uint64_t count = 0;
    Volume v = nrrdGeometry(h, count);
    v.source = source;
    if (const auto stream = nrrdStream(h, v, count)) {  // one raw or gzip stream: integers kept in their own type
        Volume whole = readNrrdRegion(*stream, GridRegion{glm::ivec3(0), v.dims - 1});
        whole.source = source;
        return whole;
    }
    const std::size_t elem = scalarSize(*h.type);
    const std::string sizes = dimsText(*h.sizes) + " x " + std::to_string(elem) + " bytes";
    if (dataFileCount(h) == 0) {
        const std::string sizeText = "header says " + sizes + " = " + std::to_string(count * elem) + " bytes";
        readNrrdData(h, path, h.dataOffset, count, v.values, v.dims, sizeText);
    } else {
        // Several files share the samples equally, in order (slices of the slowest axis, usually).
        const std::uint64_t files = dataFileCount(h);
        if (count % files != 0)
            throw InputError(source + ": " + std::to_string(count) + " grid points do not split evenly into " +
                             std::to_string(files) + " data files");
        const std::uint64_t per = count / files;
        const std::string sizeText =
            files == 1 ? "header says " + sizes + " = " + std::to_string(count * elem) + " bytes"
                       : "header says " + sizes + " in " + std::to_string(files) + " files = " +
                             std::to_string(per * elem) + " bytes per file";
        // Reserve the whole volume only when every file is at least plausibly big enough; otherwise the
        // exact check on the first short file throws.
        bool plausible = *h.encoding != NrrdEncoding::Ascii;
        for (std::uint64_t f = 0; f < files && plausible; ++f) {
            std::error_code ec;
            const std::uint64_t fileBytes = fs::file_size(dataFile(h, f), ec);
            plausible = !ec && (*h.encoding == NrrdEncoding::Raw ? fileBytes >= per * elem
                                                                  : gzipCanHold(fileBytes, per * elem));
        }
        if (plausible) {
            checkHostMemoryForVoxels(source, count);
            v.values.reserve(static_cast<std::size_t>(count));
        }
        for (std::uint64_t f = 0; f < files; ++f)
            readNrrdData(h, dataFile(h, f), 0, per, v.values, v.dims, sizeText);
    }
    v.validate();
    return v;
}

Volume readRaw(const fs::path& path, const RawLayout& layout)
{
    const std::string source = path.string();
    checkedVoxelCount(source, {layout.dims.x, layout.dims.y, layout.dims.z});  // with the memory check
    for (int a = 0; a < 3; ++a)
        if (!(layout.spacing[a] > 0.0) || !std::isfinite(layout.spacing[a]))
            throw InputError(source + ": spacing of axis " + std::to_string(a) + " must be a positive finite number");
    return readRawRegion(path, layout, GridRegion{glm::ivec3(0), layout.dims - 1});
}

namespace {

// The header of a .npy file (numpy's format, versions 1 to 3): the dict
// "{'descr': '<u2', 'fortran_order': False, 'shape': (64, 64, 93), }" after the magic, version and length.
struct NpyHeader {
    ScalarType type = ScalarType::UInt8;
    Endian endian = Endian::Little;
    bool fortranOrder = false;
    std::vector<long long> shape;
    std::uint64_t dataOffset = 0;
};

NpyHeader readNpyHeader(const fs::path& path)
{
    const std::string source = path.string();
    const std::uint64_t size = fileSize(path);
    std::ifstream in = openBinary(path);
    unsigned char pre[12] = {};
    in.read(reinterpret_cast<char*>(pre), static_cast<std::streamsize>(std::min<std::uint64_t>(size, 12)));
    if (size < 10 || std::memcmp(pre, "\x93NUMPY", 6) != 0)
        throw InputError(source + ": not a .npy file (no \\x93NUMPY magic at its start)");
    const int major = pre[6];
    if (major < 1 || major > 3)
        throw InputError(source + ": .npy format version " + std::to_string(major) + " (clvr reads versions 1 to 3)");
    std::uint64_t headerLen = 0, start = 0;
    if (major == 1) {
        headerLen = pre[8] | (std::uint64_t(pre[9]) << 8);
        start = 10;
    } else {
        if (size < 12)
            throw InputError(source + ": .npy header is truncated");
        headerLen = pre[8] | (std::uint64_t(pre[9]) << 8) | (std::uint64_t(pre[10]) << 16) | (std::uint64_t(pre[11]) << 24);
        start = 12;
    }
    if (headerLen > 65536 || start + headerLen > size)
        throw InputError(source + ": .npy header says " + std::to_string(headerLen) + " bytes, the file has " +
                         std::to_string(size - start) + " after the preamble");
    std::string dict(static_cast<std::size_t>(headerLen), '\0');
    readExactly(in, path, start, dict.data(), headerLen);

    NpyHeader h;
    h.dataOffset = start + headerLen;
    // The value after 'key': in the dict, as text up to the next ',' (or ')' for the shape tuple).
    const auto value = [&](const std::string& key) -> std::string {
        const std::size_t k = dict.find("'" + key + "'");
        if (k == std::string::npos)
            throw InputError(source + ": .npy header has no '" + key + "': " + shown(dict));
        std::size_t c = dict.find(':', k);
        if (c == std::string::npos)
            throw InputError(source + ": .npy header is malformed at '" + key + "': " + shown(dict));
        ++c;
        while (c < dict.size() && std::isspace(static_cast<unsigned char>(dict[c])))
            ++c;
        if (c < dict.size() && dict[c] == '(') {
            const std::size_t e = dict.find(')', c);
            if (e == std::string::npos)
                throw InputError(source + ": .npy header's '" + key + "' tuple is not closed: " + shown(dict));
            return dict.substr(c + 1, e - c - 1);
        }
        std::size_t e = c;
        while (e < dict.size() && dict[e] != ',' && dict[e] != '}')
            ++e;
        return trim(dict.substr(c, e - c));
    };
    std::string descr = value("descr");
    if (descr.size() < 2 || (descr.front() != '\'' && descr.front() != '"') || descr.back() != descr.front())
        throw InputError(source + ": .npy 'descr' is " + shown(descr) + ", not a simple type such as '<u2'");
    descr = descr.substr(1, descr.size() - 2);
    static const std::array<std::pair<const char*, ScalarType>, 8> kTypes{{
        {"u1", ScalarType::UInt8},   {"i1", ScalarType::Int8},    {"u2", ScalarType::UInt16}, {"i2", ScalarType::Int16},
        {"u4", ScalarType::UInt32},  {"i4", ScalarType::Int32},   {"f4", ScalarType::Float32}, {"f8", ScalarType::Float64},
    }};
    const auto known = std::find_if(kTypes.begin(), kTypes.end(),
                                    [&](const auto& t) { return descr.size() == 3 && descr.substr(1) == t.first; });
    if (known == kTypes.end() || (descr[0] != '<' && descr[0] != '>' && descr[0] != '|' && descr[0] != '='))
        throw InputError(source + ": .npy dtype " + shown(descr) +
                         " (clvr reads uint8, int8, uint16, int16, uint32, int32, float32 and float64)");
    h.type = known->second;
    h.endian = descr[0] == '>' ? Endian::Big : descr[0] == '=' && std::endian::native == std::endian::big ? Endian::Big
                                                                                                          : Endian::Little;
    const std::string order = value("fortran_order");
    if (order != "True" && order != "False")
        throw InputError(source + ": .npy 'fortran_order' is " + shown(order) + ", not True or False");
    h.fortranOrder = order == "True";
    for (const std::string& item : [&] {
             std::string t = value("shape");
             std::replace(t.begin(), t.end(), ',', ' ');
             return splitWhitespace(t);
         }()) {
        const std::optional<long long> n = parseInteger(item);
        if (!n)
            throw InputError(source + ": .npy shape entry " + shown(item) + " is not an integer");
        h.shape.push_back(*n);
    }
    if (h.shape.size() != 3)
        throw InputError(source + ": .npy array has " + std::to_string(h.shape.size()) +
                         " dimensions; clvr reads 3-D arrays indexed [x, y, z]");
    return h;
}

// A .npy's samples as a raw file: its grid (shape x, y, z) in Fortran order; in C order (z fastest) the
// same bytes as a grid with the axes reversed, which readNpy transposes.
RawLayout npyLayout(const NpyHeader& h, const glm::dvec3& spacing, const glm::dvec3& origin)
{
    RawLayout layout;
    const glm::ivec3 dims(static_cast<int>(h.shape[0]), static_cast<int>(h.shape[1]), static_cast<int>(h.shape[2]));
    layout.dims = h.fortranOrder ? dims : glm::ivec3(dims.z, dims.y, dims.x);
    layout.type = h.type;
    layout.endian = h.endian;
    layout.spacing = spacing;
    layout.origin = origin;
    layout.headerBytes = h.dataOffset;
    return layout;
}

}  // namespace

Volume readNpy(const fs::path& path, const glm::dvec3& spacing, const glm::dvec3& origin)
{
    const NpyHeader h = readNpyHeader(path);
    checkedVoxelCount(path.string(), h.shape);
    const RawLayout layout = npyLayout(h, spacing, origin);
    if (h.fortranOrder)  // x fastest in memory: clvr's own layout
        return readRaw(path, layout);
    // C order: z fastest. Read as a raw grid with the axes reversed, then transpose to x fastest.
    const glm::ivec3 dims(layout.dims.z, layout.dims.y, layout.dims.x);
    Volume reversed = readRaw(path, layout);
    Volume v;
    v.source = reversed.source;
    v.dims = dims;
    v.spacing = spacing;
    v.origin = origin;
    v.voxelType = reversed.voxelType;
    v.allocateValues();
    const std::size_t size = voxelTypeSize(v.voxelType);
    const std::uint8_t* from = reversed.valueData();
    std::uint8_t* to = v.valueData();
    const std::size_t nx = static_cast<std::size_t>(dims.x), ny = static_cast<std::size_t>(dims.y),
                      nz = static_cast<std::size_t>(dims.z);
    std::size_t src = 0;
    for (std::size_t x = 0; x < nx; ++x)
        for (std::size_t y = 0; y < ny; ++y)
            for (std::size_t z = 0; z < nz; ++z, ++src)
                std::memcpy(to + ((z * ny + y) * nx + x) * size, from + src * size, size);
    v.validate();
    return v;
}

Volume readVtkStructuredPoints(const fs::path& path)
{
    const std::string source = path.string();
    const std::uint64_t size = fileSize(path);
    std::ifstream in = openBinary(path);
    std::string text(static_cast<std::size_t>(size), '\0');
    if (size)
        readExactly(in, path, 0, text.data(), size);

    std::size_t pos = 0;
    auto nextLine = [&]() -> std::optional<std::string> {
        if (pos >= text.size())
            return std::nullopt;
        std::size_t end = text.find('\n', pos);
        if (end == std::string::npos)
            end = text.size();
        std::string line = text.substr(pos, std::min<std::size_t>(end - pos, 4096));
        pos = end + 1;
        if (!line.empty() && line.back() == '\r')
            line.pop_back();
        return line;
    };
    // The next line with content, split; empty at end of file.
    auto nextTokens = [&]() {
        while (const std::optional<std::string> line = nextLine()) {
            std::vector<std::string> t = splitWhitespace(*line);
            if (!t.empty())
                return t;
        }
        return std::vector<std::string>{};
    };

    const std::optional<std::string> magic = nextLine();
    if (!magic || asciiLower(*magic).rfind("# vtk datafile version", 0) != 0)
        throw InputError(source + ": not a VTK legacy file (the first line is " + shown(magic.value_or("")) +
                         ", expected \"# vtk DataFile Version x.y\")");
    nextLine();  // title
    const std::vector<std::string> format = nextTokens();
    const std::string fmt = format.empty() ? "" : asciiLower(format[0]);
    if (fmt != "ascii" && fmt != "binary")
        throw InputError(source + ": the third line must say ASCII or BINARY, not " +
                         shown(format.empty() ? "" : format[0]));
    const bool binary = fmt == "binary";

    std::vector<std::string> t = nextTokens();
    if (t.empty() || asciiLower(t[0]) != "dataset")
        throw InputError(source + ": expected DATASET STRUCTURED_POINTS after the " + fmt + " line");
    if (t.size() < 2 || asciiLower(t[1]) != "structured_points")
        throw InputError(source + ": DATASET is " + shown(t.size() > 1 ? t[1] : "") +
                         ", only STRUCTURED_POINTS is read as a regular volume");

    std::optional<std::vector<long long>> dims;
    glm::dvec3 spacing(1.0), origin(0.0);
    auto three = [&](const std::vector<std::string>& tok, const char* what) {
        if (tok.size() != 4)
            throw InputError(source + ": " + what + " needs 3 numbers");
        glm::dvec3 r;
        for (int a = 0; a < 3; ++a) {
            const std::optional<double> d = parseDouble(tok[static_cast<std::size_t>(a) + 1]);
            if (!d || !std::isfinite(*d))
                throw InputError(source + ": " + what + " " + shown(tok[static_cast<std::size_t>(a) + 1]) +
                                 " is not a finite number");
            r[a] = *d;
        }
        return r;
    };
    std::optional<long long> pointData;
    while (!(t = nextTokens()).empty()) {
        const std::string key = asciiLower(t[0]);
        if (key == "dimensions") {
            if (t.size() != 4)
                throw InputError(source + ": DIMENSIONS needs 3 integers");
            std::vector<long long> d;
            for (int a = 1; a <= 3; ++a) {
                const std::optional<long long> n = parseInteger(t[static_cast<std::size_t>(a)]);
                if (!n)
                    throw InputError(source + ": DIMENSIONS " + shown(t[static_cast<std::size_t>(a)]) +
                                     " is not an integer");
                d.push_back(*n);
            }
            dims = d;
        } else if (key == "spacing" || key == "aspect_ratio") {
            spacing = three(t, "SPACING");
        } else if (key == "origin") {
            origin = three(t, "ORIGIN");
        } else if (key == "point_data") {
            pointData = t.size() == 2 ? parseInteger(t[1]) : std::nullopt;
            if (!pointData)
                throw InputError(source + ": POINT_DATA needs one integer");
            break;
        } else if (key == "cell_data") {
            throw InputError(source + ": has CELL_DATA before POINT_DATA; only point scalars are read");
        } else {
            throw InputError(source + ": unexpected " + shown(t[0]) + " in the STRUCTURED_POINTS header");
        }
    }
    if (!dims)
        throw InputError(source + ": STRUCTURED_POINTS has no DIMENSIONS");
    if (!pointData)
        throw InputError(source + ": has no POINT_DATA");
    const std::uint64_t count = checkedVoxelCount(source, *dims);
    if (static_cast<std::uint64_t>(*pointData) != count || *pointData < 0)
        throw InputError(source + ": POINT_DATA " + std::to_string(*pointData) + " does not match DIMENSIONS " +
                         dimsText(*dims) + " = " + std::to_string(count));
    for (int a = 0; a < 3; ++a)
        if (!(spacing[a] > 0.0))
            throw InputError(source + ": spacing of axis " + std::to_string(a) + " is " + numberText(spacing[a]) +
                             ", must be positive");

    t = nextTokens();
    if (t.empty() || asciiLower(t[0]) != "scalars")
        throw InputError(source + ": expected SCALARS after POINT_DATA, found " +
                         shown(t.empty() ? "end of file" : t[0]));
    if (t.size() < 3 || t.size() > 4)
        throw InputError(source + ": SCALARS needs a name, a type and optionally a component count");
    const std::optional<ScalarType> type = vtkType(t[2]);
    if (!type)
        throw InputError(source + ": SCALARS type " + shown(t[2]) +
                         " is not supported (char, short, int, their unsigned forms, float and double are)");
    if (t.size() == 4 && t[3] != "1")
        throw InputError(source + ": SCALARS has " + shown(t[3]) + " components, only 1 is read");
    // LOOKUP_TABLE is optional in files VTK reads; the data begins on the line after it (or after SCALARS).
    {
        const std::size_t save = pos;
        const std::vector<std::string> lut = nextTokens();
        if (lut.empty() || asciiLower(lut[0]) != "lookup_table")
            pos = save;
    }

    Volume v;
    v.source = source;
    v.dims = glm::ivec3(static_cast<int>((*dims)[0]), static_cast<int>((*dims)[1]), static_cast<int>((*dims)[2]));
    v.spacing = spacing;
    v.origin = origin;
    const std::size_t elem = scalarSize(*type);
    if (binary) {
        const std::uint64_t bytes = count * elem;
        const std::uint64_t available = pos < text.size() ? text.size() - pos : 0;
        if (available < bytes)
            throw InputError(source + ": binary data is truncated: POINT_DATA " + dimsText(*dims) + " x " +
                             std::to_string(elem) + " bytes = " + std::to_string(bytes) + " bytes, file has " +
                             std::to_string(available) + " bytes after the header");
        v.values.resize(static_cast<std::size_t>(count));
        convertSamples(source, reinterpret_cast<const unsigned char*>(text.data() + pos), static_cast<std::size_t>(count),
                       *type, Endian::Big, v.values.data(), 0, v.dims);
    } else {
        std::uint64_t n = 0;
        std::string token;
        while (n < count && pos < text.size()) {
            while (pos < text.size() && std::isspace(static_cast<unsigned char>(text[pos])))
                ++pos;
            token.clear();
            while (pos < text.size() && !std::isspace(static_cast<unsigned char>(text[pos]))) {
                if (token.size() < 64)
                    token += text[pos];
                else if (token.size() == 64)
                    token += "...";  // a 64-character number is garbage: fail on it, do not split it
                ++pos;
            }
            if (!token.empty()) {  // values grow with what the file holds, not with what it claims
                float value = 0.0f;
                storeAsciiValue(source, token, n, &value);
                v.values.push_back(value);
                ++n;
            }
        }
        if (n < count)
            throw InputError(source + ": ASCII data is truncated: POINT_DATA says " + std::to_string(count) +
                             " values, file has " + std::to_string(n));
    }
    v.validate();
    return v;
}

Volume loadVolume(const VolumeSpec& spec)
{
    switch (spec.kind) {
    case VolumeSpec::Kind::Generator: return generateVolume(spec.generator, spec.dims);
    case VolumeSpec::Kind::Nrrd: return readNrrd(spec.file);
    case VolumeSpec::Kind::Vtk: return readVtkStructuredPoints(spec.file);
    case VolumeSpec::Kind::Raw: return readRaw(spec.file, spec.raw);
    case VolumeSpec::Kind::Npy: return readNpy(spec.file, spec.raw.spacing, spec.raw.origin);
    case VolumeSpec::Kind::VtkImage: return readVtkImage(spec.file, spec.scalar);
    }
    throw InternalError("loadVolume: unknown VolumeSpec::Kind " + std::to_string(static_cast<int>(spec.kind)));
}

namespace {

// A raw layout's grid points [lo, hi], read row by row (a slab at once where the region spans whole rows
// and planes). The file is checked as readRaw checks it: it must hold exactly the header and the samples,
// or (`exactSize` false: a NRRD, whose data may be followed by more) at least that.
Volume readRawRegion(const fs::path& path, const RawLayout& layout, const GridRegion& region, bool exactSize)
{
    const std::string source = path.string();
    const std::vector<long long> sizes{layout.dims.x, layout.dims.y, layout.dims.z};
    checkedVoxelCount(source, sizes, false);
    const std::size_t elem = scalarSize(layout.type);
    const std::uint64_t nx = static_cast<std::uint64_t>(layout.dims.x), ny = static_cast<std::uint64_t>(layout.dims.y);
    const std::uint64_t bytes = nx * ny * static_cast<std::uint64_t>(layout.dims.z) * elem;
    const std::uint64_t size = fileSize(path);
    if (layout.headerBytes > kMaxVoxels * 8 || (exactSize ? size != layout.headerBytes + bytes : size < layout.headerBytes + bytes))
        throw InputError(source + ": layout says " + dimsText(sizes) + " x " + std::to_string(elem) + " bytes" +
                         (layout.headerBytes ? " + " + std::to_string(layout.headerBytes) + " header bytes" : "") +
                         " = " + std::to_string(layout.headerBytes + bytes) + " bytes, file has " +
                         std::to_string(size) + " bytes");
    const glm::ivec3 n = region.dims();
    const std::uint64_t count = static_cast<std::uint64_t>(n.x) * static_cast<std::uint64_t>(n.y) * static_cast<std::uint64_t>(n.z);
    checkHostMemoryForVoxels(source, count);
    Volume v;
    v.source = source;
    v.dims = n;
    v.spacing = layout.spacing;
    v.origin = layout.origin + glm::dvec3(region.lo) * layout.spacing;
    const std::optional<VoxelType> native = nativeVoxelType(layout.type);
    if (native)  // 1- and 2-byte integers in their own type, read straight into place
        v.voxelType = *native;
    v.allocateValues();
    std::ifstream in = openBinary(path);
    const RegionRuns runs = regionRuns(layout.dims, region);
    std::vector<unsigned char> buffer(native ? 0 : static_cast<std::size_t>(runs.length * elem));
    for (std::size_t r = 0; r < runs.starts.size(); ++r) {
        const std::uint64_t first = runs.starts[r], at = r * runs.length;  // in the file, in the region
        if (native) {
            std::uint8_t* dst = v.valueData() + at * elem;
            readExactly(in, path, layout.headerBytes + first * elem, reinterpret_cast<char*>(dst), runs.length * elem);
            toHostOrder(dst, static_cast<std::size_t>(runs.length), elem, layout.endian);
        } else {
            readExactly(in, path, layout.headerBytes + first * elem, reinterpret_cast<char*>(buffer.data()),
                        runs.length * elem);
            convertSamples(source, buffer.data(), static_cast<std::size_t>(runs.length), layout.type, layout.endian,
                           v.values.data() + at, first, layout.dims);
        }
    }
    v.validate();
    return v;
}

}  // namespace

namespace {

// A gzip NRRD stream's grid points `region`: the compressed data read and inflated in order, 1 MiB at a time,
// keeping only the region's rows and stopping after its last one (a part near the start of the file inflates
// only that far). Integers of 1 and 2 bytes kept in their own type, as readRawRegion keeps them.
Volume readGzipRegion(const NrrdStream& st, const GridRegion& region)
{
    const std::string source = st.file.string();
    const RawLayout& layout = st.layout;
    const std::size_t elem = scalarSize(layout.type);
    const std::uint64_t nx = static_cast<std::uint64_t>(layout.dims.x), ny = static_cast<std::uint64_t>(layout.dims.y);
    const std::uint64_t total = nx * ny * static_cast<std::uint64_t>(layout.dims.z) * elem;
    const std::uint64_t size = fileSize(st.file);
    const std::uint64_t compressed = size > layout.headerBytes ? size - layout.headerBytes : 0;
    if (!gzipCanHold(compressed, total + st.gzipSkip))
        throw InputError(source + ": gzip data is truncated: " + st.sizeText + ", and " + std::to_string(compressed) +
                         " compressed bytes cannot hold that many");
    const glm::ivec3 n = region.dims();
    const std::uint64_t count = static_cast<std::uint64_t>(n.x) * static_cast<std::uint64_t>(n.y) * static_cast<std::uint64_t>(n.z);
    checkHostMemoryForVoxels(source, count);
    const RegionRuns runs = regionRuns(layout.dims, region);
    const std::uint64_t run = runs.length;
    const std::vector<std::uint64_t>& runStart = runs.starts;
    VoxelBytes bytes(static_cast<std::size_t>(count * elem));  // kept as the voxels where their type is native
    std::size_t next = 0;  // the first run not yet complete
    std::ifstream in = openBinary(st.file);
    in.seekg(static_cast<std::streamoff>(layout.headerBytes));
    gunzipTo(
        source,
        [&](unsigned char* buffer, std::size_t max) {
            in.read(reinterpret_cast<char*>(buffer), static_cast<std::streamsize>(max));
            return static_cast<std::size_t>(in.gcount());
        },
        st.gzipSkip, (runStart.back() + run) * elem, st.sizeText,
        [&](std::uint64_t offset, const unsigned char* data, std::size_t length) {
            const std::uint64_t end = offset + length;
            while (next < runStart.size()) {
                const std::uint64_t r0 = runStart[next] * elem, r1 = r0 + run * elem;
                if (r0 >= end)
                    return;
                const std::uint64_t c0 = std::max(r0, offset), c1 = std::min(r1, end);
                if (c1 > c0)
                    std::memcpy(bytes.data() + next * run * elem + (c0 - r0), data + (c0 - offset), c1 - c0);
                if (r1 > end)
                    return;  // the rest of this run comes with the next piece
                ++next;
            }
        });
    Volume v;
    v.source = source;
    v.dims = n;
    v.spacing = layout.spacing;
    v.origin = layout.origin + glm::dvec3(region.lo) * layout.spacing;
    if (const std::optional<VoxelType> native = nativeVoxelType(layout.type)) {
        v.voxelType = *native;
        toHostOrder(bytes.data(), static_cast<std::size_t>(count), elem, layout.endian);
        v.voxels = std::move(bytes);
    } else {
        v.values.resize(static_cast<std::size_t>(count));
        for (std::size_t r = 0; r < runStart.size(); ++r)
            convertSamples(source, bytes.data() + r * run * elem, static_cast<std::size_t>(run), layout.type,
                           layout.endian, v.values.data() + r * run, runStart[r], layout.dims);
    }
    v.validate();
    return v;
}

}  // namespace

namespace {

// A volume that reads by regions: its grid from the header, read once, and the reader of a region of it.
struct RegionReader {
    GridHeader header;
    std::function<Volume(const GridRegion&)> read;
};

std::optional<RegionReader> regionReader(const VolumeSpec& spec)
{
    switch (spec.kind) {
    case VolumeSpec::Kind::Raw:
        return RegionReader{{spec.raw.dims, spec.raw.spacing, spec.raw.origin},
                            [spec](const GridRegion& r) { return readRawRegion(spec.file, spec.raw, r); }};
    case VolumeSpec::Kind::Npy: {
        const NpyHeader h = readNpyHeader(spec.file);
        if (!h.fortranOrder)
            return std::nullopt;
        checkedVoxelCount(spec.file.string(), h.shape, false);
        const RawLayout layout = npyLayout(h, spec.raw.spacing, spec.raw.origin);
        return RegionReader{{layout.dims, layout.spacing, layout.origin},
                            [file = spec.file, layout](const GridRegion& r) { return readRawRegion(file, layout, r); }};
    }
    case VolumeSpec::Kind::VtkImage:
        return RegionReader{readVtkImageHeader(spec.file),
                            [spec](const GridRegion& r) { return readVtkImage(spec.file, spec.scalar, r); }};
    case VolumeSpec::Kind::Nrrd: {
        const NrrdHeader h = readNrrdHeader(spec.file);
        std::uint64_t count = 0;
        const Volume geometry = nrrdGeometry(h, count);
        std::optional<NrrdStream> stream = nrrdStream(h, geometry, count);
        if (!stream)
            return std::nullopt;
        return RegionReader{{geometry.dims, geometry.spacing, geometry.origin},
                            [st = std::move(*stream), source = spec.file.string()](const GridRegion& r) {
                                Volume v = readNrrdRegion(st, r);
                                v.source = source;
                                return v;
                            }};
    }
    default: return std::nullopt;
    }
}

}  // namespace

std::optional<GridHeader> volumeHeader(const VolumeSpec& spec)
{
    const std::optional<RegionReader> reader = regionReader(spec);
    return reader ? std::optional<GridHeader>(reader->header) : std::nullopt;
}

Volume loadVolumeRegion(const VolumeSpec& spec, const GridRegion& region)
{
    const std::optional<RegionReader> reader = regionReader(spec);
    if (!reader)
        throw InternalError("loadVolumeRegion: " + spec.file.string() + " cannot be read by regions");
    const glm::ivec3 dims = reader->header.dims;
    if (glm::any(glm::lessThan(region.lo, glm::ivec3(0))) || glm::any(glm::greaterThanEqual(region.hi, dims)) ||
        glm::any(glm::lessThan(region.hi, region.lo)))
        throw InternalError("loadVolumeRegion: a region outside the grid of " + spec.file.string());
    return reader->read(region);
}

Volume loadVolume(const nlohmann::json& spec, const fs::path& baseDir)
{
    return loadVolume(parseVolumeSpec(spec, baseDir));
}

}  // namespace clvr
