// host/cluster/bricks.cpp — a volume in bricks on one device (host/cluster/bricks.h).
#include "host/cluster/bricks.h"

#include "host/cluster/partition.h"
#include "host/runtime/errors.h"

#include <chrono>
#include <string>
#include <utility>
#include <vector>

namespace clvr {

namespace {

class BrickedRenderer : public Renderer {
public:
    BrickedRenderer(Device& device, const Scene& scene, const Volume& volume)
        : background_(scene.image.background)
    {
        const TechniqueInfo& t = technique(scene.technique);
        if (!t.sortLast)
            throw InternalError("makeBrickedRenderer: " + t.name + " does not render a part");
        Scene partScene = scene;
        partScene.image.background = glm::dvec3(0.0);  // premultiplied bricks; the background goes on last
        std::string lastError;  // why the last brick count did not fit
        for (int n = 2;; n *= 2) {
            GridPartition partition;
            try {
                partition = partitionGrid(volume.dims, volume.origin, volume.spacing, n);
            } catch (const InputError&) {
                throw DeviceError("out of device memory: " + volume.source + " does not fit " + device.listing().name +
                                  " even in " + std::to_string(n / 2) + " bricks (" + lastError + ")");
            }
            bricks_.clear();
            try {
                for (int p = 0; p < n; ++p) {
                    Brick b;
                    b.volume = cutGridPart(volume, partition, p, t.sortLastGhost);
                    bricks_.push_back(std::move(b));
                    bricks_.back().renderer = makeRenderer(device, partScene, bricks_.back().volume);
                }
            } catch (const DeviceError& e) {
                if (!isOutOfDeviceMemory(e))
                    throw;
                lastError = e.what();
                continue;  // smaller bricks
            }
            tree_ = partition.tree;
            camera_ = *scene.camera;
            return;
        }
    }

    Image4f render(FrameStats& stats) override
    {
        const auto t0 = std::chrono::steady_clock::now();
        std::vector<Image4f> images;
        images.reserve(bricks_.size());
        stats = FrameStats{};
        for (Brick& b : bricks_) {
            FrameStats s;
            images.push_back(b.renderer->render(s));
            stats.samples += s.samples;
            stats.passes.insert(stats.passes.end(), s.passes.begin(), s.passes.end());
            if (stats.extra.empty())
                stats.extra = s.extra;  // the first brick's counts, for their keys
        }
        std::vector<const Image4f*> ordered;
        for (int p : tree_.frontToBack(camera_))
            ordered.push_back(&images[static_cast<std::size_t>(p)]);
        Image4f image = compositeOver(ordered);
        addBackground(image, background_);
        stats.extra["volume_parts"] = bricks_.size();
        stats.frameMs = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
        return image;
    }

    std::uint64_t residentBytes() const override
    {
        std::uint64_t bytes = 0;
        for (const Brick& b : bricks_)
            bytes += b.renderer->residentBytes();
        return bytes;
    }

    void setTransferFunction(const TransferFunction& tf) override
    {
        for (Brick& b : bricks_)
            b.renderer->setTransferFunction(tf);
    }

    bool setCamera(const Scene& scene) override
    {
        Scene partScene = scene;
        partScene.image.background = glm::dvec3(0.0);
        for (Brick& b : bricks_)
            if (!b.renderer->setCamera(partScene))
                return false;  // the caller makes a new renderer
        camera_ = *scene.camera;
        background_ = scene.image.background;
        return true;
    }

private:
    struct Brick {
        Volume volume;
        std::unique_ptr<Renderer> renderer;
    };
    std::vector<Brick> bricks_;
    KdTree tree_;
    Camera camera_;
    glm::dvec3 background_;
};

}  // namespace

bool isOutOfDeviceMemory(const DeviceError& error)
{
    return std::string(error.what()).find("out of device memory") != std::string::npos;
}

std::unique_ptr<Renderer> makeBrickedRenderer(Device& device, const Scene& scene, const Volume& volume)
{
    return std::make_unique<BrickedRenderer>(device, scene, volume);
}

}  // namespace clvr
