// Node contact with rigid obstacles (seed spec §5.3 [REC] velocity-based Coulomb; Bardenhagen,
// Brackbill & Sulsky 2000, Comput. Methods Appl. Mech. Engrg. 187:529-541, eq. (11)) and the
// per-obstacle reaction sums (seed spec §5.4; Mast 2013 eq. (7.15) for the contact area).
#include "contact/contact.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <tuple>
#include <variant>

#include "contact/geometry.h"
#include "core/parallel.h"
#include "transfer/shape_functions.h"

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
// `allow` [m/s]: the approach speed that only closes the gap between the material and the
// surface within this step, gap / dt (speculative contact, as Box2D's speculative contacts;
// 0 without the gap test). `touching`: a particle touches the surface here; only then can the
// contact pull (adhesion, sticky contact), and a sticky contact holds the node exactly.
inline void Constrain(const SurfaceQuery& q, const ObstacleContact& law, const Vec3& vo, Real hold,
                      Vec3& v, Vec3* dv, Real allow = 0, bool touching = true) {
  const bool separable = law.separable || !touching;
  if (!touching) hold = 0;
  if (!separable) allow = 0;
  for (int k = 0; k < q.count; ++k) {
    const Vec3& n = q.normal[k];
    Vec3 rel = v - vo;
    const Real vn = rel.dot(n);  // > 0: moving away from the surface
    dv[k].setZero();
    Real target = 0;  // the normal velocity the constraint leaves
    if (vn >= 0) {
      // Released in tension unless the adhesion holds: pulling the node back needs the force
      // m vn / dt, available up to adhesion x h^(d-1) (hold = that force x dt / m).
      if (separable && !(hold > 0 && vn <= hold)) continue;
    } else {
      if (vn >= -allow) continue;  // it only closes the gap in this step
      target = -allow;
    }
    const Real dvn = target - vn;
    rel += dvn * n;
    if (law.friction > 0) {
      const Vec3 vt = rel - rel.dot(n) * n;
      const Real vt_norm = vt.norm();
      const Real limit = law.friction * std::abs(dvn);
      rel -= vt_norm <= limit ? vt : Vec3((limit / vt_norm) * vt);  // stick : slip
    }
    const Vec3 v_new = vo + rel;
    dv[k] = v_new - v;
    v = v_new;
  }
}

// World position of grid node i.
inline Vec3 NodePosition(const SparseGrid& grid, size_t i, Real dx) {
  return grid.NodeCoord(i).cast<Real>() * dx;
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

// --- Interpolated face constraint (ObstacleContact::interpolated_faces) -----------------------
// A node-by-node contact sees a face only through which nodes lie inside it: a face between
// two node planes acts from the first node plane behind it, wherever it lies in that cell, and
// the particles next to it crowd to carry its load. Measured (docs/obstacle-faces.md): 2-D lids
// half a cell off the grid read -2.4 / -3.8 % of p A, and a floating box sits +7 % deeper than
// Archimedes, its draft scattering from +3 to +17 % with the cell size. Instead, each node
// column through a planar face gets one constraint on the velocity that the kernel
// interpolates at the face (the column's 1-D weights N_j), u = sum_j N_j (v_j - v_o) . n = 0,
// solved by the least mass-weighted change dv_j = -lambda N_j / m_j n, lambda = u / sum_j
// N_j^2 / m_j (a Lagrange multiplier on the face velocity; the lumped-mass form of the
// kinematic constraint of Bardenhagen et al. 2000, eq. (11), moved from the nodes to the face).
// The column runs along the grid axis most aligned with the face normal.

// A planar face whose constraint acts on node columns.
struct ColumnFace {
  int face = 0;                 // index into Obstacle::faces
  int axis = 0;                 // column direction: the grid axis most aligned with the normal
  Vec3 normal = Vec3::UnitY();  // outward unit normal, world
  Real offset = 0;              // normal . x on the face plane [m]
  bool bounded = false;         // boxes: the column must pierce the face rectangle
  int ref_axis = 0;             // the face's normal axis in the reference pose (boxes)
  Real thickness = 0;           // the box's size along ref_axis [m]
  Vec3 ref_lo = Vec3::Zero(), ref_hi = Vec3::Zero();  // the box in the reference pose [m]
};

// 1-D kernel weight N(r) of a node r cells from a point (shape_functions.h); GIMP: the hat.
Real KernelWeight1D(ShapeFunction shape, Real r) {
  const Real a = std::abs(r);
  switch (shape) {
    case ShapeFunction::kQuadraticBspline:
      return a < 0.5 ? 0.75 - a * a : a < 1.5 ? 0.5 * (1.5 - a) * (1.5 - a) : 0;
    case ShapeFunction::kCubicBspline:
      return a < 1 ? 0.5 * a * a * a - a * a + 2.0 / 3.0 : a < 2 ? (2 - a) * (2 - a) * (2 - a) / 6 : 0;
    default:
      return a < 1 ? 1 - a : 0;
  }
}

// Reach of the 1-D kernel [cells].
Real KernelReach(ShapeFunction shape) {
  return shape == ShapeFunction::kCubicBspline ? 2.0
         : shape == ShapeFunction::kQuadraticBspline ? 1.5
                                                     : 1.0;
}

void ColumnFaces(const Obstacle& ob, const ObstaclePose& pose, int dim,
                 std::vector<ColumnFace>& out) {
  out.clear();
  if (!ob.contact.interpolated_faces) return;
  auto column_axis = [dim](const Vec3& n) {
    int a = 0;
    for (int b = 1; b < dim; ++b)
      if (std::abs(n[b]) > std::abs(n[a])) a = b;
    return a;
  };
  if (const auto* box = std::get_if<BoxShape>(&ob.shape)) {
    for (int k = 0; k < 2 * dim; ++k) {
      if ((ob.buried_faces >> k) & 1u) continue;  // no material beyond it (geometry.h)
      ColumnFace f;
      f.face = k;
      f.ref_axis = k / 2;
      const Real sign = (k % 2) ? 1 : -1;
      Vec3 point = box->min;
      if (k % 2) point[f.ref_axis] = box->max[f.ref_axis];
      f.normal = sign * (pose.rotation * Vec3::Unit(f.ref_axis));
      f.offset = f.normal.dot(pose.ToWorld(point));
      f.axis = column_axis(f.normal);
      f.bounded = true;
      f.thickness = box->max[f.ref_axis] - box->min[f.ref_axis];
      f.ref_lo = box->min;
      f.ref_hi = box->max;
      out.push_back(f);
    }
  } else if (const auto* plane = std::get_if<PlaneShape>(&ob.shape)) {
    ColumnFace f;
    f.normal = pose.rotation * plane->normal;
    f.offset = f.normal.dot(pose.ToWorld(plane->point));
    f.axis = column_axis(f.normal);
    out.push_back(f);
  }
}

// Weight of node x on face f's column constraint (> 0: x belongs to the column through it).
Real ColumnWeight(const ColumnFace& f, const ObstaclePose& pose, const Vec3& x, int dim, Real dx,
                  Real tol, ShapeFunction shape) {
  const Real na = f.normal[f.axis];
  const Real t = (f.offset - f.normal.dot(x)) / na;   // x + t e_axis lies on the face plane
  const Real along = na > 0 ? -t : t;                 // > 0: the node is on the material side
  const Real w = KernelWeight1D(shape, along / dx);
  if (w <= 0) return 0;
  if (!f.bounded) return w;
  if (along * std::abs(na) <= -f.thickness) return 0;  // beyond the box's other side
  Vec3 xf = x;
  xf[f.axis] += t;
  const Vec3 r = pose.ToReference(xf);
  for (int a = 0; a < dim; ++a) {
    if (a == f.ref_axis) continue;
    if (r[a] < f.ref_lo[a] - tol || r[a] > f.ref_hi[a] + tol) return 0;  // misses the face
  }
  return w;
}

}  // namespace

Vec3 UpDirection(const Model& model) {
  const Real g = model.gravity.norm();
  return g > 0 ? Vec3(-model.gravity / g) : Vec3::UnitY();
}

// Gap test: for the stencil nodes of every particle within 2 h of obstacle `ob`, the smallest
// gap between such a particle and the surface, max(d - 1.5 r, 0) (d its signed distance,
// r = V0^(1/d) / 2 its half-size; it touches, gap 0, within 1.5 r, the domain walls' touch test,
// WallTouchMarker in transfer/walls.h), in scratch.gap; +inf where no particle is that near.
// Only the candidate blocks of the broad phase (scratch.blocks) are written and read. A minimum
// is the same in any order: the result does not depend on the thread count.
void ObstacleGaps(const Model& model, const StepContext& ctx, const Obstacle& ob,
                  const ObstaclePose& pose, const SparseGrid& grid, const Particles& P,
                  ContactScratch& scratch) {
  const size_t nb = grid.block_count();
  scratch.gap.resize(nb * size_t(grid.block_nodes));
  scratch.candidate.assign(nb, 0);
  for (const int32_t b : scratch.blocks) {
    std::fill_n(scratch.gap.begin() + ptrdiff_t(size_t(b) * size_t(grid.block_nodes)),
                grid.block_nodes, kInf);
    scratch.candidate[size_t(b)] = 1;
  }
  ParallelFor(nb, 4, [&](size_t b) {
    bool reach = scratch.candidate[b] == 1;  // its particles' stencils lie in b and above
    for (int k = 1; k < 8 && !reach; ++k) {
      const int32_t nbk = grid.neighbor[b][k];
      reach = nbk >= 0 && scratch.candidate[size_t(nbk)] == 1;
    }
    if (!reach) return;
    for (uint32_t s = grid.block_begin[b]; s < grid.block_begin[b + 1]; ++s) {
      const size_t p = grid.sorted[s];
      const Real half = 0.5 * (model.dim == 3 ? std::cbrt(P.volume0[p]) : std::sqrt(P.volume0[p]));
      const SurfaceQuery q = QueryObstacle(ob, pose, P.x[p], model.dim, 0, 3 * ctx.dx);
      const Real g = std::max(q.distance - 1.5 * half, Real(0));
      if (!(g < 2 * ctx.dx)) continue;  // a wider gap never binds (|v| dt < h)
      Vec3i lo, n;
      StencilRange(model.shape, model.dim, P.x[p], ctx.inv_dx, lo, n);
      for (int i = 0; i < n.x(); ++i)
        for (int j = 0; j < n.y(); ++j)
          for (int k = 0; k < n.z(); ++k) {
            int32_t blk = -1;
            const int64_t node = NodeFromOwner(grid, b, lo + Vec3i(i, j, k), &blk);
            if (node < 0 || scratch.candidate[size_t(blk)] != 1) continue;
            AtomicMin(scratch.gap[size_t(node)], g);
          }
    }
  });
}

void ApplyObstacleContact(const Model& model, const StepContext& ctx,
                          const std::vector<RigidBodyState>& rigid, SparseGrid& grid,
                          ContactScratch& scratch, std::vector<ObstacleForce>* report,
                          const Particles* particles) {
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
    std::vector<ColumnFace> column_faces;
    ColumnFaces(ob, pose, model.dim, column_faces);
    const Real reach = KernelReach(model.shape) * ctx.dx;
    const bool gap = ob.contact.gap_test && particles != nullptr;
    if (gap) ObstacleGaps(model, ctx, ob, pose, grid, *particles, scratch);
    scratch.column_nodes.resize(std::max(scratch.column_nodes.size(), scratch.blocks.size()));
    ParallelFor(scratch.blocks.size(), 1, [&](size_t c) {
      const size_t b = size_t(scratch.blocks[c]);
      Real* part = &scratch.partial[c * stride];
      part[kMaxElev] = -kInf;
      part[kMinElev] = kInf;
      bool near = false;
      std::vector<ColumnNode>& columns = scratch.column_nodes[c];
      columns.clear();
      for (int l = 0; l < grid.block_nodes; ++l) {
        const size_t i = b * size_t(grid.block_nodes) + size_t(l);
        const Real m = grid.mass[i];
        if (m <= 0) continue;
        const Vec3i node = grid.block_origin[b] + grid.LocalCoord(l);
        const Vec3 x = node.cast<Real>() * ctx.dx;
        SurfaceQuery q = QueryObstacle(ob, pose, x, model.dim, tol, 2 * ctx.dx);
        near |= q.distance < 2 * ctx.dx;
        uint32_t on_columns = 0;  // Obstacle::faces that act on this node through its column
        if (!column_faces.empty() && q.distance < reach) {
          for (size_t k = 0; k < column_faces.size(); ++k) {
            const ColumnFace& f = column_faces[k];
            const Real w = ColumnWeight(f, pose, x, model.dim, ctx.dx, tol, model.shape);
            if (w <= 0) continue;
            on_columns |= 1u << f.face;
            const int a1 = (f.axis + 1) % 3, a2 = (f.axis + 2) % 3;
            const int64_t key = (int64_t(node[a1]) << 32) ^ int64_t(uint32_t(node[a2]));
            columns.push_back({int32_t(k), node[f.axis], key, i, w});
          }
        }
        if (q.distance > tol || q.count == 0) continue;
        const Real node_gap = gap ? scratch.gap[i] : 0;
        if (!(node_gap < kInf)) continue;  // no particle near the obstacle here
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
        // The faces that act on this node by itself (the others act through its columns).
        SurfaceQuery own = q;
        own.count = 0;
        for (int k = 0; k < q.count; ++k) {
          if ((on_columns >> q.face[k]) & 1u) continue;
          own.normal[own.count] = q.normal[k];
          own.face[own.count] = q.face[k];
          ++own.count;
        }
        Vec3 dv[kMaxContactFaces];
        Vec3& v = grid.velocity_new[i];
        const Vec3 before = v;
        const Real hold = ob.contact.adhesion * cell_area * ctx.dt / m;
        Constrain(own, ob.contact, pose.PointVelocity(x), hold, v, dv, node_gap / ctx.dt,
                  node_gap <= 0);
        // Force on the structure: the momentum the contact removed, m (v_u - v_c) / dt.
        const Vec3 f = m * (before - v) / ctx.dt;
        if (keep_reaction) grid.reaction[i] += f;  // for the force sensors
        const Vec3 tq = (x - ref).cross(f);
        for (int d = 0; d < 3; ++d) {
          part[kFx + d] += f[d];
          part[kTx + d] += tq[d];
        }
        part[kMaxNodal] = std::max(part[kMaxNodal], f.norm());
        // One node layer (area per h^(d-1)) where the material touches (no gap).
        const bool surface_layer = q.distance > -ctx.dx && node_gap <= 0;
        if (surface_layer) {
          part[kNodes] += 1;
          const Real e = up.dot(x);
          part[kMaxElev] = std::max(part[kMaxElev], e);
          part[kMinElev] = std::min(part[kMinElev], e);
        }
        for (int k = 0; k < own.count; ++k) {
          Real* fp = part + kHeader + kFaceSlots * own.face[k];
          for (int d = 0; d < 3; ++d) fp[d] -= m * dv[k][d] / ctx.dt;
        }
        if (surface_layer)
          for (int k = 0; k < q.count; ++k) part[kHeader + kFaceSlots * q.face[k] + 3] += 1;
      }
      if (near) scratch.near_block[b] = 1;  // one writer per block: no race
    });
    Vec3 column_force = Vec3::Zero(), column_torque = Vec3::Zero();
    std::vector<Vec3> column_face_force(size_t(faces), Vec3::Zero());
    Real column_max_nodal = 0;
    if (!column_faces.empty()) {
      // Gather in block order and sort by face, column and row: the constraint is then solved
      // column by column in the same order for any thread count.
      std::vector<ColumnNode>& all = scratch.columns;
      all.clear();
      for (size_t c = 0; c < scratch.blocks.size(); ++c)
        all.insert(all.end(), scratch.column_nodes[c].begin(), scratch.column_nodes[c].end());
      std::sort(all.begin(), all.end(), [](const ColumnNode& a, const ColumnNode& b) {
        return std::tie(a.face, a.column, a.row) < std::tie(b.face, b.column, b.row);
      });
      for (size_t g = 0; g < all.size();) {
        size_t e = g + 1;
        while (e < all.size() && all[e].face == all[g].face && all[e].column == all[g].column) ++e;
        const ColumnFace& f = column_faces[size_t(all[g].face)];
        const Vec3& n = f.normal;
        // Gap between the material and the face in this column: the smallest of its nodes'.
        Real column_gap = gap ? kInf : 0;
        for (size_t j = g; j < e && gap; ++j) column_gap = std::min(column_gap, scratch.gap[all[j].node]);
        const bool touching = column_gap <= 0;
        if (!(column_gap < kInf)) {  // no particle near the face here
          g = e;
          continue;
        }
        // Face velocity u = sum_j N_j (v_j - v_o(x_j)) . n (> 0: separating) and the
        // multiplier lambda = u / sum_j N_j^2 / m_j.
        Real u = 0, den = 0, wsum = 0;
        for (size_t j = g; j < e; ++j) {
          const ColumnNode& cn = all[j];
          const Vec3 x = NodePosition(grid, cn.node, ctx.dx);
          u += cn.weight * (grid.velocity_new[cn.node] - pose.PointVelocity(x)).dot(n);
          den += cn.weight * cn.weight / grid.mass[cn.node];
          wsum += cn.weight;
        }
        // Released in tension unless sticky or the adhesion holds: pulling the face back needs
        // the force lambda sum_j N_j / dt, available up to adhesion x h^(d-1); either only while
        // a particle touches. Approaching, the face velocity may still close the gap within the
        // step (speculative contact: u >= -wsum gap / dt, the weights sum to wsum).
        bool release;
        if (u >= 0) {
          const bool sticky = touching && !ob.contact.separable;
          const Real adhesion = touching ? ob.contact.adhesion : 0;
          release = !sticky && !(adhesion > 0 && u / den * wsum <= adhesion * cell_area * ctx.dt);
        } else {
          if (touching && !ob.contact.separable) column_gap = 0;
          u += wsum * column_gap / ctx.dt;
          release = u >= 0;
        }
        const Real lambda = u / den;
        if (!release) {
          // The force sensors get the column's force at its node nearest to the face (largest
          // weight; the first such in row order): a sensor box around a face then holds it.
          size_t nearest = g;
          for (size_t j = g + 1; j < e; ++j)
            if (all[j].weight > all[nearest].weight) nearest = j;
          for (size_t j = g; j < e; ++j) {
            const ColumnNode& cn = all[j];
            const Real m = grid.mass[cn.node];
            const Vec3 x = NodePosition(grid, cn.node, ctx.dx);
            Vec3& v = grid.velocity_new[cn.node];
            const Vec3 before = v;
            const Real dvn = -lambda * cn.weight / m;  // normal change of this node
            v += dvn * n;
            if (ob.contact.friction > 0) {  // Coulomb on the node: |dv_t| <= mu |dv_n|
              const Vec3 rel = v - pose.PointVelocity(x);
              const Vec3 vt = rel - rel.dot(n) * n;
              const Real vt_norm = vt.norm(), limit = ob.contact.friction * std::abs(dvn);
              v -= vt_norm <= limit ? vt : Vec3((limit / vt_norm) * vt);
            }
            const Vec3 fk = m * (before - v) / ctx.dt;  // force on the structure
            if (keep_reaction) grid.reaction[all[nearest].node] += fk;
            column_force += fk;
            column_torque += (x - ref).cross(fk);
            column_face_force[size_t(f.face)] += fk;
            column_max_nodal = std::max(column_max_nodal, fk.norm());
          }
        }
        g = e;
      }
    }
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
    r.force += column_force;
    r.torque += column_torque;
    r.max_nodal_force = std::max(r.max_nodal_force, column_max_nodal);
    for (int k = 0; k < faces; ++k) r.faces[size_t(k)].force += column_face_force[size_t(k)];
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
      for (int l = 0; l < grid.block_nodes; ++l) {
        const size_t i = b * size_t(grid.block_nodes) + size_t(l);
        if (grid.mass[i] <= 0) continue;
        const Vec3& f = grid.reaction[i];
        if (f.isZero(0)) continue;
        const Vec3i node = grid.block_origin[b] + grid.LocalCoord(l);
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
        if (!(q.distance < 0) || q.exit_face < 0) continue;
        // Back onto the nearest exposed face (SurfaceQuery::exit_face), a hair (1e-9 h) outside
        // so that round-off on rotated or curved faces cannot leave it inside.
        x -= (q.exit_distance - 1e-9 * ctx.dx) * q.exit_normal;
        // In a wedge between the obstacle and a walled side of the domain (a plate leaning
        // against the lid), the push can carry the particle past the wall, which DomainExit
        // would then clamp back into the obstacle. Alternate the two projections (onto the
        // walled domain box and out of the obstacle); for the convex wedge this converges to
        // its corner, the factor cos^2 of the wedge angle per round (measured: a plate at
        // 60 degrees to the lid left a particle 0.085 mm inside without it).
        for (int round = 0; round < 32; ++round) {
          bool clamped = false;
          for (int a = 0; a < model.dim; ++a) {
            if (x[a] < model.domain_min[a] && model.walls[2 * a].kind != WallKind::kOpen)
              x[a] = model.domain_min[a], clamped = true;
            else if (x[a] > model.domain_max[a] && model.walls[2 * a + 1].kind != WallKind::kOpen)
              x[a] = model.domain_max[a], clamped = true;
          }
          if (!clamped) break;
          const SurfaceQuery again = QueryObstacle(ob, poses[o], x, model.dim, 0, ctx.dx);
          if (!(again.distance < 0) || again.exit_face < 0) break;
          x -= (again.exit_distance - 1e-9 * ctx.dx) * again.exit_normal;
        }
        SurfaceQuery one = q;
        one.count = 1;
        one.normal[0] = q.exit_normal;
        one.face[0] = q.exit_face;
        Vec3 dv[kMaxContactFaces];
        const Vec3 before = P.v[p];
        Constrain(one, ob.contact, poses[o].PointVelocity(x), 0, P.v[p], dv);
        const Vec3 f = P.mass[p] * (before - P.v[p]) / ctx.dt;
        scratch.moved[chunk].push_back({p, uint32_t(o), q.exit_face, f, (x - ref[o]).cross(f)});
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
      int32_t blk = -1;
      const int64_t i = NodeFromOwner(grid, size_t(grid.particle_block[m.particle]), node, &blk);
      if (i >= 0) grid.reaction[size_t(i)] += m.force;
    }
  }
  return moved;
}

}  // namespace surge
