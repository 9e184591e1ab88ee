// Cameras: perspective with thin-lens depth of field, and orthographic.
// Camera space: x right, y up, looking along −z (the USD / OpenGL convention).
#pragma once

#include "kauri/sampler/sampling.h"

namespace kauri {

enum class CameraType : uint8_t { Perspective, Orthographic };

struct Camera {
  CameraType type = CameraType::Perspective;
  Transform camera_to_world;
  int width = 640, height = 480;
  Float tan_half_x = 0.5f, tan_half_y = 0.5f;  // perspective: half-extent of the image plane at z = −1
  Float half_w = 1, half_h = 1;                // orthographic: half-extent in world units
  Float lens_radius = 0;                       // thin lens aperture radius (0 = pinhole)
  Float focus_distance = 1;

  /// Ray through raster position `film` (pixels, y down) and lens sample `u_lens`.
  KAURI_HOST_DEVICE Ray generate_ray(Vec2 film, Vec2 u_lens) const {
    Float sx = 2 * film.x / Float(width) - 1;
    Float sy = 1 - 2 * film.y / Float(height);
    Ray r;
    if (type == CameraType::Orthographic) {
      r.o = {sx * half_w, sy * half_h, 0};
      r.d = {0, 0, -1};
    } else {
      r.o = {0, 0, 0};
      r.d = normalize(Vec3{sx * tan_half_x, sy * tan_half_y, -1});
    }
    if (lens_radius > 0) {
      // Thin lens: rays through the lens converge on the plane of focus.
      Vec2 lens = sample_uniform_disk(u_lens) * lens_radius;
      Float t = focus_distance / -r.d.z;
      Point3 focus = r.o + r.d * t;
      r.o = {r.o.x + lens.x, r.o.y + lens.y, 0};
      r.d = normalize(focus - r.o);
    }
    r.o = camera_to_world.point(r.o);
    r.d = normalize(camera_to_world.vector(r.d));
    return r;
  }
  /// Unit viewing direction (camera −z) in world space, for the depth AOV.
  KAURI_HOST_DEVICE Vec3 forward() const { return normalize(camera_to_world.vector(Vec3{0, 0, -1})); }
};

}  // namespace kauri
