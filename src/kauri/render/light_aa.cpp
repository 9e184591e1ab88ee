#include "kauri/render/light_aa.h"

#include <algorithm>
#include <cmath>

namespace kauri {

namespace {

/// World-space bounds of an area light.
void area_light_box(const Light& l, Point3* lo, Point3* hi) {
  if (l.type == LightType::Triangle) {
    *lo = vmin(l.p0, vmin(l.p1, l.p2));
    *hi = vmax(l.p0, vmax(l.p1, l.p2));
    return;
  }
  const Vec3 r{l.radius, l.radius, l.radius};  // spheres and disks
  *lo = l.p0 - r;
  *hi = l.p0 + r;
}

/// Raster position (pixels, y down) of camera-space point pc: Camera::generate_ray inverted
/// for a pinhole or orthographic camera. False where a perspective camera cannot project
/// it (at or behind the camera's plane).
bool raster_position(const Camera& cam, Point3 pc, Vec2* film) {
  Float sx, sy;
  if (cam.type == CameraType::Orthographic) {
    sx = pc.x / cam.half_w;
    sy = pc.y / cam.half_h;
  } else {
    if (!(pc.z < -1e-6f)) return false;
    sx = pc.x / (-pc.z * cam.tan_half_x);
    sy = pc.y / (-pc.z * cam.tan_half_y);
  }
  *film = {(sx + 1) * Float(cam.width) / 2, (1 - sy) * Float(cam.height) / 2};
  return std::isfinite(film->x) && std::isfinite(film->y);
}

}  // namespace

std::vector<uint8_t> light_aa_candidates(const SceneView& s, int width, int height, Float min_spread, int margin) {
  std::vector<uint8_t> mask(size_t(width) * size_t(height), 0);
  auto everywhere = [&] {
    std::fill(mask.begin(), mask.end(), uint8_t(1));
    return mask;
  };
  const Camera& cam = s.camera;
  double area = 0;
  for (int i = 0; i < s.n_lights; ++i) {
    const Light& l = s.lights[i];
    const Float bright = max_component(lamp_colour(l));
    if (!(bright > 0) || bright < min_spread) continue;
    if (l.is_infinite() || cam.lens_radius > 0) return everywhere();
    Point3 lo, hi;
    area_light_box(l, &lo, &hi);
    Float x0 = kInfinity, y0 = kInfinity, x1 = -kInfinity, y1 = -kInfinity;
    for (int c = 0; c < 8; ++c) {
      const Point3 corner{c & 1 ? hi.x : lo.x, c & 2 ? hi.y : lo.y, c & 4 ? hi.z : lo.z};
      Vec2 f;
      if (!raster_position(cam, cam.camera_to_world.inverse_point(corner), &f)) return everywhere();
      x0 = fmin_(x0, f.x), y0 = fmin_(y0, f.y), x1 = fmax_(x1, f.x), y1 = fmax_(y1, f.y);
    }
    const Float reach = Float(margin + 1);  // off-screen boxes stay off once clamped here
    const int px0 = std::max(0, int(std::floor(fmax_(x0, -reach))) - margin);
    const int py0 = std::max(0, int(std::floor(fmax_(y0, -reach))) - margin);
    const int px1 = std::min(width - 1, int(std::floor(fmin_(x1, Float(width) + reach))) + margin);
    const int py1 = std::min(height - 1, int(std::floor(fmin_(y1, Float(height) + reach))) + margin);
    if (px0 > px1 || py0 > py1) continue;  // off screen
    area += double(px1 - px0 + 1) * double(py1 - py0 + 1);
    if (area > 4.0 * double(mask.size())) return everywhere();
    for (int y = py0; y <= py1; ++y) std::fill_n(mask.begin() + std::ptrdiff_t(size_t(y) * size_t(width) + size_t(px0)), px1 - px0 + 1, uint8_t(1));
  }
  return mask;
}

}  // namespace kauri
