#include "lodforge/core/math.h"

namespace lodforge {

Mat4d Mat4d::rotation(double qx, double qy, double qz, double qw) {
  Mat4d r;
  r.at(0, 0) = 1 - 2 * (qy * qy + qz * qz);
  r.at(0, 1) = 2 * (qx * qy - qz * qw);
  r.at(0, 2) = 2 * (qx * qz + qy * qw);
  r.at(1, 0) = 2 * (qx * qy + qz * qw);
  r.at(1, 1) = 1 - 2 * (qx * qx + qz * qz);
  r.at(1, 2) = 2 * (qy * qz - qx * qw);
  r.at(2, 0) = 2 * (qx * qz - qy * qw);
  r.at(2, 1) = 2 * (qy * qz + qx * qw);
  r.at(2, 2) = 1 - 2 * (qx * qx + qy * qy);
  return r;
}

Mat4d operator*(const Mat4d& a, const Mat4d& b) {
  Mat4d r;
  for (int row = 0; row < 4; ++row) {
    for (int col = 0; col < 4; ++col) {
      double sum = 0;
      for (int k = 0; k < 4; ++k) sum += a.at(row, k) * b.at(k, col);
      r.at(row, col) = sum;
    }
  }
  return r;
}

double Mat4d::determinant3() const {
  return at(0, 0) * (at(1, 1) * at(2, 2) - at(1, 2) * at(2, 1)) -
         at(0, 1) * (at(1, 0) * at(2, 2) - at(1, 2) * at(2, 0)) +
         at(0, 2) * (at(1, 0) * at(2, 1) - at(1, 1) * at(2, 0));
}

Mat4d Mat4d::normalMatrix() const {
  // The cofactor matrix equals det * inverse-transpose; its direction (sign fixed below) is all
  // normals need, and it stays defined for singular transforms (flattened parts).
  Mat4d c;
  c.at(0, 0) = at(1, 1) * at(2, 2) - at(1, 2) * at(2, 1);
  c.at(0, 1) = at(1, 2) * at(2, 0) - at(1, 0) * at(2, 2);
  c.at(0, 2) = at(1, 0) * at(2, 1) - at(1, 1) * at(2, 0);
  c.at(1, 0) = at(0, 2) * at(2, 1) - at(0, 1) * at(2, 2);
  c.at(1, 1) = at(0, 0) * at(2, 2) - at(0, 2) * at(2, 0);
  c.at(1, 2) = at(0, 1) * at(2, 0) - at(0, 0) * at(2, 1);
  c.at(2, 0) = at(0, 1) * at(1, 2) - at(0, 2) * at(1, 1);
  c.at(2, 1) = at(0, 2) * at(1, 0) - at(0, 0) * at(1, 2);
  c.at(2, 2) = at(0, 0) * at(1, 1) - at(0, 1) * at(1, 0);
  // A mirroring transform (det < 0) would flip the cofactor's direction against inverse-transpose.
  if (determinant3() < 0) {
    for (double& v : c.m) v = -v;
    c.m[15] = 1;
  }
  return c;
}

}  // namespace lodforge
