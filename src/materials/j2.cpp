// J2 plasticity at finite strain: trial b^e, Hencky strain, radial return in Kirchhoff stress
// (Mast 2013 §3.5 and Table 3.4; spec §2.4). The only Eigen eigen-solver user besides the other
// plastic models.
#include "materials/j2.h"

#include "materials/hencky.h"

#include <Eigen/SVD>
#include <cmath>

namespace surge {
namespace {

const Real kSqrtTwoThirds = std::sqrt(2.0 / 3.0);

}  // namespace

void J2StoreBackStress(const Mat3& beta, History& h) {
  h[kJ2BackStress + 0] = beta(0, 0);
  h[kJ2BackStress + 1] = beta(1, 1);
  h[kJ2BackStress + 2] = beta(2, 2);
  h[kJ2BackStress + 3] = beta(0, 1);
  h[kJ2BackStress + 4] = beta(1, 2);
  h[kJ2BackStress + 5] = beta(0, 2);
}

Mat3 J2BackStressOf(const History& h) {
  Mat3 beta;
  beta << h[kJ2BackStress + 0], h[kJ2BackStress + 3], h[kJ2BackStress + 5],  //
      h[kJ2BackStress + 3], h[kJ2BackStress + 1], h[kJ2BackStress + 4],       //
      h[kJ2BackStress + 5], h[kJ2BackStress + 4], h[kJ2BackStress + 2];
  return beta;
}

// Finite-deformation return (Table 3.4) specialised to J2, where dgamma is closed-form (3.83).
//
// Kinematic hardening departs from the seed's principal-space algorithm, which assumes that all
// tensors share the trial eigenbasis: a back stress generally does not. We therefore (a) carry
// beta with the rotation R of the polar decomposition f = R U (a Green-Naghdi-type transport,
// our choice: it makes the update objective), and (b) return the full relative stress
// eta = s - beta in the trial eigenframe. Without back stress eta is diagonal there and the
// update is exactly the seed's principal-space return.
void J2Update(const J2Params& p, const Mat3& f, Real J, Mat3& elastic_b, History& h,
              Mat3& stress) {
  J2Update(p, f, HenckyTrialState(p.bulk_modulus, p.shear_modulus, f, elastic_b), J, elastic_b, h,
           stress);
}

void J2Update(const J2Params& p, const Mat3& f, const HenckyTrial& t, Real J, Mat3& elastic_b,
              History& h, Mat3& stress) {
  const Real G = p.shear_modulus;
  const Real H = p.kinematic_hardening;
  const Real k = p.isotropic_hardening;

  // t: trial b^e_tr = f b^e_n f^T, its principal Hencky strains and Kirchhoff stresses
  // (Table 3.4, steps 1-4).
  const Mat3& Q = t.Q;
  const Vec3& eps = t.eps;
  const Vec3 s_trial = (t.tau.array() - t.tau.sum() / 3.0).matrix();
  Mat3 tau_hat = t.tau.asDiagonal();

  Mat3 beta = Mat3::Zero();
  if (H > 0) {
    Eigen::JacobiSVD<Mat3> svd(f, Eigen::ComputeFullU | Eigen::ComputeFullV);
    const Mat3 R = svd.matrixU() * svd.matrixV().transpose();  // f = R U, det f > 0
    beta = R * J2BackStressOf(h) * R.transpose();
  }
  const Mat3 beta_hat = Q.transpose() * beta * Q;

  // Trial relative stress eta_tr = s_tr + kappa_kin_n, kappa_kin = -beta (3.70), (3.77).
  const Mat3 eta = Mat3(s_trial.asDiagonal()) - beta_hat;
  const Real eta_norm = eta.norm();
  Real& alpha = h[kJ2PlasticStrain];
  // F_tr = ||eta_tr|| - sqrt(2/3) (sigma_Y + k alpha_n) (3.82).
  const Real f_trial = eta_norm - kSqrtTwoThirds * (p.yield_stress + k * alpha);

  if (f_trial <= 0) {
    elastic_b = FromPrincipal(Q, (2.0 * eps).array().exp().matrix());  // b^e_{n+1} = b^e_tr
  } else {
    const Real dgamma = f_trial / (2.0 * G + 2.0 / 3.0 * H + 2.0 / 3.0 * k);  // (3.83)
    const Mat3 n = eta / eta_norm;  // radial return direction (3.79)
    // eps_e = eps_tr - dgamma n (Table 3.4 residual, row 1), so tau = tau_tr - 2G dgamma n
    // (n is deviatoric: the volumetric part is unchanged).
    tau_hat -= 2.0 * G * dgamma * n;
    beta += 2.0 / 3.0 * H * dgamma * (Q * n * Q.transpose());  // (3.71), (3.73)
    alpha += kSqrtTwoThirds * dgamma;  // (3.74) as corrected in spec §9 erratum 3
    if (H > 0) {
      const Mat3 eps_e = Mat3(eps.asDiagonal()) - dgamma * n;
      elastic_b = ExpTwice(Q * eps_e * Q.transpose());  // b^e = exp(2 eps_e) (4.40)
    } else {
      // n is diagonal in the trial frame: b^e = sum exp(2 eps_i) m_i (Table 3.4, 5(c)).
      const Vec3 eps_e = eps - dgamma * n.diagonal();
      elastic_b = Q * Vec3((2.0 * eps_e).array().exp()).asDiagonal() * Q.transpose();
    }
  }
  if (H > 0) J2StoreBackStress(beta, h);
  stress = (Q * tau_hat * Q.transpose()) / J;  // sigma = tau / J (3.37)
}

Real J2YieldFunction(const J2Params& p, const Mat3& tau, const History& h) {
  const Mat3 eta = Dev(tau) - J2BackStressOf(h);  // (3.70)
  return eta.norm() - kSqrtTwoThirds * (p.yield_stress + p.isotropic_hardening * h[kJ2PlasticStrain]);
}

}  // namespace surge
