// Checkpoint files (checkpoint.h; layout in docs/results-format.md, "Checkpoints"). Every array is
// stored as the raw float64/int bytes of the State's vectors (no compression, no conversion), so
// reading one back gives the State bitwise.
#include "io/checkpoint.h"

#include <hdf5.h>

#include "core/hash.h"
#include "io/h5_handle.h"

#include <algorithm>
#include <array>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <limits>
#include <type_traits>
#include <utility>
#include <vector>

#include <fcntl.h>
#include <unistd.h>

namespace surge {
namespace {

namespace fs = std::filesystem;

constexpr const char* kFormat = "surge-checkpoint";
// 2: the file starts with the checksum user block (ChecksumBlock).
constexpr int kFormatVersion = 2;

// The State's element types are stored as rows of doubles: no padding may hide in them.
static_assert(sizeof(Vec3) == 3 * sizeof(double) && sizeof(Mat3) == 9 * sizeof(double),
              "Eigen fixed-size types must be packed");
static_assert(sizeof(History) == kHistorySlots * sizeof(double), "History must be packed");
static_assert(sizeof(SymMat3) == 6 * sizeof(double), "SymMat3 must be packed");
static_assert(std::is_same_v<Real, double>, "checkpoints store Real as float64");
// Particles has exactly the 14 arrays written and read below: a new array must be added here
// (and to docs/results-format.md, "Checkpoints") or restarts silently lose it.
static_assert(sizeof(Particles) == kParticlesSize,
              "Particles changed: update WriteCheckpoint/ReadCheckpoint");

using Handle = H5Handle;  // io/h5_handle.h

void Require(bool ok, const std::string& what, const std::string& path) {
  if (!ok) throw IoError("checkpoint '" + path + "': cannot " + what);
}

// fsync(2) of a file or folder: hands its data (a folder: its entries) to the disk, so that after
// an operating-system crash or power cut the renamed checkpoint is whole, not an empty or partly
// written file under the final name (a killed process needs no fsync: the page cache survives it).
void SyncPath(const std::string& path, bool folder) {
  const int fd = ::open(path.c_str(), (folder ? O_DIRECTORY : 0) | O_RDONLY | O_CLOEXEC);
  if (fd < 0) throw IoError("checkpoint: cannot open '" + path + "' to sync it: " + std::strerror(errno));
  const int rc = ::fsync(fd);
  const int err = errno;
  ::close(fd);
  if (rc != 0) throw IoError("checkpoint: cannot sync '" + path + "': " + std::strerror(err));
}

// --- checksum ---
// The first kUserBlock bytes of a checkpoint are an HDF5 user block (H5Pset_userblock; HDF5
// ignores it and finds its superblock after it). Once the HDF5 file is closed, Surge writes there
// "surge-checkpoint fnv1a64 <16 hex digits> bytes <n>\n": the FNV-1a hash (core/hash.h) and the
// length of everything after the block. ReadCheckpoint checks both before HDF5 reads a byte, so a
// damaged or truncated checkpoint is refused with a message instead of reaching libhdf5, which on
// some corrupt files reads out of bounds or allocates without limit (docs/robustness.md,
// third-party findings).
constexpr size_t kUserBlock = 512;
constexpr const char* kChecksumTag = "surge-checkpoint fnv1a64 ";

// FNV-1a hash and length of the bytes of `fd` from offset kUserBlock to the end.
std::pair<uint64_t, uint64_t> HashAfterUserBlock(int fd, const std::string& path) {
  std::vector<char> buf(size_t(1) << 20);
  uint64_t h = kFnv1aBasis, n = 0;
  off_t at = off_t(kUserBlock);
  while (true) {
    const ssize_t got = ::pread(fd, buf.data(), buf.size(), at);
    if (got < 0) {
      if (errno == EINTR) continue;
      throw IoError("checkpoint '" + path + "': cannot read it: " + std::strerror(errno));
    }
    if (got == 0) break;
    h = Fnv1a(std::string_view(buf.data(), size_t(got)), h);
    n += uint64_t(got);
    at += got;
  }
  return {h, n};
}

// Writes the checksum block of the closed HDF5 file `path`.
void WriteChecksumBlock(const std::string& path) {
  const int fd = ::open(path.c_str(), O_RDWR | O_CLOEXEC);
  if (fd < 0) throw IoError("checkpoint '" + path + "': cannot reopen it: " + std::strerror(errno));
  try {
    const auto [h, n] = HashAfterUserBlock(fd, path);
    std::array<char, kUserBlock> block{};
    std::snprintf(block.data(), block.size(), "%s%s bytes %llu\n", kChecksumTag, HashHex(h).c_str(),
                  static_cast<unsigned long long>(n));
    if (::pwrite(fd, block.data(), block.size(), 0) != ssize_t(block.size())) {
      throw IoError("checkpoint '" + path + "': cannot write its checksum: " + std::strerror(errno));
    }
  } catch (...) {
    ::close(fd);
    throw;
  }
  ::close(fd);
}

// Checks the checksum block of `path`. Returns false when the file has none (not a checkpoint
// of this format: the HDF5 checks that follow say what it is); throws IoError when it has one
// and the rest of the file does not match it.
bool VerifyChecksumBlock(const std::string& path) {
  const int fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC);
  if (fd < 0) throw IoError("checkpoint '" + path + "': cannot open it: " + std::strerror(errno));
  std::array<char, kUserBlock + 1> block{};
  ssize_t got = ::pread(fd, block.data(), kUserBlock, 0);
  const size_t tag = std::strlen(kChecksumTag);
  unsigned long long want_n = 0;
  char want_hex[17] = {};
  if (got < ssize_t(tag) || std::memcmp(block.data(), kChecksumTag, tag) != 0 ||
      std::sscanf(block.data() + tag, "%16[0-9a-f] bytes %llu", want_hex, &want_n) != 2) {
    ::close(fd);
    return false;
  }
  std::pair<uint64_t, uint64_t> have;
  try {
    have = HashAfterUserBlock(fd, path);
  } catch (...) {
    ::close(fd);
    throw;
  }
  ::close(fd);
  if (have.second != want_n) {
    throw IoError("checkpoint '" + path + "' is damaged: " + std::to_string(have.second) +
                  " bytes after its header, " + std::to_string(want_n) +
                  " when it was written (truncated or appended to); restart from another checkpoint");
  }
  if (HashHex(have.first) != want_hex) {
    throw IoError("checkpoint '" + path + "' is damaged: content hash " + HashHex(have.first) +
                  ", " + want_hex + " when it was written; restart from another checkpoint");
  }
  return true;
}

// --- writing ---

void WriteString(hid_t loc, const char* name, const std::string& value, bool dataset,
                 const std::string& path) {
  Handle type(H5Tcopy(H5T_C_S1), H5Tclose);
  H5Tset_size(type.get(), std::max<size_t>(value.size(), 1));
  H5Tset_strpad(type.get(), H5T_STR_NULLPAD);
  H5Tset_cset(type.get(), H5T_CSET_UTF8);
  Handle space(H5Screate(H5S_SCALAR), H5Sclose);
  const std::string padded = value.empty() ? std::string(1, '\0') : value;
  if (dataset) {
    Handle ds(H5Dcreate2(loc, name, type.get(), space.get(), H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT),
              H5Dclose);
    Require(ds.ok() && H5Dwrite(ds.get(), type.get(), H5S_ALL, H5S_ALL, H5P_DEFAULT,
                                padded.data()) >= 0,
            std::string("write ") + name, path);
  } else {
    Handle attr(H5Acreate2(loc, name, type.get(), space.get(), H5P_DEFAULT, H5P_DEFAULT), H5Aclose);
    Require(attr.ok() && H5Awrite(attr.get(), type.get(), padded.data()) >= 0,
            std::string("write attribute ") + name, path);
  }
}

template <typename T>
void WriteScalar(hid_t loc, const char* name, hid_t file_type, hid_t mem_type, T value,
                 const std::string& path) {
  Handle space(H5Screate(H5S_SCALAR), H5Sclose);
  Handle attr(H5Acreate2(loc, name, file_type, space.get(), H5P_DEFAULT, H5P_DEFAULT), H5Aclose);
  Require(attr.ok() && H5Awrite(attr.get(), mem_type, &value) >= 0,
          std::string("write attribute ") + name, path);
}
void WriteReal(hid_t loc, const char* name, Real v, const std::string& path) {
  WriteScalar(loc, name, H5T_IEEE_F64LE, H5T_NATIVE_DOUBLE, v, path);
}
void WriteInt(hid_t loc, const char* name, int64_t v, const std::string& path) {
  WriteScalar(loc, name, H5T_STD_I64LE, H5T_NATIVE_INT64, v, path);
}

// rows x cols values (cols = 0: 1-D), contiguous.
void WriteArray(hid_t loc, const char* name, hid_t file_type, hid_t mem_type, const void* data,
                size_t rows, size_t cols, const std::string& path) {
  const hsize_t dims[2] = {hsize_t(rows), hsize_t(cols)};
  Handle space(H5Screate_simple(cols == 0 ? 1 : 2, dims, nullptr), H5Sclose);
  Handle ds(H5Dcreate2(loc, name, file_type, space.get(), H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT),
            H5Dclose);
  Require(ds.ok(), std::string("create ") + name, path);
  if (rows > 0) {
    Require(H5Dwrite(ds.get(), mem_type, H5S_ALL, H5S_ALL, H5P_DEFAULT, data) >= 0,
            std::string("write ") + name, path);
  }
}
void WriteDoubles(hid_t loc, const char* name, const void* data, size_t rows, size_t cols,
                  const std::string& path) {
  WriteArray(loc, name, H5T_IEEE_F64LE, H5T_NATIVE_DOUBLE, data, rows, cols, path);
}

// A rigid body state as 18 doubles: position, rotation (column-major), velocity, angular velocity.
constexpr size_t kRigidColumns = 18;
std::vector<double> FlattenRigid(const std::vector<RigidBodyState>& bodies) {
  std::vector<double> out;
  for (const RigidBodyState& b : bodies) {
    out.insert(out.end(), b.position.data(), b.position.data() + 3);
    out.insert(out.end(), b.rotation.data(), b.rotation.data() + 9);
    out.insert(out.end(), b.velocity.data(), b.velocity.data() + 3);
    out.insert(out.end(), b.angular_velocity.data(), b.angular_velocity.data() + 3);
  }
  return out;
}
std::vector<RigidBodyState> UnflattenRigid(const std::vector<double>& v) {
  std::vector<RigidBodyState> out(v.size() / kRigidColumns);
  for (size_t k = 0; k < out.size(); ++k) {
    const double* p = &v[k * kRigidColumns];
    std::copy(p, p + 3, out[k].position.data());
    std::copy(p + 3, p + 12, out[k].rotation.data());
    std::copy(p + 12, p + 15, out[k].velocity.data());
    std::copy(p + 15, p + 18, out[k].angular_velocity.data());
  }
  return out;
}

// A ForcePeak as 9 doubles: peak_force, peak_time, force_at_peak (3), impulse (3),
// peak_contact_area.
constexpr size_t kPeakColumns = 9;
void PushPeak(std::vector<double>& out, const ForcePeak& p) {
  out.push_back(p.peak_force);
  out.push_back(p.peak_time);
  out.insert(out.end(), p.force_at_peak.data(), p.force_at_peak.data() + 3);
  out.insert(out.end(), p.impulse.data(), p.impulse.data() + 3);
  out.push_back(p.peak_contact_area);
}
ForcePeak PopPeak(const double* p) {
  ForcePeak f;
  f.peak_force = p[0];
  f.peak_time = p[1];
  std::copy(p + 2, p + 5, f.force_at_peak.data());
  std::copy(p + 5, p + 8, f.impulse.data());
  f.peak_contact_area = p[8];
  return f;
}

// --- reading ---

std::string ReadString(hid_t loc, const char* name, bool dataset, const std::string& path) {
  Handle obj(dataset ? H5Dopen2(loc, name, H5P_DEFAULT) : H5Aopen(loc, name, H5P_DEFAULT),
             dataset ? H5Dclose : H5Aclose);
  Require(obj.ok(), std::string("open ") + name, path);
  Handle type(dataset ? H5Dget_type(obj.get()) : H5Aget_type(obj.get()), H5Tclose);
  Require(type.ok() && H5Tget_class(type.get()) == H5T_STRING && H5Tis_variable_str(type.get()) <= 0,
          std::string("read ") + name, path);
  // One fixed-length string of a sane size: the read writes every element of the dataspace.
  const size_t size = H5Tget_size(type.get());
  if (H5ElementCount(obj.get(), dataset) != 1 || size == 0 || size > kH5MaxStringBytes) {
    throw IoError("checkpoint '" + path + "': " + name + " is not one string of at most " +
                  std::to_string(kH5MaxStringBytes) + " bytes");
  }
  std::string out(size, '\0');
  const herr_t rc = dataset ? H5Dread(obj.get(), type.get(), H5S_ALL, H5S_ALL, H5P_DEFAULT, out.data())
                            : H5Aread(obj.get(), type.get(), out.data());
  Require(rc >= 0, std::string("read ") + name, path);
  out.resize(std::strlen(out.c_str()));
  return out;
}

template <typename T>
T ReadScalar(hid_t loc, const char* name, hid_t mem_type, const std::string& path) {
  Handle attr(H5Aopen(loc, name, H5P_DEFAULT), H5Aclose);
  T value{};
  // Exactly one value: H5Aread writes every element of the attribute into `value`.
  Require(attr.ok() && H5ElementCount(attr.get(), false) == 1 &&
              H5Aread(attr.get(), mem_type, &value) >= 0,
          std::string("read attribute ") + name, path);
  return value;
}
Real ReadReal(hid_t loc, const char* name, const std::string& path) {
  return ReadScalar<double>(loc, name, H5T_NATIVE_DOUBLE, path);
}
int64_t ReadInt(hid_t loc, const char* name, const std::string& path) {
  return ReadScalar<int64_t>(loc, name, H5T_NATIVE_INT64, path);
}

// A rows x cols dataset (cols = 0: 1-D) into `out` (resized to rows elements of T, each
// `cols` (or 1) values of mem_type). Throws when the shape is not rows x cols.
// Reads dataset `name` of shape (rows, cols) (cols 0: (rows)) into `out`, which holds
// rows * max(cols, 1) elements of mem_type; `resize` sizes it once the shape is checked.
template <typename Resize>
void ReadRows(hid_t loc, const char* name, hid_t mem_type, size_t rows, size_t cols,
              const Resize& resize, const std::string& path) {
  Handle ds(H5Dopen2(loc, name, H5P_DEFAULT), H5Dclose);
  Require(ds.ok(), std::string("open ") + name, path);
  Handle space(H5Dget_space(ds.get()), H5Sclose);
  hsize_t dims[H5S_MAX_RANK] = {};  // the rank is checked after the dims are read
  const int rank = H5Sget_simple_extent_ndims(space.get());
  H5Sget_simple_extent_dims(space.get(), dims, nullptr);
  if (rank != (cols == 0 ? 1 : 2) || dims[0] != rows || (cols != 0 && dims[1] != cols)) {
    throw IoError("checkpoint '" + path + "': " + name + " has the wrong shape (expected " +
                  std::to_string(rows) + " rows" +
                  (cols ? " x " + std::to_string(cols) : std::string()) + ")");
  }
  const hsize_t elements = hsize_t(rows) * std::max<size_t>(cols, 1);  // rows < 2^64 / cols
  if (rows > hsize_t(-1) / 1024 || !H5StorageCovers(ds.get(), elements)) {
    throw IoError("checkpoint '" + path + "': " + name + " claims " + std::to_string(rows) +
                  " rows, more than the file stores for it");
  }
  void* out = resize();
  if (rows > 0) {
    Require(H5Dread(ds.get(), mem_type, H5S_ALL, H5S_ALL, H5P_DEFAULT, out) >= 0,
            std::string("read ") + name, path);
  }
}

template <typename T>
void ReadArray(hid_t loc, const char* name, hid_t mem_type, size_t rows, size_t cols,
               std::vector<T>& out, const std::string& path) {
  ReadRows(loc, name, mem_type, rows, cols, [&]() -> void* { out.resize(rows); return out.data(); },
           path);
}

// Rows and columns of a dataset (columns 0 unless its rank is 2); any rank fits, ReadArray
// checks it.
std::pair<size_t, size_t> Shape(hid_t loc, const char* name, const std::string& path) {
  Handle ds(H5Dopen2(loc, name, H5P_DEFAULT), H5Dclose);
  Require(ds.ok(), std::string("open ") + name, path);
  Handle space(H5Dget_space(ds.get()), H5Sclose);
  hsize_t dims[H5S_MAX_RANK] = {};
  const int rank = H5Sget_simple_extent_dims(space.get(), dims, nullptr);
  Require(rank >= 1, std::string("read ") + name, path);
  return {size_t(dims[0]), rank == 2 ? size_t(dims[1]) : 0};
}

size_t Rows(hid_t loc, const char* name, const std::string& path) {
  return Shape(loc, name, path).first;
}

}  // namespace

std::string SceneHash(const std::string& text) { return Fnv1aHex(text); }

std::string CheckpointPath(const std::string& out_dir, const std::string& name, int64_t step) {
  char file[64];
  std::snprintf(file, sizeof file, "_step_%09lld.h5", static_cast<long long>(step));
  return (fs::path(out_dir) / "checkpoints" / (name + file)).string();
}

std::vector<std::string> ListCheckpoints(const std::string& out_dir, const std::string& name) {
  std::vector<std::string> out;
  std::error_code ec;
  const fs::path dir = fs::path(out_dir) / "checkpoints";
  if (!fs::is_directory(dir, ec)) return out;
  const std::string prefix = name + "_step_";
  for (const fs::directory_entry& e : fs::directory_iterator(dir, ec)) {
    const std::string f = e.path().filename().string();
    if (f.size() == prefix.size() + 12 && f.compare(0, prefix.size(), prefix) == 0 &&
        f.compare(f.size() - 3, 3, ".h5") == 0 &&
        std::all_of(f.begin() + long(prefix.size()), f.end() - 3,
                    [](char c) { return c >= '0' && c <= '9'; })) {
      out.push_back(e.path().string());
    }
  }
  std::sort(out.begin(), out.end());  // fixed-width step numbers: name order is step order
  return out;
}

void WriteCheckpoint(const std::string& path, const Checkpoint& c) {
  std::error_code ec;
  const fs::path dir = fs::path(path).parent_path();
  if (!dir.empty()) fs::create_directories(dir, ec);
  if (ec) throw IoError("cannot create checkpoint folder '" + dir.string() + "': " + ec.message());
  const std::string tmp = path + ".tmp";
  H5Eset_auto2(H5E_DEFAULT, nullptr, nullptr);
  {
    Handle fcpl(H5Pcreate(H5P_FILE_CREATE), H5Pclose);
    Require(fcpl.ok() && H5Pset_userblock(fcpl.get(), kUserBlock) >= 0, "set up the file", tmp);
    Handle file(H5Fcreate(tmp.c_str(), H5F_ACC_TRUNC, fcpl.get(), H5P_DEFAULT), H5Fclose);
    Require(file.ok(), "create the file", tmp);
    const hid_t f = file.get();
    const State& s = c.state;
    WriteString(f, "format", kFormat, false, tmp);
    WriteInt(f, "format_version", kFormatVersion, tmp);
    WriteString(f, "name", c.name, false, tmp);
    WriteString(f, "version", c.version, false, tmp);
    WriteString(f, "git_hash", c.git_hash, false, tmp);
    WriteString(f, "scene_path", c.scene_path, false, tmp);
    WriteString(f, "scene_hash", SceneHash(c.scene_text), false, tmp);
    WriteString(f, "resolved_hash", SceneHash(c.resolved_yaml), false, tmp);
    WriteReal(f, "time", s.time, tmp);
    WriteInt(f, "step", s.step, tmp);
    WriteReal(f, "dt", s.dt, tmp);
    WriteInt(f, "particles_removed", s.particles_removed, tmp);
    WriteReal(f, "wall_work", s.wall_work, tmp);
    WriteReal(f, "internal_work", s.internal_work, tmp);
    WriteReal(f, "external_work", s.external_work, tmp);
    WriteReal(f, "damping_released", s.damping_released ? 1.0 : 0.0, tmp);
    WriteReal(f, "next_output", c.next_output, tmp);
    WriteReal(f, "next_checkpoint", c.next_checkpoint, tmp);
    {
      Handle g(H5Gcreate2(f, "metadata", H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT), H5Gclose);
      Require(g.ok(), "create /metadata", tmp);
      WriteString(g.get(), "scene", c.scene_text, true, tmp);
      WriteString(g.get(), "resolved", c.resolved_yaml, true, tmp);
    }
    {
      const Particles& P = s.particles;
      const size_t n = P.size();
      Handle g(H5Gcreate2(f, "particles", H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT), H5Gclose);
      Require(g.ok(), "create /particles", tmp);
      const hid_t l = g.get();
      WriteDoubles(l, "x", P.x.data(), n, 3, tmp);
      WriteDoubles(l, "v", P.v.data(), n, 3, tmp);
      if (P.layout.affine) WriteDoubles(l, "C", P.C.data(), n, 9, tmp);
      WriteDoubles(l, "F", P.F.data(), n, 9, tmp);
      WriteDoubles(l, "stress", P.stress.data(), n, 6, tmp);  // xx yy zz xy yz xz
      if (P.layout.strain) WriteDoubles(l, "strain", P.strain.data(), n, 9, tmp);
      if (P.layout.elastic_b) WriteDoubles(l, "elastic_b", P.elastic_b.data(), n, 6, tmp);  // as stress
      if (P.layout.history)  // (n, layout.history_slots)
        WriteDoubles(l, "history", P.history.data(), n, size_t(P.history.stride()), tmp);
      WriteDoubles(l, "mass", P.mass.data(), n, 0, tmp);
      WriteDoubles(l, "volume0", P.volume0.data(), n, 0, tmp);
      if (P.layout.ext_force) WriteDoubles(l, "ext_force", P.ext_force.data(), n, 3, tmp);
      WriteArray(l, "material", H5T_STD_I32LE, H5T_NATIVE_INT32, P.material.data(), n, 0, tmp);
      WriteArray(l, "body", H5T_STD_I32LE, H5T_NATIVE_INT32, P.body.data(), n, 0, tmp);
      WriteArray(l, "id", H5T_STD_I64LE, H5T_NATIVE_INT64, P.id.data(), n, 0, tmp);
    }
    {
      std::vector<int64_t> groups;
      for (const MaterialGroup& m : s.groups) {
        groups.push_back(m.material);
        groups.push_back(int64_t(m.begin));
        groups.push_back(int64_t(m.end));
        groups.push_back(m.antilocking);
      }
      WriteArray(f, "groups", H5T_STD_I64LE, H5T_NATIVE_INT64, groups.data(), s.groups.size(), 4,
                 tmp);
      WriteDoubles(f, "rigid", FlattenRigid(s.rigid).data(), s.rigid.size(), kRigidColumns, tmp);
      WriteDoubles(f, "bullet", FlattenRigid(c.bullet).data(), c.bullet.size(), kRigidColumns, tmp);
      WriteArray(f, "bullet_contacts", H5T_STD_U8LE, H5T_NATIVE_UINT8, c.bullet_contacts.data(),
                 c.bullet_contacts.size(), 0, tmp);
    }
    {
      Handle g(H5Gcreate2(f, "workspace", H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT), H5Gclose);
      Require(g.ok(), "create /workspace", tmp);
      Require(c.bulk_viscosity_q.size() == c.bulk_viscosity_id.size(),
              "write /workspace (bulk viscosity q and id differ in length)", tmp);
      WriteDoubles(g.get(), "bulk_viscosity_q", c.bulk_viscosity_q.data(), c.bulk_viscosity_q.size(),
                   0, tmp);
      WriteArray(g.get(), "bulk_viscosity_id", H5T_STD_I64LE, H5T_NATIVE_INT64,
                 c.bulk_viscosity_id.data(), c.bulk_viscosity_id.size(), 0, tmp);
      WriteReal(g.get(), "bulk_viscosity_dt_bound", c.bulk_viscosity_dt_bound, tmp);
    }
    {
      const ResultPosition& r = c.result;
      Handle g(H5Gcreate2(f, "result", H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT), H5Gclose);
      Require(g.ok(), "create /result", tmp);
      WriteInt(g.get(), "snapshots", r.snapshots, tmp);
      WriteInt(g.get(), "energy_rows", r.energy_rows, tmp);
      WriteInt(g.get(), "force_rows", r.force_rows, tmp);
      WriteInt(g.get(), "rigid_rows", r.rigid_rows, tmp);
      WriteInt(g.get(), "force_samples", r.force_samples, tmp);
      // Per structure: its ForcePeak, peak_wetted_height, then one ForcePeak per face.
      std::vector<double> peaks;
      std::vector<int64_t> faces;
      for (const StructurePeak& p : r.force_peaks) {
        PushPeak(peaks, p);
        peaks.push_back(p.peak_wetted_height);
        for (const ForcePeak& face : p.faces) PushPeak(peaks, face);
        faces.push_back(int64_t(p.faces.size()));
      }
      WriteDoubles(g.get(), "force_peaks", peaks.data(), peaks.size(), 0, tmp);
      WriteArray(g.get(), "force_peak_faces", H5T_STD_I64LE, H5T_NATIVE_INT64, faces.data(),
                 faces.size(), 0, tmp);
    }
    Require(H5Fflush(f, H5F_SCOPE_GLOBAL) >= 0, "flush the file", tmp);
  }
  WriteChecksumBlock(tmp);
  // Whole on disk before it gets its final name, and the rename itself on disk after it: the
  // write-fsync-rename-fsync(folder) sequence of an atomic replace.
  SyncPath(tmp, false);
  fs::rename(tmp, path, ec);
  if (ec) throw IoError("cannot rename '" + tmp + "' to '" + path + "': " + ec.message());
  SyncPath(dir.empty() ? std::string(".") : dir.string(), true);
}

Checkpoint ReadCheckpoint(const std::string& path, bool verify_checksum) {
  std::error_code ec;
  if (!fs::is_regular_file(path, ec)) throw IoError("checkpoint '" + path + "': no such file");
  const bool verified = verify_checksum && VerifyChecksumBlock(path);
  H5Eset_auto2(H5E_DEFAULT, nullptr, nullptr);
  if (H5Fis_hdf5(path.c_str()) <= 0) throw IoError("checkpoint '" + path + "' is not an HDF5 file");
  Handle file(H5Fopen(path.c_str(), H5F_ACC_RDONLY, H5P_DEFAULT), H5Fclose);
  Require(file.ok(), "open the file", path);
  const hid_t f = file.get();
  if (H5Aexists(f, "format") <= 0 || ReadString(f, "format", false, path) != kFormat)
    throw IoError("'" + path + "' is not a Surge checkpoint (no format = surge-checkpoint)");
  const int64_t version = ReadInt(f, "format_version", path);
  if (version != kFormatVersion) {
    throw IoError("checkpoint '" + path + "' has format version " + std::to_string(version) +
                  "; this surge reads version " + std::to_string(kFormatVersion));
  }
  if (verify_checksum && !verified) {
    throw IoError("checkpoint '" + path + "' is damaged: its checksum header is missing or "
                  "unreadable; restart from another checkpoint");
  }
  Checkpoint c;
  c.name = ReadString(f, "name", false, path);
  c.version = ReadString(f, "version", false, path);
  c.git_hash = ReadString(f, "git_hash", false, path);
  c.scene_path = ReadString(f, "scene_path", false, path);
  c.scene_hash = ReadString(f, "scene_hash", false, path);
  c.resolved_hash = ReadString(f, "resolved_hash", false, path);
  c.scene_text = ReadString(f, "metadata/scene", true, path);
  c.resolved_yaml = ReadString(f, "metadata/resolved", true, path);
  State& s = c.state;
  s.time = ReadReal(f, "time", path);
  s.step = ReadInt(f, "step", path);
  s.dt = ReadReal(f, "dt", path);
  s.particles_removed = ReadInt(f, "particles_removed", path);
  s.wall_work = ReadReal(f, "wall_work", path);
  // Checkpoints before 2026-12-03 have no internal work: the sum restarts from 0 (energy output
  // only; the motion is unaffected).
  s.internal_work = H5Aexists(f, "internal_work") > 0 ? ReadReal(f, "internal_work", path) : 0;
  // Local damping's equilibrium rule (2026-12-03; older checkpoints: not released, no work yet).
  s.external_work = H5Aexists(f, "external_work") > 0 ? ReadReal(f, "external_work", path) : 0;
  s.damping_released =
      H5Aexists(f, "damping_released") > 0 && ReadReal(f, "damping_released", path) != 0;
  c.next_output = ReadReal(f, "next_output", path);
  c.next_checkpoint = ReadReal(f, "next_checkpoint", path);
  {
    Handle g(H5Gopen2(f, "particles", H5P_DEFAULT), H5Gclose);
    Require(g.ok(), "open /particles", path);
    const hid_t l = g.get();
    Particles& P = s.particles;
    const size_t n = Rows(l, "x", path);
    const hid_t d = H5T_NATIVE_DOUBLE;
    ReadArray(l, "x", d, n, 3, P.x, path);
    ReadArray(l, "v", d, n, 3, P.v, path);
    // An optional array (Particles::layout) is held when the checkpoint has it.
    const auto read_optional = [&](const char* name, size_t cols, bool& held, auto& array) {
      held = H5Lexists(l, name, H5P_DEFAULT) > 0;
      if (held) ReadArray(l, name, d, n, cols, array, path);
    };
    read_optional("C", 9, P.layout.affine, P.C);
    ReadArray(l, "F", d, n, 9, P.F, path);
    // A symmetric tensor array: (n, 6), or the full (n, 9) matrix of checkpoints written before
    // 2026-12-03 (stress, elastic_b).
    const auto read_symmetric = [&](const char* name, std::vector<SymMat3>& out) {
      if (Shape(l, name, path).second == 9) {
        std::vector<Mat3> full;
        ReadArray(l, name, d, n, 9, full, path);
        out.assign(full.begin(), full.end());
      } else {
        ReadArray(l, name, d, n, 6, out, path);
      }
    };
    read_symmetric("stress", P.stress);
    read_optional("strain", 9, P.layout.strain, P.strain);
    P.layout.elastic_b = H5Lexists(l, "elastic_b", H5P_DEFAULT) > 0;
    if (P.layout.elastic_b) read_symmetric("elastic_b", P.elastic_b);
    // History: (n, slots), 1 <= slots <= kHistorySlots (before 2026-12-03 always kHistorySlots).
    P.layout.history = H5Lexists(l, "history", H5P_DEFAULT) > 0;
    if (P.layout.history) {
      const size_t slots = Shape(l, "history", path).second;
      if (slots < 1 || slots > size_t(kHistorySlots)) {
        throw IoError("checkpoint '" + path + "': history has " + std::to_string(slots) +
                      " columns (expected 1 to " + std::to_string(kHistorySlots) + ")");
      }
      P.layout.history_slots = int(slots);
      ReadRows(l, "history", d, n, slots, [&]() -> void* {
        P.history.Resize(n, int(slots));
        return P.history.data();
      }, path);
    }
    ReadArray(l, "mass", d, n, 0, P.mass, path);
    ReadArray(l, "volume0", d, n, 0, P.volume0, path);
    read_optional("ext_force", 3, P.layout.ext_force, P.ext_force);
    ReadArray(l, "material", H5T_NATIVE_INT32, n, 0, P.material, path);
    ReadArray(l, "body", H5T_NATIVE_INT32, n, 0, P.body, path);
    ReadArray(l, "id", H5T_NATIVE_INT64, n, 0, P.id, path);
  }
  {
    // (material, begin, end, anti-locking setting); before per-body anti-locking (2026-12-03)
    // without the setting, which was the material's (-1).
    std::vector<std::array<int64_t, 4>> groups;
    const auto [rows, cols] = Shape(f, "groups", path);
    if (cols == 3) {
      std::vector<std::array<int64_t, 3>> old;
      ReadArray(f, "groups", H5T_NATIVE_INT64, rows, 3, old, path);
      for (const auto& g : old) groups.push_back({g[0], g[1], g[2], -1});
    } else {
      ReadArray(f, "groups", H5T_NATIVE_INT64, rows, 4, groups, path);
    }
    for (const auto& g : groups) {
      if (g[1] < 0 || g[2] < g[1] || size_t(g[2]) > s.particles.size())
        throw IoError("checkpoint '" + path + "': a material group lies outside the particles");
      if (g[0] < 0 || g[0] > std::numeric_limits<int>::max() || g[3] < -1 ||
          g[3] > std::numeric_limits<int>::max())
        throw IoError("checkpoint '" + path + "': a material group has an invalid index");
      s.groups.push_back(MaterialGroup{int(g[0]), size_t(g[1]), size_t(g[2]), int(g[3])});
    }
    const auto read_rigid = [&](const char* name) {
      std::vector<std::array<double, kRigidColumns>> rows;
      ReadArray(f, name, H5T_NATIVE_DOUBLE, Rows(f, name, path), kRigidColumns, rows, path);
      std::vector<double> flat;
      for (const auto& row : rows) flat.insert(flat.end(), row.begin(), row.end());
      return UnflattenRigid(flat);
    };
    s.rigid = read_rigid("rigid");
    c.bullet = read_rigid("bullet");
    ReadArray(f, "bullet_contacts", H5T_NATIVE_UINT8, Rows(f, "bullet_contacts", path), 0,
              c.bullet_contacts, path);
  }
  if (H5Lexists(f, "workspace", H5P_DEFAULT) > 0) {
    Handle g(H5Gopen2(f, "workspace", H5P_DEFAULT), H5Gclose);
    Require(g.ok(), "open /workspace", path);
    const size_t n = Rows(g.get(), "bulk_viscosity_q", path);
    ReadArray(g.get(), "bulk_viscosity_q", H5T_NATIVE_DOUBLE, n, 0, c.bulk_viscosity_q, path);
    ReadArray(g.get(), "bulk_viscosity_id", H5T_NATIVE_INT64, n, 0, c.bulk_viscosity_id, path);
    c.bulk_viscosity_dt_bound = ReadReal(g.get(), "bulk_viscosity_dt_bound", path);
  }
  {
    Handle g(H5Gopen2(f, "result", H5P_DEFAULT), H5Gclose);
    Require(g.ok(), "open /result", path);
    ResultPosition& r = c.result;
    r.snapshots = int(ReadInt(g.get(), "snapshots", path));
    r.energy_rows = ReadInt(g.get(), "energy_rows", path);
    r.force_rows = ReadInt(g.get(), "force_rows", path);
    r.rigid_rows = ReadInt(g.get(), "rigid_rows", path);
    r.force_samples = ReadInt(g.get(), "force_samples", path);
    std::vector<double> peaks;
    std::vector<int64_t> faces;
    ReadArray(g.get(), "force_peak_faces", H5T_NATIVE_INT64, Rows(g.get(), "force_peak_faces", path),
              0, faces, path);
    ReadArray(g.get(), "force_peaks", H5T_NATIVE_DOUBLE, Rows(g.get(), "force_peaks", path), 0,
              peaks, path);
    size_t at = 0;
    for (int64_t nf : faces) {
      const size_t need = kPeakColumns + 1 + size_t(std::max<int64_t>(nf, 0)) * kPeakColumns;
      if (nf < 0 || at + need > peaks.size())
        throw IoError("checkpoint '" + path + "': /result/force_peaks is too short");
      StructurePeak p;
      static_cast<ForcePeak&>(p) = PopPeak(&peaks[at]);
      p.peak_wetted_height = peaks[at + kPeakColumns];
      for (int64_t k = 0; k < nf; ++k)
        p.faces.push_back(PopPeak(&peaks[at + kPeakColumns + 1 + size_t(k) * kPeakColumns]));
      at += need;
      r.force_peaks.push_back(std::move(p));
    }
  }
  return c;
}

}  // namespace surge
