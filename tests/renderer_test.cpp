// tests/renderer_test.cpp — the technique registry (host/render/renderer.h): every technique is listed
// with a data kind, a line and its options; a technique accepts exactly the options it lists, and each
// listed default, given explicitly, renders the same bits as leaving the option out.
#include "host/runtime/errors.h"
#include "host/io/generators.h"
#include "host/model/mesh.h"
#include "host/render/renderer.h"
#include "tests/support/test_util.h"

#include <gtest/gtest.h>

#include <set>

namespace clvr {
namespace {

using nlohmann::json;

// An "iso" at `value`, every other key left out (gradient shading, the headlight).
IsoSpec isoAt(double value)
{
    IsoSpec iso;
    iso.value = value;
    return iso;
}

const Volume& sphere17()
{
    static const Volume v = generateVolume("sphere", {17, 17, 17});
    return v;
}

// The cube [-1, 1]^3 as the six tetrahedra around its main diagonal, value x + y + z on the corners.
const TetMesh& cubeMesh()
{
    static const TetMesh mesh = [] {
        TetMesh m;
        m.source = "cube";
        for (int k = 0; k < 8; ++k) {
            const glm::dvec3 p(k & 1 ? 1.0 : -1.0, k & 2 ? 1.0 : -1.0, k & 4 ? 1.0 : -1.0);
            m.points.push_back(p);
            m.scalars.push_back(0.5 + (p.x + p.y + p.z) / 6.0);
        }
        const int perms[6][3] = {{0, 1, 2}, {0, 2, 1}, {1, 0, 2}, {1, 2, 0}, {2, 0, 1}, {2, 1, 0}};
        for (const auto& perm : perms) {
            glm::uvec4 tet(0u);
            unsigned corner = 0;
            for (int s = 0; s < 3; ++s) {
                corner |= 1u << perm[s];
                tet[s + 1] = corner;
            }
            m.tets.push_back(tet);
        }
        m.tetsRead = m.tets.size();
        checkMesh(m);
        return m;
    }();
    return mesh;
}

// A small scene every technique can render: the iso-surface for iso3d and tetiso, lights where they are allowed.
Scene sceneFor(const TechniqueInfo& t, const json& options)
{
    Scene s;
    s.technique = t.name;
    s.camera = test::obliquePerspectiveCamera(40.0);
    s.image = ImageSpec{24, 20, {0.1, 0.2, 0.3}};
    s.transferFunction = TransferFunction({{0.0, {0.2, 0.4, 1.0}, 0.0}, {0.4, {0.3, 0.6, 1.0}, 2.0},
                                           {0.6, {1.0, 0.8, 0.3}, 4.0}, {1.0, {1.0, 0.9, 0.7}, 1.0}});
    s.options = options;
    if (t.name == "iso3d" || t.name == "tetiso")
        s.iso = isoAt(0.5);
    if (t.name == "planes" || t.name == "blend" || t.name == "stack2d")
        s.lighting = test::twoLightLighting();
    return s;
}

Image4f renderWith(const TechniqueInfo& t, const json& options)
{
    const Scene scene = sceneFor(t, options);
    std::unique_ptr<Renderer> renderer = t.data == DataKind::Volume ? makeRenderer(test::device(), scene, sphere17())
                                                                    : makeMeshRenderer(test::device(), scene, cubeMesh());
    FrameStats stats;
    return renderer->render(stats);
}

std::string errorOf(const TechniqueInfo& t, const json& options)
{
    try {
        renderWith(t, options);
    } catch (const InputError& e) {
        return e.what();
    }
    return "no error";
}

TEST(Techniques, RegistryListsNamesKindsLinesAndOptions)
{
    std::set<std::string> names;
    for (const TechniqueInfo& t : techniques()) {
        EXPECT_TRUE(names.insert(t.name).second) << "twice: " << t.name;
        EXPECT_EQ(findTechnique(t.name), &t);
        EXPECT_FALSE(t.description.empty()) << t.name;
        EXPECT_EQ(static_cast<bool>(t.makeForVolume), t.data == DataKind::Volume) << t.name;
        EXPECT_EQ(static_cast<bool>(t.makeForMesh), t.data == DataKind::Mesh) << t.name;
        std::set<std::string> options;
        for (const OptionInfo& o : t.options) {
            EXPECT_TRUE(options.insert(o.name).second) << t.name << " lists " << o.name << " twice";
            EXPECT_FALSE(o.description.empty()) << t.name << "." << o.name;
            EXPECT_EQ(o.description.find('\n'), std::string::npos) << t.name << "." << o.name << ": one line";
            EXPECT_EQ(o.defaultValue.is_null(), !o.defaultText.empty()) << t.name << "." << o.name
                                                                        << ": a default value or a text, not both";
        }
    }
    EXPECT_EQ(techniqueNames().size(), techniques().size());
    EXPECT_EQ(findTechnique("no-such-technique"), nullptr);
    EXPECT_THROW(technique("no-such-technique"), InternalError);
}

TEST(Techniques, UnknownTechniqueListsTheKnownOnes)
{
    Scene s = sceneFor(technique("slice3d"), json::object());
    s.technique = "slice4d";
    try {
        makeRenderer(test::device(), s, sphere17());
        ADD_FAILURE() << "no error";
    } catch (const InputError& e) {
        std::string known;
        for (const std::string& name : techniqueNames())
            known += (known.empty() ? "" : ", ") + name;
        EXPECT_EQ(std::string(e.what()), "technique: unknown technique \"slice4d\" (known: " + known + ")");
    }
}

// Accepted options are listed ones: a key the entry does not list is rejected with the entry's list,
// including options other techniques have.
TEST(Techniques, OptionsNotListedAreRejectedWithTheList)
{
    std::set<std::string> everyOption;
    for (const TechniqueInfo& t : techniques())
        for (const OptionInfo& o : t.options)
            everyOption.insert(o.name);
    everyOption.insert("no_such_option");
    for (const TechniqueInfo& t : techniques()) {
        for (const std::string& key : everyOption) {
            if (t.option(key))
                continue;
            EXPECT_EQ(errorOf(t, {{key, 1}}),
                      "options." + key + ": unknown option for " + t.name + " (known: " + t.optionList() + ")");
        }
    }
}

// Every listed option is accepted with its listed default, and gives the same bits as leaving it out.
TEST(Techniques, ListedDefaultsRenderTheSameImageAsNoOption)
{
    for (const TechniqueInfo& t : techniques()) {
        SCOPED_TRACE(t.name);
        const Image4f plain = renderWith(t, json::object());
        std::size_t covered = 0;
        for (const glm::vec4& p : plain.pixels())
            covered += p.a > 0.0f;
        EXPECT_GT(covered, plain.pixelCount() / 20) << "the data covers too little to tell images apart";
        for (const OptionInfo& o : t.options) {
            if (o.defaultValue.is_null())
                continue;  // the default is derived or "none": defaultText says which
            SCOPED_TRACE(o.name + " = " + o.defaultValue.dump());
            const Image4f given = renderWith(t, {{o.name, o.defaultValue}});
            EXPECT_TRUE(given.pixels() == plain.pixels());
        }
    }
}

}  // namespace
}  // namespace clvr
