// Closed-form signed distances of the obstacle primitives (Quilez's box and capped-cylinder
// SDFs, "distance functions", iquilezles.org; Ericson, Real-Time Collision Detection §5.1) and
// the dispatch to the mesh field. Inside a shape the distance is the largest face distance, so
// the active faces are those within the tolerance of it (seed spec §5.2 [REC], corners).
#include "contact/geometry.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>
#include <type_traits>
#include <variant>

#include "contact/mesh_distance.h"

namespace surge {
namespace {

constexpr Real kInf = std::numeric_limits<Real>::infinity();

inline bool Buried(uint64_t buried, int face) { return face < 64 && ((buried >> face) & 1u); }

// Collects the faces whose distance q[k] is within tol of the largest: the point is inside (or
// on) every constraint, and the nearest faces are the ones that act. Buried faces (on or beyond
// the domain boundary, Obstacle::buried_faces) never act: the nearest exposed faces do.
template <size_t N>
void ActiveFaces(const std::array<Real, N>& q_all, const std::array<Vec3, N>& n,
                 const std::array<int, N>& face, Real tol, uint64_t buried, SurfaceQuery& out) {
  std::array<Real, N> q = q_all;
  for (size_t k = 0; k < N; ++k)
    if (Buried(buried, face[k])) q[k] = -kInf;
  Real qmax = -kInf;
  for (size_t k = 0; k < N; ++k) qmax = std::max(qmax, q[k]);
  out.count = 0;
  for (size_t k = 0; k < N && out.count < kMaxContactFaces; ++k) {
    if (q[k] >= qmax - tol && q[k] > -kInf) {
      out.normal[out.count] = n[k];
      out.face[out.count] = face[k];
      ++out.count;
    }
  }
}

// The exit face of a point inside (SurfaceQuery::exit_*): among faces k with signed distances
// q[k] (<= 0 inside) and outward normals n[k], the nearest one that is not buried.
template <size_t N>
void NearestExposedFace(const std::array<Real, N>& q, const std::array<Vec3, N>& n,
                        const std::array<int, N>& face, uint64_t buried, SurfaceQuery& out) {
  Real best = -kInf;
  for (size_t k = 0; k < N; ++k) {
    if (Buried(buried, face[k]) || !(q[k] > best)) continue;
    best = q[k];
    out.exit_distance = q[k];
    out.exit_normal = n[k];
    out.exit_face = face[k];
  }
}

// Distance from "inside all face constraints" q (each q_k <= 0 inside) combined like a box:
// outside = length of the positive parts, inside = the largest (negative) part.
template <size_t N>
Real CombineBox(const std::array<Real, N>& q) {
  Real outside = 0, inside = -kInf;
  for (size_t k = 0; k < N; ++k) {
    if (q[k] > 0) outside += q[k] * q[k];
    inside = std::max(inside, q[k]);
  }
  return outside > 0 ? std::sqrt(outside) : inside;
}

SurfaceQuery QueryPlane(const PlaneShape& s, const Vec3& p, Real tol) {
  SurfaceQuery out;
  out.distance = (p - s.point).dot(s.normal);  // half-space, normal into the material
  if (out.distance <= tol) {
    out.count = 1;
    out.normal[0] = s.normal;
    out.face[0] = 0;
  }
  return out;
}

SurfaceQuery QueryBox(const BoxShape& s, const Vec3& p, int dim, Real tol, uint64_t buried) {
  const Vec3 c = 0.5 * (s.min + s.max), h = 0.5 * (s.max - s.min);
  std::array<Real, 3> q;
  std::array<Vec3, 3> n;
  std::array<int, 3> face;
  for (int a = 0; a < 3; ++a) {
    const bool upper = p[a] > c[a];
    q[a] = a < dim ? std::abs(p[a] - c[a]) - h[a] : -kInf;  // 2-D: infinite along z
    n[a] = Vec3::Zero();
    n[a][a] = upper ? 1 : -1;
    face[a] = 2 * a + (upper ? 1 : 0);  // x-, x+, y-, y+, z-, z+
  }
  SurfaceQuery out;
  out.distance = CombineBox(q);
  if (out.distance <= tol) ActiveFaces(q, n, face, tol, buried, out);
  if (buried != 0 && out.distance <= 0) {
    // Inside, with buried faces: every face of the box is a candidate exit, the far face of an
    // axis too (a barrier's foot on the floor: the top or a side; a post reaching past a side).
    std::array<Real, 6> qe;
    std::array<Vec3, 6> ne;
    std::array<int, 6> fe;
    for (int a = 0; a < 3; ++a) {
      qe[2 * a] = a < dim ? s.min[a] - p[a] : -kInf;  // a-: outward normal -e_a
      qe[2 * a + 1] = a < dim ? p[a] - s.max[a] : -kInf;
      ne[2 * a] = -Vec3::Unit(a);
      ne[2 * a + 1] = Vec3::Unit(a);
      fe[2 * a] = 2 * a;
      fe[2 * a + 1] = 2 * a + 1;
    }
    NearestExposedFace(qe, ne, fe, buried, out);
  }
  return out;
}

SurfaceQuery QuerySphere(const SphereShape& s, const Vec3& p, int dim, Real tol) {
  Vec3 r = p - s.center;
  if (dim == 2) r.z() = 0;  // a disk: a cylinder along z
  const Real len = r.norm();
  SurfaceQuery out;
  out.distance = len - s.radius;
  if (out.distance <= tol) {
    out.count = 1;
    out.normal[0] = len > 0 ? Vec3(r / len) : Vec3::UnitY();
    out.face[0] = 0;
  }
  return out;
}

SurfaceQuery QueryCylinder(const CylinderShape& s, const Vec3& p, Real tol, uint64_t buried) {
  const Vec3 axis_vec = s.top - s.base;
  const Real length = axis_vec.norm();
  const Vec3 a = axis_vec / length;
  const Real t = (p - s.base).dot(a);
  const Vec3 radial = p - s.base - t * a;
  const Real rho = radial.norm();
  // Radial direction; on the axis any perpendicular does (the side is then not the nearest face
  // unless the cylinder is thinner than its length, where the choice is arbitrary anyway).
  Vec3 er = rho > 0 ? Vec3(radial / rho) : a.unitOrthogonal();
  const std::array<Real, 3> q = {rho - s.radius, -t, t - length};
  const std::array<Vec3, 3> n = {er, -a, a};
  const std::array<int, 3> face = {0, 1, 2};  // side, base, top
  SurfaceQuery out;
  // Capped cylinder: combine the radial and the axial distance like a 2-D box.
  const std::array<Real, 2> q2 = {q[0], std::max(q[1], q[2])};
  out.distance = CombineBox(q2);
  if (out.distance <= tol) ActiveFaces(q, n, face, tol, buried, out);
  if (buried != 0 && out.distance <= 0) NearestExposedFace(q, n, face, buried, out);  // on the floor
  return out;
}

// Signed distance to a simple polygon in the xy plane with the edges within tol of the nearest.
SurfaceQuery QueryPolygon(const PolygonShape& s, const Vec3& p, int dim, Real tol,
                          uint64_t buried) {
  const auto& P = s.points;
  const int m = static_cast<int>(P.size());
  Real area2 = 0;  // twice the signed area: > 0 counter-clockwise
  for (int k = 0; k < m; ++k) {
    const auto& a = P[k];
    const auto& b = P[(k + 1) % m];
    area2 += a[0] * b[1] - b[0] * a[1];
  }
  const Real orient = area2 > 0 ? 1 : -1;
  // Distance from p to edge k (point k to point k+1).
  auto edge_distance = [&](int k) {
    const auto& a = P[k];
    const auto& b = P[(k + 1) % m];
    const Real ex = b[0] - a[0], ey = b[1] - a[1];
    const Real wx = p.x() - a[0], wy = p.y() - a[1];
    const Real t = std::clamp((wx * ex + wy * ey) / (ex * ex + ey * ey), Real(0), Real(1));
    return std::hypot(wx - t * ex, wy - t * ey);
  };
  // Nearest edge distance and inside test (crossing number).
  Real best = kInf;
  bool inside = false;
  for (int k = 0; k < m; ++k) {
    best = std::min(best, edge_distance(k));
    const auto& a = P[k];
    const auto& b = P[(k + 1) % m];
    if ((a[1] > p.y()) != (b[1] > p.y()) &&
        p.x() < a[0] + (p.y() - a[1]) * (b[0] - a[0]) / (b[1] - a[1])) {
      inside = !inside;
    }
  }
  const Real q_xy = inside ? -best : best;
  const Real q_lo = dim == 3 ? s.z0 - p.z() : -kInf;
  const Real q_hi = dim == 3 ? p.z() - s.z1 : -kInf;
  SurfaceQuery out;
  const std::array<Real, 2> q2 = {q_xy, std::max(q_lo, q_hi)};
  out.distance = CombineBox(q2);
  if (out.distance > tol) return out;
  out.count = 0;
  // Active faces among the exposed ones (buried faces never act): the nearest exposed edge and
  // the z caps, whichever is nearest, with ties.
  Real best_exposed = kInf;
  for (int k = 0; k < m; ++k)
    if (!Buried(buried, k)) best_exposed = std::min(best_exposed, edge_distance(k));
  const Real q_edge = best_exposed < kInf ? (inside ? -best_exposed : best_exposed) : -kInf;
  const Real q_zlo = Buried(buried, m) ? -kInf : q_lo;
  const Real q_zhi = Buried(buried, m + 1) ? -kInf : q_hi;
  const Real qmax = std::max({q_edge, q_zlo, q_zhi});
  // Edges: every exposed edge whose distance equals the nearest (within tol) when the xy part
  // is the largest; its outward normal is the edge normal rotated away from the interior.
  if (q_edge > -kInf && q_edge >= qmax - tol) {
    for (int k = 0; k < m && out.count < kMaxContactFaces; ++k) {
      if (Buried(buried, k) || edge_distance(k) - best_exposed > tol) continue;
      const auto& a = P[k];
      const auto& b = P[(k + 1) % m];
      Vec3 nk(orient * (b[1] - a[1]), -orient * (b[0] - a[0]), 0);
      out.normal[out.count] = nk.normalized();
      out.face[out.count] = k;
      ++out.count;
    }
  }
  if (dim == 3 && q_zlo > -kInf && q_zlo >= qmax - tol && out.count < kMaxContactFaces) {
    out.normal[out.count] = -Vec3::UnitZ();
    out.face[out.count++] = m;
  }
  if (dim == 3 && q_zhi > -kInf && q_zhi >= qmax - tol && out.count < kMaxContactFaces) {
    out.normal[out.count] = Vec3::UnitZ();
    out.face[out.count++] = m + 1;
  }
  return out;
}

SurfaceQuery QueryMesh(const MeshShape& s, const Vec3& p, Real tol, Real band) {
  const MeshDistance d = s.field->Query(p, band);
  SurfaceQuery out;
  out.distance = d.distance;
  if (d.distance <= tol && d.triangle >= 0) {
    out.count = 1;
    out.normal[0] = d.normal;
    const auto& part = s.field->mesh().part;
    out.face[0] = part.empty() ? 0 : part[d.triangle];
  }
  return out;
}

}  // namespace

ObstaclePose PoseAt(const Obstacle& obstacle, Real t, const std::vector<RigidBodyState>* rigid) {
  const ObstacleMotion& m = obstacle.motion;
  ObstaclePose pose;
  pose.center0 = m.center;
  pose.center = m.center;
  if (m.kind == ObstacleMotionKind::kFixed) return pose;
  if (m.kind == ObstacleMotionKind::kDynamic) {
    if (rigid == nullptr || m.body < 0 || size_t(m.body) >= rigid->size()) return pose;
    const RigidBodyState& s = (*rigid)[size_t(m.body)];
    pose.center = s.position;
    pose.rotation = s.rotation;
    pose.velocity = s.velocity;
    pose.angular_velocity = s.angular_velocity;
    return pose;
  }
  if (!m.table.empty()) {
    // Piecewise-linear displacement table: c(t) = c0 + d(t), v = d'(t) on the current segment.
    const auto& T = m.table;
    if (t <= T.front()[0] || T.size() == 1) {
      pose.center = m.center + Vec3(T.front()[1], T.front()[2], T.front()[3]);
    } else if (t >= T.back()[0]) {
      pose.center = m.center + Vec3(T.back()[1], T.back()[2], T.back()[3]);
    } else {
      size_t k = 1;
      while (T[k][0] < t) ++k;  // T[k-1][0] < t <= T[k][0]
      const auto& a = T[k - 1];
      const auto& b = T[k];
      const Real s = (t - a[0]) / (b[0] - a[0]);
      const Vec3 da(a[1], a[2], a[3]), db(b[1], b[2], b[3]);
      pose.center = m.center + da + s * (db - da);
      pose.velocity = (db - da) / (b[0] - a[0]);
    }
    return pose;
  }
  pose.velocity = m.velocity;
  pose.angular_velocity = m.angular_velocity;
  pose.center = m.center + t * m.velocity;
  const Real w = m.angular_velocity.norm();
  if (w > 0) {  // R(t) = exp(t [omega]x): rotation by |omega| t about omega / |omega|
    pose.rotation = Eigen::AngleAxis<Real>(w * t, m.angular_velocity / w).toRotationMatrix();
  }
  return pose;
}

SurfaceQuery QueryObstacle(const Obstacle& obstacle, const ObstaclePose& pose, const Vec3& x,
                           int dim, Real tolerance, Real band) {
  const Vec3 p = pose.ToReference(x);
  SurfaceQuery q = std::visit(
      [&](const auto& s) -> SurfaceQuery {
        using S = std::decay_t<decltype(s)>;
        if constexpr (std::is_same_v<S, PlaneShape>) return QueryPlane(s, p, tolerance);
        else if constexpr (std::is_same_v<S, BoxShape>)
          return QueryBox(s, p, dim, tolerance, obstacle.buried_faces);
        else if constexpr (std::is_same_v<S, SphereShape>) return QuerySphere(s, p, dim, tolerance);
        else if constexpr (std::is_same_v<S, CylinderShape>)
          return QueryCylinder(s, p, tolerance, obstacle.buried_faces);
        else if constexpr (std::is_same_v<S, PolygonShape>)
          return QueryPolygon(s, p, dim, tolerance, obstacle.buried_faces);
        else return QueryMesh(s, p, tolerance, band);
      },
      obstacle.shape);
  for (int k = 0; k < q.count; ++k) q.normal[k] = pose.rotation * q.normal[k];
  if (q.exit_face >= 0) {
    q.exit_normal = pose.rotation * q.exit_normal;
  } else if (q.count > 0) {  // the exit is the nearest active face
    q.exit_distance = q.distance;
    q.exit_normal = q.normal[0];
    q.exit_face = q.face[0];
  }
  return q;
}

void ReferenceBounds(const ObstacleShape& shape, int dim, Vec3& lo, Vec3& hi) {
  std::visit(
      [&](const auto& s) {
        using S = std::decay_t<decltype(s)>;
        if constexpr (std::is_same_v<S, PlaneShape>) {
          lo = Vec3::Constant(-kInf);
          hi = Vec3::Constant(kInf);
        } else if constexpr (std::is_same_v<S, BoxShape>) {
          lo = s.min;
          hi = s.max;
        } else if constexpr (std::is_same_v<S, SphereShape>) {
          lo = s.center - Vec3::Constant(s.radius);
          hi = s.center + Vec3::Constant(s.radius);
        } else if constexpr (std::is_same_v<S, CylinderShape>) {
          // The end disks' extent along world axis i is r sqrt(1 - a_i^2), a the unit axis.
          const Vec3 a = (s.top - s.base).normalized();
          Vec3 r;
          for (int i = 0; i < 3; ++i) r[i] = s.radius * std::sqrt(std::max(0.0, 1 - a[i] * a[i]));
          lo = s.base.cwiseMin(s.top) - r;
          hi = s.base.cwiseMax(s.top) + r;
        } else if constexpr (std::is_same_v<S, PolygonShape>) {
          lo = Vec3(kInf, kInf, s.z0);
          hi = Vec3(-kInf, -kInf, s.z1);
          for (const auto& q : s.points) {
            lo.x() = std::min(lo.x(), q[0]);
            lo.y() = std::min(lo.y(), q[1]);
            hi.x() = std::max(hi.x(), q[0]);
            hi.y() = std::max(hi.y(), q[1]);
          }
        } else {
          const Aabb b = s.field->bounds();
          lo = b.min;
          hi = b.max;
        }
      },
      shape);
  if (dim == 2) {  // extruded along z
    lo.z() = -kInf;
    hi.z() = kInf;
  }
}

void PosedBounds(const Obstacle& obstacle, const ObstaclePose& pose, Vec3& lo, Vec3& hi) {
  const Vec3 rlo = obstacle.bounds_min, rhi = obstacle.bounds_max;
  if (std::holds_alternative<PlaneShape>(obstacle.shape)) {
    lo = rlo;
    hi = rhi;
    return;
  }
  // Bounding box of the posed corners. 2-D shapes are infinite along z and rotate about z only:
  // bound x and y by the four posed xy corners and keep z infinite.
  const bool planar = !std::isfinite(rlo.z());
  const int corners = planar ? 4 : 8;
  lo = Vec3::Constant(kInf);
  hi = Vec3::Constant(-kInf);
  for (int c = 0; c < corners; ++c) {
    const Vec3 corner((c & 1) ? rhi.x() : rlo.x(), (c & 2) ? rhi.y() : rlo.y(),
                      planar ? pose.center0.z() : ((c & 4) ? rhi.z() : rlo.z()));
    const Vec3 w = pose.ToWorld(corner);
    lo = lo.cwiseMin(w);
    hi = hi.cwiseMax(w);
  }
  if (planar) {
    lo.z() = -kInf;
    hi.z() = kInf;
  }
}

uint64_t BuriedFaces(const ObstacleShape& shape, int dim, const Vec3& lo, const Vec3& hi, Real tol) {
  // A planar face with outward normal n at a point x is buried when n = -e_a and x_a <= lo_a, or
  // n = +e_a and x_a >= hi_a (nothing can reach it from inside the domain).
  auto buried = [&](const Vec3& n, const Vec3& x) {
    for (int a = 0; a < dim; ++a) {
      if (std::abs(std::abs(n[a]) - 1) > 1e-12) continue;
      return n[a] < 0 ? x[a] <= lo[a] + tol : x[a] >= hi[a] - tol;
    }
    return false;
  };
  uint64_t mask = 0;
  auto mark = [&](int face, bool b) {
    if (b && face < 64) mask |= uint64_t(1) << face;
  };
  std::visit(
      [&](const auto& s) {
        using S = std::decay_t<decltype(s)>;
        if constexpr (std::is_same_v<S, BoxShape>) {
          for (int a = 0; a < dim; ++a) {
            mark(2 * a, buried(-Vec3::Unit(a), s.min));
            mark(2 * a + 1, buried(Vec3::Unit(a), s.max));
          }
        } else if constexpr (std::is_same_v<S, CylinderShape>) {
          const Vec3 a = (s.top - s.base).normalized();
          mark(1, buried(-a, s.base));
          mark(2, buried(a, s.top));
        } else if constexpr (std::is_same_v<S, PolygonShape>) {
          const auto& P = s.points;
          const int m = static_cast<int>(P.size());
          Real area2 = 0;
          for (int k = 0; k < m; ++k)
            area2 += P[k][0] * P[(k + 1) % m][1] - P[(k + 1) % m][0] * P[k][1];
          const Real orient = area2 > 0 ? 1 : -1;
          for (int k = 0; k < m; ++k) {
            const auto& a = P[k];
            const auto& b = P[(k + 1) % m];
            const Vec3 n = Vec3(orient * (b[1] - a[1]), -orient * (b[0] - a[0]), 0).normalized();
            mark(k, buried(n, Vec3(a[0], a[1], 0)));
          }
          if (dim == 3) {
            mark(m, buried(-Vec3::UnitZ(), Vec3(0, 0, s.z0)));
            mark(m + 1, buried(Vec3::UnitZ(), Vec3(0, 0, s.z1)));
          }
        }
      },
      shape);
  return mask;
}

std::vector<std::string> FaceNames(const ObstacleShape& shape, int dim) {
  return std::visit(
      [&](const auto& s) -> std::vector<std::string> {
        using S = std::decay_t<decltype(s)>;
        if constexpr (std::is_same_v<S, PlaneShape>) {
          return {"plane"};
        } else if constexpr (std::is_same_v<S, BoxShape>) {
          std::vector<std::string> f = {"x-", "x+", "y-", "y+", "z-", "z+"};
          f.resize(2 * dim);
          return f;
        } else if constexpr (std::is_same_v<S, SphereShape>) {
          return {"surface"};
        } else if constexpr (std::is_same_v<S, CylinderShape>) {
          return {"side", "base", "top"};
        } else if constexpr (std::is_same_v<S, PolygonShape>) {
          std::vector<std::string> f;
          for (size_t k = 0; k < s.points.size(); ++k) f.push_back("edge" + std::to_string(k));
          if (dim == 3) {
            f.push_back("z-");
            f.push_back("z+");
          }
          return f;
        } else {
          const auto& names = s.field->mesh().part_names;
          if (names.empty()) return {"surface"};
          return names;
        }
      },
      shape);
}

}  // namespace surge
