/* kernels/cl_types.h — the host's cl_* scalar and vector type names in OpenCL C, for the kernel
 * parameter structs (kernels/..._params.h) that host and device share. The host gets them from
 * CL/cl_platform.h. No bool, size_t or float3 in a shared struct (STYLE.md §3): their size differs
 * between host and device. Guards as kernels/texture.h's, so that the headers combine in any order.
 * kernels/raster_state.h defines cl_int and cl_float without a guard; a fragment program's params
 * header comes after it (raster.cl first), so those two are left to it then. */
#ifndef CLVR_CL_TYPES_H
#define CLVR_CL_TYPES_H

#ifdef __OPENCL_C_VERSION__
#ifndef CLVR_CL_TYPES
#define CLVR_CL_TYPES
typedef uint cl_uint;
typedef float4 cl_float4;
#endif
#ifndef CLVR_CL_PARAM_TYPES
#define CLVR_CL_PARAM_TYPES
#ifndef CLVR_RASTER_STATE_H
typedef int cl_int;
typedef float cl_float;
#endif
typedef int4 cl_int4;
#endif
#else
#include <CL/cl_platform.h>
#endif

#endif
