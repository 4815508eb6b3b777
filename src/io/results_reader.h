// Reading a run's force series back (issue #6, `surge forces`): /forces of <out>/<name>.h5 and
// the scene stored with it (docs/results-format.md). Implemented in hdf5_writer.cpp, the one
// HDF5 includer of the writer side.
#pragma once
#include <string>
#include <vector>

#include "core/math.h"
#include "io/results_writer.h"  // IoError

namespace surge {

// One face of a structure, one row per step.
struct StoredFaceSeries {
  std::string name;
  std::vector<Vec3> force;         // [N] (2-D: N/m)
  std::vector<Real> contact_area;  // [m^2] (2-D: m^2/m)
};

// One structure of /forces, one row per step (row k: the step that ended at time[k]).
struct StoredForceSeries {
  std::string name;
  std::vector<Real> time, dt;       // [s]
  std::vector<Vec3> force;          // [N]
  std::vector<Real> contact_area;   // [m^2]
  std::vector<Real> wetted_height;  // [m]
  std::vector<StoredFaceSeries> faces;  // in the order of the `faces` attribute
};

struct StoredResult {
  std::string path;
  std::string name;           // root attribute `name` (the scene name)
  std::string scene_path;     // root attribute `scene_path`
  std::string scene_text;     // /metadata/scene (the scene file verbatim)
  std::string resolved_yaml;  // /metadata/resolved (after --set, defaults filled in)
  int dimension = 3;
  std::string exit_status;    // /timing attribute; "" if the run did not close the file
  std::vector<StoredForceSeries> structures;  // in the order of /forces `structures`
};

// Reads the metadata and every force series of a results file. Throws IoError naming the path
// when the file is missing or unreadable, is not an HDF5 file, is not a Surge result (no
// /metadata/scene), or its /forces group is malformed. A result without /forces has no
// structures (the scene had none).
StoredResult ReadResultForces(const std::string& h5_path);

}  // namespace surge
