// Reaction forces of one step on every structure (issue #5; seed spec §5.3-5.4): what the run loop
// logs every step (HDF5 /forces and forces_<name>.csv, docs/results-format.md) and what the peak
// tracking reads. Plain data, no behaviour.
#pragma once
#include <cstdint>
#include <string>
#include <vector>

#include "core/math.h"

namespace surge {

// One face (or face group) of a structure. 2-D values are per metre of thickness.
struct FaceForce {
  Vec3 force = Vec3::Zero();  // force ON the structure [N]: sum over its nodes of m (v_u - v_c) / dt
  Real contact_area = 0;      // sum of h^(d-1) over contact nodes with mass (seed eq. (7.15)) [m^2]
  int64_t contact_nodes = 0;  // nodes with mass the contact acted on
};

// One structure: the domain walls (name "domain", faces x-, x+, y-, y+, z-, z+) or an obstacle.
struct ObstacleForce {
  Vec3 force = Vec3::Zero();   // total force on the structure [N] (each node counted once)
  Vec3 torque = Vec3::Zero();  // about the structure's reference point [N m]
  Real contact_area = 0;       // [m^2]
  Real wetted_height = 0;      // highest contact node above the structure's lowest point, along -g [m]
  Real max_nodal_force = 0;    // largest |nodal force| on the structure this step [N]
  int64_t contact_nodes = 0;
  std::vector<FaceForce> faces;  // as ForceChannel::faces
};

// Names of what is logged; fixed for a run (built from the Model once).
struct ForceChannel {
  std::string name;                // "domain" or the obstacle's name
  std::vector<std::string> faces;  // face names
};

struct ContactReport {
  std::vector<ObstacleForce> structures;  // as the run's std::vector<ForceChannel>
};

}  // namespace surge
