// tools/bench_suites.cpp — the scene files of each `clvr bench --suite` (docs/benchmarks.md). Apart from
// tools/bench.cpp so that tests/bench_test.cpp can compile it in and check the lists against the files.
#include "tools/bench.h"

#include "host/runtime/errors.h"

#include <string>
#include <vector>

namespace clvr::tools {

std::vector<std::string> benchSuiteScenes(const std::string& suite)
{
    const std::vector<std::string> slice3d = {"slice3d-ml256.json", "slice3d-engine.json"};
    const std::vector<std::string> harc = {"harc-bluntfin-10.json", "harc-bluntfin-255.json",
                                           "harc-bluntfin-10-full.json", "harc-tetgen-1m.json"};
    // Resample-then-shade (seeds/004 Tables 1-2), as tools/make_rts_bench.py writes them: planes and blend
    // on each volume with a translucent and an opaque transfer function, then planes on the engine with
    // early termination, and with the skipping of low-opacity samples, turned off.
    std::vector<std::string> rts;
    for (const char* volume : {"engine", "lobster", "ml256"})
        for (const char* kind : {"translucent", "opaque"})
            for (const char* technique : {"planes", "blend"})
                rts.push_back(std::string("rts-") + technique + "-" + volume + "-" + kind + ".json");
    for (const char* kind : {"translucent", "opaque"})
        for (const char* off : {"no-ert", "no-skip"})
            rts.push_back(std::string("rts-planes-engine-") + kind + "-" + off + ".json");
    // The other regular-grid techniques (tools/make_regular_bench.py writes them; its docstring lists them).
    std::vector<std::string> regular;
    for (const char* volume : {"engine", "lobster", "ml256"}) {
        regular.push_back(std::string("reg-iso3d-") + volume + ".json");
        regular.push_back(std::string("reg-iso3d-") + volume + "-raster.json");
        regular.push_back(std::string("reg-iso3d-") + volume + "-bricked.json");
        if (std::string(volume) == "engine")
            regular.push_back("reg-iso3d-engine-gradientless.json");
        for (const char* suffix : {"", "-k1", "-k1-raster", "-k1-p4"})
            regular.push_back(std::string("reg-stack2d-") + volume + suffix + ".json");
        if (std::string(volume) == "engine")
            regular.push_back("reg-stack2d-engine-k1-cliptex.json");
        regular.push_back(std::string("reg-slice3d-raster-") + volume + ".json");
        regular.push_back(std::string("reg-clip-") + volume + ".json");
        regular.push_back(std::string("reg-slice3d-") + volume + ".json");
        regular.push_back(std::string("reg-clipmesh-") + volume + ".json");
        regular.push_back(std::string("reg-cliptex-") + volume + ".json");
    }
    regular.push_back("reg-spherical-atmosphere.json");
    regular.push_back("reg-spherical-atmosphere-raster.json");
    // The cell-face techniques (tools/make_tetfaces_bench.py): seeds/000's Table 1 and cellular automaton,
    // each beside harc on the same scene.
    std::vector<std::string> tetfaces;
    for (const char* mesh : {"fedata0", "fedata1", "fedata2", "fedata3"})
        for (const char* technique : {"tetslice", "fused-tetslice", "harc"})
            tetfaces.push_back(std::string("tetfaces-") + mesh + "-" + technique + ".json");
    for (const char* technique : {"tetiso", "fused-tetiso", "tetslice", "fused-tetslice", "harc"})
        tetfaces.push_back(std::string("tetfaces-automaton-") + technique + ".json");
    // seeds/002 Figure 9 on the engine (tools/make_cubefan_bench.py): error 0, 18 %, 48 % (the fans), 0 and
    // 18 % with each fragment's exact chord, the fused and tile paths at the three tolerances, then slice3d on the
    // same view with 1024 slices (its full quality) and fewer (96-100: 18 %'s image error).
    std::vector<std::string> cubefan;
    for (const char* run : {"e0", "e18", "e48", "x0", "x18", "f0", "f18", "f48", "t0", "t18", "t48"})
        cubefan.push_back(std::string("cubefan-engine-") + run + ".json");
    for (const char* slices : {"1024", "256", "128", "100", "96", "64", "32"})
        cubefan.push_back(std::string("cubefan-slice3d-") + slices + ".json");
    // Cell projection beside the ray caster (issue 11 part 5): each projtet scene is its harc twin with only
    // the technique changed.
    const std::vector<std::string> projtet = {"harc-bluntfin-10.json", "projtet-bluntfin-10.json", "harc-post.json",
                                              "projtet-post.json",     "harc-tetgen-1m.json",      "projtet-tetgen-1m.json"};
    // Time against image error (issue 14 goal 1; tools/make_accuracy_bench.py): slice3d per sample and
    // pre-integrated over slice counts, for --reference (and --peer: VTK at each scene's spacing).
    std::vector<std::string> accuracy;
    for (const char* volume : {"ml256", "engine"}) {
        for (const char* slices : {"64", "96", "128", "144", "192", "256", "512", "1024"})
            accuracy.push_back(std::string("acc-") + volume + "-sample-" + slices + ".json");
        for (const char* slices : {"64", "128", "256", "512"})
            accuracy.push_back(std::string("acc-") + volume + "-pre-" + slices + ".json");
    }
    if (suite == "accuracy")
        return accuracy;
    if (suite == "slice3d")
        return slice3d;
    if (suite == "projtet")
        return projtet;
    if (suite == "cubefan")
        return cubefan;
    if (suite == "harc")
        return harc;
    if (suite == "rts")
        return rts;
    if (suite == "regular")
        return regular;
    if (suite == "tetfaces")
        return tetfaces;
    if (suite == "all") {
        std::vector<std::string> all = slice3d;
        all.insert(all.end(), harc.begin(), harc.end());
        all.insert(all.end(), rts.begin(), rts.end());
        all.insert(all.end(), regular.begin(), regular.end());
        all.insert(all.end(), tetfaces.begin(), tetfaces.end());
        all.insert(all.end(), cubefan.begin(), cubefan.end());
        for (const std::string& name : projtet)  // the harc twins are in the harc list already
            if (name.starts_with("projtet-") || name == "harc-post.json")
                all.push_back(name);
        return all;
    }
    throw InputError("--suite: unknown suite \"" + suite + "\" (known: slice3d, harc, rts, regular, tetfaces, cubefan, projtet, accuracy, all)");
}

}  // namespace clvr::tools
