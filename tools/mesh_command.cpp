// tools/mesh_command.cpp — `clvr mesh SURFACE -o BASE [--quality Q] [--max-volume V] [--scalar S]`:
// a tetrahedral mesh of a closed surface with TetGen (host/io/tetgen_mesher.h), written as BASE.node and
// BASE.ele that a scene's {"mesh": {"file": "BASE.ele"}} reads back. docs/meshes.md documents it.
#include "host/runtime/errors.h"
#include "host/io/mesh_io.h"
#include "host/io/tetgen_mesher.h"
#include "tools/commands.h"

#include <CLI/CLI.hpp>

#include <iostream>

namespace clvr::tools {

namespace {

struct MeshCommandOptions {
    std::string surface;
    std::string base;
    MesherOptions mesher;
};

MeshCommandOptions& meshOptions()
{
    static MeshCommandOptions options;
    return options;
}

}  // namespace

CLI::App* addMeshCommand(CLI::App& app)
{
    MeshCommandOptions& o = meshOptions();
    CLI::App* mesh = app.add_subcommand("mesh", "tetrahedralize a closed surface with TetGen, write BASE.node/BASE.ele");
    mesh->add_option("surface", o.surface, "closed surface: .poly, .smesh, .off or .stl")->required();
    mesh->add_option("-o,--output", o.base, "output base name: writes BASE.node and BASE.ele")->required();
    mesh->add_option("--quality", o.mesher.quality, "TetGen -q: maximum radius-edge ratio (e.g. 1.414); 0: none")
        ->check(CLI::NonNegativeNumber)
        ->capture_default_str();
    mesh->add_option("--max-volume", o.mesher.maxVolume, "TetGen -a: maximum tetrahedron volume; 0: none")
        ->check(CLI::NonNegativeNumber)
        ->capture_default_str();
    mesh->add_option("--scalar", o.mesher.scalar,
                     "point scalar: a generator (marschner-lobb, sphere, blobs, kernel) evaluated at each point, or a "
                     ".nrrd/.nhdr volume sampled there")
        ->capture_default_str();
    return mesh;
}

int runMeshCommand()
{
    const MeshCommandOptions& o = meshOptions();
    for (const char* ext : {".node", ".ele", ".neigh"})
        checkWritable(o.base + ext, "-o");  // before meshing, as clvr render checks before rendering
    const TetMesh mesh = meshSurface(o.surface, o.mesher);
    writeTetgen(mesh, o.base);
    const glm::dvec2 range = mesh.scalarRange();
    std::cout << "wrote " << o.base << ".node and " << o.base << ".ele: " << mesh.points.size() << " points, "
              << mesh.tets.size() << " tetrahedra (TetGen -" << tetgenSwitches(o.mesher) << "), scalar " << range.x
              << ".." << range.y << "\n";
    if (range.x == range.y)  // e.g. a surface in the empty corner of a volume: not an error, but say it
        std::cerr << "clvr: note: the scalar is " << range.x
                  << " at every point of the mesh (is the surface where the scalar varies?)\n";
    return 0;
}

}  // namespace clvr::tools
