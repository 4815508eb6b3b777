// One-particle material driver: wraps UpdateStress on a one-particle group (spec §2.10).
#include "materials/material_driver.h"

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
  InitialHistory(material, initial_stress, P.elastic_b[0], P.history[0]);
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

}  // namespace surge
