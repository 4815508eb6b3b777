// Hand-built models and states for unit tests that need no scene file.
#pragma once
#include <random>

#include "core/model.h"
#include "core/state.h"

namespace surge::testing {

// A model with one Neo-Hookean material, no walls, and a domain [-10, 10]^3.
inline Model SmallModel(int dim, ShapeFunction shape, TransferScheme transfer, Real dx = 0.1) {
  Model m;
  m.name = "test";
  m.dim = dim;
  m.dx = dx;
  m.shape = shape;
  m.transfer = transfer;
  m.domain_min = Vec3(-10, -10, dim == 3 ? -10 : 0);
  m.domain_max = Vec3(10, 10, dim == 3 ? 10 : 0);
  m.time.end = 1;
  m.materials.push_back(Material{"rubber", 1000.0, NeoHookeanParams{1e5, 5e4}});
  m.bodies.push_back(BodyInfo{"body", 0});
  return m;
}

// n particles at random positions in a cube of side `size` around `centre`, random velocities
// and affine matrices (fixed seed, STYLE H.9).
inline State RandomState(int dim, size_t n, const Vec3& centre, Real size, Real dx,
                         unsigned seed = 7) {
  State s;
  Particles& P = s.particles;
  P.Resize(n);
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<Real> u(-0.5, 0.5);
  const Real vol = dim == 3 ? dx * dx * dx / 8 : dx * dx / 4;
  for (size_t p = 0; p < n; ++p) {
    P.x[p] = centre + size * Vec3(u(rng), u(rng), dim == 3 ? u(rng) : 0.0);
    if (dim == 2) P.x[p].z() = 0;
    P.v[p] = Vec3(u(rng), u(rng), dim == 3 ? u(rng) : 0.0);
    P.C[p].setZero();
    for (int i = 0; i < dim; ++i)
      for (int j = 0; j < dim; ++j) P.C[p](i, j) = u(rng);
    P.F[p].setIdentity();
    P.stress[p] = SymMat3();
    P.strain[p].setZero();
    P.mass[p] = 0.5 + u(rng);
    P.volume0[p] = vol;
    P.ext_force[p].setZero();
    P.material[p] = 0;
    P.body[p] = 0;
    P.id[p] = int64_t(p);
  }
  s.groups.push_back(MaterialGroup{0, 0, n});
  return s;
}

}  // namespace surge::testing
