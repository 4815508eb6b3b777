// Surge math types: the only place Eigen/Core is named (STYLE H.2).
#pragma once
#include <Eigen/Core>
#include <Eigen/Geometry>  // cross products
#include <Eigen/LU>        // 3x3 determinants
#include <cstdint>

namespace surge {

using Real = double;
using Vec3 = Eigen::Matrix<Real, 3, 1>;
using Mat3 = Eigen::Matrix<Real, 3, 3>;
using Vec3i = Eigen::Matrix<int, 3, 1>;

inline Mat3 Identity3() { return Mat3::Identity(); }

// Symmetric part of a 3x3 matrix.
inline Mat3 Sym(const Mat3& a) { return 0.5 * (a + a.transpose()); }

// Deviatoric part of a 3x3 matrix.
inline Mat3 Dev(const Mat3& a) { return a - (a.trace() / 3.0) * Mat3::Identity(); }

}  // namespace surge
