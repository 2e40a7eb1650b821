/* kernels/clvr_common.h — what every kernel file shares: guards and small math. OpenCL C 1.2. */
#ifndef CLVR_COMMON_H
#define CLVR_COMMON_H

/* Global sizes are padded to the work-group multiple (host/runtime/device.h); kernels return past n. */
#define CLVR_GUARD_1D(n) \
    if (get_global_id(0) >= (size_t)(n)) return
#define CLVR_GUARD_2D(w, h) \
    if (get_global_id(0) >= (size_t)(w) || get_global_id(1) >= (size_t)(h)) return

#endif
