// host/io/vtk_xml_io.cpp — .vti/.pvti/.mhd/.mha volumes and .vtu/.pvtu meshes through VTK's own readers.
// VTK reports a bad file through its output window (an error text, the reader carrying on with empty
// output); while a reader runs, that window is replaced by one that keeps the first error, which becomes
// the InputError. Sizes are checked from the header (UpdateInformation) before anything is allocated.
#include "host/io/vtk_xml_io.h"

#include "host/io/cell_split.h"
#include "host/io/volume_io.h"
#include "host/runtime/errors.h"
#include "host/runtime/file_io.h"

#include <algorithm>
#include <array>
#include <cctype>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <fstream>
#include <limits>
#include <mutex>
#include <new>
#include <string>
#include <type_traits>
#include <vector>

#ifdef CLVR_HAVE_VTK
#include <vtkCellData.h>
#include <vtkCellTypes.h>
#include <vtkDataArray.h>
#include <vtkImageData.h>
#include <vtkInformation.h>
#include <vtkLogger.h>
#include <vtkMatrix3x3.h>
#include <vtkMetaImageReader.h>
#include <vtkNew.h>
#include <vtkObjectFactory.h>
#include <vtkOutputWindow.h>
#include <vtkPointData.h>
#include <vtkPoints.h>
#include <vtkSmartPointer.h>
#include <vtkStreamingDemandDrivenPipeline.h>
#include <vtkUnstructuredGrid.h>
#include <vtkXMLDataElement.h>
#include <vtkXMLImageDataReader.h>
#include <vtkXMLPImageDataReader.h>
#include <vtkXMLPUnstructuredGridReader.h>
#include <vtkXMLUnstructuredGridReader.h>
#endif

namespace clvr {

namespace fs = std::filesystem;

namespace {

std::string extensionOf(const fs::path& path) { return asciiLower(path.extension().string()); }

}  // namespace

#ifndef CLVR_HAVE_VTK

bool haveVtkReaders() { return false; }

namespace {
[[noreturn]] void noVtk(const fs::path& path)
{
    throw InputError(path.string() + ": this clvr was built without VTK, which reads " + extensionOf(path) +
                     " files (install Debian's paraview-dev and build again: tools/setup.sh)");
}
}  // namespace

GridHeader readVtkImageHeader(const fs::path& path) { noVtk(path); }
Volume readVtkImage(const fs::path& path, const std::string&, const std::optional<GridRegion>&) { noVtk(path); }
TetMesh readVtkXmlUnstructured(const fs::path& path, const std::string&) { noVtk(path); }

#else

bool haveVtkReaders() { return true; }

namespace {

// VTK's output window while a reader runs: keeps the first error's message, drops warnings and the rest.
class ErrorCapture : public vtkOutputWindow {
public:
    static ErrorCapture* New();
    vtkTypeMacro(ErrorCapture, vtkOutputWindow);
    void DisplayErrorText(const char* text) override
    {
        if (first.empty() && text)
            first = text;
    }
    void DisplayWarningText(const char*) override {}
    void DisplayGenericWarningText(const char*) override {}
    void DisplayDebugText(const char*) override {}
    void DisplayText(const char*) override {}
    std::string first;
};
vtkStandardNewMacro(ErrorCapture);

// VTK's output window is one per process: readers run one at a time, each with its own capture.
class CapturedRead {
public:
    explicit CapturedRead(fs::path path) : lock_(mutex()), path_(std::move(path))
    {
        previous_ = vtkOutputWindow::GetInstance();
        vtkOutputWindow::SetInstance(capture_);
        // VTK 9 also logs every error to stderr through its logger, past the output window: clvr says it
        // once, in its own line. Nothing else in clvr logs through VTK.
        vtkLogger::SetStderrVerbosity(vtkLogger::VERBOSITY_OFF);
    }
    ~CapturedRead() { vtkOutputWindow::SetInstance(previous_); }
    CapturedRead(const CapturedRead&) = delete;
    CapturedRead& operator=(const CapturedRead&) = delete;

    // Throws the first error VTK reported since the last check, as "<file>: <VTK's message>".
    void check()
    {
        if (capture_->first.empty())
            return;
        std::string text = capture_->first;
        capture_->first.clear();
        fail(message(text));
    }
    [[noreturn]] void fail(const std::string& what) const { throw InputError(path_.string() + ": " + what); }

private:
    static std::mutex& mutex()
    {
        static std::mutex m;
        return m;
    }
    // "ERROR: In /build/.../vtkXMLReader.cxx, line 345\nvtkXMLImageDataReader (0x55...): Error parsing ...\n\n"
    // -> "Error parsing ...": VTK's own words without the source location, on one line.
    static std::string message(const std::string& text)
    {
        std::string m = text;
        const std::size_t obj = m.find("): ");
        if (m.rfind("ERROR: In ", 0) == 0 && obj != std::string::npos)
            m = m.substr(obj + 3);
        for (char& c : m)
            if (c == '\n' || c == '\r' || c == '\t')
                c = ' ';
        while (!m.empty() && m.back() == ' ')
            m.pop_back();
        if (m.size() > 300)
            m = m.substr(0, 300) + "...";
        return "VTK's reader failed: " + m;
    }

    std::unique_lock<std::mutex> lock_;
    fs::path path_;
    vtkSmartPointer<vtkOutputWindow> previous_;
    vtkNew<ErrorCapture> capture_;
};

// VTK's .pvti reader leaves a piece it cannot open out of the output without a word (its CanReadPiece):
// this one says which piece meeting an extent is missing.
class CheckedPImageReader : public vtkXMLPImageDataReader {
public:
    static CheckedPImageReader* New();
    vtkTypeMacro(CheckedPImageReader, vtkXMLPImageDataReader);
    // The file of the first piece that meets `extent` and cannot be read; empty when all can.
    std::string unreadablePiece(const int extent[6])
    {
        for (int i = 0; i < this->NumberOfPieces; ++i) {
            const int* e = this->PieceExtents + 6 * i;  // the summary file's Extent of piece i
            bool meets = true;
            for (int a = 0; a < 3; ++a)
                meets = meets && e[2 * a] <= extent[2 * a + 1] && extent[2 * a] <= e[2 * a + 1];
            if (meets && !this->CanReadPiece(i)) {
                const char* source = this->PieceElements[i] ? this->PieceElements[i]->GetAttribute("Source") : nullptr;
                return source ? source : "piece " + std::to_string(i);
            }
        }
        return "";
    }
    int pieceCount() const { return this->NumberOfPieces; }
    const int* pieceExtent(int i) const { return this->PieceExtents + 6 * i; }  // the summary's Extent
    // Piece i's file as the summary names it, resolved against the summary's folder; empty when it cannot be
    // read.
    std::string pieceFile(int i)
    {
        if (!this->CanReadPiece(i) || !this->PieceReaders[i] || !this->PieceReaders[i]->GetFileName())
            return "";
        return this->PieceReaders[i]->GetFileName();
    }
};
vtkStandardNewMacro(CheckedPImageReader);

// The same for .pvtu, whose every piece one process reads.
class CheckedPUnstructuredReader : public vtkXMLPUnstructuredGridReader {
public:
    static CheckedPUnstructuredReader* New();
    vtkTypeMacro(CheckedPUnstructuredReader, vtkXMLPUnstructuredGridReader);
    std::string unreadablePiece()
    {
        for (int i = 0; i < this->NumberOfPieces; ++i)
            if (!this->CanReadPiece(i)) {
                const char* source = this->PieceElements[i] ? this->PieceElements[i]->GetAttribute("Source") : nullptr;
                return source ? source : "piece " + std::to_string(i);
            }
        return "";
    }
};
vtkStandardNewMacro(CheckedPUnstructuredReader);

// MetaImage's library prints "Cannot open data file" on stdout and fails; an .mhd's data file is checked
// here first so that the error is clvr's one line. The header is "Key = Value" lines; ElementDataFile
// comes last and names the data file (LOCAL: the data follows the header; LIST or a %d pattern: several
// files, left to MetaImage).
void checkMetaImageDataFile(const fs::path& path)
{
    std::ifstream in(path, std::ios::binary);
    std::string line;
    for (int n = 0; n < 64 && std::getline(in, line); ++n) {
        const std::size_t eq = line.find('=');
        if (eq == std::string::npos || line.compare(0, 15, "ElementDataFile") != 0)
            continue;
        std::string file = line.substr(eq + 1);
        file.erase(0, file.find_first_not_of(" \t"));
        while (!file.empty() && std::isspace(static_cast<unsigned char>(file.back())))
            file.pop_back();
        if (file == "LOCAL" || file.rfind("LIST", 0) == 0 || file.find('%') != std::string::npos || file.empty())
            return;
        const fs::path data = fs::path(file).is_absolute() ? fs::path(file) : path.parent_path() / file;
        if (!fs::is_regular_file(data))
            throw InputError(path.string() + ": its ElementDataFile " + data.string() + " does not exist");
        return;
    }
}

vtkSmartPointer<vtkAlgorithm> imageReader(const fs::path& path, const std::string& ext)
{
    if (ext == ".vti") {
        auto r = vtkSmartPointer<vtkXMLImageDataReader>::New();
        r->SetFileName(path.c_str());
        return r;
    }
    if (ext == ".pvti") {
        auto r = vtkSmartPointer<CheckedPImageReader>::New();
        r->SetFileName(path.c_str());
        return r;
    }
    if (ext == ".mhd" || ext == ".mha") {
        checkMetaImageDataFile(path);
        auto r = vtkSmartPointer<vtkMetaImageReader>::New();
        r->SetFileName(path.c_str());
        return r;
    }
    throw InternalError("imageReader: " + path.string() + " is not .vti, .pvti, .mhd or .mha");
}

// The whole grid's extent, spacing and origin from the header alone.
struct ImageInfo {
    int extent[6] = {0, -1, 0, -1, 0, -1};
    glm::dvec3 spacing{1.0}, origin{0.0};
    glm::ivec3 dims() const { return {extent[1] - extent[0] + 1, extent[3] - extent[2] + 1, extent[5] - extent[4] + 1}; }
};

ImageInfo readInformation(vtkAlgorithm& reader, CapturedRead& read)
{
    reader.UpdateInformation();
    read.check();
    vtkInformation* info = reader.GetOutputInformation(0);
    ImageInfo out;
    if (!info || !info->Has(vtkStreamingDemandDrivenPipeline::WHOLE_EXTENT()))
        read.fail("no image extent in the header");
    info->Get(vtkStreamingDemandDrivenPipeline::WHOLE_EXTENT(), out.extent);
    double s[3] = {1, 1, 1}, o[3] = {0, 0, 0};
    if (info->Has(vtkDataObject::SPACING()))
        info->Get(vtkDataObject::SPACING(), s);
    if (info->Has(vtkDataObject::ORIGIN()))
        info->Get(vtkDataObject::ORIGIN(), o);
    // VTK's origin is that of index (0,0,0); an extent that starts elsewhere moves the first point.
    for (int a = 0; a < 3; ++a) {
        out.spacing[a] = s[a];
        out.origin[a] = o[a] + out.extent[2 * a] * s[a];
    }
    const glm::ivec3 d = out.dims();
    for (int a = 0; a < 3; ++a) {
        if (d[a] < 2)
            read.fail("the grid has " + std::to_string(std::max(d[a], 0)) + " points on axis " + "xyz"[a] +
                      " (extent " + std::to_string(out.extent[2 * a]) + " " + std::to_string(out.extent[2 * a + 1]) +
                      "); clvr renders 3-D grids with at least 2 points per axis");
        if (!(s[a] > 0) || !std::isfinite(s[a]) || !std::isfinite(o[a]))
            read.fail("spacing " + numberText(s[a]) + " and origin " + numberText(o[a]) + " on axis " + "xyz"[a] +
                      " (spacing must be finite and > 0; a negative spacing is a flipped axis clvr does not take)");
    }
    if (info->Has(vtkDataObject::DIRECTION())) {
        double dir[9];
        info->Get(vtkDataObject::DIRECTION(), dir);
        for (int i = 0; i < 9; ++i)
            if (dir[i] != (i % 4 == 0 ? 1.0 : 0.0))
                read.fail("the grid has a direction matrix other than the identity; clvr renders axis-aligned "
                          "grids (resample it first, e.g. with ParaView's Resample To Image)");
    }
    return out;
}

// The array to sample: by name, else the active scalars, else the first one-component array.
vtkDataArray* pointScalar(vtkDataSet& data, const std::string& name, CapturedRead& read)
{
    vtkPointData* pd = data.GetPointData();
    std::string names;
    for (int i = 0; pd && i < pd->GetNumberOfArrays(); ++i)
        if (const char* n = pd->GetArrayName(i))
            names += (names.empty() ? "" : ", ") + std::string(n);
    if (!pd || pd->GetNumberOfArrays() == 0) {
        std::string cells;
        vtkCellData* cd = data.GetCellData();
        for (int i = 0; cd && i < cd->GetNumberOfArrays(); ++i)
            if (const char* n = cd->GetArrayName(i))
                cells += (cells.empty() ? "" : ", ") + std::string(n);
        if (!cells.empty())
            read.fail("no point data, only cell data (" + cells +
                      "); clvr samples values on points: convert them first (ParaView's Cell Data to Point Data)");
        read.fail("no point data array to render");
    }
    vtkDataArray* a = nullptr;
    if (!name.empty()) {
        a = pd->GetArray(name.c_str());
        if (!a)
            read.fail("no point array named \"" + name + "\" (it has " + names + ")");
    } else if (vtkDataArray* s = pd->GetScalars(); s && s->GetNumberOfComponents() == 1) {
        a = s;
    } else {
        for (int i = 0; i < pd->GetNumberOfArrays() && !a; ++i)
            if (vtkDataArray* c = pd->GetArray(i); c && c->GetNumberOfComponents() == 1)
                a = c;
        if (!a)
            read.fail("no one-component point array (it has " + names + "); name one with \"scalar\"");
    }
    if (a->GetNumberOfComponents() != 1)
        read.fail("point array \"" + std::string(a->GetName() ? a->GetName() : "") + "\" has " +
                  std::to_string(a->GetNumberOfComponents()) + " components; clvr renders one-component arrays");
    return a;
}

// The region's values as they are read, box by box (the whole region from one file, or a .pvti's pieces):
// stored in the first box's type (1- and 2-byte integers kept so, others as float), every point marked as
// it is written, so that a region the pieces do not cover is an error, not zeros.
class RegionStore {
public:
    RegionStore(Volume& v, const int extent[6], CapturedRead& read) : v_(v), read_(read)
    {
        std::copy(extent, extent + 6, extent_);
        written_.assign(v.voxelCount(), false);
    }

    // Copies the points of `box` from `array`, which holds the points of extent `have` (x fastest).
    void copy(vtkDataArray& array, const int have[6], const int box[6], const std::string& what)
    {
        const int type = array.GetDataType();
        if (type_ < 0) {
            type_ = type;
            typeName_ = array.GetDataTypeAsString();
            switch (type) {
            case VTK_UNSIGNED_CHAR: v_.voxelType = VoxelType::UInt8; break;
            case VTK_SIGNED_CHAR:
            case VTK_CHAR: v_.voxelType = VoxelType::Int8; break;
            case VTK_SHORT: v_.voxelType = VoxelType::Int16; break;
            case VTK_UNSIGNED_SHORT: v_.voxelType = VoxelType::UInt16; break;
            case VTK_INT: case VTK_UNSIGNED_INT: case VTK_FLOAT: case VTK_DOUBLE: break;
            default:
                read_.fail(what + "point array \"" + std::string(array.GetName() ? array.GetName() : "") + "\" has type " +
                           array.GetDataTypeAsString() + " (clvr reads 8-, 16- and 32-bit integers, float32 and float64)");
            }
            v_.allocateValues();
        } else if (type != type_) {
            read_.fail(what + "point array \"" + std::string(array.GetName() ? array.GetName() : "") + "\" has type " +
                       array.GetDataTypeAsString() + ", another piece's has " + typeName_);
        }
        const void* src = array.GetVoidPointer(0);
        switch (type) {
        case VTK_UNSIGNED_CHAR: put(static_cast<const std::uint8_t*>(src), have, box); break;
        case VTK_SIGNED_CHAR:
        case VTK_CHAR: put(static_cast<const std::int8_t*>(src), have, box); break;
        case VTK_SHORT: put(static_cast<const std::int16_t*>(src), have, box); break;
        case VTK_UNSIGNED_SHORT: put(static_cast<const std::uint16_t*>(src), have, box); break;
        case VTK_INT: put(static_cast<const std::int32_t*>(src), have, box); break;
        case VTK_UNSIGNED_INT: put(static_cast<const std::uint32_t*>(src), have, box); break;
        case VTK_FLOAT: put(static_cast<const float*>(src), have, box); break;
        default: put(static_cast<const double*>(src), have, box); break;
        }
    }

    void checkCovered() const
    {
        const auto gap = std::find(written_.begin(), written_.end(), false);
        if (gap != written_.end()) {
            const std::size_t i = static_cast<std::size_t>(gap - written_.begin());
            const std::size_t nx = static_cast<std::size_t>(v_.dims.x), ny = static_cast<std::size_t>(v_.dims.y);
            read_.fail("no piece holds grid point (" + std::to_string(extent_[0] + static_cast<int>(i % nx)) + "," +
                       std::to_string(extent_[2] + static_cast<int>(i / nx % ny)) + "," +
                       std::to_string(extent_[4] + static_cast<int>(i / nx / ny)) + ") of the extent read");
        }
    }

private:
    template <typename S>
    void put(const S* src, const int have[6], const int box[6])
    {
        const std::size_t hx = static_cast<std::size_t>(have[1] - have[0] + 1), hy = static_cast<std::size_t>(have[3] - have[2] + 1);
        const std::size_t dx = static_cast<std::size_t>(v_.dims.x), dy = static_cast<std::size_t>(v_.dims.y);
        const std::size_t size = voxelTypeSize(v_.voxelType);
        for (int k = box[4]; k <= box[5]; ++k)
            for (int j = box[2]; j <= box[3]; ++j) {
                const S* row = src + (static_cast<std::size_t>(k - have[4]) * hy + static_cast<std::size_t>(j - have[2])) * hx +
                               static_cast<std::size_t>(box[0] - have[0]);
                const std::size_t at = (static_cast<std::size_t>(k - extent_[4]) * dy + static_cast<std::size_t>(j - extent_[2])) * dx +
                                       static_cast<std::size_t>(box[0] - extent_[0]);
                const std::size_t count = static_cast<std::size_t>(box[1] - box[0] + 1);
                if (v_.native())
                    std::memcpy(v_.valueData() + at * size, row, count * size);  // the same type (checked)
                else
                    for (std::size_t i = 0; i < count; ++i)
                        v_.values[at + i] = static_cast<float>(row[i]);
                std::fill(written_.begin() + static_cast<std::ptrdiff_t>(at),
                          written_.begin() + static_cast<std::ptrdiff_t>(at + count), true);
            }
    }

    Volume& v_;
    CapturedRead& read_;
    int extent_[6];
    int type_ = -1;
    std::string typeName_;
    std::vector<bool> written_;
};

// Reads the points of `box` (index space) from one image file through `reader` (its information already
// read) into `store`; the array is `scalar` by name, else the file's choice (pointScalar). Returns the
// array's name, so that a .pvti's other pieces take the same one. `what` names a piece in messages.
std::string readImageBox(vtkAlgorithm& reader, const int box[6], const std::string& scalar, RegionStore& store,
                         CapturedRead& read, const std::string& what)
{
    const std::string prefix = what.empty() ? "" : "piece " + what + ": ";
    try {
        reader.UpdateExtent(box);
    } catch (const std::bad_alloc&) {
        read.fail("out of host memory while reading");
    }
    read.check();
    vtkImageData* image = vtkImageData::SafeDownCast(reader.GetOutputDataObject(0));
    if (!image)
        read.fail(prefix + "no image data read");
    int have[6];
    image->GetExtent(have);
    for (int a = 0; a < 3; ++a)
        if (have[2 * a] > box[2 * a] || have[2 * a + 1] < box[2 * a + 1])
            read.fail(prefix + "the data read covers less than the header's extent (a piece or part of the data is missing)");
    vtkDataArray* array = pointScalar(*image, scalar, read);
    const std::uint64_t haveCount = static_cast<std::uint64_t>(have[1] - have[0] + 1) *
                                    static_cast<std::uint64_t>(have[3] - have[2] + 1) *
                                    static_cast<std::uint64_t>(have[5] - have[4] + 1);
    if (static_cast<std::uint64_t>(array->GetNumberOfTuples()) != haveCount)
        read.fail(prefix + "point array \"" + std::string(array->GetName() ? array->GetName() : "") + "\" has " +
                  std::to_string(array->GetNumberOfTuples()) + " values for " + std::to_string(haveCount) + " points");
    store.copy(*array, have, box, prefix);
    return array->GetName() ? array->GetName() : scalar;
}

}  // namespace

GridHeader readVtkImageHeader(const fs::path& path)
{
    fileSize(path);
    CapturedRead read(path);
    vtkSmartPointer<vtkAlgorithm> reader = imageReader(path, extensionOf(path));
    const ImageInfo info = readInformation(*reader, read);
    return {info.dims(), info.spacing, info.origin};
}

Volume readVtkImage(const fs::path& path, const std::string& scalar, const std::optional<GridRegion>& region)
{
    fileSize(path);  // "no such file" in clvr's words, before VTK's
    CapturedRead read(path);
    vtkSmartPointer<vtkAlgorithm> reader = imageReader(path, extensionOf(path));
    const ImageInfo info = readInformation(*reader, read);
    const glm::ivec3 dims = info.dims();
    glm::ivec3 lo(0), hi = dims - 1;
    if (region) {
        lo = region->lo;
        hi = region->hi;
        if (glm::any(glm::lessThan(lo, glm::ivec3(0))) || glm::any(glm::greaterThanEqual(hi, dims)) ||
            glm::any(glm::lessThan(hi, lo)))
            throw InternalError("readVtkImage: a region outside the grid");
    }
    const glm::ivec3 n = hi - lo + 1;
    const std::uint64_t count = static_cast<std::uint64_t>(n.x) * static_cast<std::uint64_t>(n.y) * static_cast<std::uint64_t>(n.z);
    if (count > kMaxVoxels)
        read.fail("the grid has " + std::to_string(count) + " points, more than clvr's limit of " +
                  std::to_string(kMaxVoxels));
    // VTK's own copy in the file's type and clvr's float copy: at most 8 + 4 bytes a point.
    checkHostMemory(path.string() + ": " + std::to_string(count) + " grid points", count * 12);

    const int want[6] = {info.extent[0] + lo.x, info.extent[0] + hi.x, info.extent[2] + lo.y,
                         info.extent[2] + hi.y, info.extent[4] + lo.z, info.extent[4] + hi.z};
    Volume v;
    v.dims = n;
    v.spacing = info.spacing;
    v.origin = info.origin + glm::dvec3(lo) * info.spacing;
    v.source = path.string();
    RegionStore store(v, want, read);
    auto* pieces = CheckedPImageReader::SafeDownCast(reader);
    if (!pieces) {  // one file: VTK reads the region's rows or blocks of it
        readImageBox(*reader, want, scalar, store, read, "");
    } else {
        // A .pvti: each piece that meets the region read on its own and copied here, never by VTK's parallel
        // reader, whose copy trusts the summary's types and extents (a piece of another type than the
        // summary says overflowed its buffer under fuzzing: fuzz/regressions/vti).
        std::string name = scalar;
        for (int i = 0; i < pieces->pieceCount(); ++i) {
            const int* e = pieces->pieceExtent(i);
            int box[6];
            bool meets = true;
            for (int a = 0; a < 3; ++a) {
                box[2 * a] = std::max(e[2 * a], want[2 * a]);
                box[2 * a + 1] = std::min(e[2 * a + 1], want[2 * a + 1]);
                meets = meets && box[2 * a] <= box[2 * a + 1];
            }
            if (!meets)
                continue;
            const std::string file = pieces->pieceFile(i);
            if (file.empty())
                read.fail("its piece " + pieces->unreadablePiece(box) + " cannot be read (missing or not a .vti file)");
            auto piece = vtkSmartPointer<vtkXMLImageDataReader>::New();
            piece->SetFileName(file.c_str());
            piece->UpdateInformation();
            read.check();
            name = readImageBox(*piece, box, name, store, read, fs::path(file).filename().string());
        }
    }
    store.checkCovered();
    v.validate();
    return v;
}

TetMesh readVtkXmlUnstructured(const fs::path& path, const std::string& scalar)
{
    fileSize(path);
    CapturedRead read(path);
    const std::string ext = extensionOf(path);
    vtkSmartPointer<vtkAlgorithm> reader;
    if (ext == ".vtu") {
        auto r = vtkSmartPointer<vtkXMLUnstructuredGridReader>::New();
        r->SetFileName(path.c_str());
        reader = r;
    } else if (ext == ".pvtu") {
        auto r = vtkSmartPointer<CheckedPUnstructuredReader>::New();
        r->SetFileName(path.c_str());
        r->UpdateInformation();
        read.check();
        if (const std::string missing = r->unreadablePiece(); !missing.empty())
            read.fail("its piece " + missing + " cannot be read (missing or not a .vtu file)");
        reader = r;
    } else {
        throw InternalError("readVtkXmlUnstructured: " + path.string() + " is not .vtu or .pvtu");
    }
    try {
        reader->Update();
    } catch (const std::bad_alloc&) {
        read.fail("out of host memory while reading");
    }
    read.check();
    vtkUnstructuredGrid* grid = vtkUnstructuredGrid::SafeDownCast(reader->GetOutputDataObject(0));
    if (!grid || !grid->GetPoints() || grid->GetNumberOfPoints() == 0)
        read.fail("no points");
    if (grid->GetNumberOfCells() == 0)
        read.fail("no cells");
    vtkDataArray* array = pointScalar(*grid, scalar, read);
    const vtkIdType nPoints = grid->GetNumberOfPoints(), nCells = grid->GetNumberOfCells();
    if (array->GetNumberOfTuples() != nPoints)
        read.fail("point array \"" + std::string(array->GetName() ? array->GetName() : "") + "\" has " +
                  std::to_string(array->GetNumberOfTuples()) + " values for " + std::to_string(nPoints) + " points");
    if (nPoints > std::numeric_limits<std::uint32_t>::max())
        read.fail(std::to_string(nPoints) + " points, more than clvr's 32-bit point indices hold");

    TetMesh mesh;
    mesh.source = path.string();
    mesh.points.resize(static_cast<std::size_t>(nPoints));
    mesh.scalars.resize(static_cast<std::size_t>(nPoints));
    for (vtkIdType i = 0; i < nPoints; ++i) {
        double p[3];
        grid->GetPoint(i, p);
        mesh.points[static_cast<std::size_t>(i)] = glm::dvec3(p[0], p[1], p[2]);
        mesh.scalars[static_cast<std::size_t>(i)] = array->GetComponent(i, 0);
    }
    mesh.tets.reserve(static_cast<std::size_t>(nCells));
    vtkNew<vtkIdList> ids;
    for (vtkIdType c = 0; c < nCells; ++c) {
        const int type = grid->GetCellType(c);
        grid->GetCellPoints(c, ids);
        const vtkIdType k = ids->GetNumberOfIds();
        const vtkIdType need = type == VTK_TETRA ? 4 : (type == VTK_HEXAHEDRON || type == VTK_VOXEL) ? 8 : type == VTK_WEDGE ? 6 : 0;
        if (need == 0)
            read.fail("cell " + std::to_string(c) + " is a " + vtkCellTypes::GetClassNameFromTypeId(type) + " (type " +
                      std::to_string(type) + "); clvr takes tetrahedra, and splits hexahedra, voxels and wedges");
        if (k != need)
            read.fail("cell " + std::to_string(c) + " of type " + std::to_string(type) + " has " + std::to_string(k) +
                      " points, not " + std::to_string(need));
        std::array<std::uint32_t, 8> v{};
        for (vtkIdType i = 0; i < k; ++i) {
            const vtkIdType id = ids->GetId(i);
            if (id < 0 || id >= nPoints)
                read.fail("cell " + std::to_string(c) + " has point index " + std::to_string(id) +
                          ", out of range (the mesh has " + std::to_string(nPoints) + " points)");
            v[static_cast<std::size_t>(i)] = static_cast<std::uint32_t>(id);
        }
        if (type == VTK_TETRA)
            mesh.tets.emplace_back(v[0], v[1], v[2], v[3]);
        else if (type == VTK_HEXAHEDRON)
            splitHex(v, mesh.tets);
        else if (type == VTK_VOXEL)  // a voxel's points in x-fastest order: 0 1 3 2 / 4 5 7 6 as a hexahedron
            splitHex({v[0], v[1], v[3], v[2], v[4], v[5], v[7], v[6]}, mesh.tets);
        else
            splitWedge({v[0], v[1], v[2], v[3], v[4], v[5]}, mesh.tets);
    }
    mesh.tetsRead = mesh.tets.size();
    return mesh;
}

#endif  // CLVR_HAVE_VTK

}  // namespace clvr
