// One-particle material driver: wraps UpdateStress on a one-particle group (spec §2.10).
#include "materials/material_driver.h"

#include <Eigen/LU>

#include "core/step_context.h"
#include "materials/update_stress.h"

namespace surge {

MaterialPoint MakeMaterialPoint(const Material& material, const Mat3& initial_stress) {
  MaterialPoint pt;
  pt.model.name = "material_point";
  pt.model.materials.push_back(material);
  pt.groups.push_back(MaterialGroup{0, 0, 1});
  Particles& P = pt.particles;
  P.Resize(1);
  P.x[0].setZero();
  P.v[0].setZero();
  P.C[0].setZero();
  P.F[0].setIdentity();
  P.stress[0] = initial_stress;
  P.strain[0].setZero();
  History history;
  InitialHistory(material, initial_stress, P.elastic_b[0], history);
  P.history.Set(0, history);
  P.volume0[0] = 1.0;
  P.mass[0] = material.density;
  P.ext_force[0].setZero();
  P.material[0] = 0;
  P.body[0] = 0;
  P.id[0] = 0;
  pt.velocity_gradient.assign(1, Mat3::Zero());
  return pt;
}

void StepMaterialPoint(MaterialPoint& pt, const Mat3& L, Real dt) {
  StepContext ctx;
  ctx.dt = dt;
  pt.velocity_gradient[0] = L;
  UpdateStress(pt.model, ctx, pt.velocity_gradient, pt.groups, pt.particles);
}

namespace {

// Elastic moduli (K, G) of a material with a shear modulus; (K, 0) for a fluid.
std::array<Real, 2> ElasticModuli(const Material& m) {
  return std::visit(
      [](const auto& p) -> std::array<Real, 2> {
        if constexpr (requires { p.shear_modulus; }) {
          return {p.bulk_modulus, p.shear_modulus};
        } else {
          return {p.bulk_modulus, 0.0};
        }
      },
      m.params);
}

}  // namespace

int MixedControlStep(MaterialPoint& pt, const MixedControl& c, Real dt, Real tol) {
  std::array<int, 6> unknown{};
  int m = 0;
  for (int v = 0; v < 6; ++v)
    if (c.stress_controlled[v]) unknown[m++] = v;
  if (m == 0) {
    StepMaterialPoint(pt, c.L, dt);
    return 0;
  }
  using VecX = Eigen::Matrix<Real, Eigen::Dynamic, 1>;
  using MatX = Eigen::Matrix<Real, Eigen::Dynamic, Eigen::Dynamic>;
  const auto with_rates = [&](const VecX& x) {
    Mat3 L = c.L;
    for (int a = 0; a < m; ++a) {
      const int i = kVoigtI[unknown[a]], j = kVoigtJ[unknown[a]];
      if (i == j) {
        L(i, i) = x[a];
      } else {  // d_ij = x with no spin added: L_ij = L_ji = x + the prescribed skew part
        const Real w = 0.5 * (c.L(i, j) - c.L(j, i));
        L(i, j) = x[a] + w;
        L(j, i) = x[a] - w;
      }
    }
    return L;
  };
  MaterialPoint trial;
  const auto residual = [&](const VecX& x) {
    trial = pt;
    StepMaterialPoint(trial, with_rates(x), dt);
    VecX r(m);
    for (int a = 0; a < m; ++a) {
      const int i = kVoigtI[unknown[a]], j = kVoigtJ[unknown[a]];
      r[a] = trial.particles.stress[0](i, j) - c.target(i, j);
    }
    return r;
  };
  // Jacobian d sigma_u / d x from C^e = K 1 x 1 + 2G I_dev (3.46 with erratum 1), times dt.
  const auto [K, G] = ElasticModuli(pt.model.materials[0]);
  MatX jac(m, m);
  for (int a = 0; a < m; ++a) {
    for (int b = 0; b < m; ++b) {
      const bool normal_a = unknown[a] < 3, normal_b = unknown[b] < 3;
      Real cab = 0;
      if (normal_a && normal_b) cab = K - 2.0 * G / 3.0 + (a == b ? 2.0 * G : 0.0);
      if (!normal_a && !normal_b && a == b) cab = 2.0 * G;
      jac(a, b) = cab * dt;
    }
  }
  VecX x(m);
  for (int a = 0; a < m; ++a) x[a] = Sym(c.L)(kVoigtI[unknown[a]], kVoigtJ[unknown[a]]);
  VecX r = residual(x);
  MaterialPoint best = trial;
  for (int it = 1; it <= 100; ++it) {
    if (r.cwiseAbs().maxCoeff() <= tol) {
      pt = trial;
      return it - 1;
    }
    const VecX dx = -jac.fullPivLu().solve(r);
    const VecX x_new = x + dx;
    const VecX r_new = residual(x_new);
    if (r_new.cwiseAbs().maxCoeff() < r.cwiseAbs().maxCoeff()) best = trial;
    // Broyden's "good" update: J += (dr - J dx) dx^T / (dx . dx).
    const Real dd = dx.squaredNorm();
    if (dd > 0) jac += (r_new - r - jac * dx) * dx.transpose() / dd;
    x = x_new;
    r = r_new;
  }
  if (r.cwiseAbs().maxCoeff() <= tol) {
    pt = trial;
    return 100;
  }
  pt = best;
  return -1;
}

}  // namespace surge
