// Stress update dispatch: one std::visit per material group (STYLE H.4).
#include "materials/update_stress.h"

#include <algorithm>
#include <array>
#include <type_traits>

#include "core/parallel.h"
#include "materials/bingham_fluid.h"
#include "materials/drucker_prager.h"
#include "materials/frictional_fluid.h"
#include "materials/hencky.h"
#include "materials/j2.h"
#include "materials/linear_elastic.h"
#include "materials/matsuoka_nakai.h"
#include "materials/modified_drucker_prager.h"
#include "materials/mohr_coulomb.h"
#include "materials/neo_hookean.h"
#include "materials/newtonian_fluid.h"
#include "materials/smooth_cap_drucker_prager.h"
#include "materials/snow.h"

namespace surge {
namespace {

template <class... Ts>
struct Overloaded : Ts... {
  using Ts::operator()...;
};
template <class... Ts>
Overloaded(Ts...) -> Overloaded<Ts...>;

}  // namespace

void UpdateStress(const Model& model, const StepContext& ctx,
                  const std::vector<Mat3>& velocity_gradient,
                  const std::vector<MaterialGroup>& groups, Particles& P) {
  const Real dt = ctx.dt;
  for (const MaterialGroup& g : groups) {
    const size_t count = g.end - g.begin;
    std::visit(Overloaded{
                   [&](const LinearElasticParams& params) {
                     ParallelFor(count, 1024, [&](size_t k) {
                       const size_t p = g.begin + k;
                       const Mat3 f = Mat3::Identity() + dt * velocity_gradient[p];  // (2.18)
                       P.F[p] = f * P.F[p];
                       Mat3 stress = P.stress[p];
                       LinearElasticUpdate(params, Sym(f - Mat3::Identity()), stress,
                                           P.strain[p]);
                       P.stress[p] = stress;
                     });
                   },
                   [&](const NeoHookeanParams& params) {
                     ParallelFor(count, 1024, [&](size_t k) {
                       const size_t p = g.begin + k;
                       const Mat3 f = Mat3::Identity() + dt * velocity_gradient[p];  // (2.18)
                       P.F[p] = f * P.F[p];
                       P.stress[p] = NeoHookeanStress(params, P.F[p]);
                     });
                   },
                   [&](const auto& params) {
                     // Elastoplastic models (Hencky elasticity, b^e, Table 3.4): each provides
                     // PlasticUpdate(params, f, trial, J, b^e, history, sigma) in its own header
                     // and takes the trial state from here, two particles at a time
                     // (HenckyTrialStates: two spectral decompositions side by side). The pairs
                     // are fixed (2k, 2k+1 of the group) and each particle's result is bitwise
                     // what the one-particle path gives, so neither the thread count nor the
                     // pairing changes a result.
                     static_assert(
                         requires(const Mat3& f, const HenckyTrial& t, Real J, Mat3& b, History& h,
                                  Mat3& s) { PlasticUpdate(params, f, t, J, b, h, s); },
                         "an elastoplastic model must take its Hencky trial state from the caller");
                     const Real K = params.bulk_modulus, G = params.shear_modulus;
                     ParallelFor((count + 1) / 2, 128, [&](size_t k) {
                       const size_t p0 = g.begin + 2 * k, n = std::min<size_t>(2, g.end - p0);
                       Mat3 f[2], b[2];
                       for (size_t i = 0; i < n; ++i) {
                         f[i] = Mat3::Identity() + dt * velocity_gradient[p0 + i];  // (2.18)
                         P.F[p0 + i] = f[i] * P.F[p0 + i];
                         b[i] = P.elastic_b[p0 + i];  // b^e stored as its 6 components
                       }
                       HenckyTrial t[2];
                       if (n == 2) {
                         HenckyTrialStates(K, G, f[0], b[0], f[1], b[1], t[0], t[1]);
                       } else {
                         t[0] = HenckyTrialState(K, G, f[0], b[0]);
                       }
                       for (size_t i = 0; i < n; ++i) {
                         const size_t p = p0 + i;
                         Mat3 stress;
                         History h = P.history.Get(p);  // the run's slots, the rest zero
                         PlasticUpdate(params, f[i], t[i], P.F[p].determinant(), b[i], h, stress);
                         P.history.Set(p, h);
                         P.elastic_b[p] = b[i];
                         P.stress[p] = stress;
                       }
                     });
                   },
                   [&](const NewtonianFluidParams& params) {
                     ParallelFor(count, 1024, [&](size_t k) {
                       const size_t p = g.begin + k;
                       const Mat3 f = Mat3::Identity() + dt * velocity_gradient[p];  // (2.18)
                       P.F[p] = f * P.F[p];
                       P.stress[p] = NewtonianFluidStress(params, P.F[p].determinant(),
                                                          velocity_gradient[p]);  // (6.1)-(6.2)
                     });
                   },
                   [&](const BinghamFluidParams& params) {
                     ParallelFor(count, 1024, [&](size_t k) {
                       const size_t p = g.begin + k;
                       const Mat3 f = Mat3::Identity() + dt * velocity_gradient[p];  // (2.18)
                       P.F[p] = f * P.F[p];
                       Mat3 stress;
                       History h = P.history.Get(p);
                       BinghamFluidUpdate(params, P.F[p].determinant(), velocity_gradient[p], dt,
                                          h, stress);  // A3D (7.37)
                       P.history.Set(p, h);
                       P.stress[p] = stress;
                     });
                   },
                   [&](const FrictionalFluidParams& params) {
                     ParallelFor(count, 1024, [&](size_t k) {
                       const size_t p = g.begin + k;
                       const Mat3 f = Mat3::Identity() + dt * velocity_gradient[p];  // (2.18)
                       P.F[p] = f * P.F[p];
                       Mat3 stress;
                       History h = P.history.Get(p);
                       FrictionalFluidUpdate(params, P.F[p].determinant(), velocity_gradient[p],
                                             dt, h, stress);  // A3D (7.38)
                       P.history.Set(p, h);
                       P.stress[p] = stress;
                     });
                   },
               },
               model.materials[g.material].params);
  }
}

namespace {

// psi per reference volume [J/m^3] of one model (the energy record, docs/results-format.md).
template <class Pm>
Real EnergyDensityOf(const Pm& p, const Mat3& F, const SymMat3& stress, const Mat3& strain) {
  if constexpr (std::is_same_v<Pm, LinearElasticParams>) {
    return LinearElasticEnergy(stress.matrix(), strain);
  } else if constexpr (std::is_same_v<Pm, NeoHookeanParams>) {
    return NeoHookeanEnergy(p, F);
  } else if constexpr (std::is_same_v<Pm, NewtonianFluidParams>) {
    return NewtonianFluidEnergy(p, F.determinant());
  } else if constexpr (std::is_same_v<Pm, BinghamFluidParams> ||
                       std::is_same_v<Pm, FrictionalFluidParams>) {
    return NewtonianFluidEnergy(EquationOfStateOf(p), F.determinant());  // EOS part only
  } else {  // elastoplastic: Hencky energy of b^e (3.45)
    return HenckyEnergy(p.bulk_modulus, p.shear_modulus, F.determinant(), stress);
  }
}

}  // namespace

Real StrainEnergyDensity(const Material& material, const Mat3& F, const Mat3& stress,
                         const Mat3& strain) {
  return std::visit(
      [&](const auto& p) { return EnergyDensityOf(p, F, SymMat3(stress), strain); },
      material.params);
}

void InitialHistory(const Material& material, const Mat3& stress, SymMat3& elastic_b,
                    History& history) {
  history = History{};
  elastic_b = Mat3::Identity();
  std::visit(
      [&](const auto& p) {
        using P = std::decay_t<decltype(p)>;
        if constexpr (kIsElastoplastic<P>) {
          // At F = I, tau = sigma: b^e from the elastic compliance (3.47), (4.40).
          elastic_b = ElasticBFromStress(p.bulk_modulus, p.shear_modulus, stress);
          if constexpr (requires { InitialPlasticHistory(p, stress, history); }) {
            InitialPlasticHistory(p, stress, history);
          }
        }
      },
      material.params);
}

int HistorySlotsOf(const MaterialParams& params) {
  return std::visit(
      [](const auto& p) {
        using P = std::decay_t<decltype(p)>;
        if constexpr (std::is_same_v<P, J2Params>) return kJ2HistorySlots;
        else if constexpr (std::is_same_v<P, DruckerPragerParams>) return kDpHistorySlots;
        else if constexpr (std::is_same_v<P, SmoothCapDruckerPragerParams>) return kScdpHistorySlots;
        else if constexpr (std::is_same_v<P, ModifiedDruckerPragerParams>) return kMdpHistorySlots;
        else if constexpr (std::is_same_v<P, MatsuokaNakaiParams>) return kMnHistorySlots;
        else if constexpr (std::is_same_v<P, MohrCoulombParams> || std::is_same_v<P, TrescaParams>)
          return kMcHistorySlots;
        else if constexpr (std::is_same_v<P, SnowParams>) return kSnowHistorySlots;
        else if constexpr (std::is_same_v<P, BinghamFluidParams> ||
                           std::is_same_v<P, FrictionalFluidParams>)
          return kFluidHistorySlots;
        else {
          static_assert(!kIsElastoplastic<P>, "an elastoplastic model must declare its history slots");
          return 0;
        }
      },
      params);
}

ParticleLayout ParticleLayoutFor(const Model& model, bool tractions) {
  ParticleLayout layout{model.transfer == TransferScheme::kApic, false, false, false, tractions, 0};
  for (const Material& m : model.materials) {
    std::visit(
        [&](const auto& p) {
          using P = std::decay_t<decltype(p)>;
          layout.strain |= std::is_same_v<P, LinearElasticParams>;  // (small-strain Hooke)
          layout.elastic_b |= kIsElastoplastic<P>;                 // b^e, Table 3.4
        },
        m.params);
    layout.history_slots = std::max(layout.history_slots, HistorySlotsOf(m.params));
  }
  layout.history = layout.history_slots > 0;
  return layout;
}

namespace {
const Mat3 kNoStrain = Mat3::Zero();  // models other than linear_elastic ignore the strain
}  // namespace

Real StrainEnergy(const Model& model, const std::vector<MaterialGroup>& groups,
                  const Particles& P) {
  Real total = 0;
  for (const MaterialGroup& g : groups) {
    const Material& mat = model.materials[g.material];
    std::array<Real, kReductionChunks> partial{};
    std::visit(  // once per group, not per particle
        [&](const auto& params) {
          ParallelChunks(g.end - g.begin, [&](size_t c, size_t b, size_t e) {
            Real sum = 0;
            for (size_t p = g.begin + b; p < g.begin + e; ++p)
              sum += EnergyDensityOf(params, P.F[p], P.stress[p],
                                     P.strain.empty() ? kNoStrain : P.strain[p]) *
                     P.volume0[p];
            partial[c] = sum;
          });
        },
        mat.params);
    for (Real s : partial) total += s;
  }
  return total;
}

}  // namespace surge
