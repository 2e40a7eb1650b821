// tools/ceiling_stack2d.h — the speed ceiling for stack2d's fused path: kernels/stack2d.cl's stack2d_fused
// for direct volume rendering without shading (each pixel's ray steps through the drawn stack's planes,
// front to back; per plane the ray's point, the box test, the trilinear sample of the stack, the transfer
// function, alpha = 1 - exp(-tau Delta) with the half slabs at the ends, "over"; no empty-space skipping)
// as a plain C++ loop on std::threads over rows. `clvr bench` times it interleaved with clvr on stack2d
// scenes and reports clvr's samples/s as a fraction of its (docs/benchmarks.md). Not part of the library;
// tests/bench_test.cpp checks its image and samples against the kernel's.
#pragma once

#include "host/model/camera.h"
#include "host/model/image.h"
#include "host/model/scene.h"
#include "host/model/transfer_function.h"
#include "host/model/volume.h"
#include "host/render/grid/stack2d.h"
#include "tools/ceiling.h"

#include <glm/glm.hpp>

#include <cstdint>

namespace clvr::tools {

class Stack2dCeiling final : public VolumeCeiling {
public:
    // The volume and options as stack2d renders them (the fused path, unshaded, no iso-surface or clip
    // texture: stack2dCeilingFits), the camera it uses (Session::camera), the image.
    Stack2dCeiling(const Volume& volume, const TransferFunction& tf, const Camera& camera, const ImageSpec& image,
                   const Stack2dOptions& options);
    nlohmann::json describe() const override { return {{"axis", axis_}, {"planes", planes_}}; }

private:
    std::uint64_t renderRow(int y, Image4f& image) const override;

    Volume stack_;  // the drawn stack as a volume of (b, c, axis) grid points, as the kernel reads it
    Camera camera_;
    glm::vec3 background_;
    int axis_, planes_;
    float step_, ertAlpha_;
    glm::vec4 toStack_[3];  // world -> stack grid coordinates, rows
    CeilingClassifier classify_;
};

// Whether the ceiling does what the scene's renderer does: the fused path, no lights, no iso, no clip texture.
bool stack2dCeilingFits(const Scene& scene, const Stack2dOptions& options);

}  // namespace clvr::tools
