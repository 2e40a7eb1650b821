// kernels/util.cl — buffer fills used by clears and tests.
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
