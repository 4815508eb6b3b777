// Modified Drucker-Prager: closed-form cone and apex returns in principal Kirchhoff stress
// (Mast 2013 §3.6.1, §3.6.3-3.6.4; spec §2.5, §2.7).
#include "materials/modified_drucker_prager.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "materials/friction_angles.h"
#include "materials/hencky.h"

namespace surge {
namespace {

// Angles of the converged state (3.112)-(3.114). I1 in Pa (Cauchy, tension positive).
void UpdateAngles(const ModifiedDruckerPragerParams& p, Real I1, History& h) {
  const Real lambda = h[kMdpLambda];
  // (3.113); clamped at 0: in tension (a2 I1 > 0) the law can fall below zero, outside its range.
  const Real phi_f = std::max(0.0, MobilisedFrictionDeg(p.friction, I1, lambda));
  const Real phi_cs = CriticalFrictionDeg(p.friction, lambda);           // (3.114)
  h[kMdpFriction] = phi_f;
  h[kMdpCritical] = phi_cs;
  h[kMdpDilation] = p.zero_dilation ? 0.0 : DilationAngleDeg(phi_f, phi_cs);  // (3.112)
}

}  // namespace

Real ModifiedDruckerPragerYield(const ModifiedDruckerPragerParams& p, const Mat3& tau,
                                const History& h) {
  const Real phi = Radians(h[kMdpFriction]);
  return Dev(tau).norm() + DruckerPragerSlope(phi) * tau.trace() +
         DruckerPragerCohesionTerm(p.cohesion, phi);  // (3.106)-(3.107)
}

void InitialPlasticHistory(const ModifiedDruckerPragerParams& p, const Mat3& stress,
                           History& h) {
  h[kMdpLambda] = 0;
  UpdateAngles(p, stress.trace(), h);
}

void PlasticUpdate(const ModifiedDruckerPragerParams& p, const Mat3& f, Real J, Mat3& elastic_b,
                   History& h, Mat3& stress) {
  const HenckyTrial t = HenckyTrialState(p.bulk_modulus, p.shear_modulus, f, elastic_b);
  PlasticUpdate(p, f, t, J, elastic_b, h, stress);
}

void PlasticUpdate(const ModifiedDruckerPragerParams& p, const Mat3&, const HenckyTrial& t,
                   Real J, Mat3& elastic_b, History& h, Mat3& stress) {
  const Real K = p.bulk_modulus, G = p.shear_modulus;  // t: Table 3.4, steps 1-4
  // Frozen angles of the step (semi-implicit, Tu et al. 2009).
  const Real phi = Radians(h[kMdpFriction]);
  const Real rho_f = DruckerPragerSlope(phi);                       // (3.107)
  const Real sigma_eff = DruckerPragerCohesionTerm(p.cohesion, phi);  // (3.107)
  const Real rho_g = DruckerPragerSlope(Radians(h[kMdpDilation]));  // (3.109), sign of psi
  const Real I1 = t.tau.sum();
  const Vec3 s = (t.tau.array() - I1 / 3.0).matrix();
  const Real s_norm = s.norm();
  const Real F = s_norm + rho_f * I1 + sigma_eff;  // (3.106)
  Vec3 tau = t.tau;
  if (F > 0) {
    // I1 at the apex, >= 0 (spec §9 erratum 4); none for a zero angle (a cylinder).
    const Real apex = rho_f > 0 ? -sigma_eff / rho_f : std::numeric_limits<Real>::infinity();
    // Cone return (3.88)-(3.91) with H = k = 0: dgamma = F / (2G + 9K varrho_F varrho_G).
    const Real dgamma = F / (2.0 * G + 9.0 * K * rho_f * rho_g);
    const Real I1_new = I1 - 9.0 * K * rho_g * dgamma;  // (3.89)
    const bool overshoot = s_norm - 2.0 * G * dgamma < 0;  // past the axis (spec §2.5 [REC])
    // dgamma < 0: 2G + 9K varrho_F varrho_G <= 0 (strongly contractive psi_G), no return along
    // the flow direction exists; the state goes to the apex (liquefaction, docs/materials.md).
    if (!overshoot && I1_new <= apex && dgamma >= 0) {
      tau = s * (1.0 - 2.0 * G * dgamma / s_norm) + Vec3::Constant(I1_new / 3.0);
      h[kMdpLambda] += dgamma;  // (3.116), deviatoric norm of dgamma g
    } else {
      // Apex / tension cutoff (3.94)-(3.100): the deviator is removed (dgamma_1 = ||s|| / 2G)
      // and I1 returns to the apex; for c = 0 this is the stress-free state.
      tau = Vec3::Constant(apex / 3.0);
      h[kMdpLambda] += s_norm / (2.0 * G);
    }
    UpdateAngles(p, tau.sum() / J, h);
  }
  HenckyFinish(t, K, G, tau, J, elastic_b, stress);  // Table 3.4, 5(c)-(d)
}

}  // namespace surge
