// Node contact with rigid obstacles (seed spec §5.3 [REC] velocity-based Coulomb; Bardenhagen,
// Brackbill & Sulsky 2000, Comput. Methods Appl. Mech. Engrg. 187:529-541, eq. (11)) and the
// per-obstacle reaction sums (seed spec §5.4; Mast 2013 eq. (7.15) for the contact area).
#include "contact/contact.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>

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
inline void Constrain(const SurfaceQuery& q, const ObstacleContact& law, const Vec3& vo, Vec3& v,
                      Vec3* dv) {
  for (int k = 0; k < q.count; ++k) {
    const Vec3& n = q.normal[k];
    Vec3 rel = v - vo;
    const Real vn = rel.dot(n);  // > 0: moving away from the surface
    dv[k].setZero();
    if (vn >= 0 && law.separable) continue;  // released in tension
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

void ApplyObstacleContact(const Model& model, const StepContext& ctx, SparseGrid& grid,
                          ContactScratch& scratch, std::vector<ObstacleForce>* report) {
  const Real t1 = ctx.time + ctx.dt;  // the constraint acts on v_{n+1}
  const Real tol = 1e-9 * ctx.dx;     // node-on-surface test, robust to round-off of i*dx
  const Real cell_area = model.dim == 3 ? ctx.dx * ctx.dx : ctx.dx;  // h^(d-1), (7.15)
  const Vec3 up = UpDirection(model);
  if (report) report->assign(model.obstacles.size(), ObstacleForce{});
  const size_t nb = grid.block_count();
  for (size_t o = 0; o < model.obstacles.size(); ++o) {
    const Obstacle& ob = model.obstacles[o];
    const ObstaclePose pose = PoseAt(ob, t1);
    // Broad phase: blocks whose node box meets the obstacle's posed bounds.
    Vec3 lo, hi;
    PosedBounds(ob, pose, lo, hi);
    scratch.blocks.clear();
    for (size_t b = 0; b < nb; ++b) {
      const Vec3 blo = grid.block_origin[b].cast<Real>() * ctx.dx;
      const Vec3 bhi = blo + Vec3::Constant((kBlockDim - 1) * ctx.dx);
      bool overlap = true;
      for (int a = 0; a < model.dim; ++a) overlap &= bhi[a] >= lo[a] - tol && blo[a] <= hi[a] + tol;
      if (overlap) scratch.blocks.push_back(int32_t(b));
    }
    const int faces = int(ob.faces.size());
    const size_t stride = kHeader + kFaceSlots * size_t(faces);
    scratch.partial.assign(scratch.blocks.size() * stride, 0);
    const Vec3 ref = pose.ToWorld(ob.reference_point);
    ParallelFor(scratch.blocks.size(), 1, [&](size_t c) {
      const size_t b = size_t(scratch.blocks[c]);
      Real* part = &scratch.partial[c * stride];
      part[kMaxElev] = -kInf;
      part[kMinElev] = kInf;
      for (int l = 0; l < kBlockNodes; ++l) {
        const size_t i = b * kBlockNodes + l;
        const Real m = grid.mass[i];
        if (m <= 0) continue;
        const Vec3i node = grid.block_origin[b] + Vec3i(l / 64, (l / 8) % 8, l % 8);
        const Vec3 x = node.cast<Real>() * ctx.dx;
        const SurfaceQuery q = QueryObstacle(ob, pose, x, model.dim, tol, 2 * ctx.dx);
        if (q.distance > tol || q.count == 0) continue;
        Vec3 dv[kMaxContactFaces];
        Vec3& v = grid.velocity_new[i];
        const Vec3 before = v;
        Constrain(q, ob.contact, pose.PointVelocity(x), v, dv);
        // Force on the structure: the momentum the contact removed, m (v_u - v_c) / dt.
        const Vec3 f = m * (before - v) / ctx.dt;
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

int64_t ProjectParticlesOutOfObstacles(const Model& model, const StepContext& ctx,
                                       Particles& P, ContactScratch& scratch,
                                       std::vector<ObstacleForce>* report) {
  const Real t1 = ctx.time + ctx.dt;  // positions are x_{n+1}
  const size_t no = model.obstacles.size();
  constexpr int kSums = 7;  // force, torque, moved count
  std::vector<Real>& partial = scratch.particle_partial;
  partial.assign(kReductionChunks * no * kSums, 0);
  std::vector<ObstaclePose>& poses = scratch.poses;
  std::vector<Vec3>&lo = scratch.lo, &hi = scratch.hi, &ref = scratch.ref;
  poses.resize(no);
  lo.resize(no);
  hi.resize(no);
  ref.resize(no);
  for (size_t o = 0; o < no; ++o) {
    poses[o] = PoseAt(model.obstacles[o], t1);
    PosedBounds(model.obstacles[o], poses[o], lo[o], hi[o]);
    ref[o] = poses[o].ToWorld(model.obstacles[o].reference_point);
  }
  ParallelChunks(P.size(), [&](size_t chunk, size_t b, size_t e) {
    for (size_t p = b; p < e; ++p) {
      for (size_t o = 0; o < no; ++o) {
        Vec3& x = P.x[p];
        bool in_box = true;
        for (int a = 0; a < model.dim; ++a) in_box &= x[a] >= lo[o][a] && x[a] <= hi[o][a];
        if (!in_box) continue;
        const Obstacle& ob = model.obstacles[o];
        const SurfaceQuery q = QueryObstacle(ob, poses[o], x, model.dim, 0, 2 * ctx.dx);
        if (!(q.distance < 0) || q.count == 0) continue;
        x -= q.distance * q.normal[0];  // back onto the nearest face
        SurfaceQuery one = q;
        one.count = 1;
        Vec3 dv[kMaxContactFaces];
        const Vec3 before = P.v[p];
        Constrain(one, ob.contact, poses[o].PointVelocity(x), P.v[p], dv);
        const Vec3 f = P.mass[p] * (before - P.v[p]) / ctx.dt;
        const Vec3 tq = (x - ref[o]).cross(f);
        Real* s = &partial[(chunk * no + o) * kSums];
        for (int d = 0; d < 3; ++d) {
          s[d] += f[d];
          s[3 + d] += tq[d];
        }
        s[6] += 1;
      }
    }
  });
  int64_t moved = 0;
  for (size_t o = 0; o < no; ++o) {
    for (size_t c = 0; c < kReductionChunks; ++c) {
      const Real* s = &partial[(c * no + o) * kSums];
      if (report) {
        (*report)[o].force += Vec3(s[0], s[1], s[2]);
        (*report)[o].torque += Vec3(s[3], s[4], s[5]);
      }
      moved += int64_t(s[6]);
    }
  }
  return moved;
}

}  // namespace surge
