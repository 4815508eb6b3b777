// The only includer of HDF5 (STYLE H.10): run metadata, particle snapshots, energy series.
// The XDMF sidecar is written by xdmf.cpp from the snapshot list kept here.
#include <hdf5.h>

#include <Eigen/Eigenvalues>
#include <array>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <vector>

#include "io/results_writer.h"
#include "io/xdmf.h"

namespace surge {
namespace {

namespace fs = std::filesystem;

// Owns an hid_t and closes it with the matching H5*close.
class Handle {
 public:
  Handle(hid_t id, herr_t (*close)(hid_t)) : id_(id), close_(close) {}
  ~Handle() {
    if (id_ >= 0) close_(id_);
  }
  Handle(const Handle&) = delete;
  Handle& operator=(const Handle&) = delete;
  hid_t get() const { return id_; }
  bool ok() const { return id_ >= 0; }

 private:
  hid_t id_;
  herr_t (*close_)(hid_t);
};

void Require(bool ok, const std::string& what, const std::string& path) {
  if (!ok) throw IoError("HDF5 error: cannot " + what + " in '" + path + "'");
}

void WriteStringAttr(hid_t obj, const char* name, const std::string& value, const std::string& path) {
  Handle type(H5Tcopy(H5T_C_S1), H5Tclose);
  H5Tset_size(type.get(), std::max<size_t>(value.size(), 1));
  H5Tset_strpad(type.get(), H5T_STR_NULLPAD);
  Handle space(H5Screate(H5S_SCALAR), H5Sclose);
  Handle attr(H5Acreate2(obj, name, type.get(), space.get(), H5P_DEFAULT, H5P_DEFAULT), H5Aclose);
  Require(attr.ok(), std::string("create attribute ") + name, path);
  const std::string padded = value.empty() ? std::string(1, '\0') : value;
  Require(H5Awrite(attr.get(), type.get(), padded.data()) >= 0, std::string("write attribute ") + name, path);
}

template <typename T>
void WriteScalarAttr(hid_t obj, const char* name, hid_t type, T value, const std::string& path) {
  Handle space(H5Screate(H5S_SCALAR), H5Sclose);
  Handle attr(H5Acreate2(obj, name, type, space.get(), H5P_DEFAULT, H5P_DEFAULT), H5Aclose);
  Require(attr.ok() && H5Awrite(attr.get(), type, &value) >= 0, std::string("write attribute ") + name, path);
}

void WriteStringDataset(hid_t loc, const char* name, const std::string& value, const std::string& path) {
  Handle type(H5Tcopy(H5T_C_S1), H5Tclose);
  H5Tset_size(type.get(), std::max<size_t>(value.size(), 1));
  H5Tset_strpad(type.get(), H5T_STR_NULLPAD);
  Handle space(H5Screate(H5S_SCALAR), H5Sclose);
  Handle ds(H5Dcreate2(loc, name, type.get(), space.get(), H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT), H5Dclose);
  Require(ds.ok(), std::string("create dataset ") + name, path);
  const std::string padded = value.empty() ? std::string(1, '\0') : value;
  Require(H5Dwrite(ds.get(), type.get(), H5S_ALL, H5S_ALL, H5P_DEFAULT, padded.data()) >= 0,
          std::string("write dataset ") + name, path);
}

// An n x cols dataset (cols = 0: 1-D), chunked and deflated when large.
void WriteArray(hid_t loc, const char* name, hid_t mem_type, hid_t file_type, const void* data,
                size_t n, size_t cols, const std::string& path) {
  hsize_t dims[2] = {hsize_t(n), hsize_t(cols)};
  const int rank = cols == 0 ? 1 : 2;
  Handle space(H5Screate_simple(rank, dims, nullptr), H5Sclose);
  Handle plist(H5Pcreate(H5P_DATASET_CREATE), H5Pclose);
  if (n >= 4096) {
    hsize_t chunk[2] = {std::min<hsize_t>(n, 65536), hsize_t(cols)};
    H5Pset_chunk(plist.get(), rank, chunk);
    H5Pset_deflate(plist.get(), 1);
  }
  Handle ds(H5Dcreate2(loc, name, file_type, space.get(), H5P_DEFAULT, plist.get(), H5P_DEFAULT), H5Dclose);
  Require(ds.ok(), std::string("create dataset ") + name, path);
  if (n > 0)
    Require(H5Dwrite(ds.get(), mem_type, H5S_ALL, H5S_ALL, H5P_DEFAULT, data) >= 0,
            std::string("write dataset ") + name, path);
}

constexpr int kEnergyColumns = 8;
constexpr const char* kEnergyNames[kEnergyColumns] = {
    "time", "step", "dt", "kinetic", "strain", "gravitational", "wall_work", "total"};

}  // namespace

void StrainInvariants(const Mat3& F, Real& volumetric, Real& equivalent) {
  const Real J = F.determinant();
  volumetric = J > 0 ? std::log(J) : std::numeric_limits<Real>::quiet_NaN();
  Eigen::SelfAdjointEigenSolver<Mat3> eig(F * F.transpose());
  const Vec3 lam = eig.eigenvalues();
  Vec3 eps;
  for (int i = 0; i < 3; ++i) eps[i] = 0.5 * std::log(std::max(lam[i], 1e-300));  // Hencky
  const Real mean = eps.sum() / 3.0;
  const Vec3 e = eps - Vec3::Constant(mean);
  equivalent = std::sqrt(2.0 / 3.0 * e.squaredNorm());
}

std::string Hdf5Version() {
  unsigned maj = 0, min = 0, rel = 0;
  H5get_libversion(&maj, &min, &rel);
  return std::to_string(maj) + "." + std::to_string(min) + "." + std::to_string(rel);
}

struct ResultsWriter::Impl {
  std::string name, h5, xmf;
  int dim = 3;
  hid_t file = -1;
  hid_t snapshots = -1;
  hid_t energy = -1;
  std::array<hid_t, kEnergyColumns> energy_sets{};
  hsize_t energy_rows = 0;
  std::vector<EnergyRecord> pending;
  std::vector<XdmfSnapshot> written;
  bool closed = false;

  void FlushEnergy() {
    if (pending.empty()) return;
    const hsize_t add = pending.size();
    std::vector<double> col(add);
    for (int c = 0; c < kEnergyColumns; ++c) {
      for (size_t r = 0; r < add; ++r) {
        const EnergyRecord& e = pending[r];
        const double v[kEnergyColumns] = {e.time,   double(e.step),    e.dt,        e.kinetic,
                                          e.strain, e.gravitational, e.wall_work,
                                          e.kinetic + e.strain + e.gravitational};
        col[r] = v[c];
      }
      const hsize_t new_size = energy_rows + add;
      H5Dset_extent(energy_sets[c], &new_size);
      Handle fspace(H5Dget_space(energy_sets[c]), H5Sclose);
      const hsize_t start = energy_rows;
      H5Sselect_hyperslab(fspace.get(), H5S_SELECT_SET, &start, nullptr, &add, nullptr);
      Handle mspace(H5Screate_simple(1, &add, nullptr), H5Sclose);
      Require(H5Dwrite(energy_sets[c], H5T_NATIVE_DOUBLE, mspace.get(), fspace.get(), H5P_DEFAULT,
                       col.data()) >= 0,
              "append energy rows", h5);
    }
    energy_rows += add;
    pending.clear();
  }

  void CloseHandles() {
    for (hid_t& d : energy_sets)
      if (d > 0) H5Dclose(d), d = -1;
    if (energy > 0) H5Gclose(energy), energy = -1;
    if (snapshots > 0) H5Gclose(snapshots), snapshots = -1;
    if (file > 0) H5Fclose(file), file = -1;
  }
};

ResultsWriter::ResultsWriter(const std::string& out_dir, const std::string& name,
                             const RunMetadata& meta, const Model& model)
    : impl_(std::make_unique<Impl>()) {
  Impl& I = *impl_;
  I.name = name;
  I.dim = model.dim;
  std::error_code ec;
  fs::create_directories(out_dir, ec);
  if (ec || !fs::is_directory(out_dir))
    throw IoError("cannot create results folder '" + out_dir + "': " + (ec ? ec.message() : "not a directory"));
  I.h5 = (fs::path(out_dir) / (name + ".h5")).string();
  I.xmf = (fs::path(out_dir) / (name + ".xmf")).string();
  H5Eset_auto2(H5E_DEFAULT, nullptr, nullptr);  // errors become IoError, not stderr noise
  I.file = H5Fcreate(I.h5.c_str(), H5F_ACC_TRUNC, H5P_DEFAULT, H5P_DEFAULT);
  Require(I.file >= 0, "create the file", I.h5);

  WriteStringAttr(I.file, "name", name, I.h5);
  WriteStringAttr(I.file, "version", meta.version, I.h5);
  WriteStringAttr(I.file, "git_hash", meta.git_hash, I.h5);
  WriteStringAttr(I.file, "command_line", meta.command_line, I.h5);
  WriteStringAttr(I.file, "start_time_utc", meta.start_time_utc, I.h5);
  WriteStringAttr(I.file, "scene_path", meta.scene_path, I.h5);
  WriteScalarAttr(I.file, "threads", H5T_NATIVE_INT, meta.threads, I.h5);
  WriteScalarAttr(I.file, "dimension", H5T_NATIVE_INT, model.dim, I.h5);
  WriteScalarAttr(I.file, "cell_size", H5T_NATIVE_DOUBLE, model.dx, I.h5);
  {
    Handle g(H5Gcreate2(I.file, "metadata", H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT), H5Gclose);
    Require(g.ok(), "create group /metadata", I.h5);
    WriteStringDataset(g.get(), "scene", meta.scene_text, I.h5);
    WriteStringDataset(g.get(), "resolved", meta.resolved_yaml, I.h5);
  }
  I.snapshots = H5Gcreate2(I.file, "snapshots", H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT);
  Require(I.snapshots >= 0, "create group /snapshots", I.h5);
  I.energy = H5Gcreate2(I.file, "energy", H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT);
  Require(I.energy >= 0, "create group /energy", I.h5);
  for (int c = 0; c < kEnergyColumns; ++c) {
    hsize_t zero = 0, unlimited = H5S_UNLIMITED, chunk = 4096;
    Handle space(H5Screate_simple(1, &zero, &unlimited), H5Sclose);
    Handle plist(H5Pcreate(H5P_DATASET_CREATE), H5Pclose);
    H5Pset_chunk(plist.get(), 1, &chunk);
    I.energy_sets[c] = H5Dcreate2(I.energy, kEnergyNames[c], H5T_IEEE_F64LE, space.get(),
                                  H5P_DEFAULT, plist.get(), H5P_DEFAULT);
    Require(I.energy_sets[c] >= 0, std::string("create /energy/") + kEnergyNames[c], I.h5);
  }
  H5Fflush(I.file, H5F_SCOPE_GLOBAL);
}

ResultsWriter::~ResultsWriter() {
  if (!impl_ || impl_->closed) return;
  try {
    impl_->FlushEnergy();
  } catch (...) {
  }
  impl_->CloseHandles();
}

void ResultsWriter::WriteSnapshot(const State& state) {
  Impl& I = *impl_;
  const Particles& P = state.particles;
  const size_t n = P.size();
  char group_name[16];
  std::snprintf(group_name, sizeof group_name, "%06d", int(I.written.size()));
  Handle g(H5Gcreate2(I.snapshots, group_name, H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT), H5Gclose);
  Require(g.ok(), std::string("create snapshot ") + group_name, I.h5);
  WriteScalarAttr(g.get(), "time", H5T_NATIVE_DOUBLE, state.time, I.h5);
  WriteScalarAttr(g.get(), "step", H5T_NATIVE_LLONG, static_cast<long long>(state.step), I.h5);

  std::vector<double> vec(3 * n), stress(6 * n), pressure(n), mises(n), ev(n), eq(n);
  for (size_t p = 0; p < n; ++p)
    for (int d = 0; d < 3; ++d) vec[3 * p + d] = P.x[p][d];
  WriteArray(g.get(), "position", H5T_NATIVE_DOUBLE, H5T_IEEE_F64LE, vec.data(), n, 3, I.h5);
  for (size_t p = 0; p < n; ++p)
    for (int d = 0; d < 3; ++d) vec[3 * p + d] = P.v[p][d];
  WriteArray(g.get(), "velocity", H5T_NATIVE_DOUBLE, H5T_IEEE_F64LE, vec.data(), n, 3, I.h5);
  for (size_t p = 0; p < n; ++p) {
    const Mat3& s = P.stress[p];
    const double voigt[6] = {s(0, 0), s(1, 1), s(2, 2), s(0, 1), s(0, 2), s(1, 2)};
    for (int k = 0; k < 6; ++k) stress[6 * p + k] = voigt[k];
    pressure[p] = -s.trace() / 3.0;  // tension positive, so p > 0 in compression
    const Mat3 dev = Dev(s);
    mises[p] = std::sqrt(1.5 * (dev.array() * dev.array()).sum());
    StrainInvariants(P.F[p], ev[p], eq[p]);
  }
  WriteArray(g.get(), "stress", H5T_NATIVE_DOUBLE, H5T_IEEE_F64LE, stress.data(), n, 6, I.h5);
  WriteArray(g.get(), "pressure", H5T_NATIVE_DOUBLE, H5T_IEEE_F64LE, pressure.data(), n, 0, I.h5);
  WriteArray(g.get(), "von_mises", H5T_NATIVE_DOUBLE, H5T_IEEE_F64LE, mises.data(), n, 0, I.h5);
  WriteArray(g.get(), "strain_volumetric", H5T_NATIVE_DOUBLE, H5T_IEEE_F64LE, ev.data(), n, 0, I.h5);
  WriteArray(g.get(), "strain_equivalent", H5T_NATIVE_DOUBLE, H5T_IEEE_F64LE, eq.data(), n, 0, I.h5);
  WriteArray(g.get(), "material", H5T_NATIVE_INT32, H5T_STD_I32LE, P.material.data(), n, 0, I.h5);
  WriteArray(g.get(), "body", H5T_NATIVE_INT32, H5T_STD_I32LE, P.body.data(), n, 0, I.h5);
  WriteArray(g.get(), "id", H5T_NATIVE_INT64, H5T_STD_I64LE, P.id.data(), n, 0, I.h5);

  I.FlushEnergy();
  Require(H5Fflush(I.file, H5F_SCOPE_GLOBAL) >= 0, "flush", I.h5);
  I.written.push_back(XdmfSnapshot{std::string("/snapshots/") + group_name, state.time, n});
  WriteXdmf(I.xmf, fs::path(I.h5).filename().string(), I.written);
}

void ResultsWriter::AppendEnergy(const EnergyRecord& e) { impl_->pending.push_back(e); }

void ResultsWriter::Close(const StageSeconds& stage_seconds, int64_t steps, double wall_seconds,
                          const std::string& exit_status) {
  Impl& I = *impl_;
  if (I.closed) return;
  I.FlushEnergy();
  {
    Handle g(H5Gcreate2(I.file, "timing", H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT), H5Gclose);
    Require(g.ok(), "create group /timing", I.h5);
    for (int s = 0; s < kStageCount; ++s)
      WriteScalarAttr(g.get(), StageName(Stage(s)), H5T_NATIVE_DOUBLE, stage_seconds[s], I.h5);
    WriteScalarAttr(g.get(), "steps", H5T_NATIVE_LLONG, static_cast<long long>(steps), I.h5);
    WriteScalarAttr(g.get(), "wall_seconds", H5T_NATIVE_DOUBLE, wall_seconds, I.h5);
    WriteStringAttr(g.get(), "exit_status", exit_status, I.h5);
  }
  I.CloseHandles();
  I.closed = true;
}

std::string ResultsWriter::h5_path() const { return impl_->h5; }
std::string ResultsWriter::xmf_path() const { return impl_->xmf; }
int ResultsWriter::snapshot_count() const { return int(impl_->written.size()); }

}  // namespace surge
