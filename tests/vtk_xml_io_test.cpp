// tests/vtk_xml_io_test.cpp — the formats VTK's readers bring (host/io/vtk_xml_io.h) and numpy's .npy
// (host/io/volume_io.h): files written here by VTK's own writers (every encoding and compressor of .vti,
// pieces of .pvti and .pvtu, MetaImage .mhd and .mha) and by hand (.npy), read back value for value
// against the arrays they were written from; regions read from .vti and .pvti equal the same region cut
// from the whole; .vtu cells split as the legacy reader splits them; a volume from .vti renders the
// bits of the same volume from its generator; every bad input is one InputError naming the file.
#include "host/io/cell_split.h"
#include "host/io/generators.h"
#include "host/io/mesh_io.h"
#include "host/io/volume_io.h"
#include "host/io/vtk_xml_io.h"
#include "host/model/scene.h"
#include "host/runtime/errors.h"
#include "tests/support/test_util.h"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <bit>
#include <cstring>
#include <filesystem>
#include <fstream>

#ifdef CLVR_HAVE_VTK
#include <vtkCell.h>
#include <vtkCellArray.h>
#include <vtkIdList.h>
#include <vtkFloatArray.h>
#include <vtkImageData.h>
#include <vtkMetaImageWriter.h>
#include <vtkNew.h>
#include <vtkPointData.h>
#include <vtkCellData.h>
#include <vtkPoints.h>
#include <vtkUnsignedShortArray.h>
#include <vtkUnstructuredGrid.h>
#include <vtkUnstructuredGridWriter.h>
#include <vtkXMLImageDataWriter.h>
#include <vtkXMLPImageDataWriter.h>
#include <vtkXMLPUnstructuredGridWriter.h>
#include <vtkXMLUnstructuredGridWriter.h>
#endif

namespace fs = std::filesystem;

namespace clvr {
namespace {

using test::TempDir;

// The value written at grid point (i, j, k): distinct everywhere, exact in uint16 and float.
double valueAt(int i, int j, int k) { return 1000.0 + i + 17.0 * j + 301.0 * k; }

void expectVolumeValues(const Volume& v, const glm::ivec3& dims, const glm::ivec3& offset = glm::ivec3(0))
{
    ASSERT_EQ(v.dims, dims);
    ASSERT_NO_THROW(v.validate());  // one storage, of the right size
    for (int k = 0; k < dims.z; ++k)
        for (int j = 0; j < dims.y; ++j)
            for (int i = 0; i < dims.x; ++i)
                ASSERT_EQ(v.at(i, j, k), valueAt(offset.x + i, offset.y + j, offset.z + k)) << i << " " << j << " " << k;
}

// ---------------------------------------------------------------------------------------------------
// numpy .npy, written byte for byte as numpy.save does.

std::string npyFile(const std::string& descr, bool fortran, const glm::ivec3& shape, const std::string& data, int version = 1)
{
    std::string dict = "{'descr': '" + descr + "', 'fortran_order': " + (fortran ? "True" : "False") + ", 'shape': (" +
                       std::to_string(shape.x) + ", " + std::to_string(shape.y) + ", " + std::to_string(shape.z) + "), }";
    const std::size_t pre = version == 1 ? 10 : 12;
    while ((pre + dict.size() + 1) % 64 != 0)
        dict += ' ';
    dict += '\n';
    std::string out = "\x93NUMPY";
    out += static_cast<char>(version);
    out += '\0';
    const std::size_t n = dict.size();
    out += static_cast<char>(n & 0xff);
    out += static_cast<char>((n >> 8) & 0xff);
    if (version > 1) {
        out += '\0';
        out += '\0';
    }
    return out + dict + data;
}

// valueAt over `dims` as `T` in the array order numpy would write: C order (the last index fastest) of an
// array indexed [x, y, z], or Fortran order (x fastest); bytes swapped for `bigEndian`.
template <typename T>
std::string npyData(const glm::ivec3& dims, bool fortran, bool bigEndian)
{
    std::string out;
    const auto put = [&](int i, int j, int k) {
        T v = static_cast<T>(valueAt(i, j, k));
        char b[sizeof(T)];
        std::memcpy(b, &v, sizeof(T));
        if (bigEndian)
            std::reverse(b, b + sizeof(T));
        out.append(b, sizeof(T));
    };
    if (fortran) {
        for (int k = 0; k < dims.z; ++k)
            for (int j = 0; j < dims.y; ++j)
                for (int i = 0; i < dims.x; ++i)
                    put(i, j, k);
    } else {
        for (int i = 0; i < dims.x; ++i)
            for (int j = 0; j < dims.y; ++j)
                for (int k = 0; k < dims.z; ++k)
                    put(i, j, k);
    }
    return out;
}

TEST(Npy, EveryOrderTypeAndEndianReadsIndexedXyz)
{
    TempDir dir;
    const glm::ivec3 dims(5, 4, 3);
    struct Case {
        std::string descr;
        std::function<std::string(bool, bool)> data;
    };
    const std::vector<Case> cases = {
        {"u2", [&](bool f, bool b) { return npyData<std::uint16_t>(dims, f, b); }},
        {"i2", [&](bool f, bool b) { return npyData<std::int16_t>(dims, f, b); }},
        {"i4", [&](bool f, bool b) { return npyData<std::int32_t>(dims, f, b); }},
        {"u4", [&](bool f, bool b) { return npyData<std::uint32_t>(dims, f, b); }},
        {"f4", [&](bool f, bool b) { return npyData<float>(dims, f, b); }},
        {"f8", [&](bool f, bool b) { return npyData<double>(dims, f, b); }},
    };
    for (const Case& c : cases)
        for (bool fortran : {false, true})
            for (bool big : {false, true})
                for (int version : {1, 2}) {
                    SCOPED_TRACE(c.descr + (fortran ? " F" : " C") + (big ? " big" : " little") + " v" + std::to_string(version));
                    const fs::path path = dir / "a.npy";
                    test::writeFile(path, npyFile((big ? ">" : "<") + c.descr, fortran, dims, c.data(fortran, big), version));
                    const Volume v = readNpy(path, {0.5, 1.0, 2.0}, {1.0, 2.0, 3.0});
                    expectVolumeValues(v, dims);
                    EXPECT_EQ(v.spacing, glm::dvec3(0.5, 1.0, 2.0));
                    EXPECT_EQ(v.origin, glm::dvec3(1.0, 2.0, 3.0));
                }
    // uint8 (values mod 256 do not fit valueAt: check the layout with small values instead).
    std::string bytes;
    for (int i = 0; i < 2; ++i)
        for (int j = 0; j < 3; ++j)
            for (int k = 0; k < 4; ++k)
                bytes += static_cast<char>(i + 2 * j + 6 * k);
    test::writeFile(dir / "b.npy", npyFile("|u1", false, {2, 3, 4}, bytes));
    const Volume b = readNpy(dir / "b.npy");
    for (int k = 0; k < 4; ++k)
        for (int j = 0; j < 3; ++j)
            for (int i = 0; i < 2; ++i)
                EXPECT_EQ(b.at(i, j, k), i + 2 * j + 6 * k);
}

TEST(Npy, SceneVolumeTakesSpacingAndOrigin)
{
    TempDir dir;
    const glm::ivec3 dims(3, 3, 2);
    test::writeFile(dir / "v.npy", npyFile("<f4", false, dims, npyData<float>(dims, false, false)));
    const Volume v = loadVolume(nlohmann::json::parse(R"({"file": "v.npy", "spacing": [2, 2, 3], "origin": [-1, 0, 0]})"),
                                dir.path());
    expectVolumeValues(v, dims);
    EXPECT_EQ(v.spacing, glm::dvec3(2, 2, 3));
    EXPECT_EQ(v.origin, glm::dvec3(-1, 0, 0));
    EXPECT_THROW(loadVolume(nlohmann::json::parse(R"({"file": "v.npy", "dims": [3, 3, 2]})"), dir.path()), InputError);
    EXPECT_THROW(loadVolume(nlohmann::json::parse(R"({"file": "v.npy", "spacing": [0, 1, 1]})"), dir.path()), InputError);
}

TEST(Npy, BadFilesAreOneInputErrorNamingTheFile)
{
    TempDir dir;
    const glm::ivec3 dims(3, 3, 2);
    const std::string good = npyFile("<u2", false, dims, npyData<std::uint16_t>(dims, false, false));
    const std::vector<std::pair<std::string, std::string>> bad = {
        {"empty", ""},
        {"no magic", "NUMPY" + good.substr(6)},
        {"version 9", good.substr(0, 6) + "\x09" + good.substr(7)},
        {"truncated data", good.substr(0, good.size() - 1)},
        {"trailing data", good + "xx"},
        {"header past the end", good.substr(0, 20)},
        {"complex dtype", npyFile("<c8", false, dims, npyData<std::uint16_t>(dims, false, false))},
        {"structured dtype", npyFile("[('a', '<u2')]", false, dims, "")},
        {"2-D", [] {
             std::string f = npyFile("<u2", false, {3, 3, 1}, std::string(18, '\0'));
             const std::size_t at = f.find("(3, 3, 1)");
             return f.replace(at, 9, "(3, 3)   ");
         }()},
        {"negative shape", [&] {
             std::string f = good;
             return f.replace(f.find("(3, 3, 2)"), 9, "(3, -3, 2)").substr(0, f.size());
         }()},
        {"huge shape", [&] {
             std::string f = good;
             return f.replace(f.find("(3, 3, 2)"), 9, "(99999999, 99999999, 99999999)");
         }()},
        {"NaN", npyFile("<f4", true, {2, 2, 2}, [] {
             std::string d = npyData<float>({2, 2, 2}, true, false);
             const float nan = std::numeric_limits<float>::quiet_NaN();
             std::memcpy(d.data() + 8, &nan, 4);
             return d;
         }())},
    };
    for (const auto& [name, bytes] : bad) {
        SCOPED_TRACE(name);
        const fs::path path = dir / "bad.npy";
        test::writeFile(path, bytes);
        EXPECT_TRUE(test::throwsInputError([&] { readNpy(path); }, {path.string()}));
    }
    EXPECT_THROW(readNpy(dir / "missing.npy"), InputError);
}

// ---------------------------------------------------------------------------------------------------
// VTK's formats.

#ifndef CLVR_HAVE_VTK

TEST(VtkXmlIo, WithoutVtkEachFormatIsOneClearError)
{
    TempDir dir;
    for (const char* name : {"a.vti", "a.pvti", "a.mhd", "a.mha", "a.vtu", "a.pvtu"}) {
        test::writeFile(dir / name, "x");
        EXPECT_TRUE(test::throwsInputError(
            [&] {
                if (std::string(name).find("vtu") != std::string::npos)
                    readVtkXmlUnstructured(dir / name);
                else
                    readVtkImage(dir / name);
            },
            {"built without VTK"}))
            << name;
    }
}

#else

// A grid with extent (2, 1, 0) .. (2, 1, 0) + dims - 1, uint16 "density" = valueAt of the point's index
// from the extent's start, and a float "other" (its negative). `piece`, when given, is the part of that
// grid to make (an extent inside it): the same values at the same points.
vtkNew<vtkImageData> makeImage(const glm::ivec3& dims = {7, 5, 4}, const int* piece = nullptr)
{
    const int whole[6] = {2, 2 + dims.x - 1, 1, 1 + dims.y - 1, 0, dims.z - 1};
    const int* e = piece ? piece : whole;
    vtkNew<vtkImageData> image;
    image->SetExtent(e[0], e[1], e[2], e[3], e[4], e[5]);
    image->SetSpacing(0.5, 0.25, 2.0);
    image->SetOrigin(-1.0, 0.0, 3.0);
    vtkNew<vtkUnsignedShortArray> density;
    density->SetName("density");
    vtkNew<vtkFloatArray> other;
    other->SetName("other");
    for (int k = e[4]; k <= e[5]; ++k)
        for (int j = e[2]; j <= e[3]; ++j)
            for (int i = e[0]; i <= e[1]; ++i) {
                density->InsertNextValue(static_cast<unsigned short>(valueAt(i - 2, j - 1, k)));
                other->InsertNextValue(static_cast<float>(-valueAt(i - 2, j - 1, k)));
            }
    image->GetPointData()->AddArray(other);  // first, so that "the active scalars" is not "the first"
    image->GetPointData()->SetScalars(density);
    return image;
}

void expectImageGeometry(const Volume& v)
{
    EXPECT_EQ(v.spacing, glm::dvec3(0.5, 0.25, 2.0));
    // VTK's origin is that of index (0, 0, 0); the extent starts at (2, 1, 0).
    EXPECT_EQ(v.origin, glm::dvec3(-1.0 + 2 * 0.5, 0.0 + 1 * 0.25, 3.0));
}

TEST(VtkXmlIo, VtiEveryEncodingAndCompressor)
{
    TempDir dir;
    vtkNew<vtkImageData> image = makeImage();
    struct Mode {
        const char* name;
        int mode;
        bool encode;
        int compressor;
    };
    const Mode modes[] = {
        {"ascii", vtkXMLWriter::Ascii, false, vtkXMLWriter::NONE},
        {"binary", vtkXMLWriter::Binary, true, vtkXMLWriter::NONE},
        {"binary zlib", vtkXMLWriter::Binary, true, vtkXMLWriter::ZLIB},
        {"appended raw", vtkXMLWriter::Appended, false, vtkXMLWriter::NONE},
        {"appended base64 zlib", vtkXMLWriter::Appended, true, vtkXMLWriter::ZLIB},
        {"appended raw zlib", vtkXMLWriter::Appended, false, vtkXMLWriter::ZLIB},
        {"appended raw lz4", vtkXMLWriter::Appended, false, vtkXMLWriter::LZ4},
        {"appended raw lzma", vtkXMLWriter::Appended, false, vtkXMLWriter::LZMA},
    };
    for (const Mode& m : modes) {
        SCOPED_TRACE(m.name);
        const fs::path path = dir / "a.vti";
        vtkNew<vtkXMLImageDataWriter> writer;
        writer->SetInputData(image);
        writer->SetFileName(path.c_str());
        writer->SetDataMode(m.mode);
        writer->SetEncodeAppendedData(m.encode);
        writer->SetCompressorType(m.compressor);
        writer->SetBlockSize(64);  // several compressed blocks
        ASSERT_EQ(writer->Write(), 1);
        const Volume v = readVtkImage(path);
        expectVolumeValues(v, {7, 5, 4});
        expectImageGeometry(v);
        EXPECT_EQ(v.voxelType, VoxelType::UInt16);  // kept in its own type: no float copy
        EXPECT_EQ(v.valueBytes(), v.voxelCount() * 2);
        // By name: the float array, negated values.
        const Volume other = readVtkImage(path, "other");
        EXPECT_EQ(other.at(3, 2, 1), -valueAt(3, 2, 1));
        EXPECT_FALSE(other.native());
        // A region: the same values as the same points of the whole.
        const Volume region = readVtkImage(path, "", GridRegion{{1, 2, 1}, {5, 4, 2}});
        expectVolumeValues(region, {5, 3, 2}, {1, 2, 1});
        EXPECT_EQ(region.origin, v.origin + glm::dvec3(1, 2, 1) * v.spacing);
    }
}

TEST(VtkXmlIo, PvtiPiecesWholeAndRegions)
{
    // A 9x6x8 grid (extent 2..10, 1..6, 0..7) in four pieces, cut at x = 6 and z = 3 (pieces share those
    // layers of points, as VTK's writers cut them), each written by VTK as its own .vti.
    TempDir dir;
    const int pieces[4][6] = {{2, 6, 1, 6, 0, 3}, {6, 10, 1, 6, 0, 3}, {2, 6, 1, 6, 3, 7}, {6, 10, 1, 6, 3, 7}};
    std::string summary = R"(<?xml version="1.0"?>
<VTKFile type="PImageData" version="1.0" byte_order="LittleEndian" header_type="UInt64">
  <PImageData WholeExtent="2 10 1 6 0 7" GhostLevel="0" Origin="-1 0 3" Spacing="0.5 0.25 2">
    <PPointData Scalars="density">
      <PDataArray type="Float32" Name="other"/>
      <PDataArray type="UInt16" Name="density"/>
    </PPointData>
)";
    for (int p = 0; p < 4; ++p) {
        vtkNew<vtkImageData> image = makeImage({9, 6, 8}, pieces[p]);
        vtkNew<vtkXMLImageDataWriter> writer;
        writer->SetInputData(image);
        writer->SetFileName((dir / ("p_" + std::to_string(p) + ".vti")).c_str());
        writer->SetDataModeToAppended();
        writer->SetCompressorTypeToZLib();
        ASSERT_EQ(writer->Write(), 1);
        summary += "    <Piece Extent=\"";
        for (int a = 0; a < 6; ++a)
            summary += std::to_string(pieces[p][a]) + (a < 5 ? " " : "");
        summary += "\" Source=\"p_" + std::to_string(p) + ".vti\"/>\n";
    }
    summary += "  </PImageData>\n</VTKFile>\n";
    test::writeFile(dir / "p.pvti", summary);

    const GridHeader header = readVtkImageHeader(dir / "p.pvti");
    EXPECT_EQ(header.dims, glm::ivec3(9, 6, 8));
    const Volume whole = readVtkImage(dir / "p.pvti");
    expectVolumeValues(whole, {9, 6, 8});
    expectImageGeometry(whole);
    // Regions across piece boundaries and inside one piece.
    for (const GridRegion& r : {GridRegion{{0, 0, 0}, {8, 5, 3}}, GridRegion{{2, 1, 3}, {6, 4, 5}}, GridRegion{{0, 0, 4}, {8, 5, 7}}}) {
        const Volume part = readVtkImage(dir / "p.pvti", "", r);
        expectVolumeValues(part, r.hi - r.lo + 1, r.lo);
    }

    // A region opens only the pieces it meets: without piece 1 (x 6..10, z 0..3) the region x 0..3,
    // z 0..7 still reads, and what needs piece 1 is one error, no half volume.
    fs::remove(dir / "p_1.vti");
    expectVolumeValues(readVtkImage(dir / "p.pvti", "", GridRegion{{0, 0, 0}, {3, 5, 7}}), {4, 6, 8});
    expectVolumeValues(readVtkImage(dir / "p.pvti", "", GridRegion{{0, 0, 4}, {8, 5, 7}}), {9, 6, 4}, {0, 0, 4});
    EXPECT_THROW(readVtkImage(dir / "p.pvti"), InputError);
    EXPECT_THROW(readVtkImage(dir / "p.pvti", "", GridRegion{{5, 0, 0}, {6, 5, 1}}), InputError);

    // clvr copies the pieces itself (VTK's parallel reader trusts the summary: a piece of another type than
    // the summary says overflowed its copy under fuzzing). A summary that lies about the type reads by the
    // pieces' own; pieces of different types, and pieces that leave a hole, are one error each.
    std::string lying = summary;
    const std::string declared = "<PDataArray type=\"UInt16\"";
    lying.replace(lying.find(declared), declared.size(), "<PDataArray type=\"UInt64\"");
    fs::remove(dir / "p.pvti");
    test::writeFile(dir / "lie.pvti", lying);
    fs::copy_file(dir / "p_0.vti", dir / "p_1.vti");  // a piece at the wrong extent
    EXPECT_THROW(readVtkImage(dir / "lie.pvti"), InputError);  // piece 1 does not hold its extent
    expectVolumeValues(readVtkImage(dir / "lie.pvti", "", GridRegion{{0, 0, 0}, {3, 5, 7}}), {4, 6, 8});
    vtkNew<vtkImageData> floatPiece = makeImage({9, 6, 8}, pieces[1]);
    vtkNew<vtkFloatArray> asFloat;
    asFloat->SetName("density");
    asFloat->DeepCopy(floatPiece->GetPointData()->GetArray("density"));
    floatPiece->GetPointData()->RemoveArray("density");
    floatPiece->GetPointData()->SetScalars(asFloat);
    vtkNew<vtkXMLImageDataWriter> writer1;
    writer1->SetInputData(floatPiece);
    writer1->SetFileName((dir / "p_1.vti").c_str());
    ASSERT_EQ(writer1->Write(), 1);
    EXPECT_TRUE(test::throwsInputError([&] { readVtkImage(dir / "lie.pvti", "density"); }, {"another piece's has"}));
    std::string holed = summary;
    holed.erase(holed.find("    <Piece Extent=\"6 10 1 6 0 3\""), holed.find("\n", holed.find("Extent=\"6 10 1 6 0 3\"")) -
                                                                  holed.find("    <Piece Extent=\"6 10 1 6 0 3\"") + 1);
    test::writeFile(dir / "holed.pvti", holed);
    EXPECT_TRUE(test::throwsInputError([&] { readVtkImage(dir / "holed.pvti"); }, {"no piece holds grid point"}));
}

TEST(VtkXmlIo, MetaImageMhdAndMha)
{
    TempDir dir;
    vtkNew<vtkImageData> image = makeImage();
    image->GetPointData()->RemoveArray("other");
    image->SetExtent(0, 6, 0, 4, 0, 3);  // MetaImage has no extent start: the origin says where it is
    for (const char* name : {"a.mhd", "b.mha"}) {
        SCOPED_TRACE(name);
        vtkNew<vtkMetaImageWriter> writer;
        writer->SetInputData(image);
        writer->SetFileName((dir / name).c_str());
        writer->SetCompression(std::string(name) == "b.mha");
        writer->Write();
        const Volume v = loadVolume(nlohmann::json{{"file", name}}, dir.path());
        expectVolumeValues(v, {7, 5, 4});
        EXPECT_EQ(v.spacing, glm::dvec3(0.5, 0.25, 2.0));
        EXPECT_EQ(v.origin, glm::dvec3(-1.0, 0.0, 3.0));
    }
    // A header whose data file is missing.
    fs::remove(dir / "a.raw");
    fs::remove(dir / "a.zraw");
    EXPECT_THROW(readVtkImage(dir / "a.mhd"), InputError);
}

TEST(VtkXmlIo, BadImageFilesAreOneInputErrorNamingTheFile)
{
    TempDir dir;
    vtkNew<vtkImageData> image = makeImage();
    vtkNew<vtkXMLImageDataWriter> writer;
    writer->SetInputData(image);
    writer->SetFileName((dir / "good.vti").c_str());
    writer->SetDataModeToAppended();
    writer->EncodeAppendedDataOff();
    ASSERT_EQ(writer->Write(), 1);
    const std::string good = test::readFile(dir / "good.vti");

    vtkNew<vtkImageData> cells;
    cells->SetDimensions(3, 3, 3);
    vtkNew<vtkFloatArray> c;
    c->SetName("pressure");
    c->SetNumberOfValues(8);
    c->FillValue(1.0f);
    cells->GetCellData()->AddArray(c);
    writer->SetInputData(cells);
    writer->SetFileName((dir / "cells.vti").c_str());
    ASSERT_EQ(writer->Write(), 1);

    const std::vector<std::pair<std::string, std::string>> bad = {
        {"empty", ""},
        {"not XML", "hello"},
        {"truncated data", good.substr(0, good.size() - 200)},
        {"truncated XML", good.substr(0, 300)},
        {"flat grid", [&] {
             std::string s = good;
             const std::size_t at = s.find("WholeExtent=\"2 8 1 5 0 3\"");
             return at == std::string::npos ? std::string("missing") : s.replace(at, 25, "WholeExtent=\"2 8 1 5 0 0\"");
         }()},
        {"huge extent", [&] {
             std::string s = good;
             const std::size_t at = s.find("WholeExtent=\"2 8 1 5 0 3\"");
             return at == std::string::npos ? std::string("missing") : s.replace(at, 25, "WholeExtent=\"0 99999 0 99999 0 99999\"");
         }()},
        {"zero spacing", [&] {
             std::string s = good;
             const std::size_t at = s.find("Spacing=\"");
             return at == std::string::npos ? std::string("missing") : s.replace(at, 9, "Spacing=\"0 ");
         }()},
    };
    for (const auto& [name, bytes] : bad) {
        SCOPED_TRACE(name);
        ASSERT_NE(bytes, "missing");
        const fs::path path = dir / "bad.vti";
        test::writeFile(path, bytes);
        EXPECT_TRUE(test::throwsInputError([&] { readVtkImage(path); }, {path.string()}));
    }
    EXPECT_TRUE(test::throwsInputError([&] { readVtkImage(dir / "cells.vti"); }, {"pressure"}));
    EXPECT_TRUE(test::throwsInputError([&] { readVtkImage(dir / "good.vti", "velocity"); }, {"other, density"}));
    EXPECT_THROW(readVtkImage(dir / "missing.vti"), InputError);
}

// A grid of one tetrahedron, one hexahedron, one wedge (sharing points), as VTK writes it.
vtkNew<vtkUnstructuredGrid> makeGrid()
{
    vtkNew<vtkPoints> points;
    const double p[][3] = {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}, {0, 0, 1}, {1, 0, 1}, {1, 1, 1}, {0, 1, 1},
                           {2, 0, 0}, {2, 1, 0}, {2, 0, 1}, {0.5, 0.5, 2}};
    for (const auto& q : p)
        points->InsertNextPoint(q);
    vtkNew<vtkUnstructuredGrid> grid;
    grid->SetPoints(points);
    const vtkIdType hex[] = {0, 1, 2, 3, 4, 5, 6, 7};
    const vtkIdType wedge[] = {1, 8, 2, 5, 10, 6};  // triangles 1-8-2 and 5-10-6; 9 unused by cells
    const vtkIdType tet[] = {4, 5, 7, 11};
    grid->InsertNextCell(VTK_HEXAHEDRON, 8, hex);
    grid->InsertNextCell(VTK_WEDGE, 6, wedge);
    grid->InsertNextCell(VTK_TETRA, 4, tet);
    vtkNew<vtkFloatArray> s;
    s->SetName("temperature");
    for (int i = 0; i < 12; ++i)
        s->InsertNextValue(static_cast<float>(i) * 0.5f);
    grid->GetPointData()->SetScalars(s);
    return grid;
}

TEST(VtkXmlIo, VtuSplitsCellsAsTheLegacyReader)
{
    TempDir dir;
    vtkNew<vtkUnstructuredGrid> grid = makeGrid();
    vtkNew<vtkUnstructuredGridWriter> legacy;
    legacy->SetInputData(grid);
    legacy->SetFileName((dir / "g.vtk").c_str());
    ASSERT_EQ(legacy->Write(), 1);
    const TetMesh want = readVtkUnstructured(dir / "g.vtk");
    ASSERT_EQ(want.tets.size(), 6u + 3u + 1u);
    for (int mode : {vtkXMLWriter::Ascii, vtkXMLWriter::Binary, vtkXMLWriter::Appended}) {
        SCOPED_TRACE(mode);
        vtkNew<vtkXMLUnstructuredGridWriter> writer;
        writer->SetInputData(grid);
        writer->SetFileName((dir / "g.vtu").c_str());
        writer->SetDataMode(mode);
        ASSERT_EQ(writer->Write(), 1);
        const TetMesh got = readVtkXmlUnstructured(dir / "g.vtu");
        EXPECT_EQ(got.tets, want.tets);
        EXPECT_EQ(got.points, want.points);
        EXPECT_EQ(got.scalars, want.scalars);
        EXPECT_EQ(got.tetsRead, 10u);
    }
    // Through the scene's "mesh", checked and split.
    const TetMesh loaded = loadMesh(nlohmann::json{{"file", "g.vtu"}, {"scalar", "temperature"}}, dir.path());
    EXPECT_EQ(loaded.tets.size(), 10u);
    EXPECT_THROW(loadMesh(nlohmann::json{{"file", "g.vtu"}, {"scalar", "pressure"}}, dir.path()), InputError);
}

TEST(VtkXmlIo, VtuVoxelIsItsHexahedron)
{
    TempDir dir;
    vtkNew<vtkUnstructuredGrid> grid = makeGrid();
    vtkNew<vtkUnstructuredGrid> voxel;
    voxel->SetPoints(grid->GetPoints());
    voxel->GetPointData()->ShallowCopy(grid->GetPointData());
    const vtkIdType v[] = {0, 1, 3, 2, 4, 5, 7, 6};  // the hexahedron 0..7 in the voxel's x-fastest order
    voxel->InsertNextCell(VTK_VOXEL, 8, v);
    vtkNew<vtkXMLUnstructuredGridWriter> writer;
    writer->SetInputData(voxel);
    writer->SetFileName((dir / "v.vtu").c_str());
    ASSERT_EQ(writer->Write(), 1);
    const TetMesh got = readVtkXmlUnstructured(dir / "v.vtu");
    std::vector<glm::uvec4> hex;
    splitHex({0, 1, 2, 3, 4, 5, 6, 7}, hex);
    EXPECT_EQ(got.tets, hex);
}

TEST(VtkXmlIo, PvtuPiecesMakeTheWholeMesh)
{
    TempDir dir;
    // Two pieces of makeGrid(): the hexahedron and the wedge, and the tetrahedron, each with every point
    // (points shared by the pieces come twice; the topology welds them).
    vtkNew<vtkUnstructuredGrid> grid = makeGrid();
    for (int piece = 0; piece < 2; ++piece) {
        vtkNew<vtkUnstructuredGrid> part;
        part->SetPoints(grid->GetPoints());
        part->GetPointData()->ShallowCopy(grid->GetPointData());
        for (vtkIdType c = piece == 0 ? 0 : 2; c < (piece == 0 ? 2 : 3); ++c)
            part->InsertNextCell(grid->GetCellType(c), grid->GetCell(c)->GetPointIds());
        vtkNew<vtkXMLUnstructuredGridWriter> writer;
        writer->SetInputData(part);
        writer->SetFileName((dir / ("g_" + std::to_string(piece) + ".vtu")).c_str());
        ASSERT_EQ(writer->Write(), 1);
    }
    test::writeFile(dir / "g.pvtu", R"(<?xml version="1.0"?>
<VTKFile type="PUnstructuredGrid" version="1.0" byte_order="LittleEndian" header_type="UInt64">
  <PUnstructuredGrid GhostLevel="0">
    <PPointData Scalars="temperature"><PDataArray type="Float32" Name="temperature"/></PPointData>
    <PPoints><PDataArray type="Float32" NumberOfComponents="3"/></PPoints>
    <Piece Source="g_0.vtu"/>
    <Piece Source="g_1.vtu"/>
  </PUnstructuredGrid>
</VTKFile>
)");
    vtkNew<vtkUnstructuredGridWriter> legacy;
    legacy->SetInputData(grid);
    legacy->SetFileName((dir / "g.vtk").c_str());
    ASSERT_EQ(legacy->Write(), 1);
    const TetMesh mesh = loadMesh(nlohmann::json{{"file", "g.pvtu"}}, dir.path());
    const TetMesh whole = loadMesh(nlohmann::json{{"file", "g.vtk"}}, dir.path());
    EXPECT_EQ(mesh.points.size(), 24u);
    EXPECT_EQ(mesh.tets.size(), whole.tets.size());
    const auto volume = [](const TetMesh& m) {
        double sum = 0.0;
        for (const glm::uvec4& t : m.tets)
            sum += signedVolume6(m.points[t.x], m.points[t.y], m.points[t.z], m.points[t.w]) / 6.0;
        return sum;
    };
    EXPECT_NEAR(volume(mesh), volume(whole), 1e-12);
    EXPECT_NEAR(volume(whole), 1.0 + 0.5 + 1.0 / 6.0, 1e-12);  // the hexahedron, the wedge, the tetrahedron
    // A missing piece is an error, not a smaller mesh.
    fs::remove(dir / "g_1.vtu");
    EXPECT_THROW(loadMesh(nlohmann::json{{"file", "g.pvtu"}}, dir.path()), InputError);
}

TEST(VtkXmlIo, BadMeshFilesAreOneInputErrorNamingTheFile)
{
    TempDir dir;
    vtkNew<vtkUnstructuredGrid> grid = makeGrid();
    const vtkIdType pyramid[] = {0, 1, 2, 3, 11};
    grid->InsertNextCell(VTK_PYRAMID, 5, pyramid);
    vtkNew<vtkXMLUnstructuredGridWriter> writer;
    writer->SetInputData(grid);
    writer->SetFileName((dir / "pyr.vtu").c_str());
    ASSERT_EQ(writer->Write(), 1);
    EXPECT_TRUE(test::throwsInputError([&] { readVtkXmlUnstructured(dir / "pyr.vtu"); }, {"vtkPyramid"}));
    const std::string good = test::readFile(dir / "pyr.vtu");
    for (const std::string& bytes : {std::string(), std::string("<VTKFile"), good.substr(0, good.size() / 2)}) {
        test::writeFile(dir / "bad.vtu", bytes);
        EXPECT_TRUE(test::throwsInputError([&] { readVtkXmlUnstructured(dir / "bad.vtu"); }, {"bad.vtu"}));
    }
}

TEST(VtkXmlIo, VtiRendersTheBitsOfItsGenerator)
{
    TempDir dir;
    const Volume ml = generateVolume("marschner-lobb", {24, 24, 24});
    vtkNew<vtkImageData> image;
    image->SetDimensions(ml.dims.x, ml.dims.y, ml.dims.z);
    image->SetSpacing(ml.spacing.x, ml.spacing.y, ml.spacing.z);
    image->SetOrigin(ml.origin.x, ml.origin.y, ml.origin.z);
    vtkNew<vtkFloatArray> values;
    values->SetName("f");
    for (float v : ml.values)
        values->InsertNextValue(v);
    image->GetPointData()->SetScalars(values);
    vtkNew<vtkXMLImageDataWriter> writer;
    writer->SetInputData(image);
    writer->SetFileName((dir / "ml.vti").c_str());
    ASSERT_EQ(writer->Write(), 1);

    const Scene scene = defaultScene({"image.width=32", "image.height=24"});
    const Volume read = loadVolume(nlohmann::json{{"file", "ml.vti"}}, dir.path());
    EXPECT_EQ(read.values, ml.values);
    EXPECT_TRUE(test::sameBits(test::renderScene(scene, read), test::renderScene(scene, ml)));
}

#endif  // CLVR_HAVE_VTK

}  // namespace
}  // namespace clvr
