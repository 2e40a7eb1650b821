// tools/render_output.h — what `clvr render` and its cluster form (tools/cluster_command.cpp) share about
// outputs: the image files a command will write (checked before any work), files written atomically,
// frames removed again when a command fails, and the stderr notes about frame 0.
#pragma once

#include "host/model/image.h"
#include "host/render/renderer.h"
#include "tools/commands.h"

#include <filesystem>
#include <string>
#include <vector>

namespace clvr::tools {

// The file name's extension in lower case (".png").
std::string lowerExtension(const std::filesystem::path& p);

// Writes `text` to `path` through a temporary file in the same folder, renamed into place.
void writeFileAtomically(const std::string& path, const std::string& text);

// The --orbit output pattern: printf-style with exactly one integer conversion. InputError otherwise.
void checkFramePattern(const std::string& pattern);

// Frame k's file name from a pattern checkFramePattern accepted.
std::string framePath(const std::string& pattern, int k);

// The image files the command writes: one, or one per orbit frame; each checked (format, writable
// folder, a name of its own) before anything is rendered. InputError otherwise.
std::vector<std::string> outputPaths(const RenderOptions& options);

// The images a command has written, removed again unless keep() is called: a command that fails leaves
// all its frames or none (an --orbit that fails at frame 3 takes frames 0..2 with it).
class WrittenFiles {
public:
    WrittenFiles() = default;
    WrittenFiles(const WrittenFiles&) = delete;
    WrittenFiles& operator=(const WrittenFiles&) = delete;
    ~WrittenFiles()
    {
        if (kept_)
            return;
        for (const std::string& path : paths_) {
            std::error_code ignored;
            std::filesystem::remove(path, ignored);
        }
    }
    void add(const std::string& path) { paths_.push_back(path); }
    void keep() { kept_ = true; }

private:
    std::vector<std::string> paths_;
    bool kept_ = false;
};

// One stderr note when checkMesh changed the mesh (docs/meshes.md): the counts are in --stats too.
void noteMeshRepairs(const FrameStats& stats);

// One stderr note when frame 0 is empty (alpha 0 in every pixel).
void noteEmptyImage(const Image4f& image, const std::string& technique);

}  // namespace clvr::tools
