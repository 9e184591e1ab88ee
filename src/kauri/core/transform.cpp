#include <cmath>

#include "kauri/core/math.h"

namespace kauri {

bool make_transform(const double rows[3][4], Transform* out) {
  // Invert the affine matrix [A | t]: inverse is [A⁻¹ | −A⁻¹ t].
  const double (*a)[4] = rows;
  double det = a[0][0] * (a[1][1] * a[2][2] - a[1][2] * a[2][1]) -
               a[0][1] * (a[1][0] * a[2][2] - a[1][2] * a[2][0]) +
               a[0][2] * (a[1][0] * a[2][1] - a[1][1] * a[2][0]);
  if (!std::isfinite(det) || std::fabs(det) < 1e-20) return false;
  double inv[3][3];
  inv[0][0] = (a[1][1] * a[2][2] - a[1][2] * a[2][1]) / det;
  inv[0][1] = (a[0][2] * a[2][1] - a[0][1] * a[2][2]) / det;
  inv[0][2] = (a[0][1] * a[1][2] - a[0][2] * a[1][1]) / det;
  inv[1][0] = (a[1][2] * a[2][0] - a[1][0] * a[2][2]) / det;
  inv[1][1] = (a[0][0] * a[2][2] - a[0][2] * a[2][0]) / det;
  inv[1][2] = (a[0][2] * a[1][0] - a[0][0] * a[1][2]) / det;
  inv[2][0] = (a[1][0] * a[2][1] - a[1][1] * a[2][0]) / det;
  inv[2][1] = (a[0][1] * a[2][0] - a[0][0] * a[2][1]) / det;
  inv[2][2] = (a[0][0] * a[1][1] - a[0][1] * a[1][0]) / det;
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 4; ++c) out->m[r][c] = Float(a[r][c]);
    double t = 0;
    for (int c = 0; c < 3; ++c) {
      out->inv[r][c] = Float(inv[r][c]);
      t -= inv[r][c] * a[c][3];
    }
    out->inv[r][3] = Float(t);
  }
  return true;
}

Transform look_at(Point3 eye, Point3 target, Vec3 up) {
  Vec3 fwd = normalize(target - eye);
  Vec3 right = normalize(cross(fwd, up));
  Vec3 new_up = cross(right, fwd);
  // Columns: camera x = right, y = up, z = −forward.
  double rows[3][4] = {{right.x, new_up.x, -fwd.x, eye.x},
                       {right.y, new_up.y, -fwd.y, eye.y},
                       {right.z, new_up.z, -fwd.z, eye.z}};
  Transform t;
  make_transform(rows, &t);
  return t;
}

Transform compose(const Transform& a, const Transform& b) {
  double rows[3][4];
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 4; ++c) {
      double v = c == 3 ? double(a.m[r][3]) : 0.0;
      for (int k = 0; k < 3; ++k) v += double(a.m[r][k]) * double(b.m[k][c]);
      rows[r][c] = v;
    }
  Transform t;
  make_transform(rows, &t);
  return t;
}

}  // namespace kauri
