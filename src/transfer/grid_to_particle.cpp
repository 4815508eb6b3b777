// G2P (Mast 2013 eq. (2.22)) and the particle velocity gradient (2.17). Each run of a block's
// particles (SparseGrid::runs) gathers the padded halo of the block's nodes once, then updates its
// particles; runs are independent.
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

// Halo node layouts: APIC and the velocity gradient need only v_{i,n+1}; FLIP and APIC with the
// linear kernel also v_{i,n}.
// Keeping the APIC halo at 24 bytes per node lets a 10^3-node halo stay in L1.
struct NodeV1 {
  Real v1[3];  // v_{i,n+1}
};
struct NodeV01 {
  Real v1[3];  // v_{i,n+1}
  Real v0[3];  // v_{i,n}
};

// Fills halo[0 .. Pad::kSize) from the node velocities v_new (v_{n+1}) and v_old (v_n).
template <int kDim, class K, class Node>
void GatherHalo(const SparseGrid& grid, size_t blk, const Vec3* v_new, const Vec3* v_old,
                Node* halo) {
  using Pad = BlockPad<kDim, K>;
  for (int a = 0; a < Pad::E; ++a)
    for (int b = 0; b < Pad::E; ++b)
      for (int c = 0; c < Pad::Ez; ++c) {
        const long g = PaddedToGrid(grid, blk, a, b, c);
        Node& n = halo[Pad::Index(a, b, c)];
        for (int d = 0; d < 3; ++d) {
          n.v1[d] = g < 0 ? 0.0 : v_new[g][d];
          if constexpr (std::is_same_v<Node, NodeV01>) n.v0[d] = g < 0 ? 0.0 : v_old[g][d];
        }
      }
}

// The common field's halo, or with body contacts one halo per velocity field (a particle reads
// the field of its body: Anura3D manual §6.2, each body is updated from its own field).
template <int kDim, class K, class Node>
void GatherHalos(const SparseGrid& grid, size_t blk, std::vector<Node>& halo) {
  using Pad = BlockPad<kDim, K>;
  if (grid.field_count == 0) {
    halo.resize(Pad::kSize);
    GatherHalo<kDim, K>(grid, blk, grid.velocity_new.data(), grid.velocity.data(), halo.data());
    return;
  }
  const size_t nodes = grid.mass.size();
  halo.resize(size_t(grid.field_count) * Pad::kSize);
  for (int f = 0; f < grid.field_count; ++f)
    GatherHalo<kDim, K>(grid, blk, grid.field_velocity_new.data() + f * nodes,
                        grid.field_velocity.data() + f * nodes, halo.data() + f * Pad::kSize);
}

enum class G2PMode { kFlip, kPicFlip, kApic };

// The particles of run r. kWide: the node sums as Real4 (x, y, z, unused) instead of a Real2 and
// a scalar (AVX build, GatherRunWide), lane for lane the same operations (core/simd.h).
template <int kDim, class K, G2PMode kMode, bool kWide>
[[gnu::always_inline]] inline void GatherRunImpl(const Model& model, const StepContext& ctx,
                                                 const SparseGrid& grid, Particles& P,
                                                 std::vector<Mat3>* velocity_gradient,
                                                 std::vector<Vec3>* x_new,
                                                 const GradientSink* sink, bool advect, size_t r) {
  using Pad = BlockPad<kDim, K>;
  const Real alpha = kMode == G2PMode::kFlip ? 1.0 : model.flip_ratio;
  const SparseGrid::ParticleRun run = grid.runs[r];
  const size_t blk = run.block;
  // Linear APIC also reads v_{i,n} (the affine increment below).
  using Node =
      std::conditional_t<kMode == G2PMode::kApic && !kApicUsesGradient<K>, NodeV1, NodeV01>;
  thread_local std::vector<Node> halo;
  thread_local std::vector<Mat3> run_gradient;  // L_p of the run, for the sink
  if (sink) run_gradient.resize(run.end - run.begin);
  GatherHalos<kDim, K>(grid, blk, halo);
  if constexpr (kWide) halo.emplace_back();  // the spare node the last Real4 load reads into
  const Vec3i origin = grid.block_origin[blk];
  for (uint32_t s = run.begin; s < run.end; ++s) {
    const uint32_t p = grid.sorted[s];
    const Node* field_halo = halo.data();
    if (grid.field_count > 0) field_halo += size_t(model.body_field[P.body[p]]) * Pad::kSize;
    const Vec3 x = P.x[p];
    Stencil<kDim, K> st;
    st.Compute(x, ctx.inv_dx, KernelHalfWidth<K>(kDim, P.volume0[p], ctx.inv_dx));
    const Vec3i lb = st.base - origin;
    Real vpic[3] = {0, 0, 0};  // sum N v_{n+1}
    Real dv[3] = {0, 0, 0};    // sum N (v_{n+1} - v_n)
    Real l[3][3] = {};         // sum v_{n+1} (x) grad N
    Real bm[3][3] = {};        // sum N v_{n+1} (x) (x_i - x_p)
    Real off[3][Stencil<kDim, K>::W];
    for (int d = 0; d < 3; ++d)
      for (int k = 0; k < (d < kDim ? st.W : 1); ++k) off[d][k] = (st.base[d] + k) * ctx.dx - x[d];
    constexpr bool kNeedB = kMode == G2PMode::kApic && !kApicUsesGradient<K>;
    const bool need_l =
        velocity_gradient || sink || (kMode == G2PMode::kApic && kApicUsesGradient<K>);
    // The kernel is a tensor product, so the sums separate: for each (i, j) the k sums
    //   s0 = sum_k w_k v1,  s1 = sum_k g_k v1,  s2 = sum_k w_k oz_k v1,  sd = sum_k w_k (v1 - v0)
    // are formed once and then weighted by the (i, j) factors, instead of forming every term of
    // v_pic, L (2.17) and B per node (about half the multiplications of the per-node form).
    Real wz_oz[Stencil<kDim, K>::W];
    for (int k = 0; k < st.Wz; ++k) wz_oz[k] = st.w[2][k] * off[2][k];
    if constexpr (kWide) {
      // Lanes: each node velocity loaded as one Real4 (x, y, z, and the next value in the halo,
      // which lane 3 carries along unused; the halo has one spare node at its end).
      Real4 vpic4 = {}, dv4 = {}, bm4[3] = {}, l4[3] = {};  // columns of the sums
      for (int i = 0; i < st.W; ++i)
        for (int j = 0; j < st.W; ++j) {
          const Node* row = &field_halo[Pad::Index(lb.x() + i, lb.y() + j, lb.z())];
          Real4 s0 = {}, s1 = {}, s2 = {}, sd = {};
          for (int k = 0; k < st.Wz; ++k) {
            Real4 v;
            std::memcpy(&v, row[k].v1, sizeof v);
            const Real wk = st.w[2][k];
            s0 += wk * v;
            if constexpr (kMode != G2PMode::kApic) {
              Real4 v0;
              std::memcpy(&v0, row[k].v0, sizeof v0);
              sd += wk * (v - v0);
            }
            if constexpr (kNeedB) s2 += wz_oz[k] * v;
            if (need_l) s1 += st.g[2][k] * v;
          }
          const Real wxy = st.w[0][i] * st.w[1][j];
          vpic4 += wxy * s0;
          if constexpr (kMode != G2PMode::kApic) dv4 += wxy * sd;
          if constexpr (kNeedB) {
            const Real bx = wxy * off[0][i], by = wxy * off[1][j];
            bm4[0] += bx * s0;
            bm4[1] += by * s0;
            bm4[2] += wxy * s2;
          }
          if (need_l) {
            // grad N = (g_i w_j w_k, w_i g_j w_k, w_i w_j g_k)
            const Real gx = st.g[0][i] * st.w[1][j], gy = st.w[0][i] * st.g[1][j];
            l4[0] += gx * s0;
            l4[1] += gy * s0;
            l4[2] += wxy * s1;
          }
        }
      for (int r = 0; r < 3; ++r) {
        vpic[r] = vpic4[r];
        dv[r] = dv4[r];
        for (int c = 0; c < 3; ++c) {
          bm[r][c] = bm4[c][r];
          l[r][c] = l4[c][r];
        }
      }
    } else {
      // Lanes: each node velocity is loaded as (x, y) in a Real2 plus z as a scalar.
      Real2 vpic2 = {0, 0}, dv2 = {0, 0}, bm2[3] = {}, l2[3] = {};  // x, y rows of the sums
      for (int i = 0; i < st.W; ++i)
        for (int j = 0; j < st.W; ++j) {
          const Node* row = &field_halo[Pad::Index(lb.x() + i, lb.y() + j, lb.z())];
          Real2 s0 = {0, 0}, s1 = {0, 0}, s2 = {0, 0}, sd = {0, 0};
          Real s0z = 0, s1z = 0, s2z = 0, sdz = 0;
          for (int k = 0; k < st.Wz; ++k) {
            Real2 v;
            std::memcpy(&v, row[k].v1, sizeof v);
            const Real vz = row[k].v1[2], wk = st.w[2][k];
            s0 += wk * v;
            s0z += wk * vz;
            if constexpr (kMode != G2PMode::kApic) {
              Real2 v0;
              std::memcpy(&v0, row[k].v0, sizeof v0);
              sd += wk * (v - v0);
              sdz += wk * (vz - row[k].v0[2]);
            }
            if constexpr (kNeedB) {
              s2 += wz_oz[k] * v;
              s2z += wz_oz[k] * vz;
            }
            if (need_l) {
              s1 += st.g[2][k] * v;
              s1z += st.g[2][k] * vz;
            }
          }
          const Real wxy = st.w[0][i] * st.w[1][j];
          vpic2 += wxy * s0;
          vpic[2] += wxy * s0z;
          if constexpr (kMode != G2PMode::kApic) {
            dv2 += wxy * sd;
            dv[2] += wxy * sdz;
          }
          if constexpr (kNeedB) {
            const Real bx = wxy * off[0][i], by = wxy * off[1][j];
            bm2[0] += bx * s0;
            bm2[1] += by * s0;
            bm2[2] += wxy * s2;
            bm[2][0] += bx * s0z;
            bm[2][1] += by * s0z;
            bm[2][2] += wxy * s2z;
          }
          if (need_l) {
            // grad N = (g_i w_j w_k, w_i g_j w_k, w_i w_j g_k)
            const Real gx = st.g[0][i] * st.w[1][j], gy = st.w[0][i] * st.g[1][j];
            l2[0] += gx * s0;
            l2[1] += gy * s0;
            l2[2] += wxy * s1;
            l[2][0] += gx * s0z;
            l[2][1] += gy * s0z;
            l[2][2] += wxy * s1z;
          }
        }
      for (int r = 0; r < 2; ++r) {
        vpic[r] = vpic2[r];
        dv[r] = dv2[r];
        for (int c = 0; c < 3; ++c) {
          bm[r][c] = bm2[c][r];
          l[r][c] = l2[c][r];
        }
      }
    }
    const Vec3 v_pic(vpic[0], vpic[1], vpic[2]);
    Mat3 L, B;
    for (int r = 0; r < 3; ++r)
      for (int c = 0; c < 3; ++c) {
        L(r, c) = l[r][c];
        B(r, c) = bm[r][c];
      }
    if constexpr (kMode == G2PMode::kApic) {
      P.v[p] = v_pic;  // APIC velocity (Jiang et al. 2015, eq. (8))
      if constexpr (kApicUsesGradient<K>) {
        // Linear kernel: the start-of-step field's exact affine matrix plus the step's increment
        // projected with a constant D (docs/stability.md, "Linear shape functions with APIC"):
        //   C_p = sum_i v_{i,n} (grad N_ip)^T
        //       + (4 / dx^2) sum_i N_ip (v_{i,n+1} - v_{i,n}) (x_i - x_p)^T.
        // The first term is B_p D_p^{-1} of Jiang et al. 2015, eq. (7), which for multilinear N
        // equals the gradient form (§5.3); the second is eq. (7) with D_p = dx^2/4 I (§5.3, the
        // quadratic B-spline's D and the largest D_p of the linear kernel). Taking the whole
        // C_p = sum v_{i,n+1} (grad N_ip)^T instead hands a node that a particle has just reached
        // (mass N_ip m_p -> 0, |grad N_ip| = 1/dx, acceleration ~ 1/N_ip) its full explicit
        // increment back through the next P2G: with linear weights the affine round trip is
        // lossless, so that node's velocity is kept from step to step and its tiny mass makes
        // the explicit update unstable below the wave-speed CFL limit. Weighting the increment
        // by N_ip, as the B-splines' B_p D_p^{-1} does, bounds it.
        // Separable sums as in the loop above: per (i, j) the k sums a0 = sum w_k v0,
        // a1 = sum g_k v0, d0 = sum w_k dv, d2 = sum w_k oz_k dv (dv = v1 - v0), then the
        // columns of sum v0 (grad N)^T (c) and of sum N dv (x_i - x_p)^T (b).
        Vec3 c[3] = {Vec3::Zero(), Vec3::Zero(), Vec3::Zero()};
        Vec3 b[3] = {Vec3::Zero(), Vec3::Zero(), Vec3::Zero()};
        for (int i = 0; i < st.W; ++i)
          for (int j = 0; j < st.W; ++j) {
            const Node* row = &field_halo[Pad::Index(lb.x() + i, lb.y() + j, lb.z())];
            Vec3 a0 = Vec3::Zero(), a1 = Vec3::Zero(), d0 = Vec3::Zero(), d2 = Vec3::Zero();
            for (int k = 0; k < st.Wz; ++k) {
              const Vec3 v0(row[k].v0[0], row[k].v0[1], row[k].v0[2]);
              const Vec3 dv = Vec3(row[k].v1[0], row[k].v1[1], row[k].v1[2]) - v0;
              a0 += st.w[2][k] * v0;
              a1 += st.g[2][k] * v0;
              d0 += st.w[2][k] * dv;
              d2 += wz_oz[k] * dv;
            }
            const Real wxy = st.w[0][i] * st.w[1][j];
            c[0] += (st.g[0][i] * st.w[1][j]) * a0;
            c[1] += (st.w[0][i] * st.g[1][j]) * a0;
            c[2] += wxy * a1;
            b[0] += (wxy * off[0][i]) * d0;
            b[1] += (wxy * off[1][j]) * d0;
            b[2] += wxy * d2;
          }
        const Real inv_d = 4.0 * ctx.inv_dx * ctx.inv_dx;  // D_p^{-1} = 4/dx^2 I
        for (int col = 0; col < 3; ++col) P.C[p].col(col) = c[col] + inv_d * b[col];
      } else if constexpr (kApicConstantD<K>) {
        P.C[p] = (K::kInvDScale * ctx.inv_dx * ctx.inv_dx) * B;  // B D^{-1}, eq. (7)
      } else {
        // General D_p, diagonal: D_dd = sum_k w_d[k] (x_{base+k} - x_p)_d^2.
        Vec3 inv_d = Vec3::Zero();
        for (int d = 0; d < kDim; ++d) {
          Real D = 0;
          for (int k = 0; k < st.W; ++k) {
            const Real xi = (st.base[d] + k) * ctx.dx - x[d];
            D += st.w[d][k] * xi * xi;
          }
          inv_d[d] = 1.0 / D;
        }
        P.C[p] = B * inv_d.asDiagonal();
      }
    } else {
      // FLIP increment (2.22) blended with PIC: v = a (v + sum N dv) + (1 - a) sum N v_{n+1}.
      P.v[p] = alpha * (P.v[p] + Vec3(dv[0], dv[1], dv[2])) + (1.0 - alpha) * v_pic;
    }
    if (velocity_gradient)
      (*velocity_gradient)[p] = L;
    else if (sink)
      run_gradient[s - run.begin] = L;
    if (!advect) continue;  // AdvectParticles (APIC: v_p = v_pic)
    const Vec3 xn = x + ctx.dt * v_pic;  // x_{n+1} = x_n + sum N dx_i, dx_i = dt v_{n+1} (2.16)
    if (x_new)
      (*x_new)[p] = xn;
    else
      P.x[p] = xn;
  }
  if (sink) (*sink)(r, &grid.sorted[run.begin], run_gradient.data(), run.end - run.begin);
}

// The two builds of GatherRunImpl: portable, and for AVX (core/simd.h).
template <int kDim, class K, G2PMode kMode>
void GatherRun(const Model& model, const StepContext& ctx, const SparseGrid& grid, Particles& P,
               std::vector<Mat3>* velocity_gradient, std::vector<Vec3>* x_new,
               const GradientSink* sink, bool advect, size_t r) {
  GatherRunImpl<kDim, K, kMode, false>(model, ctx, grid, P, velocity_gradient, x_new, sink, advect,
                                       r);
}
#if SURGE_HAVE_WIDE_SIMD
template <int kDim, class K, G2PMode kMode>
SURGE_TARGET_WIDE void GatherRunWide(const Model& model, const StepContext& ctx,
                                     const SparseGrid& grid, Particles& P,
                                     std::vector<Mat3>* velocity_gradient,
                                     std::vector<Vec3>* x_new, const GradientSink* sink,
                                     bool advect, size_t r) {
  GatherRunImpl<kDim, K, kMode, true>(model, ctx, grid, P, velocity_gradient, x_new, sink, advect,
                                      r);
}
#endif

template <int kDim, class K, G2PMode kMode>
void GatherBlocks(const Model& model, const StepContext& ctx, const SparseGrid& grid,
                  Particles& P, std::vector<Mat3>* velocity_gradient, std::vector<Vec3>* x_new,
                  const GradientSink* sink, bool advect) {
  [[maybe_unused]] const bool wide = WideSimd();
  ForOwnedRuns(grid, [&](size_t r) {
#if SURGE_HAVE_WIDE_SIMD
    if (wide)
      return GatherRunWide<kDim, K, kMode>(model, ctx, grid, P, velocity_gradient, x_new, sink,
                                           advect, r);
#endif
    GatherRun<kDim, K, kMode>(model, ctx, grid, P, velocity_gradient, x_new, sink, advect, r);
  });
}

template <int kDim, class K>
void GradientBlocks(const StepContext& ctx, const SparseGrid& grid, const Particles& P,
                    std::vector<Mat3>& velocity_gradient) {
  using Pad = BlockPad<kDim, K>;
  ForOwnedRuns(grid, [&](size_t r) {
    const SparseGrid::ParticleRun run = grid.runs[r];
    const size_t blk = run.block;
    thread_local std::vector<NodeV1> halo;
    halo.resize(Pad::kSize);  // MUSL: single field only (the scene builder refuses body contacts)
    GatherHalo<kDim, K>(grid, blk, grid.velocity_new.data(), grid.velocity.data(), halo.data());
    const Vec3i origin = grid.block_origin[blk];
    for (uint32_t s = run.begin; s < run.end; ++s) {
      const uint32_t p = grid.sorted[s];
      Stencil<kDim, K> st;
      st.Compute(P.x[p], ctx.inv_dx, KernelHalfWidth<K>(kDim, P.volume0[p], ctx.inv_dx));
      const Vec3i lb = st.base - origin;
      Mat3 L = Mat3::Zero();
      for (int i = 0; i < st.W; ++i)
        for (int j = 0; j < st.W; ++j)
          for (int k = 0; k < st.Wz; ++k) {
            const Real* v1 = halo[Pad::Index(lb.x() + i, lb.y() + j, lb.z() + k)].v1;
            L += Vec3(v1[0], v1[1], v1[2]) * st.Gradient(i, j, k).transpose();  // (2.17)
          }
      velocity_gradient[p] = L;
    }
  });
}

}  // namespace

void GridToParticle(const Model& model, const StepContext& ctx, const SparseGrid& grid,
                    Particles& particles, std::vector<Mat3>* velocity_gradient,
                    std::vector<Vec3>* x_new, const GradientSink* sink, bool advect) {
  SURGE_CHECK(advect || (model.transfer == TransferScheme::kApic && !x_new),
              "deferred advection needs APIC (x += dt v_p)");
  if (velocity_gradient) velocity_gradient->resize(particles.size());
  if (x_new) x_new->resize(particles.size());
  DispatchKernel(model.dim, model.shape, [&]<int kDim, class K>() {
    switch (model.transfer) {
      case TransferScheme::kFlip:
        GatherBlocks<kDim, K, G2PMode::kFlip>(model, ctx, grid, particles, velocity_gradient,
                                              x_new, sink, advect);
        break;
      case TransferScheme::kPicFlip:
        GatherBlocks<kDim, K, G2PMode::kPicFlip>(model, ctx, grid, particles, velocity_gradient,
                                                 x_new, sink, advect);
        break;
      case TransferScheme::kApic:
        GatherBlocks<kDim, K, G2PMode::kApic>(model, ctx, grid, particles, velocity_gradient,
                                              x_new, sink, advect);
        break;
    }
  });
}

void AdvectParticles(const StepContext& ctx, Particles& P) {
  ParallelChunks(P.size(), [&](size_t, size_t begin, size_t end) {
    for (size_t p = begin; p < end; ++p) P.x[p] = P.x[p] + ctx.dt * P.v[p];  // (2.16)
  });
}

void ComputeVelocityGradient(const Model& model, const StepContext& ctx, const SparseGrid& grid,
                             const Particles& particles, std::vector<Mat3>& velocity_gradient) {
  velocity_gradient.resize(particles.size());
  DispatchKernel(model.dim, model.shape, [&]<int kDim, class K>() {
    GradientBlocks<kDim, K>(ctx, grid, particles, velocity_gradient);
  });
}

}  // namespace surge
