// P2G (Mast 2013 eq. (2.12)): mass, momentum (+ APIC affine term), internal and traction forces.
// A block accumulates its particles into a padded local buffer and adds it into itself and its 7
// upper neighbours, every node in colour order (no atomics on the sums, fixed summation order):
// on one thread (and with per-body fields) colour by colour, on more each block on the thread
// that owns its particles (OrderedBlockScatter, transfer/owned_loops.h).

#include <algorithm>
#include <array>
#include <cstring>
#include <type_traits>

#include "core/check.h"
#include "core/parallel.h"
#include "core/simd.h"
#include "transfer/dispatch.h"
#include "transfer/owned_loops.h"
#include "transfer/stencil_loop.h"
#include "transfer/transfer.h"

namespace surge {
namespace {

// Single field: the node sums as four two-lane vectors.
struct NodeAccum {
  Real2 v[4];  // (m, px), (py, pz), (fx, fy), (fz, unused)
};
// With per-body velocity fields: also the first mass moment sum_p m_p N_ip (x_p - x_i).
struct FieldAccum {
  Real m, px, py, pz, fx, fy, fz, gx, gy, gz;  // g: first mass moment
};

// Adds a block's per-field padded sums into the field arrays and, field by field in a fixed
// order, into the common field.
template <class Pad>
void FlushFields(SparseGrid& grid, size_t blk, const std::vector<FieldAccum>& buf, int xlo,
                 int xhi) {
  const size_t nodes = grid.mass.size();
  for (int f = 0; f < grid.field_count; ++f) {
    const FieldAccum* fb = buf.data() + size_t(f) * Pad::kSize;
    for (int a = xlo; a < xhi; ++a)
      for (int b = 0; b < Pad::E; ++b)
        for (int c = 0; c < Pad::Ez; ++c) {
          const FieldAccum& n = fb[Pad::Index(a, b, c)];
          if (n.m == 0) continue;  // a field's particles give every node of their stencil mass
          const long g = PaddedToGrid(grid, blk, a, b, c);
          SURGE_ASSERT(g >= 0);
          if (g < 0) continue;
          const size_t gf = size_t(f) * nodes + size_t(g);
          const Vec3 p(n.px, n.py, n.pz), force(n.fx, n.fy, n.fz);
          grid.field_mass[gf] += n.m;
          grid.field_momentum[gf] += p;
          grid.field_force[gf] += force;
          grid.field_mass_moment[gf] += Vec3(n.gx, n.gy, n.gz);
          grid.mass[g] += n.m;
          grid.momentum[g] += p;
          grid.force[g] += force;
        }
  }
}

// Adds padded node (a, b, c) of a block's sums into the grid (skipped when all its sums are zero).
template <class Pad, bool kFull>
void FlushNode(SparseGrid& grid, size_t blk, const std::vector<NodeAccum>& buf, int a, int b, int c) {
  const NodeAccum& n = buf[Pad::Index(a, b, c)];
  if (n.v[0][0] == 0 && n.v[0][1] == 0 && n.v[1][0] == 0 && n.v[1][1] == 0 && n.v[2][0] == 0 &&
      n.v[2][1] == 0 && n.v[3][0] == 0)
    return;
  const long g = PaddedToGrid(grid, blk, a, b, c);
  SURGE_ASSERT(g >= 0);
  if (g < 0) return;
  grid.momentum[g] += Vec3(n.v[0][1], n.v[1][0], n.v[1][1]);
  if constexpr (kFull) {
    grid.mass[g] += n.v[0][0];
    grid.force[g] += Vec3(n.v[2][0], n.v[2][1], n.v[3][0]);
  }
}

// kFull: mass, momentum and force; otherwise momentum only (MUSL re-map). kFields: one padded
// buffer per velocity field (body_field maps a particle's body to its field), written to the
// grid's field arrays and summed into the common field (Anura3D manual (6.1)-(6.3): the common
// field is the sum of the body fields).
// [xlo, xhi): the slab of padded x node columns this call accumulates and writes (all: 0 to
// Pad::E). Calls on disjoint slabs of one block may run in parallel: each node still sums the
// block's particles in their sorted order, so the result is the same bitwise for any split.
// flush = false: only accumulate into buf (OrderedBlockScatter then adds it into the grid).
// kWide: the single field's node updates as two Real4 (AVX build, ScatterBlockWide) instead of
// four Real2, lane for lane the same operations (core/simd.h).
template <int kDim, class K, bool kApic, bool kFull, bool kFields, bool kWide>
[[gnu::always_inline]] inline void ScatterBlockImpl(
    const StepContext& ctx, const Particles& P, SparseGrid& grid, size_t blk,
    std::vector<std::conditional_t<kFields, FieldAccum, NodeAccum>>& buf, const int* body_field,
    int xlo, int xhi, bool flush) {
  using Pad = BlockPad<kDim, K>;
  using Accum = std::conditional_t<kFields, FieldAccum, NodeAccum>;
  const int fields = kFields ? grid.field_count : 1;
  buf.assign(size_t(fields) * Pad::kSize, Accum{});
  const Vec3i origin = grid.block_origin[blk];
  const Real dx = ctx.dx;
  for (uint32_t s = grid.block_begin[blk]; s < grid.block_begin[blk + 1]; ++s) {
    const uint32_t p = grid.sorted[s];
    Accum* field_buf = buf.data();
    if constexpr (kFields) field_buf += size_t(body_field[P.body[p]]) * Pad::kSize;
    const Vec3& x = P.x[p];
    Stencil<kDim, K> st;
    st.Compute(x, ctx.inv_dx, KernelHalfWidth<K>(kDim, P.volume0[p], ctx.inv_dx));
    const Vec3i lb = st.base - origin;
    const int i_begin = std::max(0, xlo - lb.x()), i_end = std::min(st.W, xhi - lb.x());
    if (i_begin >= i_end) continue;  // the particle's stencil misses this slab
    const Real m = P.mass[p];
    const Vec3& vp = P.v[p];
    const Real mv[3] = {m * vp.x(), m * vp.y(), m * vp.z()};
    // Node offsets x_i - x_p per axis (APIC affine term).
    Real off[3][Stencil<kDim, K>::W];
    for (int d = 0; d < 3; ++d)
      for (int k = 0; k < (d < kDim ? st.W : 1); ++k) off[d][k] = (st.base[d] + k) * dx - x[d];
    Mat3 mC = Mat3::Zero();
    if constexpr (kApic) mC = m * P.C[p];
    // Internal force -V_p sigma_p grad N_ip with V_p = J V0 (2.11; sigma-bar m = tau V0).
    Mat3 neg_vs = Mat3::Zero();
    Vec3 fext = Vec3::Zero();
    if constexpr (kFull) {
      neg_vs = -(P.volume0[p] * Det3(P.F[p])) * P.stress[p].matrix();
      if (P.layout.ext_force)
        fext = ctx.ramp * P.ext_force[p];  // particle tractions (App. B.2.9), ramped (App. B.2.3)
    }
    // Lane vectors of the single-field path: (m, m v), the columns of mC as (0, mC[:,c]), the
    // columns of -V sigma as (S[:,c], 0) and (f_ext, 0), each as two Real2.
    const Real2 v_mv[2] = {{kFull ? m : 0.0, mv[0]}, {mv[1], mv[2]}};
    Real2 v_mc[3][2], v_s[3][2];
    const Real2 v_fext[2] = {{fext.x(), fext.y()}, {fext.z(), 0.0}};
    for (int c = 0; c < 3; ++c) {
      v_mc[c][0] = Real2{0.0, mC(0, c)};
      v_mc[c][1] = Real2{mC(1, c), mC(2, c)};
      v_s[c][0] = Real2{neg_vs(0, c), neg_vs(1, c)};
      v_s[c][1] = Real2{neg_vs(2, c), 0.0};
    }
    // The same lanes as Real4 for the wide build: (m, m v), (0, mC[:,c]), (S[:,c], 0), (f_ext, 0).
    [[maybe_unused]] const Real4 w_mv = {kFull ? m : 0.0, mv[0], mv[1], mv[2]},
                                 w_fext = {fext.x(), fext.y(), fext.z(), 0.0};
    [[maybe_unused]] const Real4 w_mc[3] = {{0.0, mC(0, 0), mC(1, 0), mC(2, 0)},
                                            {0.0, mC(0, 1), mC(1, 1), mC(2, 1)},
                                            {0.0, mC(0, 2), mC(1, 2), mC(2, 2)}};
    [[maybe_unused]] const Real4 w_s[3] = {{neg_vs(0, 0), neg_vs(1, 0), neg_vs(2, 0), 0.0},
                                           {neg_vs(0, 1), neg_vs(1, 1), neg_vs(2, 1), 0.0},
                                           {neg_vs(0, 2), neg_vs(1, 2), neg_vs(2, 2), 0.0}};
    // Terms that depend on (i, j) or on k only are hoisted out of the inner loop. With
    // w = wxy w_k and oz_k = (x_i - x_p)_z:
    //   momentum  w (m v + mC (x_i - x_p)) = w_k a_ij + (w_k oz_k) b_ij,
    //             a_ij = wxy (m v + mC[:,0] ox_i + mC[:,1] oy_j),  b_ij = wxy mC[:,2]
    //   force     -V sigma grad N + w f_ext = w_k fa_ij + g_k fb_ij,
    //             fa_ij = S (gx_ij, gy_ij, 0) + wxy f_ext,  fb_ij = wxy S[:,2]
    Real wk_oz[Stencil<kDim, K>::W];
    for (int k = 0; k < st.Wz; ++k) wk_oz[k] = st.w[2][k] * off[2][k];
    for (int i = i_begin; i < i_end; ++i) {
      for (int j = 0; j < st.W; ++j) {
        const Real wxy = st.w[0][i] * st.w[1][j];
        const Real wm = wxy * m;
        Real ca[3], cb[3] = {0, 0, 0};
        for (int r = 0; r < 3; ++r) ca[r] = wxy * mv[r];
        if constexpr (kApic)
          for (int r = 0; r < 3; ++r) {
            ca[r] += wxy * (mC(r, 0) * off[0][i] + mC(r, 1) * off[1][j]);
            cb[r] = wxy * mC(r, 2);
          }
        Real fa[3] = {0, 0, 0}, fb[3] = {0, 0, 0};
        if constexpr (kFull) {
          const Real gx = st.g[0][i] * st.w[1][j], gy = st.w[0][i] * st.g[1][j];
          for (int r = 0; r < 3; ++r) {
            fa[r] = neg_vs(r, 0) * gx + neg_vs(r, 1) * gy + wxy * fext[r];
            fb[r] = wxy * neg_vs(r, 2);
          }
        }
        Accum* row = &field_buf[Pad::Index(lb.x() + i, lb.y() + j, lb.z())];
        if constexpr (!kFields) {
          // Node sums as lane updates: (m, p) += w_k (wm, a) + (w_k oz_k) (0, b),
          // f += w_k fa + g_k fb, with the (i, j) vectors built from the per-particle vectors by
          // lane-wise operations only (no element inserts in the loop).
          const Real ox = off[0][i], oy = off[1][j];
          const Real gx = st.g[0][i] * st.w[1][j], gy = st.w[0][i] * st.g[1][j];
          if constexpr (kWide) {
            // (m, p) and (f, unused) as one Real4 each, lane for lane a[0..1] and a[2..3] below.
            const Real4 a4[2] = {kApic ? wxy * (w_mv + ox * w_mc[0] + oy * w_mc[1]) : wxy * w_mv,
                                 gx * w_s[0] + gy * w_s[1] + wxy * w_fext};
            const Real4 b4[2] = {wxy * w_mc[2], wxy * w_s[2]};
            for (int k = 0; k < st.Wz; ++k) {
              const Real wk = st.w[2][k], wo = wk_oz[k], g2 = st.g[2][k];
              Real4 n0, n1;
              std::memcpy(&n0, row[k].v, sizeof n0);
              if constexpr (kApic)
                n0 += wk * a4[0] + wo * b4[0];  // APIC (Jiang et al. 2015, eq. (9))
              else
                n0 += wk * a4[0];
              std::memcpy(row[k].v, &n0, sizeof n0);
              if constexpr (kFull) {
                std::memcpy(&n1, row[k].v + 2, sizeof n1);
                n1 += wk * a4[1] + g2 * b4[1];  // (2.11) + traction
                std::memcpy(row[k].v + 2, &n1, sizeof n1);
              }
            }
            continue;
          }
          Real2 a[4], b[4];
          for (int h = 0; h < 2; ++h) {
            a[h] = kApic ? wxy * (v_mv[h] + ox * v_mc[0][h] + oy * v_mc[1][h]) : wxy * v_mv[h];
            b[h] = wxy * v_mc[2][h];
            a[2 + h] = gx * v_s[0][h] + gy * v_s[1][h] + wxy * v_fext[h];
            b[2 + h] = wxy * v_s[2][h];
          }
          for (int k = 0; k < st.Wz; ++k) {
            const Real wk = st.w[2][k], wo = wk_oz[k], g2 = st.g[2][k];
            Real2* n = row[k].v;
            for (int h = 0; h < 2; ++h) {
              if constexpr (kApic)
                n[h] += wk * a[h] + wo * b[h];  // APIC (Jiang et al. 2015, eq. (9))
              else
                n[h] += wk * a[h];
              if constexpr (kFull) n[2 + h] += wk * a[2 + h] + g2 * b[2 + h];  // (2.11) + traction
            }
          }
          continue;
        }
        for (int k = 0; k < st.Wz; ++k) {
          const Real wk = st.w[2][k];
          Accum& a = row[k];
          if constexpr (kFields) {
            if constexpr (kApic) {
              // APIC: m_p (v_p + C_p (x_i - x_p)) (Jiang et al. 2015, eq. (9)).
              const Real wo = wk_oz[k];
              a.px += wk * ca[0] + wo * cb[0];
              a.py += wk * ca[1] + wo * cb[1];
              a.pz += wk * ca[2] + wo * cb[2];
            } else {
              a.px += wk * ca[0];
              a.py += wk * ca[1];
              a.pz += wk * ca[2];
            }
            if constexpr (kFull) {
              // Internal force -V_p sigma_p grad N_ip (2.11) plus the traction share w f_ext.
              const Real g2 = st.g[2][k];
              a.m += wk * wm;
              a.fx += wk * fa[0] + g2 * fb[0];
              a.fy += wk * fa[1] + g2 * fb[1];
              a.fz += wk * fa[2] + g2 * fb[2];
            }
            // First mass moment w m_p (x_p - x_i) of the particle's field (contact normals).
            const Real w = wxy * wk, wmk = w * m;
            a.gx -= wmk * off[0][i];
            a.gy -= wmk * off[1][j];
            a.gz -= wmk * off[2][k];
          }
        }
      }
    }
  }
  if (!flush) return;
  if constexpr (kFields) {
    FlushFields<Pad>(grid, blk, buf, xlo, xhi);
  } else {
    for (int a = xlo; a < xhi; ++a)
      for (int b = 0; b < Pad::E; ++b)
        for (int c = 0; c < Pad::Ez; ++c) FlushNode<Pad, kFull>(grid, blk, buf, a, b, c);
  }
}

// The two builds of ScatterBlockImpl: portable, and for AVX (core/simd.h).
template <int kDim, class K, bool kApic, bool kFull, bool kFields = false>
void ScatterBlock(const StepContext& ctx, const Particles& P, SparseGrid& grid, size_t blk,
                  std::vector<std::conditional_t<kFields, FieldAccum, NodeAccum>>& buf,
                  const int* body_field, int xlo, int xhi, bool flush = true) {
  ScatterBlockImpl<kDim, K, kApic, kFull, kFields, false>(ctx, P, grid, blk, buf, body_field, xlo,
                                                          xhi, flush);
}
#if SURGE_HAVE_WIDE_SIMD
template <int kDim, class K, bool kApic, bool kFull>
SURGE_TARGET_WIDE void ScatterBlockWide(const StepContext& ctx, const Particles& P,
                                        SparseGrid& grid, size_t blk, std::vector<NodeAccum>& buf) {
  ScatterBlockImpl<kDim, K, kApic, kFull, false, true>(ctx, P, grid, blk, buf, nullptr, 0,
                                                       BlockPad<kDim, K>::E, false);
}
#endif

template <int kDim, class K, bool kApic, bool kFull, bool kFields>
void Scatter(const StepContext& ctx, const Particles& particles, SparseGrid& grid,
             const int* body_field) {
  using Pad = BlockPad<kDim, K>;
  const size_t threads = WorkerThreads();
  if constexpr (!kFields) {
    // Single field: each block on the thread that owns its particles (OrderedBlockScatter).
    using Buffer = std::vector<NodeAccum>;
    [[maybe_unused]] const bool wide = WideSimd();
    OrderedBlockScatter<Buffer>(
        grid, kDim,
        [&](size_t b, Buffer& buf) {
#if SURGE_HAVE_WIDE_SIMD
          if (wide) return ScatterBlockWide<kDim, K, kApic, kFull>(ctx, particles, grid, b, buf);
#endif
          ScatterBlock<kDim, K, kApic, kFull>(ctx, particles, grid, b, buf, nullptr, 0, Pad::E,
                                              /*flush=*/false);
        },
        [&](size_t b, const Buffer& buf, int o) {
          ForPaddedNodesIn<Pad>(o, [&](int a, int bb, int c) { FlushNode<Pad, kFull>(grid, b, buf, a, bb, c); });
        });
    return;
  }
  for (int colour = 0; colour < 8; ++colour) {
    const auto& blocks = grid.colour[colour];
    // A colour with few blocks (small runs: a 1e4-particle column has one or two per colour)
    // is split further into slabs of padded x columns, so that every thread has work; a slab
    // repeats the stencil weights of the particles it touches. The sums do not depend on the
    // split (ScatterBlock), so the split may follow the thread count.
    const size_t slabs = threads <= 1 || blocks.size() >= 4 * threads ? 1
                         : blocks.size() >= threads                 ? 2
                                                                    : 4;
    ParallelFor(blocks.size() * slabs, 1, [&](size_t t) {
      thread_local std::vector<std::conditional_t<kFields, FieldAccum, NodeAccum>> buf;
      const size_t b = t / slabs, s = t % slabs;
      const int xlo = int(size_t(Pad::E) * s / slabs), xhi = int(size_t(Pad::E) * (s + 1) / slabs);
      ScatterBlock<kDim, K, kApic, kFull, kFields>(ctx, particles, grid, blocks[b], buf,
                                                   body_field, xlo, xhi);
    });
  }
}

template <bool kFull, bool kFields = false>
void ScatterDispatch(const Model& model, const StepContext& ctx, const Particles& particles,
                     SparseGrid& grid) {
  const bool apic = model.transfer == TransferScheme::kApic;
  const int* body_field = model.body_field.data();
  DispatchKernel(model.dim, model.shape, [&]<int kDim, class K>() {
    if (apic)
      Scatter<kDim, K, true, kFull, kFields>(ctx, particles, grid, body_field);
    else
      Scatter<kDim, K, false, kFull, kFields>(ctx, particles, grid, body_field);
  });
}

}  // namespace

void ParticleToGrid(const Model& model, const StepContext& ctx, const Particles& particles,
                    SparseGrid& grid) {
  if (model.field_count == 0) {
    grid.field_count = 0;
    ScatterDispatch<true>(model, ctx, particles, grid);
    return;
  }
  // Per-body velocity fields, only where a scene has body contacts. The sums are zeroed each
  // step (a 2-D block holds only its z = 0 plane, SparseGrid::SetDimension). The
  // velocities are only written where a field has mass and read, with weight zero, elsewhere:
  // they need to be finite, not zero (new entries start at zero).
  const size_t nodes = grid.mass.size(), n = size_t(model.field_count) * nodes;
  grid.field_count = model.field_count;
  grid.field_mass.resize(n);
  grid.field_momentum.resize(n);
  grid.field_force.resize(n);
  grid.field_mass_moment.resize(n);
  grid.field_velocity.resize(n, Vec3::Zero());
  grid.field_velocity_new.resize(n, Vec3::Zero());
  ParallelFor(grid.block_count() * size_t(model.field_count), 4, [&](size_t k) {
    const size_t f = k / grid.block_count(), b = k % grid.block_count();
    for (int l = 0; l < grid.block_nodes; ++l) {
      const size_t i = f * nodes + b * size_t(grid.block_nodes) + size_t(l);
      grid.field_mass[i] = 0;
      grid.field_momentum[i].setZero();
      grid.field_force[i].setZero();
      grid.field_mass_moment[i].setZero();
    }
  });
  ScatterDispatch<true, true>(model, ctx, particles, grid);
}

void RemapMomentum(const Model& model, const StepContext& ctx, const Particles& particles,
                   SparseGrid& grid) {
  // The grid update handed momentum's buffer to `velocity` (SparseGrid::momentum), which the
  // MUSL ghost nodes still read: a second buffer, reused from step to step.
  grid.momentum.assign(grid.mass.size(), Vec3::Zero());
  ScatterDispatch<false>(model, ctx, particles, grid);
  ApplyRemappedVelocity(model, ctx, grid);
}

}  // namespace surge
