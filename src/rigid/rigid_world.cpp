// RigidWorld (rigid_world.h): the only Bullet includer (STYLE H.10). Bullet 3.24, double precision
// (cmake/deps/bullet.cmake); mass properties from closed forms and, for hulls, tetrahedra.
#include "rigid/rigid_world.h"

#include <BulletCollision/CollisionDispatch/btSimulationIslandManager.h>
#include <LinearMath/btConvexHullComputer.h>
#include <btBulletDynamicsCommon.h>

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cstring>
#include <map>
#include <utility>
#include <cmath>
#include <numbers>
#include <stdexcept>

#include "core/check.h"

// Debian ships float (default) and double (*-float64) Bullet libraries. We link the double ones:
// the MPM works in double, and a float world would round every force, pose and velocity that
// crosses this interface to ~6e-8 relative (a 1e-4 m/s change on a body moving at 10 m/s would be
// at the float resolution), and State/SetState could not round-trip a Real.
static_assert(sizeof(btScalar) == sizeof(surge::Real),
              "Bullet must be double precision (BT_USE_DOUBLE_PRECISION + *-float64 libraries)");

namespace surge {
namespace {

// Bullet's default collision margin (CONVEX_DISTANCE_MARGIN, 0.04 m). Boxes and cylinders keep it
// inside their extents (edges rounded by the margin), hulls are shrunk by it before the margin
// is added back. For small bodies it is capped at a tenth of the smallest half-size.
constexpr Real kDefaultMargin = 0.04;
constexpr Real kMarginFraction = 0.1;

void Require(bool condition, const std::string& name, const std::string& message) {
  if (!condition) throw std::invalid_argument("rigid body '" + name + "': " + message);
}

btVector3 ToBt(const Vec3& v) { return btVector3(v.x(), v.y(), v.z()); }
Vec3 FromBt(const btVector3& v) { return Vec3(v.x(), v.y(), v.z()); }
btMatrix3x3 ToBt(const Mat3& m) {
  return btMatrix3x3(m(0, 0), m(0, 1), m(0, 2), m(1, 0), m(1, 1), m(1, 2), m(2, 0), m(2, 1),
                     m(2, 2));
}
Mat3 FromBt(const btMatrix3x3& m) {
  Mat3 r;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) r(i, j) = m[i][j];
  return r;
}

// Hull of `points` (shrink = 0: its vertices are input points, original_vertex_index valid).
void ComputeHull(const std::vector<Vec3>& points, Real shrink, Real shrink_clamp,
                 btConvexHullComputer& hull, Real* applied_shrink) {
  static_assert(sizeof(Vec3) == 3 * sizeof(double));
  const Real s = hull.compute(points.front().data(), static_cast<int>(sizeof(Vec3)),
                              static_cast<int>(points.size()), shrink, shrink_clamp);
  if (applied_shrink != nullptr) *applied_shrink = s;
}

// Volume, centroid and inertia per unit density of the convex hull: fan-triangulate each hull face,
// form tetrahedra with an interior reference point r, and sum
//   V_t = a . (b x c) / 6,   int x x^T dV = V_t / 20 (a a^T + b b^T + c c^T + s s^T), s = a + b + c
// (vertices relative to r; Tonon 2004, J. Math. Stat. 1(1) 8-11; Blow & Binstock 2004, "How to find
// the inertia tensor of a 3D solid body represented by a triangle mesh"). Then the parallel-axis
// shift to the centroid and I = tr(C) 1 - C. Uses the input coordinates, not Bullet's rounded ones.
ShapeMassProperties HullMassProperties(const std::vector<Vec3>& points) {
  if (points.size() < 4) throw std::invalid_argument("convex hull needs at least 4 points");
  btConvexHullComputer hull;
  ComputeHull(points, 0, 0, hull, nullptr);
  if (hull.faces.size() < 4) throw std::invalid_argument("convex hull is degenerate (flat)");
  Vec3 r = Vec3::Zero();
  for (int i = 0; i < hull.vertices.size(); ++i) r += points[hull.original_vertex_index[i]];
  r /= hull.vertices.size();
  Real volume = 0;
  Vec3 first = Vec3::Zero();   // int (x - r) dV
  Mat3 second = Mat3::Zero();  // int (x - r)(x - r)^T dV
  auto point = [&](int hull_vertex) { return points[hull.original_vertex_index[hull_vertex]] - r; };
  for (int f = 0; f < hull.faces.size(); ++f) {
    const btConvexHullComputer::Edge* e0 = &hull.edges[hull.faces[f]];
    const int v0 = e0->getSourceVertex();
    for (const btConvexHullComputer::Edge* e = e0->getNextEdgeOfFace(); e != e0;
         e = e->getNextEdgeOfFace()) {
      if (e->getTargetVertex() == v0) break;
      const Vec3 a = point(v0), b = point(e->getSourceVertex()), c = point(e->getTargetVertex());
      const Real vt = a.dot(b.cross(c)) / 6;
      const Vec3 s = a + b + c;
      volume += vt;
      first += vt * s / 4;
      second += (vt / 20) *
                (a * a.transpose() + b * b.transpose() + c * c.transpose() + s * s.transpose());
    }
  }
  if (volume < 0) {  // face orientation convention: take the outward one whatever Bullet's is
    volume = -volume;
    first = -first;
    second = -second;
  }
  if (!(volume > 0)) throw std::invalid_argument("convex hull has zero volume");
  ShapeMassProperties p;
  p.volume = volume;
  const Vec3 d = first / volume;
  p.centroid = r + d;
  const Mat3 c = second - volume * d * d.transpose();
  p.inertia_per_density = c.trace() * Mat3::Identity() - c;
  return p;
}

}  // namespace

ShapeMassProperties ComputeShapeMassProperties(const RigidShape& shape) {
  constexpr Real kPi = std::numbers::pi_v<Real>;
  ShapeMassProperties p;
  if (const auto* box = std::get_if<RigidBox>(&shape)) {
    // Solid cuboid with half extents (a, b, c): I_xx = m (b^2 + c^2) / 3, ... (e.g. Goldstein,
    // Classical Mechanics 3rd ed. §5.3 / any table: m (B^2 + C^2) / 12 with full edges B = 2b).
    const Vec3& h = box->half_extents;
    p.volume = 8 * h.x() * h.y() * h.z();
    const Vec3 h2 = h.cwiseProduct(h);
    p.inertia_per_density.diagonal() =
        p.volume / 3 * Vec3(h2.y() + h2.z(), h2.x() + h2.z(), h2.x() + h2.y());
  } else if (const auto* sphere = std::get_if<RigidSphere>(&shape)) {
    // Solid sphere: V = 4/3 pi r^3, I = 2/5 m r^2.
    const Real r = sphere->radius;
    p.volume = 4 * kPi * r * r * r / 3;
    p.inertia_per_density.diagonal().setConstant(2 * p.volume * r * r / 5);
  } else if (const auto* cyl = std::get_if<RigidCylinder>(&shape)) {
    // Solid cylinder, axis y, length L = 2h: V = pi r^2 L, I_yy = m r^2 / 2,
    // I_xx = I_zz = m (3 r^2 + L^2) / 12.
    const Real r = cyl->radius, h = cyl->half_height;
    p.volume = kPi * r * r * 2 * h;
    const Real side = p.volume * (3 * r * r + 4 * h * h) / 12;
    p.inertia_per_density.diagonal() = Vec3(side, p.volume * r * r / 2, side);
  } else if (const auto* hull = std::get_if<RigidConvexHull>(&shape)) {
    p = HullMassProperties(hull->points);
  } else {
    throw std::invalid_argument("a triangle mesh has no volume (static bodies only)");
  }
  return p;
}

// Key of a contact manifold: the user indices (RigidWorld body index; -1 for the ground plane)
// of its two bodies, in the manifold's own order.
std::pair<int, int> ManifoldKey(const btPersistentManifold& m) {
  return {m.getBody0()->getUserIndex(), m.getBody1()->getUserIndex()};
}

// Puts the dispatcher's contact manifolds in the order of their keys. The sequential-impulse
// solver visits contacts in this array's order, which Bullet leaves to the history of pair
// creation and removal (and its broadphase's enlarged bounding boxes); in key order, a step's
// result depends only on the manifolds' contents, which checkpoints hold (ContactCache), so a
// restarted run continues bitwise.
void SortManifolds(btDispatcher& dispatcher) {
  const int n = dispatcher.getNumManifolds();
  if (n < 2) return;
  btPersistentManifold** array = dispatcher.getInternalManifoldPointer();
  std::stable_sort(array, array + n, [](const btPersistentManifold* a, const btPersistentManifold* b) {
    return ManifoldKey(*a) < ManifoldKey(*b);
  });
  for (int i = 0; i < n; ++i) array[i]->m_index1a = i;  // releaseManifold finds it there
}

// btDiscreteDynamicsWorld with the contact manifolds in key order when the constraints are
// solved. With split islands off (set in RigidWorld's constructor) the solver takes that array
// as it is; Bullet's island split would re-sort it with a non-stable sort.
class SortedContactsWorld : public btDiscreteDynamicsWorld {
 public:
  using btDiscreteDynamicsWorld::btDiscreteDynamicsWorld;
  void solveConstraints(btContactSolverInfo& info) override {
    SortManifolds(*getDispatcher());
    btDiscreteDynamicsWorld::solveConstraints(info);
  }
};

// ContactCache layout: a header (kContactCacheMagic, sizeof(btManifoldPoint)), then per manifold
// a ManifoldRecord and its points as btManifoldPoint bytes.
constexpr uint32_t kContactCacheMagic = 0x53434331;  // "SCC1"
struct ManifoldRecord {
  int32_t key0, key1, points, pad;
  double breaking_threshold, processing_threshold;
};

struct RigidWorld::Impl {
  btDefaultCollisionConfiguration configuration;
  btCollisionDispatcher dispatcher{&configuration};
  btDbvtBroadphase broadphase;
  btSequentialImpulseConstraintSolver solver;
  SortedContactsWorld world{&dispatcher, &broadphase, &solver, &configuration};

  std::vector<std::unique_ptr<btTriangleMesh>> meshes;  // owned by us, referenced by shapes
  std::vector<std::unique_ptr<btCollisionShape>> shapes;
  std::unique_ptr<btRigidBody> ground;
  std::vector<std::unique_ptr<btRigidBody>> bodies;  // index = body id
  std::vector<std::string> names;
  std::vector<Real> masses;             // [kg], 0 = static
  std::vector<Vec3> principal_inertia;  // [kg m^2]

  ~Impl() {
    // Bodies must leave the world before they die (btCollisionWorld's destructor touches them).
    for (auto& body : bodies) world.removeRigidBody(body.get());
    if (ground) world.removeRigidBody(ground.get());
  }

  btRigidBody& Body(int body) {
    SURGE_CHECK(body >= 0 && body < static_cast<int>(bodies.size()), "no such rigid body");
    return *bodies[body];
  }
};

RigidWorld::RigidWorld(const Vec3& gravity, const std::optional<GroundPlane>& ground)
    : impl_(std::make_unique<Impl>()) {
  btDiscreteDynamicsWorld& world = impl_->world;
  world.setGravity(ToBt(gravity));
  // Bullet defaults kept, stated here because they decide the physics: 10 sequential-impulse
  // iterations, warm starting, split impulse (penetration recovery does not add momentum),
  // restitution only above 0.2 m/s approach speed, no solver-order randomisation (determinism).
  btContactSolverInfo& info = world.getSolverInfo();
  info.m_solverMode &= ~SOLVER_RANDMIZE_ORDER;
  // One solver batch over every contact, in key order (SortedContactsWorld): bodies in separate
  // groups do not interact, so this changes no result beyond round-off, and it keeps the order
  // a function of the state.
  world.getSimulationIslandManager()->setSplitIslands(false);
  if (ground) {
    SURGE_CHECK(ground->normal.norm() > 0, "ground plane normal is zero");
    const Vec3 n = ground->normal.normalized();
    impl_->shapes.push_back(std::make_unique<btStaticPlaneShape>(ToBt(n), n.dot(ground->point)));
    btRigidBody::btRigidBodyConstructionInfo ci(0, nullptr, impl_->shapes.back().get());
    ci.m_friction = ground->friction;
    ci.m_restitution = 0;
    impl_->ground = std::make_unique<btRigidBody>(ci);
    impl_->ground->setUserIndex(-1);
    world.addRigidBody(impl_->ground.get());
  }
}

RigidWorld::~RigidWorld() = default;

int RigidWorld::AddBody(const RigidBodyDesc& desc) {
  const std::string& name = desc.name;
  Require(desc.mass >= 0 && desc.density >= 0, name, "mass and density must be >= 0");
  Require(!(desc.mass > 0 && desc.density > 0), name, "give mass or density, not both");
  Require(std::isfinite(desc.mass) && std::isfinite(desc.density), name, "mass is not finite");
  const Mat3& rot = desc.rotation;
  Require((rot.transpose() * rot - Mat3::Identity()).norm() < 1e-9 && rot.determinant() > 0, name,
          "rotation is not a proper orthonormal matrix");
  Require(desc.friction >= 0 && desc.restitution >= 0 && desc.restitution <= 1, name,
          "friction must be >= 0 and restitution in [0, 1]");
  const bool dynamic = desc.mass > 0 || desc.density > 0;

  // Body frame handed to Bullet: principal axes P of the inertia, origin at the centre of mass.
  Mat3 principal_axes = Mat3::Identity();
  Vec3 centroid = Vec3::Zero();
  Vec3 inertia = Vec3::Zero();  // principal moments [kg m^2]
  Real mass = 0;
  std::unique_ptr<btCollisionShape> shape;

  if (const auto* box = std::get_if<RigidBox>(&desc.shape)) {
    Require(box->half_extents.minCoeff() > 0, name, "box half extents must be > 0");
    auto s = std::make_unique<btBoxShape>(ToBt(box->half_extents));
    s->setMargin(std::min(kDefaultMargin, kMarginFraction * box->half_extents.minCoeff()));
    shape = std::move(s);
  } else if (const auto* sphere = std::get_if<RigidSphere>(&desc.shape)) {
    Require(sphere->radius > 0, name, "sphere radius must be > 0");
    shape = std::make_unique<btSphereShape>(sphere->radius);  // the radius is the margin: exact
  } else if (const auto* cyl = std::get_if<RigidCylinder>(&desc.shape)) {
    Require(cyl->radius > 0 && cyl->half_height > 0, name, "cylinder sizes must be > 0");
    auto s =
        std::make_unique<btCylinderShape>(btVector3(cyl->radius, cyl->half_height, cyl->radius));
    s->setMargin(
        std::min(kDefaultMargin, kMarginFraction * std::min(cyl->radius, cyl->half_height)));
    shape = std::move(s);
  } else if (const auto* mesh = std::get_if<RigidTriangleMesh>(&desc.shape)) {
    Require(!dynamic, name, "triangle meshes are static only (mass = density = 0)");
    Require(!mesh->triangles.empty(), name, "triangle mesh is empty");
    auto tm =
        std::make_unique<btTriangleMesh>(/*use32bitIndices=*/true, /*use4componentVertices=*/true);
    const int nv = static_cast<int>(mesh->vertices.size());
    for (const auto& t : mesh->triangles) {
      Require(t[0] >= 0 && t[0] < nv && t[1] >= 0 && t[1] < nv && t[2] >= 0 && t[2] < nv, name,
              "triangle index out of range");
      tm->addTriangle(ToBt(mesh->vertices[t[0]]), ToBt(mesh->vertices[t[1]]),
                      ToBt(mesh->vertices[t[2]]), /*removeDuplicateVertices=*/false);
    }
    shape =
        std::make_unique<btBvhTriangleMeshShape>(tm.get(), /*useQuantizedAabbCompression=*/true);
    impl_->meshes.push_back(std::move(tm));
  }

  if (const auto* hull = std::get_if<RigidConvexHull>(&desc.shape)) {
    ShapeMassProperties props;
    try {
      props = ComputeShapeMassProperties(*hull);
    } catch (const std::invalid_argument& e) {
      Require(false, name, e.what());
    }
    centroid = props.centroid;
    const Mat3& j = props.inertia_per_density;
    const Real off = std::abs(j(0, 1)) + std::abs(j(0, 2)) + std::abs(j(1, 2));
    if (off > 1e-12 * j.trace()) {  // not already principal in the given frame: rotate to it
      Eigen::SelfAdjointEigenSolver<Mat3> eig(j);
      principal_axes = eig.eigenvectors();
      if (principal_axes.determinant() < 0) principal_axes.col(2) = -principal_axes.col(2);
    }
    const Real mass_scale = desc.density > 0 ? desc.density : desc.mass / props.volume;
    mass = desc.density > 0 ? desc.density * props.volume : desc.mass;
    inertia = mass_scale * (principal_axes.transpose() * j * principal_axes).diagonal();
    // Collision shape: hull shrunk by the margin (Bullet adds it back), in the principal frame.
    btConvexHullComputer shrunk;
    Real margin = 0;
    ComputeHull(hull->points, kDefaultMargin, kMarginFraction, shrunk, &margin);
    Require(margin > 0, name, "convex hull too thin for a collision margin");
    auto s = std::make_unique<btConvexHullShape>();
    for (int i = 0; i < shrunk.vertices.size(); ++i) {
      const Vec3 local = principal_axes.transpose() * (FromBt(shrunk.vertices[i]) - centroid);
      s->addPoint(ToBt(local), /*recalculateLocalAabb=*/false);
    }
    s->recalcLocalAabb();
    s->setMargin(margin);
    shape = std::move(s);
  } else if (dynamic) {
    const ShapeMassProperties props = ComputeShapeMassProperties(desc.shape);
    mass = desc.density > 0 ? desc.density * props.volume : desc.mass;
    inertia = (mass / props.volume) * props.inertia_per_density.diagonal();
  }
  Require(!dynamic || (mass > 0 && std::isfinite(mass) && inertia.minCoeff() > 0), name,
          "mass and inertia must be positive and finite");

  btRigidBody::btRigidBodyConstructionInfo ci(mass, nullptr, shape.get(), ToBt(inertia));
  ci.m_startWorldTransform =
      btTransform(ToBt(Mat3(rot * principal_axes)), ToBt(Vec3(desc.position + rot * centroid)));
  ci.m_friction = desc.friction;
  ci.m_restitution = desc.restitution;
  ci.m_linearDamping = 0;  // no numerical damping: the MPM contact is the only dissipation
  ci.m_angularDamping = 0;
  auto body = std::make_unique<btRigidBody>(ci);
  if (dynamic) {
    // Never sleep: a sleeping body ignores applied forces, and MPM loads arrive at any time.
    body->setActivationState(DISABLE_DEACTIVATION);
    body->setLinearVelocity(ToBt(desc.velocity));
    body->setAngularVelocity(ToBt(desc.angular_velocity));
    // Implicit gyroscopic term in the body frame (Bullet's default since 2.83, stated explicitly).
    body->setFlags(BT_ENABLE_GYROSCOPIC_FORCE_IMPLICIT_BODY);
  } else {
    Require(desc.velocity.isZero() && desc.angular_velocity.isZero(), name,
            "a static body cannot have a velocity");
  }
  body->setUserIndex(static_cast<int>(impl_->bodies.size()));  // ManifoldKey
  impl_->world.addRigidBody(body.get());
  impl_->shapes.push_back(std::move(shape));
  impl_->bodies.push_back(std::move(body));
  impl_->names.push_back(name);
  impl_->masses.push_back(mass);
  impl_->principal_inertia.push_back(inertia);
  return static_cast<int>(impl_->bodies.size()) - 1;
}

int RigidWorld::BodyCount() const { return static_cast<int>(impl_->bodies.size()); }

const std::string& RigidWorld::Name(int body) const {
  impl_->Body(body);
  return impl_->names[body];
}

void RigidWorld::ApplyForce(int body, const Vec3& force, const Vec3& torque_about_com) {
  btRigidBody& b = impl_->Body(body);
  if (b.isStaticObject()) return;
  b.applyCentralForce(ToBt(force));
  b.applyTorque(ToBt(torque_about_com));
}

void RigidWorld::Step(Real dt) {
  SURGE_CHECK(dt > 0 && std::isfinite(dt), "rigid step needs dt > 0");
  // maxSubSteps = 0: Bullet's variable-step mode, one internal step of exactly dt, no time
  // accumulation and no interpolated motion states (its defaults (1, 1/60) would step at 60 Hz
  // and interpolate between). The fixed step argument is then unused; pass dt for clarity.
  // One step: gravity and the applied forces act on v (semi-implicit Euler), contacts are solved,
  // then x += v dt (Bullet btRigidBody::integrateVelocities, predictIntegratedTransform).
  impl_->world.stepSimulation(dt, /*maxSubSteps=*/0, /*fixedTimeStep=*/dt);
  impl_->world.clearForces();  // stepSimulation already does; our contract does not rely on it
}

RigidWorld::BodyState RigidWorld::State(int body) const {
  const btRigidBody& b = impl_->Body(body);
  BodyState s;
  s.position = FromBt(b.getWorldTransform().getOrigin());
  s.rotation = FromBt(b.getWorldTransform().getBasis());
  s.velocity = FromBt(b.getLinearVelocity());
  s.angular_velocity = FromBt(b.getAngularVelocity());
  return s;
}

void RigidWorld::SetState(int body, const BodyState& state) {
  btRigidBody& b = impl_->Body(body);
  if (b.isStaticObject()) {
    SURGE_CHECK(state.velocity.isZero() && state.angular_velocity.isZero(),
                "a static body cannot have a velocity");
  }
  const btTransform t(ToBt(state.rotation), ToBt(state.position));
  b.setWorldTransform(t);
  b.setInterpolationWorldTransform(t);
  b.setLinearVelocity(ToBt(state.velocity));
  b.setAngularVelocity(ToBt(state.angular_velocity));
  b.setInterpolationLinearVelocity(ToBt(state.velocity));
  b.setInterpolationAngularVelocity(ToBt(state.angular_velocity));
  b.updateInertiaTensor();
  impl_->world.updateSingleAabb(&b);
}

std::vector<uint8_t> RigidWorld::ContactCache() const {
  btDispatcher& dispatcher = impl_->dispatcher;
  SortManifolds(dispatcher);
  std::vector<uint8_t> out;
  auto put = [&out](const void* data, size_t size) {
    const size_t at = out.size();
    out.resize(at + size);
    std::memcpy(out.data() + at, data, size);
  };
  const uint32_t header[2] = {kContactCacheMagic, uint32_t(sizeof(btManifoldPoint))};
  put(header, sizeof header);
  for (int i = 0; i < dispatcher.getNumManifolds(); ++i) {
    const btPersistentManifold& m = *dispatcher.getManifoldByIndexInternal(i);
    if (m.getNumContacts() == 0) continue;  // an empty manifold is the same as none
    const auto [k0, k1] = ManifoldKey(m);
    const ManifoldRecord r{k0, k1, m.getNumContacts(), 0, m.getContactBreakingThreshold(),
                           m.getContactProcessingThreshold()};
    put(&r, sizeof r);
    for (int j = 0; j < m.getNumContacts(); ++j) {
      btManifoldPoint pt = m.getContactPoint(j);
      pt.m_userPersistentData = nullptr;  // a pointer means nothing in a file (and Surge sets none)
      put(&pt, sizeof pt);
    }
  }
  return out;
}

int RigidWorld::RestoreContactCache(const std::vector<uint8_t>& cache) {
  uint32_t header[2] = {0, 0};
  SURGE_CHECK(cache.size() >= sizeof header, "rigid contact cache: too short");
  std::memcpy(header, cache.data(), sizeof header);
  SURGE_CHECK(header[0] == kContactCacheMagic && header[1] == sizeof(btManifoldPoint),
              "rigid contact cache: written by another build of Bullet");
  // Pairs and (empty) manifolds for the restored poses, as the next step's collision detection
  // would make them; then each manifold gets the points it held when the checkpoint was written.
  btDispatcher& dispatcher = impl_->dispatcher;
  impl_->world.performDiscreteCollisionDetection();
  std::map<std::pair<int, int>, btPersistentManifold*> by_key;
  for (int i = 0; i < dispatcher.getNumManifolds(); ++i) {
    btPersistentManifold* m = dispatcher.getManifoldByIndexInternal(i);
    m->clearManifold();
    by_key[ManifoldKey(*m)] = m;
  }
  int missing = 0;
  size_t at = sizeof header;
  while (at < cache.size()) {
    ManifoldRecord r{};
    SURGE_CHECK(at + sizeof r <= cache.size(), "rigid contact cache: truncated");
    std::memcpy(&r, cache.data() + at, sizeof r);
    at += sizeof r;
    SURGE_CHECK(r.points >= 0 && r.points <= MANIFOLD_CACHE_SIZE &&
                    at + size_t(r.points) * sizeof(btManifoldPoint) <= cache.size(),
                "rigid contact cache: bad manifold record");
    const auto it = by_key.find({r.key0, r.key1});
    if (it == by_key.end()) {
      ++missing;  // the pair is not in contact range any more at the restored poses
      at += size_t(r.points) * sizeof(btManifoldPoint);
      continue;
    }
    btPersistentManifold& m = *it->second;
    m.setContactBreakingThreshold(r.breaking_threshold);
    m.setContactProcessingThreshold(r.processing_threshold);
    for (int j = 0; j < r.points; ++j) {
      btManifoldPoint pt;
      std::memcpy(static_cast<void*>(&pt), cache.data() + at, sizeof pt);
      at += sizeof pt;
      m.addManifoldPoint(pt, /*isPredictive=*/true);  // appended in order: no validity check
    }
  }
  SortManifolds(dispatcher);
  return missing;
}

Real RigidWorld::Mass(int body) const {
  impl_->Body(body);
  return impl_->masses[body];
}

Vec3 RigidWorld::PrincipalInertia(int body) const {
  impl_->Body(body);
  return impl_->principal_inertia[body];
}

Mat3 RigidWorld::InertiaWorld(int body) const {
  const Mat3 r = State(body).rotation;
  return r * PrincipalInertia(body).asDiagonal() * r.transpose();
}

}  // namespace surge
