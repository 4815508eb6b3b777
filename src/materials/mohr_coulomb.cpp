// Mohr-Coulomb / Tresca return in principal Kirchhoff space (Anura3D manual §7.1.2, (7.24)-(7.27);
// Clausen, Damkilde & Andersen 2006; de Souza Neto, Peric & Owen 2008 §8.2; spec
// seed-anura3d.md §A.16.2 [REC]) inside the finite-strain skeleton of Mast (2013) Table 3.4.
//
// Tension positive, sorted tau_1 >= tau_2 >= tau_3. The planes are, x 2,
//   f_ij = (tau_i - tau_j) + (tau_i + tau_j) sin(phi) - 2 c cos(phi),   i above j,
// and the potential (7.27) likewise with psi. Erratum (spec §A.16.2 note on (7.26)): the printed
// F_1 = 1/2 |s'_2 - s'_3| + 1/2 (s'_2 + s'_3) sin(phi) - c cos(phi) (7.26) already has the
// tension-positive sign (the PLAXIS form it comes from): read as compression positive, strength
// would fall with confinement, against (7.25). So the sin terms are NOT flipped; the form above
// is the spec's own recipe (§A.16.2 step 2) and reproduces the triaxial strength
// q_f = 6 sin(phi) / (3 - sin(phi)) (p' + c cot(phi)) (tests/verification/mohr_coulomb_driver_test). Each plane is linear in tau, so with the linear
// principal elasticity [C^e_d] of the Hencky law the return to one plane, to an edge (two planes)
// or to the apex is exact and closed form (Clausen et al. 2006; de Souza Neto et al. 2008 §8.2).
#include "materials/mohr_coulomb.h"

#include <algorithm>
#include <array>
#include <cmath>

#include "materials/hencky.h"

namespace surge {
namespace {

// Gradient of f_ij (or of the potential g_ij with sin(psi)) w.r.t. the sorted principal stresses:
// +(1 + s) at i, -(1 - s) at j (from (7.26)-(7.27), tension positive).
Vec3 PlaneGradient(int i, int j, Real s) {
  Vec3 a = Vec3::Zero();
  a[i] = 1 + s;
  a[j] = -(1 - s);
  return a;
}

// Elastic principal block of [C^e_d]: tau_i = K tr(eps) + 2G (eps_i - tr(eps)/3) (spec §2.0,
// erratum 1 of spec §9: the factor 2).
Mat3 PrincipalStiffness(Real K, Real G) {
  return (K - 2.0 * G / 3.0) * Mat3::Ones() + 2.0 * G * Mat3::Identity();
}

bool Ordered(const Vec3& tau) { return tau[0] >= tau[1] && tau[1] >= tau[2]; }

// Return to the edge where the main plane (1,3) and the plane (i,j) meet: two multipliers from
// f_13(tau) = f_ij(tau) = 0 with tau = trial - dg_1 C b_13 - dg_2 C b_ij (de Souza Neto et al.
// 2008 §8.2; Clausen et al. 2006, return to a line, non-associated: b the potential gradients).
McReturn EdgeReturn(const McSurface& s, const Mat3& C, const Vec3& trial, int i, int j,
                    McRegion region) {
  const Real k = 2.0 * s.cohesion * s.cos_phi;
  const Vec3 a1 = PlaneGradient(0, 2, s.sin_phi), b1 = PlaneGradient(0, 2, s.sin_psi);
  const Vec3 a2 = PlaneGradient(i, j, s.sin_phi), b2 = PlaneGradient(i, j, s.sin_psi);
  const Vec3 cb1 = C * b1, cb2 = C * b2;
  const Real A11 = a1.dot(cb1), A12 = a1.dot(cb2), A21 = a2.dot(cb1), A22 = a2.dot(cb2);
  const Real r1 = a1.dot(trial) - k, r2 = a2.dot(trial) - k;  // trial values of the two planes
  const Real det = A11 * A22 - A12 * A21;
  McReturn r;
  r.region = region;
  r.dgamma[0] = (A22 * r1 - A12 * r2) / det;
  r.dgamma[1] = (A11 * r2 - A21 * r1) / det;
  r.tau = trial - r.dgamma[0] * cb1 - r.dgamma[1] * cb2;
  return r;
}

// Return with a Rankine tension cut-off (the PLAXIS Mohr-Coulomb option; Koiter's multi-surface
// rule, as de Souza Neto et al. 2008 §8.2 apply it to the Mohr-Coulomb edges): the admissible set is the nine linear planes
// a . tau <= k, the six Mohr-Coulomb planes f_ij (flow b = the potential g_ij) and the three
// cut-off planes tau_i <= t (associated, b = e_i). By Koiter's rule the return is
// tau = trial - sum_{active} dgamma_m C b_m with dgamma_m >= 0 and every active plane satisfied
// with equality; for linear planes and linear elasticity each active set is one linear solve.
// The sets are tried by size (1, 2, 3), cut-off planes first, and the first whose multipliers
// are >= 0 and whose stress satisfies all nine planes is taken. At most three planes meet in a
// point of principal space, so one of the sets is the answer (a plastic trial outside the set).
McReturn TensionCutoffReturn(const McSurface& s, const Mat3& C, const Vec3& trial) {
  struct Plane {
    Vec3 a, cb;  // yield gradient, C times the flow direction
    Real k;      // a . tau <= k
  };
  std::array<Plane, 9> planes;
  int n = 0;
  for (int i = 0; i < 3; ++i) planes[size_t(n++)] = Plane{Vec3::Unit(i), C * Vec3::Unit(i), s.tension};
  const Real k_mc = 2.0 * s.cohesion * s.cos_phi;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j)
      if (i != j)
        planes[size_t(n++)] =
            Plane{PlaneGradient(i, j, s.sin_phi), C * PlaneGradient(i, j, s.sin_psi), k_mc};
  const Real scale = trial.cwiseAbs().maxCoeff() + k_mc + std::abs(s.tension);
  const Real tol = 1e-11 * scale;
  auto admissible = [&](const Vec3& tau) {
    for (const Plane& p : planes)
      if (p.a.dot(tau) - p.k > tol) return false;
    return true;
  };
  // One active set: solve sum_m (a_l . C b_m) dgamma_m = a_l . trial - k_l (l, m in the set).
  auto try_set = [&](const int* set, int size, McReturn& out) {
    Mat3 A = Mat3::Identity();
    Vec3 rhs = Vec3::Zero();
    for (int l = 0; l < size; ++l) {
      const Plane& pl = planes[size_t(set[l])];
      rhs[l] = pl.a.dot(trial) - pl.k;
      for (int m = 0; m < size; ++m) A(l, m) = pl.a.dot(planes[size_t(set[m])].cb);
    }
    // Dependent planes (a plane and its mirror, three Mohr-Coulomb planes through the apex
    // line) give a singular system: skip, another set reaches the same point.
    const Real det = A.determinant();
    if (!(std::abs(det) > 1e-12 * std::pow(A.cwiseAbs().maxCoeff(), size))) return false;
    const Vec3 dg = A.inverse() * rhs;
    Vec3 tau = trial;
    const Real dg_scale = dg.cwiseAbs().maxCoeff();
    for (int m = 0; m < size; ++m) {
      if (dg[m] < -1e-12 * dg_scale) return false;  // round-off at a region boundary passes
      tau -= dg[m] * planes[size_t(set[m])].cb;
    }
    if (!admissible(tau)) return false;
    out.tau = tau;
    out.region = McRegion::kTension;
    out.dgamma[0] = dg[0];
    out.dgamma[1] = size > 1 ? dg[1] : 0;
    return true;
  };
  McReturn r;
  int set[3];
  for (set[0] = 0; set[0] < 9; ++set[0])
    if (try_set(set, 1, r)) return r;
  for (set[0] = 0; set[0] < 9; ++set[0])
    for (set[1] = set[0] + 1; set[1] < 9; ++set[1])
      if (try_set(set, 2, r)) return r;
  for (set[0] = 0; set[0] < 9; ++set[0])
    for (set[1] = set[0] + 1; set[1] < 9; ++set[1])
      for (set[2] = set[1] + 1; set[2] < 9; ++set[2])
        if (try_set(set, 3, r)) return r;
  // Not reached for a finite trial; keep the state admissible regardless: the hydrostatic
  // point below both the cut-off and the apex.
  const Real apex = s.sin_phi > 0 ? s.cohesion * s.cos_phi / s.sin_phi
                                  : std::numeric_limits<Real>::infinity();
  r.tau = Vec3::Constant(std::min(s.tension, apex));
  r.region = McRegion::kTension;
  return r;
}

// The return without a cut-off: main plane, edges, apex (below).
McReturn MohrCoulombOnlyReturn(const McSurface& s, Real K, Real G, const Vec3& trial);

}  // namespace

McSurface SurfaceOf(const MohrCoulombParams& p) {
  return McSurface{std::sin(p.friction_angle), std::cos(p.friction_angle),
                   std::sin(p.dilation_angle), p.cohesion, p.tension_cutoff};
}

// Tresca (7.24) is Mohr-Coulomb with phi = psi = 0 and c = s_u (manual §7.1.2.1).
McSurface SurfaceOf(const TrescaParams& p) {
  return McSurface{0, 1, 0, p.undrained_strength, p.tension_cutoff};
}

Real MohrCoulombYield(const McSurface& s, const Vec3& tau) {
  // max_{i != j} f_ij: f_ij grows with tau_i and falls with tau_j (1 - sin(phi) >= 0), so the
  // maximum is the (largest, smallest) plane (7.26) whatever the order of `tau`.
  const Real hi = tau.maxCoeff(), lo = tau.minCoeff();
  return (hi - lo) + (hi + lo) * s.sin_phi - 2.0 * s.cohesion * s.cos_phi;
}

McReturn MohrCoulombReturn(const McSurface& s, Real K, Real G, const Vec3& trial) {
  McReturn r = MohrCoulombOnlyReturn(s, K, G, trial);
  // The cut-off acts where the Mohr-Coulomb state (elastic or returned) has tau_1 > t; tau_1 is
  // the largest (the returns keep the order), so one comparison decides.
  if (!(r.tau[0] > s.tension)) return r;  // (a NaN trial keeps the plain path)
  return TensionCutoffReturn(s, PrincipalStiffness(K, G), trial);
}

namespace {
McReturn MohrCoulombOnlyReturn(const McSurface& s, Real K, Real G, const Vec3& trial) {
  McReturn r;
  r.tau = trial;
  const Real f_trial = MohrCoulombYield(s, trial);  // f_13 of the sorted trial (7.26)
  if (f_trial <= 0) return r;                       // elastic step

  // 1. Main plane: tau = trial - dgamma C b_13, dgamma = f_tr / (a_13 . C b_13) (spec §A.16.2
  //    step 3, where a_13 . C b_13 = 4G(1 + sin phi sin psi / 3) + 4K sin phi sin psi).
  const Mat3 C = PrincipalStiffness(K, G);
  const Vec3 cb = C * PlaneGradient(0, 2, s.sin_psi);
  r.dgamma[0] = f_trial / PlaneGradient(0, 2, s.sin_phi).dot(cb);
  r.tau = trial - r.dgamma[0] * cb;
  r.region = McRegion::kMainPlane;
  if (Ordered(r.tau)) return r;  // spec §A.16.2 step 4: the ordering survives

  // 2. Edge: the main-plane return first breaks tau_1 >= tau_2 (left) or tau_2 >= tau_3 (right);
  //    tau_1 - tau_2 falls by 2G(1 + sin psi) dgamma and tau_2 - tau_3 by 2G(1 - sin psi) dgamma,
  //    so the right edge is hit first iff (1 - sin psi) tau_1 - 2 tau_2 + (1 + sin psi) tau_3 > 0
  //    [DERIVED] (the test of de Souza Neto et al. 2008 §8.2).
  const bool right =
      (1 - s.sin_psi) * trial[0] - 2 * trial[1] + (1 + s.sin_psi) * trial[2] > 0;
  McReturn edge = right ? EdgeReturn(s, C, trial, 0, 1, McRegion::kRightEdge)
                        : EdgeReturn(s, C, trial, 1, 2, McRegion::kLeftEdge);
  const bool edge_ordered = right ? edge.tau[0] >= 0.5 * (edge.tau[1] + edge.tau[2])
                                  : 0.5 * (edge.tau[0] + edge.tau[1]) >= edge.tau[2];
  if ((edge.dgamma[0] >= 0 && edge.dgamma[1] >= 0 && edge_ordered) || s.sin_phi == 0) {
    return edge;  // Tresca (phi = 0) has no apex: its edges are unbounded in p
  }

  // 3. Apex: tau_i = c cot(phi), zero deviator (spec §A.16.2 step 5; perfect plasticity).
  r.tau = Vec3::Constant(s.cohesion * s.cos_phi / s.sin_phi);
  r.region = McRegion::kApex;
  r.dgamma[0] = r.dgamma[1] = 0;
  return r;
}
}  // namespace

void MohrCoulombUpdate(const McSurface& s, Real K, Real G, const Mat3& f, Real J,
                       Mat3& elastic_b, History& h, Mat3& stress) {
  MohrCoulombUpdate(s, K, G, HenckyTrialState(K, G, f, elastic_b), J, elastic_b, h, stress);
}

void MohrCoulombUpdate(const McSurface& s, Real K, Real G, const HenckyTrial& t, Real J,
                       Mat3& elastic_b, History& h, Mat3& stress) {
  // t: trial b^e_tr = f b^e_n f^T, principal Hencky strains and Kirchhoff stresses (Table 3.4,
  // steps 1-4). The eigen-solver leaves them unordered: sort through a permutation.
  std::array<int, 3> order = {0, 1, 2};
  std::sort(order.begin(), order.end(), [&](int i, int j) { return t.tau[i] > t.tau[j]; });
  const Vec3 sorted(t.tau[order[0]], t.tau[order[1]], t.tau[order[2]]);

  const McReturn r = MohrCoulombReturn(s, K, G, sorted);
  h[kMcReturnRegion] = static_cast<Real>(r.region);
  Vec3 tau = t.tau;
  if (r.region != McRegion::kElastic) {
    for (int k = 0; k < 3; ++k) tau[order[k]] = r.tau[k];
    // d_eps^p = eps_tr - eps_e with eps_e = [D^e_d] tau (Table 3.4 residual, row 1; (3.47)).
    const Vec3 deps_p = t.eps - HenckyStrain(K, G, tau);
    h[kMcPlasticStrain] += std::sqrt(2.0 / 3.0 * deps_p.squaredNorm());
    h[kMcVolumetricPlastic] += deps_p.sum();  // ln J^p increment
  }
  HenckyFinish(t, K, G, tau, J, elastic_b, stress);  // Table 3.4 steps 5(c)-(d), (3.37)
}

}  // namespace surge
