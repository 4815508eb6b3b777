// Volumetric anti-locking, node- and cell-based (Mast 2013 §4.4.1-4.4.5, Table 4.1; spec
// seed-algorithms.md §3.3-3.6): the trace of the trial (elastic) Hencky strain, theta = ln J^tr,
// is projected onto the control volumes, and the increment f is rescaled so that the particle
// takes the projected value, an F-bar-type form of the seed's hydrostatic shift (de Souza Neto
// et al. 1996, IJSS 33:3277). Scatter as in particle_to_grid.cpp.
#include "stabilize/antilocking.h"

#include <cmath>
#include <type_traits>
#include <variant>

#include "core/check.h"
#include "core/parallel.h"
#include "transfer/dispatch.h"
#include "transfer/stencil_loop.h"

namespace surge {
namespace {

// How theta_p is formed for one material group.
struct Mode {
  bool elastoplastic = false;  // J_n = sqrt(det b^e_n) rather than det F_n
  bool increment = false;      // theta = ln det f only (AntiLockingStrain::kIncrement)
};

struct Accum {
  Real w, wq;  // sum w m, sum w m theta
};

// Determinant; in 2-D (plane strain) of the in-plane block only.
template <int kDim>
Real Det(const Mat3& a) {
  if constexpr (kDim == 2) return a(0, 0) * a(1, 1) - a(0, 1) * a(1, 0);
  return a.determinant();
}

// Trial volumetric strain theta_p = tr(1/2 log b^tr) = ln det f + ln J_n (seed (4.36)-(4.38) and
// §3.5): J_n = det F_n for elastic solids and fluids, whose state is F; J^e_n = sqrt(det b^e_n)
// for the elastoplastic models, whose trial elastic strain is approximated (seed §4.4.5).
// With the increment option, theta_p = ln det f: only the step's volume change is projected.
template <int kDim>
Real TrialTheta(const Mat3& f, const Particles& P, size_t p, const Mode& mode) {
  if (mode.increment) return std::log(Det<kDim>(f));
  const Real jn = mode.elastoplastic ? std::sqrt(Det<kDim>(P.elastic_b[p])) : Det<kDim>(P.F[p]);
  return std::log(Det<kDim>(f) * jn);
}

// Control-volume sums of a per-particle quantity q_p = value(p) over one block's particles of
// group [begin, end), weight m_p, into its padded buffer, then into the grid slots (fixed order:
// particle order, then colour order). Node-based: weight N_ip m_p at every stencil node (4.29).
// Cell-based: weight m_p at the slot of the cell's lower corner node floor(x/dx), which every
// kernel's stencil contains (4.25). A non-finite q_p is skipped (left to CheckState).
template <int kDim, class K, bool kNode, class Value>
void ScatterBlock(const StepContext& ctx, const Particles& P, const std::vector<Vec3>& x_n,
                  size_t begin, size_t end, const SparseGrid& grid, size_t blk,
                  std::vector<Accum>& buf, AntiLockingScratch& s, const Value& value) {
  using Pad = BlockPad<kDim, K>;
  buf.assign(Pad::kSize, Accum{0, 0});
  const Vec3i origin = grid.block_origin[blk];
  bool any = false;
  for (uint32_t k = grid.block_begin[blk]; k < grid.block_begin[blk + 1]; ++k) {
    const uint32_t p = grid.sorted[k];
    if (p < begin || p >= end) continue;
    any = true;
    const Real q = value(p);
    if (!std::isfinite(q)) continue;
    const Real m = P.mass[p], mq = m * q;
    if constexpr (kNode) {
      Stencil<kDim, K> st;
      st.Compute(x_n[p], ctx.inv_dx, KernelHalfWidth<K>(kDim, P.volume0[p], ctx.inv_dx));
      const Vec3i lb = st.base - origin;
      for (int i = 0; i < st.W; ++i)
        for (int j = 0; j < st.W; ++j)
          for (int c = 0; c < st.Wz; ++c) {
            const Real w = st.Weight(i, j, c);
            Accum& a = buf[Pad::Index(lb.x() + i, lb.y() + j, lb.z() + c)];
            a.w += w * m;
            a.wq += w * mq;
          }
    } else {
      Vec3i cell = Vec3i::Zero();
      for (int d = 0; d < kDim; ++d) cell[d] = int(std::floor(x_n[p][d] * ctx.inv_dx));
      const Vec3i lc = cell - origin;
      Accum& a = buf[Pad::Index(lc.x(), lc.y(), lc.z())];
      a.w += m;
      a.wq += mq;
    }
  }
  if (!any) return;
  for (int a = 0; a < Pad::E; ++a)
    for (int b = 0; b < Pad::E; ++b)
      for (int c = 0; c < Pad::Ez; ++c) {
        const Accum& n = buf[Pad::Index(a, b, c)];
        if (n.w == 0) continue;
        const long g = PaddedToGrid(grid, blk, a, b, c);
        SURGE_ASSERT(g >= 0);
        if (g < 0) continue;
        s.weight[g] += n.w;
        s.weighted[g] += n.wq;
      }
}

// The projected value q-bar_p of the group's particles of one block, handed to apply(p, q-bar).
// Node-based: q-bar_p = sum_i N_ip q-bar_i, q-bar_i = sum N m q / sum N m (4.29)-(4.32).
// Cell-based: q-bar_p = q-bar_c = sum_c m q / sum_c m (4.25)-(4.28).
template <int kDim, class K, bool kNode, class Apply>
void GatherBlock(const StepContext& ctx, const Particles& P, const std::vector<Vec3>& x_n,
                 size_t begin, size_t end, const SparseGrid& grid, size_t blk,
                 const AntiLockingScratch& s, const Apply& apply) {
  const Vec3i origin = grid.block_origin[blk];
  for (uint32_t k = grid.block_begin[blk]; k < grid.block_begin[blk + 1]; ++k) {
    const uint32_t p = grid.sorted[k];
    if (p < begin || p >= end) continue;
    Real q_bar = 0;
    if constexpr (kNode) {
      Stencil<kDim, K> st;
      st.Compute(x_n[p], ctx.inv_dx, KernelHalfWidth<K>(kDim, P.volume0[p], ctx.inv_dx));
      const Vec3i lb = st.base - origin;
      for (int i = 0; i < st.W; ++i)
        for (int j = 0; j < st.W; ++j)
          for (int c = 0; c < st.Wz; ++c) {
            const Real w = st.Weight(i, j, c);
            if (w == 0) continue;  // a node of zero weight may have no mass at all
            const long g = PaddedToGrid(grid, blk, lb.x() + i, lb.y() + j, lb.z() + c);
            SURGE_ASSERT(g >= 0);
            q_bar += w * (s.weighted[g] / s.weight[g]);
          }
    } else {
      Vec3i cell = Vec3i::Zero();
      for (int d = 0; d < kDim; ++d) cell[d] = int(std::floor(x_n[p][d] * ctx.inv_dx));
      const Vec3i lc = cell - origin;
      const long g = PaddedToGrid(grid, blk, lc.x(), lc.y(), lc.z());
      SURGE_ASSERT(g >= 0);
      q_bar = s.weighted[g] / s.weight[g];
    }
    if (std::isfinite(q_bar)) apply(p, q_bar);  // a non-finite one is left to CheckState
  }
}

// Mass-weighted L2 projection of value(p) onto the group's control volumes and back (seed
// (4.12)-(4.13) with S = [1], sums (4.24)); apply(p, q-bar_p) receives the result.
template <int kDim, class K, bool kNode, class Value, class Apply>
void Project(const StepContext& ctx, const Particles& P, const std::vector<Vec3>& x_n,
             size_t begin, size_t end, const SparseGrid& grid, AntiLockingScratch& s,
             const Value& value, const Apply& apply) {
  s.weight.assign(grid.block_count() * kBlockNodes, 0.0);
  s.weighted.assign(grid.block_count() * kBlockNodes, 0.0);
  for (int colour = 0; colour < 8; ++colour) {
    const auto& blocks = grid.colour[colour];
    ParallelFor(blocks.size(), 1, [&](size_t i) {
      thread_local std::vector<Accum> buf;
      ScatterBlock<kDim, K, kNode>(ctx, P, x_n, begin, end, grid, blocks[i], buf, s, value);
    });
  }
  ParallelFor(grid.block_count(), 1, [&](size_t blk) {
    GatherBlock<kDim, K, kNode>(ctx, P, x_n, begin, end, grid, blk, s, apply);
  });
}

// Runs `body.template operator()<kDim, K, kNode>()` for the group's method, shape and dimension.
template <class Body>
void DispatchProjection(const Model& model, AntiLockingMethod method, const Body& body) {
  DispatchKernel(model.dim, model.shape, [&]<int kDim, class K>() {
    if (method == AntiLockingMethod::kNode)
      body.template operator()<kDim, K, true>();
    else
      body.template operator()<kDim, K, false>();
  });
}

}  // namespace

bool AnyAntiLocking(const Model& model) {
  for (const AntiLocking& a : model.antilocking)
    if (a.method != AntiLockingMethod::kNone) return true;
  return false;
}

void ProjectVolumetricStrain(const Model& model, const StepContext& ctx,
                             const std::vector<MaterialGroup>& groups, const Particles& particles,
                             const std::vector<Vec3>& x_n, const SparseGrid& grid,
                             AntiLockingScratch& scratch, std::vector<Mat3>& velocity_gradient) {
  SURGE_CHECK(x_n.size() == particles.size() && velocity_gradient.size() == particles.size(),
              "anti-locking needs x_n and L_p of every particle");
  std::vector<Mat3>& L = velocity_gradient;
  for (const MaterialGroup& g : groups) {
    if (g.end == g.begin || size_t(g.material) >= model.antilocking.size()) continue;
    const AntiLockingMethod method = model.antilocking[g.material].method;
    if (method == AntiLockingMethod::kNone) continue;
    Mode mode;
    mode.increment = model.antilocking[g.material].strain == AntiLockingStrain::kIncrement;
    mode.elastoplastic = std::visit(
        [](const auto& p) { return kIsElastoplastic<std::decay_t<decltype(p)>>; },
        model.materials[g.material].params);
    DispatchProjection(model, method, [&]<int kDim, class K, bool kNode>() {
      const auto theta = [&](size_t p) {
        return TrialTheta<kDim>(Mat3::Identity() + ctx.dt * L[p], particles, p, mode);  // (2.18)
      };
      // Seed §3.5 (AS1 as a hydrostatic shift): each principal trial log strain moves by
      // (theta-bar - theta)/dim, i.e. f-bar = exp((theta-bar - theta)/dim) f, so that
      // ln det(f-bar) + ln J_n = theta-bar; the deviatoric part of f is kept (P = I_dev, (4.16)).
      const auto shift = [&](size_t p, Real theta_bar) {
        Mat3 f = Mat3::Identity() + ctx.dt * L[p];  // (2.18)
        const Real theta_p = TrialTheta<kDim>(f, particles, p, mode);
        if (!std::isfinite(theta_p)) return;  // inverted: left to CheckState
        const Real scale = std::exp((theta_bar - theta_p) / kDim);
        if constexpr (kDim == 3) {
          f *= scale;
        } else {
          f.template topLeftCorner<2, 2>() *= scale;
        }
        L[p] = (f - Mat3::Identity()) / ctx.dt;
      };
      Project<kDim, K, kNode>(ctx, particles, x_n, g.begin, g.end, grid, scratch, theta, shift);
    });
  }
}

bool AnyStressAveraging(const Model& model) {
  for (const AntiLocking& a : model.antilocking)
    if (a.method != AntiLockingMethod::kNone && a.stress) return true;
  return false;
}

void ProjectMeanStress(const Model& model, const StepContext& ctx,
                       const std::vector<MaterialGroup>& groups, Particles& particles,
                       const std::vector<Vec3>& x_n, const SparseGrid& grid,
                       AntiLockingScratch& scratch) {
  SURGE_CHECK(x_n.size() == particles.size(), "stress averaging needs x_n of every particle");
  Particles& P = particles;
  for (const MaterialGroup& g : groups) {
    if (g.end == g.begin || size_t(g.material) >= model.antilocking.size()) continue;
    const AntiLocking& a = model.antilocking[g.material];
    if (a.method == AntiLockingMethod::kNone || !a.stress) continue;
    DispatchProjection(model, a.method, [&]<int kDim, class K, bool kNode>() {
      // The seed projects the specific stress sigma-bar = tau / rho0 (Table 4.1 step 6, (4.25)_2,
      // (4.29)_2 with M = [1 1 1 0 0 0]): q_p = tr(tau_p) / (3 rho0_p), tau = J sigma (3.37),
      // rho0_p = m_p / V0_p.
      const auto mean_specific = [&](size_t p) {
        return P.F[p].determinant() * P.volume0[p] * P.stress[p].trace() / (3.0 * P.mass[p]);
      };
      // Step 7 with P = I_dev: sigma_p <- sigma_p + (rho0_p q-bar_p / J_p - tr(sigma_p)/3) 1,
      // the deviator kept (4.28), (4.32)_2.
      const auto replace = [&](size_t p, Real q_bar) {
        const Real mean = q_bar * P.mass[p] / (P.volume0[p] * P.F[p].determinant());
        P.stress[p].diagonal().array() += mean - P.stress[p].trace() / 3.0;
      };
      Project<kDim, K, kNode>(ctx, P, x_n, g.begin, g.end, grid, scratch, mean_specific, replace);
    });
  }
}

}  // namespace surge
