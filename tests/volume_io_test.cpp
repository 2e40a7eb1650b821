// tests/volume_io_test.cpp — regular-volume input: the real data sets checked against bytes read
// independently, bit-exact round trips through raw, NRRD (attached, detached, multi-file, gzip, ascii) and
// VTK (ASCII, big-endian BINARY) files written here, the scene's "volume" object, and every bad input
// giving a one-line InputError that names the file. Files are written to a temporary directory.
#include "host/runtime/errors.h"
#include "host/io/volume_io.h"
#include "host/io/generators.h"
#include "tests/support/test_util.h"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>
#include <zlib.h>

#include <unistd.h>

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <functional>
#include <limits>
#include <sstream>

namespace fs = std::filesystem;
using clvr::Endian;
using clvr::ScalarType;

namespace {

using clvr::test::gzip;
using clvr::test::throwsInputError;
using clvr::test::readFile;
using clvr::test::TempDir;
using clvr::test::writeFile;

// Values encoded as `T` in the given byte order, independently of the readers.
template <typename T>
std::string encode(const std::vector<double>& values, Endian endian)
{
    std::string out;
    for (double d : values) {
        const T v = static_cast<T>(d);
        char b[sizeof(T)];
        std::memcpy(b, &v, sizeof(T));
        if ((endian == Endian::Big) != (std::endian::native == std::endian::big))
            std::reverse(b, b + sizeof(T));
        out.append(b, sizeof(T));
    }
    return out;
}

std::string encode(ScalarType type, const std::vector<double>& values, Endian endian)
{
    switch (type) {
    case ScalarType::UInt8: return encode<std::uint8_t>(values, endian);
    case ScalarType::Int8: return encode<std::int8_t>(values, endian);
    case ScalarType::Int16: return encode<std::int16_t>(values, endian);
    case ScalarType::UInt16: return encode<std::uint16_t>(values, endian);
    case ScalarType::Int32: return encode<std::int32_t>(values, endian);
    case ScalarType::UInt32: return encode<std::uint32_t>(values, endian);
    case ScalarType::Float32: return encode<float>(values, endian);
    case ScalarType::Float64: return encode<double>(values, endian);
    }
    return {};
}

// Decompresses a whole gzip file with zlib's gz* interface (not the reader's inflate loop).
std::string gunzipFile(const fs::path& path)
{
    gzFile f = gzopen(path.c_str(), "rb");
    EXPECT_NE(f, nullptr);
    std::string out;
    char buf[1 << 16];
    int n;
    while ((n = gzread(f, buf, sizeof buf)) > 0)
        out.append(buf, static_cast<std::size_t>(n));
    gzclose(f);
    return out;
}

// A small volume with odd sizes (index bugs show) whose values fit every type exactly:
// integers 0..119 shifted into the signed range where the type is signed, halves for floats.
constexpr glm::ivec3 kDims{5, 4, 6};

std::vector<double> testValues(ScalarType type)
{
    std::vector<double> v;
    for (int n = 0; n < kDims.x * kDims.y * kDims.z; ++n) {
        switch (type) {
        case ScalarType::Int8:
        case ScalarType::Int16:
        case ScalarType::Int32: v.push_back(n - 60); break;
        case ScalarType::Float32:
        case ScalarType::Float64: v.push_back((n - 60) * 0.5 + 0.125); break;
        default: v.push_back(n * 2 + 1); break;
        }
    }
    return v;
}

void expectValues(const clvr::Volume& v, const std::vector<double>& expected)
{
    ASSERT_EQ(v.dims, kDims);
    ASSERT_EQ(v.voxelCount(), expected.size());
    ASSERT_NO_THROW(v.validate());  // one storage, of the right size
    for (std::size_t i = 0; i < expected.size(); ++i)
        ASSERT_EQ(v.value(i), static_cast<float>(expected[i])) << "value " << i;
}

const char* nrrdTypeName(ScalarType t)
{
    switch (t) {
    case ScalarType::UInt8: return "uchar";
    case ScalarType::Int8: return "signed char";
    case ScalarType::Int16: return "short";
    case ScalarType::UInt16: return "unsigned short";
    case ScalarType::Int32: return "int";
    case ScalarType::UInt32: return "uint";
    case ScalarType::Float32: return "float";
    case ScalarType::Float64: return "double";
    }
    return "";
}

std::string nrrdHeader(const std::string& type, const std::string& extra, const std::string& encoding = "raw",
                       const std::string& endian = "little")
{
    return "NRRD0004\n# written by volume_io_test\ntype: " + type + "\ndimension: 3\nsizes: 5 4 6\n" +
           "spacings: 0.5 0.25 2\nendian: " + endian + "\nencoding: " + encoding + "\n" + extra;
}

// ------------------------------------------------------------------------------------------------
// The real data sets.

TEST(VolumeIo, HeadsqMultiFileHeaderMatchesSliceFilesByteForByte)
{
    const clvr::Volume v = clvr::readNrrd(clvr::test::sharedData("headsq/quarter.nhdr"));
    ASSERT_EQ(v.dims, glm::ivec3(64, 64, 93));
    EXPECT_EQ(v.spacing, glm::dvec3(3.2, 3.2, 1.5));
    EXPECT_EQ(v.origin, glm::dvec3(0.0));
    // quarter.<k+1> holds slice k as 64x64 little-endian int16 (the header's "endian: little").
    auto voxel = [](int i, int j, int k) {
        const std::string slice = readFile(clvr::test::sharedData("headsq/quarter." + std::to_string(k + 1)));
        EXPECT_EQ(slice.size(), 64u * 64u * 2u);
        const std::size_t at = (static_cast<std::size_t>(j) * 64 + i) * 2;
        return static_cast<std::int16_t>(static_cast<std::uint8_t>(slice[at]) |
                                         static_cast<std::uint8_t>(slice[at + 1]) << 8);
    };
    EXPECT_EQ(v.at(32, 32, 46), voxel(32, 32, 46));  // quarter.47
    EXPECT_EQ(v.at(0, 0, 0), voxel(0, 0, 0));
    EXPECT_EQ(v.at(63, 63, 92), voxel(63, 63, 92));
    EXPECT_EQ(v.at(17, 41, 70), voxel(17, 41, 70));
    EXPECT_NE(v.at(32, 32, 46), 0.0f) << "the middle of the head is not air";
    // Every voxel: the whole range and sum agree with an independent read.
    double lo = 1e9, hi = -1e9, sum = 0, expectedSum = 0;
    for (int k = 0; k < 93; ++k) {
        const std::string slice = readFile(clvr::test::sharedData("headsq/quarter." + std::to_string(k + 1)));
        for (std::size_t n = 0; n < 64 * 64; ++n) {
            const double x = static_cast<std::int16_t>(static_cast<std::uint8_t>(slice[2 * n]) |
                                                       static_cast<std::uint8_t>(slice[2 * n + 1]) << 8);
            lo = std::min(lo, x);
            hi = std::max(hi, x);
            expectedSum += x;
            sum += v.value(static_cast<std::size_t>(k) * 4096 + n);
        }
    }
    EXPECT_EQ(v.range(), glm::dvec2(lo, hi));
    EXPECT_EQ(sum, expectedSum);
    EXPECT_GT(hi, 1000.0) << "CT numbers stay CT numbers (no normalisation)";
}

// The attached gzip data, decompressed with zlib's gz* file interface from a copy without the header.
void expectMatchesIndependentGunzip(const clvr::Volume& v, const std::string& file)
{
    const std::string bytes = readFile(clvr::test::sharedData(file));
    const std::size_t blank = bytes.find("\n\n");
    ASSERT_NE(blank, std::string::npos);
    TempDir dir;
    writeFile(dir / "data.gz", bytes.substr(blank + 2));
    const std::string raw = gunzipFile(dir / "data.gz");
    ASSERT_EQ(raw.size(), v.voxelCount());
    for (std::size_t i = 0; i < raw.size(); ++i)
        ASSERT_EQ(v.value(i), static_cast<float>(static_cast<std::uint8_t>(raw[i]))) << "voxel " << i;
}

TEST(VolumeIo, EngineGzipNrrd)
{
    const clvr::Volume v = clvr::readNrrd(clvr::test::sharedData("engine/engine.nrrd"));
    ASSERT_EQ(v.dims, glm::ivec3(256, 256, 128));
    EXPECT_EQ(v.spacing, glm::dvec3(1.0));
    EXPECT_EQ(v.origin, glm::dvec3(0.0));
    const glm::dvec2 r = v.range();
    EXPECT_GE(r.x, 0.0);
    EXPECT_EQ(r.y, 255.0);  // README: 0 .. 255, with clamped voxels
    expectMatchesIndependentGunzip(v, "engine/engine.nrrd");
}

TEST(VolumeIo, LobsterGzipNrrdThroughLoadVolume)
{
    const clvr::Volume v = clvr::loadVolume({{"file", "lobster/lobster.nrrd"}}, clvr::test::sharedData(""));
    ASSERT_EQ(v.dims, glm::ivec3(301, 324, 56));
    EXPECT_EQ(v.spacing, glm::dvec3(1.0, 1.0, 1.4));
    const glm::dvec2 r = v.range();
    EXPECT_GE(r.x, 0.0);
    EXPECT_EQ(r.y, 255.0);
    expectMatchesIndependentGunzip(v, "lobster/lobster.nrrd");
}

// ------------------------------------------------------------------------------------------------
// Round trips, bit-exact.

TEST(VolumeIo, RawRoundTripEveryTypeAndEndian)
{
    TempDir dir;
    const std::array<std::pair<ScalarType, const char*>, 8> types{{
        {ScalarType::UInt8, "uint8"}, {ScalarType::Int8, "int8"}, {ScalarType::Int16, "int16"},
        {ScalarType::UInt16, "uint16"}, {ScalarType::Int32, "int32"}, {ScalarType::UInt32, "uint32"},
        {ScalarType::Float32, "float32"}, {ScalarType::Float64, "float64"},
    }};
    for (const auto& [type, name] : types) {
        for (Endian endian : {Endian::Little, Endian::Big}) {
            SCOPED_TRACE(std::string(name) + (endian == Endian::Big ? " big" : " little"));
            const std::vector<double> values = testValues(type);
            writeFile(dir / "v.raw", std::string(7, 'h') + encode(type, values, endian));
            const nlohmann::json spec = {{"file", "v.raw"},          {"dims", {5, 4, 6}},
                                         {"type", name},             {"endian", endian == Endian::Big ? "big" : "little"},
                                         {"spacing", {0.5, 1, 2}},   {"origin", {-1, 0, 3.5}},
                                         {"header_bytes", 7}};
            const clvr::Volume v = clvr::loadVolume(spec, dir.path());
            expectValues(v, values);
            // 1- and 2-byte integers stay in their own type (no float copy), the rest become float.
            const bool native = clvr::scalarSize(type) <= 2 && type != ScalarType::Float32;
            EXPECT_EQ(v.native(), native);
            EXPECT_EQ(v.valueBytes(), v.voxelCount() * (native ? clvr::scalarSize(type) : 4));
            EXPECT_EQ(v.spacing, glm::dvec3(0.5, 1, 2));
            EXPECT_EQ(v.origin, glm::dvec3(-1, 0, 3.5));
        }
    }
    // readRaw directly, defaults: spacing 1, origin 0.
    writeFile(dir / "d.bin", encode(ScalarType::UInt16, testValues(ScalarType::UInt16), Endian::Big));
    clvr::RawLayout layout;
    layout.dims = kDims;
    layout.type = ScalarType::UInt16;
    layout.endian = Endian::Big;
    const clvr::Volume v = clvr::readRaw(dir / "d.bin", layout);
    expectValues(v, testValues(ScalarType::UInt16));
    EXPECT_EQ(v.spacing, glm::dvec3(1.0));
}

TEST(VolumeIo, NrrdAttachedRawEveryTypeAndEndian)
{
    TempDir dir;
    for (ScalarType type : {ScalarType::UInt8, ScalarType::Int8, ScalarType::Int16, ScalarType::UInt16,
                            ScalarType::Int32, ScalarType::UInt32, ScalarType::Float32, ScalarType::Float64}) {
        for (Endian endian : {Endian::Little, Endian::Big}) {
            SCOPED_TRACE(std::string(nrrdTypeName(type)) + (endian == Endian::Big ? " big" : " little"));
            const std::vector<double> values = testValues(type);
            writeFile(dir / "v.nrrd", nrrdHeader(nrrdTypeName(type), "space origin: (1,2,3)\n\n", "raw",
                                                 endian == Endian::Big ? "big" : "little") +
                                          encode(type, values, endian));
            const clvr::Volume v = clvr::readNrrd(dir / "v.nrrd");
            expectValues(v, values);
            EXPECT_EQ(v.spacing, glm::dvec3(0.5, 0.25, 2));
            EXPECT_EQ(v.origin, glm::dvec3(1, 2, 3));
        }
    }
}

TEST(VolumeIo, NrrdTypeSpellings)
{
    TempDir dir;
    const std::vector<std::pair<std::string, ScalarType>> spellings{
        {"unsigned char", ScalarType::UInt8}, {"uint8_t", ScalarType::UInt8},     {"int8", ScalarType::Int8},
        {"short int", ScalarType::Int16},     {"int16_t", ScalarType::Int16},    {"signed short", ScalarType::Int16},
        {"ushort", ScalarType::UInt16},       {"uint16", ScalarType::UInt16},    {"signed int", ScalarType::Int32},
        {"int32_t", ScalarType::Int32},       {"unsigned int", ScalarType::UInt32}, {"uint32", ScalarType::UInt32},
        {"float", ScalarType::Float32},       {"double", ScalarType::Float64}};
    for (const auto& [name, type] : spellings) {
        SCOPED_TRACE(name);
        const std::vector<double> values = testValues(type);
        writeFile(dir / "v.nrrd", nrrdHeader(name, "\n") + encode(type, values, Endian::Little));
        expectValues(clvr::readNrrd(dir / "v.nrrd"), values);
    }
}

TEST(VolumeIo, NrrdDetachedSingleFileWithSpaceDirections)
{
    TempDir dir;
    const std::vector<double> values = testValues(ScalarType::Int16);
    fs::create_directories(dir / "sub");
    writeFile(dir / "sub" / "v.raw", encode(ScalarType::Int16, values, Endian::Big));
    writeFile(dir / "v.nhdr", "NRRD0005\ntype: int16\ndimension: 3\nsizes: 5 4 6\n"
                              "space: left-posterior-superior\nspace directions: (0.5,0,0) (0, 0.25, 0)\t( 0,0,2 )\n"
                              "space origin: (-1.5, 0, 2.25)\nkinds: domain domain domain\nendian: big\n"
                              "encoding: raw\ndata file: sub/v.raw\n");
    const clvr::Volume v = clvr::loadVolume({{"file", "v.nhdr"}}, dir.path());
    expectValues(v, values);
    EXPECT_EQ(v.spacing, glm::dvec3(0.5, 0.25, 2));
    EXPECT_EQ(v.origin, glm::dvec3(-1.5, 0, 2.25));
}

TEST(VolumeIo, NrrdDetachedFormattedFileNamesAndList)
{
    TempDir dir;
    const std::vector<double> values = testValues(ScalarType::Float32);
    const std::string all = encode(ScalarType::Float32, values, Endian::Little);
    const std::size_t slice = all.size() / 6;
    std::string list;
    for (int k = 0; k < 6; ++k) {
        char name[32];
        std::snprintf(name, sizeof name, "s%03d.raw", 10 + 2 * k);  // s010.raw, s012.raw, ...
        writeFile(dir / name, all.substr(k * slice, slice));
        list += std::string(name) + "\n";
    }
    writeFile(dir / "fmt.nhdr", nrrdHeader("float", "data file: s%03d.raw 10 20 2 2\n"));
    expectValues(clvr::readNrrd(dir / "fmt.nhdr"), values);
    writeFile(dir / "list.nhdr", nrrdHeader("float", "data file: LIST\n" + list));
    expectValues(clvr::readNrrd(dir / "list.nhdr"), values);
    // Descending numbers take the files in the order the header gives them.
    writeFile(dir / "down.nhdr", nrrdHeader("float", "data file: s%03d.raw 20 10 -2\n"));
    const clvr::Volume down = clvr::readNrrd(dir / "down.nhdr");
    EXPECT_EQ(down.at(0, 0, 0), static_cast<float>(values[5 * 20]));
}

TEST(VolumeIo, NrrdGzipAttachedAndDetached)
{
    TempDir dir;
    const std::vector<double> values = testValues(ScalarType::UInt16);
    const std::string data = encode(ScalarType::UInt16, values, Endian::Big);
    writeFile(dir / "a.nrrd", nrrdHeader("ushort", "\n", "gzip", "big") + gzip(data));
    expectValues(clvr::readNrrd(dir / "a.nrrd"), values);
    writeFile(dir / "d.raw.gz", gzip(data));
    writeFile(dir / "d.nhdr", nrrdHeader("ushort", "data file: d.raw.gz\n", "gz", "big"));
    expectValues(clvr::readNrrd(dir / "d.nhdr"), values);
    // Two concatenated gzip members read as one stream.
    writeFile(dir / "m.nrrd", nrrdHeader("ushort", "\n", "gzip", "big") + gzip(data.substr(0, 100)) +
                                  gzip(data.substr(100)));
    expectValues(clvr::readNrrd(dir / "m.nrrd"), values);
    // byte skip applies to the decompressed data.
    writeFile(dir / "s.nrrd", nrrdHeader("ushort", "byte skip: 3\n\n", "gzip", "big") + gzip("abc" + data));
    expectValues(clvr::readNrrd(dir / "s.nrrd"), values);
}

TEST(VolumeIo, NrrdAsciiByteSkipLineSkipAndCrLf)
{
    TempDir dir;
    const std::vector<double> values = testValues(ScalarType::Float64);
    std::ostringstream text;
    text.precision(17);
    for (std::size_t i = 0; i < values.size(); ++i)
        text << values[i] << (i % 7 == 6 ? "\n" : " ");
    writeFile(dir / "a.nrrd", nrrdHeader("double", "\n", "ascii") + text.str());
    expectValues(clvr::readNrrd(dir / "a.nrrd"), values);

    const std::vector<double> ints = testValues(ScalarType::Int32);
    const std::string data = encode(ScalarType::Int32, ints, Endian::Little);
    writeFile(dir / "skip.raw", "line one\nline two\n" + std::string(5, 'x') + data);
    writeFile(dir / "skip.nhdr", nrrdHeader("int", "line skip: 2\nbyte skip: 5\ndata file: ./skip.raw\n"));
    expectValues(clvr::readNrrd(dir / "skip.nhdr"), ints);
    writeFile(dir / "tail.raw", std::string(11, 'x') + data);
    writeFile(dir / "tail.nhdr", nrrdHeader("int", "byte skip: -1\ndata file: tail.raw\n"));
    expectValues(clvr::readNrrd(dir / "tail.nhdr"), ints);

    std::string crlf = nrrdHeader("int", "\n");
    for (std::size_t p = 0; (p = crlf.find('\n', p)) != std::string::npos; p += 2)
        crlf.replace(p, 1, "\r\n");
    writeFile(dir / "crlf.nrrd", crlf + data);
    expectValues(clvr::readNrrd(dir / "crlf.nrrd"), ints);
}

TEST(VolumeIo, NrrdDimensionFourWithOneComponent)
{
    TempDir dir;
    const std::vector<double> values = testValues(ScalarType::UInt8);
    writeFile(dir / "v.nrrd", "NRRD0004\ntype: uchar\ndimension: 4\nsizes: 1 5 4 6\n"
                              "space directions: none (2,0,0) (0,3,0) (0,0,4)\nencoding: raw\n\n" +
                                  encode(ScalarType::UInt8, values, Endian::Little));
    const clvr::Volume v = clvr::readNrrd(dir / "v.nrrd");
    expectValues(v, values);
    EXPECT_EQ(v.spacing, glm::dvec3(2, 3, 4));
    writeFile(dir / "s.nrrd", "NRRD0004\ntype: uchar\ndimension: 4\nsizes: 1 5 4 6\n"
                              "spacings: nan 2 3 4\nencoding: raw\n\n" +
                                  encode(ScalarType::UInt8, values, Endian::Little));
    EXPECT_EQ(clvr::readNrrd(dir / "s.nrrd").spacing, glm::dvec3(2, 3, 4));
}

std::string vtkHeader(const std::string& format, const std::string& type, const std::string& dataset = "STRUCTURED_POINTS")
{
    return "# vtk DataFile Version 3.0\nwritten by volume_io_test\n" + format + "\nDATASET " + dataset +
           "\nDIMENSIONS 5 4 6\nORIGIN -1 0.5 2\nSPACING 0.5 0.25 2\nPOINT_DATA 120\nSCALARS density " + type +
           " 1\nLOOKUP_TABLE default\n";
}

TEST(VolumeIo, VtkAsciiAndBigEndianBinaryRoundTrip)
{
    TempDir dir;
    const std::vector<std::pair<ScalarType, const char*>> types{
        {ScalarType::UInt8, "unsigned_char"}, {ScalarType::Int16, "short"},   {ScalarType::UInt16, "unsigned_short"},
        {ScalarType::Int32, "int"},           {ScalarType::Float32, "float"}, {ScalarType::Float64, "double"}};
    for (const auto& [type, name] : types) {
        SCOPED_TRACE(name);
        const std::vector<double> values = testValues(type);
        writeFile(dir / "b.vtk", vtkHeader("BINARY", name) + encode(type, values, Endian::Big) + "\n");
        const clvr::Volume b = clvr::readVtkStructuredPoints(dir / "b.vtk");
        expectValues(b, values);
        EXPECT_EQ(b.origin, glm::dvec3(-1, 0.5, 2));
        EXPECT_EQ(b.spacing, glm::dvec3(0.5, 0.25, 2));

        std::ostringstream text;
        text.precision(17);
        for (std::size_t i = 0; i < values.size(); ++i)
            text << values[i] << (i % 9 == 8 ? "\n" : " ");
        writeFile(dir / "a.vtk", vtkHeader("ASCII", name) + text.str() + "\n");
        expectValues(clvr::loadVolume({{"file", "a.vtk"}}, dir.path()), values);
    }
    // Without LOOKUP_TABLE, and with the geometry keywords in another order.
    const std::vector<double> values = testValues(ScalarType::Int16);
    writeFile(dir / "n.vtk", "# vtk DataFile Version 2.0\nt\nBINARY\nDATASET STRUCTURED_POINTS\nSPACING 1 1 1\n"
                             "ORIGIN 0 0 0\nDIMENSIONS 5 4 6\nPOINT_DATA 120\nSCALARS s short\n" +
                                 encode(ScalarType::Int16, values, Endian::Big));
    expectValues(clvr::readVtkStructuredPoints(dir / "n.vtk"), values);
}

// ------------------------------------------------------------------------------------------------
// The scene's "volume" object.

TEST(VolumeIo, LoadVolumeGeneratorAndRelativePaths)
{
    const clvr::Volume g = clvr::loadVolume({{"generator", "sphere"}, {"dims", {9, 7, 5}}}, "/nonexistent");
    EXPECT_EQ(g.dims, glm::ivec3(9, 7, 5));
    EXPECT_EQ(g.at(4, 3, 2), 1.0f);
    const clvr::Volume h = clvr::loadVolume({{"file", "quarter.nhdr"}}, clvr::test::sharedData("headsq"));
    EXPECT_EQ(h.dims, glm::ivec3(64, 64, 93));
    const clvr::Volume a = clvr::loadVolume({{"file", clvr::test::sharedData("headsq/quarter.nhdr")}}, "/elsewhere");
    std::vector<float> sa, sh;
    EXPECT_EQ(a.floats(sa), h.floats(sh));
}

TEST(VolumeIo, LoadVolumeRejectsUnknownKeysAndBadValues)
{
    TempDir dir;
    const fs::path base = dir.path();
    auto load = [&](nlohmann::json spec) { return [spec, base] { clvr::loadVolume(spec, base); }; };
    EXPECT_TRUE(throwsInputError(load({{"file", "x.nrrd"}, {"dimz", 3}}), {"unknown key \"dimz\""}));
    EXPECT_TRUE(throwsInputError(load({{"generator", "sphere"}, {"dims", {4, 4, 4}}, {"colour", 1}}),
                                 {"unknown key \"colour\""}));
    EXPECT_TRUE(throwsInputError(load({{"file", "x.raw"}, {"dims", {4, 4, 4}}, {"type", "uint8"}, {"spacings", 1}}),
                                 {"unknown key \"spacings\""}));
    EXPECT_TRUE(throwsInputError(load({{"generator", "sphere"}}), {"\"dims\" is missing"}));
    EXPECT_TRUE(throwsInputError(load({{"generator", "sphere"}, {"dims", {4, 4}}}), {"\"dims\""}));
    EXPECT_TRUE(throwsInputError(load({{"generator", "sphere"}, {"dims", {4, 4, 4.5}}}), {"\"dims\""}));
    EXPECT_TRUE(throwsInputError(load({{"generator", "cube"}, {"dims", {4, 4, 4}}}), {"cube"}));
    EXPECT_TRUE(throwsInputError(load({{"generator", 3}, {"dims", {4, 4, 4}}}), {"\"generator\" must be a string"}));
    EXPECT_TRUE(throwsInputError(load({{"file", "x.nrrd"}, {"generator", "sphere"}}), {"both"}));
    EXPECT_TRUE(throwsInputError(load(nlohmann::json::object()), {"neither"}));
    EXPECT_TRUE(throwsInputError(load(nlohmann::json::array()), {"volume"}));
    EXPECT_TRUE(throwsInputError(load({{"file", "x.raw"}, {"dims", {4, 4, 4}}}), {"\"type\" is missing"}));
    EXPECT_TRUE(throwsInputError(load({{"file", "x.raw"}, {"dims", {4, 4, 4}}, {"type", "int64"}}), {"\"type\""}));
    EXPECT_TRUE(throwsInputError(load({{"file", "x.raw"}, {"dims", {4, 4, 4}}, {"type", "int16"}}),
                                 {"\"endian\" is missing"}));
    EXPECT_TRUE(throwsInputError(
        load({{"file", "x.raw"}, {"dims", {4, 4, 4}}, {"type", "uint8"}, {"endian", "middle"}}), {"\"endian\""}));
    EXPECT_TRUE(throwsInputError(
        load({{"file", "x.raw"}, {"dims", {4, 4, 4}}, {"type", "uint8"}, {"spacing", {1, 1}}}), {"\"spacing\""}));
    EXPECT_TRUE(throwsInputError(
        load({{"file", "x.raw"}, {"dims", {4, 4, 4}}, {"type", "uint8"}, {"header_bytes", -1}}), {"\"header_bytes\""}));
    EXPECT_TRUE(throwsInputError(load({{"file", "x.img"}}), {"x.img", "unknown volume format"}));
    EXPECT_TRUE(throwsInputError(load({{"file", "x.nrrd"}, {"dims", {4, 4, 4}}}), {"unknown key \"dims\"", ".nrrd"}));
    EXPECT_TRUE(throwsInputError(load({{"file", 7}}), {"\"file\" must be a string"}));
}

// ------------------------------------------------------------------------------------------------
// Bad files: one line naming the file and what is wrong.

TEST(VolumeIo, MissingFiles)
{
    TempDir dir;
    const fs::path missing = dir / "missing.nrrd";
    EXPECT_TRUE(throwsInputError([&] { clvr::readNrrd(missing); }, {missing.string(), "no such file"}));
    EXPECT_TRUE(throwsInputError([&] { clvr::readVtkStructuredPoints(dir / "m.vtk"); }, {"m.vtk", "no such file"}));
    clvr::RawLayout layout;
    layout.dims = kDims;
    EXPECT_TRUE(throwsInputError([&] { clvr::readRaw(dir / "m.raw", layout); }, {"m.raw", "no such file"}));
    EXPECT_TRUE(throwsInputError([&] { clvr::readNrrd(dir.path()); }, {"directory"}));
    // A detached header whose data file is missing names the data file.
    writeFile(dir / "d.nhdr", nrrdHeader("uchar", "data file: gone.raw\n"));
    EXPECT_TRUE(throwsInputError([&] { clvr::readNrrd(dir / "d.nhdr"); }, {"gone.raw", "no such file"}));
    writeFile(dir / "q.nhdr", nrrdHeader("uchar", "data file: q.%d 1 6 1\n"));
    writeFile(dir / "q.1", std::string(20, '\0'));
    EXPECT_TRUE(throwsInputError([&] { clvr::readNrrd(dir / "q.nhdr"); }, {"q.2", "no such file"}));
}

TEST(VolumeIo, NrrdHeaderErrors)
{
    TempDir dir;
    const fs::path p = dir / "bad.nrrd";
    const std::string data = encode(ScalarType::UInt8, testValues(ScalarType::UInt8), Endian::Little);
    auto expectError = [&](const std::string& contents, std::vector<std::string> pieces) {
        writeFile(p, contents);
        pieces.push_back(p.string());
        return throwsInputError([&] { clvr::readNrrd(p); }, pieces);
    };
    EXPECT_TRUE(expectError("P5\n5 4\n255\n" + data, {"not a NRRD file"}));
    EXPECT_TRUE(expectError("", {"not a NRRD file"}));
    EXPECT_TRUE(expectError(std::string(3 << 20, 'N'), {"not a NRRD file"}));  // no newline anywhere: bounded
    EXPECT_TRUE(expectError("NRRD0004\ntype: uchar\ndimension: 3\nencoding: raw\n\n" + data, {"\"sizes\""}));
    EXPECT_TRUE(expectError("NRRD0004\nsizes: 5 4 6\ndimension: 3\nencoding: raw\n\n" + data, {"\"type\""}));
    EXPECT_TRUE(expectError("NRRD0004\ntype: uchar\nsizes: 5 4 6\ndimension: 3\n\n" + data, {"\"encoding\""}));
    EXPECT_TRUE(expectError("NRRD0004\ntype: uchar\nsizes: 5 4 6\nencoding: raw\n\n" + data, {"\"dimension\""}));
    EXPECT_TRUE(expectError("NRRD0004\ntype: short\nsizes: 5 4 6\ndimension: 3\nencoding: raw\n\n" + data,
                            {"\"endian\""}));
    EXPECT_TRUE(expectError(nrrdHeader("long long", "\n") + data, {"type \"long long\"", "not supported"}));
    EXPECT_TRUE(expectError(nrrdHeader("block", "\n") + data, {"type \"block\"", "not supported"}));
    EXPECT_TRUE(expectError(nrrdHeader("uchar", "\n", "bzip2") + data, {"encoding \"bzip2\"", "not supported"}));
    EXPECT_TRUE(expectError(nrrdHeader("uchar", "\n", "hex") + data, {"encoding \"hex\"", "not supported"}));
    EXPECT_TRUE(expectError(nrrdHeader("uchar", "\n", "raw", "middle") + data, {"endian \"middle\""}));
    EXPECT_TRUE(expectError("NRRD0004\ntype: uchar\ndimension: 2\nsizes: 20 6\nencoding: raw\n\n" + data,
                            {"dimension is 2", "only 3D"}));
    EXPECT_TRUE(expectError("NRRD0004\ntype: uchar\ndimension: 5\nsizes: 1 5 4 6 1\nencoding: raw\n\n" + data,
                            {"dimension is 5"}));
    EXPECT_TRUE(expectError("NRRD0004\ntype: uchar\ndimension: 4\nsizes: 3 5 4 2\nencoding: raw\n\n" + data,
                            {"dimension is 4 with 3 values per grid point"}));
    EXPECT_TRUE(expectError("NRRD0004\ntype: uchar\ndimension: 3\nsizes: 5 4\nencoding: raw\n\n" + data,
                            {"sizes has 2 entries"}));
    EXPECT_TRUE(expectError("NRRD0004\ntype: uchar\ndimension: 3\nsizes: 5 0 6\nencoding: raw\n\n" + data,
                            {"size of axis 1 is 0", "positive"}));
    EXPECT_TRUE(expectError("NRRD0004\ntype: uchar\ndimension: 3\nsizes: 5 4 -6\nencoding: raw\n\n" + data,
                            {"size of axis 2 is -6"}));
    EXPECT_TRUE(expectError("NRRD0004\ntype: uchar\ndimension: 3\nsizes: 5 four 6\nencoding: raw\n\n" + data,
                            {"not integers"}));
    EXPECT_TRUE(expectError("NRRD0004\ntype: uchar\ndimension: 3\nsizes: 1 4 6\nencoding: raw\n\n" + data,
                            {"dimension 0 is 1"}));  // Volume::validate: trilinear needs 2 points per axis
    // Too large: beyond 2^34 grid points, and a product that overflows 64 bits; nothing is allocated.
    EXPECT_TRUE(expectError("NRRD0004\ntype: uchar\ndimension: 3\nsizes: 100000 100000 100000\nencoding: raw\n\n",
                            {"100000x100000x100000 is too large"}));
    EXPECT_TRUE(expectError("NRRD0004\ntype: uchar\ndimension: 3\nsizes: 4000000000 4000000000 4000000000\n"
                            "encoding: raw\n\n",
                            {"too large", "overflows"}));
    EXPECT_TRUE(expectError("NRRD0004\ntype: uchar\ndimension: 3\nsizes: 99999999999999999999 4 6\n"
                            "encoding: raw\n\n",
                            {"not integers"}));
    for (const char* s : {"0.5 0 2", "0.5 -1 2", "0.5 nan 2", "0.5 inf 2"})
        EXPECT_TRUE(expectError("NRRD0004\ntype: uchar\ndimension: 3\nsizes: 5 4 6\nspacings: " + std::string(s) +
                                    "\nencoding: raw\n\n" + data,
                                {"spacing of axis 1"}));
    EXPECT_TRUE(expectError("NRRD0004\ntype: uchar\ndimension: 3\nsizes: 5 4 6\n"
                            "space directions: (1,0,0) (0.5,0.5,0) (0,0,1)\nencoding: raw\n\n" + data,
                            {"not axis-aligned", "axis 1"}));
    EXPECT_TRUE(expectError("NRRD0004\ntype: uchar\ndimension: 3\nsizes: 5 4 6\n"
                            "space directions: (1,0,0) (0,1,0) (0,0,-1)\nencoding: raw\n\n" + data,
                            {"space direction of axis 2", "positive"}));
    EXPECT_TRUE(expectError("NRRD0004\ntype: uchar\ndimension: 3\nsizes: 5 4 6\n"
                            "space directions: (1,0,0) (0,1) (0,0,1)\nencoding: raw\n\n" + data,
                            {"not a vector"}));
    EXPECT_TRUE(expectError("NRRD0004\ntype: uchar\ndimension: 3\nsizes: 5 4 6\n"
                            "space origin: (0,nan,0)\nencoding: raw\n\n" + data,
                            {"space origin"}));
    EXPECT_TRUE(expectError("NRRD0004\ntype: uchar\ndimension: 3\nsizes: 5 4 6\nspace dimension: 2\n"
                            "encoding: raw\n\n" + data,
                            {"space dimension"}));
    EXPECT_TRUE(expectError("NRRD0004\ntype: uchar\ndimension: 3\nsizes: 5 4 6\nencoding: raw\nno colon here\n\n" + data,
                            {"field: value", "no colon here"}));
    EXPECT_TRUE(expectError("NRRD0004\ntype: uchar\ndimension: 3\nsizes: 5 4 6\nencoding: raw\n", {"no data file"}));
    EXPECT_TRUE(expectError(nrrdHeader("uchar", "data file: f%s.raw 1 6 1\n"), {"data file format"}));
    EXPECT_TRUE(expectError(nrrdHeader("uchar", "data file: f%d.raw 1 6 0\n"), {"data file"}));
    EXPECT_TRUE(expectError(nrrdHeader("uchar", "data file: f%d.raw -9223372036854775808 9223372036854775807 1\n"),
                            {"data file"}));
    EXPECT_TRUE(expectError(nrrdHeader("uchar", "data file: f%d.raw 1 100000000 1\n"), {"too many files"}));
    EXPECT_TRUE(expectError(nrrdHeader("uchar", "data file: f%d.raw 1 7 1\n"), {"do not split evenly"}));
    // 2^20 names of 100 characters: expanded as they are read, no longer all before any check (the
    // header alone took 20 s under ASan; found by fuzz_nrrd_detached, fuzz/regressions/nrrd_detached).
    EXPECT_TRUE(expectError(nrrdHeader("uchar", "data file: f%099d.raw 1 1048576 1\n"), {"do not split evenly"}));
    EXPECT_TRUE(expectError(nrrdHeader("uchar", "data file: LIST\n"), {"LIST names no files"}));
    EXPECT_TRUE(expectError(nrrdHeader("uchar", "data file: a b\n"), {"data file"}));
}

TEST(VolumeIo, NrrdDataTooShortSaysBothSizes)
{
    TempDir dir;
    const std::string data = encode(ScalarType::Int16, testValues(ScalarType::Int16), Endian::Little);
    writeFile(dir / "a.nrrd", nrrdHeader("short", "\n") + data.substr(0, 200));
    EXPECT_TRUE(throwsInputError([&] { clvr::readNrrd(dir / "a.nrrd"); },
                                 {(dir / "a.nrrd").string(), "header says 5x4x6 x 2 bytes = 240 bytes, file has 200 bytes"}));
    writeFile(dir / "d.raw", data.substr(0, 239));
    writeFile(dir / "d.nhdr", nrrdHeader("short", "data file: d.raw\n"));
    EXPECT_TRUE(throwsInputError([&] { clvr::readNrrd(dir / "d.nhdr"); },
                                 {"d.raw", "header says 5x4x6 x 2 bytes = 240 bytes, file has 239 bytes"}));
    for (int k = 1; k <= 6; ++k)
        writeFile(dir / ("q." + std::to_string(k)), data.substr(0, k == 4 ? 30 : 40));
    writeFile(dir / "q.nhdr", nrrdHeader("short", "data file: q.%d 1 6 1\n"));
    EXPECT_TRUE(throwsInputError([&] { clvr::readNrrd(dir / "q.nhdr"); },
                                 {"q.4", "5x4x6 x 2 bytes in 6 files = 40 bytes per file, file has 30 bytes"}));
    writeFile(dir / "skip.nhdr", nrrdHeader("short", "byte skip: 100\ndata file: d.raw\n"));
    EXPECT_TRUE(throwsInputError([&] { clvr::readNrrd(dir / "skip.nhdr"); }, {"d.raw", "file has 139 bytes"}));
    writeFile(dir / "tail.nhdr", nrrdHeader("short", "byte skip: -1\ndata file: d.raw\n"));
    EXPECT_TRUE(throwsInputError([&] { clvr::readNrrd(dir / "tail.nhdr"); }, {"d.raw", "240 bytes"}));
    writeFile(dir / "lines.nhdr", nrrdHeader("short", "line skip: 3\ndata file: d.raw\n"));
    writeFile(dir / "d.raw", "one line\n");
    EXPECT_TRUE(throwsInputError([&] { clvr::readNrrd(dir / "lines.nhdr"); }, {"d.raw", "line skip 3"}));
    writeFile(dir / "t.nrrd", nrrdHeader("double", "\n", "ascii") + "1 2 3\n4 5\n");
    EXPECT_TRUE(throwsInputError([&] { clvr::readNrrd(dir / "t.nrrd"); }, {"t.nrrd", "120 values, file has 5"}));
    writeFile(dir / "w.nrrd", nrrdHeader("double", "\n", "ascii") + "1 2 x3\n");
    EXPECT_TRUE(throwsInputError([&] { clvr::readNrrd(dir / "w.nrrd"); }, {"w.nrrd", "\"x3\", not a number"}));
    writeFile(dir / "l.nrrd", nrrdHeader("double", "\n", "ascii") + "1 2 " + std::string(70, '1') + "\n");
    EXPECT_TRUE(throwsInputError([&] { clvr::readNrrd(dir / "l.nrrd"); }, {"l.nrrd", "value 2", "not a number"}));
}

// A header that claims a huge volume over a few bytes of data is a short file, said before any memory
// bound (issue 15: it was reported as needing 30517 MiB).
TEST(VolumeIo, NrrdHugeHeaderOverAShortFileIsAShortFile)
{
    TempDir dir;
    const std::string header = "NRRD0004\ntype: float\ndimension: 3\nsizes: 2000 2000 2000\nendian: little\nencoding: ";
    writeFile(dir / "raw.nrrd", header + "raw\n\n" + std::string(64, '\0'));
    EXPECT_TRUE(throwsInputError([&] { clvr::readNrrd(dir / "raw.nrrd"); },
                                 {"raw.nrrd", "= 32000000000 bytes, file has 64 bytes"}));
    writeFile(dir / "gz.nrrd", header + "gzip\n\n" + std::string(64, '\0'));
    EXPECT_TRUE(throwsInputError([&] { clvr::readNrrd(dir / "gz.nrrd"); },
                                 {"gz.nrrd", "gzip data is truncated: header says", "64 compressed bytes cannot hold that many"}));
}

TEST(VolumeIo, NrrdGzipTruncatedOrCorrupt)
{
    TempDir dir;
    const std::string data = encode(ScalarType::Float32, testValues(ScalarType::Float32), Endian::Little);
    const std::string z = gzip(data);
    const std::string header = nrrdHeader("float", "\n", "gzip");
    writeFile(dir / "trunc.nrrd", header + z.substr(0, z.size() / 2));
    EXPECT_TRUE(throwsInputError([&] { clvr::readNrrd(dir / "trunc.nrrd"); }, {"trunc.nrrd", "gzip data is truncated"}));
    writeFile(dir / "empty.nrrd", header);
    EXPECT_TRUE(throwsInputError([&] { clvr::readNrrd(dir / "empty.nrrd"); }, {"empty.nrrd", "truncated"}));
    std::string bad = z;
    for (std::size_t i = 12; i < 40 && i < bad.size(); ++i)
        bad[i] = static_cast<char>(bad[i] ^ 0x5a);
    writeFile(dir / "corrupt.nrrd", header + bad);
    EXPECT_TRUE(throwsInputError([&] { clvr::readNrrd(dir / "corrupt.nrrd"); }, {"corrupt.nrrd", "gzip data"}));
    writeFile(dir / "notgz.nrrd", header + data);  // raw bytes where gzip belongs
    EXPECT_TRUE(throwsInputError([&] { clvr::readNrrd(dir / "notgz.nrrd"); }, {"notgz.nrrd", "gzip"}));
    // Fewer samples than the header says, complete stream.
    writeFile(dir / "short.nrrd", header + gzip(data.substr(0, 400)));
    EXPECT_TRUE(throwsInputError([&] { clvr::readNrrd(dir / "short.nrrd"); },
                                 {"short.nrrd", "decompresses to 400 bytes", "480 bytes"}));
    // A tiny file claiming a large volume is refused before anything that size is allocated
    // (512^3 floats = 512 MiB fits this machine's memory, so the gzip cap is what refuses it)...
    writeFile(dir / "huge.nrrd", "NRRD0004\ntype: float\ndimension: 3\nsizes: 512 512 512\nendian: little\n"
                                 "encoding: gzip\n\n" + z);
    EXPECT_TRUE(throwsInputError([&] { clvr::readNrrd(dir / "huge.nrrd"); }, {"huge.nrrd", "truncated"}));
    // ... and one larger than half the machine's memory too: the short data is said first (the host-memory
    // bound applies once the data could be there; the generator below reaches it).
    writeFile(dir / "huger.nrrd", "NRRD0004\ntype: float\ndimension: 3\nsizes: 4096 2048 1024\nendian: little\n"
                                  "encoding: gzip\n\n" + z);
    EXPECT_TRUE(throwsInputError([&] { clvr::readNrrd(dir / "huger.nrrd"); }, {"huger.nrrd", "truncated"}));
    // The generator refuses a grid over half of this machine's memory before allocating it. Sized from the
    // machine: 4096x2048x1024 floats (32 GiB) fit half of a 128 GiB machine, where it was generated for
    // 100 s (2026-12-04) instead of refused. Up to the 2^34-point cap (64 GiB) the memory bound says it;
    // on machines with more memory than twice that, the cap.
    const std::uint64_t physical =
        static_cast<std::uint64_t>(::sysconf(_SC_PHYS_PAGES)) * static_cast<std::uint64_t>(::sysconf(_SC_PAGE_SIZE));
    int depth = 2;  // 4096 x 4096 x depth grid points, the fewest over half the memory
    while (depth < 1024 && std::uint64_t(4096) * 4096 * depth * sizeof(float) <= physical / 2)
        depth *= 2;
    if (std::uint64_t(4096) * 4096 * depth * sizeof(float) > physical / 2) {
        EXPECT_TRUE(throwsInputError([&] { clvr::generateVolume("sphere", {4096, 4096, depth}); },
                                     {"generator sphere", "MiB of memory"}));
    }
    EXPECT_TRUE(throwsInputError([&] { clvr::generateVolume("sphere", {4096, 4096, 1025}); },
                                 {"generator sphere", "more than 2^34 grid points"}));
}

TEST(VolumeIo, NanAndInfinityInFloatData)
{
    TempDir dir;
    std::vector<double> values = testValues(ScalarType::Float32);
    values[3 + 5 * (2 + 4 * 1)] = std::numeric_limits<double>::quiet_NaN();  // grid point (3,2,1)
    writeFile(dir / "nan.nrrd", nrrdHeader("float", "\n") + encode(ScalarType::Float32, values, Endian::Little));
    EXPECT_TRUE(throwsInputError([&] { clvr::readNrrd(dir / "nan.nrrd"); }, {"nan.nrrd", "(3,2,1) is NaN"}));
    writeFile(dir / "nan.raw", encode(ScalarType::Float64, values, Endian::Big));
    EXPECT_TRUE(throwsInputError(
        [&] {
            clvr::loadVolume({{"file", "nan.raw"}, {"dims", {5, 4, 6}}, {"type", "float64"}, {"endian", "big"}},
                             dir.path());
        },
        {"nan.raw", "NaN"}));
    writeFile(dir / "nan.vtk", vtkHeader("BINARY", "float") + encode(ScalarType::Float32, values, Endian::Big));
    EXPECT_TRUE(throwsInputError([&] { clvr::readVtkStructuredPoints(dir / "nan.vtk"); }, {"nan.vtk", "NaN"}));
    writeFile(dir / "nan2.nrrd", nrrdHeader("float", "\n", "ascii") + "1 2 nan 4\n");
    EXPECT_TRUE(throwsInputError([&] { clvr::readNrrd(dir / "nan2.nrrd"); }, {"nan2.nrrd", "NaN"}));
    values = testValues(ScalarType::Float64);
    values[0] = 1e300;  // finite double, infinite as float
    writeFile(dir / "big.nrrd", nrrdHeader("double", "\n") + encode(ScalarType::Float64, values, Endian::Little));
    EXPECT_TRUE(throwsInputError([&] { clvr::readNrrd(dir / "big.nrrd"); }, {"big.nrrd", "(0,0,0)", "too large"}));
}

TEST(VolumeIo, RawSizeMismatch)
{
    TempDir dir;
    writeFile(dir / "v.raw", std::string(239, '\0'));
    const nlohmann::json spec = {{"file", "v.raw"}, {"dims", {5, 4, 6}}, {"type", "uint16"}, {"endian", "little"}};
    EXPECT_TRUE(throwsInputError([&] { clvr::loadVolume(spec, dir.path()); },
                                 {"v.raw", "layout says 5x4x6 x 2 bytes = 240 bytes, file has 239 bytes"}));
    writeFile(dir / "v.raw", std::string(250, '\0'));
    EXPECT_TRUE(throwsInputError([&] { clvr::loadVolume(spec, dir.path()); }, {"v.raw", "file has 250 bytes"}));
    nlohmann::json withHeader = spec;
    withHeader["header_bytes"] = 11;
    EXPECT_TRUE(throwsInputError([&] { clvr::loadVolume(withHeader, dir.path()); },
                                 {"v.raw", "+ 11 header bytes = 251 bytes, file has 250 bytes"}));
    clvr::RawLayout layout;
    layout.dims = {100000, 100000, 100000};
    EXPECT_TRUE(throwsInputError([&] { clvr::readRaw(dir / "v.raw", layout); }, {"v.raw", "too large"}));
    layout.dims = {5, 4, 6};
    layout.spacing = {1, 0, 1};
    EXPECT_TRUE(throwsInputError([&] { clvr::readRaw(dir / "v.raw", layout); }, {"v.raw", "spacing of axis 1"}));
    layout.spacing = {1, 1, 1};
    layout.headerBytes = std::numeric_limits<std::uint64_t>::max() - 100;  // would wrap around when added
    EXPECT_TRUE(throwsInputError([&] { clvr::readRaw(dir / "v.raw", layout); }, {"v.raw", "file has 250 bytes"}));
}

TEST(VolumeIo, VtkErrors)
{
    TempDir dir;
    const fs::path p = dir / "bad.vtk";
    const std::string data = encode(ScalarType::Int16, testValues(ScalarType::Int16), Endian::Big);
    auto expectError = [&](const std::string& contents, std::vector<std::string> pieces) {
        writeFile(p, contents);
        pieces.push_back(p.string());
        return throwsInputError([&] { clvr::readVtkStructuredPoints(p); }, pieces);
    };
    EXPECT_TRUE(expectError("hello\n", {"not a VTK legacy file"}));
    EXPECT_TRUE(expectError("", {"not a VTK legacy file"}));
    EXPECT_TRUE(expectError(vtkHeader("BINARY", "short", "UNSTRUCTURED_GRID") + data,
                            {"DATASET is \"UNSTRUCTURED_GRID\"", "only STRUCTURED_POINTS"}));
    EXPECT_TRUE(expectError(vtkHeader("BINARY", "short", "RECTILINEAR_GRID") + data, {"RECTILINEAR_GRID"}));
    EXPECT_TRUE(expectError(vtkHeader("XML", "short") + data, {"ASCII or BINARY"}));
    EXPECT_TRUE(expectError(vtkHeader("BINARY", "short") + data.substr(0, 100),
                            {"truncated", "5x4x6 x 2 bytes = 240 bytes, file has 100 bytes"}));
    EXPECT_TRUE(expectError(vtkHeader("ASCII", "short") + "1 2 3 4\n", {"truncated", "120 values, file has 4"}));
    EXPECT_TRUE(expectError(vtkHeader("ASCII", "short") + "1 2 three 4\n", {"\"three\", not a number"}));
    EXPECT_TRUE(expectError(vtkHeader("BINARY", "bit") + data, {"type \"bit\"", "not supported"}));
    std::string s = vtkHeader("BINARY", "short");
    EXPECT_TRUE(expectError(s.replace(s.find("POINT_DATA 120"), 14, "POINT_DATA 121") + data,
                            {"POINT_DATA 121 does not match DIMENSIONS 5x4x6 = 120"}));
    s = vtkHeader("BINARY", "short");
    EXPECT_TRUE(expectError(s.replace(s.find("DIMENSIONS 5 4 6"), 16, "DIMENSIONS 5 0 6") + data, {"size of axis 1 is 0"}));
    s = vtkHeader("BINARY", "short");
    EXPECT_TRUE(expectError(s.replace(s.find("SPACING 0.5"), 11, "SPACING -.5") + data, {"spacing of axis 0"}));
    s = vtkHeader("BINARY", "short");
    EXPECT_TRUE(expectError(s.replace(s.find(" 1\nLOOKUP"), 2, " 3") + data, {"\"3\" components"}));
    s = vtkHeader("BINARY", "short");
    EXPECT_TRUE(expectError(s.replace(s.find("SCALARS"), 7, "VECTORS") + data, {"expected SCALARS", "VECTORS"}));
    EXPECT_TRUE(expectError("# vtk DataFile Version 3.0\nt\nASCII\nDATASET STRUCTURED_POINTS\nDIMENSIONS 5 4 6\n"
                            "CELL_DATA 60\nSCALARS s float\n",
                            {"CELL_DATA"}));
    EXPECT_TRUE(expectError("# vtk DataFile Version 3.0\nt\nASCII\nDATASET STRUCTURED_POINTS\nDIMENSIONS 5 4 6\n",
                            {"no POINT_DATA"}));
    EXPECT_TRUE(expectError("# vtk DataFile Version 3.0\nt\nASCII\nDATASET STRUCTURED_POINTS\nDIMENSIONS 100000 100000 "
                            "100000\nPOINT_DATA 1\nSCALARS s float\n1\n",
                            {"too large"}));
}

// Arbitrary bytes after a valid magic line never crash a reader (run under the sanitizer build).
TEST(VolumeIo, GarbageNeverCrashes)
{
    TempDir dir;
    clvr::test::Rng rng(20261122);
    const int nrrdHeaderSize = static_cast<int>(nrrdHeader("short", "\n").size());
    const int vtkHeaderSize = static_cast<int>(vtkHeader("BINARY", "short").size());
    const std::string validNrrd = nrrdHeader("short", "\n") + std::string(240, '\1');
    const std::string validVtk = vtkHeader("BINARY", "short") + std::string(240, '\1');
    const char digits[] = "0123456789-.9e";
    for (int trial = 0; trial < 600; ++trial) {
        std::string nrrd = validNrrd, vtk = validVtk;
        // Odd trials change header bytes only, mostly into digits, where the sizes and spacings live.
        const bool header = trial % 2 == 1;
        for (int m = 0; m < 1 + trial % 5; ++m) {
            const char c = header && m % 2 == 0 ? digits[rng.integer(0, 13)] : static_cast<char>(rng.integer(0, 255));
            nrrd[static_cast<std::size_t>(
                rng.integer(9, header ? nrrdHeaderSize - 1 : static_cast<int>(nrrd.size()) - 1))] = c;
            vtk[static_cast<std::size_t>(
                rng.integer(27, header ? vtkHeaderSize - 1 : static_cast<int>(vtk.size()) - 1))] = c;
        }
        if (trial % 7 == 0) {
            nrrd.resize(static_cast<std::size_t>(rng.integer(0, static_cast<int>(nrrd.size()))));
            vtk.resize(static_cast<std::size_t>(rng.integer(0, static_cast<int>(vtk.size()))));
        }
        writeFile(dir / "g.nrrd", nrrd);
        writeFile(dir / "g.vtk", vtk);
        try {
            clvr::readNrrd(dir / "g.nrrd");
        } catch (const clvr::InputError&) {
        }
        try {
            clvr::readVtkStructuredPoints(dir / "g.vtk");
        } catch (const clvr::InputError&) {
        }
    }
}

}  // namespace

namespace clvr {
namespace {

// The host-memory guards say what needs how much, before an allocation the OOM killer would end.
TEST(HostMemory, MoreThanHalfOfTheMachineIsAnInputErrorNamingWhat)
{
    EXPECT_NO_THROW(checkHostMemory("small", 1u << 20));
    EXPECT_NO_THROW(checkHostMemoryForVoxels("small.nrrd", 1u << 20));
    try {
        checkHostMemory("engine.nrrd: cubefan's octree", std::uint64_t(1) << 62);
        ADD_FAILURE() << "no error";
    } catch (const InputError& e) {
        const std::string m = e.what();
        EXPECT_EQ(m.rfind("engine.nrrd: cubefan's octree needs ", 0), 0u) << m;
        EXPECT_NE(m.find("more than half of this machine's"), std::string::npos) << m;
    }
    EXPECT_THROW(checkHostMemoryForVoxels("huge.nrrd", std::uint64_t(1) << 60), InputError);
}

// VoxelBytes: page-aligned (what lets a device buffer use it in place), zero-filled, copied by value.
TEST(VoxelBytes, AlignedZeroFilledAndCopiedByValue)
{
    VoxelBytes a(5000);
    ASSERT_EQ(a.size(), 5000u);
    EXPECT_EQ(reinterpret_cast<std::uintptr_t>(a.data()) % 4096, 0u);
    EXPECT_TRUE(std::all_of(a.data(), a.data() + a.size(), [](std::uint8_t b) { return b == 0; }));
    a[4999] = 9;
    VoxelBytes b = a;  // a copy: its own block
    EXPECT_NE(b.data(), a.data());
    EXPECT_TRUE(b == a);
    b[0] = 1;
    EXPECT_EQ(a[0], 0) << "the copy shares nothing";
    EXPECT_FALSE(b == a);
    const std::uint8_t* block = b.data();
    VoxelBytes c = std::move(b);  // a move: the same block
    EXPECT_EQ(c.data(), block);
    EXPECT_TRUE(b.empty());
    c.resize(3);
    EXPECT_EQ(c.size(), 3u);
    EXPECT_EQ(c[0], 1);
    c.resize(6);
    EXPECT_EQ(c[0], 1);
    EXPECT_EQ(c[5], 0);
    std::weak_ptr<const void> owner = c.owner();
    c = VoxelBytes();
    EXPECT_TRUE(owner.expired());
}

}  // namespace
}  // namespace clvr
