// host/model/camera.cpp — camera frame, primary rays and GL-style matrices.
#include "host/model/camera.h"

#include "host/runtime/errors.h"

#include <glm/gtc/matrix_transform.hpp>

#include <cmath>

namespace clvr {
namespace {

bool finite(const glm::dvec3& v)
{
    return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z);
}

}  // namespace

void Camera::validate() const
{
    if (!finite(position) || !finite(focalPoint) || !finite(viewUp))
        throw InputError("camera: position, focal_point and view_up must be finite numbers");
    const glm::dvec3 d = focalPoint - position;
    if (glm::length(d) <= 1e-12 * (1.0 + glm::length(position)))
        throw InputError("camera: position equals focal_point, so there is no view direction");
    if (glm::length(viewUp) == 0.0 || glm::length(glm::cross(glm::normalize(d), glm::normalize(viewUp))) < 1e-9)
        throw InputError("camera: view_up is parallel to the view direction (or zero)");
    if (!parallel && !(viewAngle > 0.0 && viewAngle < 180.0))
        throw InputError("camera: view_angle must be in (0, 180) degrees, got " + std::to_string(viewAngle));
    if (parallel && !(parallelScale > 0.0 && std::isfinite(parallelScale)))
        throw InputError("camera: parallel_scale must be > 0, got " + std::to_string(parallelScale));
    if (bandFullHeight < 0 || bandY0 < 0 || (bandFullHeight == 0 && bandY0 != 0))
        throw InternalError("camera: a band must lie in an image of positive height");
}

glm::dvec3 Camera::forward() const { return glm::normalize(focalPoint - position); }
glm::dvec3 Camera::right() const { return glm::normalize(glm::cross(forward(), viewUp)); }
glm::dvec3 Camera::up() const { return glm::cross(right(), forward()); }

Camera Camera::relativeTo(const glm::dvec3& origin) const
{
    Camera c = *this;
    c.position -= origin;
    c.focalPoint -= origin;
    return c;
}

Ray Camera::ray(double px, double py, int width, int height) const
{
    return PixelRays(*this, width, height).at(px, py);
}

PixelRays::PixelRays(const Camera& camera, int width, int height)
    : position_(camera.position), forward_(camera.forward()), right_(camera.right()), up_(camera.up()),
      width_(width), height_(camera.fullHeight(height)), aspect_(width / height_),
      scale_(camera.parallel ? camera.parallelScale : std::tan(glm::radians(camera.viewAngle) * 0.5)),
      y0_(camera.bandY0), parallel_(camera.parallel)
{
}

Ray PixelRays::at(double px, double py) const
{
    // Normalized device coordinates of the pixel center, y up.
    const double ndcX = (px + 0.5) / width_ * 2.0 - 1.0;
    const double ndcY = 1.0 - (py + y0_ + 0.5) / height_ * 2.0;  // y0_ = 0: the whole image
    if (parallel_) {
        const glm::dvec3 origin = position_ + (ndcX * scale_ * aspect_) * right_ + (ndcY * scale_) * up_;
        return {origin, forward_};
    }
    return {position_, glm::normalize(forward_ + (ndcX * scale_ * aspect_) * right_ + (ndcY * scale_) * up_)};
}

glm::dmat4 Camera::viewMatrix() const
{
    return glm::lookAt(position, focalPoint, viewUp);
}

glm::dmat4 Camera::projectionMatrix(int width, int height, double near, double far) const
{
    if (bandFullHeight > 0) {  // an off-centre frustum holding only the band's rows
        const double full = bandFullHeight, aspect = width / full;
        const double top = 1.0 - 2.0 * bandY0 / full, bottom = 1.0 - 2.0 * (bandY0 + height) / full;
        const double s = parallel ? parallelScale : std::tan(glm::radians(viewAngle) * 0.5);
        if (parallel)
            return glm::ortho(-s * aspect, s * aspect, s * bottom, s * top, near, far);
        return glm::frustum(-s * aspect * near, s * aspect * near, s * bottom * near, s * top * near, near, far);
    }
    const double aspect = static_cast<double>(width) / height;
    if (parallel)
        return glm::ortho(-parallelScale * aspect, parallelScale * aspect, -parallelScale, parallelScale, near, far);
    return glm::perspective(glm::radians(viewAngle), aspect, near, far);
}

}  // namespace clvr
