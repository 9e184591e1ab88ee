#include "kauri/render/light_aa.h"

#include <algorithm>
#include <cmath>

namespace kauri {

namespace {

/// World-space bounds of an area light: a triangle's corners, or a sphere or disk's
/// centre ± its bounding radius (which covers an instance's non-uniform scale, where
/// `radius` is an average).
void area_light_box(const Light& l, Point3* lo, Point3* hi) {
  if (l.type == LightType::Triangle) {
    *lo = vmin(l.p0, vmin(l.p1, l.p2));
    *hi = vmax(l.p0, vmax(l.p1, l.p2));
    return;
  }
  const Float r = fmax_(l.radius, l.bound_radius);
  *lo = l.p0 - Vec3{r, r, r};
  *hi = l.p0 + Vec3{r, r, r};
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

/// Where a lamp can appear on the film.
enum class LampReach { Nowhere, Rect, Everywhere };
struct PixelRect {
  int x0, y0, x1, y1;  // inclusive
};

/// Whether a distant light's cone can meet a camera ray: its axis (the direction a ray
/// travels to see it, −n) within the half-diagonal field of view plus the cone's angle of
/// the camera's forward axis (orthographic: within the cone's angle).
bool distant_in_view(const Camera& cam, const Light& l) {
  const Vec3 d = normalize(cam.camera_to_world.inverse_vector(-l.n));  // camera space; forward is −z
  const Float cone = std::acos(fmin_(fmax_(l.cos_max, Float(-1)), Float(1)));
  const Float fov = cam.type == CameraType::Orthographic
                        ? Float(0)
                        : std::atan(std::sqrt(sqr(cam.tan_half_x) + sqr(cam.tan_half_y)));
  const Float angle = std::acos(fmin_(fmax_(-d.z, Float(-1)), Float(1)));
  return angle <= fov + cone + Float(1e-3);
}

/// The pixels a lamp's projection can reach (within `margin`), for a pinhole or
/// orthographic camera; Everywhere where it cannot be bounded (a thin lens, a box across
/// the camera's plane, a distant light in view), Nowhere where the camera cannot see it
/// (off screen, wholly behind the camera).
LampReach lamp_reach(const Camera& cam, const Light& l, int width, int height, int margin, PixelRect* rect) {
  if (l.type == LightType::Distant) return distant_in_view(cam, l) ? LampReach::Everywhere : LampReach::Nowhere;
  if (cam.lens_radius > 0) return LampReach::Everywhere;
  Point3 lo, hi;
  area_light_box(l, &lo, &hi);
  Float x0 = kInfinity, y0 = kInfinity, x1 = -kInfinity, y1 = -kInfinity;
  int behind = 0;
  for (int c = 0; c < 8; ++c) {
    const Point3 corner{c & 1 ? hi.x : lo.x, c & 2 ? hi.y : lo.y, c & 4 ? hi.z : lo.z};
    const Point3 pc = cam.camera_to_world.inverse_point(corner);
    Vec2 f;
    if (!raster_position(cam, pc, &f)) {
      ++behind;
      continue;
    }
    x0 = fmin_(x0, f.x), y0 = fmin_(y0, f.y), x1 = fmax_(x1, f.x), y1 = fmax_(y1, f.y);
  }
  if (behind == 8) return LampReach::Nowhere;      // wholly behind a pinhole camera
  if (behind > 0) return LampReach::Everywhere;    // across its plane: unbounded on screen
  // Clamped on both sides before the conversion to int (a box near the camera's plane can
  // project arbitrarily far).
  const Float reach = Float(margin + 1);
  auto clamp_x = [&](Float v) { return fmin_(fmax_(v, -reach), Float(width) + reach); };
  auto clamp_y = [&](Float v) { return fmin_(fmax_(v, -reach), Float(height) + reach); };
  rect->x0 = std::max(0, int(std::floor(clamp_x(x0))) - margin);
  rect->y0 = std::max(0, int(std::floor(clamp_y(y0))) - margin);
  rect->x1 = std::min(width - 1, int(std::floor(clamp_x(x1))) + margin);
  rect->y1 = std::min(height - 1, int(std::floor(clamp_y(y1))) + margin);
  return rect->x0 > rect->x1 || rect->y0 > rect->y1 ? LampReach::Nowhere : LampReach::Rect;
}

}  // namespace

LightAAMask light_aa_candidates(const SceneView& s, int width, int height, Float spread_share, int margin) {
  LightAAMask m;
  const Camera& cam = s.camera;
  // The threshold from the lamps the camera can see (an unseen sun or a lamp behind the
  // camera would otherwise set the scale for the ones in view).
  Float brightest = 0;
  for (int i = 0; i < s.n_lights; ++i) {
    const Float bright = max_component(lamp_colour(s.lights[i]));
    PixelRect r;
    if (bright > brightest && lamp_reach(cam, s.lights[i], width, height, margin, &r) != LampReach::Nowhere)
      brightest = bright;
  }
  m.min_spread = spread_share * brightest;
  if (!(brightest > 0)) return m;
  m.pixels.assign(size_t(width) * size_t(height), 0);
  double area = 0;
  for (int i = 0; i < s.n_lights; ++i) {
    const Light& l = s.lights[i];
    const Float bright = max_component(lamp_colour(l));
    if (!(bright > 0) || bright < m.min_spread) continue;
    PixelRect r;
    const LampReach reach = lamp_reach(cam, l, width, height, margin, &r);
    if (reach == LampReach::Nowhere) continue;
    area += reach == LampReach::Everywhere ? double(m.pixels.size())
                                           : double(r.x1 - r.x0 + 1) * double(r.y1 - r.y0 + 1);
    if (reach == LampReach::Everywhere || area > 4.0 * double(m.pixels.size())) {
      std::fill(m.pixels.begin(), m.pixels.end(), uint8_t(1));
      return m;
    }
    for (int y = r.y0; y <= r.y1; ++y)
      std::fill_n(m.pixels.begin() + std::ptrdiff_t(size_t(y) * size_t(width) + size_t(r.x0)), r.x1 - r.x0 + 1,
                  uint8_t(1));
  }
  return m;
}

}  // namespace kauri
