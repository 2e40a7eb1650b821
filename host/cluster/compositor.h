// host/cluster/compositor.h — sort-last compositing with IceT (docs/cluster.md): every rank hands its
// premultiplied float RGBA image, IceT blends them "over" in the given order of ranks (front first,
// ICET_COMPOSITE_MODE_BLEND, ordered, radix-k), and rank 0 gets the image. Built with CLVR_MPI only.
#pragma once

#include "host/cluster/world.h"
#include "host/model/image.h"

#include <vector>

namespace clvr::cluster {

class Compositor {
public:
    // An IceT context on MPI_COMM_WORLD for width x height images. A collective.
    Compositor(const World& world, int width, int height);
    ~Compositor();
    Compositor(const Compositor&) = delete;
    Compositor& operator=(const Compositor&) = delete;

    // Composites every rank's `mine` (premultiplied, no background) in `frontToBack` (every rank once,
    // the same list on every rank). Returns the image on rank 0, an empty image elsewhere. A collective.
    // InternalError when IceT reports an error.
    Image4f composite(const Image4f& mine, const std::vector<int>& frontToBack);

private:
    const World& world_;
    int width_, height_;
    void* context_ = nullptr;  // IceTContext, kept opaque so that only compositor.cpp includes IceT
};

}  // namespace clvr::cluster
