// host/model/transfer_function.cpp — validation and evaluation of the piecewise-linear transfer function.
#include "host/model/transfer_function.h"

#include "host/runtime/errors.h"

#include <algorithm>
#include <cmath>
#include <string>

namespace clvr {

TransferFunction::TransferFunction(std::vector<ControlPoint> points) : points_(std::move(points))
{
    if (points_.size() < 2)
        throw InputError("transfer_function: needs at least two control points, got " + std::to_string(points_.size()));
    // Kernels walk the control points a ray segment crosses (harc splits every segment at them): the
    // bound keeps a hostile scene from making each sample cost millions of steps.
    if (points_.size() > kMaxControlPoints)
        throw InputError("transfer_function: " + std::to_string(points_.size()) + " control points, at most " +
                         std::to_string(kMaxControlPoints));
    for (std::size_t i = 0; i < points_.size(); ++i) {
        const ControlPoint& p = points_[i];
        const std::string where = "transfer_function: point " + std::to_string(i);
        if (!std::isfinite(p.s) || !std::isfinite(p.tau) || !std::isfinite(p.color.r) || !std::isfinite(p.color.g) ||
            !std::isfinite(p.color.b))
            throw InputError(where + " has a NaN or infinite value");
        if (p.tau < 0.0)
            throw InputError(where + " has negative extinction tau " + std::to_string(p.tau));
        for (int c = 0; c < 3; ++c)
            if (p.color[c] < 0.0 || p.color[c] > 1.0)
                throw InputError(where + " has a color component outside [0, 1]");
        if (i > 0 && !(p.s > points_[i - 1].s))
            throw InputError(where + ": s values must increase strictly (" + std::to_string(points_[i - 1].s) +
                             " then " + std::to_string(p.s) + ")");
    }
}

glm::dvec4 TransferFunction::operator()(double s) const
{
    auto value = [](const ControlPoint& p) { return glm::dvec4(p.color, p.tau); };
    if (!(s > points_.front().s))
        return value(points_.front());
    if (s >= points_.back().s)
        return value(points_.back());
    const auto hi = std::upper_bound(points_.begin(), points_.end(), s,
                                     [](double v, const ControlPoint& p) { return v < p.s; });
    const auto lo = hi - 1;
    const double t = (s - lo->s) / (hi->s - lo->s);
    return glm::mix(value(*lo), value(*hi), t);
}

}  // namespace clvr
