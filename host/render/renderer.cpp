// host/render/renderer.cpp — technique names and the factory makeRenderer.
#include "host/render/renderer.h"

#include "host/errors.h"
#include "host/render/blend.h"
#include "host/render/harc.h"
#include "host/render/iso3d.h"
#include "host/render/planes.h"
#include "host/render/slice3d.h"

namespace clvr {

std::vector<std::string> techniqueNames() { return {"slice3d", "iso3d", "planes", "blend", "harc"}; }

std::unique_ptr<Renderer> makeRenderer(Device& device, const Scene& scene, const Volume& volume)
{
    if (scene.technique == "slice3d") {
        if (volume.values.empty())
            throw InputError("technique slice3d needs a regular-grid \"volume\", and the scene has none");
        return makeSlice3dRenderer(device, scene, volume);
    }
    if (scene.technique == "iso3d") {
        if (volume.values.empty())
            throw InputError("technique iso3d needs a regular-grid \"volume\", and the scene has none");
        return makeIso3dRenderer(device, scene, volume);
    }
    if (scene.technique == "planes") {
        if (volume.values.empty())
            throw InputError("technique planes needs a regular-grid \"volume\", and the scene has none");
        return makePlanesRenderer(device, scene, volume);
    }
    if (scene.technique == "blend") {
        if (volume.values.empty())
            throw InputError("technique blend needs a regular-grid \"volume\", and the scene has none");
        return makeBlendRenderer(device, scene, volume);
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
    if (scene.technique != "slice3d" && scene.technique != "iso3d" && scene.technique != "planes" &&
        scene.technique != "blend")
        throw InputError("technique: unknown technique \"" + scene.technique + "\" (mesh techniques: harc)");
    throw InputError("technique \"" + scene.technique + "\" renders regular-grid volumes, and the scene has a \"mesh\" (mesh techniques: harc)");
}

}  // namespace clvr
