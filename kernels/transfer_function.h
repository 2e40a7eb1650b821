/* kernels/transfer_function.h — the piecewise-linear transfer function of DESIGN.md on the device:
 * control points (s, r, g, b, tau), evaluated exactly (no table): the end points' values hold
 * outside [s_0, s_{n-1}], as host/transfer_function.h does. OpenCL C 1.2.
 * Layout of the float buffer (host: packTransferFunction in host/render/slice3d.h):
 *   tf[0 .. n)            s_i, increasing
 *   tf[m + 4i .. m + 4i+4) (r, g, b, tau)_i,  m = n rounded up to a multiple of 4 (vload4 alignment) */
#ifndef CLVR_TRANSFER_FUNCTION_H
#define CLVR_TRANSFER_FUNCTION_H

/* (r, g, b, tau) at data value x; tau is extinction per world unit. */
float4 clvr_tf_eval(global const float* tf, const int n, const float x)
{
    global const float* rgbt = tf + ((n + 3) & ~3);
    if (!(x > tf[0]))
        return vload4(0, rgbt);
    if (x >= tf[n - 1])
        return vload4(n - 1, rgbt);
    int i = 1;
    while (tf[i] <= x)  /* first s_i > x; terminates because x < s_{n-1} */
        ++i;
    const float t = (x - tf[i - 1]) / (tf[i] - tf[i - 1]);
    const float4 a = vload4(i - 1, rgbt);
    return a + t * (vload4(i, rgbt) - a);
}

#endif
