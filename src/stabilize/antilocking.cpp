// Volumetric anti-locking, node- and cell-based (Mast 2013 §4.4.1-4.4.5, Table 4.1; spec
// seed-algorithms.md §3.3-3.6): the trace of the trial (elastic) Hencky strain, theta = ln J^tr,
// is projected onto the control volumes, and the increment f is rescaled so that the particle
// takes the projected value, an F-bar-type form of the seed's hydrostatic shift (de Souza Neto
// et al. 1996, IJSS 33:3277). Scatter as in particle_to_grid.cpp.
#include "stabilize/antilocking.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>
#include <limits>
#include <type_traits>
#include <variant>

#include "core/check.h"
#include "core/parallel.h"
#include "core/simd.h"
#include "materials/hencky.h"
#include "materials/symmetric_eigen.h"
#include "transfer/dispatch.h"
#include "transfer/owned_loops.h"
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

// Trial volumetric strain theta_p = tr(1/2 log b^tr) = ln det f + ln J_n (seed (4.36)-(4.38) and
// §3.5): J_n = det F_n for elastic solids and fluids, whose state is F; J^e_n = sqrt(det b^e_n)
// for the elastoplastic models, whose trial elastic strain is approximated (seed §4.4.5).
// With the increment option, theta_p = ln det f: only the step's volume change is projected.
template <int kDim>
Real TrialTheta(const Mat3& f, const Particles& P, size_t p, const Mode& mode) {
  if (mode.increment) return std::log(DetOfDim<kDim>(f));
  const Real jn =
      mode.elastoplastic ? std::sqrt(DetOfDim<kDim>(P.elastic_b[p])) : DetOfDim<kDim>(P.F[p]);
  return std::log(DetOfDim<kDim>(f) * jn);
}

// Seed §3.5 (AS1 as a hydrostatic shift): each principal trial log strain moves by
// (theta-bar - theta)/dim, i.e. f-bar = exp((theta-bar - theta)/dim) f, so that
// ln det(f-bar) + ln J_n = theta-bar; the deviatoric part of f is kept (P = I_dev, (4.16)).
// theta_p is the particle's TrialTheta of this f, kept from the scatter (AntiLockingScratch::
// theta). Replaces L_p by (f-bar - I)/dt. An inverted particle (theta_p not finite) is left to
// CheckState.
template <int kDim>
void ShiftVolumetric(const StepContext& ctx, Real theta_p, Real theta_bar, Mat3& L) {
  if (!std::isfinite(theta_p)) return;
  const Real scale = std::exp((theta_bar - theta_p) / kDim);
  // Entry by entry, the same operations as f = I + dt L (2.18), f *= scale (the in-plane block in
  // 2-D; the other entries times 1, which is exact), L = (f - I) / dt, as lanes of two over the
  // nine entries in storage order (column-major): GCC called Eigen's unrolled 3x3 assignments out
  // of line here (3.5 % of the column impact's step), and the nine scalar divisions were 2.8 % of
  // it.
  constexpr int kIn = kDim == 3 ? 0b111111111 : 0b000011011;  // the entries f *= scale touches
  Real* l = L.data();
  const Real dt = ctx.dt;
  for (int e = 0; e < 8; e += 2) {
    const Real2 delta = {e % 4 == 0 ? 1.0 : 0.0, 0.0};  // the diagonal: entries 0, 4 (and 8)
    const Real2 m = {(kIn >> e) & 1 ? scale : 1.0, (kIn >> (e + 1)) & 1 ? scale : 1.0};
    Real2 f;
    std::memcpy(&f, l + e, sizeof f);
    f = (delta + dt * f) * m;
    f = (f - delta) / dt;
    std::memcpy(l + e, &f, sizeof f);
  }
  const Real f8 = (1.0 + dt * l[8]) * ((kIn >> 8) & 1 ? scale : 1.0);
  l[8] = (f8 - 1.0) / dt;
}

// Control-volume sums of a per-particle quantity q_p = value(p) over one block's particles of
// group [begin, end), weight m_p, into its padded buffer, then into the grid slots (fixed order:
// particle order, then colour order). Node-based: weight N_ip m_p at every stencil node (4.29).
// Cell-based: weight m_p at the slot of the cell's lower corner node floor(x/dx), which every
// kernel's stencil contains (4.25). A non-finite q_p is skipped (left to CheckState).
// flush = false: only fill buf (OrderedBlockScatter adds it with FlushSlot).
template <class Pad>
void FlushSlot(const SparseGrid& grid, size_t blk, const std::vector<Accum>& buf,
               AntiLockingScratch& s, int a, int b, int c) {
  const Accum& n = buf[Pad::Index(a, b, c)];
  if (n.w == 0) return;
  const long g = PaddedToGrid(grid, blk, a, b, c);
  SURGE_ASSERT(g >= 0);
  if (g < 0) return;
  s.weight[g] += n.w;
  s.weighted[g] += n.wq;
}

template <int kDim, class K, bool kNode, class Value>
[[gnu::always_inline]] inline void ScatterBlock(
    const StepContext& ctx, const Particles& P, const std::vector<Vec3>& x_n, size_t begin,
    size_t end, const SparseGrid& grid, size_t blk, std::vector<Accum>& buf, AntiLockingScratch& s,
    const Value& value, bool flush = true) {
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
      // N_ip = w_i w_j w_c (tensor product): the (i, j) factors times m and m q once per row.
      // The node's two sums (w, wq) as one lane pair (core/simd.h).
      for (int i = 0; i < st.W; ++i)
        for (int j = 0; j < st.W; ++j) {
          const Real wxy = st.w[0][i] * st.w[1][j];
          const Real2 wmq = {wxy * m, wxy * mq};
          Accum* row = &buf[Pad::Index(lb.x() + i, lb.y() + j, lb.z())];
          if constexpr (kDim == 2) {  // one node per (i, j): w_z = 1
            row[0].w += wmq[0];
            row[0].wq += wmq[1];
            continue;
          }
          for (int c = 0; c < st.Wz; ++c) {
            Real2 n;
            std::memcpy(&n, &row[c], sizeof n);
            n += st.w[2][c] * wmq;
            std::memcpy(&row[c], &n, sizeof n);
          }
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
  if (!any || !flush) return;
  for (int a = 0; a < Pad::E; ++a)
    for (int b = 0; b < Pad::E; ++b)
      for (int c = 0; c < Pad::Ez; ++c) FlushSlot<Pad>(grid, blk, buf, s, a, b, c);
}

// The projected value q-bar_p of the group's particles of one block, handed to apply(p, q-bar);
// s.weighted holds the slot means q-bar_i (Project divides it by s.weight before the gather).
// Node-based: q-bar_p = sum_i N_ip q-bar_i, q-bar_i = sum N m q / sum N m (4.29)-(4.32), summed
// axis by axis with N_ip = w_x w_y w_z (the tensor product): sum_x w_x sum_y w_y sum_z w_z q-bar_i,
// 39 multiplications instead of 54 and short, independent chains of additions. Every stencil
// node is summed, those of zero weight too: Project sets an empty slot's mean to 0.
// Cell-based: q-bar_p = q-bar_c = sum_c m q / sum_c m (4.25)-(4.28).
template <int kDim, class K, bool kNode, class Apply>
[[gnu::always_inline]] inline void GatherBlock(
    const StepContext& ctx, const Particles& P, const std::vector<Vec3>& x_n, size_t begin,
    size_t end, const SparseGrid& grid, const SparseGrid::ParticleRun& run,
    const AntiLockingScratch& s, const Apply& apply) {
  using Pad = BlockPad<kDim, K>;
  const size_t blk = run.block;
  const Vec3i origin = grid.block_origin[blk];
  // Node-based: a run of more than a few particles first copies the q-bar_i of its block's padded
  // nodes into a halo (one neighbour lookup per node instead of one per particle and stencil
  // node; the same values, so the same sums). A node of no active block reads 0: no particle's
  // stencil holds one (the grid rebuild activates every stencil's blocks).
  thread_local std::vector<Real> halo;
  const bool use_halo = kNode && run.end - run.begin > 32;
  if (use_halo) {
    halo.resize(Pad::kSize);
    for (int a = 0; a < Pad::E; ++a)
      for (int b = 0; b < Pad::E; ++b)
        for (int c = 0; c < Pad::Ez; ++c) {
          const long g = PaddedToGrid(grid, blk, a, b, c);
          halo[Pad::Index(a, b, c)] = g < 0 ? 0.0 : s.weighted[g];
        }
  }
  for (uint32_t k = run.begin; k < run.end; ++k) {
    const uint32_t p = grid.sorted[k];
    if (p < begin || p >= end) continue;
    Real q_bar = 0;
    if constexpr (kNode) {
      Stencil<kDim, K> st;
      st.Compute(x_n[p], ctx.inv_dx, KernelHalfWidth<K>(kDim, P.volume0[p], ctx.inv_dx));
      const Vec3i lb = st.base - origin;
      for (int i = 0; i < st.W; ++i) {
        Real q_y = 0;
        for (int j = 0; j < st.W; ++j) {
          Real q_z = 0;
          if (use_halo) {
            const Real* row = &halo[size_t(Pad::Index(lb.x() + i, lb.y() + j, lb.z()))];
            if constexpr (kDim == 2) {
              q_z = row[0];  // w_z = 1
            } else {
              for (int c = 0; c < st.Wz; ++c) q_z += st.w[2][c] * row[c];
            }
          } else {
            for (int c = 0; c < st.Wz; ++c) {
              const long g = PaddedToGrid(grid, blk, lb.x() + i, lb.y() + j, lb.z() + c);
              SURGE_ASSERT(g >= 0);
              q_z += st.w[2][c] * (g < 0 ? 0.0 : s.weighted[g]);  // q-bar_i, from Project
            }
          }
          q_y += st.w[1][j] * q_z;
        }
        q_bar += st.w[0][i] * q_y;
      }
    } else {
      Vec3i cell = Vec3i::Zero();
      for (int d = 0; d < kDim; ++d) cell[d] = int(std::floor(x_n[p][d] * ctx.inv_dx));
      const Vec3i lc = cell - origin;
      const long g = PaddedToGrid(grid, blk, lc.x(), lc.y(), lc.z());
      SURGE_ASSERT(g >= 0);
      q_bar = s.weighted[g];  // q-bar_c, normalised once per cell slot by Project
    }
    if (std::isfinite(q_bar)) apply(p, q_bar);  // a non-finite one is left to CheckState
  }
}

// ScatterBlock and GatherBlock as out-of-line functions, portable and, where the CPU has it, an
// AVX build (core/simd.h): the same operations in the same order, so the same bits, with SSE4.1's
// `roundsd` for the stencil's floor (about ten instructions in the portable build) and the node
// sums' lane pairs in VEX form. Measured on the column impact (docs/benchmarks.md, twenty-fourth
// increment).
template <int kDim, class K, bool kNode, class Value>
void ScatterBlockPortable(const StepContext& ctx, const Particles& P, const std::vector<Vec3>& x_n,
                          size_t begin, size_t end, const SparseGrid& grid, size_t blk,
                          std::vector<Accum>& buf, AntiLockingScratch& s, const Value& value) {
  ScatterBlock<kDim, K, kNode>(ctx, P, x_n, begin, end, grid, blk, buf, s, value, false);
}
template <int kDim, class K, bool kNode, class Apply>
void GatherBlockPortable(const StepContext& ctx, const Particles& P, const std::vector<Vec3>& x_n,
                         size_t begin, size_t end, const SparseGrid& grid,
                         const SparseGrid::ParticleRun& run, const AntiLockingScratch& s,
                         const Apply& apply) {
  GatherBlock<kDim, K, kNode>(ctx, P, x_n, begin, end, grid, run, s, apply);
}
#if SURGE_HAVE_WIDE_SIMD
template <int kDim, class K, bool kNode, class Value>
SURGE_TARGET_WIDE void ScatterBlockWide(const StepContext& ctx, const Particles& P,
                                        const std::vector<Vec3>& x_n, size_t begin, size_t end,
                                        const SparseGrid& grid, size_t blk,
                                        std::vector<Accum>& buf, AntiLockingScratch& s,
                                        const Value& value) {
  ScatterBlock<kDim, K, kNode>(ctx, P, x_n, begin, end, grid, blk, buf, s, value, false);
}
template <int kDim, class K, bool kNode, class Apply>
SURGE_TARGET_WIDE void GatherBlockWide(const StepContext& ctx, const Particles& P,
                                       const std::vector<Vec3>& x_n, size_t begin, size_t end,
                                       const SparseGrid& grid, const SparseGrid::ParticleRun& run,
                                       const AntiLockingScratch& s, const Apply& apply) {
  GatherBlock<kDim, K, kNode>(ctx, P, x_n, begin, end, grid, run, s, apply);
}
#endif

// Mass-weighted L2 projection of value(p) onto the group's control volumes and back (seed
// (4.12)-(4.13) with S = [1], sums (4.24)); apply(p, q-bar_p) receives the result.
template <int kDim, class K, bool kNode, class Value, class Apply>
void Project(const StepContext& ctx, const Particles& P, const std::vector<Vec3>& x_n,
             size_t begin, size_t end, const SparseGrid& grid, AntiLockingScratch& s,
             const Value& value, const Apply& apply) {
  using Pad = BlockPad<kDim, K>;
  // The sums start at zero, cleared block by block by the thread that owns the block (as the
  // P2G sums in RebuildGrid): a serial clear was 0.5 % of a 1e4-particle water step.
  const size_t per_block = size_t(grid.block_nodes);
  s.weight.resize(grid.block_count() * per_block);
  s.weighted.resize(grid.block_count() * per_block);
  ForOwnedBlocks(grid, [&](size_t b) {
    std::fill_n(s.weight.begin() + ptrdiff_t(b * per_block), per_block, 0.0);
    std::fill_n(s.weighted.begin() + ptrdiff_t(b * per_block), per_block, 0.0);
  });
  // Each block on the thread that owns its particles, every slot's sums in colour order.
  [[maybe_unused]] const bool wide = WideSimd();
  using Buffer = std::vector<Accum>;
  OrderedBlockScatter<Buffer>(
      grid, kDim,
      [&](size_t b, Buffer& buf) {
#if SURGE_HAVE_WIDE_SIMD
        if (wide)
          return ScatterBlockWide<kDim, K, kNode>(ctx, P, x_n, begin, end, grid, b, buf, s, value);
#endif
        ScatterBlockPortable<kDim, K, kNode>(ctx, P, x_n, begin, end, grid, b, buf, s, value);
      },
      [&](size_t b, const Buffer& buf, int o) {
        ForPaddedNodesIn<Pad>(o, [&](int a, int bb, int c) { FlushSlot<Pad>(grid, b, buf, s, a, bb, c); });
      });
  // The node (cell) means q-bar_i = sum N m q / sum N m (4.30), once per slot, in place: the gather
  // then multiplies instead of dividing at every stencil node. An empty slot is never used with a
  // weight > 0: its node mean is 0, which the node gather multiplies by a zero weight; its cell
  // mean stays 0/0 = NaN (only a particle whose own q_p was not finite reads it, and skips it).
  ForOwnedBlocks(grid, [&](size_t b) {
    for (size_t g = b * per_block; g < (b + 1) * per_block; ++g)
      s.weighted[g] = kNode && s.weight[g] == 0 ? 0.0 : s.weighted[g] / s.weight[g];
  });
  ForOwnedRuns(grid, [&](size_t r) {
#if SURGE_HAVE_WIDE_SIMD
    if (wide)
      return GatherBlockWide<kDim, K, kNode>(ctx, P, x_n, begin, end, grid, grid.runs[r], s, apply);
#endif
    GatherBlockPortable<kDim, K, kNode>(ctx, P, x_n, begin, end, grid, grid.runs[r], s, apply);
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

// ---- Full-tensor approximations: AS2, AS3CV and the hybrid control volume (seed (4.17)-(4.23),
// (4.33)-(4.35)) in the finite-deformation form of §4.4.4-4.4.5. ----

// Filtered components (seed filter M of (4.17)-(4.22)): the trace and the normal deviator
// components, which vary linearly over a control volume (S rows [1, xi, eta, zeta]), then the
// shears, constant. 3-D: {tr eps, e11, e22 | eps12, eps13, eps23}, e33 = -e11 - e22. 2-D (plane
// strain, the in-plane block): {eps11 + eps22, (eps11 - eps22)/2 | eps12}.
// kTrace: the trace alone, linear (node-based AS1 with `fit: linear`, ProjectLinearTrace): 14
// moments per node in 3-D and 9 in 2-D instead of 25 and 13, the same sums for the trace.
template <int kDim, bool kTrace = false>
struct Filtered {
  static constexpr bool kTraceOnly = kTrace;
  static constexpr int kLinear = kTrace ? 1 : kDim == 3 ? 3 : 2;  // linear components, trace first
  static constexpr int kConst = kTrace ? 0 : kDim == 3 ? 3 : 1;   // constant components (shears)
  static constexpr int kSym = kDim * (kDim + 1) / 2;  // entries of sum w xi xi^T
  // Moment sums of one cell: sum w, sum w xi, sum w xi xi^T, per linear component sum w q and
  // sum w xi q, per constant component sum w q (the normal equations of (4.25)_1, as particle
  // sums (4.24); w = m_p).
  static constexpr int kMoments = 1 + kDim + kSym + kLinear * (1 + kDim) + kConst;
  std::array<Real, kLinear + kConst> q;

  static Filtered Of(const Mat3& e) {
    static_assert(!kTrace);
    Filtered r;
    if constexpr (kDim == 3) {
      const Real tr = e.trace();
      r.q = {tr, e(0, 0) - tr / 3, e(1, 1) - tr / 3, e(0, 1), e(0, 2), e(1, 2)};
    } else {
      r.q = {e(0, 0) + e(1, 1), (e(0, 0) - e(1, 1)) / 2, e(0, 1)};
    }
    return r;
  }
  // The reconstruction M* (4.19): the tensor of these components; in 2-D the out-of-plane
  // entries are the particle's own (`own`), the in-plane/out-of-plane shears zero.
  Mat3 Tensor(const Mat3& own) const {
    static_assert(!kTrace);
    Mat3 e;
    if constexpr (kDim == 3) {
      const Real t = q[0] / 3;
      e << t + q[1], q[3], q[4],  //
          q[3], t + q[2], q[5],   //
          q[4], q[5], t - q[1] - q[2];
    } else {
      e.setZero();
      e(0, 0) = q[0] / 2 + q[1];
      e(1, 1) = q[0] / 2 - q[1];
      e(0, 1) = e(1, 0) = q[2];
      e(2, 2) = own(2, 2);
    }
    return e;
  }
};

// Position of x in its cell, xi = x/dx - floor(x/dx) - 1/2, in cell units (origin at the cell
// centre; the fitted field does not depend on the origin, spec §3.3 [DERIVED]).
template <int kDim>
Eigen::Matrix<Real, kDim, 1> CellXi(const Vec3& x, Real inv_dx, Vec3i& cell) {
  Eigen::Matrix<Real, kDim, 1> xi;
  cell.setZero();
  for (int d = 0; d < kDim; ++d) {
    const Real u = x[d] * inv_dx;
    cell[d] = int(std::floor(u));
    xi[d] = u - cell[d] - 0.5;
  }
  return xi;
}

// Weighted least-squares fit over one control volume (a cell, or a node's support), from its
// moment sums `a` (Filtered::kMoments), at the position xi (min_trace, min_det: the singularity
// test below): the linear components a + b.(xi - c) with the mass centroid c as origin
// (spec §3.3 [REC]), the normal equations in centred form C b = sum w (xi - c) q / sum w,
// C = sum w (xi - c)(xi - c)^T / sum w; the constant components the weighted mean. When C is
// singular (the cell's particles on a plane or a line, a body entering a cell) every component
// falls back to the constant approximation for this control volume and step (seed §4.4.6).
// max_dist limits the extrapolation: a point farther than max_dist from the centroid in the
// support's own metric, (xi - c)^T C^-1 (xi - c) > max_dist^2, is pulled back along xi - c onto
// that ellipsoid (the linear fit's variance grows as that distance squared; a limiter of ours,
// not the seed's).
template <int kDim, class F = Filtered<kDim>>
F CellFit(const Real* a, const Eigen::Matrix<Real, kDim, 1>& xi, bool* linear_out,
          Real min_trace = 1e-8, Real min_det = 1e-10,
          Real max_dist = std::numeric_limits<Real>::infinity()) {
  using VecD = Eigen::Matrix<Real, kDim, 1>;
  using MatD = Eigen::Matrix<Real, kDim, kDim>;
  const Real s0 = a[0];
  VecD c;
  for (int d = 0; d < kDim; ++d) c[d] = a[1 + d] / s0;
  MatD C;
  int k = 1 + kDim;
  for (int d = 0; d < kDim; ++d)
    for (int e = d; e < kDim; ++e, ++k) C(d, e) = C(e, d) = a[k] / s0 - c[d] * c[e];
  const Real tr = C.trace();
  // Singularity test: the spread must exceed round-off (tr C > 1e-8 cell^2, an RMS spread of
  // 1e-4 cells; one particle leaves C = O(1e-16) of either sign) and det C must not be small
  // against (tr C / dim)^dim, 1 for an isotropic spread.
  const bool linear = tr > min_trace && C.determinant() > min_det * std::pow(tr / kDim, kDim);
  if (linear_out) *linear_out = linear;
  const MatD Cinv = linear ? MatD(C.inverse()) : MatD::Zero();
  VecD at = xi - c;  // where the fit is evaluated, relative to the centroid
  if (linear && std::isfinite(max_dist)) {
    const Real d2 = at.dot(Cinv * at);
    if (d2 > max_dist * max_dist) at *= max_dist / std::sqrt(d2);
  }
  F out;
  for (int l = 0; l < F::kLinear; ++l, k += 1 + kDim) {
    const Real mean = a[k] / s0;
    out.q[l] = mean;
    if (linear) {
      VecD cov;
      for (int d = 0; d < kDim; ++d) cov[d] = a[k + 1 + d] / s0 - c[d] * mean;
      out.q[l] += (Cinv * cov).dot(at);
    }
  }
  for (int l = 0; l < F::kConst; ++l, ++k) out.q[F::kLinear + l] = a[k] / s0;
  return out;
}

// g(A) = Q diag(g(lambda)) Q^T of the symmetric in-plane 2x2 block of A, by one exact rotation.
template <class G>
Eigen::Matrix2d SymmetricFunction2(const Mat3& A, const G& g) {
  const Real a = A(0, 0), d = A(1, 1), c = 0.5 * (A(0, 1) + A(1, 0));
  const Real phi = 0.5 * std::atan2(2 * c, a - d), cs = std::cos(phi), sn = std::sin(phi);
  const Real l1 = a * cs * cs + 2 * c * sn * cs + d * sn * sn;
  const Real l2 = a * sn * sn - 2 * c * sn * cs + d * cs * cs;
  Eigen::Matrix2d Q;
  Q << cs, -sn, sn, cs;
  return Q * Eigen::Vector2d(g(l1), g(l2)).asDiagonal() * Q.transpose();
}

// The trial (elastic) Hencky strain eps = 1/2 ln b^tr, b^tr = f b_ref f^T (seed (4.36)-(4.38)),
// and the inverse stretch (b^tr)^(-1/2). In 2-D the in-plane block and the 33 entry separately
// (plane strain: b^tr is block diagonal). False when b^tr is not positive definite.
template <int kDim>
bool TrialLogStrain(const Mat3& f, const Mat3& b_ref, Mat3& eps, Mat3& inv_stretch) {
  const Mat3 b = f * b_ref * f.transpose();
  if constexpr (kDim == 3) {
    Vec3 lam;
    Mat3 Q;
    SymmetricEigen(b, lam, Q);
    if (!(lam.minCoeff() > 0) || !std::isfinite(lam.maxCoeff())) return false;
    eps = FromPrincipal(Q, 0.5 * lam.array().log().matrix());
    inv_stretch = FromPrincipal(Q, lam.array().rsqrt().matrix());
  } else {
    const Real det = b(0, 0) * b(1, 1) - b(0, 1) * b(1, 0);
    if (!(det > 0) || !(b(0, 0) > 0) || !(b(2, 2) > 0) || !std::isfinite(det)) return false;
    eps.setZero();
    inv_stretch.setZero();
    eps.topLeftCorner<2, 2>() = SymmetricFunction2(b, [](Real l) { return 0.5 * std::log(l); });
    inv_stretch.topLeftCorner<2, 2>() = SymmetricFunction2(b, [](Real l) { return 1 / std::sqrt(l); });
    eps(2, 2) = 0.5 * std::log(b(2, 2));
    inv_stretch(2, 2) = 1 / std::sqrt(b(2, 2));
  }
  return true;
}

// The increment that takes b_ref to exp(2 eps_h) (seed (4.40)): f-bar = exp(eps_h) (b^tr)^(-1/2) f,
// so f-bar b_ref f-bar^T = exp(eps_h) (b^tr)^(-1/2) b^tr (b^tr)^(-1/2) exp(eps_h) = exp(2 eps_h).
// In 2-D the in-plane block only; f's out-of-plane entries are kept (f33 = 1 in plane strain).
template <int kDim>
Mat3 ProjectedIncrement(const Mat3& f, const Mat3& eps_h, const Mat3& inv_stretch) {
  if constexpr (kDim == 3) {
    Vec3 e;
    Mat3 Q;
    SymmetricEigen(eps_h, e, Q);
    return FromPrincipal(Q, e.array().exp().matrix()) * inv_stretch * f;
  } else {
    Mat3 out = f;
    const Eigen::Matrix2d v = SymmetricFunction2(eps_h, [](Real l) { return std::exp(l); });
    out.topLeftCorner<2, 2>() = v * inv_stretch.topLeftCorner<2, 2>() * f.topLeftCorner<2, 2>();
    return out;
  }
}

// Adds one particle's weighted moments (weight w at position xi, components f) to the sums `a`
// (layout of Filtered::kMoments). The cell-based scatter's; the node-based one forms the same
// moments as products of per-axis factors (ScatterMoments, MomentExponents).
template <int kDim, class F>
void AddMoments(Real* a, Real w, const Eigen::Matrix<Real, kDim, 1>& xi, const F& f) {
  int j = 0;
  a[j++] += w;
  for (int d = 0; d < kDim; ++d) a[j++] += w * xi[d];
  for (int d = 0; d < kDim; ++d)
    for (int e = d; e < kDim; ++e) a[j++] += w * xi[d] * xi[e];
  for (int l = 0; l < F::kLinear; ++l) {
    a[j++] += w * f.q[l];
    for (int d = 0; d < kDim; ++d) a[j++] += w * xi[d] * f.q[l];
  }
  for (int l = 0; l < F::kConst; ++l) a[j++] += w * f.q[F::kLinear + l];
}

// The moments of AddMoments' layout as products: moment mi is w prod_d xi_d^e[mi][d], times the
// component q[comp[mi]] (comp -1: none).
template <int kDim, class F>
struct MomentExponents {
  std::array<std::array<int, 3>, F::kMoments> e{};
  std::array<int, F::kMoments> comp{};
  constexpr MomentExponents() {
    int j = 0;
    const auto put = [&](int d0, int d1, int component) {  // d0, d1: an axis each, or -1
      if (d0 >= 0) ++e[size_t(j)][size_t(d0)];
      if (d1 >= 0) ++e[size_t(j)][size_t(d1)];
      comp[size_t(j++)] = component;
    };
    put(-1, -1, -1);
    for (int d = 0; d < kDim; ++d) put(d, -1, -1);
    for (int d = 0; d < kDim; ++d)
      for (int b = d; b < kDim; ++b) put(d, b, -1);
    for (int l = 0; l < F::kLinear; ++l) {
      put(-1, -1, l);
      for (int d = 0; d < kDim; ++d) put(d, -1, l);
    }
    for (int l = 0; l < F::kConst; ++l) put(-1, -1, F::kLinear + l);
  }
};

// Adds the part of a block's padded moment buffer that lies in its upper neighbour o into the
// grid slots (stride kMoments; OrderedBlockScatter's add).
template <int kDim, class K, class F>
void AddMomentsIn(const SparseGrid& grid, size_t blk, const std::vector<Real>& buf, int o,
                AntiLockingScratch& s) {
  using Pad = BlockPad<kDim, K>;
  constexpr int M = F::kMoments;
  ForPaddedNodesIn<Pad>(o, [&](int a, int b, int c) {
    const Real* n = &buf[size_t(Pad::Index(a, b, c)) * M];
    if (n[0] == 0) return;
    const long g = PaddedToGrid(grid, blk, a, b, c);
    SURGE_ASSERT(g >= 0);
    if (g < 0) return;
    Real* out = &s.moments[size_t(g) * M];
    for (int j = 0; j < M; ++j) out[j] += n[j];
  });
}

// Moment sums of one block's particles of [begin, end), through the padded block buffer as in
// ScatterBlock (fixed order: particle order, then colour order), into scratch.moments (stride
// kMoments). Cell-based (4.25)_1: weight m_p at xi = the position in the cell (CellXi), in the
// slot of the cell's lower-corner node. Node-based (4.29)_1 with H_i = sum S^T S N_ip m_p: weight
// N_ip m_p at every node of the stencil, at xi = (x_p - x_i)/dx (node-centred, cell units).
// The components: the filter of s.tensor[p], or with F::kTraceOnly the trace s.theta[p].
template <int kDim, class K, bool kNode, class F>
[[gnu::always_inline]] inline void ScatterMoments(const StepContext& ctx, const Particles& P,
                                                  const std::vector<Vec3>& x_n, size_t begin,
                                                  size_t end, const SparseGrid& grid, size_t blk,
                                                  std::vector<Real>& buf,
                                                  const AntiLockingScratch& s) {
  using Pad = BlockPad<kDim, K>;
  constexpr int M = F::kMoments;
  buf.assign(size_t(Pad::kSize) * M, 0.0);
  const Vec3i origin = grid.block_origin[blk];
  for (uint32_t k = grid.block_begin[blk]; k < grid.block_begin[blk + 1]; ++k) {
    const uint32_t p = grid.sorted[k];
    if (p < begin || p >= end || !s.tensor_ok[p]) continue;
    F f;
    if constexpr (F::kTraceOnly)
      f.q[0] = s.theta[p];
    else
      f = F::Of(s.tensor[p]);
    if constexpr (kNode) {
      // The node moments separate along the axes: with N_ip = w_x w_y w_z and xi = (x_p - x_i)/dx,
      // every moment of AddMoments is m q^(0|1) prod_d w_d xi_d^e_d (MomentExponents), formed as
      // a per-(i, j) factor u times a per-z-node factor v: M multiply-adds per node.
      constexpr MomentExponents<kDim, F> kE{};
      Stencil<kDim, K> st;
      st.Compute(x_n[p], ctx.inv_dx, KernelHalfWidth<K>(kDim, P.volume0[p], ctx.inv_dx));
      const Vec3i lb = st.base - origin;
      Real pw[3][3][Stencil<kDim, K>::W];  // [axis][exponent e][node k]: w_d(k) xi_d(k)^e
      for (int d = 0; d < 3; ++d)
        for (int k = 0; k < (d < kDim ? st.W : 1); ++k) {
          const Real xi = d < kDim ? x_n[p][d] * ctx.inv_dx - (st.base[d] + k) : 0.0;
          pw[d][0][k] = st.w[d][k];
          pw[d][1][k] = st.w[d][k] * xi;
          pw[d][2][k] = st.w[d][k] * xi * xi;
        }
      Real qm[M], v[Stencil<kDim, K>::Wz][M];  // m q_comp (m alone without a component); z factors
      for (int mi = 0; mi < M; ++mi) {
        qm[mi] = kE.comp[mi] < 0 ? P.mass[p] : P.mass[p] * f.q[size_t(kE.comp[mi])];
        for (int c = 0; c < st.Wz; ++c) v[c][mi] = pw[2][kE.e[mi][2]][c];
      }
      for (int i = 0; i < st.W; ++i)
        for (int j = 0; j < st.W; ++j) {
          Real u[M];
          for (int mi = 0; mi < M; ++mi)
            u[mi] = qm[mi] * pw[0][kE.e[mi][0]][i] * pw[1][kE.e[mi][1]][j];
          Real* __restrict row = &buf[size_t(Pad::Index(lb.x() + i, lb.y() + j, lb.z())) * M];
          for (int c = 0; c < st.Wz; ++c)
            for (int mi = 0; mi < M; ++mi) row[c * M + mi] += u[mi] * v[c][mi];
        }
    } else {
      Vec3i cell;
      const auto xi = CellXi<kDim>(x_n[p], ctx.inv_dx, cell);
      const Vec3i lc = cell - origin;
      AddMoments<kDim, F>(&buf[size_t(Pad::Index(lc.x(), lc.y(), lc.z())) * M], P.mass[p], xi, f);
    }
  }
}

// ScatterMoments out of line, portable and AVX builds (as ScatterBlockWide: the same bits).
template <int kDim, class K, bool kNode, class F>
void ScatterMomentsPortable(const StepContext& ctx, const Particles& P,
                            const std::vector<Vec3>& x_n, size_t begin, size_t end,
                            const SparseGrid& grid, size_t blk, std::vector<Real>& buf,
                            const AntiLockingScratch& s) {
  ScatterMoments<kDim, K, kNode, F>(ctx, P, x_n, begin, end, grid, blk, buf, s);
}
#if SURGE_HAVE_WIDE_SIMD
template <int kDim, class K, bool kNode, class F>
SURGE_TARGET_WIDE void ScatterMomentsWide(const StepContext& ctx, const Particles& P,
                                          const std::vector<Vec3>& x_n, size_t begin, size_t end,
                                          const SparseGrid& grid, size_t blk,
                                          std::vector<Real>& buf, const AntiLockingScratch& s) {
  ScatterMoments<kDim, K, kNode, F>(ctx, P, x_n, begin, end, grid, blk, buf, s);
}
#endif

// The node gather q^h_p = sum_i N_ip q-hat_i (4.32) of one particle run, from the node fits
// s.node_fit (stride Q), each particle's sum handed to hand(p, sum).
template <int kDim, class K, class F, class Hand>
[[gnu::always_inline]] inline void GatherNodeFits(const StepContext& ctx, const Particles& P,
                                                  const std::vector<Vec3>& x_n, size_t begin,
                                                  size_t end, const SparseGrid& grid,
                                                  const SparseGrid::ParticleRun& run,
                                                  const AntiLockingScratch& s, const Hand& hand) {
  using Pad = BlockPad<kDim, K>;
  constexpr int Q = F::kLinear + F::kConst;
  const size_t blk = run.block;
  const Vec3i origin = grid.block_origin[blk];
  // The block's padded node fits, copied once per run (as GatherBlock's halo: the same
  // values, one neighbour lookup per node); 0 where no block is active (as an empty node:
  // only zero weights meet them).
  thread_local std::vector<Real> halo;
  halo.resize(size_t(Pad::kSize) * Q);
  for (int a = 0; a < Pad::E; ++a)
    for (int b = 0; b < Pad::E; ++b)
      for (int c = 0; c < Pad::Ez; ++c) {
        const long g = PaddedToGrid(grid, blk, a, b, c);
        Real* h = &halo[size_t(Pad::Index(a, b, c)) * Q];
        for (int q = 0; q < Q; ++q)
          h[q] = g < 0 ? 0.0 : s.node_fit[size_t(g) * Q + size_t(q)];
      }
  for (uint32_t k = run.begin; k < run.end; ++k) {
    const uint32_t p = grid.sorted[k];
    if (p < begin || p >= end || !s.tensor_ok[p]) continue;
    Stencil<kDim, K> st;
    st.Compute(x_n[p], ctx.inv_dx, KernelHalfWidth<K>(kDim, P.volume0[p], ctx.inv_dx));
    const Vec3i lb = st.base - origin;
    // sum_i N_ip q-hat_i axis by axis, as GatherBlock (every node: empty ones hold 0).
    F sum;
    sum.q.fill(0);
    for (int i = 0; i < st.W; ++i) {
      std::array<Real, Q> sum_y{};
      for (int j = 0; j < st.W; ++j) {
        std::array<Real, Q> sum_z{};
        const Real* row = &halo[size_t(Pad::Index(lb.x() + i, lb.y() + j, lb.z())) * Q];
        for (int c = 0; c < st.Wz; ++c)
          for (int q = 0; q < Q; ++q) sum_z[size_t(q)] += st.w[2][c] * row[c * Q + q];
        for (int q = 0; q < Q; ++q) sum_y[size_t(q)] += st.w[1][j] * sum_z[size_t(q)];
      }
      for (int q = 0; q < Q; ++q) sum.q[size_t(q)] += st.w[0][i] * sum_y[size_t(q)];
    }
    hand(p, sum);
  }
}

template <int kDim, class K, class F, class Hand>
void GatherNodeFitsPortable(const StepContext& ctx, const Particles& P,
                            const std::vector<Vec3>& x_n, size_t begin, size_t end,
                            const SparseGrid& grid, const SparseGrid::ParticleRun& run,
                            const AntiLockingScratch& s, const Hand& hand) {
  GatherNodeFits<kDim, K, F>(ctx, P, x_n, begin, end, grid, run, s, hand);
}
#if SURGE_HAVE_WIDE_SIMD
template <int kDim, class K, class F, class Hand>
SURGE_TARGET_WIDE void GatherNodeFitsWide(const StepContext& ctx, const Particles& P,
                                          const std::vector<Vec3>& x_n, size_t begin, size_t end,
                                          const SparseGrid& grid,
                                          const SparseGrid::ParticleRun& run,
                                          const AntiLockingScratch& s, const Hand& hand) {
  GatherNodeFits<kDim, K, F>(ctx, P, x_n, begin, end, grid, run, s, hand);
}
#endif

// The full-tensor approximation of one material group's per-particle tensor field s.tensor (the
// particles with s.tensor_ok): AS2 / AS3CV on cell- or node-based control volumes, or the hybrid
// (trace from node-based AS1, deviator from cell-based AS2). Hands each particle's approximated
// tensor to apply(p, tensor) (seed Table 4.1 steps 3 and 6: (4.25)-(4.27), (4.29)-(4.32),
// (4.33)-(4.35)). In 2-D the out-of-plane normal entry is the particle's own.
// F = Filtered<kDim, true>: the trace s.theta[p] alone, node-based (ProjectLinearTrace);
// apply(p, theta-hat_p) receives the fitted trace.
template <int kDim, class K, class F = Filtered<kDim>, class Apply>
void FitFullTensor(const StepContext& ctx, const Particles& P, const std::vector<Vec3>& x_n,
                   size_t begin, size_t end, const SparseGrid& grid, const AntiLocking& al,
                   AntiLockingScratch& s, const Apply& apply) {
  constexpr int M = F::kMoments;
  // The fitted components handed to apply: the reconstructed tensor M* (4.19), or the trace.
  const auto hand = [&](size_t p, const F& fit) {
    if constexpr (F::kTraceOnly)
      apply(p, fit.q[0]);
    else
      apply(p, fit.Tensor(s.tensor[p]));
  };
  // Hybrid, volumetric part: node-based AS1 of the trace (4.29)-(4.32), (4.34)_1, (4.35)_1.
  const bool hybrid = !F::kTraceOnly && al.method == AntiLockingMethod::kHybrid;
  if constexpr (!F::kTraceOnly) {
    if (hybrid) {
      s.theta_bar.assign(P.size(), std::numeric_limits<Real>::quiet_NaN());
      const auto theta = [&](size_t p) {
        return s.tensor_ok[p] ? F::Of(s.tensor[p]).q[0] : std::numeric_limits<Real>::quiet_NaN();
      };
      const auto keep = [&](size_t p, Real theta_bar) { s.theta_bar[p] = theta_bar; };
      Project<kDim, K, true>(ctx, P, x_n, begin, end, grid, s, theta, keep);
    }
  }
  // Cell moments (4.25) with H_c = sum S^T S m, or node moments (4.29) with H_i = sum S^T S N m,
  // colour-phased as every scatter.
  const bool node = al.method == AntiLockingMethod::kNode;
  const bool constant_trace = al.approach == AntiLockingApproach::kConstantVolumetric;
  // `fit: constant` (the seed's ConstantAntiLocking): every component the control volume's
  // weighted mean, as the singularity fallback (an infinite spread threshold) everywhere.
  constexpr Real kAlwaysConstant = std::numeric_limits<Real>::infinity();
  // 4 keeps the fit exact at the corner nodes of a full lattice (3-D: just over 3 standard
  // deviations; antilocking_projection_test) and cuts the wall ghost's 9 to 4. Tank at rest
  // (fold_all): pressure RMS 0.0110 / 0.0117 / 0.0136 / 0.0136 at 1.5 / 2 / 3 / 4, unlimited
  // 0.0135, but then the full-tensor fit blows the barrier up (2026-12-07).
  constexpr Real kMaxNodeExtrapolation = 4;
  // The moment sums start at zero, cleared block by block by the thread that owns the block,
  // then each block's sums on that thread, every slot's in colour order (OrderedBlockScatter:
  // the sums of the colour-phased loop, bitwise, for any thread count).
  const size_t per_block = size_t(grid.block_nodes) * size_t(M);
  s.moments.resize(grid.block_count() * per_block);
  ForOwnedBlocks(grid, [&](size_t b) {
    std::fill_n(s.moments.begin() + ptrdiff_t(b * per_block), per_block, 0.0);
  });
  [[maybe_unused]] const bool wide = WideSimd();
  using Buffer = std::vector<Real>;
  OrderedBlockScatter<Buffer>(
      grid, kDim,
      [&](size_t b, Buffer& buf) {
        const auto scatter = [&]<bool kNode>() {
#if SURGE_HAVE_WIDE_SIMD
          if (wide)
            return ScatterMomentsWide<kDim, K, kNode, F>(ctx, P, x_n, begin, end, grid, b, buf, s);
#endif
          ScatterMomentsPortable<kDim, K, kNode, F>(ctx, P, x_n, begin, end, grid, b, buf, s);
        };
        if (node)
          scatter.template operator()<true>();
        else
          scatter.template operator()<false>();
      },
      [&](size_t b, const Buffer& buf, int o) { AddMomentsIn<kDim, K, F>(grid, b, buf, o, s); });
  if (node) {
    // Node-based: the nodal values q-hat_i = S(xi_i) alpha_i (4.31), the support's fit at the
    // node itself (xi = 0 in node-centred coordinates); AS3CV takes the trace's weighted mean.
    // Then q^h_p = M* sum_i N_ip q-hat_i (4.32).
    constexpr int Q = F::kLinear + F::kConst;
    s.node_fit.resize(grid.block_count() * size_t(grid.block_nodes) * size_t(Q));
    ForOwnedBlocks(grid, [&](size_t blk) {
      for (int l = 0; l < grid.block_nodes; ++l) {
        const size_t g = blk * size_t(grid.block_nodes) + size_t(l);
        const Real* a = &s.moments[g * M];
        if (a[0] == 0) {  // an empty node: 0 (only zero weights meet it)
          std::fill_n(s.node_fit.begin() + ptrdiff_t(g * Q), Q, 0.0);
          continue;
        }
        // A node's fit is evaluated at the node, which can lie outside its particles (a free
        // surface, the outer nodes of a B-spline stencil): extrapolating a thin support's slopes
        // made the water tank blow up within 0.3 s with the cell criteria (1e-8, 1e-10). A node
        // takes the linear fit only when its particles spread over tr C > 0.05 cell^2 (an RMS
        // spread of about 0.13 cells per axis) with det C > 1e-3 (tr C / dim)^dim. Even then the
        // ghost node beyond a wall sees only a strip half a cell thick, 1.25 cells away: its
        // slopes, extrapolated over about 9 standard deviations of the strip, blew the full-tensor
        // fit of the dam break with barrier up at the folded side wall (2026-12-07), so the fit
        // is evaluated at most kMaxNodeExtrapolation standard deviations from the centroid
        // (docs/antilocking.md, "Linear node fit at walls and free surfaces").
        F fit = CellFit<kDim, F>(a, Eigen::Matrix<Real, kDim, 1>::Zero(), nullptr,
                                 al.constant_fit ? kAlwaysConstant : 0.05, 1e-3,
                                 kMaxNodeExtrapolation);
        if (constant_trace) fit.q[0] = a[1 + kDim + F::kSym] / a[0];  // AS3CV (4.23)
        for (int q = 0; q < Q; ++q) s.node_fit[g * Q + size_t(q)] = fit.q[q];
      }
    });
    ForOwnedRuns(grid, [&](size_t r) {
#if SURGE_HAVE_WIDE_SIMD
      if (wide)
        return GatherNodeFitsWide<kDim, K, F>(ctx, P, x_n, begin, end, grid, grid.runs[r], s, hand);
#endif
      GatherNodeFitsPortable<kDim, K, F>(ctx, P, x_n, begin, end, grid, grid.runs[r], s, hand);
    });
    return;
  }
  // q^h_p = M* S_p alpha_c (4.27), or for the hybrid M*_vol theta-bar_p + M*_dev S_p alpha_c
  // (4.34)-(4.35).
  ForOwnedRuns(grid, [&](size_t r) {
    const SparseGrid::ParticleRun run = grid.runs[r];
    const size_t blk = run.block;
    const Vec3i origin = grid.block_origin[blk];
    for (uint32_t k = run.begin; k < run.end; ++k) {
      const uint32_t p = grid.sorted[k];
      if (p < begin || p >= end || !s.tensor_ok[p]) continue;
      Vec3i cell;
      const auto xi = CellXi<kDim>(x_n[p], ctx.inv_dx, cell);
      const Vec3i lc = cell - origin;
      const long g = PaddedToGrid(grid, blk, lc.x(), lc.y(), lc.z());
      SURGE_ASSERT(g >= 0);
      if (g < 0) continue;
      const Real* a = &s.moments[size_t(g) * M];
      F fit = CellFit<kDim, F>(a, xi, nullptr, al.constant_fit ? kAlwaysConstant : 1e-8);
      if (hybrid) {
        if (!std::isfinite(s.theta_bar[p])) continue;  // left to CheckState
        fit.q[0] = s.theta_bar[p];
      } else if (constant_trace) {
        fit.q[0] = a[1 + kDim + F::kSym] / a[0];  // AS3CV: the trace constant (4.23)
      }
      hand(p, fit);
    }
  });
}

// AS2 / AS3CV / hybrid on the trial strain of one material group (seed Table 4.1 steps 2-4):
// the trial (elastic) Hencky strain (4.36)-(4.38) is approximated by FitFullTensor, and L_p is
// replaced by (f-bar_p - I)/dt with f-bar_p b_ref f-bar_p^T = exp(2 eps^h_p) (4.40).
template <int kDim, class K>
void ProjectFullTensor(const StepContext& ctx, const Particles& P, const std::vector<Vec3>& x_n,
                       size_t begin, size_t end, const SparseGrid& grid, const Mode& mode,
                       const AntiLocking& al, AntiLockingScratch& s, std::vector<Mat3>& L) {
  const size_t n = P.size();
  s.tensor.resize(n);
  s.inv_stretch.resize(n);
  s.tensor_ok.resize(n);
  // Step 2: the trial (elastic) strain of every particle of the group.
  ParallelFor(end - begin, 256, [&](size_t i) {
    const size_t p = begin + i;
    const Mat3 f = Increment(ctx.dt, L[p]);  // (2.18)
    const Mat3 b_ref = mode.increment       ? Mat3::Identity()
                       : mode.elastoplastic ? P.elastic_b[p].matrix()
                                            : Mat3(P.F[p] * P.F[p].transpose());
    s.tensor_ok[p] = TrialLogStrain<kDim>(f, b_ref, s.tensor[p], s.inv_stretch[p]);
  });
  // Steps 3-4.
  FitFullTensor<kDim, K>(ctx, P, x_n, begin, end, grid, al, s, [&](size_t p, const Mat3& eps_h) {
    const Mat3 f = Increment(ctx.dt, L[p]);  // (2.18)
    const Mat3 f_bar = ProjectedIncrement<kDim>(f, eps_h, s.inv_stretch[p]);
    if (f_bar.allFinite()) L[p] = (f_bar - Mat3::Identity()) / ctx.dt;
  });
}

// Node-based AS1 with `fit: linear` (AntiLocking::linear_trace): theta_p (TrialTheta) is fitted
// linearly over each node's support by the full-tensor node fit reduced to the trace
// (Filtered<kDim, true>), so each node takes its support's linear fit of theta at the node, within
// kMaxNodeExtrapolation standard deviations (4.29)-(4.31) with S rows [1, xi, eta, zeta], and
// theta-bar_p = sum_i N_ip theta-hat_i (4.32)_1. The particle then shifts as in AS1 (seed §3.5).
// No spectral decomposition: the fit of a fluid's trace without the full tensor's cost.
template <int kDim, class K>
void ProjectLinearTrace(const StepContext& ctx, const Particles& P, const std::vector<Vec3>& x_n,
                        size_t begin, size_t end, const SparseGrid& grid, const Mode& mode,
                        const AntiLocking& al, AntiLockingScratch& s, std::vector<Mat3>& L) {
  const size_t n = P.size();
  s.theta.resize(n);
  s.tensor_ok.resize(n);
  ParallelFor(end - begin, 1024, [&](size_t i) {
    const size_t p = begin + i;
    const Real theta = TrialTheta<kDim>(Increment(ctx.dt, L[p]), P, p, mode);  // (2.18)
    s.theta[p] = theta;
    s.tensor_ok[p] = std::isfinite(theta);  // else left to CheckState
  });
  FitFullTensor<kDim, K, Filtered<kDim, true>>(
      ctx, P, x_n, begin, end, grid, al, s, [&](size_t p, Real theta_bar) {
        if (std::isfinite(theta_bar)) ShiftVolumetric<kDim>(ctx, s.theta[p], theta_bar, L[p]);
      });
}

// AS2 / AS3CV / hybrid on the stress of one material group (seed Table 4.1 steps 6-7, (4.25)_2,
// (4.28), (4.29)_2-(4.32)_2, (4.35)): the specific Kirchhoff stress q_p = tau_p / rho0_p =
// J_p V0_p sigma_p / m_p is approximated with the strain's filter, control volumes and weights,
// and sigma_p <- rho0_p q^h_p / J_p (P = 0 for AS2: the whole tensor is replaced; in 2-D the
// in-plane block, sigma_33 shifted with its mean). The material's state (b^e, F, history) is not
// touched, as with the volumetric stress approximation.
template <int kDim, class K>
void ProjectFullTensorStress(const StepContext& ctx, Particles& P, const std::vector<Vec3>& x_n,
                             size_t begin, size_t end, const SparseGrid& grid,
                             const AntiLocking& al, AntiLockingScratch& s) {
  const size_t n = P.size();
  s.tensor.resize(n);
  s.tensor_ok.resize(n);
  ParallelFor(end - begin, 1024, [&](size_t i) {
    const size_t p = begin + i;
    const Real J = Det3(P.F[p]);
    s.tensor[p] = (J * P.volume0[p] / P.mass[p]) * P.stress[p].matrix();  // tau / rho0 (3.37)
    s.tensor_ok[p] = J > 0 && s.tensor[p].allFinite();  // else left to CheckState
  });
  FitFullTensor<kDim, K>(ctx, P, x_n, begin, end, grid, al, s, [&](size_t p, const Mat3& q_h) {
    Mat3 q = q_h;
    if constexpr (kDim == 2) {
      // Plane strain: the in-plane block is approximated; sigma_33 (a reaction, which the 2-D
      // forces never read) moves with the in-plane mean, so that the particle keeps its own
      // sigma_33 - (sigma_11 + sigma_22)/2 and a fluid's pressure is smoothed as a whole.
      const Mat3& own = s.tensor[p];
      q(2, 2) += 0.5 * ((q_h(0, 0) + q_h(1, 1)) - (own(0, 0) + own(1, 1)));
    }
    const Mat3 sigma = (P.mass[p] / (P.volume0[p] * Det3(P.F[p]))) * q;
    if (sigma.allFinite()) P.stress[p] = sigma;
  });
}

// Anura3D's strain smoothing (manual §6.7, the nodal mixed discretisation of Detournay & Dzik
// 2006, (6.34)-(6.37)) on the grid's cells: the cell value theta_c is the mass-weighted mean of the
// cell's particles (the MPM cell has no Gauss point of its own; this is cell-based AS1, (4.25));
// each node takes the mean over the non-empty cells around it (6.35: element-volume weights, all
// equal on a regular grid); each cell takes the mean of its 2^dim corner nodes (6.36); and each
// particle's volumetric strain is replaced by its cell's value, the deviatoric part kept (6.37).
// Cell sums in the slot of the cell's lower corner node, as ScatterBlock's cell branch.
template <int kDim, class K>
void SmoothVolumetricStrain(const StepContext& ctx, const Particles& P, const std::vector<Vec3>& x_n,
                            size_t begin, size_t end, const SparseGrid& grid, const Mode& mode,
                            AntiLockingScratch& s, std::vector<Mat3>& L) {
  const size_t slots = grid.block_count() * size_t(grid.block_nodes);
  s.weight.assign(slots, 0.0);
  s.weighted.assign(slots, 0.0);
  s.theta.resize(P.size());
  const auto theta = [&](size_t p) {  // each particle once (its own block), kept for the shift
    return s.theta[p] = TrialTheta<kDim>(Increment(ctx.dt, L[p]), P, p, mode);  // (2.18)
  };
  for (int colour = 0; colour < 8; ++colour) {
    const auto& blocks = grid.colour[colour];
    ParallelFor(blocks.size(), 1, [&](size_t i) {
      thread_local std::vector<Accum> buf;
      ScatterBlock<kDim, K, false>(ctx, P, x_n, begin, end, grid, blocks[i], buf, s, theta);
    });
  }
  // (6.35): node value = mean of the cell values around it, colour-phased (a cell writes its own
  // block and its + neighbours), so the sums are in a fixed order.
  s.node_sum.assign(slots, 0.0);
  s.node_count.assign(slots, 0.0);
  constexpr int kz = kDim == 3 ? 2 : 1;
  for (int colour = 0; colour < 8; ++colour) {
    const auto& blocks = grid.colour[colour];
    ParallelFor(blocks.size(), 1, [&](size_t i) {
      const size_t blk = size_t(blocks[i]);
      for (int l = 0; l < grid.block_nodes; ++l) {
        const size_t g = blk * size_t(grid.block_nodes) + size_t(l);
        if (s.weight[g] == 0) continue;  // an empty cell
        const Real theta_c = s.weighted[g] / s.weight[g];
        const Vec3i lc = grid.LocalCoord(l);
        const int lx = lc.x(), ly = lc.y(), lz = lc.z();
        for (int a = 0; a < 2; ++a)
          for (int b = 0; b < 2; ++b)
            for (int c = 0; c < kz; ++c) {
              const long n = PaddedToGrid(grid, blk, lx + a, ly + b, lz + c);
              SURGE_ASSERT(n >= 0);  // a corner of a non-empty cell is in its particles' stencils
              if (n < 0) continue;
              s.node_sum[size_t(n)] += theta_c;
              s.node_count[size_t(n)] += 1;
            }
      }
    });
  }
  // (6.36)-(6.37): the cell's mean of its corner nodes replaces the particle's volumetric strain.
  ForOwnedRuns(grid, [&](size_t r) {
    const SparseGrid::ParticleRun run = grid.runs[r];
    const size_t blk = run.block;
    const Vec3i origin = grid.block_origin[blk];
    for (uint32_t k = run.begin; k < run.end; ++k) {
      const uint32_t p = grid.sorted[k];
      if (p < begin || p >= end) continue;
      Vec3i cell = Vec3i::Zero();
      for (int d = 0; d < kDim; ++d) cell[d] = int(std::floor(x_n[p][d] * ctx.inv_dx));
      const Vec3i lc = cell - origin;
      Real sum = 0;
      bool ok = true;
      for (int a = 0; a < 2; ++a)
        for (int b = 0; b < 2; ++b)
          for (int c = 0; c < kz; ++c) {
            const long n = PaddedToGrid(grid, blk, lc.x() + a, lc.y() + b, lc.z() + c);
            if (n < 0 || s.node_count[size_t(n)] == 0) {
              ok = false;  // the particle's own cell was skipped (non-finite theta): CheckState
              continue;
            }
            sum += s.node_sum[size_t(n)] / s.node_count[size_t(n)];
          }
      const Real theta_bar = sum / Real(2 * 2 * kz);
      if (ok && std::isfinite(theta_bar)) ShiftVolumetric<kDim>(ctx, s.theta[p], theta_bar, L[p]);
    }
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
    if (g.end == g.begin || size_t(g.AntiLockingIndex()) >= model.antilocking.size()) continue;
    const AntiLocking& al = model.antilocking[size_t(g.AntiLockingIndex())];
    const AntiLockingMethod method = al.method;
    if (method == AntiLockingMethod::kNone) continue;
    Mode mode;
    mode.increment = al.strain == AntiLockingStrain::kIncrement;
    mode.elastoplastic = std::visit(
        [](const auto& p) { return kIsElastoplastic<std::decay_t<decltype(p)>>; },
        model.materials[g.material].params);
    if (method == AntiLockingMethod::kSmoothing) {
      DispatchKernel(model.dim, model.shape, [&]<int kDim, class K>() {
        SmoothVolumetricStrain<kDim, K>(ctx, particles, x_n, g.begin, g.end, grid, mode, scratch, L);
      });
      continue;
    }
    if (method == AntiLockingMethod::kHybrid || al.approach != AntiLockingApproach::kVolumetric) {
      DispatchKernel(model.dim, model.shape, [&]<int kDim, class K>() {
        ProjectFullTensor<kDim, K>(ctx, particles, x_n, g.begin, g.end, grid, mode, al, scratch, L);
      });
      continue;
    }
    if (al.linear_trace) {
      DispatchKernel(model.dim, model.shape, [&]<int kDim, class K>() {
        ProjectLinearTrace<kDim, K>(ctx, particles, x_n, g.begin, g.end, grid, mode, al, scratch, L);
      });
      continue;
    }
    DispatchProjection(model, method, [&]<int kDim, class K, bool kNode>() {
      scratch.theta.resize(particles.size());
      const auto theta = [&](size_t p) {  // each particle once (its own block), kept for the shift
        return scratch.theta[p] =
                   TrialTheta<kDim>(Increment(ctx.dt, L[p]), particles, p, mode);  // (2.18)
      };
      const auto shift = [&](size_t p, Real theta_bar) {
        ShiftVolumetric<kDim>(ctx, scratch.theta[p], theta_bar, L[p]);
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

void ProjectStress(const Model& model, const StepContext& ctx,
                       const std::vector<MaterialGroup>& groups, Particles& particles,
                       const std::vector<Vec3>& x_n, const SparseGrid& grid,
                       AntiLockingScratch& scratch) {
  SURGE_CHECK(x_n.size() == particles.size(), "stress averaging needs x_n of every particle");
  Particles& P = particles;
  for (const MaterialGroup& g : groups) {
    if (g.end == g.begin || size_t(g.AntiLockingIndex()) >= model.antilocking.size()) continue;
    const AntiLocking& a = model.antilocking[size_t(g.AntiLockingIndex())];
    if (a.method == AntiLockingMethod::kNone || !a.stress) continue;
    if (a.method == AntiLockingMethod::kHybrid || a.approach != AntiLockingApproach::kVolumetric) {
      DispatchKernel(model.dim, model.shape, [&]<int kDim, class K>() {
        ProjectFullTensorStress<kDim, K>(ctx, P, x_n, g.begin, g.end, grid, a, scratch);
      });
      continue;
    }
    DispatchProjection(model, a.method, [&]<int kDim, class K, bool kNode>() {
      // The seed projects the specific stress sigma-bar = tau / rho0 (Table 4.1 step 6, (4.25)_2,
      // (4.29)_2 with M = [1 1 1 0 0 0]): q_p = tr(tau_p) / (3 rho0_p), tau = J sigma (3.37),
      // rho0_p = m_p / V0_p.
      const auto mean_specific = [&](size_t p) {
        return Det3(P.F[p]) * P.volume0[p] * P.stress[p].trace() / (3.0 * P.mass[p]);
      };
      // Step 7 with P = I_dev: sigma_p <- sigma_p + (rho0_p q-bar_p / J_p - tr(sigma_p)/3) 1,
      // the deviator kept (4.28), (4.32)_2.
      const auto replace = [&](size_t p, Real q_bar) {
        const Real mean = q_bar * P.mass[p] / (P.volume0[p] * Det3(P.F[p]));
        const Real shift = mean - P.stress[p].trace() / 3.0;
        for (int d = 0; d < 3; ++d) P.stress[p].v[d] += shift;
      };
      Project<kDim, K, kNode>(ctx, P, x_n, g.begin, g.end, grid, scratch, mean_specific, replace);
    });
  }
}

}  // namespace surge
