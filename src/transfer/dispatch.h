// Maps the runtime (dimension, shape function) pair onto the templated kernels: a closed set of
// eight instantiations (STYLE H.10). f is a generic lambda called as f.template operator()<D, K>().
#pragma once
#include <type_traits>

#include "transfer/shape_functions.h"

namespace surge {

template <int kDim, typename F>
void DispatchKernel(ShapeFunction shape, F&& f) {
  switch (shape) {
    case ShapeFunction::kLinear: f.template operator()<kDim, LinearKernel>(); break;
    case ShapeFunction::kGimp: f.template operator()<kDim, GimpKernel>(); break;
    case ShapeFunction::kQuadraticBspline:
      f.template operator()<kDim, QuadraticBsplineKernel>();
      break;
    case ShapeFunction::kCubicBspline: f.template operator()<kDim, CubicBsplineKernel>(); break;
  }
}

template <typename F>
void DispatchKernel(int dim, ShapeFunction shape, F&& f) {
  if (dim == 2)
    DispatchKernel<2>(shape, f);
  else
    DispatchKernel<3>(shape, f);
}

// APIC: C_p = B_p D_p^{-1} (Jiang et al. 2015, eq. (7)). B-splines have D_p = dx^2/kInvDScale I
// (§5.3); for the multilinear kernel B_p D_p^{-1} equals sum_i v_i (grad N_ip)^T (§5.3), i.e. the
// velocity gradient, which G2P takes of the start-of-step velocities only and adds the step's
// increment with D_p = dx^2/4 I (grid_to_particle.cpp, docs/stability.md); GIMP uses the general
// D_p = sum_i N_ip (x_i - x_p)(x_i - x_p)^T, diagonal for tensor-product kernels with linear
// reproduction.
template <class K>
constexpr bool kApicUsesGradient = std::is_same_v<K, LinearKernel>;
template <class K>
constexpr bool kApicConstantD = requires { K::kInvDScale; };

}  // namespace surge
