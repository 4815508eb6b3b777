// Runtime access to the shape function kernels (tests, tools).
#include "transfer/shape_functions.h"

#include "transfer/dispatch.h"

namespace surge {

int StencilWidth(ShapeFunction shape) {
  switch (shape) {
    case ShapeFunction::kLinear: return LinearKernel::kWidth;
    case ShapeFunction::kGimp: return GimpKernel::kWidth;
    case ShapeFunction::kQuadraticBspline: return QuadraticBsplineKernel::kWidth;
    case ShapeFunction::kCubicBspline: return CubicBsplineKernel::kWidth;
  }
  return 0;
}

int EvaluateShape(ShapeFunction shape, int dim, const Vec3& x, Real dx, Real lp, Vec3i* nodes,
                  Real* weights, Vec3* gradients) {
  int count = 0;
  DispatchKernel(dim, shape, [&]<int kDim, class K>() {
    Stencil<kDim, K> s;
    s.Compute(x, 1.0 / dx, lp);
    for (int i = 0; i < s.W; ++i)
      for (int j = 0; j < s.W; ++j)
        for (int k = 0; k < s.Wz; ++k) {
          nodes[count] = s.base + Vec3i(i, j, k);
          weights[count] = s.Weight(i, j, k);
          gradients[count] = s.Gradient(i, j, k);
          ++count;
        }
  });
  return count;
}

}  // namespace surge
