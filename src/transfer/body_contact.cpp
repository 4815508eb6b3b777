// Frictional contact between MPM bodies on per-body velocity fields (Bardenhagen, Brackbill &
// Sulsky 2000, CMAME 187:529-541; Bardenhagen et al. 2001, CMES 2:509-522; the predictor-
// corrector of the Anura3D manual §6.2, eqs. (6.1)-(6.14); spec seed-anura3d.md A.8).
//
// ParticleToGrid has summed each field's mass, momentum, force and mass gradient, and the
// common field (their sum) went through the grid update, the walls and the obstacles as in
// single-field MPM. Here, at every node where two or more fields have mass:
//   1. each field predicts v_f = v_f,n + dt (f_f / m_f + g) (6.1)-(6.2) and takes the velocity
//      change the walls, obstacles and local damping made to the common field, so that
//      sum_f m_f v_f equals m v_c, the common (centre-of-mass) velocity after the constraints
//      (6.3): the damping force on the node is shared among the fields in proportion to mass
//      (with mass scaling, P2G scales the fields' masses and momenta as the common field's);
//   2. the normal is the outward normal of one body of the pair, the first one the scene
//      lists (the flat or stiff one: a slab, a wall), at the node: from that body's local
//      centre of mass xbar (m_i,f xbar = sum_{p in f} m_p N_ip x_p) to the node, n = (x_i -
//      xbar) / |.|; the other body uses -n. Opposite normals keep the correction momentum-
//      conserving for two bodies. [Surge] Normals that mix both bodies - Bardenhagen's
//      antisymmetrised mass gradient (A.8.3 [REC]) and the difference of the two local centres
//      of mass - were tried first: at a block's bottom corner they tilt by 27-90 degrees (the
//      block's own edge dominates where the base has only a kernel tail of mass), the corner
//      acts as a ramp, and a block on an incline stuck (a = 0 where g (sin th - mu cos th) =
//      1.48 m/s^2; tests/verification/body_contact_test). At nodes on or beyond a domain
//      wall the component along the wall's normal is dropped (the wall cuts the body's
//      material off there; with it, a 3-D block spanning a slab between two slip walls slid
//      33 % slow);
//   3. with dv = v_f - v_c: approaching when dv.n_f > 0 (6.4) (always, for a non-separable
//      pair): the normal part is removed (6.9)-(6.12) and the tangential part is limited by
//      Coulomb friction, |dv_t| <= mu |dv.n| (6.8) with (6.14): stick if below, else slip by
//      the excess; separating fields keep their own velocity (free separation, A.8.4).
//      [Surge] Gap test (BodyContact::gap_test, separable pairs): the fields share nodes as soon
//      as their kernels overlap, up to 2 x 1.5 h apart with quadratic B-splines, so without it
//      bodies stop about two cells short of each other. Where the particles of the two bodies
//      have not met along n (gap g > 0, ComputeBodyContactGaps), the contact is speculative, as
//      the obstacles' (contact.cpp): the fields may still close the gap within the step, a
//      relative approach of g / dt, i.e. dv.n_f up to m_other / (m_f + m_other) g / dt for
//      field f, and only the approach beyond that is removed (friction on the removed part);
//   4. the domain walls act on each field's velocity (their extra reaction is logged on the
//      walls); nodes where only one field has mass take the common velocity unchanged.
// Pairs of bodies that are not in Model::body_contacts are bonded: they take v_c, as in
// single-field MPM.
#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <string>

#include "core/check.h"
#include "core/parallel.h"
#include "transfer/shape_functions.h"
#include "transfer/transfer.h"
#include "transfer/walls.h"

namespace surge {
namespace {

// Per-block partial sums: wall face forces and torques (6 x 6), per-field contact forces (3 per
// field), the contact node count, then per pair: force (3), torque (3), nodes, largest nodal
// force, highest and lowest node along -g.
constexpr int kFieldSums = 6 * kFaceCount;
constexpr int kPairSums = 10;
constexpr int kPairForce = 0, kPairTorque = 3, kPairNodes = 6, kPairMax = 7, kPairTop = 8,
              kPairBottom = 9;

// The pair's normal at node i (x its position) for field f (step 2): outward of the normal body
// `master`'s material for that body, into it for the other; the component along a wall's normal
// dropped on or beyond the wall; zero where it is undefined.
Vec3 PairNormal(const SparseGrid& grid, size_t i, int master, int f, const Vec3& x,
                const WallPlane* walls, int wall_count, Real tolerance, Real dx) {
  const size_t mi = size_t(master) * grid.mass.size() + i;
  Vec3 n = grid.field_mass_moment[mi] / grid.field_mass[mi];  // xbar - x_i
  if (master == f) n = -n;
  // On or beyond a domain wall the body's material is cut off by the wall, which shifts its local
  // centre of mass along the wall normal; a wall is a symmetry plane of the material (slip), so
  // that component is dropped.
  for (int k = 0; k < wall_count; ++k)
    if (walls[k].sign * (x[walls[k].axis] - walls[k].level) <= tolerance) n[walls[k].axis] = 0;
  const Real n_norm = n.norm();
  return n_norm > 1e-9 * dx ? Vec3(n / n_norm) : Vec3::Zero();  // zero: no normal part
}

}  // namespace

std::vector<int> BodyContactPairTable(const Model& model) {
  const int F = model.field_count;
  std::vector<int> table(size_t(F) * F, -1);
  for (size_t c = 0; c < model.body_contacts.size(); ++c) {
    const BodyContact& bc = model.body_contacts[c];
    const int fa = model.body_field[bc.body_a], fb = model.body_field[bc.body_b];
    table[size_t(fa) * F + fb] = table[size_t(fb) * F + fa] = int(c);
  }
  return table;
}

void ComputeBodyContactGaps(const Model& model, const StepContext& ctx, const SparseGrid& grid,
                            const Particles& P, BodyContactGaps& gaps) {
  const int F = grid.field_count;
  const size_t nb = grid.block_count(), N = grid.mass.size();
  const std::vector<int> pair = BodyContactPairTable(model);
  WallPlane walls[kFaceCount];
  const int wall_count = ActiveWalls(model, walls);
  const Real tolerance = 1e-9 * ctx.dx, inf = std::numeric_limits<Real>::infinity();
  gaps.master.assign(N, -1);
  gaps.other.assign(N, -1);
  gaps.normal.resize(N);
  gaps.front_master.assign(N, -inf);
  gaps.front_other.assign(N, inf);
  ParallelFor(nb, 4, [&](size_t b) {
    for (int l = 0; l < grid.block_nodes; ++l) {
      const size_t i = b * size_t(grid.block_nodes) + size_t(l);
      if (!(grid.mass[i] > 0)) continue;
      int fa = -1, fb = -1;  // the two heaviest fields here (lowest index on a tie)
      for (int f = 0; f < F; ++f) {
        const Real mf = grid.field_mass[f * N + i];
        if (!(mf > 0)) continue;
        if (fa < 0 || mf > grid.field_mass[fa * N + i]) {
          fb = fa;
          fa = f;
        } else if (fb < 0 || mf > grid.field_mass[fb * N + i]) {
          fb = f;
        }
      }
      if (fb < 0) continue;
      const int c = pair[size_t(fa) * F + fb];
      if (c < 0 || !model.body_contacts[c].gap_test || !model.body_contacts[c].separable) continue;
      const int master = model.body_field[model.body_contacts[c].normal_body];
      const Vec3 x = (grid.block_origin[b] + grid.LocalCoord(l)).cast<Real>() * ctx.dx;
      const Vec3 n = PairNormal(grid, i, master, master, x, walls, wall_count, tolerance, ctx.dx);
      if (n.isZero()) continue;
      gaps.master[i] = int8_t(master);
      gaps.other[i] = int8_t(master == fa ? fb : fa);
      gaps.normal[i] = n;
    }
  });
  ParallelFor(nb, 4, [&](size_t b) {
    for (uint32_t k = grid.block_begin[b]; k < grid.block_begin[b + 1]; ++k) {
      const size_t p = grid.sorted[k];
      const int f = model.body_field[size_t(P.body[p])];
      if (f < 0) continue;
      const Real r = 0.5 * (model.dim == 3 ? std::cbrt(P.volume0[p]) : std::sqrt(P.volume0[p]));
      Vec3i lo, n;
      StencilRange(model.shape, model.dim, P.x[p], ctx.inv_dx, lo, n);
      for (int a = 0; a < n.x(); ++a)
        for (int c = 0; c < n.y(); ++c)
          for (int e = 0; e < n.z(); ++e) {
            const Vec3i node = lo + Vec3i(a, c, e);
            int32_t blk = -1;
            const int64_t i = NodeFromOwner(grid, b, node, &blk);
            if (i < 0 || gaps.master[size_t(i)] < 0) continue;
            const Real s = (P.x[p] - node.cast<Real>() * ctx.dx).dot(gaps.normal[size_t(i)]);
            if (gaps.master[size_t(i)] == f) {
              AtomicMax(gaps.front_master[size_t(i)], s + r);
            } else if (gaps.other[size_t(i)] == f) {
              AtomicMin(gaps.front_other[size_t(i)], s - r);
            }
          }
    }
  });
}

void ApplyBodyContact(const Model& model, const StepContext& ctx, SparseGrid& grid,
                      WallReport& walls_report, BodyContactReport& report,
                      const BodyContactGaps* gaps) {
  const int F = grid.field_count;
  SURGE_CHECK(F > 0 && F <= kMaxVelocityFields,
              "body contact needs 1.." + std::to_string(kMaxVelocityFields) +
                  " velocity fields, got " + std::to_string(F));
  const std::vector<int> pair = BodyContactPairTable(model);
  WallPlane walls[kFaceCount];
  const int wall_count = ActiveWalls(model, walls);
  const Real tolerance = 1e-9 * ctx.dx;  // node-on-wall test, as in the grid update
  const bool keep_reaction = !model.sensors.empty();
  const size_t nb = grid.block_count(), N = grid.mass.size();
  const int pairs = int(model.body_contacts.size());
  const int contact_nodes_at = kFieldSums + 3 * F, pair_at = contact_nodes_at + 1;
  const size_t K = size_t(pair_at + kPairSums * pairs);  // sums per block
  std::vector<Real> partial(nb * K, 0.0);
  for (size_t b = 0; b < nb; ++b)
    for (int c = 0; c < pairs; ++c) {
      partial[b * K + pair_at + kPairSums * c + kPairTop] = -std::numeric_limits<Real>::infinity();
      partial[b * K + pair_at + kPairSums * c + kPairBottom] = std::numeric_limits<Real>::infinity();
    }
  const Real g_norm = model.gravity.norm();
  const Vec3 up = g_norm > 0 ? Vec3(-model.gravity / g_norm) : Vec3::UnitY();
  ParallelFor(nb, 4, [&](size_t b) {
    Real* part = &partial[b * K];
    for (int l = 0; l < grid.block_nodes; ++l) {
      const size_t i = b * size_t(grid.block_nodes) + size_t(l);
      const Real m = grid.mass[i];
      if (m <= 0) continue;
      int present = 0;
      for (int f = 0; f < F; ++f) present += grid.field_mass[f * N + i] > 0;
      if (present <= 1) {  // one body here: its field is the common field
        for (int f = 0; f < F; ++f) {
          if (!(grid.field_mass[f * N + i] > 0)) continue;
          grid.field_velocity[f * N + i] = grid.velocity[i];
          grid.field_velocity_new[f * N + i] = grid.velocity_new[i];
        }
        continue;
      }
      part[contact_nodes_at] += 1;
      const Vec3 vc = grid.velocity_new[i];
      // The common field's prediction, as the grid update made it (2.13)-(2.14), and the change
      // its constraints (walls, obstacles) made.
      const Vec3 vu = grid.velocity[i] + ctx.dt * (grid.force[i] / m + ctx.gravity);
      const Vec3 constraint = vc - vu;
      const Vec3i node = grid.block_origin[b] + grid.LocalCoord(l);
      const Vec3 x = node.cast<Real>() * ctx.dx;
      for (int f = 0; f < F; ++f) {
        const size_t fi = f * N + i;
        const Real mf = grid.field_mass[fi];
        if (!(mf > 0)) continue;
        const Vec3 vn = grid.field_momentum[fi] / mf;                              // (2.13)
        const Vec3 w = vn + ctx.dt * (grid.field_force[fi] / mf + ctx.gravity) + constraint;  // (6.1)
        // The partner: the other field with the most mass here (lowest index on a tie).
        int partner = -1;
        for (int g = 0; g < F; ++g) {
          if (g == f || !(grid.field_mass[g * N + i] > 0)) continue;
          if (partner < 0 || grid.field_mass[g * N + i] > grid.field_mass[partner * N + i]) partner = g;
        }
        const int c = pair[size_t(f) * F + partner];
        Vec3 v = vc;  // bonded: the common velocity (single-field MPM)
        if (c >= 0) {
          // Normal (step 2 above): the outward normal of the pair's normal body at the node,
          // from the node away from that body's local centre of mass; into it for the other.
          const BodyContact& bc = model.body_contacts[c];
          const int master = model.body_field[bc.normal_body];
          const Vec3 n = PairNormal(grid, i, master, f, x, walls, wall_count, tolerance, ctx.dx);
          const Vec3 dv = w - vc;
          const Real dvn = dv.dot(n);                // (6.4): > 0 approaching
          // Gap test (step 3): the approach the gap still allows this field, relative to v_c.
          Real allowed = 0;
          if (gaps && gaps->master[i] >= 0 && (f == gaps->master[i] || f == gaps->other[i]) &&
              (partner == gaps->master[i] || partner == gaps->other[i])) {
            const Real mp = grid.field_mass[size_t(partner) * N + i];
            allowed = mp / (mf + mp) * gaps->Gap(i) / ctx.dt;
          }
          if (dvn > allowed || !bc.separable) {
            const Vec3 dvt = dv - dvn * n;           // (6.5)
            const Real dvt_norm = dvt.norm();
            const Real limit = bc.friction * std::abs(dvn - allowed);  // (6.8) with (6.14)
            const Vec3 base = allowed > 0 ? Vec3(vc + allowed * n) : vc;
            v = dvt_norm <= limit ? base : Vec3(base + (1 - limit / dvt_norm) * dvt);  // stick : slip
          } else {
            v = w;  // separating: free
          }
        }
        // Force on field f from the other bodies (6.6)-(6.7): the momentum the correction moved.
        const Vec3 contact_force = mf * (v - w) / ctx.dt;
        for (int d = 0; d < 3; ++d) part[kFieldSums + 3 * f + d] += contact_force[d];
        if (c >= 0 && f == model.body_field[model.body_contacts[c].normal_body] && v != w) {
          Real* q = part + pair_at + kPairSums * c;  // the force on the pair's normal body
          const Vec3 tq = x.cross(contact_force);
          for (int d = 0; d < 3; ++d) {
            q[kPairForce + d] += contact_force[d];
            q[kPairTorque + d] += tq[d];
          }
          q[kPairNodes] += 1;
          q[kPairMax] = std::max(q[kPairMax], contact_force.norm());
          q[kPairTop] = std::max(q[kPairTop], up.dot(x));
          q[kPairBottom] = std::min(q[kPairBottom], up.dot(x));
        }
        if (wall_count > 0) {
          const Vec3 before = v;
          Vec3 dvw[kFaceCount];
          if (ApplyWalls(walls, wall_count, x, tolerance, v, dvw, &grid, node)) {
            for (int k = 0; k < wall_count; ++k) {
              const Vec3 r = -mf * dvw[k] / ctx.dt;  // reaction on the wall (spec §5.3)
              const Vec3 tq = x.cross(r);
              Real* s = &part[6 * walls[k].face];
              for (int d = 0; d < 3; ++d) {
                s[d] += r[d];
                s[3 + d] += tq[d];
              }
            }
            if (keep_reaction) grid.reaction[i] += mf * (before - v) / ctx.dt;
          }
        }
        grid.field_velocity[fi] = vn;
        grid.field_velocity_new[fi] = v;
      }
    }
  });
  report.force.assign(F, Vec3::Zero());
  report.contact_nodes = 0;
  report.pairs.assign(pairs, ObstacleForce{});
  const Real cell_area = model.dim == 3 ? ctx.dx * ctx.dx : ctx.dx;  // h^(d-1) (7.15)
  std::vector<Real> top(pairs, -std::numeric_limits<Real>::infinity());
  std::vector<Real> bottom(pairs, std::numeric_limits<Real>::infinity());
  for (size_t b = 0; b < nb; ++b) {  // block order: deterministic for any thread count
    const Real* part = &partial[b * K];
    for (int k = 0; k < kFaceCount; ++k) {
      const Real* s = part + 6 * k;
      walls_report.force[k] += Vec3(s[0], s[1], s[2]);
      walls_report.torque[k] += Vec3(s[3], s[4], s[5]);
    }
    for (int f = 0; f < F; ++f)
      report.force[f] += Vec3(part[kFieldSums + 3 * f], part[kFieldSums + 3 * f + 1],
                              part[kFieldSums + 3 * f + 2]);
    report.contact_nodes += int64_t(part[contact_nodes_at]);
    for (int c = 0; c < pairs; ++c) {
      const Real* q = part + pair_at + kPairSums * c;
      ObstacleForce& o = report.pairs[c];
      o.force += Vec3(q[kPairForce], q[kPairForce + 1], q[kPairForce + 2]);
      o.torque += Vec3(q[kPairTorque], q[kPairTorque + 1], q[kPairTorque + 2]);
      o.contact_nodes += int64_t(q[kPairNodes]);
      o.max_nodal_force = std::max(o.max_nodal_force, q[kPairMax]);
      top[c] = std::max(top[c], q[kPairTop]);
      bottom[c] = std::min(bottom[c], q[kPairBottom]);
    }
  }
  for (int c = 0; c < pairs; ++c) {
    ObstacleForce& o = report.pairs[c];
    o.contact_area = Real(o.contact_nodes) * cell_area;
    o.wetted_height = o.contact_nodes > 0 ? top[c] - bottom[c] : 0;
  }
}

}  // namespace surge
