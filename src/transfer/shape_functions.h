// Grid shape functions on a regular grid with nodes at integer multiples of dx (Mast 2013 §2.3;
// spec seed-algorithms.md §1.5). Each kernel gives, for a particle at xi = x/dx (cell units):
//   Base(xi)   the first node of its kWidth-node stencil along one axis,
//   Eval(f,..) weights w[k] and derivatives dw[k] = dN/dxi for nodes base+k, with f = xi - base.
// 3-D weights are tensor products; gradients are the analytic derivatives times 1/dx.
#pragma once
#include <cmath>

#include "core/math.h"
#include "core/model.h"

namespace surge {

// Linear hat N(d) = 1 - |d| (seed default, 8-node trilinear cell; spec §1.5).
struct LinearKernel {
  static constexpr int kWidth = 2;
  static int Base(Real xi) { return static_cast<int>(std::floor(xi)); }
  static void Eval(Real f, Real /*lp*/, Real* w, Real* dw) {
    w[0] = 1.0 - f;
    w[1] = f;
    dw[0] = -1.0;
    dw[1] = 1.0;
  }
};

// uGIMP (Bardenhagen & Kober 2004; Mast 2013 eqs. (2.23)-(2.24), spec §1.5): the linear hat
// averaged over a particle domain of half-width lp (cell units, lp <= 1/2). For distance
// d = |xi - i|: 1 - (d^2 + lp^2)/(2 lp) if d < lp; 1 - d if lp <= d <= 1 - lp;
// (1 + lp - d)^2 / (4 lp) if 1 - lp < d < 1 + lp; 0 otherwise.
struct GimpKernel {
  static constexpr int kWidth = 3;
  static int Base(Real xi) { return static_cast<int>(std::floor(xi - 0.5)); }
  static void Eval(Real f, Real lp, Real* w, Real* dw) {
    for (int k = 0; k < 3; ++k) {
      const Real s = f - k;  // signed distance particle - node
      const Real d = std::abs(s);
      const Real sign = s < 0 ? -1.0 : 1.0;
      if (d < lp) {
        w[k] = 1.0 - (s * s + lp * lp) / (2.0 * lp);
        dw[k] = -s / lp;
      } else if (d <= 1.0 - lp) {
        w[k] = 1.0 - d;
        dw[k] = -sign;
      } else if (d < 1.0 + lp) {
        const Real t = 1.0 + lp - d;
        w[k] = t * t / (4.0 * lp);
        dw[k] = -sign * t / (2.0 * lp);
      } else {
        w[k] = 0.0;
        dw[k] = 0.0;
      }
    }
  }
};

// Quadratic B-spline (Steffen et al. 2008): N(d) = 3/4 - d^2 for d < 1/2,
// 1/2 (3/2 - d)^2 for 1/2 <= d < 3/2.
struct QuadraticBsplineKernel {
  static constexpr int kWidth = 3;
  static int Base(Real xi) { return static_cast<int>(std::floor(xi - 0.5)); }
  static void Eval(Real f, Real /*lp*/, Real* w, Real* dw) {
    const Real a = 1.5 - f, b = f - 1.0, c = f - 0.5;  // f in [0.5, 1.5)
    w[0] = 0.5 * a * a;
    w[1] = 0.75 - b * b;
    w[2] = 0.5 * c * c;
    dw[0] = -a;
    dw[1] = -2.0 * b;
    dw[2] = c;
  }
  // APIC inertia-like tensor D_p = dx^2/4 I (Jiang et al. 2015, §5.3).
  static constexpr Real kInvDScale = 4.0;
};

// Cubic B-spline (Steffen et al. 2008): N(d) = d^3/2 - d^2 + 2/3 for d < 1,
// (2 - d)^3 / 6 for 1 <= d < 2.
struct CubicBsplineKernel {
  static constexpr int kWidth = 4;
  static int Base(Real xi) { return static_cast<int>(std::floor(xi)) - 1; }
  static void Eval(Real f, Real /*lp*/, Real* w, Real* dw) {
    const Real d0 = f, d1 = f - 1.0, d2 = 2.0 - f, d3 = 3.0 - f;  // f in [1, 2)
    const Real t0 = 2.0 - d0, t3 = 2.0 - d3;
    w[0] = t0 * t0 * t0 / 6.0;
    w[1] = 0.5 * d1 * d1 * d1 - d1 * d1 + 2.0 / 3.0;
    w[2] = 0.5 * d2 * d2 * d2 - d2 * d2 + 2.0 / 3.0;
    w[3] = t3 * t3 * t3 / 6.0;
    dw[0] = -0.5 * t0 * t0;
    dw[1] = 1.5 * d1 * d1 - 2.0 * d1;
    dw[2] = -(1.5 * d2 * d2 - 2.0 * d2);
    dw[3] = 0.5 * t3 * t3;
  }
  // APIC D_p = dx^2/3 I (Jiang et al. 2015, §5.3).
  static constexpr Real kInvDScale = 3.0;
};

// Weights and gradients of one particle over its stencil: W nodes per axis (1 along z in 2-D).
// The stencil of a particle at x for the scene's kernel, chosen at run time (for passes outside
// the templated transfers): first node lo and width n per axis (lo = 0, n = 1 along z in 2-D).
inline void StencilRange(ShapeFunction shape, int dim, const Vec3& x, Real inv_dx, Vec3i& lo,
                         Vec3i& n) {
  lo = Vec3i::Zero();
  n = Vec3i::Ones();
  for (int a = 0; a < dim; ++a) {
    const Real xi = x[a] * inv_dx;
    switch (shape) {
      case ShapeFunction::kLinear: lo[a] = LinearKernel::Base(xi), n[a] = LinearKernel::kWidth; break;
      case ShapeFunction::kGimp: lo[a] = GimpKernel::Base(xi), n[a] = GimpKernel::kWidth; break;
      case ShapeFunction::kQuadraticBspline:
        lo[a] = QuadraticBsplineKernel::Base(xi), n[a] = QuadraticBsplineKernel::kWidth;
        break;
      case ShapeFunction::kCubicBspline:
        lo[a] = CubicBsplineKernel::Base(xi), n[a] = CubicBsplineKernel::kWidth;
        break;
    }
  }
}

template <int kDim, class K>
struct Stencil {
  static constexpr int W = K::kWidth;
  static constexpr int Wz = kDim == 3 ? W : 1;
  Vec3i base;    // global index of the first node
  Real w[3][W];  // per-axis weights
  Real g[3][W];  // per-axis weight derivatives dN/dx [1/m]

  // x: particle position [m]; lp: GIMP half-width in cell units (ignored by other kernels).
  // Always inlined: called once per particle in every scatter and gather, and GCC left it out of
  // line in the anti-locking loops once they became lambdas of the owned loops (+30 % there).
  [[gnu::always_inline]] void Compute(const Vec3& x, Real inv_dx, Real lp) {
    for (int d = 0; d < kDim; ++d) {
      const Real xi = x[d] * inv_dx;
      base[d] = K::Base(xi);
      K::Eval(xi - base[d], lp, w[d], g[d]);
      for (int k = 0; k < W; ++k) g[d][k] *= inv_dx;
    }
    if constexpr (kDim == 2) {
      base[2] = 0;
      w[2][0] = 1.0;
      g[2][0] = 0.0;
    }
  }
  Real Weight(int i, int j, int k) const { return w[0][i] * w[1][j] * w[2][k]; }
  Vec3 Gradient(int i, int j, int k) const {
    return Vec3(g[0][i] * w[1][j] * w[2][k], w[0][i] * g[1][j] * w[2][k],
                w[0][i] * w[1][j] * g[2][k]);
  }
};

// Runtime evaluation for tests and tools: weights and gradients of all stencil nodes of a
// particle at x. Returns the number of nodes written (W^dim); nodes[] are global node indices.
int EvaluateShape(ShapeFunction shape, int dim, const Vec3& x, Real dx, Real lp, Vec3i* nodes,
                  Real* weights, Vec3* gradients);

// Stencil width per axis and the GIMP half-width of a particle of volume V0 (cell units).
int StencilWidth(ShapeFunction shape);
inline Real GimpHalfWidth(int dim, Real volume0, Real inv_dx) {
  const Real side = dim == 3 ? std::cbrt(volume0) : std::sqrt(volume0);
  return 0.5 * side * inv_dx;
}

}  // namespace surge
