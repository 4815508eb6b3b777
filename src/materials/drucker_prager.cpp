// Traditional Drucker-Prager: closed-form cone and apex returns (Mast 2013 §3.6.1; spec §2.5).
// Kinematic hardening follows the J2 model's treatment (materials/j2.cpp): the back stress is
// carried with the rotation of the polar decomposition of f and the relative stress is returned
// as a full tensor in the trial eigenframe.
#include "materials/drucker_prager.h"

#include <Eigen/SVD>
#include <cmath>
#include <limits>

#include "materials/hencky.h"
#include "materials/j2.h"

namespace surge {
namespace {

const Real kSqrtTwoThirds = std::sqrt(2.0 / 3.0);

}  // namespace

Real DruckerPragerApex(const DruckerPragerParams& p, const History&) {
  if (p.friction_slope <= 0) return std::numeric_limits<Real>::infinity();
  // The cutoff F2 = I1 - c - kappa_2 with kappa_2 = 0 (Petek 2006; spec §2.5) stays at the apex
  // of the initial cone: c = sqrt(2/3) sigma_Y / varrho_F >= 0 (3.86), sign per erratum 4.
  return kSqrtTwoThirds * p.yield_stress / p.friction_slope;
}

Real DruckerPragerYield(const DruckerPragerParams& p, const Mat3& tau, const History& h) {
  return (Dev(tau) - J2BackStressOf(h)).norm() + p.friction_slope * tau.trace() -
         kSqrtTwoThirds * (p.yield_stress + p.isotropic_hardening * h[kJ2PlasticStrain]);  // (3.84)
}

void PlasticUpdate(const DruckerPragerParams& p, const Mat3& f, Real J, Mat3& elastic_b,
                   History& h, Mat3& stress) {
  const HenckyTrial t = HenckyTrialState(p.bulk_modulus, p.shear_modulus, f, elastic_b);
  PlasticUpdate(p, f, t, J, elastic_b, h, stress);
}

void PlasticUpdate(const DruckerPragerParams& p, const Mat3& f, const HenckyTrial& t, Real J,
                   Mat3& elastic_b, History& h, Mat3& stress) {
  const Real K = p.bulk_modulus, G = p.shear_modulus;  // t: Table 3.4, steps 1-4
  const Real H = p.kinematic_hardening, k = p.isotropic_hardening;
  const Real rho_f = p.friction_slope, rho_g = p.dilation_slope;
  const Mat3& Q = t.Q;
  const Real I1 = t.tau.sum();
  const Vec3 s_trial = (t.tau.array() - I1 / 3.0).matrix();

  Mat3 beta = Mat3::Zero();
  if (H > 0) {  // back stress carried with the rotation R of f = R U (as in j2.cpp)
    Eigen::JacobiSVD<Mat3> svd(f, Eigen::ComputeFullU | Eigen::ComputeFullV);
    const Mat3 R = svd.matrixU() * svd.matrixV().transpose();
    beta = R * J2BackStressOf(h) * R.transpose();
  }
  const Mat3 beta_hat = Q.transpose() * beta * Q;  // in the trial eigenframe
  const Mat3 eta = Mat3(s_trial.asDiagonal()) - beta_hat;  // (3.77)
  const Real eta_norm = eta.norm();
  Real& alpha = h[kJ2PlasticStrain];
  const Real radius = kSqrtTwoThirds * (p.yield_stress + k * alpha);
  const Real F1 = eta_norm + rho_f * I1 - radius;  // (3.84)

  Mat3 tau_hat = t.tau.asDiagonal();
  bool general = false;  // tau_hat off-diagonal in the trial frame (kinematic hardening)
  const Real cutoff = DruckerPragerApex(p, h);
  const Real F2 = I1 - cutoff;  // (3.93) with kappa_2 = 0
  if (F1 > 0 || F2 > 0) {
    const Real hard = 2.0 / 3.0 * H + 2.0 / 3.0 * k;
    Real dgamma1 = 0, dgamma2 = 0;
    bool cone = false;
    if (F1 > 0) {
      // Cone return (3.88)-(3.91): dgamma = F1 / (2G + 2/3 H + 2/3 k + 9K varrho_G varrho_F),
      // accepted unless it passes the axis of the relative stress or the cutoff (spec §2.5
      // [REC], erratum 5).
      dgamma1 = F1 / (2.0 * G + hard + 9.0 * K * rho_g * rho_f);
      cone = eta_norm - (2.0 * G + 2.0 / 3.0 * H) * dgamma1 >= 0 &&
             I1 - 9.0 * K * rho_g * dgamma1 <= cutoff;  // (3.89)
    }
    if (!cone) {
      // Corner (both surfaces) or cutoff alone, (3.94)-(3.100): the 2x2 system
      //   F1 = (2G + 2/3 H + 2/3 k + 9K rho_G rho_F) dg1 + 9K rho_F dg2,  F2 = 9K rho_G dg1 + 9K dg2
      // gives dg1 = (F1 - rho_F F2) / (2G + 2/3 H + 2/3 k), dg2 = F2 / (9K) - rho_G dg1; dg1 < 0
      // means the cone is not active (cutoff alone: dg1 = 0).
      dgamma1 = std::max(0.0, (F1 - rho_f * F2) / (2.0 * G + hard));
      dgamma2 = std::max(0.0, F2 / (9.0 * K) - rho_g * dgamma1);
    }
    const Mat3 n = eta_norm > 0 ? Mat3(eta / eta_norm) : Mat3::Zero();  // (3.79)
    // tau = tau_tr - dgamma_1 (2G n + 3K varrho_G 1) - 3K dgamma_2 1 (3.90), (3.95).
    tau_hat -= dgamma1 * (2.0 * G * n + 3.0 * K * rho_g * Mat3::Identity()) +
               3.0 * K * dgamma2 * Mat3::Identity();
    beta += 2.0 / 3.0 * H * dgamma1 * (Q * n * Q.transpose());  // (3.71), (3.73)
    alpha += kSqrtTwoThirds * dgamma1;                          // (3.74), erratum 3
    h[kDpPlasticVolume] += 3.0 * rho_g * dgamma1 + 3.0 * dgamma2;  // tr(dg1 g_1 + dg2 g_2)
    general = H > 0 && dgamma1 > 0;
  }
  if (H > 0) J2StoreBackStress(beta, h);
  if (!general) {
    HenckyFinish(t, K, G, tau_hat.diagonal(), J, elastic_b, stress);  // Table 3.4, 5(c)-(d)
    return;
  }
  // Relative stress not diagonal in the trial frame (kinematic hardening): full-tensor update,
  // b^e = exp(2 D^e : tau) (4.40), sigma = tau / J (3.37).
  const Mat3 tau = Q * tau_hat * Q.transpose();
  elastic_b = ElasticBFromStress(K, G, Sym(tau));
  stress = tau / J;
}

}  // namespace surge
