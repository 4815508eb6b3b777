// G2P (Mast 2013 eq. (2.22)) and the particle velocity gradient (2.17). Each block gathers the
// padded halo of its nodes once, then updates its particles; blocks are independent.
#include "core/parallel.h"
#include "transfer/dispatch.h"
#include "transfer/stencil_loop.h"
#include "transfer/transfer.h"

namespace surge {
namespace {

struct NodeVel {
  Vec3 v0;  // v_{i,n}
  Vec3 v1;  // v_{i,n+1}
};

template <int kDim, class K>
void GatherHalo(const SparseGrid& grid, size_t blk, std::vector<NodeVel>& halo) {
  using Pad = BlockPad<kDim, K>;
  halo.resize(Pad::kSize);
  for (int a = 0; a < Pad::E; ++a)
    for (int b = 0; b < Pad::E; ++b)
      for (int c = 0; c < Pad::Ez; ++c) {
        const long g = PaddedToGrid(grid, blk, a, b, c);
        NodeVel& n = halo[Pad::Index(a, b, c)];
        if (g < 0) {
          n.v0.setZero();
          n.v1.setZero();
        } else {
          n.v0 = grid.velocity[g];
          n.v1 = grid.velocity_new[g];
        }
      }
}

enum class G2PMode { kFlip, kPicFlip, kApic };

template <int kDim, class K, G2PMode kMode>
void GatherBlocks(const Model& model, const StepContext& ctx, const SparseGrid& grid,
                  Particles& P, std::vector<Mat3>* velocity_gradient, std::vector<Vec3>* x_new) {
  using Pad = BlockPad<kDim, K>;
  const Real alpha = kMode == G2PMode::kFlip ? 1.0 : model.flip_ratio;
  ParallelFor(grid.block_count(), 1, [&](size_t blk) {
    thread_local std::vector<NodeVel> halo;
    GatherHalo<kDim, K>(grid, blk, halo);
    const Vec3i origin = grid.block_origin[blk];
    for (uint32_t s = grid.block_begin[blk]; s < grid.block_begin[blk + 1]; ++s) {
      const uint32_t p = grid.sorted[s];
      const Vec3 x = P.x[p];
      Stencil<kDim, K> st;
      st.Compute(x, ctx.inv_dx, KernelHalfWidth<K>(kDim, P.volume0[p], ctx.inv_dx));
      const Vec3i lb = st.base - origin;
      Vec3 v_pic = Vec3::Zero();  // sum N v_{n+1}
      Vec3 dv = Vec3::Zero();     // sum N (v_{n+1} - v_n)
      Mat3 L = Mat3::Zero();      // sum v_{n+1} (x) grad N
      Mat3 B = Mat3::Zero();      // sum N v_{n+1} (x) (x_i - x_p)
      for (int i = 0; i < st.W; ++i)
        for (int j = 0; j < st.W; ++j)
          for (int k = 0; k < st.Wz; ++k) {
            const Real w = st.Weight(i, j, k);
            const NodeVel& n = halo[Pad::Index(lb.x() + i, lb.y() + j, lb.z() + k)];
            v_pic += w * n.v1;
            if constexpr (kMode != G2PMode::kApic) dv += w * (n.v1 - n.v0);
            if constexpr (kMode == G2PMode::kApic && !kApicUsesGradient<K>) {
              const Vec3 xi = (st.base + Vec3i(i, j, k)).template cast<Real>() * ctx.dx - x;
              B += (w * n.v1) * xi.transpose();
            }
            if (velocity_gradient || (kMode == G2PMode::kApic && kApicUsesGradient<K>))
              L += n.v1 * st.Gradient(i, j, k).transpose();
          }
      if constexpr (kMode == G2PMode::kApic) {
        P.v[p] = v_pic;  // APIC velocity (Jiang et al. 2015, eq. (8))
        if constexpr (kApicUsesGradient<K>) {
          P.C[p] = L;
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
        P.v[p] = alpha * (P.v[p] + dv) + (1.0 - alpha) * v_pic;
      }
      if (velocity_gradient) (*velocity_gradient)[p] = L;
      const Vec3 xn = x + ctx.dt * v_pic;  // x_{n+1} = x_n + sum N dx_i, dx_i = dt v_{n+1} (2.16)
      if (x_new)
        (*x_new)[p] = xn;
      else
        P.x[p] = xn;
    }
  });
}

template <int kDim, class K>
void GradientBlocks(const StepContext& ctx, const SparseGrid& grid, const Particles& P,
                    std::vector<Mat3>& velocity_gradient) {
  using Pad = BlockPad<kDim, K>;
  ParallelFor(grid.block_count(), 1, [&](size_t blk) {
    thread_local std::vector<NodeVel> halo;
    GatherHalo<kDim, K>(grid, blk, halo);
    const Vec3i origin = grid.block_origin[blk];
    for (uint32_t s = grid.block_begin[blk]; s < grid.block_begin[blk + 1]; ++s) {
      const uint32_t p = grid.sorted[s];
      Stencil<kDim, K> st;
      st.Compute(P.x[p], ctx.inv_dx, KernelHalfWidth<K>(kDim, P.volume0[p], ctx.inv_dx));
      const Vec3i lb = st.base - origin;
      Mat3 L = Mat3::Zero();
      for (int i = 0; i < st.W; ++i)
        for (int j = 0; j < st.W; ++j)
          for (int k = 0; k < st.Wz; ++k)
            L += halo[Pad::Index(lb.x() + i, lb.y() + j, lb.z() + k)].v1 *
                 st.Gradient(i, j, k).transpose();  // (2.17)
      velocity_gradient[p] = L;
    }
  });
}

}  // namespace

void GridToParticle(const Model& model, const StepContext& ctx, const SparseGrid& grid,
                    Particles& particles, std::vector<Mat3>* velocity_gradient,
                    std::vector<Vec3>* x_new) {
  if (velocity_gradient) velocity_gradient->resize(particles.size());
  if (x_new) x_new->resize(particles.size());
  DispatchKernel(model.dim, model.shape, [&]<int kDim, class K>() {
    switch (model.transfer) {
      case TransferScheme::kFlip:
        GatherBlocks<kDim, K, G2PMode::kFlip>(model, ctx, grid, particles, velocity_gradient, x_new);
        break;
      case TransferScheme::kPicFlip:
        GatherBlocks<kDim, K, G2PMode::kPicFlip>(model, ctx, grid, particles, velocity_gradient,
                                                 x_new);
        break;
      case TransferScheme::kApic:
        GatherBlocks<kDim, K, G2PMode::kApic>(model, ctx, grid, particles, velocity_gradient, x_new);
        break;
    }
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
