// kernels/util.cl — buffer fills used by clears and tests, and a probe of clvr_exp2 for its test.
#include "clvr_common.h"

kernel void fill_float4(global float4* dst, const float4 value, const uint n)
{
    CLVR_GUARD_1D(n);
    dst[get_global_id(0)] = value;
}

kernel void fill_float(global float* dst, const float value, const uint n)
{
    CLVR_GUARD_1D(n);
    dst[get_global_id(0)] = value;
}

kernel void fill_uchar(global uchar* dst, const uchar value, const uint n)
{
    CLVR_GUARD_1D(n);
    dst[get_global_id(0)] = value;
}

/* out[0] = how many of n iterations a loop runs (Device::loopIterationCap). Each iteration reads memory,
 * so no compiler can fold the loop; ones[] holds 16 ones. */
kernel void loop_iterations(global uint* out, global const uint* ones, const uint n)
{
    if (get_global_id(0) != 0)
        return;
    uint k = 0u;
    for (uint i = 0u; i < n; ++i)
        k += ones[i & 15u];
    out[0] = k;
}

/* out[i] = clvr_exp2(x[i]) (tests/device_test.cpp against the host's exp2). */
kernel void exp2_values(global float* out, global const float* x, const uint n)
{
    CLVR_GUARD_1D(n);
    out[get_global_id(0)] = clvr_exp2(x[get_global_id(0)]);
}

/* out[i] = clvr_atan2(y[i], x[i]) (tests/device_test.cpp against the host's atan2). */
kernel void atan2_values(global float* out, global const float* y, global const float* x, const uint n)
{
    CLVR_GUARD_1D(n);
    out[get_global_id(0)] = clvr_atan2(y[get_global_id(0)], x[get_global_id(0)]);
}
