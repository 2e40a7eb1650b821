// host/cluster/compositor.cpp — IceT's ordered float blend (host/cluster/compositor.h). The calls are
// those ../shared/CLUSTER-NOTES.md measured: one tile displayed on rank 0, no depth, sequential strategy
// with radix-k for the single image.
#include "host/cluster/compositor.h"

#include "host/runtime/errors.h"

#include <IceT.h>
#include <IceTMPI.h>

#include <cstring>
#include <string>

namespace clvr::cluster {

Compositor::Compositor(const World& world, int width, int height) : world_(world), width_(width), height_(height)
{
    IceTCommunicator comm = icetCreateMPICommunicator(MPI_COMM_WORLD);
    IceTContext context = icetCreateContext(comm);
    icetDestroyMPICommunicator(comm);  // the context keeps its own duplicate
    context_ = new IceTContext(context);
    icetDiagnostics(ICET_DIAG_OFF);  // errors come back through icetGetError, as one line of ours
    icetResetTiles();
    icetAddTile(0, 0, width, height, 0);
    icetStrategy(ICET_STRATEGY_SEQUENTIAL);
    icetSingleImageStrategy(ICET_SINGLE_IMAGE_STRATEGY_RADIXK);
    icetSetColorFormat(ICET_IMAGE_COLOR_RGBA_FLOAT);
    icetSetDepthFormat(ICET_IMAGE_DEPTH_NONE);
    icetCompositeMode(ICET_COMPOSITE_MODE_BLEND);
    icetEnable(ICET_ORDERED_COMPOSITE);
}

Compositor::~Compositor()
{
    IceTContext* context = static_cast<IceTContext*>(context_);
    icetDestroyContext(*context);
    delete context;
}

Image4f Compositor::composite(const Image4f& mine, const std::vector<int>& frontToBack)
{
    if (mine.width() != width_ || mine.height() != height_ ||
        frontToBack.size() != static_cast<std::size_t>(world_.size()))
        throw InternalError("Compositor::composite: image size or rank order does not match the compositor");
    icetSetContext(*static_cast<IceTContext*>(context_));
    const std::vector<IceTInt> order(frontToBack.begin(), frontToBack.end());
    icetCompositeOrder(order.data());
    // The view matrices only serve IceT's culling of ranks by their bounds, which clvr does not set.
    const IceTDouble identity[16] = {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1};
    const IceTFloat clear[4] = {0.0f, 0.0f, 0.0f, 0.0f};
    const IceTImage result = icetCompositeImage(mine.pixels().data(), nullptr, nullptr, identity, identity, clear);
    const IceTEnum error = icetGetError();
    if (error != ICET_NO_ERROR)
        throw InternalError("IceT compositing failed (IceT error " + std::to_string(error) + ")");
    if (world_.rank() != 0)
        return Image4f();
    if (icetImageGetWidth(result) != width_ || icetImageGetHeight(result) != height_)
        throw InternalError("IceT returned an image of another size");
    Image4f out(width_, height_);
    std::memcpy(out.pixels().data(), icetImageGetColorcf(result), out.pixelCount() * sizeof(glm::vec4));
    return out;
}

}  // namespace clvr::cluster
