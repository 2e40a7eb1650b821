// host/render/renderer.cpp — technique names and the factories makeRenderer and makeMeshRenderer.
#include "host/render/renderer.h"

#include "host/runtime/errors.h"
#include "host/render/grid/blend.h"
#include "host/render/tet/harc.h"
#include "host/render/grid/iso3d.h"
#include "host/render/grid/planes.h"
#include "host/render/grid/slice3d.h"
#include "host/render/grid/spherical.h"
#include "host/render/grid/stack2d.h"

#include <functional>

namespace clvr {
namespace {

// The regular-grid techniques, in the order `clvr info` and error messages list them.
struct VolumeTechnique {
    const char* name;
    std::function<std::unique_ptr<Renderer>(Device&, const Scene&, const Volume&)> make;
};

const std::vector<VolumeTechnique>& volumeTechniques()
{
    static const std::vector<VolumeTechnique> techniques = {
        {"slice3d", makeSlice3dRenderer}, {"stack2d", makeStack2dRenderer}, {"iso3d", makeIso3dRenderer},
        {"planes", makePlanesRenderer},   {"blend", makeBlendRenderer},   {"spherical", makeSphericalRenderer},
    };
    return techniques;
}

const VolumeTechnique* findVolumeTechnique(const std::string& name)
{
    for (const VolumeTechnique& t : volumeTechniques())
        if (name == t.name)
            return &t;
    return nullptr;
}

}  // namespace

std::vector<std::string> techniqueNames()
{
    std::vector<std::string> names;
    for (const VolumeTechnique& t : volumeTechniques())
        names.emplace_back(t.name);
    names.emplace_back("harc");
    return names;
}

std::unique_ptr<Renderer> makeRenderer(Device& device, const Scene& scene, const Volume& volume)
{
    if (const VolumeTechnique* t = findVolumeTechnique(scene.technique)) {
        if (volume.values.empty())
            throw InputError("technique " + scene.technique + " needs a regular-grid \"volume\", and the scene has none");
        return t->make(device, scene, volume);
    }
    if (scene.technique == "harc")
        throw InputError("technique harc needs a tetrahedral \"mesh\", and the scene has none");
    std::string known;
    for (const std::string& name : techniqueNames())
        known += (known.empty() ? "" : ", ") + name;
    throw InputError("technique: unknown technique \"" + scene.technique + "\" (known: " + known + ")");
}

std::unique_ptr<Renderer> makeMeshRenderer(Device& device, const Scene& scene, const TetMesh& mesh)
{
    if (scene.technique == "harc")
        return makeHarcRenderer(device, scene, mesh, buildTopology(mesh));
    if (!findVolumeTechnique(scene.technique))
        throw InputError("technique: unknown technique \"" + scene.technique + "\" (mesh techniques: harc)");
    throw InputError("technique \"" + scene.technique +
                     "\" renders regular-grid volumes, and the scene has a \"mesh\" (mesh techniques: harc)");
}

}  // namespace clvr
