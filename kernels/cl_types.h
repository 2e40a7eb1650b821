/* kernels/cl_types.h — the host's cl_* scalar and vector type names in OpenCL C, for every header whose
 * structs host and device share (raster_state.h, texture.h, ray.h, the kernel parameter structs
 * kernels/..._params.h). The host gets them from CL/cl_platform.h. No bool, size_t or float3 in a shared
 * struct (STYLE.md §3): their size differs between host and device (float3 is 16 bytes in OpenCL, 12 in
 * glm::vec3). */
#ifndef CLVR_CL_TYPES_H
#define CLVR_CL_TYPES_H

#ifdef __OPENCL_C_VERSION__
typedef uint cl_uint;
typedef int cl_int;
typedef ulong cl_ulong;
typedef float cl_float;
typedef float4 cl_float4;
typedef int4 cl_int4;
typedef uint4 cl_uint4;
#else
#include <CL/cl_platform.h>
#endif

#endif
