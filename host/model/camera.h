// host/model/camera.h — the camera of DESIGN.md, as VTK's vtkCamera: position, focal point, view up,
// vertical view angle in degrees (perspective) or parallel scale (half the view height, world units).
// Rays go through pixel centers; image row 0 is the top row.
#pragma once

#include <glm/glm.hpp>

namespace clvr {

struct Ray {
    glm::dvec3 origin;
    glm::dvec3 direction;  // unit length
};

struct Camera {
    glm::dvec3 position{0.0, 0.0, 4.0};
    glm::dvec3 focalPoint{0.0};
    glm::dvec3 viewUp{0.0, 1.0, 0.0};
    double viewAngle = 30.0;  // degrees, vertical
    bool parallel = false;
    double parallelScale = 1.0;
    // Sort-first (docs/cluster.md): the camera renders only rows [bandY0, bandY0 + height) of an image
    // bandFullHeight rows tall, `height` being the height its users pass (ray, PixelRays, projectionMatrix,
    // toClCamera); the pixels are those of the full image's rows. 0: the whole image.
    int bandFullHeight = 0;
    int bandY0 = 0;

    // Throws InputError ("camera: ...") for position == focal point, view_up parallel to the view
    // direction, a view angle outside (0, 180), a parallel scale <= 0, or non-finite values.
    // (The band is set by code, never by a scene: InternalError for a negative one.)
    void validate() const;

    // Orthonormal frame: forward (towards the focal point), right, up (view_up made orthogonal).
    glm::dvec3 forward() const;
    glm::dvec3 right() const;
    glm::dvec3 up() const;

    // The same camera in coordinates whose origin is `origin` (position and focal point moved by -origin): the
    // camera of a renderer that shifts its data there.
    Camera relativeTo(const glm::dvec3& origin) const;

    // The ray through the center of pixel (px, py) of a width x height image (row 0 at the top).
    // PixelRays gives the same rays without recomputing the basis per pixel.
    Ray ray(double px, double py, int width, int height) const;

    // OpenGL-style matrices for the raster stage: world -> eye, eye -> clip (near/far > 0 in eye units).
    glm::dmat4 viewMatrix() const;
    glm::dmat4 projectionMatrix(int width, int height, double near, double far) const;

    // The full image's height for a band, else `height` itself.
    int fullHeight(int height) const { return bandFullHeight > 0 ? bandFullHeight : height; }
};

// The rays of one camera and image size, with the basis (forward, right, up, tan of the half angle)
// computed once: at(px, py) is bit-for-bit Camera::ray(px, py, width, height), which is defined by it.
class PixelRays {
public:
    PixelRays(const Camera& camera, int width, int height);
    Ray at(double px, double py) const;

private:
    glm::dvec3 position_, forward_, right_, up_;
    double width_, height_, aspect_, scale_;  // scale: tan(view_angle / 2), or parallel_scale
    double y0_;                               // the band's first row (0 for the whole image)
    bool parallel_;
};

}  // namespace clvr
