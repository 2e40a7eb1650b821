// host/model/transfer_function.h — the piecewise-linear transfer function of DESIGN.md: control points
// (s, r, g, b, tau), s in data units, r,g,b emitted color in [0,1], tau >= 0 extinction per world
// unit. Outside [s_first, s_last] the end points' values hold (as VTK's piecewise functions clamp).
#pragma once

#include <glm/glm.hpp>

#include <cstddef>
#include <vector>

namespace clvr {

struct ControlPoint {
    double s = 0.0;
    glm::dvec3 color{0.0};  // emitted r, g, b in [0, 1]
    double tau = 0.0;       // extinction per world unit
};

inline constexpr std::size_t kMaxControlPoints = 4096;

class TransferFunction {
public:
    TransferFunction() = default;
    // Throws InputError for fewer than two or more than kMaxControlPoints points, unsorted (or repeated)
    // s, NaN or infinite values, colors outside [0,1] or negative tau.
    explicit TransferFunction(std::vector<ControlPoint> points);

    const std::vector<ControlPoint>& points() const { return points_; }
    double sMin() const { return points_.front().s; }
    double sMax() const { return points_.back().s; }

    // (r, g, b, tau) at data value s.
    glm::dvec4 operator()(double s) const;

private:
    std::vector<ControlPoint> points_;
};

}  // namespace clvr
