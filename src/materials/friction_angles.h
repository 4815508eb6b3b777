// Friction and dilation angles shared by the Drucker-Prager and Matsuoka-Nakai soil models:
// the DP cone constants of a friction angle (Mast 2013 (3.107), (3.109)) and the evolving
// friction, critical-state and dilation angles (Mast 2013 (3.112)-(3.116); spec §2.7, errata 7,
// 9 and 10 of spec §9).
#pragma once
#include <cmath>
#include <numbers>

#include "core/math.h"

namespace surge {

inline Real Radians(Real degrees) { return degrees * std::numbers::pi / 180.0; }
inline Real Degrees(Real radians) { return radians * 180.0 / std::numbers::pi; }

// Slope of the Drucker-Prager cone through the Mohr-Coulomb compression (outer) vertices:
// varrho = sqrt(2/3) 2 sin(phi) / (3 - sin(phi)) (3.107); the same map gives varrho_G of the
// dilation angle (3.109). varrho(90 deg) = sqrt(2/3) = 0.8165 (erratum 7). phi in radians.
inline Real DruckerPragerSlope(Real phi) {
  const Real s = std::sin(phi);
  return std::sqrt(2.0 / 3.0) * 2.0 * s / (3.0 - s);
}

// Cohesion term of that cone: sigma_Y^Eff = -sqrt(2/3) 6 c cos(phi) / (3 - sin(phi)) (3.107),
// so F = ||s|| + varrho I1 + sigma_Y^Eff. c is the Mohr-Coulomb cohesion [Pa], phi in radians.
inline Real DruckerPragerCohesionTerm(Real cohesion, Real phi) {
  return -std::sqrt(2.0 / 3.0) * 6.0 * cohesion * std::cos(phi) / (3.0 - std::sin(phi));
}

// Constants a0..a5 of the evolution laws (3.113)-(3.114); angles in degrees. a2 is stored in
// 1/Pa (the seed's Table 3.5 gives it in 1/kPa: 3.33e-4 1/kPa = 3.33e-7 1/Pa, erratum 10).
struct FrictionCurve {
  Real a0 = 0;  // critical-state (final) angle [deg]
  Real a1 = 0;  // peak height and rate [deg]
  Real a2 = 0;  // pressure sensitivity [1/Pa]
  Real a3 = 0;  // width of the phi_F curve [-]
  Real a4 = 0;  // a0 - a4 = initial angle (at a2 I1 = 0) [deg]
  Real a5 = 0;  // width of the phi_cs curve [-]
};

// Mobilised friction angle phi_F = a0 + (a1 lambda - a4) exp(a2 I1 - a3 lambda) [deg] (3.113);
// I1 = tr(sigma) [Pa] (tension positive, so I1 < 0 in compression).
inline Real MobilisedFrictionDeg(const FrictionCurve& c, Real I1, Real lambda) {
  return c.a0 + (c.a1 * lambda - c.a4) * std::exp(c.a2 * I1 - c.a3 * lambda);
}

// Critical-state friction angle phi_cs = a0 - a4 exp(-a5 lambda) [deg] (3.114).
inline Real CriticalFrictionDeg(const FrictionCurve& c, Real lambda) {
  return c.a0 - c.a4 * std::exp(-c.a5 * lambda);
}

// Stress-dilatancy: tan(psi_G) = tan(phi_F) - tan(phi_cs) (3.112); psi < 0 is contraction.
// Angles in degrees.
inline Real DilationAngleDeg(Real phi_f_deg, Real phi_cs_deg) {
  return Degrees(std::atan(std::tan(Radians(phi_f_deg)) - std::tan(Radians(phi_cs_deg))));
}

}  // namespace surge
