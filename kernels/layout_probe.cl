// kernels/layout_probe.cl — sizes and offsets of the kernel parameter structs as this device compiles
// them (kernels/params_layout.h's list, in its order), for tests/layout_test.cpp to compare with the
// host's. The raster stage's layouts have their own probe in kernels/raster.cl.
#include "blend_params.h"
#include "cubefan_params.h"
#include "harc_entry_params.h"
#include "harc_params.h"
#include "iso3d_params.h"
#include "pixel_transfer_params.h"
#include "planes_params.h"
#include "projtet_params.h"
#include "ray.h"
#include "slice3d_params.h"
#include "spherical_params.h"
#include "stack2d_params.h"
#include "tetiso_params.h"
#include "tetslice_params.h"

/* out[0] = the number of entries n, out[1 .. n] the entries. */
kernel void params_layout_probe(global uint* out)
{
    if (get_global_id(0) != 0)
        return;
    uint n = 0;
#define CLVR_LAYOUT_SIZE(T) out[++n] = (uint)sizeof(T);
#define CLVR_LAYOUT_FIELD(T, f) out[++n] = (uint)__builtin_offsetof(T, f);
#include "params_layout.h"
#undef CLVR_LAYOUT_SIZE
#undef CLVR_LAYOUT_FIELD
    out[0] = n;
}
