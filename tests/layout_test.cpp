// tests/layout_test.cpp — the shared host/device layouts (kernels/raster_state.h, kernels/texture.h,
// the kernel parameter structs of kernels/..._params.h and kernels/ray.h): a kernel writes
// sizeof/offsetof of every Cl* struct as the device compiles it; the host compares.
#include "raster/fragment_state.h"
#include "raster/rasterizer.h"
#include "tests/support/test_util.h"

#include "kernels/blend_params.h"
#include "kernels/cubefan_params.h"
#include "kernels/harc_entry_params.h"
#include "kernels/harc_params.h"
#include "kernels/iso3d_params.h"
#include "kernels/pixel_transfer_params.h"
#include "kernels/planes_params.h"
#include "kernels/projtet_params.h"
#include "kernels/ray.h"
#include "kernels/slice3d_params.h"
#include "kernels/spherical_params.h"
#include "kernels/stack2d_params.h"
#include "kernels/tetiso_params.h"
#include "kernels/tetslice_params.h"
#include "kernels/texture.h"

#include <gtest/gtest.h>

#include <cstddef>
#include <string>
#include <vector>

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
        {"sizeof(ClRasterPass)", sizeof(ClRasterPass)},
        {"sizeof(ClTexture)", sizeof(ClTexture)},
        {"offsetof(ClTexture, border)", offsetof(ClTexture, border)},
        {"offsetof(ClTriangle, col_min)", offsetof(ClTriangle, col_min)},
        {"offsetof(ClTriangle, row_max)", offsetof(ClTriangle, row_max)},
        {"offsetof(ClRasterPass, triangle_base)", offsetof(ClRasterPass, triangle_base)},
        {"offsetof(ClRasterPass, fragment)", offsetof(ClRasterPass, fragment)},
        {"offsetof(ClRasterPass, blend)", offsetof(ClRasterPass, blend)},
        {"offsetof(ClRasterPass, item_h_log2)", offsetof(ClRasterPass, item_h_log2)},
    };
    for (std::size_t i = 0; i < std::size(want); ++i)
        EXPECT_EQ(got[i], want[i].second) << want[i].first << ": device " << got[i] << ", host " << want[i].second;
    EXPECT_EQ(got[std::size(want)], 0xffffffffu) << "the probe wrote more entries than the host checks";
}

// kernels/params_layout.h on the host: (what, sizeof or offsetof) in the list's order.
struct LayoutEntry {
    std::string what;
    std::size_t bytes;
};

std::vector<LayoutEntry> hostParamsLayout()
{
    return {
#define CLVR_LAYOUT_SIZE(T) {"sizeof(" #T ")", sizeof(T)},
#define CLVR_LAYOUT_FIELD(T, f) {"offsetof(" #T ", " #f ")", offsetof(T, f)},
#include "kernels/params_layout.h"
#undef CLVR_LAYOUT_SIZE
#undef CLVR_LAYOUT_FIELD
    };
}

TEST(Layout, DeviceAndHostAgreeOnEveryParamsStruct)
{
    clvr::Device& device = clvr::test::device();
    const std::vector<LayoutEntry> want = hostParamsLayout();
    cl::Kernel k = device.kernel("layout_probe.cl", "params_layout_probe");
    const std::vector<cl_uint> init(want.size() + 2, 0xffffffffu);
    cl::Buffer out = device.upload("params layout probe", init, CL_MEM_READ_WRITE);
    k.setArg(0, out);
    device.launch("params layout probe", k, 1);
    const std::vector<cl_uint> got = device.download<cl_uint>(out, init.size());
    device.takePassTimes();

    ASSERT_EQ(got[0], want.size()) << "entries written by the device";
    for (std::size_t i = 0; i < want.size(); ++i)
        EXPECT_EQ(got[i + 1], want[i].bytes) << want[i].what << ": device " << got[i + 1] << ", host " << want[i].bytes;
    EXPECT_EQ(got[want.size() + 1], 0xffffffffu) << "the probe wrote past its entries";
}

// Each params struct travels as one by-value argument next to the kernel's buffers: the whole argument
// list must fit CL_DEVICE_MAX_PARAMETER_SIZE (at least 1024 bytes in OpenCL 1.2; buffers count as
// pointers).
TEST(Layout, EveryParamsStructFitsTheKernelArgumentSpace)
{
    const std::size_t limit = clvr::test::device().device().getInfo<CL_DEVICE_MAX_PARAMETER_SIZE>();
    const std::pair<const char*, std::size_t> argumentBytes[] = {
        {"slice3d_fused", sizeof(ClSlice3dParams) + 8 * sizeof(void*)},
        {"planes_render", sizeof(ClPlanesParams) + 7 * sizeof(void*)},
        {"blend_render", sizeof(ClBlendParams) + 6 * sizeof(void*)},
        {"harc_render", sizeof(ClHarcParams) + 9 * sizeof(void*)},
        {"spherical_shell", sizeof(ClSphericalParams) + 5 * sizeof(void*)},
        {"spherical_fused", sizeof(ClSphericalFusedParams) + 5 * sizeof(void*)},
        {"slice3d_over_background", sizeof(ClSlice3dOverBackgroundParams) + 1 * sizeof(void*)},
        {"iso3d_finish", sizeof(ClIso3dFinishParams) + 2 * sizeof(void*)},
        {"iso3d_fused", sizeof(ClIso3dFusedParams) + 6 * sizeof(void*)},
        {"stack2d_iso_finish", sizeof(ClStack2dIsoFinishParams) + 2 * sizeof(void*)},
        {"stack2d_fused", sizeof(ClStack2dFusedParams) + 8 * sizeof(void*)},
        {"pixel_transfer", sizeof(ClPixelTransferParams) + 2 * sizeof(void*)},
        {"draw_pixels", sizeof(ClDrawPixelsParams) + 4 * sizeof(void*)},
        {"pixel_texture", sizeof(ClPixelTextureParams) + 2 * sizeof(void*)},
        {"accum", sizeof(ClAccumParams) + 2 * sizeof(void*)},
        {"tetslice_composite", sizeof(ClTetsliceCompositeParams) + 4 * sizeof(void*)},
        {"tetiso_weights", sizeof(ClTetisoParams) + 3 * sizeof(void*)},
        {"cubefan_fused", sizeof(ClCubefanFusedParams) + 7 * sizeof(void*)},
        {"projtet_fused", sizeof(ClProjtetFusedParams) + 8 * sizeof(void*)},
    };
    for (const auto& [kernel, bytes] : argumentBytes) {
        EXPECT_LE(bytes, limit) << kernel;
        EXPECT_LE(bytes, 1024u) << kernel << ": over OpenCL 1.2's guaranteed minimum";
    }
    // The sizes the headers document (a field added without its padding shows here first).
    EXPECT_EQ(sizeof(ClCamera), 80u);
    EXPECT_EQ(sizeof(ClSlice3dParams), 416u);
    EXPECT_EQ(sizeof(ClPlanesParams), 288u);
    EXPECT_EQ(sizeof(ClBlendParams), 256u);
    EXPECT_EQ(sizeof(ClHarcParams), 256u);
    EXPECT_EQ(sizeof(ClSphericalParams), 192u);
    EXPECT_EQ(sizeof(ClSphericalFusedParams), 288u);
    EXPECT_EQ(sizeof(ClSlice3dOverBackgroundParams), 32u);
    EXPECT_EQ(sizeof(ClTetsliceCompositeParams), 112u);
    EXPECT_EQ(sizeof(ClTetisoParams), 32u);
    EXPECT_EQ(sizeof(ClIso3dFinishParams), 48u);
    EXPECT_EQ(sizeof(ClIso3dFusedParams), 240u);
    EXPECT_EQ(sizeof(ClCubefanFusedParams), 192u);
    EXPECT_EQ(sizeof(ClProjtetFusedParams), 128u);
    EXPECT_EQ(sizeof(ClStack2dIsoFinishParams), 32u);
    EXPECT_EQ(sizeof(ClStack2dFusedParams), 384u);
    EXPECT_EQ(sizeof(ClPixelTransfer), 128u);
    EXPECT_EQ(sizeof(ClPixelTransferParams), 144u);
    EXPECT_EQ(sizeof(ClDrawPixelsParams), 208u);
    EXPECT_EQ(sizeof(ClPixelTextureParams), 64u);
    EXPECT_EQ(sizeof(ClAccumParams), 12u);
    // Fragment-program uniforms: float4s only, within the raster stage's uniform count.
    EXPECT_EQ(sizeof(ClSlice3dUniforms), 176u);
    EXPECT_EQ(sizeof(ClIso3dUniforms), 112u);
    EXPECT_EQ(sizeof(ClHarcEntryUniforms), 96u);
    EXPECT_EQ(sizeof(ClStack2dUniforms), 368u);
    for (const std::size_t bytes : {sizeof(ClSlice3dUniforms), sizeof(ClIso3dUniforms), sizeof(ClHarcEntryUniforms),
                                    sizeof(ClStack2dUniforms)})
        EXPECT_LE(bytes, CLVR_MAX_UNIFORMS * sizeof(cl_float4));
}

}  // namespace
