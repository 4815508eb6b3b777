// The only includer of HDF5 (STYLE H.10): run metadata, particle snapshots, energy, force and
// rigid-body series and stage timings in <out>/<name>.h5, and the force and rigid-body series
// as CSV. Layout and units:
// docs/results-format.md. The XDMF sidecar is written by xdmf.cpp from the snapshot list kept here.
#include <hdf5.h>
#include <zlib.h>

#include "io/h5_handle.h"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <array>
#include <atomic>
#include <charconv>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <limits>
#include <set>
#include <vector>

#include "core/parallel.h"
#include "io/results_reader.h"
#include "io/results_writer.h"
#include "io/xdmf.h"

namespace surge {
namespace {

namespace fs = std::filesystem;

using Handle = H5Handle;  // io/h5_handle.h

// The innermost message on the HDF5 error stack of the last failed call (it names the cause,
// e.g. "unable to open file: ... errno = 13, error message = 'Permission denied'").
std::string Hdf5ErrorDetail() {
  std::string detail;
  H5Ewalk2(
      H5E_DEFAULT, H5E_WALK_DOWNWARD,
      [](unsigned, const H5E_error2_t* e, void* out) -> herr_t {
        if (e->desc && *e->desc) *static_cast<std::string*>(out) = e->desc;
        return 0;
      },
      &detail);
  return detail;
}

void Require(bool ok, const std::string& what, const std::string& path) {
  if (ok) return;
  const std::string detail = Hdf5ErrorDetail();
  throw IoError("HDF5 error: cannot " + what + " in '" + path + "'" +
                (detail.empty() ? "" : " (" + detail + ")"));
}

// Fixed-length UTF-8 string type of value.size() bytes (at least 1: HDF5 has no empty strings).
hid_t StringType(const std::string& value) {
  const hid_t type = H5Tcopy(H5T_C_S1);
  H5Tset_size(type, std::max<size_t>(value.size(), 1));
  H5Tset_strpad(type, H5T_STR_NULLPAD);
  H5Tset_cset(type, H5T_CSET_UTF8);
  return type;
}

// An attribute of that name is replaced (a restarted run rewrites what Close wrote before).
void DeleteAttrIfAny(hid_t obj, const char* name, const std::string& path) {
  if (H5Aexists(obj, name) > 0)
    Require(H5Adelete(obj, name) >= 0, std::string("replace attribute ") + name, path);
}

void WriteStringAttr(hid_t obj, const char* name, const std::string& value,
                     const std::string& path) {
  DeleteAttrIfAny(obj, name, path);
  Handle type(StringType(value), H5Tclose);
  Handle space(H5Screate(H5S_SCALAR), H5Sclose);
  Handle attr(H5Acreate2(obj, name, type.get(), space.get(), H5P_DEFAULT, H5P_DEFAULT), H5Aclose);
  Require(attr.ok(), std::string("create attribute ") + name, path);
  const std::string padded = value.empty() ? std::string(1, '\0') : value;
  Require(H5Awrite(attr.get(), type.get(), padded.data()) >= 0,
          std::string("write attribute ") + name, path);
}

template <typename T>
void WriteScalarAttr(hid_t obj, const char* name, hid_t type, T value, const std::string& path) {
  DeleteAttrIfAny(obj, name, path);
  Handle space(H5Screate(H5S_SCALAR), H5Sclose);
  Handle attr(H5Acreate2(obj, name, type, space.get(), H5P_DEFAULT, H5P_DEFAULT), H5Aclose);
  Require(attr.ok() && H5Awrite(attr.get(), type, &value) >= 0,
          std::string("write attribute ") + name, path);
}

void WriteStringDataset(hid_t loc, const char* name, const std::string& value,
                        const std::string& path) {
  Handle type(StringType(value), H5Tclose);
  Handle space(H5Screate(H5S_SCALAR), H5Sclose);
  Handle ds(H5Dcreate2(loc, name, type.get(), space.get(), H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT),
            H5Dclose);
  Require(ds.ok(), std::string("create dataset ") + name, path);
  const std::string padded = value.empty() ? std::string(1, '\0') : value;
  Require(H5Dwrite(ds.get(), type.get(), H5S_ALL, H5S_ALL, H5P_DEFAULT, padded.data()) >= 0,
          std::string("write dataset ") + name, path);
}

// Arrays of at least this many rows are chunked and deflated; smaller ones stay contiguous
// (a chunk index and filter pipeline cost more than they save on a few kB).
constexpr size_t kCompressRows = 4096;
// Rows per chunk: 16384 x 6 doubles = 768 KiB, within the default chunk cache (1 MiB), small
// enough that a reader slicing a few particles does not inflate much, and enough chunks for
// every thread to deflate its share (a 98 304-particle snapshot: 6 per array). Deflate's window
// is 32 KiB, so larger chunks would not compress better.
constexpr size_t kChunkRows = 16384;
constexpr int kDeflateLevel = 1;  // the cheapest level

// An n x cols dataset (cols = 0: 1-D). Large arrays are chunked, byte-shuffled and deflated at
// level 1 (HDF5's shuffle and deflate filters, which every HDF5 reader applies). The chunks are
// shuffled and deflated on the worker threads and stored with H5Dwrite_chunk: the byte
// transposition of H5Z_filter_shuffle, then zlib's compress2 (H5Z_filter_deflate), on each
// full-size chunk, the edge chunk padded with the fill value 0, are the bytes the filters
// themselves store. Through the filters one thread did all of it: deflate alone took 0.27 s of
// every flagship snapshot (98 304 particles), 10 % of the whole run on 2 threads. The shuffle
// groups the doubles' sign and exponent bytes: on the flagship's snapshots it made deflate 30 %
// faster and the file 24 % smaller (h5repack; docs/benchmarks.md, twenty-fifth increment).
void WriteArray(hid_t loc, const char* name, hid_t mem_type, hid_t file_type, const void* data,
                size_t n, size_t cols, const std::string& path) {
  const hsize_t dims[2] = {hsize_t(n), hsize_t(cols)};
  const int rank = cols == 0 ? 1 : 2;
  Handle space(H5Screate_simple(rank, dims, nullptr), H5Sclose);
  Handle plist(H5Pcreate(H5P_DATASET_CREATE), H5Pclose);
  const bool chunked = n >= kCompressRows;
  const hsize_t chunk_rows = std::min<hsize_t>(n, kChunkRows);
  if (chunked) {
    const hsize_t chunk[2] = {chunk_rows, hsize_t(cols)};
    H5Pset_chunk(plist.get(), rank, chunk);
    H5Pset_shuffle(plist.get());  // first in the pipeline: shuffle, then deflate
    H5Pset_deflate(plist.get(), kDeflateLevel);
  }
  Handle ds(H5Dcreate2(loc, name, file_type, space.get(), H5P_DEFAULT, plist.get(), H5P_DEFAULT),
            H5Dclose);
  Require(ds.ok(), std::string("create dataset ") + name, path);
  if (n == 0) return;
  // Raw chunks hold the file's bytes: the memory type must be the file type (a little-endian
  // host's native numbers); otherwise HDF5 converts and deflates.
  if (!chunked || H5Tequal(mem_type, file_type) <= 0) {
    Require(H5Dwrite(ds.get(), mem_type, H5S_ALL, H5S_ALL, H5P_DEFAULT, data) >= 0,
            std::string("write dataset ") + name, path);
    return;
  }
  const size_t value_bytes = H5Tget_size(file_type);
  const size_t row_bytes = value_bytes * std::max<size_t>(cols, 1);
  const size_t chunk_bytes = size_t(chunk_rows) * row_bytes, total = n * row_bytes;
  const size_t chunks = (n + size_t(chunk_rows) - 1) / size_t(chunk_rows);
  // In batches of a few chunks per thread, so that the compressed copies held at once stay a
  // few MB however large the array (a 4e6-particle stress array is 192 MB).
  const size_t batch = 4 * std::max<size_t>(WorkerThreads(), 1);
  std::vector<std::vector<Bytef>> packed(std::min(batch, chunks));
  for (size_t first = 0; first < chunks; first += batch) {
    const size_t count_here = std::min(batch, chunks - first);
    std::atomic<bool> failed{false};
    ParallelFor(count_here, 1, [&](size_t k) {
      const size_t c = first + k;
      const size_t begin = c * chunk_bytes, bytes = std::min(chunk_bytes, total - begin);
      const Bytef* src = static_cast<const Bytef*>(data) + begin;
      // Shuffle: byte b of value i goes to b * count + i; the edge chunk's values past n are
      // the fill value 0.
      const size_t count = chunk_bytes / value_bytes, present = bytes / value_bytes;
      std::vector<Bytef> shuffled(chunk_bytes, 0);
      for (size_t i = 0; i < present; ++i)
        for (size_t b = 0; b < value_bytes; ++b) shuffled[b * count + i] = src[i * value_bytes + b];
      uLongf size = compressBound(uLong(chunk_bytes));
      packed[k].resize(size);
      if (compress2(packed[k].data(), &size, shuffled.data(), uLong(chunk_bytes),
                    kDeflateLevel) != Z_OK)
        failed = true;
      packed[k].resize(size);
    });
    Require(!failed, std::string("deflate dataset ") + name, path);
    for (size_t k = 0; k < count_here; ++k) {  // in chunk order
      const hsize_t offset[2] = {hsize_t(first + k) * chunk_rows, 0};
      Require(H5Dwrite_chunk(ds.get(), H5P_DEFAULT, 0, offset, packed[k].size(),
                             packed[k].data()) >= 0,
              std::string("write dataset ") + name, path);
    }
  }
}

constexpr int kEnergyColumns = 9;
constexpr const char* kEnergyNames[kEnergyColumns] = {
    "time", "step", "dt", "kinetic", "strain", "gravitational", "wall_work", "total",
    "internal_work"};
// Buffered energy rows are written (and the file flushed) at each snapshot, on Close, and
// whenever this many have accumulated, so a run with sparse snapshots that is killed keeps
// all but the last few hundred rows.
constexpr size_t kEnergyFlushRows = 1024;
constexpr hsize_t kEnergyChunkRows = 4096;

// File access: metadata-cache evictions off (see "Crash safety" at ResultsWriter::Impl; HDF5
// allows that only with automatic cache resizing off), and H5Fclose refuses to close while an
// object is open, so that Commit really closes the file instead of deferring it.
void ConfigureFileAccess(hid_t fapl, const std::string& path) {
  H5AC_cache_config_t config;
  config.version = H5AC__CURR_CACHE_CONFIG_VERSION;
  Require(fapl >= 0 && H5Pget_mdc_config(fapl, &config) >= 0, "read the cache settings", path);
  config.evictions_enabled = false;
  config.incr_mode = H5C_incr__off;
  config.flash_incr_mode = H5C_flash_incr__off;
  config.decr_mode = H5C_decr__off;
  Require(H5Pset_mdc_config(fapl, &config) >= 0, "configure the metadata cache", path);
  Require(H5Pset_fclose_degree(fapl, H5F_CLOSE_SEMI) >= 0, "set the close degree", path);
}


// --- Force series (/forces, forces_<name>.csv) ---

// Pending force rows are written (HDF5 and CSV, both flushed) once this many have accumulated,
// besides at every snapshot and on Close: a killed run loses at most the last 999 rows.
constexpr size_t kForceFlushRows = 1000;
constexpr hsize_t kForceChunkRows = 4096;  // as the energy columns

// One structure's pending rows, column by column; cleared (capacity kept) after each flush.
struct ForceColumns {
  std::vector<double> time, dt, force, torque, contact_area, wetted_height, max_nodal_force;
  std::vector<int64_t> step, contact_nodes;
  std::vector<std::vector<double>> face_force, face_contact_area;  // [face][row (x 3)]
  std::vector<std::vector<int64_t>> face_contact_nodes;            // [face][row]

  void Resize(size_t faces) {
    face_force.resize(faces);
    face_contact_area.resize(faces);
    face_contact_nodes.resize(faces);
  }
  void Push(Real t, int64_t s, Real step_dt, const ObstacleForce& in) {
    time.push_back(t);
    step.push_back(s);
    dt.push_back(step_dt);
    for (int d = 0; d < 3; ++d) {
      force.push_back(in.force[d]);
      torque.push_back(in.torque[d]);
    }
    contact_area.push_back(in.contact_area);
    wetted_height.push_back(in.wetted_height);
    max_nodal_force.push_back(in.max_nodal_force);
    contact_nodes.push_back(in.contact_nodes);
    for (size_t f = 0; f < in.faces.size(); ++f) {
      for (int d = 0; d < 3; ++d) face_force[f].push_back(in.faces[f].force[d]);
      face_contact_area[f].push_back(in.faces[f].contact_area);
      face_contact_nodes[f].push_back(in.faces[f].contact_nodes);
    }
  }
  void Clear() {
    for (auto* v : {&time, &dt, &force, &torque, &contact_area, &wetted_height, &max_nodal_force})
      v->clear();
    step.clear();
    contact_nodes.clear();
    for (size_t f = 0; f < face_force.size(); ++f) {
      face_force[f].clear();
      face_contact_area[f].clear();
      face_contact_nodes[f].clear();
    }
  }
};

// Structure names become HDF5 link names and file names: [A-Za-z0-9_-]+. Face names become
// link names and CSV column prefixes, and the domain's are x-, x+, ...: [A-Za-z0-9_+-]+.
bool IsSafeName(const std::string& name, bool allow_plus = false) {
  if (name.empty()) return false;
  for (char c : name) {
    const bool ok = (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') ||
                    c == '_' || c == '-' || (allow_plus && c == '+');
    if (!ok) return false;
  }
  return true;
}

std::string Join(const std::vector<std::string>& names) {
  std::string out;
  for (const std::string& n : names) out += (out.empty() ? "" : ",") + n;
  return out;
}

// An empty extendible n x cols dataset (cols = 0: 1-D) with a `units` attribute.
void CreateSeries(hid_t loc, const char* name, hid_t file_type, size_t cols, const char* units,
                  const std::string& path) {
  const int rank = cols == 0 ? 1 : 2;
  const hsize_t zero[2] = {0, hsize_t(cols)};
  const hsize_t max[2] = {H5S_UNLIMITED, hsize_t(cols)};
  const hsize_t chunk[2] = {kForceChunkRows, hsize_t(cols)};
  Handle space(H5Screate_simple(rank, zero, max), H5Sclose);
  Handle plist(H5Pcreate(H5P_DATASET_CREATE), H5Pclose);
  H5Pset_chunk(plist.get(), rank, chunk);
  Handle ds(H5Dcreate2(loc, name, file_type, space.get(), H5P_DEFAULT, plist.get(), H5P_DEFAULT),
            H5Dclose);
  Require(ds.ok(), std::string("create dataset ") + name, path);
  WriteStringAttr(ds.get(), "units", units, path);
}

// Appends `add` rows of data (add x cols values) to an extendible dataset that has `rows` rows.
void AppendSeries(hid_t loc, const char* name, hid_t mem_type, const void* data, hsize_t rows,
                  hsize_t add, size_t cols, const std::string& path) {
  if (add == 0) return;
  Handle ds(H5Dopen2(loc, name, H5P_DEFAULT), H5Dclose);
  Require(ds.ok(), std::string("open dataset ") + name, path);
  const int rank = cols == 0 ? 1 : 2;
  const hsize_t size[2] = {rows + add, hsize_t(cols)};
  Require(H5Dset_extent(ds.get(), size) >= 0, std::string("extend ") + name, path);
  Handle file_space(H5Dget_space(ds.get()), H5Sclose);
  const hsize_t start[2] = {rows, 0}, count[2] = {add, hsize_t(cols)};
  H5Sselect_hyperslab(file_space.get(), H5S_SELECT_SET, start, nullptr, count, nullptr);
  Handle mem_space(H5Screate_simple(rank, count, nullptr), H5Sclose);
  Require(H5Dwrite(ds.get(), mem_type, mem_space.get(), file_space.get(), H5P_DEFAULT, data) >= 0,
          std::string("append rows to ") + name, path);
}

// Cuts an extendible dataset back to its first `rows` rows (a restart discards what the
// interrupted run wrote after its checkpoint). Throws IoError when it has fewer.
void TruncateSeries(hid_t loc, const std::string& name, hsize_t rows, const std::string& path) {
  Handle ds(H5Dopen2(loc, name.c_str(), H5P_DEFAULT), H5Dclose);
  Require(ds.ok(), "open dataset " + name, path);
  Handle space(H5Dget_space(ds.get()), H5Sclose);
  hsize_t dims[2] = {0, 0};
  const int rank = H5Sget_simple_extent_ndims(space.get());
  Require(rank >= 1 && rank <= 2 && H5Sget_simple_extent_dims(space.get(), dims, nullptr) >= 0,
          "read the shape of " + name, path);
  if (dims[0] < rows) {
    throw IoError("'" + path + "': " + name + " has " + std::to_string(dims[0]) +
                  " rows, fewer than the checkpoint's " + std::to_string(rows) +
                  " (the result is not the one the checkpoint was written with)");
  }
  dims[0] = rows;
  Require(H5Dset_extent(ds.get(), dims) >= 0, "truncate " + name, path);
}

// Keeps the header and the first `rows` rows of a CSV series and opens it for appending.
// Throws IoError when the file is missing or has fewer rows.
FILE* TruncateCsv(const std::string& path, int64_t rows) {
  FILE* f = std::fopen(path.c_str(), "rb");
  if (!f) throw IoError("cannot open '" + path + "' to continue it: " + std::strerror(errno));
  int64_t lines = 0;
  long keep = 0;
  for (int c; lines < rows + 1 && (c = std::fgetc(f)) != EOF;) {
    if (c == '\n') {
      ++lines;
      keep = std::ftell(f);
    }
  }
  std::fclose(f);
  if (lines < rows + 1) {
    throw IoError("'" + path + "' has " + std::to_string(std::max<int64_t>(lines - 1, 0)) +
                  " rows, fewer than the checkpoint's " + std::to_string(rows));
  }
  std::error_code ec;
  fs::resize_file(path, uintmax_t(keep), ec);
  if (ec) throw IoError("cannot truncate '" + path + "': " + ec.message());
  f = std::fopen(path.c_str(), "a");
  if (!f) throw IoError("cannot open '" + path + "' to continue it: " + std::strerror(errno));
  return f;
}

void WriteVectorAttr(hid_t obj, const char* name, const Vec3& value, const std::string& path) {
  DeleteAttrIfAny(obj, name, path);
  const hsize_t three = 3;
  Handle space(H5Screate_simple(1, &three, nullptr), H5Sclose);
  Handle attr(H5Acreate2(obj, name, H5T_IEEE_F64LE, space.get(), H5P_DEFAULT, H5P_DEFAULT),
              H5Aclose);
  const double v[3] = {value.x(), value.y(), value.z()};
  Require(attr.ok() && H5Awrite(attr.get(), H5T_NATIVE_DOUBLE, v) >= 0,
          std::string("write attribute ") + name, path);
}

void WritePeakAttrs(hid_t obj, const ForcePeak& p, const std::string& path) {
  WriteScalarAttr(obj, "peak_force", H5T_NATIVE_DOUBLE, p.peak_force, path);
  WriteScalarAttr(obj, "peak_time", H5T_NATIVE_DOUBLE, p.peak_time, path);
  WriteVectorAttr(obj, "force_at_peak", p.force_at_peak, path);
  WriteVectorAttr(obj, "impulse", p.impulse, path);
  WriteScalarAttr(obj, "peak_contact_area", H5T_NATIVE_DOUBLE, p.peak_contact_area, path);
}

// Shortest text that reads back to the same double (std::to_chars), e.g. "0.1", "nan".
void AppendNumber(std::string& line, double v) {
  char buf[32];
  const auto end = std::to_chars(buf, buf + sizeof buf, v).ptr;
  line.append(buf, end);
}
void AppendNumber(std::string& line, int64_t v) {
  char buf[24];
  const auto end = std::to_chars(buf, buf + sizeof buf, v).ptr;
  line.append(buf, end);
}

// --- Rigid-body series (/rigid, rigid_<name>.csv) ---

// Pending rigid rows are flushed like the force rows (kForceFlushRows, on their own count).
constexpr size_t kRigidFlushRows = 1000;

// One body's pending rows, column by column; cleared (capacity kept) after each flush.
struct RigidColumns {
  std::vector<double> time, position, rotation, velocity, angular_velocity;  // x 1, 3, 4, 3, 3
  std::vector<int64_t> step;

  void Push(Real t, int64_t s, const RigidBodyState& b) {
    time.push_back(t);
    step.push_back(s);
    const std::array<Real, 4> q = RotationQuaternion(b.rotation);
    rotation.insert(rotation.end(), q.begin(), q.end());
    for (int d = 0; d < 3; ++d) {
      position.push_back(b.position[d]);
      velocity.push_back(b.velocity[d]);
      angular_velocity.push_back(b.angular_velocity[d]);
    }
  }
  void Clear() {
    for (auto* v : {&time, &position, &rotation, &velocity, &angular_velocity}) v->clear();
    step.clear();
  }
};

}  // namespace

std::array<Real, 4> RotationQuaternion(const Mat3& R) {
  Eigen::Quaternion<Real> q(R);  // Shoemake 1987, as Eigen implements it
  q.normalize();
  const Real sign = q.w() < 0 ? -1 : 1;
  return {sign * q.w(), sign * q.x(), sign * q.y(), sign * q.z()};
}

void StrainInvariants(const Mat3& F, Real& volumetric, Real& equivalent) {
  const Real J = F.determinant();
  volumetric = J > 0 ? std::log(J) : std::numeric_limits<Real>::quiet_NaN();
  // Hencky strain eps = 1/2 ln(b), b = F F^T, from the eigenvalues of b (Bonet & Wood 2008,
  // sec. 3.5). Its trace is ln J, so e = dev(eps) has the same eigenvectors.
  const Eigen::SelfAdjointEigenSolver<Mat3> eig(F * F.transpose(), Eigen::EigenvaluesOnly);
  const Vec3 lambda_sq = eig.eigenvalues();
  Vec3 eps;
  for (int i = 0; i < 3; ++i) {
    eps[i] = lambda_sq[i] > 0 ? 0.5 * std::log(lambda_sq[i])
                              : std::numeric_limits<Real>::quiet_NaN();
  }
  const Vec3 e = eps - Vec3::Constant(eps.sum() / 3.0);
  equivalent = std::sqrt(2.0 / 3.0 * e.squaredNorm());
}

std::string Hdf5Version() {
  unsigned major = 0, minor = 0, release = 0;
  H5get_libversion(&major, &minor, &release);
  return std::to_string(major) + "." + std::to_string(minor) + "." + std::to_string(release);
}

// Crash safety. HDF5 1.10 has no journal: the file on disk is consistent right after H5Fflush,
// but until the next flush two things can break it if the process dies. (1) The metadata cache
// may evict, i.e. write, a dirty entry (a group's grown local heap, say) while the entries that
// point to it are still old on disk. (2) The library may reuse file space freed since the last
// flush (the heap's old block, which the on-disk metadata still points to) for raw data that it
// writes at once. So evictions are off (metadata reaches the disk only in H5Fflush), the file
// space strategy is NONE (freed space is never reused: a few kB lost per snapshot), and after
// each flush the file is closed and reopened, which empties the never-evicting cache and bounds
// its memory by one snapshot's metadata. A kill during the flush or close itself can still leave
// a broken file. Measured with SIGKILL at random moments of a loop of back-to-back 2000-particle
// snapshots (results_writer_test with N=2000): a listed snapshot was unreadable after 11 of 1200
// kills with HDF5's defaults and 5 of 1200 with these settings. In a real run the writer is busy
// a small fraction of the time, and a kill while stepping is harmless.
struct ResultsWriter::Impl {
  std::string h5, xmf;
  hid_t fapl = -1;
  hid_t file = -1;
  hid_t snapshots = -1;
  hid_t energy = -1;
  std::array<hid_t, kEnergyColumns> energy_sets;
  hsize_t energy_rows = 0;
  std::vector<EnergyRecord> pending;
  std::vector<XdmfSnapshot> written;
  // Per-snapshot scratch for one derived field at a time (at most 6 doubles per particle, the
  // stress), kept between snapshots so that writing allocates only on growth.
  std::vector<double> scratch;
  bool closed = false;
  // Force series: pending rows per structure, rows already in the .h5, one CSV per structure.
  std::string out_dir;
  int dim = 3;
  bool forces_begun = false;
  ForceSummary summary{std::vector<ForceChannel>{}};
  std::vector<ForceColumns> force_pending;
  size_t force_pending_rows = 0;
  hsize_t force_rows = 0;
  std::vector<std::string> csv_paths;
  std::vector<FILE*> csv;
  std::string line;  // CSV scratch
  // Rigid-body series: pending rows per body, rows already in the .h5, one CSV per body.
  bool rigid_begun = false;
  std::vector<std::string> rigid_names;
  std::vector<RigidColumns> rigid_pending;
  size_t rigid_pending_rows = 0;
  hsize_t rigid_rows = 0;
  std::vector<std::string> rigid_csv_paths;
  std::vector<FILE*> rigid_csv;
  // A restart (the reopening constructor): BeginForces and BeginRigid truncate and continue.
  bool resuming = false;
  ResultPosition resume;

  Impl() { energy_sets.fill(-1); }
  ~Impl() {
    CloseHandles();
    if (fapl >= 0) H5Pclose(fapl);
    CloseCsv();
  }

  // Appends the pending force rows to /forces/<name>/... (the CSV rows stay pending for
  // WriteForceCsv, which follows the next Commit or file close).
  void WriteForceRows() {
    const hsize_t add = force_pending_rows;
    if (add == 0) return;
    const std::vector<ForceChannel>& channels = summary.channels();
    for (size_t s = 0; s < channels.size(); ++s) {
      const ForceColumns& c = force_pending[s];
      const std::string group = "/forces/" + channels[s].name;
      Handle g(H5Gopen2(file, group.c_str(), H5P_DEFAULT), H5Gclose);
      Require(g.ok(), "open group " + group, h5);
      const auto doubles = [&](hid_t loc, const char* name, const std::vector<double>& v,
                               size_t cols) {
        AppendSeries(loc, name, H5T_NATIVE_DOUBLE, v.data(), force_rows, add, cols, h5);
      };
      const auto integers = [&](hid_t loc, const char* name, const std::vector<int64_t>& v) {
        AppendSeries(loc, name, H5T_NATIVE_INT64, v.data(), force_rows, add, 0, h5);
      };
      doubles(g.get(), "time", c.time, 0);
      integers(g.get(), "step", c.step);
      doubles(g.get(), "dt", c.dt, 0);
      doubles(g.get(), "force", c.force, 3);
      doubles(g.get(), "torque", c.torque, 3);
      doubles(g.get(), "contact_area", c.contact_area, 0);
      doubles(g.get(), "wetted_height", c.wetted_height, 0);
      doubles(g.get(), "max_nodal_force", c.max_nodal_force, 0);
      integers(g.get(), "contact_nodes", c.contact_nodes);
      for (size_t f = 0; f < channels[s].faces.size(); ++f) {
        const std::string face = "faces/" + channels[s].faces[f];
        Handle fg(H5Gopen2(g.get(), face.c_str(), H5P_DEFAULT), H5Gclose);
        Require(fg.ok(), "open group " + group + "/" + face, h5);
        doubles(fg.get(), "force", c.face_force[f], 3);
        doubles(fg.get(), "contact_area", c.face_contact_area[f], 0);
        integers(fg.get(), "contact_nodes", c.face_contact_nodes[f]);
      }
    }
    force_rows += add;
  }

  // Appends the pending rows to the CSV files, flushes them to the OS (a killed process keeps
  // them) and clears the pending rows.
  void WriteForceCsv() {
    if (force_pending_rows == 0) return;
    for (size_t s = 0; s < csv.size(); ++s) {
      const ForceColumns& c = force_pending[s];
      for (size_t r = 0; r < force_pending_rows; ++r) {
        line.clear();
        const auto number = [&](auto v) {
          AppendNumber(line, v);
          line += ',';
        };
        number(c.time[r]);
        number(c.step[r]);
        number(c.dt[r]);
        for (int d = 0; d < 3; ++d) number(c.force[3 * r + d]);
        for (int d = 0; d < 3; ++d) number(c.torque[3 * r + d]);
        number(c.contact_area[r]);
        number(c.wetted_height[r]);
        number(c.max_nodal_force[r]);
        number(c.contact_nodes[r]);
        for (size_t f = 0; f < c.face_force.size(); ++f) {
          for (int d = 0; d < 3; ++d) number(c.face_force[f][3 * r + d]);
          number(c.face_contact_area[f][r]);
          number(c.face_contact_nodes[f][r]);
        }
        line.back() = '\n';
        if (std::fputs(line.c_str(), csv[s]) == EOF)
          throw IoError("cannot write '" + csv_paths[s] + "'");
      }
      if (std::fflush(csv[s]) != 0) throw IoError("cannot write '" + csv_paths[s] + "'");
    }
    for (ForceColumns& c : force_pending) c.Clear();
    force_pending_rows = 0;
  }

  // Appends the pending rigid rows to /rigid/<name>/... (the CSV rows stay pending for
  // WriteRigidCsv, which follows the next Commit or file close).
  void WriteRigidRows() {
    const hsize_t add = rigid_pending_rows;
    if (add == 0) return;
    for (size_t b = 0; b < rigid_names.size(); ++b) {
      const RigidColumns& c = rigid_pending[b];
      const std::string group = "/rigid/" + rigid_names[b];
      Handle g(H5Gopen2(file, group.c_str(), H5P_DEFAULT), H5Gclose);
      Require(g.ok(), "open group " + group, h5);
      const auto doubles = [&](const char* name, const std::vector<double>& v, size_t cols) {
        AppendSeries(g.get(), name, H5T_NATIVE_DOUBLE, v.data(), rigid_rows, add, cols, h5);
      };
      doubles("time", c.time, 0);
      AppendSeries(g.get(), "step", H5T_NATIVE_INT64, c.step.data(), rigid_rows, add, 0, h5);
      doubles("position", c.position, 3);
      doubles("rotation", c.rotation, 4);
      doubles("velocity", c.velocity, 3);
      doubles("angular_velocity", c.angular_velocity, 3);
    }
    rigid_rows += add;
  }

  // Appends the pending rigid rows to the CSV files, flushes them to the OS and clears them.
  void WriteRigidCsv() {
    if (rigid_pending_rows == 0) return;
    for (size_t b = 0; b < rigid_csv.size(); ++b) {
      const RigidColumns& c = rigid_pending[b];
      for (size_t r = 0; r < rigid_pending_rows; ++r) {
        line.clear();
        const auto number = [&](auto v) {
          AppendNumber(line, v);
          line += ',';
        };
        number(c.time[r]);
        number(c.step[r]);
        for (int d = 0; d < 3; ++d) number(c.position[3 * r + d]);
        for (int d = 0; d < 4; ++d) number(c.rotation[4 * r + d]);
        for (int d = 0; d < 3; ++d) number(c.velocity[3 * r + d]);
        for (int d = 0; d < 3; ++d) number(c.angular_velocity[3 * r + d]);
        line.back() = '\n';
        if (std::fputs(line.c_str(), rigid_csv[b]) == EOF)
          throw IoError("cannot write '" + rigid_csv_paths[b] + "'");
      }
      if (std::fflush(rigid_csv[b]) != 0)
        throw IoError("cannot write '" + rigid_csv_paths[b] + "'");
    }
    for (RigidColumns& c : rigid_pending) c.Clear();
    rigid_pending_rows = 0;
  }

  // Never throws.
  void CloseCsv() {
    for (FILE*& f : csv) {
      if (f) std::fclose(f);
      f = nullptr;
    }
    for (FILE*& f : rigid_csv) {
      if (f) std::fclose(f);
      f = nullptr;
    }
  }

  void WriteEnergyRows() {
    if (pending.empty()) return;
    const hsize_t add = pending.size();
    std::vector<double> column(add);
    for (int c = 0; c < kEnergyColumns; ++c) {
      for (size_t r = 0; r < add; ++r) {
        const EnergyRecord& e = pending[r];
        const double row[kEnergyColumns] = {e.time,      double(e.step), e.dt,
                                            e.kinetic,   e.strain,       e.gravitational,
                                            e.wall_work, e.kinetic + e.strain + e.gravitational,
                                            e.internal_work};
        column[r] = row[c];
      }
      const hsize_t new_size = energy_rows + add;
      Require(H5Dset_extent(energy_sets[c], &new_size) >= 0, "extend the energy series", h5);
      Handle file_space(H5Dget_space(energy_sets[c]), H5Sclose);
      const hsize_t start = energy_rows;
      H5Sselect_hyperslab(file_space.get(), H5S_SELECT_SET, &start, nullptr, &add, nullptr);
      Handle mem_space(H5Screate_simple(1, &add, nullptr), H5Sclose);
      Require(H5Dwrite(energy_sets[c], H5T_NATIVE_DOUBLE, mem_space.get(), file_space.get(),
                       H5P_DEFAULT, column.data()) >= 0,
              "append energy rows", h5);
    }
    energy_rows += add;
    pending.clear();
  }

  // Opens the groups and energy datasets that the writer keeps open.
  void OpenHandles() {
    snapshots = H5Gopen2(file, "snapshots", H5P_DEFAULT);
    Require(snapshots >= 0, "open group /snapshots", h5);
    energy = H5Gopen2(file, "energy", H5P_DEFAULT);
    Require(energy >= 0, "open group /energy", h5);
    for (int c = 0; c < kEnergyColumns; ++c) {
      energy_sets[c] = H5Dopen2(energy, kEnergyNames[c], H5P_DEFAULT);
      Require(energy_sets[c] >= 0, std::string("open /energy/") + kEnergyNames[c], h5);
    }
  }

  // Puts everything written so far on disk, then closes and reopens the file (see above).
  void Commit() {
    Require(H5Fflush(file, H5F_SCOPE_GLOBAL) >= 0, "flush the file", h5);
    const hid_t closing = file;
    file = -1;
    CloseHandles();
    Require(H5Fclose(closing) >= 0, "close the file", h5);
    file = H5Fopen(h5.c_str(), H5F_ACC_RDWR, fapl);
    Require(file >= 0, "reopen the file", h5);
    OpenHandles();
  }

  // Never throws: used by the destructors.
  void CloseHandles() {
    for (hid_t& d : energy_sets) {
      if (d >= 0) H5Dclose(d);
      d = -1;
    }
    if (energy >= 0) H5Gclose(energy);
    if (snapshots >= 0) H5Gclose(snapshots);
    if (file >= 0) H5Fclose(file);
    energy = snapshots = file = -1;
  }
};

ResultsWriter::ResultsWriter(const std::string& out_dir, const std::string& name,
                             const RunMetadata& meta, const Model& model)
    : impl_(std::make_unique<Impl>()) {
  Impl& I = *impl_;
  if (!IsSafeName(name))
    throw IoError("result name '" + name + "' is empty or not [A-Za-z0-9_-]+ (it names files in '" +
                  out_dir + "')");
  std::error_code ec;
  fs::create_directories(out_dir, ec);
  if (ec || !fs::is_directory(out_dir)) {
    throw IoError("cannot create results folder '" + out_dir +
                  "': " + (ec ? ec.message() : "not a directory"));
  }
  I.out_dir = out_dir;
  I.dim = model.dim;
  I.h5 = (fs::path(out_dir) / (name + ".h5")).string();
  I.xmf = (fs::path(out_dir) / (name + ".xmf")).string();
  // Failures become IoError with the HDF5 message (Hdf5ErrorDetail), not a stack dump on
  // stderr. This is process-wide for the default error stack.
  H5Eset_auto2(H5E_DEFAULT, nullptr, nullptr);
  Handle fcpl(H5Pcreate(H5P_FILE_CREATE), H5Pclose);
  Require(H5Pset_file_space_strategy(fcpl.get(), H5F_FSPACE_STRATEGY_NONE, 0, 1) >= 0,
          "set the file space strategy", I.h5);
  I.fapl = H5Pcreate(H5P_FILE_ACCESS);
  ConfigureFileAccess(I.fapl, I.h5);
  // A run over an old result (--force) truncates its .h5: the old .xmf goes first, so that a
  // kill before the first snapshot never leaves an .xmf listing snapshots the new file lacks
  // (kill9_test).
  if (fs::remove(I.xmf, ec); ec) throw IoError("cannot remove the old '" + I.xmf + "': " + ec.message());
  I.file = H5Fcreate(I.h5.c_str(), H5F_ACC_TRUNC, fcpl.get(), I.fapl);
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
  {
    Handle g(H5Gcreate2(I.file, "snapshots", H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT), H5Gclose);
    Require(g.ok(), "create group /snapshots", I.h5);
  }
  {
    Handle energy(H5Gcreate2(I.file, "energy", H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT), H5Gclose);
    Require(energy.ok(), "create group /energy", I.h5);
    for (int c = 0; c < kEnergyColumns; ++c) {
      const hsize_t zero = 0, unlimited = H5S_UNLIMITED;
      Handle space(H5Screate_simple(1, &zero, &unlimited), H5Sclose);
      Handle plist(H5Pcreate(H5P_DATASET_CREATE), H5Pclose);
      H5Pset_chunk(plist.get(), 1, &kEnergyChunkRows);
      Handle ds(H5Dcreate2(energy.get(), kEnergyNames[c], H5T_IEEE_F64LE, space.get(), H5P_DEFAULT,
                           plist.get(), H5P_DEFAULT),
                H5Dclose);
      Require(ds.ok(), std::string("create /energy/") + kEnergyNames[c], I.h5);
    }
  }
  I.OpenHandles();
  I.Commit();
}

ResultsWriter::ResultsWriter(const std::string& out_dir, const std::string& name,
                             const Model& model, const ResultPosition& resume)
    : impl_(std::make_unique<Impl>()) {
  Impl& I = *impl_;
  if (!IsSafeName(name))
    throw IoError("result name '" + name + "' is empty or not [A-Za-z0-9_-]+ (it names files in '" +
                  out_dir + "')");
  I.out_dir = out_dir;
  I.dim = model.dim;
  I.h5 = (fs::path(out_dir) / (name + ".h5")).string();
  I.xmf = (fs::path(out_dir) / (name + ".xmf")).string();
  I.resuming = true;
  I.resume = resume;
  H5Eset_auto2(H5E_DEFAULT, nullptr, nullptr);
  std::error_code ec;
  if (!fs::is_regular_file(I.h5, ec) || H5Fis_hdf5(I.h5.c_str()) <= 0) {
    throw IoError("cannot continue '" + I.h5 +
                  "': no such HDF5 file (a restart continues the result in the results folder the "
                  "checkpoint was written for; give it with --out)");
  }
  I.fapl = H5Pcreate(H5P_FILE_ACCESS);
  ConfigureFileAccess(I.fapl, I.h5);
  I.file = H5Fopen(I.h5.c_str(), H5F_ACC_RDWR, I.fapl);
  Require(I.file >= 0, "open the file to continue it", I.h5);
  if (H5Lexists(I.file, "metadata", H5P_DEFAULT) <= 0 ||
      H5Lexists(I.file, "snapshots", H5P_DEFAULT) <= 0 ||
      H5Lexists(I.file, "energy", H5P_DEFAULT) <= 0) {
    throw IoError("cannot continue '" + I.h5 + "': not a Surge result");
  }
  // Close writes /timing; the continued run writes it again at its end.
  if (H5Lexists(I.file, "timing", H5P_DEFAULT) > 0)
    Require(H5Ldelete(I.file, "timing", H5P_DEFAULT) >= 0, "remove /timing", I.h5);
  I.OpenHandles();
  // Snapshots 000000, 000001, ... : the checkpoint's first `snapshots` stay (and are listed in
  // the .xmf again), later ones are unlinked (their space is not reused: file space strategy
  // NONE, see "Crash safety").
  for (int k = 0;; ++k) {
    char sn[16];
    std::snprintf(sn, sizeof sn, "%06d", k);
    if (H5Lexists(I.snapshots, sn, H5P_DEFAULT) <= 0) break;
    if (k >= resume.snapshots) {
      Require(H5Ldelete(I.snapshots, sn, H5P_DEFAULT) >= 0, std::string("remove snapshot ") + sn,
              I.h5);
      continue;
    }
    Handle g(H5Gopen2(I.snapshots, sn, H5P_DEFAULT), H5Gclose);
    Require(g.ok(), std::string("open snapshot ") + sn, I.h5);
    double time = 0;
    Handle attr(H5Aopen(g.get(), "time", H5P_DEFAULT), H5Aclose);
    Require(attr.ok() && H5Aread(attr.get(), H5T_NATIVE_DOUBLE, &time) >= 0,
            std::string("read the time of snapshot ") + sn, I.h5);
    Handle ds(H5Dopen2(g.get(), "position", H5P_DEFAULT), H5Dclose);
    Require(ds.ok(), std::string("open snapshot ") + sn + "/position", I.h5);
    Handle space(H5Dget_space(ds.get()), H5Sclose);
    hsize_t dims[2] = {0, 0};
    Require(H5Sget_simple_extent_dims(space.get(), dims, nullptr) >= 0,
            std::string("read snapshot ") + sn + "/position", I.h5);
    I.written.push_back(XdmfSnapshot{std::string("/snapshots/") + sn, time, size_t(dims[0])});
  }
  if (int(I.written.size()) != resume.snapshots) {
    throw IoError("cannot continue '" + I.h5 + "': it has " + std::to_string(I.written.size()) +
                  " snapshots, fewer than the checkpoint's " + std::to_string(resume.snapshots));
  }
  for (int c = 0; c < kEnergyColumns; ++c)
    TruncateSeries(I.energy, kEnergyNames[c], hsize_t(resume.energy_rows), I.h5);
  I.energy_rows = hsize_t(resume.energy_rows);
  // The .xmf lists only the kept snapshots before the commit removes the later ones from the
  // disk: the kept ones are there before and after, so a kill at any point finds it consistent.
  WriteXdmf(I.xmf, fs::path(I.h5).filename().string(), I.written);
  I.Commit();
}

ResultPosition ResultsWriter::Flush() {
  Impl& I = *impl_;
  if (I.closed) throw IoError("Flush after Close on '" + I.h5 + "'");
  I.WriteEnergyRows();
  I.WriteForceRows();
  I.WriteRigidRows();
  I.Commit();
  I.WriteForceCsv();
  I.WriteRigidCsv();
  ResultPosition p;
  p.snapshots = int(I.written.size());
  p.energy_rows = int64_t(I.energy_rows);
  p.force_rows = int64_t(I.force_rows);
  p.rigid_rows = int64_t(I.rigid_rows);
  if (I.forces_begun) {
    for (size_t s = 0; s < I.summary.size(); ++s) p.force_peaks.push_back(I.summary.structure(s));
    p.force_samples = I.summary.samples();
  }
  return p;
}

ResultsWriter::~ResultsWriter() {
  if (!impl_ || impl_->closed) return;
  try {
    impl_->WriteEnergyRows();
    impl_->WriteForceRows();
    impl_->WriteRigidRows();
  } catch (...) {
    // A destructor must not throw; the rows written so far stay in the file.
  }
  impl_->CloseHandles();
  try {
    impl_->WriteForceCsv();
  } catch (...) {
  }
  try {
    impl_->WriteRigidCsv();
  } catch (...) {
  }
  impl_->CloseCsv();
}

void ResultsWriter::WriteSnapshot(const State& state) {
  Impl& I = *impl_;
  if (I.closed) throw IoError("WriteSnapshot after Close on '" + I.h5 + "'");
  const Particles& P = state.particles;
  const size_t n = P.size();
  char name[16];
  std::snprintf(name, sizeof name, "%06d", int(I.written.size()));
  {  // the group is closed before Commit closes the file
    Handle g(H5Gcreate2(I.snapshots, name, H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT), H5Gclose);
    Require(g.ok(), std::string("create snapshot ") + name, I.h5);
    WriteScalarAttr(g.get(), "time", H5T_NATIVE_DOUBLE, state.time, I.h5);
    WriteScalarAttr(g.get(), "step", H5T_NATIVE_INT64, int64_t{state.step}, I.h5);
    const auto write_doubles = [&](const char* dataset, const double* v, size_t cols) {
      WriteArray(g.get(), dataset, H5T_NATIVE_DOUBLE, H5T_IEEE_F64LE, v, n, cols, I.h5);
    };
    // A derived field of `cols` doubles per particle (0: a scalar), filled into the scratch by
    // fill(p, out) and written. Independent per particle: the output does not depend on threads.
    const auto write_derived = [&](const char* dataset, size_t cols, auto fill) {
      const size_t stride = std::max<size_t>(cols, 1);
      I.scratch.resize(stride * n);
      double* out = I.scratch.data();
      ParallelFor(n, 4096, [&](size_t p) { fill(p, out + stride * p); });
      write_doubles(dataset, out, cols);
    };
    static_assert(sizeof(Vec3) == 3 * sizeof(double), "x and v are written as n x 3 doubles");
    write_doubles("position", n ? P.x[0].data() : nullptr, 3);
    write_doubles("velocity", n ? P.v[0].data() : nullptr, 3);
    write_derived("stress", 6, [&](size_t p, double* out) {
      // VTK/ParaView order xx yy zz xy yz xz (SymMat3's own), so ParaView's labels are right.
      std::copy(P.stress[p].v, P.stress[p].v + 6, out);
    });
    write_derived("pressure", 0, [&](size_t p, double* out) {
      *out = -P.stress[p].trace() / 3.0;  // > 0 in compression
    });
    write_derived("von_mises", 0, [&](size_t p, double* out) {
      *out = std::sqrt(1.5 * Dev(P.stress[p].matrix()).squaredNorm());  // q = sqrt(3/2 s:s)
    });
    {  // both strain invariants from one eigen-solve per particle: two halves of the scratch
      I.scratch.resize(2 * n);
      double* volumetric = I.scratch.data();
      double* equivalent = volumetric + n;
      ParallelFor(n, 4096,
                  [&](size_t p) { StrainInvariants(P.F[p], volumetric[p], equivalent[p]); });
      write_doubles("strain_volumetric", volumetric, 0);
      write_doubles("strain_equivalent", equivalent, 0);
    }
    WriteArray(g.get(), "material", H5T_NATIVE_INT32, H5T_STD_I32LE, P.material.data(), n, 0, I.h5);
    WriteArray(g.get(), "body", H5T_NATIVE_INT32, H5T_STD_I32LE, P.body.data(), n, 0, I.h5);
    WriteArray(g.get(), "id", H5T_NATIVE_INT64, H5T_STD_I64LE, P.id.data(), n, 0, I.h5);
    // 0 for elastic and fluid models (no history array when the run has no plastic model)
    write_derived("plastic_strain", 0, [&](size_t p, double* out) {
      *out = P.layout.history ? P.history[p][kPlasticStrainSlot] : 0.0;
    });
  }
  I.WriteEnergyRows();
  I.WriteForceRows();
  I.WriteRigidRows();
  I.Commit();
  I.WriteForceCsv();
  I.WriteRigidCsv();
  // The .xmf lists a snapshot only once it is on disk.
  I.written.push_back(XdmfSnapshot{std::string("/snapshots/") + name, state.time, n});
  WriteXdmf(I.xmf, fs::path(I.h5).filename().string(), I.written);
}

void ResultsWriter::AppendEnergy(const EnergyRecord& e) {
  Impl& I = *impl_;
  if (I.closed) throw IoError("AppendEnergy after Close on '" + I.h5 + "'");
  I.pending.push_back(e);
  if (I.pending.size() >= kEnergyFlushRows) {
    I.WriteEnergyRows();
    I.Commit();
  }
}

void ResultsWriter::BeginForces(const std::vector<ForceChannel>& channels) {
  Impl& I = *impl_;
  if (I.closed) throw IoError("BeginForces after Close on '" + I.h5 + "'");
  if (I.forces_begun) throw IoError("BeginForces called twice on '" + I.h5 + "'");
  std::set<std::string> names;
  for (const ForceChannel& c : channels) {
    if (!IsSafeName(c.name) || !names.insert(c.name).second)
      throw IoError("force channel name '" + c.name + "' is empty, repeated or not [A-Za-z0-9_-]+");
    std::set<std::string> faces;
    for (const std::string& f : c.faces) {
      if (!IsSafeName(f, /*allow_plus=*/true) || !faces.insert(f).second)
        throw IoError("face name '" + f + "' of '" + c.name +
                      "' is empty, repeated or not [A-Za-z0-9_+-]+");
    }
  }
  I.forces_begun = true;
  I.summary = ForceSummary(channels);
  I.force_pending.assign(channels.size(), ForceColumns{});
  for (size_t s = 0; s < channels.size(); ++s) I.force_pending[s].Resize(channels[s].faces.size());

  // 2-D values are per metre of thickness (the units say so; the CSV headers keep the 3-D names).
  const bool plane = I.dim == 2;
  const char* force_units = plane ? "N/m" : "N";
  const char* torque_units = plane ? "N m/m" : "N m";
  const char* area_units = plane ? "m^2/m" : "m^2";
  if (I.resuming) {  // a restart: the series exist; cut them back to the checkpoint's rows
    const hsize_t rows = hsize_t(I.resume.force_rows);
    Handle forces(H5Gopen2(I.file, "forces", H5P_DEFAULT), H5Gclose);
    Require(forces.ok(), "open group /forces", I.h5);
    for (const ForceChannel& c : channels) {
      Handle g(H5Gopen2(forces.get(), c.name.c_str(), H5P_DEFAULT), H5Gclose);
      Require(g.ok(), "open group /forces/" + c.name, I.h5);
      for (const char* series : {"time", "step", "dt", "force", "torque", "contact_area",
                                 "wetted_height", "max_nodal_force", "contact_nodes"})
        TruncateSeries(g.get(), series, rows, I.h5);
      for (const std::string& f : c.faces) {
        for (const char* series : {"force", "contact_area", "contact_nodes"})
          TruncateSeries(g.get(), "faces/" + f + "/" + series, rows, I.h5);
      }
    }
    I.force_rows = rows;
    I.summary.Restore(I.resume.force_peaks, I.resume.force_samples);
  } else {  // groups are closed before Commit closes the file
    Handle forces(H5Gcreate2(I.file, "forces", H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT), H5Gclose);
    Require(forces.ok(), "create group /forces", I.h5);
    std::vector<std::string> all;
    for (const ForceChannel& c : channels) all.push_back(c.name);
    WriteStringAttr(forces.get(), "structures", Join(all), I.h5);
    for (const ForceChannel& c : channels) {
      Handle g(H5Gcreate2(forces.get(), c.name.c_str(), H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT),
               H5Gclose);
      Require(g.ok(), "create group /forces/" + c.name, I.h5);
      WriteStringAttr(g.get(), "faces", Join(c.faces), I.h5);
      CreateSeries(g.get(), "time", H5T_IEEE_F64LE, 0, "s", I.h5);
      CreateSeries(g.get(), "step", H5T_STD_I64LE, 0, "-", I.h5);
      CreateSeries(g.get(), "dt", H5T_IEEE_F64LE, 0, "s", I.h5);
      CreateSeries(g.get(), "force", H5T_IEEE_F64LE, 3, force_units, I.h5);
      CreateSeries(g.get(), "torque", H5T_IEEE_F64LE, 3, torque_units, I.h5);
      CreateSeries(g.get(), "contact_area", H5T_IEEE_F64LE, 0, area_units, I.h5);
      CreateSeries(g.get(), "wetted_height", H5T_IEEE_F64LE, 0, "m", I.h5);
      CreateSeries(g.get(), "max_nodal_force", H5T_IEEE_F64LE, 0, force_units, I.h5);
      CreateSeries(g.get(), "contact_nodes", H5T_STD_I64LE, 0, "-", I.h5);
      Handle faces(H5Gcreate2(g.get(), "faces", H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT), H5Gclose);
      Require(faces.ok(), "create group /forces/" + c.name + "/faces", I.h5);
      for (const std::string& f : c.faces) {
        Handle fg(H5Gcreate2(faces.get(), f.c_str(), H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT),
                  H5Gclose);
        Require(fg.ok(), "create group /forces/" + c.name + "/faces/" + f, I.h5);
        CreateSeries(fg.get(), "force", H5T_IEEE_F64LE, 3, force_units, I.h5);
        CreateSeries(fg.get(), "contact_area", H5T_IEEE_F64LE, 0, area_units, I.h5);
        CreateSeries(fg.get(), "contact_nodes", H5T_STD_I64LE, 0, "-", I.h5);
      }
    }
  }
  I.Commit();

  for (const ForceChannel& c : channels) {
    const std::string path = forces_csv_path(c.name);
    if (I.resuming) {
      I.csv.push_back(TruncateCsv(path, I.resume.force_rows));
      I.csv_paths.push_back(path);
      continue;
    }
    FILE* f = std::fopen(path.c_str(), "w");
    if (!f) throw IoError("cannot create '" + path + "': " + std::strerror(errno));
    I.csv.push_back(f);
    I.csv_paths.push_back(path);
    std::string header =
        "time_s,step,dt_s,fx_N,fy_N,fz_N,tx_Nm,ty_Nm,tz_Nm,contact_area_m2,wetted_height_m,"
        "max_nodal_force_N,contact_nodes";
    for (const std::string& face : c.faces) {
      for (const char* column :
           {"_fx_N", "_fy_N", "_fz_N", "_contact_area_m2", "_contact_nodes"})
        header += "," + face + column;
    }
    header += '\n';
    if (std::fputs(header.c_str(), f) == EOF || std::fflush(f) != 0)
      throw IoError("cannot write '" + path + "'");
  }
}

void ResultsWriter::AppendForces(Real time, int64_t step, Real dt, const ContactReport& report) {
  Impl& I = *impl_;
  if (I.closed) throw IoError("AppendForces after Close on '" + I.h5 + "'");
  if (!I.forces_begun) {
    if (report.structures.empty()) return;  // nothing to log, BeginForces may be skipped
    throw IoError("AppendForces before BeginForces on '" + I.h5 + "'");
  }
  I.summary.Add(time, dt, report);  // checks the report's shape first
  for (size_t s = 0; s < report.structures.size(); ++s)
    I.force_pending[s].Push(time, step, dt, report.structures[s]);
  ++I.force_pending_rows;
  if (I.force_pending_rows >= kForceFlushRows) {
    I.WriteForceRows();
    I.Commit();
    I.WriteForceCsv();
  }
}

void ResultsWriter::BeginRigid(const std::vector<std::string>& names) {
  Impl& I = *impl_;
  if (I.closed) throw IoError("BeginRigid after Close on '" + I.h5 + "'");
  if (I.rigid_begun) throw IoError("BeginRigid called twice on '" + I.h5 + "'");
  std::set<std::string> seen;
  for (const std::string& name : names) {
    if (!IsSafeName(name) || !seen.insert(name).second)
      throw IoError("rigid body name '" + name + "' is empty, repeated or not [A-Za-z0-9_-]+");
  }
  I.rigid_begun = true;
  I.rigid_names = names;
  I.rigid_pending.assign(names.size(), RigidColumns{});
  if (I.resuming) {  // a restart: the series exist; cut them back to the checkpoint's rows
    const hsize_t rows = hsize_t(I.resume.rigid_rows);
    for (const std::string& name : names) {
      const std::string group = "/rigid/" + name;
      Handle g(H5Gopen2(I.file, group.c_str(), H5P_DEFAULT), H5Gclose);
      Require(g.ok(), "open group " + group, I.h5);
      for (const char* series :
           {"time", "step", "position", "rotation", "velocity", "angular_velocity"})
        TruncateSeries(g.get(), series, rows, I.h5);
    }
    I.rigid_rows = rows;
  } else {  // groups are closed before Commit closes the file
    Handle rigid(H5Gcreate2(I.file, "rigid", H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT), H5Gclose);
    Require(rigid.ok(), "create group /rigid", I.h5);
    WriteStringAttr(rigid.get(), "bodies", Join(names), I.h5);
    for (const std::string& name : names) {
      Handle g(H5Gcreate2(rigid.get(), name.c_str(), H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT),
               H5Gclose);
      Require(g.ok(), "create group /rigid/" + name, I.h5);
      CreateSeries(g.get(), "time", H5T_IEEE_F64LE, 0, "s", I.h5);
      CreateSeries(g.get(), "step", H5T_STD_I64LE, 0, "-", I.h5);
      CreateSeries(g.get(), "position", H5T_IEEE_F64LE, 3, "m", I.h5);
      CreateSeries(g.get(), "rotation", H5T_IEEE_F64LE, 4, "-", I.h5);
      CreateSeries(g.get(), "velocity", H5T_IEEE_F64LE, 3, "m/s", I.h5);
      CreateSeries(g.get(), "angular_velocity", H5T_IEEE_F64LE, 3, "rad/s", I.h5);
    }
  }
  I.Commit();

  for (const std::string& name : names) {
    const std::string path = rigid_csv_path(name);
    if (I.resuming) {
      I.rigid_csv.push_back(TruncateCsv(path, I.resume.rigid_rows));
      I.rigid_csv_paths.push_back(path);
      continue;
    }
    FILE* f = std::fopen(path.c_str(), "w");
    if (!f) throw IoError("cannot create '" + path + "': " + std::strerror(errno));
    I.rigid_csv.push_back(f);
    I.rigid_csv_paths.push_back(path);
    const char* header =
        "time_s,step,x_m,y_m,z_m,qw,qx,qy,qz,vx_m_s,vy_m_s,vz_m_s,wx_rad_s,wy_rad_s,wz_rad_s\n";
    if (std::fputs(header, f) == EOF || std::fflush(f) != 0)
      throw IoError("cannot write '" + path + "'");
  }
}

void ResultsWriter::AppendRigid(Real time, int64_t step,
                                const std::vector<RigidBodyState>& bodies) {
  Impl& I = *impl_;
  if (I.closed) throw IoError("AppendRigid after Close on '" + I.h5 + "'");
  if (!I.rigid_begun) {
    if (bodies.empty()) return;  // nothing to log, BeginRigid may be skipped
    throw IoError("AppendRigid before BeginRigid on '" + I.h5 + "'");
  }
  if (bodies.size() != I.rigid_names.size())
    throw std::logic_error("AppendRigid: " + std::to_string(bodies.size()) + " bodies, " +
                           std::to_string(I.rigid_names.size()) + " names");
  for (size_t b = 0; b < bodies.size(); ++b) I.rigid_pending[b].Push(time, step, bodies[b]);
  ++I.rigid_pending_rows;
  if (I.rigid_pending_rows >= kRigidFlushRows) {
    I.WriteRigidRows();
    I.Commit();
    I.WriteRigidCsv();
  }
}

void ResultsWriter::Close(const StageSeconds& stage_seconds, int64_t steps, double wall_seconds,
                          const std::string& exit_status) {
  Impl& I = *impl_;
  if (I.closed) return;
  I.WriteEnergyRows();
  I.WriteForceRows();
  I.WriteRigidRows();
  if (I.forces_begun) {  // the peak/impulse summary as attributes of the force groups
    const std::vector<ForceChannel>& channels = I.summary.channels();
    for (size_t s = 0; s < channels.size(); ++s) {
      const std::string group = "/forces/" + channels[s].name;
      Handle g(H5Gopen2(I.file, group.c_str(), H5P_DEFAULT), H5Gclose);
      Require(g.ok(), "open group " + group, I.h5);
      const StructurePeak& peak = I.summary.structure(s);
      WritePeakAttrs(g.get(), peak, I.h5);
      WriteScalarAttr(g.get(), "peak_wetted_height", H5T_NATIVE_DOUBLE, peak.peak_wetted_height,
                      I.h5);
      for (size_t f = 0; f < channels[s].faces.size(); ++f) {
        const std::string face = "faces/" + channels[s].faces[f];
        Handle fg(H5Gopen2(g.get(), face.c_str(), H5P_DEFAULT), H5Gclose);
        Require(fg.ok(), "open group " + group + "/" + face, I.h5);
        WritePeakAttrs(fg.get(), peak.faces[f], I.h5);
      }
    }
  }
  {
    Handle g(H5Gcreate2(I.file, "timing", H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT), H5Gclose);
    Require(g.ok(), "create group /timing", I.h5);
    for (int s = 0; s < kStageCount; ++s)
      WriteScalarAttr(g.get(), StageName(Stage(s)), H5T_NATIVE_DOUBLE, stage_seconds[s], I.h5);
    WriteScalarAttr(g.get(), "steps", H5T_NATIVE_INT64, steps, I.h5);
    WriteScalarAttr(g.get(), "wall_seconds", H5T_NATIVE_DOUBLE, wall_seconds, I.h5);
    WriteStringAttr(g.get(), "exit_status", exit_status, I.h5);
  }
  I.closed = true;
  I.CloseHandles();
  I.WriteForceCsv();
  I.WriteRigidCsv();
  I.CloseCsv();
}

std::string ResultsWriter::h5_path() const { return impl_->h5; }
std::string ResultsWriter::xmf_path() const { return impl_->xmf; }
int ResultsWriter::snapshot_count() const { return int(impl_->written.size()); }
std::string ResultsWriter::forces_csv_path(const std::string& structure) const {
  return (fs::path(impl_->out_dir) / ("forces_" + structure + ".csv")).string();
}
std::string ResultsWriter::rigid_csv_path(const std::string& body) const {
  return (fs::path(impl_->out_dir) / ("rigid_" + body + ".csv")).string();
}
const ForceSummary& ResultsWriter::force_summary() const { return impl_->summary; }

// --- Reading the force series back (results_reader.h) --------------------------------------

namespace {

// A string attribute or scalar string dataset: fixed-length (as written here) or variable.
std::string ReadString(hid_t obj, bool dataset, const std::string& what, const std::string& path) {
  Handle type(dataset ? H5Dget_type(obj) : H5Aget_type(obj), H5Tclose);
  Require(type.ok() && H5Tget_class(type.get()) == H5T_STRING, "read string " + what, path);
  // Exactly one string: the read writes every element of the dataspace (a list of strings would
  // overflow `s` or `out`).
  Require(H5ElementCount(obj, dataset) == 1, "read string " + what + " (not one string)", path);
  if (H5Tis_variable_str(type.get()) > 0) {
    Handle mem(H5Tcopy(H5T_C_S1), H5Tclose);
    H5Tset_size(mem.get(), H5T_VARIABLE);
    char* s = nullptr;
    const herr_t rc = dataset ? H5Dread(obj, mem.get(), H5S_ALL, H5S_ALL, H5P_DEFAULT, &s)
                              : H5Aread(obj, mem.get(), &s);
    Require(rc >= 0, "read string " + what, path);
    std::string out = s ? s : "";
    H5free_memory(s);
    return out;
  }
  // Fixed length: read in the stored type itself (UTF-8 to ASCII has no conversion path).
  const size_t size = H5Tget_size(type.get());
  Require(size > 0 && size <= kH5MaxStringBytes, "read string " + what + " (corrupt length)", path);
  std::string out(size, '\0');
  const herr_t rc = dataset ? H5Dread(obj, type.get(), H5S_ALL, H5S_ALL, H5P_DEFAULT, out.data())
                            : H5Aread(obj, type.get(), out.data());
  Require(rc >= 0, "read string " + what, path);
  out.resize(std::strlen(out.c_str()));
  return out;
}

std::string ReadStringAttr(hid_t obj, const char* name, const std::string& path) {
  Handle attr(H5Aopen(obj, name, H5P_DEFAULT), H5Aclose);
  Require(attr.ok(), std::string("open attribute ") + name, path);
  return ReadString(attr.get(), false, name, path);
}

std::vector<std::string> SplitNames(const std::string& s) {
  std::vector<std::string> out;
  size_t start = 0;
  while (start < s.size()) {
    const size_t comma = s.find(',', start);
    const size_t end = comma == std::string::npos ? s.size() : comma;
    if (end > start) out.push_back(s.substr(start, end - start));
    start = end + 1;
  }
  return out;
}

// An n (cols = 0) or n x cols float64 dataset, row-major.
std::vector<double> ReadDoubles(hid_t loc, const std::string& name, size_t cols, size_t& rows,
                                const std::string& path) {
  Handle ds(H5Dopen2(loc, name.c_str(), H5P_DEFAULT), H5Dclose);
  Require(ds.ok(), "open dataset " + name, path);
  Handle space(H5Dget_space(ds.get()), H5Sclose);
  hsize_t dims[2] = {0, 0};
  const int rank = H5Sget_simple_extent_ndims(space.get());
  if (rank != (cols == 0 ? 1 : 2)) throw IoError("'" + path + "': " + name + " has rank " + std::to_string(rank));
  H5Sget_simple_extent_dims(space.get(), dims, nullptr);
  if (cols != 0 && dims[1] != cols)
    throw IoError("'" + path + "': " + name + " has " + std::to_string(dims[1]) + " columns, expected " + std::to_string(cols));
  if (dims[0] > hsize_t(-1) / 1024 || !H5StorageCovers(ds.get(), dims[0] * std::max<size_t>(cols, 1)))
    throw IoError("'" + path + "': " + name + " claims " + std::to_string(dims[0]) + " rows, more than the file stores for it");
  rows = size_t(dims[0]);
  std::vector<double> out(rows * std::max<size_t>(cols, 1));
  if (!out.empty()) {
    Require(H5Dread(ds.get(), H5T_NATIVE_DOUBLE, H5S_ALL, H5S_ALL, H5P_DEFAULT, out.data()) >= 0,
            "read dataset " + name, path);
  }
  return out;
}

std::vector<Real> ReadColumn(hid_t loc, const std::string& name, size_t n, const std::string& path) {
  size_t rows = 0;
  std::vector<double> v = ReadDoubles(loc, name, 0, rows, path);
  if (rows != n) throw IoError("'" + path + "': " + name + " has " + std::to_string(rows) + " rows, time has " + std::to_string(n));
  return std::vector<Real>(v.begin(), v.end());
}

std::vector<Vec3> ReadVectors(hid_t loc, const std::string& name, size_t n, const std::string& path) {
  size_t rows = 0;
  const std::vector<double> v = ReadDoubles(loc, name, 3, rows, path);
  if (rows != n) throw IoError("'" + path + "': " + name + " has " + std::to_string(rows) + " rows, time has " + std::to_string(n));
  std::vector<Vec3> out(n);
  for (size_t k = 0; k < n; ++k) out[k] = Vec3(v[3 * k], v[3 * k + 1], v[3 * k + 2]);
  return out;
}

}  // namespace

StoredResult ReadResultForces(const std::string& h5_path) {
  StoredResult r;
  r.path = h5_path;
  std::error_code ec;
  if (!fs::exists(h5_path, ec)) throw IoError("'" + h5_path + "': no such file");
  if (!fs::is_regular_file(h5_path, ec)) throw IoError("'" + h5_path + "': not a regular file");
  H5Eset_auto2(H5E_DEFAULT, nullptr, nullptr);
  if (H5Fis_hdf5(h5_path.c_str()) <= 0)
    throw IoError("'" + h5_path + "' is not an HDF5 file (expected a Surge result <out>/<name>.h5)");
  Handle file(H5Fopen(h5_path.c_str(), H5F_ACC_RDONLY, H5P_DEFAULT), H5Fclose);
  Require(file.ok(), "open the file", h5_path);
  if (H5Lexists(file.get(), "metadata", H5P_DEFAULT) <= 0 ||
      H5Lexists(file.get(), "metadata/scene", H5P_DEFAULT) <= 0) {
    throw IoError("'" + h5_path + "' is not a Surge result (no /metadata/scene)");
  }
  {
    Handle ds(H5Dopen2(file.get(), "metadata/scene", H5P_DEFAULT), H5Dclose);
    Require(ds.ok(), "open /metadata/scene", h5_path);
    r.scene_text = ReadString(ds.get(), true, "/metadata/scene", h5_path);
  }
  if (H5Lexists(file.get(), "metadata/resolved", H5P_DEFAULT) > 0) {
    Handle ds(H5Dopen2(file.get(), "metadata/resolved", H5P_DEFAULT), H5Dclose);
    Require(ds.ok(), "open /metadata/resolved", h5_path);
    r.resolved_yaml = ReadString(ds.get(), true, "/metadata/resolved", h5_path);
  }
  if (H5Aexists(file.get(), "name") > 0) r.name = ReadStringAttr(file.get(), "name", h5_path);
  if (H5Aexists(file.get(), "scene_path") > 0)
    r.scene_path = ReadStringAttr(file.get(), "scene_path", h5_path);
  if (H5Aexists(file.get(), "dimension") > 0) {
    Handle attr(H5Aopen(file.get(), "dimension", H5P_DEFAULT), H5Aclose);
    int dim = 3;
    if (attr.ok() && H5ElementCount(attr.get(), false) == 1 &&
        H5Aread(attr.get(), H5T_NATIVE_INT, &dim) >= 0)
      r.dimension = dim;
  }
  if (H5Lexists(file.get(), "timing", H5P_DEFAULT) > 0) {
    Handle g(H5Gopen2(file.get(), "timing", H5P_DEFAULT), H5Gclose);
    if (g.ok() && H5Aexists(g.get(), "exit_status") > 0)
      r.exit_status = ReadStringAttr(g.get(), "exit_status", h5_path);
  }
  if (H5Lexists(file.get(), "forces", H5P_DEFAULT) <= 0) return r;
  Handle forces(H5Gopen2(file.get(), "forces", H5P_DEFAULT), H5Gclose);
  Require(forces.ok(), "open group /forces", h5_path);
  for (const std::string& name : SplitNames(ReadStringAttr(forces.get(), "structures", h5_path))) {
    Handle g(H5Gopen2(forces.get(), name.c_str(), H5P_DEFAULT), H5Gclose);
    Require(g.ok(), "open group /forces/" + name, h5_path);
    StoredForceSeries s;
    s.name = name;
    size_t n = 0;
    const std::vector<double> t = ReadDoubles(g.get(), "time", 0, n, h5_path);
    s.time.assign(t.begin(), t.end());
    s.dt = ReadColumn(g.get(), "dt", n, h5_path);
    s.force = ReadVectors(g.get(), "force", n, h5_path);
    s.contact_area = ReadColumn(g.get(), "contact_area", n, h5_path);
    s.wetted_height = ReadColumn(g.get(), "wetted_height", n, h5_path);
    for (const std::string& face : SplitNames(ReadStringAttr(g.get(), "faces", h5_path))) {
      StoredFaceSeries f;
      f.name = face;
      const std::string fp = "faces/" + face;
      Handle fg(H5Gopen2(g.get(), fp.c_str(), H5P_DEFAULT), H5Gclose);
      Require(fg.ok(), "open group /forces/" + name + "/" + fp, h5_path);
      f.force = ReadVectors(fg.get(), "force", n, h5_path);
      f.contact_area = ReadColumn(fg.get(), "contact_area", n, h5_path);
      s.faces.push_back(std::move(f));
    }
    r.structures.push_back(std::move(s));
  }
  return r;
}

}  // namespace surge
