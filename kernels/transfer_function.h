/* kernels/transfer_function.h — the piecewise-linear transfer function of DESIGN.md on the device:
 * control points (s, r, g, b, tau), evaluated exactly from its control points (no table; float
 * rounding only), the end points' values held outside [s_0, s_{n-1}] as host/model/transfer_function.h
 * does. OpenCL C 1.2.
 * Layout of the float buffer (host: packTransferFunction in host/render/grid/slice3d.h), m = n rounded
 * up to a multiple of 4 (vload4 alignment):
 *   tf[0 .. n)                  s_i, strictly increasing
 *   tf[m + 4i .. m + 4i + 4)     (r, g, b, tau) at s_i
 *   tf[m + 4n + 4i .. + 4)       slope of segment i, ((r,g,b,tau)_{i+1} - (r,g,b,tau)_i) / (s_{i+1} - s_i)
 *                                (0 for i = n - 1), so that evaluation needs no division */
#ifndef CLVR_TRANSFER_FUNCTION_H
#define CLVR_TRANSFER_FUNCTION_H

/* (r, g, b, tau) at data value x; tau is extinction per world unit. */
float4 clvr_tf_eval(global const float* tf, const int n, const float x)
{
    global const float* value = tf + ((n + 3) & ~3);
    global const float* slope = value + 4 * n;
    if (!(x > tf[0]))
        return vload4(0, value);
    if (x >= tf[n - 1])
        return vload4(n - 1, value);
    int i = 0;
    while (tf[i + 1] <= x) /* s_i <= x < s_{i+1}; terminates because x < s_{n-1} */
        ++i;
    return vload4(i, value) + (x - tf[i]) * vload4(i, slope);
}

#endif
