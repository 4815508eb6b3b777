// The XDMF 3 sidecar that lets ParaView read the particle snapshots straight from the .h5.
#pragma once
#include <string>
#include <vector>

namespace surge {

struct XdmfSnapshot {
  std::string group;  // HDF5 path of the snapshot group, e.g. "/snapshots/000003"
  double time = 0;
  size_t particles = 0;
};

// Writes (atomically: temp file + rename) a temporal collection of polyvertex grids.
// h5_name is the .h5 file name relative to the .xmf (never an absolute path).
void WriteXdmf(const std::string& xmf_path, const std::string& h5_name,
               const std::vector<XdmfSnapshot>& snapshots);

}  // namespace surge
