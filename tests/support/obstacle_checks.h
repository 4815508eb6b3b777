// Shared checks of the obstacle tests (tests/verification/obstacle*_test.cpp,
// rigid_coupling_test.cpp): particle penetration into obstacles, total mass and momentum.
#pragma once
#include <algorithm>

#include "contact/geometry.h"
#include "scene/scene.h"

namespace surge::testing {

// Largest depth of a particle inside any obstacle at the current state, at the obstacles' poses
// at state.time (dynamic ones from State::rigid); 0 when none is inside.
inline Real MaxPenetration(const LoadedScene& scene) {
  Real depth = 0;
  for (const Obstacle& o : scene.model.obstacles) {
    const ObstaclePose pose = PoseAt(o, scene.state.time, &scene.state.rigid);
    for (const Vec3& x : scene.state.particles.x) {
      const SurfaceQuery q = QueryObstacle(o, pose, x, scene.model.dim, 0, scene.model.dx);
      // Inside: the depth below the face it would leave through (SurfaceQuery::exit_face).
      const Real d = q.distance < 0 && q.exit_face >= 0 ? q.exit_distance : q.distance;
      depth = std::max(depth, -d);
    }
  }
  return depth;
}

inline Real TotalMass(const Particles& P) {
  Real m = 0;
  for (Real mp : P.mass) m += mp;
  return m;
}

inline Vec3 Momentum(const Particles& P) {
  Vec3 p = Vec3::Zero();
  for (size_t i = 0; i < P.size(); ++i) p += P.mass[i] * P.v[i];
  return p;
}

}  // namespace surge::testing
