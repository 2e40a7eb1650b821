// tests/layout_test.cpp — the shared host/device layouts (kernels/raster_state.h, kernels/texture.h):
// a kernel writes sizeof/offsetof of every Cl* struct as the device compiles it; the host compares.
#include "raster/fragment_state.h"
#include "raster/rasterizer.h"
#include "tests/support/test_util.h"

#include "kernels/texture.h"

#include <gtest/gtest.h>

#include <cstddef>

namespace {

TEST(Layout, DeviceAndHostAgreeOnEveryClStruct)
{
    clvr::Device& device = clvr::test::device();
    cl::Kernel k = device.kernel("raster.cl", "raster_layout_probe", clvr::raster::kDefaultFragmentProgram);
    const std::vector<cl_uint> init(32, 0xffffffffu);
    cl::Buffer out = device.upload("layout probe", init, CL_MEM_READ_WRITE);
    k.setArg(0, out);
    device.launch("layout probe", k, 1);
    const std::vector<cl_uint> got = device.download<cl_uint>(out, init.size());
    device.takePassTimes();

    const std::pair<const char*, std::size_t> want[] = {
        {"sizeof(ClFragmentState)", sizeof(ClFragmentState)},
        {"offsetof(ClFragmentState, stencil_test)", offsetof(ClFragmentState, stencil_test)},
        {"offsetof(ClFragmentState, stencil_dppass)", offsetof(ClFragmentState, stencil_dppass)},
        {"offsetof(ClFragmentState, alpha_ref)", offsetof(ClFragmentState, alpha_ref)},
        {"offsetof(ClFragmentState, color_mask)", offsetof(ClFragmentState, color_mask)},
        {"sizeof(ClBlendState)", sizeof(ClBlendState)},
        {"offsetof(ClBlendState, color)", offsetof(ClBlendState, color)},
        {"offsetof(ClBlendState, enabled)", offsetof(ClBlendState, enabled)},
        {"offsetof(ClBlendState, dst_alpha)", offsetof(ClBlendState, dst_alpha)},
        {"sizeof(ClTriangle)", sizeof(ClTriangle)},
        {"offsetof(ClTriangle, y)", offsetof(ClTriangle, y)},
        {"offsetof(ClTriangle, bias)", offsetof(ClTriangle, bias)},
        {"offsetof(ClTriangle, front_facing)", offsetof(ClTriangle, front_facing)},
        {"offsetof(ClTriangle, inv_area)", offsetof(ClTriangle, inv_area)},
        {"offsetof(ClTriangle, depth)", offsetof(ClTriangle, depth)},
        {"offsetof(ClTriangle, inv_w)", offsetof(ClTriangle, inv_w)},
        {"offsetof(ClTriangle, attr_over_w)", offsetof(ClTriangle, attr_over_w)},
        {"sizeof(ClTexture)", sizeof(ClTexture)},
        {"offsetof(ClTexture, border)", offsetof(ClTexture, border)},
        {"offsetof(ClTriangle, col_min)", offsetof(ClTriangle, col_min)},
        {"offsetof(ClTriangle, row_max)", offsetof(ClTriangle, row_max)},
    };
    for (std::size_t i = 0; i < std::size(want); ++i)
        EXPECT_EQ(got[i], want[i].second) << want[i].first << ": device " << got[i] << ", host " << want[i].second;
    EXPECT_EQ(got[std::size(want)], 0xffffffffu) << "the probe wrote more entries than the host checks";
}

}  // namespace
