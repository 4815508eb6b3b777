// Node contact with rigid obstacles (seed spec §5.3 [REC] velocity-based Coulomb; Bardenhagen,
// Brackbill & Sulsky 2000, Comput. Methods Appl. Mech. Engrg. 187:529-541, eq. (11)) and the
// per-obstacle reaction sums (seed spec §5.4; Mast 2013 eq. (7.15) for the contact area).
#include "contact/contact.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <variant>

#include "contact/geometry.h"
#include "core/parallel.h"

namespace surge {
namespace {

constexpr Real kInf = std::numeric_limits<Real>::infinity();

// Per-block partial sums of one obstacle: totals, then 4 values per face.
enum Slot { kFx, kFy, kFz, kTx, kTy, kTz, kNodes, kMaxElev, kMinElev, kMaxNodal, kHeader };
constexpr int kFaceSlots = 4;  // fx, fy, fz, nodes

// Constrains the velocity `v` (world) of a node or particle relative to the obstacle velocity
// `vo` on each active face in turn; dv[k] receives face k's change. Seed spec §5.3 [REC]:
// remove the approaching normal component (all of it when bilateral), then Coulomb friction on
// the tangential remainder, |dv_t| <= mu |dv_n| (Bardenhagen et al. 2000, eq. (11)).
// `hold` [m/s]: the separating normal speed the adhesion can still stop (0 without adhesion).
inline void Constrain(const SurfaceQuery& q, const ObstacleContact& law, const Vec3& vo, Real hold,
                      Vec3& v, Vec3* dv) {
  for (int k = 0; k < q.count; ++k) {
    const Vec3& n = q.normal[k];
    Vec3 rel = v - vo;
    const Real vn = rel.dot(n);  // > 0: moving away from the surface
    dv[k].setZero();
    // Released in tension unless the adhesion holds: pulling the node back needs the force
    // m vn / dt, available up to adhesion x h^(d-1) (hold = that force x dt / m).
    if (law.separable && (vn > hold || (vn >= 0 && hold == 0))) continue;
    rel -= vn * n;
    if (law.friction > 0) {
      const Vec3 vt = rel - rel.dot(n) * n;
      const Real vt_norm = vt.norm();
      const Real limit = law.friction * std::abs(vn);
      rel -= vt_norm <= limit ? vt : Vec3((limit / vt_norm) * vt);  // stick : slip
    }
    const Vec3 v_new = vo + rel;
    dv[k] = v_new - v;
    v = v_new;
  }
}

// Broad phase: the blocks (in block order) whose node box meets [lo, hi] widened by tol.
void BlocksMeeting(const SparseGrid& grid, Real dx, int dim, const Vec3& lo, const Vec3& hi,
                   Real tol, std::vector<int32_t>& out) {
  out.clear();
  for (size_t b = 0; b < grid.block_count(); ++b) {
    const Vec3 blo = grid.block_origin[b].cast<Real>() * dx;
    const Vec3 bhi = blo + Vec3::Constant((kBlockDim - 1) * dx);
    bool overlap = true;
    for (int a = 0; a < dim; ++a) overlap &= bhi[a] >= lo[a] - tol && blo[a] <= hi[a] + tol;
    if (overlap) out.push_back(int32_t(b));
  }
}

Real BaseElevation(const Obstacle& o, const ObstaclePose& pose, const Vec3& up) {
  Vec3 lo, hi;
  PosedBounds(o, pose, lo, hi);
  Real base = kInf;
  for (int c = 0; c < 8; ++c) {
    const Vec3 corner((c & 1) ? hi.x() : lo.x(), (c & 2) ? hi.y() : lo.y(),
                      (c & 4) ? hi.z() : lo.z());
    Real e = 0;
    for (int a = 0; a < 3; ++a) {
      if (up[a] == 0) continue;  // infinite extent along a direction orthogonal to up
      e += up[a] * corner[a];
    }
    base = std::min(base, e);
  }
  return std::isfinite(base) ? base : kInf;  // infinite: use the lowest contact node instead
}

}  // namespace

Vec3 UpDirection(const Model& model) {
  const Real g = model.gravity.norm();
  return g > 0 ? Vec3(-model.gravity / g) : Vec3::UnitY();
}

void ApplyObstacleContact(const Model& model, const StepContext& ctx,
                          const std::vector<RigidBodyState>& rigid, SparseGrid& grid,
                          ContactScratch& scratch, std::vector<ObstacleForce>* report) {
  const Real t1 = ctx.time + ctx.dt;  // the constraint acts on v_{n+1}
  const Real tol = 1e-9 * ctx.dx;     // node-on-surface test, robust to round-off of i*dx
  const Real cell_area = model.dim == 3 ? ctx.dx * ctx.dx : ctx.dx;  // h^(d-1), (7.15)
  const Vec3 up = UpDirection(model);
  if (report) report->assign(model.obstacles.size(), ObstacleForce{});
  const size_t nb = grid.block_count();
  scratch.near_block.assign(nb, 0);
  for (size_t o = 0; o < model.obstacles.size(); ++o) {
    const Obstacle& ob = model.obstacles[o];
    const ObstaclePose pose = PoseAt(ob, t1, &rigid);
    // Broad phase: blocks whose node box meets the obstacle's posed bounds.
    Vec3 lo, hi;
    PosedBounds(ob, pose, lo, hi);
    BlocksMeeting(grid, ctx.dx, model.dim, lo, hi, tol, scratch.blocks);
    const int faces = int(ob.faces.size());
    const size_t stride = kHeader + kFaceSlots * size_t(faces);
    scratch.partial.assign(scratch.blocks.size() * stride, 0);
    const Vec3 ref = pose.ToWorld(ob.reference_point);
    // Only these shapes report several faces at a point (planes, spheres, meshes: one).
    const bool multi_face = std::holds_alternative<BoxShape>(ob.shape) ||
                            std::holds_alternative<CylinderShape>(ob.shape) ||
                            std::holds_alternative<PolygonShape>(ob.shape);
    const bool keep_reaction = report && !model.sensors.empty();  // not again in MUSL re-map
    ParallelFor(scratch.blocks.size(), 1, [&](size_t c) {
      const size_t b = size_t(scratch.blocks[c]);
      Real* part = &scratch.partial[c * stride];
      part[kMaxElev] = -kInf;
      part[kMinElev] = kInf;
      bool near = false;
      for (int l = 0; l < kBlockNodes; ++l) {
        const size_t i = b * kBlockNodes + l;
        const Real m = grid.mass[i];
        if (m <= 0) continue;
        const Vec3i node = grid.block_origin[b] + Vec3i(l / 64, (l / 8) % 8, l % 8);
        const Vec3 x = node.cast<Real>() * ctx.dx;
        SurfaceQuery q = QueryObstacle(ob, pose, x, model.dim, tol, 2 * ctx.dx);
        near |= q.distance < 2 * ctx.dx;
        if (q.distance > tol || q.count == 0) continue;
        // Nodal layer of a face: a node inside acts on every face whose plane lies less than
        // one cell (h) ahead of it, not only on the nearest. A face off the grid planes is
        // represented by the first node row behind it (< h inside), and at an edge that row's
        // end node is nearer to the other face: without this, a lid half a cell off the grid
        // lost its edge nodes (up to h of its width at each end). Measured on 2-D lids half a
        // cell off the grid (tests/verification/obstacle_test.cpp, LidBuoyancy*): 8 cells wide
        // -16 % -> -8 %, 16 cells wide -5.7 % -> -2.2 %; the floating box of
        // rigid_coupling_test sits +11 % instead of +26 % too deep. Nodes exactly h behind a face
        // (aligned faces) are not added: the aligned layer is unchanged. Mast 2013 eq. (7.15)
        // counts the same layer (one node row of area h^(d-1) per face); seed spec §5.2 [REC]
        // constrains the span of every active normal at edges.
        if (multi_face && q.distance > tol - ctx.dx) {
          const Real tie = ctx.dx + q.distance - 2 * tol;  // faces with distance > -h + tol
          if (tie > tol) q = QueryObstacle(ob, pose, x, model.dim, tie, 2 * ctx.dx);
        }
        Vec3 dv[kMaxContactFaces];
        Vec3& v = grid.velocity_new[i];
        const Vec3 before = v;
        const Real hold = ob.contact.adhesion * cell_area * ctx.dt / m;
        Constrain(q, ob.contact, pose.PointVelocity(x), hold, v, dv);
        // Force on the structure: the momentum the contact removed, m (v_u - v_c) / dt.
        const Vec3 f = m * (before - v) / ctx.dt;
        if (keep_reaction) grid.reaction[i] += f;  // for the force sensors
        const Vec3 tq = (x - ref).cross(f);
        for (int d = 0; d < 3; ++d) {
          part[kFx + d] += f[d];
          part[kTx + d] += tq[d];
        }
        part[kMaxNodal] = std::max(part[kMaxNodal], f.norm());
        const bool surface_layer = q.distance > -ctx.dx;  // one node layer: area per h^(d-1)
        if (surface_layer) {
          part[kNodes] += 1;
          const Real e = up.dot(x);
          part[kMaxElev] = std::max(part[kMaxElev], e);
          part[kMinElev] = std::min(part[kMinElev], e);
        }
        for (int k = 0; k < q.count; ++k) {
          Real* fp = part + kHeader + kFaceSlots * q.face[k];
          for (int d = 0; d < 3; ++d) fp[d] -= m * dv[k][d] / ctx.dt;
          if (surface_layer) fp[3] += 1;
        }
      }
      if (near) scratch.near_block[b] = 1;  // one writer per block: no race
    });
    if (!report) continue;
    ObstacleForce& r = (*report)[o];
    r.faces.assign(size_t(faces), FaceForce{});
    Real max_elev = -kInf, min_elev = kInf;
    for (size_t c = 0; c < scratch.blocks.size(); ++c) {  // block order: deterministic
      const Real* part = &scratch.partial[c * stride];
      r.force += Vec3(part[kFx], part[kFy], part[kFz]);
      r.torque += Vec3(part[kTx], part[kTy], part[kTz]);
      r.contact_nodes += int64_t(part[kNodes]);
      r.max_nodal_force = std::max(r.max_nodal_force, part[kMaxNodal]);
      max_elev = std::max(max_elev, part[kMaxElev]);
      min_elev = std::min(min_elev, part[kMinElev]);
      for (int k = 0; k < faces; ++k) {
        const Real* fp = part + kHeader + kFaceSlots * k;
        r.faces[k].force += Vec3(fp[0], fp[1], fp[2]);
        r.faces[k].contact_nodes += int64_t(fp[3]);
      }
    }
    r.contact_area = Real(r.contact_nodes) * cell_area;
    for (FaceForce& f : r.faces) f.contact_area = Real(f.contact_nodes) * cell_area;
    if (r.contact_nodes > 0) {
      const Real base = BaseElevation(ob, pose, up);
      r.wetted_height = max_elev - (std::isfinite(base) ? base : min_elev);
    }
  }
}

void SumSensors(const Model& model, const StepContext& ctx, const SparseGrid& grid,
                ContactScratch& scratch, std::vector<ObstacleForce>& out) {
  const Real tol = 1e-9 * ctx.dx;
  const Real cell_area = model.dim == 3 ? ctx.dx * ctx.dx : ctx.dx;  // h^(d-1), (7.15)
  const Vec3 up = UpDirection(model);
  out.assign(model.sensors.size(), ObstacleForce{});
  for (size_t s = 0; s < model.sensors.size(); ++s) {
    const Sensor& sensor = model.sensors[s];
    BlocksMeeting(grid, ctx.dx, model.dim, sensor.min, sensor.max, tol, scratch.blocks);
    const size_t stride = kHeader;
    scratch.partial.assign(scratch.blocks.size() * stride, 0);
    const Vec3 center = 0.5 * (sensor.min + sensor.max);
    ParallelFor(scratch.blocks.size(), 1, [&](size_t c) {
      const size_t b = size_t(scratch.blocks[c]);
      Real* part = &scratch.partial[c * stride];
      part[kMaxElev] = -kInf;
      for (int l = 0; l < kBlockNodes; ++l) {
        const size_t i = b * kBlockNodes + l;
        if (grid.mass[i] <= 0) continue;
        const Vec3& f = grid.reaction[i];
        if (f.isZero(0)) continue;
        const Vec3i node = grid.block_origin[b] + Vec3i(l / 64, (l / 8) % 8, l % 8);
        const Vec3 x = node.cast<Real>() * ctx.dx;
        bool inside = true;
        for (int a = 0; a < model.dim; ++a)
          inside &= x[a] >= sensor.min[a] - tol && x[a] <= sensor.max[a] + tol;
        if (!inside) continue;
        const Vec3 tq = (x - center).cross(f);
        for (int d = 0; d < 3; ++d) {
          part[kFx + d] += f[d];
          part[kTx + d] += tq[d];
        }
        part[kNodes] += 1;
        part[kMaxNodal] = std::max(part[kMaxNodal], f.norm());
        part[kMaxElev] = std::max(part[kMaxElev], up.dot(x));
      }
    });
    ObstacleForce& r = out[s];
    Real max_elev = -kInf;
    for (size_t c = 0; c < scratch.blocks.size(); ++c) {  // block order: deterministic
      const Real* part = &scratch.partial[c * stride];
      r.force += Vec3(part[kFx], part[kFy], part[kFz]);
      r.torque += Vec3(part[kTx], part[kTy], part[kTz]);
      r.contact_nodes += int64_t(part[kNodes]);
      r.max_nodal_force = std::max(r.max_nodal_force, part[kMaxNodal]);
      max_elev = std::max(max_elev, part[kMaxElev]);
    }
    r.contact_area = Real(r.contact_nodes) * cell_area;
    if (r.contact_nodes > 0) {
      Real base = kInf;  // lowest corner of the sensor box along up
      for (int c = 0; c < 8; ++c) {
        const Vec3 corner((c & 1) ? sensor.max.x() : sensor.min.x(),
                          (c & 2) ? sensor.max.y() : sensor.min.y(),
                          model.dim == 3 ? ((c & 4) ? sensor.max.z() : sensor.min.z()) : 0.0);
        base = std::min(base, up.dot(corner));
      }
      r.wetted_height = max_elev - base;
    }
  }
}

int64_t ProjectParticlesOutOfObstacles(const Model& model, const StepContext& ctx,
                                       const std::vector<RigidBodyState>& rigid,
                                       SparseGrid& grid, Particles& P,
                                       ContactScratch& scratch, std::vector<ObstacleForce>* report) {
  const Real t1 = ctx.time + ctx.dt;  // positions are x_{n+1}
  const size_t no = model.obstacles.size();
  std::vector<ObstaclePose>& poses = scratch.poses;
  std::vector<Vec3>&lo = scratch.lo, &hi = scratch.hi, &ref = scratch.ref;
  poses.resize(no);
  lo.resize(no);
  hi.resize(no);
  ref.resize(no);
  for (size_t o = 0; o < no; ++o) {
    poses[o] = PoseAt(model.obstacles[o], t1, &rigid);
    PosedBounds(model.obstacles[o], poses[o], lo[o], hi[o]);
    ref[o] = poses[o].ToWorld(model.obstacles[o].reference_point);
  }
  scratch.moved.resize(kReductionChunks);
  for (auto& m : scratch.moved) m.clear();
  // Broad phase, once per block: the block or one of the upper neighbours its particles'
  // stencils reach was near an obstacle. With no such block (material far from every obstacle)
  // the pass over the particles is skipped: a configured obstacle the flow never reaches costs
  // one pass over the blocks.
  const size_t nb = grid.block_count();
  std::vector<uint8_t> near_owner(nb, 0);
  bool any_near = false;
  for (size_t blk = 0; blk < nb; ++blk) {
    bool near = scratch.near_block[blk] != 0;
    for (int k = 1; k < 8 && !near; ++k) {
      const int32_t nbk = grid.neighbor[blk][k];
      near = nbk >= 0 && scratch.near_block[size_t(nbk)] != 0;
    }
    near_owner[blk] = near;
    any_near |= near;
  }
  if (any_near) ParallelChunks(P.size(), [&](size_t chunk, size_t b, size_t e) {
    for (size_t p = b; p < e; ++p) {
      if (!near_owner[size_t(grid.particle_block[p])]) continue;
      for (size_t o = 0; o < no; ++o) {
        Vec3& x = P.x[p];
        bool in_box = true;
        for (int a = 0; a < model.dim; ++a) in_box &= x[a] >= lo[o][a] && x[a] <= hi[o][a];
        if (!in_box) continue;
        const Obstacle& ob = model.obstacles[o];
        const SurfaceQuery q = QueryObstacle(ob, poses[o], x, model.dim, 0, ctx.dx);
        if (!(q.distance < 0) || q.count == 0) continue;
        // Back onto the nearest exposed face, a hair (1e-9 h) outside so that round-off on
        // rotated or curved faces cannot leave it inside.
        x -= (q.distance - 1e-9 * ctx.dx) * q.normal[0];
        SurfaceQuery one = q;
        one.count = 1;
        Vec3 dv[kMaxContactFaces];
        const Vec3 before = P.v[p];
        Constrain(one, ob.contact, poses[o].PointVelocity(x), 0, P.v[p], dv);
        const Vec3 f = P.mass[p] * (before - P.v[p]) / ctx.dt;
        scratch.moved[chunk].push_back({p, uint32_t(o), q.face[0], f, (x - ref[o]).cross(f)});
      }
    }
  });
  // Serially, in chunk (= particle) order, deterministic: the momentum taken from each moved
  // particle joins its obstacle's force, torque and face sums, and the reaction of the grid node
  // nearest to it (for the force sensors). That node lies in the particle's owner block or one
  // of its upper neighbours (the particle moved less than a cell since it was binned).
  int64_t moved = 0;
  for (const auto& list : scratch.moved) {
    for (const ProjectedParticle& m : list) {
      ++moved;
      if (report) {
        ObstacleForce& r = (*report)[m.obstacle];
        r.force += m.force;
        r.torque += m.torque;
        if (m.face >= 0 && size_t(m.face) < r.faces.size()) r.faces[size_t(m.face)].force += m.force;
      }
      if (model.sensors.empty()) continue;  // the nodal reaction is read by sensors only
      const Vec3i node = (P.x[m.particle] * ctx.inv_dx).array().round().cast<int>();
      const int32_t owner = grid.particle_block[m.particle];
      const Vec3i local = node - grid.block_origin[size_t(owner)];
      int k = 0;
      bool ok = true;
      for (int d = 0; d < 3; ++d) {
        ok &= local[d] >= 0 && local[d] < 2 * kBlockDim;
        if (local[d] >= kBlockDim) k |= 1 << d;
      }
      if (!ok) continue;
      const int32_t blk = grid.neighbor[size_t(owner)][k];
      if (blk < 0) continue;
      const Vec3i l = local - Vec3i((k & 1) ? kBlockDim : 0, (k & 2) ? kBlockDim : 0,
                                    (k & 4) ? kBlockDim : 0);
      grid.reaction[size_t(blk) * kBlockNodes + LocalNode(l.x(), l.y(), l.z())] += m.force;
    }
  }
  return moved;
}

}  // namespace surge
