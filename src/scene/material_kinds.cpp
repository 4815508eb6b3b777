// The one table of material kinds (STYLE H.4): scene name, the model's keys with their units,
// ranges and defaults, and the constructor of its parameter struct. The parser, the writer and
// the builder all read this table, so a new model adds a MaterialModel value, a params struct in
// materials/material_params.h and one row here (docs/scene-reference.md lists the keys).
#include <numbers>
#include <stdexcept>
#include <string>

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
    {"friction_angle", "deg", 0, false, 90, true, true},     // 0 <= phi < 90
    {"cohesion", "Pa", 0, false, kInf, false, false},        // c >= 0
    {"max_viscosity", "Pa s", 0, true, kInf, false, false},  // mu_max > mu_d; 1000 mu_d
    {"equation_of_state", "", 0, false, kInf, false, false, 0, kEosChoices},
    {"tait_gamma", "-", 1, true, kInf, false, false, 7},  // gamma > 1
};
MaterialParams MakeFrictionalFluid(const MaterialSpec& m) {
  return FrictionalFluidParams{m.Param("bulk_modulus"), m.Param("viscosity"),
                               m.Param("friction_angle") * std::numbers::pi / 180.0,
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
