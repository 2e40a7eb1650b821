// host/render/renderer.cpp — the technique registry (each technique's entry comes from its own file,
// next to its option parser) and the factories makeRenderer and makeMeshRenderer.
#include "host/render/renderer.h"

#include "host/runtime/errors.h"
#include "host/render/grid/blend.h"
#include "host/render/grid/cubefan.h"
#include "host/render/tet/harc.h"
#include "host/render/tet/projtet.h"
#include "host/render/tet/tetiso.h"
#include "host/render/tet/tetslice.h"
#include "host/render/grid/iso3d.h"
#include "host/render/grid/planes.h"
#include "host/render/grid/slice3d.h"
#include "host/render/grid/spherical.h"
#include "host/render/grid/stack2d.h"

namespace clvr {
namespace {

[[noreturn]] void sortLastUnsupported(const TechniqueInfo& t)
{
    std::string able;
    for (const TechniqueInfo& other : techniques())
        if (other.sortLast)
            able += (able.empty() ? "" : ", ") + other.name;
    throw InputError("technique " + t.name + " does not render a part of a data set (sort-last renders " + able +
                     "); use --distribution sort-first (every rank renders image rows of the whole data) or frames");
}

std::string joined(const std::vector<std::string>& names)
{
    std::string out;
    for (const std::string& name : names)
        out += (out.empty() ? "" : ", ") + name;
    return out;
}

std::vector<std::string> namesOf(DataKind kind)
{
    std::vector<std::string> names;
    for (const TechniqueInfo& t : techniques())
        if (t.data == kind)
            names.push_back(t.name);
    return names;
}

[[noreturn]] void unknownTechnique(const std::string& name)
{
    throw InputError("technique: unknown technique \"" + name + "\" (known: " + joined(techniqueNames()) + ")");
}

}  // namespace

const char* dataKindName(DataKind kind)
{
    return kind == DataKind::Volume ? "volume" : "mesh";
}

const OptionInfo* TechniqueInfo::option(const std::string& key) const
{
    for (const OptionInfo& o : options)
        if (o.name == key)
            return &o;
    return nullptr;
}

std::string TechniqueInfo::optionList() const
{
    std::vector<std::string> names;
    for (const OptionInfo& o : options)
        names.push_back(o.name);
    return joined(names);
}

const std::vector<TechniqueInfo>& techniques()
{
    static const std::vector<TechniqueInfo> all = {slice3dTechnique(), stack2dTechnique(), iso3dTechnique(),
                                                   planesTechnique(),  blendTechnique(),   sphericalTechnique(),
                                                   harcTechnique(),    tetsliceTechnique(), tetisoTechnique(),
                                                   projtetTechnique(),  cubefanTechnique()};
    return all;
}

const TechniqueInfo* findTechnique(const std::string& name)
{
    for (const TechniqueInfo& t : techniques())
        if (t.name == name)
            return &t;
    return nullptr;
}

const TechniqueInfo& technique(const std::string& name)
{
    if (const TechniqueInfo* t = findTechnique(name))
        return *t;
    throw InternalError("technique \"" + name + "\" is not in the registry");
}

std::vector<std::string> techniqueNames()
{
    std::vector<std::string> names;
    for (const TechniqueInfo& t : techniques())
        names.push_back(t.name);
    return names;
}

std::unique_ptr<Renderer> makeRenderer(Device& device, const Scene& scene, const Volume& volume)
{
    const TechniqueInfo* t = findTechnique(scene.technique);
    if (!t)
        unknownTechnique(scene.technique);
    if (t->data != DataKind::Volume)
        throw InputError("technique " + t->name + " needs a tetrahedral \"mesh\", and the scene has none");
    if (volume.voxelCount() == 0)
        throw InputError("technique " + t->name + " needs a regular-grid \"volume\", and the scene has none");
    if (volume.part && !t->sortLast)
        sortLastUnsupported(*t);
    return t->makeForVolume(device, scene, volume);
}

std::unique_ptr<Renderer> makeMeshRenderer(Device& device, const Scene& scene, const TetMesh& mesh)
{
    const TechniqueInfo* t = findTechnique(scene.technique);
    if (!t)
        throw InputError("technique: unknown technique \"" + scene.technique +
                         "\" (mesh techniques: " + joined(namesOf(DataKind::Mesh)) + ")");
    if (t->data != DataKind::Mesh)
        throw InputError("technique \"" + t->name + "\" renders regular-grid volumes, and the scene has a \"mesh\" " +
                         "(mesh techniques: " + joined(namesOf(DataKind::Mesh)) + ")");
    if (mesh.part && !t->sortLast)
        sortLastUnsupported(*t);
    return t->makeForMesh(device, scene, mesh);
}

}  // namespace clvr
