// tests/data_spec_test.cpp — the scene's "volume" and "mesh" as VolumeSpec / MeshSpec (host/model/data_spec.h):
// parseScene fills the typed fields (paths resolved against the scene's folder) and rejects a malformed
// spec with loadVolume's / loadMesh's message before any file is read.
#include "host/model/scene.h"
#include "host/runtime/errors.h"

#include <gtest/gtest.h>

#include <string>

namespace {

using clvr::InputError;
using clvr::MeshSpec;
using clvr::Scene;
using clvr::VolumeSpec;
namespace fs = std::filesystem;

const std::string kTf = R"("transfer_function": {"points": [[0, 0,0,0, 0], [1, 1,1,1, 4]]})";

// The scene {"volume"|"mesh": spec, transfer_function}, in the folder /no/such/scenes (nothing to read).
Scene parseWith(const std::string& key, const std::string& spec)
{
    return clvr::parseScene("{\"" + key + "\": " + spec + ", " + kTf + "}", "scene.json", "/no/such/scenes");
}

// The InputError message of parseWith; fails the test when there is none.
std::string errorOf(const std::string& key, const std::string& spec)
{
    try {
        parseWith(key, spec);
    } catch (const InputError& e) {
        return e.what();
    }
    ADD_FAILURE() << "no error for " << key << ": " << spec;
    return {};
}

TEST(DataSpec, GeneratorHoldsNameAndDims)
{
    const Scene s = parseWith("volume", R"({"generator": "blobs", "dims": [4, 5, 6]})");
    ASSERT_TRUE(s.volume.has_value());
    EXPECT_EQ(s.volume->kind, VolumeSpec::Kind::Generator);
    EXPECT_EQ(s.volume->generator, "blobs");
    EXPECT_EQ(s.volume->dims, glm::ivec3(4, 5, 6));
    EXPECT_FALSE(s.mesh.has_value());
}

TEST(DataSpec, FilesAreResolvedAgainstTheSceneFolder)
{
    const Scene nrrd = parseWith("volume", R"({"file": "ct/head.nhdr"})");
    EXPECT_EQ(nrrd.volume->kind, VolumeSpec::Kind::Nrrd);
    EXPECT_EQ(nrrd.volume->file, fs::path("/no/such/scenes/ct/head.nhdr"));
    const Scene vtk = parseWith("volume", R"({"file": "/abs/v.vtk"})");
    EXPECT_EQ(vtk.volume->kind, VolumeSpec::Kind::Vtk);
    EXPECT_EQ(vtk.volume->file, fs::path("/abs/v.vtk"));
    for (const char* name : {"a.vti", "a.PVTI", "a.mhd", "a.mha"}) {
        const Scene v = parseWith("volume", std::string(R"({"file": ")") + name + R"(", "scalar": "rho"})");
        EXPECT_EQ(v.volume->kind, VolumeSpec::Kind::VtkImage) << name;
        EXPECT_EQ(v.volume->scalar, "rho");
    }
    const Scene npy = parseWith("volume", R"({"file": "a.npy", "spacing": [1, 2, 3]})");
    EXPECT_EQ(npy.volume->kind, VolumeSpec::Kind::Npy);
    EXPECT_EQ(npy.volume->raw.spacing, glm::dvec3(1, 2, 3));
    EXPECT_EQ(npy.volume->raw.origin, glm::dvec3(0.0));
    EXPECT_EQ(errorOf("volume", R"({"file": "a.vti", "spacing": [1, 1, 1]})"),
              "volume: unknown key \"spacing\" for a .vti file (allowed: file, scalar)");
    EXPECT_EQ(parseWith("mesh", R"({"file": "m.pvtu"})").mesh->kind, MeshSpec::Kind::File);
}

TEST(DataSpec, RawLayoutHoldsWhatTheSceneSays)
{
    const Scene s = parseWith("volume", R"({"file": "e.bin", "dims": [256, 256, 110], "type": "int16",
        "endian": "big", "spacing": [1, 1, 2.5], "origin": [-1, 0, 3], "header_bytes": 62})");
    ASSERT_EQ(s.volume->kind, VolumeSpec::Kind::Raw);
    EXPECT_EQ(s.volume->file, fs::path("/no/such/scenes/e.bin"));
    const clvr::RawLayout& r = s.volume->raw;
    EXPECT_EQ(r.dims, glm::ivec3(256, 256, 110));
    EXPECT_EQ(r.type, clvr::ScalarType::Int16);
    EXPECT_EQ(r.endian, clvr::Endian::Big);
    EXPECT_EQ(r.spacing, glm::dvec3(1, 1, 2.5));
    EXPECT_EQ(r.origin, glm::dvec3(-1, 0, 3));
    EXPECT_EQ(r.headerBytes, 62u);
}

// Malformed specs fail in parseScene, with the message loadVolume gave when it checked them at load time;
// the files named do not exist, so any read would fail differently.
TEST(DataSpec, MalformedVolumeFailsInParse)
{
    EXPECT_EQ(errorOf("volume", R"({"generator": "marschner-lobb", "dims": [1, 2]})"),
              "volume: \"dims\" must be an array of 3 integers");
    EXPECT_EQ(errorOf("volume", R"({"generator": "sphere", "dims": [8, 8, 8], "spacing": [1, 1, 1]})"),
              "volume: unknown key \"spacing\" for a generator (allowed: generator, dims)");
    EXPECT_EQ(errorOf("volume", R"({"file": "a.nrrd", "generator": "sphere"})"),
              "volume: needs exactly one of \"file\" and \"generator\", has both");
    EXPECT_EQ(errorOf("volume", R"({"file": "a.raw", "dims": [2, 2, 2], "type": "int16"})"),
              "volume: \"endian\" is missing (little or big)");
    EXPECT_EQ(errorOf("volume", R"({"file": "a.raw", "dims": [2, 2, 2], "type": "half"})"),
              "volume: \"type\" is \"half\" (uint8, int8, int16, uint16, int32, uint32, float32 or float64)");
    EXPECT_EQ(errorOf("volume", R"({"file": "a.nrrd", "dims2": 1})"),
              "volume: unknown key \"dims2\" for a .nrrd file (allowed: file)");
    EXPECT_EQ(errorOf("volume", R"({"file": "a.png"})"),
              "/no/such/scenes/a.png: unknown volume format \".png\" (.nrrd, .nhdr, .vtk, .vti, .pvti, .mhd, .mha, .npy, or .raw / any file with \"dims\")");
}

TEST(DataSpec, MeshFileAndPlot3d)
{
    const Scene vtk = parseWith("mesh", R"({"file": "post.vtk", "scalar": 2})");
    ASSERT_TRUE(vtk.mesh.has_value());
    EXPECT_FALSE(vtk.volume.has_value());
    EXPECT_EQ(vtk.mesh->kind, MeshSpec::Kind::File);
    EXPECT_EQ(vtk.mesh->file, fs::path("/no/such/scenes/post.vtk"));
    EXPECT_EQ(vtk.mesh->scalar, "2");
    const Scene p3d = parseWith("mesh", R"({"file": "xyz.bin", "q_file": "/q/q.bin"})");
    EXPECT_EQ(p3d.mesh->kind, MeshSpec::Kind::Plot3d);
    EXPECT_EQ(p3d.mesh->file, fs::path("/no/such/scenes/xyz.bin"));
    EXPECT_EQ(p3d.mesh->qFile, fs::path("/q/q.bin"));
    EXPECT_EQ(p3d.mesh->scalar, "density");  // the PLOT3D default
}

TEST(DataSpec, SurfaceOptions)
{
    const Scene s = parseWith("mesh", R"({"surface": "torus.off", "quality": 1.5, "max_volume": 0.002,
        "scalar": "vol/ct.nrrd"})");
    ASSERT_EQ(s.mesh->kind, MeshSpec::Kind::Surface);
    EXPECT_EQ(s.mesh->surface, fs::path("/no/such/scenes/torus.off"));
    EXPECT_EQ(s.mesh->quality, 1.5);
    EXPECT_EQ(s.mesh->maxVolume, 0.002);
    EXPECT_EQ(s.mesh->scalar, "/no/such/scenes/vol/ct.nrrd");  // a volume file: resolved
    const Scene g = parseWith("mesh", R"({"surface": "torus.off", "scalar": "blobs"})");
    EXPECT_EQ(g.mesh->scalar, "blobs");  // a generator: as written
    EXPECT_EQ(g.mesh->quality, 0.0);
    EXPECT_EQ(parseWith("mesh", R"({"surface": "torus.off"})").mesh->scalar, "sphere");
}

TEST(DataSpec, MalformedMeshFailsInParse)
{
    EXPECT_EQ(errorOf("mesh", R"({"file": "a.vtk", "q": 1})"),
              "scene: mesh.q is not a mesh key (file, q_file, scalar, or surface)");
    EXPECT_EQ(errorOf("mesh", R"({"file": "a.vtk", "scalar": -1})"),
              "scene: mesh.scalar must be a name (string) or an attribute index (non-negative integer)");
    EXPECT_EQ(errorOf("mesh", R"({"file": "xyz.bin"})"),
              "scene: mesh.file /no/such/scenes/xyz.bin looks like a PLOT3D grid: mesh.q_file is missing");
    EXPECT_EQ(errorOf("mesh", R"({"file": "a.obj"})"),
              "/no/such/scenes/a.obj: unknown mesh format \".obj\" (.node, .ele, .vtk, .vtu, .pvtu, .off, or PLOT3D with q_file)");
    EXPECT_EQ(errorOf("mesh", R"({"surface": "t.off", "max_volume": 0})"),
              "scene: mesh.max_volume must be a positive number, got 0");
    EXPECT_EQ(errorOf("mesh", R"({"surface": "t.off", "file": "a.vtk"})"),
              "scene: mesh.file is not a key of a surface mesh (surface, quality, max_volume, scalar)");
}

// --set and --unset act on the JSON before the spec is parsed.
TEST(DataSpec, SetAndUnsetReachTheSpec)
{
    const std::string text = R"({"volume": {"generator": "sphere", "dims": [8, 8, 8]}, "mesh": {"file": "m.vtk"}, )" +
                             kTf + "}";
    const Scene s = clvr::parseScene(text, "scene.json", "/d", {"volume.dims=[2,3,4]"}, {"mesh"});
    EXPECT_EQ(s.volume->dims, glm::ivec3(2, 3, 4));
    EXPECT_FALSE(s.mesh.has_value());
}

}  // namespace
