// Eigen-decomposition of a symmetric 3x3 matrix for the principal-space stress updates
// (Mast 2013 Table 3.4, step 2: the spectral decomposition of b^e_tr).
#pragma once
#include "core/math.h"

namespace surge {

// A = Q diag(values) Q^T with Q orthonormal (columns are eigenvectors) and values ascending.
// Only the symmetric part of A is read.
//
// One eigenvalue from the characteristic cubic, an exact rotation for the other two: the extreme
// eigenvalue farthest from the other two is a root of the cubic (Smith 1961, Commun. ACM 4(4):168)
// found by a monotone Newton iteration, accurate also near a double root; its eigenvector is the
// largest cross product of two rows of A - lambda I; the remaining pair diagonalises the 2x2
// projection of A onto that vector's complement by one Jacobi rotation (Golub & Van Loan 2013,
// Alg. 8.5.1), which is exact for any gap, zero included.
// Residual |A Q - Q diag| <= ~6e-16 |A| and |Q^T Q - I| <= ~2e-15 on random, double, near-double
// and triple roots (tests/unit/materials/symmetric_eigen_test.cpp); about 2.4x faster than
// Eigen::SelfAdjointEigenSolver's iterative QR on this machine (docs/benchmarks.md).
void SymmetricEigen(const Mat3& a, Vec3& values, Mat3& vectors);

// Two decompositions at once, each bitwise equal to SymmetricEigen of its matrix: the same
// operations in the two lanes of a vector register, so two dependent chains of divisions and
// square roots run side by side (docs/benchmarks.md, eleventh increment).
void SymmetricEigen2(const Mat3& a0, const Mat3& a1, Vec3& values0, Mat3& vectors0, Vec3& values1,
                     Mat3& vectors1);

// Four decompositions at once (a[0..3] into values[k], vectors[k]), each bitwise equal to
// SymmetricEigen of its matrix: the AVX build (core/simd.h) where WideSimd(), else two
// SymmetricEigen2.
void SymmetricEigen4(const Mat3* a, Vec3* values, Mat3* vectors);

}  // namespace surge
