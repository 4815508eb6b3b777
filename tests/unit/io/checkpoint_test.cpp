// Checkpoints (io/checkpoint.h, issue 9): a State with every field set (NaN included) reads back
// bit for bit; the file appears only whole (no .tmp left, rewrite replaces); foreign files are
// refused naming the path; ListCheckpoints orders by step. ResultsWriter's reopening constructor
// (a restart) cuts snapshots, energy, force and rigid series and their CSV files back to a
// ResultPosition and continues the force summary. The scene keys output.checkpoint_every and
// output.checkpoints_keep.
#include "io/checkpoint.h"

#include <gtest/gtest.h>
#include <hdf5.h>

#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <limits>
#include <random>
#include <utility>

#include "io/results_reader.h"
#include "io/results_writer.h"
#include "scene/scene.h"

namespace surge {
namespace {

namespace fs = std::filesystem;

class CheckpointTest : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() /
           ("surge_checkpoint_" + std::to_string(::testing::UnitTest::GetInstance()->random_seed()) +
            "_" + ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }
  fs::path dir_;
};

// Byte equality of two vectors (NaN == NaN when the bits agree).
template <typename T>
bool SameBytes(const std::vector<T>& a, const std::vector<T>& b) {
  return a.size() == b.size() && (a.empty() || std::memcmp(a.data(), b.data(), a.size() * sizeof(T)) == 0);
}

bool SameBytes(const HistoryArray& a, const HistoryArray& b) {
  return a.size() == b.size() && (a.size() == 0 || a.stride() == b.stride()) &&
         (a.size() == 0 ||
          std::memcmp(a.data(), b.data(), a.size() * size_t(a.stride()) * sizeof(Real)) == 0);
}

bool SameRigid(const std::vector<RigidBodyState>& a, const std::vector<RigidBodyState>& b) {
  if (a.size() != b.size()) return false;
  for (size_t k = 0; k < a.size(); ++k) {
    if (a[k].position != b[k].position || a[k].rotation != b[k].rotation ||
        a[k].velocity != b[k].velocity || a[k].angular_velocity != b[k].angular_velocity)
      return false;
  }
  return true;
}

Checkpoint FullCheckpoint(size_t n) {
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> u(-1e3, 1e3);
  const auto vec = [&] { return Vec3(u(rng), u(rng), u(rng)); };
  const auto mat = [&] { return Mat3(Mat3::NullaryExpr([&](Eigen::Index, Eigen::Index) { return u(rng); })); };
  Checkpoint c;
  State& s = c.state;
  s.time = 0.1 + 1e-17;
  s.step = 1234567;
  s.dt = 3.3e-5;
  s.particles_removed = 42;
  s.wall_work = -std::nextafter(1.5, 2.0);
  s.internal_work = std::nextafter(2.25, 3.0);
  s.external_work = std::nextafter(4.5, 5.0);
  s.damping_released = true;
  Particles& P = s.particles;
  P.Resize(n);
  for (size_t p = 0; p < n; ++p) {
    P.x[p] = vec();
    P.v[p] = vec();
    P.C[p] = mat();
    P.F[p] = mat();
    P.stress[p] = mat();
    P.strain[p] = mat();
    P.elastic_b[p] = mat();
    for (int k = 0; k < P.history.stride(); ++k) P.history[p][k] = u(rng);
    P.mass[p] = u(rng);
    P.volume0[p] = u(rng);
    P.ext_force[p] = vec();
    P.material[p] = int32_t(p % 3);
    P.body[p] = int32_t(p % 2);
    P.id[p] = int64_t(1e12) + int64_t(p);
  }
  if (n > 0) P.stress[0].v[4] = std::numeric_limits<Real>::quiet_NaN();  // yz
  s.groups = {{0, 0, n / 2}, {2, n / 2, n, 3}};  // the second with a body's own anti-locking
  s.rigid = {{vec(), mat(), vec(), vec()}, {vec(), mat(), vec(), vec()}};
  c.bullet = {{vec(), mat(), vec(), vec()}, {vec(), mat(), vec(), vec()}};
  c.bulk_viscosity_q.assign(n, 0);
  c.bulk_viscosity_id.assign(n, 0);
  for (size_t p = 0; p < n; ++p) {
    c.bulk_viscosity_q[p] = u(rng);
    c.bulk_viscosity_id[p] = int64_t(n - p);
  }
  c.bulk_viscosity_dt_bound = 2.5e-4;
  c.next_output = 0.15;
  c.next_checkpoint = 0.2;
  c.result.snapshots = 4;
  c.result.energy_rows = 1001;
  c.result.force_rows = 1000;
  c.result.rigid_rows = 999;
  c.result.force_samples = 1000;
  StructurePeak a;
  a.peak_force = 12.5;
  a.peak_time = 0.0625;
  a.force_at_peak = vec();
  a.impulse = vec();
  a.peak_contact_area = 3;
  a.peak_wetted_height = 0.75;
  a.faces.resize(2);
  a.faces[1].impulse = vec();
  StructurePeak b;  // peak_time NaN: no sample yet
  c.result.force_peaks = {a, b};
  c.name = "dam";
  c.scene_path = "scenes/dam.yaml";
  c.scene_text = "name: dam  # 20° ✓\n";
  c.resolved_yaml = "name: dam\n";
  c.version = "0.1";
  c.git_hash = "abc";
  return c;
}

TEST_F(CheckpointTest, RoundTripIsBitwise) {
  for (size_t n : {size_t(0), size_t(7), size_t(5000)}) {
    const Checkpoint c = FullCheckpoint(n);
    const std::string path = CheckpointPath(dir_.string(), "dam", c.state.step);
    EXPECT_EQ(path, (dir_ / "checkpoints" / "dam_step_001234567.h5").string());
    WriteCheckpoint(path, c);
    const Checkpoint r = ReadCheckpoint(path);
    const Particles &P = c.state.particles, &Q = r.state.particles;
    EXPECT_TRUE(SameBytes(P.x, Q.x) && SameBytes(P.v, Q.v) && SameBytes(P.C, Q.C) &&
                SameBytes(P.F, Q.F) && SameBytes(P.stress, Q.stress) &&
                SameBytes(P.strain, Q.strain) && SameBytes(P.elastic_b, Q.elastic_b) &&
                SameBytes(P.history, Q.history) && SameBytes(P.mass, Q.mass) &&
                SameBytes(P.volume0, Q.volume0) && SameBytes(P.ext_force, Q.ext_force) &&
                SameBytes(P.material, Q.material) && SameBytes(P.body, Q.body) &&
                SameBytes(P.id, Q.id))
        << "n = " << n;
    EXPECT_EQ(r.state.time, c.state.time);
    EXPECT_EQ(r.state.step, c.state.step);
    EXPECT_EQ(r.state.dt, c.state.dt);
    EXPECT_EQ(r.state.particles_removed, 42);
    EXPECT_EQ(r.state.wall_work, c.state.wall_work);
    EXPECT_EQ(r.state.internal_work, c.state.internal_work);
    EXPECT_EQ(r.state.external_work, c.state.external_work);
    EXPECT_TRUE(r.state.damping_released);
    ASSERT_EQ(r.state.groups.size(), 2u);
    EXPECT_EQ(r.state.groups[1].material, 2);
    EXPECT_EQ(r.state.groups[1].begin, n / 2);
    EXPECT_EQ(r.state.groups[1].end, n);
    EXPECT_EQ(r.state.groups[0].antilocking, -1);
    EXPECT_EQ(r.state.groups[1].antilocking, 3);
    EXPECT_TRUE(SameRigid(r.state.rigid, c.state.rigid));
    EXPECT_TRUE(SameRigid(r.bullet, c.bullet));
    EXPECT_TRUE(SameBytes(r.bulk_viscosity_q, c.bulk_viscosity_q));
    EXPECT_TRUE(SameBytes(r.bulk_viscosity_id, c.bulk_viscosity_id));
    EXPECT_EQ(r.bulk_viscosity_dt_bound, 2.5e-4);
    EXPECT_EQ(r.next_output, 0.15);
    EXPECT_EQ(r.next_checkpoint, 0.2);
    EXPECT_EQ(r.result.snapshots, 4);
    EXPECT_EQ(r.result.energy_rows, 1001);
    EXPECT_EQ(r.result.force_rows, 1000);
    EXPECT_EQ(r.result.rigid_rows, 999);
    EXPECT_EQ(r.result.force_samples, 1000);
    ASSERT_EQ(r.result.force_peaks.size(), 2u);
    const StructurePeak& a = r.result.force_peaks[0];
    EXPECT_EQ(a.peak_force, 12.5);
    EXPECT_EQ(a.peak_time, 0.0625);
    EXPECT_EQ(a.force_at_peak, c.result.force_peaks[0].force_at_peak);
    EXPECT_EQ(a.impulse, c.result.force_peaks[0].impulse);
    EXPECT_EQ(a.peak_contact_area, 3);
    EXPECT_EQ(a.peak_wetted_height, 0.75);
    ASSERT_EQ(a.faces.size(), 2u);
    EXPECT_EQ(a.faces[1].impulse, c.result.force_peaks[0].faces[1].impulse);
    EXPECT_TRUE(std::isnan(r.result.force_peaks[1].peak_time));
    EXPECT_TRUE(r.result.force_peaks[1].faces.empty());
    EXPECT_EQ(r.name, "dam");
    EXPECT_EQ(r.scene_path, "scenes/dam.yaml");
    EXPECT_EQ(r.scene_text, c.scene_text);
    EXPECT_EQ(r.resolved_yaml, c.resolved_yaml);
    EXPECT_EQ(r.scene_hash, SceneHash(c.scene_text));
    EXPECT_EQ(r.resolved_hash, SceneHash(c.resolved_yaml));
    EXPECT_EQ(r.version, "0.1");
    EXPECT_EQ(r.git_hash, "abc");
  }
}

TEST_F(CheckpointTest, WrittenWholeOrNotAtAll) {
  Checkpoint c = FullCheckpoint(10);
  const std::string path = CheckpointPath(dir_.string(), "dam", 5);
  WriteCheckpoint(path, c);
  c.state.time = 7;
  WriteCheckpoint(path, c);  // replaces the file
  EXPECT_EQ(ReadCheckpoint(path).state.time, 7);
  EXPECT_FALSE(fs::exists(path + ".tmp"));
  // An unwritable folder: IoError naming the file, nothing under the final name.
  const std::string blocked = (dir_ / "file" / "checkpoints" / "x_step_000000001.h5").string();
  std::ofstream(dir_ / "file") << "a file, not a folder";
  EXPECT_THROW(WriteCheckpoint(blocked, c), IoError);
}

TEST_F(CheckpointTest, ForeignFilesAreRefusedNamingThePath) {
  const auto expect_error = [](const std::string& path, const std::string& fragment) {
    try {
      ReadCheckpoint(path);
      ADD_FAILURE() << "no IoError for " << path;
    } catch (const IoError& e) {
      EXPECT_NE(std::string(e.what()).find(fragment), std::string::npos) << e.what();
      EXPECT_NE(std::string(e.what()).find(path), std::string::npos) << e.what();
    }
  };
  expect_error((dir_ / "missing.h5").string(), "no such file");
  std::ofstream(dir_ / "text.h5") << "not hdf5";
  expect_error((dir_ / "text.h5").string(), "not an HDF5 file");
  Model m;
  m.name = "result";
  m.dx = 0.5;
  { ResultsWriter w(dir_.string(), "result", RunMetadata{}, m); }
  expect_error((dir_ / "result.h5").string(), "not a Surge checkpoint");
}

// A checkpoint carries the FNV-1a hash and length of its bytes (an HDF5 user block), checked
// before HDF5 opens it: a flipped byte, a cut-off or lengthened file and a damaged header are
// each refused naming the file, and never reach libhdf5 (which on some corrupt files reads out of
// bounds or allocates without limit: docs/robustness.md).
TEST_F(CheckpointTest, DamagedFilesAreRefusedBeforeHdf5ReadsThem) {
  const Checkpoint c = FullCheckpoint(6);
  const std::string good = (dir_ / "good.h5").string();
  WriteCheckpoint(good, c);
  EXPECT_EQ(ReadCheckpoint(good).state.particles.size(), 6u);
  std::string bytes;
  {
    std::ifstream in(good, std::ios::binary);
    bytes.assign(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
  }
  ASSERT_EQ(bytes.compare(0, 25, "surge-checkpoint fnv1a64 "), 0) << bytes.substr(0, 40);
  const auto variant = [&](const std::string& name, std::string data, const std::string& fragment) {
    const std::string path = (dir_ / name).string();
    std::ofstream(path, std::ios::binary) << data;
    try {
      ReadCheckpoint(path);
      ADD_FAILURE() << "no IoError for " << name;
    } catch (const IoError& e) {
      EXPECT_NE(std::string(e.what()).find(path), std::string::npos) << e.what();
      EXPECT_NE(std::string(e.what()).find(fragment), std::string::npos) << e.what();
    }
  };
  std::string flipped = bytes;
  flipped[bytes.size() / 2] ^= 0x10;
  variant("flipped.h5", flipped, "is damaged: content hash");
  variant("cut.h5", bytes.substr(0, bytes.size() - 100), "bytes after its header");
  variant("longer.h5", bytes + "x", "bytes after its header");
  std::string header = bytes;
  header[3] = 'X';  // the tag: no checksum block, though HDF5 would read the rest
  variant("header.h5", header, "checksum header is missing");
}

// Replaces attribute `name` of `loc` in `file` by an int64 array of `n` elements (a scalar read
// of it wrote n values into one).
void ReplaceWithArrayAttr(const std::string& file, const char* loc, const char* name, hsize_t n) {
  const hid_t f = H5Fopen(file.c_str(), H5F_ACC_RDWR, H5P_DEFAULT);
  const hid_t o = H5Oopen(f, loc, H5P_DEFAULT);
  H5Adelete(o, name);
  const hid_t space = H5Screate_simple(1, &n, nullptr);
  const hid_t a = H5Acreate2(o, name, H5T_STD_I64LE, space, H5P_DEFAULT, H5P_DEFAULT);
  const std::vector<int64_t> v(n, 1);
  H5Awrite(a, H5T_NATIVE_INT64, v.data());
  H5Aclose(a);
  H5Sclose(space);
  H5Oclose(o);
  H5Fclose(f);
}

// Shapes the reader used to trust (an attribute read as a scalar, a dataset's rank): a crafted or
// corrupt file gave a stack or heap overflow; now an IoError naming the file (fuzz_io checks).
// The files are edited through HDF5, so their checksum no longer matches: read without it, to
// test what lies behind it.
// A FLIP run without linear_elastic, plastic models or tractions holds no C, strain, b^e, history
// or ext_force (Particles::layout): the checkpoint stores only the arrays held, and reading it gives
// the same layout back with the others empty.
TEST_F(CheckpointTest, OptionalArraysRoundTripByLayout) {
  for (int mask = 0; mask < 32; ++mask) {
    Checkpoint c = FullCheckpoint(6);
    Particles& P = c.state.particles;
    // The history's stride varies with the mask: a run stores only its models' slots.
    P.layout = ParticleLayout{bool(mask & 16), bool(mask & 1), bool(mask & 2), bool(mask & 4),
                              bool(mask & 8), 1 + mask % kHistorySlots};
    P.Resize(3);  // drops the arrays the layout does not hold
    ASSERT_EQ(P.history.size(), (mask & 4) ? 3u : 0u);
    if (mask & 4) {
      ASSERT_EQ(P.history.stride(), 1 + mask % kHistorySlots);
    }
    ASSERT_EQ(P.strain.size(), (mask & 1) ? 3u : 0u);
    ASSERT_EQ(P.ext_force.size(), (mask & 8) ? 3u : 0u);
    c.state.groups = {{0, 0, 3}};
    c.bulk_viscosity_q.resize(3);
    c.bulk_viscosity_id.resize(3);
    const std::string path = (dir_ / ("lean" + std::to_string(mask) + ".h5")).string();
    WriteCheckpoint(path, c);
    const Checkpoint r = ReadCheckpoint(path);
    const Particles& Q = r.state.particles;
    EXPECT_EQ(Q.layout.affine, P.layout.affine) << mask;
    EXPECT_EQ(Q.layout.strain, P.layout.strain) << mask;
    EXPECT_EQ(Q.layout.elastic_b, P.layout.elastic_b) << mask;
    EXPECT_EQ(Q.layout.history, P.layout.history) << mask;
    if (P.layout.history) {
      EXPECT_EQ(Q.layout.history_slots, P.layout.history_slots) << mask;
    }
    EXPECT_EQ(Q.layout.ext_force, P.layout.ext_force) << mask;
    EXPECT_TRUE(SameBytes(P.x, Q.x) && SameBytes(P.C, Q.C) && SameBytes(P.strain, Q.strain) &&
                SameBytes(P.elastic_b, Q.elastic_b) && SameBytes(P.history, Q.history) &&
                SameBytes(P.ext_force, Q.ext_force) && SameBytes(P.id, Q.id))
        << mask;
  }
}

// Checkpoints written before 2026-12-03 hold the stress as (N, 9) column-major matrices; they are
// still read, into the 6 stored components (the file is edited through HDF5, so it is read
// without its checksum).
TEST_F(CheckpointTest, NineComponentStressAndElasticBOfOlderCheckpointsAreRead) {
  const Checkpoint c = FullCheckpoint(5);
  const std::string path = (dir_ / "nine.h5").string();
  WriteCheckpoint(path, c);
  std::vector<Mat3> full(5), b(5);
  for (size_t p = 0; p < 5; ++p) {
    full[p] = Mat3(c.state.particles.stress[p]) + Mat3::Identity();
    b[p] = Mat3(c.state.particles.elastic_b[p]) + 2 * Mat3::Identity();  // symmetric, as written
  }
  {  // both symmetric arrays as the full matrices that checkpoints before 2026-12-03 held
    const hid_t f = H5Fopen(path.c_str(), H5F_ACC_RDWR, H5P_DEFAULT);
    for (const auto& [name, data] : {std::pair{"particles/stress", &full}, std::pair{"particles/elastic_b", &b}}) {
      H5Ldelete(f, name, H5P_DEFAULT);
      const hsize_t dims[2] = {5, 9};
      const hid_t space = H5Screate_simple(2, dims, nullptr);
      const hid_t d =
          H5Dcreate2(f, name, H5T_IEEE_F64LE, space, H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT);
      H5Dwrite(d, H5T_NATIVE_DOUBLE, H5S_ALL, H5S_ALL, H5P_DEFAULT, data->data());
      H5Dclose(d);
      H5Sclose(space);
    }
    H5Fclose(f);
  }
  const Checkpoint r = ReadCheckpoint(path, /*verify_checksum=*/false);
  ASSERT_EQ(r.state.particles.elastic_b.size(), 5u);
  for (size_t p = 0; p < 5; ++p) {
    for (int i = 0; i < 3; ++i) {
      for (int j = 0; j < 3; ++j) {
        if (!std::isnan(b[p](i, j))) {
          EXPECT_EQ(r.state.particles.elastic_b[p](i, j), b[p](i, j));
        }
      }
    }
  }
  ASSERT_EQ(r.state.particles.stress.size(), 5u);
  for (size_t p = 0; p < 5; ++p) {
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j)
        if (std::isnan(full[p](i, j)))  // FullCheckpoint's NaN in particle 0 (yz)
          EXPECT_TRUE(std::isnan(r.state.particles.stress[p](i, j))) << p << " " << i << j;
        else
          EXPECT_EQ(r.state.particles.stress[p](i, j), full[p](i, j)) << p << " " << i << j;
  }
}

// Checkpoints written before per-body anti-locking hold (material, begin, end) per group: each
// group then has its material's own setting.
TEST_F(CheckpointTest, ThreeColumnGroupsOfOlderCheckpointsAreRead) {
  Checkpoint c = FullCheckpoint(6);
  c.state.groups = {{0, 0, 2}, {1, 2, 6, 4}};
  const std::string path = (dir_ / "groups3.h5").string();
  WriteCheckpoint(path, c);
  {
    const hid_t f = H5Fopen(path.c_str(), H5F_ACC_RDWR, H5P_DEFAULT);
    H5Ldelete(f, "groups", H5P_DEFAULT);
    const int64_t rows[2][3] = {{0, 0, 2}, {1, 2, 6}};
    const hsize_t dims[2] = {2, 3};
    const hid_t space = H5Screate_simple(2, dims, nullptr);
    const hid_t d = H5Dcreate2(f, "groups", H5T_STD_I64LE, space, H5P_DEFAULT, H5P_DEFAULT,
                               H5P_DEFAULT);
    H5Dwrite(d, H5T_NATIVE_INT64, H5S_ALL, H5S_ALL, H5P_DEFAULT, rows);
    H5Dclose(d);
    H5Sclose(space);
    H5Fclose(f);
  }
  const Checkpoint r = ReadCheckpoint(path, /*verify_checksum=*/false);
  ASSERT_EQ(r.state.groups.size(), 2u);
  EXPECT_EQ(r.state.groups[1].material, 1);
  EXPECT_EQ(r.state.groups[1].end, 6u);
  EXPECT_EQ(r.state.groups[1].antilocking, -1);
  EXPECT_EQ(r.state.groups[1].AntiLockingIndex(), 1);
  // And the current form keeps the setting.
  const std::string now = (dir_ / "groups4.h5").string();
  WriteCheckpoint(now, c);
  EXPECT_EQ(ReadCheckpoint(now).state.groups[1].antilocking, 4);
}

TEST_F(CheckpointTest, MalformedShapesAreRefusedNamingThePath) {
  const Checkpoint c = FullCheckpoint(4);
  const auto expect_error = [](const std::string& path) {
    EXPECT_THROW(ReadCheckpoint(path), IoError) << path;  // the checksum, first
    try {
      ReadCheckpoint(path, /*verify_checksum=*/false);
      ADD_FAILURE() << "no IoError for " << path;
    } catch (const IoError& e) {
      EXPECT_NE(std::string(e.what()).find(path), std::string::npos) << e.what();
    }
  };
  const std::string step = (dir_ / "step.h5").string();
  WriteCheckpoint(step, c);
  ReplaceWithArrayAttr(step, "/", "step", 64);
  expect_error(step);
  const std::string name = (dir_ / "name.h5").string();  // a list of strings, not one
  WriteCheckpoint(name, c);
  {
    const hid_t f = H5Fopen(name.c_str(), H5F_ACC_RDWR, H5P_DEFAULT);
    H5Adelete(f, "name");
    const hid_t type = H5Tcopy(H5T_C_S1);
    H5Tset_size(type, 4);
    const hsize_t n = 16;
    const hid_t space = H5Screate_simple(1, &n, nullptr);
    const hid_t a = H5Acreate2(f, "name", type, space, H5P_DEFAULT, H5P_DEFAULT);
    const std::string text(64, 'x');
    H5Awrite(a, type, text.data());
    H5Aclose(a);
    H5Sclose(space);
    H5Tclose(type);
    H5Fclose(f);
  }
  expect_error(name);
  const std::string rank = (dir_ / "rank.h5").string();  // particles/x of rank 4
  WriteCheckpoint(rank, c);
  {
    const hid_t f = H5Fopen(rank.c_str(), H5F_ACC_RDWR, H5P_DEFAULT);
    H5Ldelete(f, "particles/x", H5P_DEFAULT);
    const hsize_t dims[4] = {4, 3, 2, 2};
    const hid_t space = H5Screate_simple(4, dims, nullptr);
    const hid_t d = H5Dcreate2(f, "particles/x", H5T_IEEE_F64LE, space, H5P_DEFAULT, H5P_DEFAULT,
                               H5P_DEFAULT);
    const std::vector<double> v(48, 0.5);
    H5Dwrite(d, H5T_NATIVE_DOUBLE, H5S_ALL, H5S_ALL, H5P_DEFAULT, v.data());
    H5Dclose(d);
    H5Sclose(space);
    H5Fclose(f);
  }
  expect_error(rank);
}

TEST_F(CheckpointTest, ListedOldestFirst) {
  const Checkpoint c = FullCheckpoint(1);
  for (int64_t step : {1000, 20, 300}) WriteCheckpoint(CheckpointPath(dir_.string(), "dam", step), c);
  WriteCheckpoint(CheckpointPath(dir_.string(), "dam_b", 1), c);  // another run's name
  std::ofstream(dir_ / "checkpoints" / "dam_step_000000400.h5.tmp") << "partial";
  const std::vector<std::string> list = ListCheckpoints(dir_.string(), "dam");
  ASSERT_EQ(list.size(), 3u);
  EXPECT_EQ(fs::path(list[0]).filename(), "dam_step_000000020.h5");
  EXPECT_EQ(fs::path(list[2]).filename(), "dam_step_000001000.h5");
  EXPECT_TRUE(ListCheckpoints((dir_ / "none").string(), "dam").empty());
}

size_t CsvLines(const std::string& path) {
  std::ifstream in(path);
  size_t n = 0;
  for (std::string line; std::getline(in, line);) ++n;
  return n;
}

hsize_t Rows(hid_t f, const char* name) {
  const hid_t ds = H5Dopen2(f, name, H5P_DEFAULT);
  const hid_t space = H5Dget_space(ds);
  hsize_t dims[2] = {0, 0};
  H5Sget_simple_extent_dims(space, dims, nullptr);
  H5Sclose(space);
  H5Dclose(ds);
  return dims[0];
}

// Writes `rows` steps of forces and rigid rows, a snapshot every 10 steps.
void WriteSteps(ResultsWriter& w, State& s, int from, int to) {
  for (int k = from; k < to; ++k) {
    s.time = 0.01 * (k + 1);
    s.step = k + 1;
    ContactReport r;
    r.structures.resize(1);
    r.structures[0].force = Vec3(k, -k, 0.5 * k);
    r.structures[0].faces.resize(1);
    r.structures[0].faces[0].force = Vec3(k, 0, 0);
    w.AppendEnergy(EnergyRecord{s.time, s.step, 0.01, double(k), 0, 0, 0});
    w.AppendForces(s.time, s.step, 0.01, r);
    s.rigid[0].position.x() = 0.001 * k;
    w.AppendRigid(s.time, s.step, s.rigid);
    if ((k + 1) % 10 == 0) w.WriteSnapshot(s);
  }
}

TEST_F(CheckpointTest, ResumedResultIsCutBackToTheCheckpoint) {
  Model m;
  m.name = "run";
  m.dx = 0.5;
  const std::vector<ForceChannel> channels = {{"wall", {"front"}}};
  State s;
  s.particles.Resize(3);
  for (Mat3& F : s.particles.F) F = Mat3::Identity();
  s.rigid.resize(1);
  ResultPosition at;
  {
    ResultsWriter w(dir_.string(), "run", RunMetadata{}, m);
    w.BeginForces(channels);
    w.BeginRigid({"box"});
    w.WriteSnapshot(s);
    WriteSteps(w, s, 0, 25);
    at = w.Flush();
    WriteSteps(w, s, 25, 47);  // the part a restart redoes
    w.WriteSnapshot(s);
    w.Close(StageSeconds{}, 47, 1.0, "interrupted");
  }
  EXPECT_EQ(at.snapshots, 3);
  EXPECT_EQ(at.energy_rows, 25);
  EXPECT_EQ(at.force_rows, 25);
  EXPECT_EQ(at.rigid_rows, 25);
  EXPECT_EQ(at.force_samples, 25);
  ASSERT_EQ(at.force_peaks.size(), 1u);
  EXPECT_EQ(at.force_peaks[0].peak_time, 0.25);
  {
    ResultsWriter w(dir_.string(), "run", m, at);
    w.BeginForces(channels);
    w.BeginRigid({"box"});
    EXPECT_EQ(w.snapshot_count(), 3);
    EXPECT_EQ(w.force_summary().samples(), 25);
    EXPECT_EQ(w.force_summary().structure(0).peak_time, 0.25);
    EXPECT_EQ(CsvLines(w.forces_csv_path("wall")), 26u);  // header + 25 rows
    EXPECT_EQ(CsvLines(w.rigid_csv_path("box")), 26u);
    s.step = 25;
    WriteSteps(w, s, 25, 30);
    w.Close(StageSeconds{}, 30, 1.0, "completed");
  }
  const hid_t f = H5Fopen((dir_ / "run.h5").c_str(), H5F_ACC_RDONLY, H5P_DEFAULT);
  ASSERT_GE(f, 0);
  EXPECT_EQ(Rows(f, "/energy/time"), 30u);
  EXPECT_EQ(Rows(f, "/forces/wall/force"), 30u);
  EXPECT_EQ(Rows(f, "/forces/wall/faces/front/contact_nodes"), 30u);
  EXPECT_EQ(Rows(f, "/rigid/box/position"), 30u);
  EXPECT_GT(H5Lexists(f, "/snapshots/000003", H5P_DEFAULT), 0);  // written at step 30
  EXPECT_EQ(H5Lexists(f, "/snapshots/000004", H5P_DEFAULT), 0);  // the old run's, removed
  H5Fclose(f);
  const StoredResult r = ReadResultForces((dir_ / "run.h5").string());
  EXPECT_EQ(r.exit_status, "completed");
  ASSERT_EQ(r.structures.size(), 1u);
  EXPECT_EQ(r.structures[0].time.size(), 30u);
  EXPECT_EQ(r.structures[0].force[29], Vec3(29, -29, 14.5));
  EXPECT_EQ(CsvLines((dir_ / "forces_wall.csv").string()), 31u);
  EXPECT_EQ(CsvLines((dir_ / "rigid_box.csv").string()), 31u);

  // A position beyond what the result holds is refused.
  ResultPosition beyond = at;
  beyond.force_rows = 1000;
  try {
    ResultsWriter w(dir_.string(), "run", m, beyond);
    w.BeginForces(channels);
    ADD_FAILURE() << "no IoError for a result shorter than the checkpoint";
  } catch (const IoError& e) {
    EXPECT_NE(std::string(e.what()).find("fewer than the checkpoint's 1000"), std::string::npos)
        << e.what();
  }
  EXPECT_THROW(ResultsWriter((dir_ / "elsewhere").string(), "run", m, at), IoError);
  EXPECT_THROW(ResultsWriter(dir_.string(), "../run", RunMetadata{}, m), IoError);
}

TEST(CheckpointSceneKeysTest, DefaultsRangesAndResolvedScene) {
  const std::string base =
      "name: t\n"
      "dimension: 2\n"
      "time: {end: 1.0}\n"
      "grid: {cell_size: 0.25}\n"
      "domain: {min: [0, 0], max: [2, 2]}\n"
      "materials:\n"
      "  m: {model: linear_elastic, density: 1000, youngs_modulus: 1.0e6, poisson_ratio: 0.3}\n"
      "bodies:\n"
      "  - {name: b, material: m, region: {box: {min: [0, 0], max: [1, 1]}}}\n";
  const LoadedScene plain = LoadSceneFromString(base, "t.yaml");
  EXPECT_EQ(plain.model.output.checkpoint_every, 0);
  EXPECT_EQ(plain.model.output.checkpoints_keep, 3);
  EXPECT_EQ(plain.resolved_yaml.find("checkpoint"), std::string::npos)
      << "defaults stay out of the resolved scene (sweep digests)";
  const LoadedScene set =
      LoadSceneFromString(base + "output: {checkpoint_every: 0.25, checkpoints_keep: 5}\n", "t.yaml");
  EXPECT_EQ(set.model.output.checkpoint_every, 0.25);
  EXPECT_EQ(set.model.output.checkpoints_keep, 5);
  const LoadedScene again = LoadSceneFromString(set.resolved_yaml, "resolved.yaml");
  EXPECT_EQ(again.model.output.checkpoint_every, 0.25);
  EXPECT_EQ(again.model.output.checkpoints_keep, 5);
  for (const char* bad : {"output: {checkpoint_every: -1}\n", "output: {checkpoints_keep: 0}\n",
                          "output: {checkpoints_keep: 2.5}\n"}) {
    try {
      LoadSceneFromString(base + bad, "t.yaml");
      ADD_FAILURE() << "accepted " << bad;
    } catch (const SceneError& e) {
      EXPECT_NE(std::string(e.what()).find("t.yaml:10:"), std::string::npos) << e.what();
      EXPECT_NE(std::string(e.what()).find("output.checkpoint"), std::string::npos) << e.what();
    }
  }
}

}  // namespace
}  // namespace surge
