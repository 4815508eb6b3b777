// The one table of material kinds (STYLE H.4): scene name, the model's keys with their units,
// ranges and defaults, and the constructor of its parameter struct. The parser, the writer and
// the builder all read this table, so a new model adds a MaterialModel value, a params struct in
// materials/material_params.h and one row here (docs/scene-reference.md lists the keys).
#include <numbers>
#include <stdexcept>
#include <string>

#include "materials/friction_angles.h"
#include "scene/scene_spec.h"

namespace surge {
namespace {

constexpr Real kInf = std::numeric_limits<Real>::infinity();

// --- linear_elastic, neo_hookean: the elastic pair only ---------------------------------------

MaterialParams MakeLinearElastic(const MaterialSpec& m) {
  return LinearElasticParams{m.bulk_modulus, m.shear_modulus};
}
MaterialParams MakeNeoHookean(const MaterialSpec& m) {
  return NeoHookeanParams{m.bulk_modulus, m.shear_modulus};
}

// --- j2 (Mast 2013 §3.5) ----------------------------------------------------------------------

constexpr ParamDesc kJ2Keys[] = {
    {"yield_stress", "Pa", 0, true, kInf, false, true},  // sigma_Y > 0
    {"isotropic_hardening", "Pa"},                       // k >= 0
    {"kinematic_hardening", "Pa"},                       // H >= 0
};
MaterialParams MakeJ2(const MaterialSpec& m) {
  return J2Params{m.bulk_modulus, m.shear_modulus, m.Param("yield_stress"),
                  m.Param("isotropic_hardening"), m.Param("kinematic_hardening")};
}

// --- newtonian_fluid (Mast 2013 §6.1) ---------------------------------------------------------

constexpr const char* kEosChoices[] = {"linear", "tait"};  // EquationOfState order
constexpr ParamDesc kFluidKeys[] = {
    {"bulk_modulus", "Pa", 0, true, kInf, false, true},  // K > 0
    {"viscosity", "Pa s", 0, false, kInf, false, true},  // mu >= 0
    {"equation_of_state", "", 0, false, kInf, false, false, 0, kEosChoices},
    {"tait_gamma", "-", 1, true, kInf, false, false, 7},  // gamma > 1
};
MaterialParams MakeNewtonianFluid(const MaterialSpec& m) {
  return NewtonianFluidParams{m.Param("bulk_modulus"), m.Param("viscosity"),
                              static_cast<EquationOfState>(m.Param("equation_of_state")),
                              m.Param("tait_gamma")};
}
std::optional<ParamError> CheckNewtonianFluid(const MaterialSpec& m) {
  if (m.values.count("tait_gamma") &&
      static_cast<EquationOfState>(m.Param("equation_of_state")) != EquationOfState::kTait) {
    return ParamError{"tait_gamma", "tait_gamma applies only with equation_of_state: tait"};
  }
  return std::nullopt;
}

// --- bingham_fluid, frictional_fluid (Anura3D manual §7.2.2-7.2.3) ---------------------------

// mu_max when not written: 1000 mu_d (docs/materials.md: creep rate tau / mu_max vs the viscous
// time step, which scales with 1 / mu_max).
constexpr Real kDefaultMaxViscosityRatio = 1000;
Real MaxViscosity(const MaterialSpec& m) {
  return m.values.count("max_viscosity") ? m.Param("max_viscosity")
                                         : kDefaultMaxViscosityRatio * m.Param("viscosity");
}
constexpr ParamDesc kBinghamKeys[] = {
    {"bulk_modulus", "Pa", 0, true, kInf, false, true},      // K > 0
    {"viscosity", "Pa s", 0, false, kInf, false, false},     // mu_d >= 0
    {"yield_stress", "Pa", 0, false, kInf, false, true},     // tau_y >= 0
    {"max_viscosity", "Pa s", 0, true, kInf, false, false},  // mu_max > mu_d; 1000 mu_d
    {"equation_of_state", "", 0, false, kInf, false, false, 0, kEosChoices},
    {"tait_gamma", "-", 1, true, kInf, false, false, 7},  // gamma > 1
};
MaterialParams MakeBinghamFluid(const MaterialSpec& m) {
  return BinghamFluidParams{m.Param("bulk_modulus"), m.Param("viscosity"),
                            m.Param("yield_stress"), MaxViscosity(m),
                            static_cast<EquationOfState>(m.Param("equation_of_state")),
                            m.Param("tait_gamma")};
}
constexpr ParamDesc kFrictionalKeys[] = {
    {"bulk_modulus", "Pa", 0, true, kInf, false, true},      // K > 0
    {"viscosity", "Pa s", 0, false, kInf, false, false},     // mu_d >= 0
    {"friction_angle_deg", "deg", 0, false, 90, true, true},     // 0 <= phi < 90
    {"cohesion", "Pa", 0, false, kInf, false, false},        // c >= 0
    {"max_viscosity", "Pa s", 0, true, kInf, false, false},  // mu_max > mu_d; 1000 mu_d
    {"equation_of_state", "", 0, false, kInf, false, false, 0, kEosChoices},
    {"tait_gamma", "-", 1, true, kInf, false, false, 7},  // gamma > 1
};
MaterialParams MakeFrictionalFluid(const MaterialSpec& m) {
  return FrictionalFluidParams{m.Param("bulk_modulus"), m.Param("viscosity"),
                               m.Param("friction_angle_deg") * std::numbers::pi / 180.0,
                               m.Param("cohesion"), MaxViscosity(m),
                               static_cast<EquationOfState>(m.Param("equation_of_state")),
                               m.Param("tait_gamma")};
}
// Cross-key rules of both: the EOS rule of the Newtonian fluid, and mu_max > mu_d (given, or
// mu_d > 0 for the 1000 mu_d default).
std::optional<ParamError> CheckViscoplasticFluid(const MaterialSpec& m) {
  if (auto e = CheckNewtonianFluid(m)) return e;
  if (!m.values.count("max_viscosity") && m.Param("viscosity") == 0) {
    return ParamError{"max_viscosity",
                      "max_viscosity (the cap mu_max [Pa s]) is required when viscosity is 0; "
                      "its default is 1000 x viscosity"};
  }
  if (MaxViscosity(m) <= m.Param("viscosity")) {
    return ParamError{"max_viscosity", "max_viscosity must exceed viscosity (" +
                                           std::to_string(m.Param("viscosity")) + " Pa s)"};
  }
  return std::nullopt;
}

// --- snow (cohesive modified Cam-clay, Gaume et al. 2018) ------------------------------------

constexpr ParamDesc kSnowKeys[] = {
    {"critical_state_slope", "-", 0, true, kInf, false, true},    // M > 0
    {"cohesion_ratio", "-", 0, false, 1, true, true},             // 0 <= beta < 1
    {"hardening_factor", "-", 0, true, kInf, false, true},        // xi > 0
    {"consolidation_pressure", "Pa", 0, false, kInf, false, true},  // p0 >= 0 at the start
};
MaterialParams MakeSnow(const MaterialSpec& m) {
  return SnowParams{m.bulk_modulus, m.shear_modulus, m.Param("critical_state_slope"),
                    m.Param("cohesion_ratio"), m.Param("hardening_factor"),
                    m.Param("consolidation_pressure")};
}
// Critical-state friction angle for `k0: jaky`: sin phi = 3 M_cs / (6 + M_cs) (triaxial
// compression, Wood 1990), M_cs = M (1 + beta) / ((1 - beta) sqrt(1 + 2 beta)) the q/p ratio at
// the top of the ellipse (materials/snow.h).
Real SnowFrictionAngleDeg(const MaterialSpec& m) {
  const Real beta = m.Param("cohesion_ratio");
  const Real ratio =
      m.Param("critical_state_slope") * (1 + beta) / ((1 - beta) * std::sqrt(1 + 2 * beta));
  const Real sin_phi = 3 * ratio / (6 + ratio);  // < 1 for ratio < 3
  return std::asin(sin_phi < 1 ? sin_phi : 1) * 180.0 / std::numbers::pi;
}

// --- matsuoka_nakai, matsuoka_nakai_dp (Mast 2013 §3.7-§3.8; spec §2.8) --------------------

// Friction curve (3.113)-(3.114): angles in degrees, a2 in 1/Pa (the seed's Table 3.5 gives 1/kPa:
// 3.33e-4 1/kPa = 3.33e-7 1/Pa).
constexpr const char* kDilationChoices[] = {"stress_dilatancy", "zero"};  // zero_dilation
constexpr ParamDesc kMatsuokaNakaiKeys[] = {
    {"cohesion", "Pa", 0, false, kInf, false, false},  // c_F >= 0, hydrostatic shift
    {"a0", "deg", 0, true, 90, true, true},            // critical-state angle, 0 < a0 < 90
    {"a1", "deg", 0, false, kInf, false, false},       // peak height and rate >= 0
    {"a2", "1/Pa", 0, false, kInf, false, false},      // pressure sensitivity >= 0
    {"a3", "-", 0, false, kInf, false, false},         // width of phi_F >= 0
    {"a4", "deg", 0, false, 90, true, false},          // a0 - a4 = initial angle
    {"a5", "-", 0, false, kInf, false, false},         // width of phi_cs >= 0
    {"dilation", "", 0, false, kInf, false, false, 0, kDilationChoices},
};
MatsuokaNakaiParams MakeMatsuokaNakaiParams(const MaterialSpec& m,
                                            MatsuokaNakaiPotential potential) {
  MatsuokaNakaiParams p{m.bulk_modulus, m.shear_modulus, m.Param("cohesion"), {}, false,
                        potential};
  p.friction = FrictionCurve{m.Param("a0"), m.Param("a1"), m.Param("a2"),
                             m.Param("a3"), m.Param("a4"), m.Param("a5")};
  p.zero_dilation = m.Param("dilation") == 1;
  return p;
}
MaterialParams MakeMatsuokaNakai(const MaterialSpec& m) {
  return MakeMatsuokaNakaiParams(m, MatsuokaNakaiPotential::kMatsuokaNakai);
}
MaterialParams MakeMatsuokaNakaiDp(const MaterialSpec& m) {
  return MakeMatsuokaNakaiParams(m, MatsuokaNakaiPotential::kDruckerPrager);
}
// phi_F must stay below 90 deg: a1 > 0 needs a3 > 0 (else phi_F grows without bound), and the
// peak a0 + (a1/a3) exp(-1 - a3 a4 / a1) (at a2 I1 = 0, spec §2.7 [DERIVED]) must be < 90 deg.
std::optional<ParamError> CheckMatsuokaNakai(const MaterialSpec& m) {
  const Real a0 = m.Param("a0"), a1 = m.Param("a1"), a3 = m.Param("a3"), a4 = m.Param("a4");
  if (a4 > a0) {
    return ParamError{"a4", "a4 must not exceed a0 (" + std::to_string(a0) +
                                " deg): a0 - a4 is the initial friction angle"};
  }
  if (a1 > 0 && a3 == 0) {
    return ParamError{"a3", "a3 must be > 0 when a1 > 0 (phi_F = a0 + (a1 lambda - a4) "
                            "exp(a2 I1 - a3 lambda) would grow without bound)"};
  }
  if (a1 > 0) {
    const Real peak = a0 + a1 / a3 * std::exp(-1 - a3 * a4 / a1);
    if (peak >= 89) {
      return ParamError{"a1", "peak friction angle a0 + (a1/a3) exp(-1 - a3 a4/a1) = " +
                                  std::to_string(peak) + " deg must be < 89 deg"};
    }
  }
  return std::nullopt;
}
// `k0: jaky` of the evolving-friction models takes the initial angle a0 - a4 (at a2 I1 = 0), so
// that the Jaky state lies inside the initial surface (docs/scene-reference.md).
Real MatsuokaNakaiFrictionAngleDeg(const MaterialSpec& m) {
  return m.Param("a0") - m.Param("a4");
}

// --- modified_drucker_prager (Mast 2013 §3.6.3-3.6.4): the same keys as Matsuoka-Nakai -------
MaterialParams MakeModifiedDruckerPrager(const MaterialSpec& m) {
  ModifiedDruckerPragerParams p{m.bulk_modulus, m.shear_modulus, m.Param("cohesion"), {}, false};
  p.friction = FrictionCurve{m.Param("a0"), m.Param("a1"), m.Param("a2"),
                             m.Param("a3"), m.Param("a4"), m.Param("a5")};
  p.zero_dilation = m.Param("dilation") == 1;
  return p;
}

// --- mohr_coulomb, tresca (Anura3D manual §7.1.2; materials/mohr_coulomb.h) -------------------

constexpr ParamDesc kMohrCoulombKeys[] = {
    {"friction_angle_deg", "deg", 0, false, 90, true, true},  // 0 <= phi < 90
    {"dilation_angle_deg", "deg", 0, false, 90, true, false},  // 0 <= psi <= phi, default 0
    {"cohesion", "Pa", 0, false, kInf, false, false},      // c >= 0, default 0
    {"tension_cutoff", "Pa", 0, false, kInf, false, false, kInf},  // t >= 0, default none
};
MaterialParams MakeMohrCoulomb(const MaterialSpec& m) {
  return MohrCoulombParams{m.bulk_modulus, m.shear_modulus,
                           m.Param("friction_angle_deg") * std::numbers::pi / 180.0,
                           m.Param("dilation_angle_deg") * std::numbers::pi / 180.0,
                           m.Param("cohesion"), m.Param("tension_cutoff")};
}
// psi <= phi: a dilation angle above the friction angle gives more plastic work out than in
// (Anura3D manual §7.1.2.2; Bolton (7.28) has phi = phi_cs + 0.8 psi >= psi).
std::optional<ParamError> CheckMohrCoulomb(const MaterialSpec& m) {
  if (m.Param("dilation_angle_deg") > m.Param("friction_angle_deg")) {
    return ParamError{"dilation_angle_deg", "dilation_angle_deg must not exceed friction_angle_deg (" +
                                            std::to_string(m.Param("friction_angle_deg")) + " deg)"};
  }
  return std::nullopt;
}
Real MohrCoulombFrictionAngleDeg(const MaterialSpec& m) { return m.Param("friction_angle_deg"); }
constexpr ParamDesc kTrescaKeys[] = {
    {"undrained_strength", "Pa", 0, true, kInf, false, true},  // s_u > 0
    {"tension_cutoff", "Pa", 0, false, kInf, false, false, kInf},  // t >= 0, default none
};
MaterialParams MakeTresca(const MaterialSpec& m) {
  return TrescaParams{m.bulk_modulus, m.shear_modulus, m.Param("undrained_strength"),
                      m.Param("tension_cutoff")};
}

// --- drucker_prager (Mast 2013 §3.6.1; spec §2.5) --------------------------------------------
constexpr ParamDesc kDruckerPragerKeys[] = {
    {"friction_angle_deg", "deg", 0, false, 90, true, true},  // phi in [0, 90)
    {"dilation_angle_deg", "deg", 0, false, 90, true, false},  // 0 <= psi <= phi, default 0
    {"cohesion", "Pa", 0, false, kInf, false, false},          // c >= 0 (Mohr-Coulomb)
    {"isotropic_hardening", "Pa"},                             // k >= 0
    {"kinematic_hardening", "Pa"},                             // H >= 0
};
MaterialParams MakeDruckerPrager(const MaterialSpec& m) {
  const Real phi = m.Param("friction_angle_deg") * std::numbers::pi / 180.0;
  const Real psi = m.Param("dilation_angle_deg") * std::numbers::pi / 180.0;
  // sqrt(2/3) sigma_Y = -sigma_Y^Eff of the cone through the MC compression vertices (3.107).
  const Real sigma_y = -DruckerPragerCohesionTerm(m.Param("cohesion"), phi) / std::sqrt(2.0 / 3.0);
  return DruckerPragerParams{m.bulk_modulus,           m.shear_modulus,
                             DruckerPragerSlope(phi),  DruckerPragerSlope(psi),
                             sigma_y,                  m.Param("isotropic_hardening"),
                             m.Param("kinematic_hardening")};
}
std::optional<ParamError> CheckDruckerPrager(const MaterialSpec& m) {
  if (m.Param("dilation_angle_deg") > m.Param("friction_angle_deg")) {
    return ParamError{"dilation_angle_deg",
                      "dilation_angle_deg must not exceed friction_angle_deg (" +
                          std::to_string(m.Param("friction_angle_deg")) + " deg)"};
  }
  if (m.Param("friction_angle_deg") == 0 && m.Param("cohesion") == 0) {
    return ParamError{"cohesion", "with friction_angle_deg 0 the cohesion must be > 0 (no strength)"};
  }
  return std::nullopt;
}

// --- drucker_prager_smooth_cap (Mast 2013 §3.6.2; spec §2.6) ---------------------------------
constexpr ParamDesc kSmoothCapKeys[] = {
    {"friction_angle_deg", "deg", 0, false, 90, true, true},  // phi in [0, 90)
    {"yield_stress", "Pa", 0, true, kInf, false, true},       // mu > 0 (the cap needs it)
    {"associativity", "-", 0, false, 1, false, false, 0},     // varrho_G / varrho_F in [0, 1]
};
MaterialParams MakeSmoothCapDruckerPrager(const MaterialSpec& m) {
  return SmoothCapDruckerPragerParams{
      m.bulk_modulus, m.shear_modulus,
      DruckerPragerSlope(m.Param("friction_angle_deg") * std::numbers::pi / 180.0),  // (3.107)
      m.Param("yield_stress"), m.Param("associativity")};
}
Real SmoothCapFrictionAngleDeg(const MaterialSpec& m) { return m.Param("friction_angle_deg"); }

// Geostatic initial stress is refused for hyperelastic models and fluids: their stress is a
// function of F (and L), and F starts at I. Elastoplastic models accept it: their stress is a
// function of the elastic b^e, which InitialHistory sets from the prescribed stress.
constexpr MaterialKind kMaterialKinds[] = {
    {"linear_elastic", MaterialModel::kLinearElastic, true, true, {}, &MakeLinearElastic},
    {"neo_hookean", MaterialModel::kNeoHookean, false, true, {}, &MakeNeoHookean},
    {"j2", MaterialModel::kJ2, true, true, kJ2Keys, &MakeJ2},
    {"newtonian_fluid", MaterialModel::kNewtonianFluid, false, false, kFluidKeys,
     &MakeNewtonianFluid, &CheckNewtonianFluid},
    {"bingham_fluid", MaterialModel::kBinghamFluid, false, false, kBinghamKeys,
     &MakeBinghamFluid, &CheckViscoplasticFluid},
    {"frictional_fluid", MaterialModel::kFrictionalFluid, false, false, kFrictionalKeys,
     &MakeFrictionalFluid, &CheckViscoplasticFluid},
    {"snow", MaterialModel::kSnow, true, true, kSnowKeys, &MakeSnow, nullptr,
     &SnowFrictionAngleDeg},
    {"matsuoka_nakai", MaterialModel::kMatsuokaNakai, true, true, kMatsuokaNakaiKeys,
     &MakeMatsuokaNakai, &CheckMatsuokaNakai, &MatsuokaNakaiFrictionAngleDeg},
    {"matsuoka_nakai_dp", MaterialModel::kMatsuokaNakaiDp, true, true, kMatsuokaNakaiKeys,
     &MakeMatsuokaNakaiDp, &CheckMatsuokaNakai, &MatsuokaNakaiFrictionAngleDeg},
    {"drucker_prager", MaterialModel::kDruckerPrager, true, true, kDruckerPragerKeys,
     &MakeDruckerPrager, &CheckDruckerPrager, &SmoothCapFrictionAngleDeg},
    {"drucker_prager_smooth_cap", MaterialModel::kSmoothCapDruckerPrager, true, true,
     kSmoothCapKeys, &MakeSmoothCapDruckerPrager, nullptr, &SmoothCapFrictionAngleDeg},
    {"modified_drucker_prager", MaterialModel::kModifiedDruckerPrager, true, true,
     kMatsuokaNakaiKeys, &MakeModifiedDruckerPrager, &CheckMatsuokaNakai,
     &MatsuokaNakaiFrictionAngleDeg},
    {"mohr_coulomb", MaterialModel::kMohrCoulomb, true, true, kMohrCoulombKeys, &MakeMohrCoulomb,
     &CheckMohrCoulomb, &MohrCoulombFrictionAngleDeg},
    {"tresca", MaterialModel::kTresca, true, true, kTrescaKeys, &MakeTresca},
};

}  // namespace

std::span<const MaterialKind> MaterialKinds() { return kMaterialKinds; }

const MaterialKind& FindMaterialKind(MaterialModel model) {
  for (const MaterialKind& k : kMaterialKinds) {
    if (k.model == model) return k;
  }
  return kMaterialKinds[0];  // unreachable: every MaterialModel has a row
}

Real MaterialSpec::Param(std::string_view key) const {
  if (const auto it = values.find(key); it != values.end()) return it->second;
  for (const ParamDesc& d : FindMaterialKind(model).params) {
    if (key == d.key) return d.default_value;
  }
  throw std::logic_error("material model '" + std::string(FindMaterialKind(model).name) +
                         "' has no key '" + std::string(key) + "'");  // a programming error
}

}  // namespace surge
