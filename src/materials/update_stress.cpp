// Stress update dispatch: one std::visit per material group (STYLE H.4).
#include "materials/update_stress.h"

#include <algorithm>
#include <array>
#include <atomic>
#include <type_traits>

#include "core/parallel.h"
#include "core/simd.h"
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

// sigma : sym(L) from the 6 stored components (Voigt xx yy zz xy yz xz), times J V0: the stress
// power of one particle [W] (Mast 2013 (2.18): d = sym(L) is the rate the update uses).
Real StressPowerOf(const SymMat3& stress, const Mat3& l, Real J, Real V0) {
  const Real* t = stress.v;
  const Real power = t[0] * l(0, 0) + t[1] * l(1, 1) + t[2] * l(2, 2) + t[3] * (l(0, 1) + l(1, 0)) +
                     t[4] * (l(1, 2) + l(2, 1)) + t[5] * (l(0, 2) + l(2, 0));
  return J * V0 * power;
}

// One particle's step from its L_p (Mast 2013 (2.18)-(2.20)) for the non-Hencky models: F_{n+1} =
// (I + dt L) F_n, then the model's stress. Hencky models go through UpdateSpan's pairs instead.
template <class Pm>
void UpdateOne(const Pm& params, Real dt, size_t p, const Mat3& L, Particles& P) {
  const Mat3 f = Increment(dt, L);  // (2.18)
  P.F[p] = Mul(f, P.F[p]);  // F_{n+1} = f F_n (2.18)
  if constexpr (std::is_same_v<Pm, LinearElasticParams>) {
    Mat3 stress = P.stress[p];
    LinearElasticUpdate(params, Sym(f - Mat3::Identity()), stress, P.strain[p]);
    P.stress[p] = stress;
  } else if constexpr (std::is_same_v<Pm, NeoHookeanParams>) {
    P.stress[p] = NeoHookeanStress(params, P.F[p]);
  } else if constexpr (std::is_same_v<Pm, NewtonianFluidParams>) {
    P.stress[p] = NewtonianFluidStress(params, Det3(P.F[p]), L);  // (6.1)-(6.2)
  } else {
    static_assert(std::is_same_v<Pm, BinghamFluidParams> || std::is_same_v<Pm, FrictionalFluidParams>);
    Mat3 stress;
    History h = P.history.Get(p);
    if constexpr (std::is_same_v<Pm, BinghamFluidParams>)
      BinghamFluidUpdate(params, Det3(P.F[p]), L, dt, h, stress);  // A3D (7.37)
    else
      FrictionalFluidUpdate(params, Det3(P.F[p]), L, dt, h, stress);  // A3D (7.38)
    P.history.Set(p, h);
    P.stress[p] = stress;
  }
}

// The step of particles index(k), k in [k_begin, k_end), all of one material, with gradients
// grad(k); with `energy` returns the sum of their stress powers P_n + P_{n+1} in k order, else 0.
// Elastoplastic models (Hencky elasticity, b^e, Table 3.4) provide PlasticUpdate(params, f, trial,
// J, b^e, history, sigma) in their own headers and take the trial state from here, two particles
// or four at a time (HenckyTrialStates, HenckyTrialStates4: two or four spectral decompositions
// side by side, four in the AVX build, core/simd.h). Each particle's result
// is bitwise what the one-particle path gives, so neither the thread count, the split into spans
// nor the pairing changes a result.
// With `checks`, each particle goes through checks->Test after its update.
template <class Pm, class Index, class Grad>
Real UpdateSpan(const Pm& params, Real dt, size_t k_begin, size_t k_end, const Index& index,
                const Grad& grad, Particles& P, bool energy, EndChecks* checks = nullptr) {
  // P_n of particle p, read before its update (F_n, sigma_n), or P_{n+1} after it.
  const auto power_of = [&](size_t p, const Mat3& L, Real J) {
    return energy ? StressPowerOf(P.stress[p], L, J, P.volume0[p]) : 0.0;
  };
  Real sum = 0;
  if constexpr (kIsElastoplastic<Pm>) {
    static_assert(
        requires(const Mat3& f, const HenckyTrial& t, Real J, Mat3& b, History& h, Mat3& s) {
          PlasticUpdate(params, f, t, J, b, h, s);
        },
        "an elastoplastic model must take its Hencky trial state from the caller");
    const Real K = params.bulk_modulus, G = params.shear_modulus;
    const size_t group = WideSimd() ? 4 : 2;  // SymmetricEigen4 (AVX) or SymmetricEigen2
    for (size_t k0 = k_begin; k0 < k_end; k0 += group) {
      const size_t n = std::min<size_t>(group, k_end - k0);
      size_t p[4];
      Mat3 f[4], b[4];
      Real before[4] = {0, 0, 0, 0};
      for (size_t i = 0; i < n; ++i) {
        p[i] = index(k0 + i);
        const Mat3& L = grad(k0 + i);
        if (energy) before[i] = power_of(p[i], L, Det3(P.F[p[i]]));
        f[i] = Increment(dt, L);  // (2.18)
        P.F[p[i]] = Mul(f[i], P.F[p[i]]);  // F_{n+1} = f F_n (2.18)
        b[i] = P.elastic_b[p[i]];  // b^e stored as its 6 components
      }
      HenckyTrial t[4];
      if (n == 4) {
        HenckyTrialStates4(K, G, f, b, t);
      } else {
        for (size_t i = 0; i < n; i += 2) {
          if (i + 1 < n)
            HenckyTrialStates(K, G, f[i], b[i], f[i + 1], b[i + 1], t[i], t[i + 1]);
          else
            t[i] = HenckyTrialState(K, G, f[i], b[i]);
        }
      }
      Mat3 stress[4];
      History h[4];
      Real J[4];
      for (size_t i = 0; i < n; ++i) {
        h[i] = P.history.Get(p[i]);  // the run's slots, the rest zero
        J[i] = Det3(P.F[p[i]]);
      }
      bool lanes = false;  // the return four lanes wide, each lane bitwise the loop below
      if constexpr (requires { PlasticUpdate4(params, t, J, b, h, stress); }) {
        lanes = n == 4;
        if (lanes) PlasticUpdate4(params, t, J, b, h, stress);
      }
      if (!lanes)
        for (size_t i = 0; i < n; ++i)
          PlasticUpdate(params, f[i], t[i], J[i], b[i], h[i], stress[i]);
      for (size_t i = 0; i < n; ++i) {
        P.history.Set(p[i], h[i]);
        P.elastic_b[p[i]] = b[i];
        P.stress[p[i]] = stress[i];
        if (energy) sum += before[i] + power_of(p[i], grad(k0 + i), J[i]);
        if (checks) checks->Test(P, p[i], J[i]);
      }
    }
  } else {
    for (size_t k = k_begin; k < k_end; ++k) {
      const size_t p = index(k);
      const Mat3& L = grad(k);
      const Real before = energy ? power_of(p, L, Det3(P.F[p])) : 0.0;
      UpdateOne(params, dt, p, L, P);
      if (energy || checks) {
        const Real J = Det3(P.F[p]);
        if (energy) sum += before + power_of(p, L, J);
        if (checks) checks->Test(P, p, J);
      }
    }
  }
  return sum;
}

}  // namespace

void UpdateStress(const Model& model, const StepContext& ctx,
                  const std::vector<Mat3>& velocity_gradient,
                  const std::vector<MaterialGroup>& groups, Particles& P, Real* stress_power,
                  const EndChecks* checks, bool* clean) {
  const Real dt = ctx.dt;
  const bool energy = stress_power != nullptr;
  if (energy) *stress_power = 0;
  // Set by any span with a particle that fails the checks: a set, so thread-independent.
  std::atomic<bool> dirty{false};
  for (const MaterialGroup& g : groups) {
    const size_t count = g.end - g.begin;
    std::visit(
        [&](const auto& params) {
          const auto index = [&](size_t k) { return g.begin + k; };
          const auto grad = [&](size_t k) -> const Mat3& { return velocity_gradient[g.begin + k]; };
          // One span's update, with its own copy of the checks.
          const auto span = [&](size_t b, size_t e, bool with_energy) {
            if (!checks) return UpdateSpan(params, dt, b, e, index, grad, P, with_energy);
            EndChecks own = *checks;
            const Real sum = UpdateSpan(params, dt, b, e, index, grad, P, with_energy, &own);
            if (!own.clean) dirty.store(true, std::memory_order_relaxed);
            return sum;
          };
          if (!energy) {
            // Spans of 256 (Hencky models, in pairs) or 1024 particles.
            const size_t grain = kIsElastoplastic<std::decay_t<decltype(params)>> ? 256 : 1024;
            ParallelForStatic((count + grain - 1) / grain, [&](size_t c) {
              span(c * grain, std::min(count, (c + 1) * grain), false);
            });
            return;
          }
          // With the stress power: fixed chunks, summed in chunk order (any thread count).
          std::array<Real, kReductionChunks> partial{};
          ParallelChunks(count, [&](size_t c, size_t b, size_t e) { partial[c] = span(b, e, true); });
          for (Real v : partial) *stress_power += v;
        },
        model.materials[g.material].params);
  }
  if (clean) *clean = checks && !dirty.load();
}

Real UpdateStressOfRun(const Model& model, const StepContext& ctx, const uint32_t* ids,
                       const Mat3* velocity_gradient, size_t n, Particles& P, bool energy,
                       EndChecks* checks) {
  Real sum = 0;
  const auto index = [&](size_t k) { return size_t(ids[k]); };
  const auto grad = [&](size_t k) -> const Mat3& { return velocity_gradient[k]; };
  for (size_t begin = 0; begin < n;) {  // spans of one material, in run order
    const int32_t material = P.material[ids[begin]];
    size_t end = begin + 1;
    while (end < n && P.material[ids[end]] == material) ++end;
    sum += std::visit(
        [&](const auto& params) {
          return UpdateSpan(params, ctx.dt, begin, end, index, grad, P, energy, checks);
        },
        model.materials[size_t(material)].params);
    begin = end;
  }
  return sum;
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
    return NewtonianFluidEnergy(p, Det3(F));
  } else if constexpr (std::is_same_v<Pm, BinghamFluidParams> ||
                       std::is_same_v<Pm, FrictionalFluidParams>) {
    return NewtonianFluidEnergy(EquationOfStateOf(p), Det3(F));  // EOS part only
  } else {  // elastoplastic: Hencky energy of b^e (3.45)
    return HenckyEnergy(p.bulk_modulus, p.shear_modulus, Det3(F), stress);
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
