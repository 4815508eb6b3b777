// ResultsWriter: layout, values, verbatim scene text, energy rows, timing, XDMF, crash safety
// (a child process killed after or during a snapshot), errors; force series (HDF5 and CSV, flush
// cadence, kill, summary attributes); rigid-body series (HDF5 and CSV, flush cadence, kill,
// misuse) and RotationQuaternion; StrainInvariants.
#include "io/results_writer.h"

#include <gtest/gtest.h>
#include <hdf5.h>
#include <tbb/global_control.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <limits>
#include <numbers>
#include <random>
#include <sstream>
#include <thread>

namespace surge {
namespace {

namespace fs = std::filesystem;

constexpr double kEps = std::numeric_limits<double>::epsilon();
// Energy rows the writer buffers before writing them without a snapshot (hdf5_writer.cpp).
constexpr size_t kFlushRows = 1024;
// Force rows likewise (the cadence promised in results_writer.h).
constexpr size_t kForceFlushRows = 1000;

Model TinyModel(int dim = 3) {
  Model m;
  m.name = "tiny";
  m.dim = dim;
  m.dx = 0.5;
  return m;
}

// n particles: x = (p, 2p, -1), v = (1, 0, 0), F = I, zero stress, body p % 2, id 100 + p;
// particle 0 has F = diag(1.1, 1, 1) and sigma = -3 I plus a 2 Pa xy shear.
State TinyState(size_t n) {
  State s;
  Particles& P = s.particles;
  P.Resize(n);
  for (size_t p = 0; p < n; ++p) {
    P.x[p] = Vec3(double(p), 2.0 * double(p), -1.0);
    P.v[p] = Vec3(1, 0, 0);
    P.F[p] = Mat3::Identity();
    P.stress[p] = Mat3::Zero();
    P.material[p] = 0;
    P.body[p] = int32_t(p % 2);
    P.id[p] = int64_t(100 + p);
  }
  if (n > 0) {
    P.F[0](0, 0) = 1.1;
    Mat3 s = -3.0 * Mat3::Identity();
    s(0, 1) = s(1, 0) = 2.0;
    s(1, 2) = s(2, 1) = 0.5;  // yz
    s(0, 2) = s(2, 0) = 0.25;  // xz
    P.stress[0] = s;
  }
  return s;
}

// --- Readers (HDF5 C API) ---

std::vector<hsize_t> Dims(hid_t file, const std::string& path) {
  hid_t ds = H5Dopen2(file, path.c_str(), H5P_DEFAULT);
  if (ds < 0) return {};
  hid_t space = H5Dget_space(ds);
  std::vector<hsize_t> d(H5Sget_simple_extent_ndims(space));
  H5Sget_simple_extent_dims(space, d.data(), nullptr);
  H5Sclose(space);
  H5Dclose(ds);
  return d;
}

template <typename T>
std::vector<T> Read(hid_t file, const std::string& path, hid_t mem_type) {
  hid_t ds = H5Dopen2(file, path.c_str(), H5P_DEFAULT);
  EXPECT_GE(ds, 0) << path;
  if (ds < 0) return {};
  hsize_t n = 1;
  for (hsize_t d : Dims(file, path)) n *= d;
  std::vector<T> out(n);
  if (n) {
    EXPECT_GE(H5Dread(ds, mem_type, H5S_ALL, H5S_ALL, H5P_DEFAULT, out.data()), 0) << path;
  }
  H5Dclose(ds);
  return out;
}

std::vector<double> ReadDoubles(hid_t file, const std::string& path) {
  return Read<double>(file, path, H5T_NATIVE_DOUBLE);
}

std::string ReadStringDataset(hid_t file, const std::string& path) {
  hid_t ds = H5Dopen2(file, path.c_str(), H5P_DEFAULT);
  EXPECT_GE(ds, 0) << path;
  if (ds < 0) return {};
  hid_t type = H5Dget_type(ds);
  EXPECT_EQ(H5Tget_cset(type), H5T_CSET_UTF8) << path;
  std::string s(H5Tget_size(type), '\0');
  H5Dread(ds, type, H5S_ALL, H5S_ALL, H5P_DEFAULT, s.data());
  H5Tclose(type);
  H5Dclose(ds);
  while (!s.empty() && s.back() == '\0') s.pop_back();
  return s;
}

std::string ReadStringAttr(hid_t obj, const char* name) {
  hid_t attr = H5Aopen(obj, name, H5P_DEFAULT);
  EXPECT_GE(attr, 0) << name;
  if (attr < 0) return {};
  hid_t type = H5Aget_type(attr);
  std::string s(H5Tget_size(type), '\0');
  H5Aread(attr, type, s.data());
  H5Tclose(type);
  H5Aclose(attr);
  while (!s.empty() && s.back() == '\0') s.pop_back();
  return s;
}

template <typename T>
T ReadAttr(hid_t obj, const char* name, hid_t mem_type) {
  T value{};
  hid_t attr = H5Aopen(obj, name, H5P_DEFAULT);
  EXPECT_GE(attr, 0) << name;
  if (attr < 0) return value;
  H5Aread(attr, mem_type, &value);
  H5Aclose(attr);
  return value;
}

std::string ReadText(const fs::path& path) {
  std::ifstream in(path);
  std::stringstream text;
  text << in.rdbuf();
  return text.str();
}

size_t Count(const std::string& text, const std::string& what) {
  size_t count = 0;
  for (size_t at = text.find(what); at != std::string::npos; at = text.find(what, at + 1)) ++count;
  return count;
}

class ResultsWriterTest : public ::testing::Test {
 protected:
  void SetUp() override {
    const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
    dir_ = fs::temp_directory_path() /
           ("surge_io_" + std::to_string(getpid()) + "_" + info->name());
    fs::remove_all(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }
  fs::path dir_;
};

TEST_F(ResultsWriterTest, WritesLayoutValuesTimingAndXdmf) {
  RunMetadata meta;
  meta.scene_path = "scenes/tiny.yaml";
  meta.scene_text = "name: tiny  # ünïcode ✓ 应力\n\ttabs and \"quotes\" & <tags>\nline three\n";
  meta.resolved_yaml = "name: tiny\ngrid: {dx: 0.5}\n";
  meta.version = "0.1.0";
  meta.git_hash = "abc123";
  meta.command_line = "surge run scenes/tiny.yaml --threads 2";
  meta.start_time_utc = "2026-01-01T00:00:00Z";
  meta.threads = 2;
  StageSeconds seconds{};
  for (int s = 0; s < kStageCount; ++s) seconds[s] = 0.25 * s;
  {
    ResultsWriter w(dir_.string(), "tiny", meta, TinyModel());
    State s = TinyState(5);
    w.AppendEnergy(EnergyRecord{0.0, 0, 0.0, 1.0, 2.0, 3.0, 0.0});
    w.WriteSnapshot(s);
    s.time = 0.5;
    s.step = 7;
    s.particles.x[4].z() = 0.25;
    w.AppendEnergy(EnergyRecord{0.25, 3, 0.1, 1.25, 2.25, 3.25, -0.25});
    w.AppendEnergy(EnergyRecord{0.5, 7, 0.1, 1.5, 2.5, 3.5, -0.5, 4.75});
    w.WriteSnapshot(s);
    w.AppendEnergy(EnergyRecord{0.6, 8, 0.1, 1.0, 1.0, 1.0, 0.0});  // after the last snapshot
    EXPECT_EQ(w.snapshot_count(), 2);
    EXPECT_EQ(w.h5_path(), (dir_ / "tiny.h5").string());
    EXPECT_EQ(w.xmf_path(), (dir_ / "tiny.xmf").string());
    w.Close(seconds, 8, 1.25, "completed");
  }
  hid_t f = H5Fopen((dir_ / "tiny.h5").c_str(), H5F_ACC_RDONLY, H5P_DEFAULT);
  ASSERT_GE(f, 0);

  // Root attributes and metadata.
  EXPECT_EQ(ReadStringAttr(f, "version"), "0.1.0");
  EXPECT_EQ(ReadStringAttr(f, "git_hash"), "abc123");
  EXPECT_EQ(ReadStringAttr(f, "command_line"), meta.command_line);
  EXPECT_EQ(ReadStringAttr(f, "start_time_utc"), meta.start_time_utc);
  EXPECT_EQ(ReadStringAttr(f, "scene_path"), meta.scene_path);
  EXPECT_EQ(ReadAttr<int>(f, "threads", H5T_NATIVE_INT), 2);
  EXPECT_EQ(ReadAttr<int>(f, "dimension", H5T_NATIVE_INT), 3);
  EXPECT_EQ(ReadAttr<double>(f, "cell_size", H5T_NATIVE_DOUBLE), 0.5);
  EXPECT_EQ(ReadStringDataset(f, "/metadata/scene"), meta.scene_text);
  EXPECT_EQ(ReadStringDataset(f, "/metadata/resolved"), meta.resolved_yaml);

  // Snapshot attributes and shapes.
  hid_t g1 = H5Gopen2(f, "/snapshots/000001", H5P_DEFAULT);
  ASSERT_GE(g1, 0);
  EXPECT_EQ(ReadAttr<double>(g1, "time", H5T_NATIVE_DOUBLE), 0.5);
  EXPECT_EQ(ReadAttr<int64_t>(g1, "step", H5T_NATIVE_INT64), 7);
  H5Gclose(g1);
  const std::string s0 = "/snapshots/000000/";
  const std::string s1 = "/snapshots/000001/";
  EXPECT_EQ(Dims(f, s1 + "position"), (std::vector<hsize_t>{5, 3}));
  EXPECT_EQ(Dims(f, s1 + "velocity"), (std::vector<hsize_t>{5, 3}));
  EXPECT_EQ(Dims(f, s1 + "stress"), (std::vector<hsize_t>{5, 6}));
  for (const char* scalar : {"pressure", "von_mises", "strain_volumetric", "strain_equivalent",
                             "material", "body", "id", "plastic_strain"})
    EXPECT_EQ(Dims(f, s1 + scalar), (std::vector<hsize_t>{5})) << scalar;

  // Values.
  const auto pos = ReadDoubles(f, s1 + "position");
  EXPECT_EQ(pos[3 * 4 + 1], 8.0);
  EXPECT_EQ(pos[3 * 4 + 2], 0.25);
  EXPECT_EQ(ReadDoubles(f, s0 + "position")[3 * 4 + 2], -1.0);
  EXPECT_EQ(ReadDoubles(f, s0 + "velocity")[3 * 2], 1.0);
  const auto stress = ReadDoubles(f, s0 + "stress");  // xx yy zz xy yz xz (VTK order)
  EXPECT_EQ(std::vector<double>(stress.begin(), stress.begin() + 6),
            (std::vector<double>{-3, -3, -3, 2, 0.5, 0.25}));
  EXPECT_EQ(ReadDoubles(f, s0 + "pressure")[0], 3.0);
  // q = sqrt(3/2 s:s), s the deviator: only the shear pairs remain,
  // s:s = 2 (2^2 + 0.5^2 + 0.25^2) = 8.625, q = sqrt(12.9375).
  EXPECT_NEAR(ReadDoubles(f, s0 + "von_mises")[0], std::sqrt(12.9375), 8 * kEps);
  EXPECT_NEAR(ReadDoubles(f, s0 + "strain_volumetric")[0], std::log(1.1), 4 * kEps);
  // Hencky eps = diag(ln 1.1, 0, 0), e = ln 1.1 (2/3, -1/3, -1/3): sqrt(2/3 e:e) = 2/3 ln 1.1.
  EXPECT_NEAR(ReadDoubles(f, s0 + "strain_equivalent")[0], 2.0 / 3.0 * std::log(1.1), 4 * kEps);
  EXPECT_EQ(ReadDoubles(f, s0 + "strain_equivalent")[1], 0.0);
  EXPECT_EQ(ReadDoubles(f, s0 + "plastic_strain"), std::vector<double>(5, 0.0));
  EXPECT_EQ(Read<int32_t>(f, s1 + "body", H5T_NATIVE_INT32),
            (std::vector<int32_t>{0, 1, 0, 1, 0}));
  EXPECT_EQ(Read<int64_t>(f, s1 + "id", H5T_NATIVE_INT64),
            (std::vector<int64_t>{100, 101, 102, 103, 104}));

  // Energy: every appended row, including the one after the last snapshot.
  const auto time = ReadDoubles(f, "/energy/time");
  EXPECT_EQ(time, (std::vector<double>{0.0, 0.25, 0.5, 0.6}));
  EXPECT_EQ(ReadDoubles(f, "/energy/step"), (std::vector<double>{0, 3, 7, 8}));
  EXPECT_EQ(ReadDoubles(f, "/energy/wall_work")[2], -0.5);
  EXPECT_EQ(ReadDoubles(f, "/energy/total")[2], 1.5 + 2.5 + 3.5);
  EXPECT_EQ(ReadDoubles(f, "/energy/internal_work")[2], 4.75);
  for (const char* column : {"dt", "kinetic", "strain", "gravitational", "internal_work"})
    EXPECT_EQ(Dims(f, std::string("/energy/") + column), (std::vector<hsize_t>{4})) << column;

  // Timing.
  hid_t t = H5Gopen2(f, "/timing", H5P_DEFAULT);
  ASSERT_GE(t, 0);
  for (int s = 0; s < kStageCount; ++s)
    EXPECT_EQ(ReadAttr<double>(t, StageName(Stage(s)), H5T_NATIVE_DOUBLE), 0.25 * s);
  EXPECT_EQ(ReadAttr<int64_t>(t, "steps", H5T_NATIVE_INT64), 8);
  EXPECT_EQ(ReadAttr<double>(t, "wall_seconds", H5T_NATIVE_DOUBLE), 1.25);
  EXPECT_EQ(ReadStringAttr(t, "exit_status"), "completed");
  H5Gclose(t);
  H5Fclose(f);

  // XDMF: relative references, one grid per snapshot, every field.
  const std::string x = ReadText(dir_ / "tiny.xmf");
  EXPECT_NE(x.find(">tiny.h5:/snapshots/000001/position<"), std::string::npos);
  EXPECT_EQ(x.find(dir_.string()), std::string::npos) << "no absolute paths in the .xmf";
  EXPECT_EQ(Count(x, "GridType=\"Uniform\""), 2u);
  EXPECT_EQ(Count(x, "CollectionType=\"Temporal\""), 1u);
  EXPECT_EQ(Count(x, "TopologyType=\"Polyvertex\" NumberOfElements=\"5\""), 2u);
  EXPECT_NE(x.find("<Time Value=\"0.5\"/>"), std::string::npos);
  EXPECT_NE(x.find("AttributeType=\"Tensor6\""), std::string::npos);
  for (const char* name : {"velocity", "stress", "pressure", "von_mises", "strain_volumetric",
                           "strain_equivalent", "material", "body", "id"})
    EXPECT_EQ(Count(x, std::string("Attribute Name=\"") + name + "\""), 2u) << name;
  EXPECT_FALSE(fs::exists(dir_ / "tiny.xmf.tmp"));
}

TEST_F(ResultsWriterTest, TwoDimensionalRunsKeepThreeComponents) {
  {
    ResultsWriter w(dir_.string(), "plane", RunMetadata{}, TinyModel(/*dim=*/2));
    State s = TinyState(3);
    for (Vec3& x : s.particles.x) x.z() = 0;
    w.WriteSnapshot(s);
    w.Close(StageSeconds{}, 0, 0, "completed");
  }
  hid_t f = H5Fopen((dir_ / "plane.h5").c_str(), H5F_ACC_RDONLY, H5P_DEFAULT);
  ASSERT_GE(f, 0);
  EXPECT_EQ(ReadAttr<int>(f, "dimension", H5T_NATIVE_INT), 2);
  EXPECT_EQ(Dims(f, "/snapshots/000000/position"), (std::vector<hsize_t>{3, 3}));
  EXPECT_EQ(ReadDoubles(f, "/snapshots/000000/position")[3 * 2 + 2], 0.0);
  H5Fclose(f);
}

TEST_F(ResultsWriterTest, EmptySnapshotAndLargeCompressedSnapshot) {
  const size_t n = 10000;  // above the compression threshold: chunked + deflated
  {
    ResultsWriter w(dir_.string(), "sizes", RunMetadata{}, TinyModel());
    w.WriteSnapshot(TinyState(0));
    w.WriteSnapshot(TinyState(n));
    w.Close(StageSeconds{}, 0, 0, "completed");
  }
  hid_t f = H5Fopen((dir_ / "sizes.h5").c_str(), H5F_ACC_RDONLY, H5P_DEFAULT);
  ASSERT_GE(f, 0);
  EXPECT_EQ(Dims(f, "/snapshots/000000/position"), (std::vector<hsize_t>{0, 3}));
  EXPECT_EQ(Dims(f, "/snapshots/000000/id"), (std::vector<hsize_t>{0}));
  const auto pos = ReadDoubles(f, "/snapshots/000001/position");
  ASSERT_EQ(pos.size(), 3 * n);
  EXPECT_EQ(pos[3 * (n - 1) + 1], 2.0 * double(n - 1));
  EXPECT_EQ(Read<int64_t>(f, "/snapshots/000001/id", H5T_NATIVE_INT64).back(),
            int64_t(100 + n - 1));
  H5Fclose(f);
}

// A snapshot of ten chunks, the last an edge chunk (150 000 particles: 16 384 rows a chunk),
// whose chunks the writer shuffles and deflates itself on the worker threads (H5Dwrite_chunk),
// in batches of 4 chunks per thread (three batches on 1 thread, two on 2): HDF5 reads every
// array back through its own shuffle and deflate filters bit for bit, and the arrays are stored
// compressed.
TEST_F(ResultsWriterTest, SelfDeflatedChunksReadBackThroughTheFilters) {
  const size_t n = 150000;
  State s = TinyState(n);
  std::mt19937_64 rng(7);
  std::normal_distribution<double> noise(0.0, 1.0);
  for (size_t p = 0; p < n; ++p) {
    s.particles.x[p] = Vec3(noise(rng), 0.01 * double(p), 3.0 + noise(rng));
    s.particles.v[p] = Vec3(noise(rng), -noise(rng), 1e-3 * noise(rng));
    Mat3 t;
    t << noise(rng), noise(rng), noise(rng), 0, noise(rng), noise(rng), 0, 0, noise(rng);
    s.particles.stress[p] = Mat3(1e4 * (t + t.transpose()));
    s.particles.material[p] = int32_t(p % 3);
  }
  for (const int threads : {1, 2}) {
    const std::string name = "chunks" + std::to_string(threads);
    {
      tbb::global_control limit(tbb::global_control::max_allowed_parallelism, threads);
      ResultsWriter w(dir_.string(), name, RunMetadata{}, TinyModel());
      w.WriteSnapshot(s);
      w.Close(StageSeconds{}, 0, 0, "completed");
    }
    hid_t f = H5Fopen((dir_ / (name + ".h5")).c_str(), H5F_ACC_RDONLY, H5P_DEFAULT);
    ASSERT_GE(f, 0);
    const auto pos = ReadDoubles(f, "/snapshots/000000/position");
    const auto vel = ReadDoubles(f, "/snapshots/000000/velocity");
    const auto stress = ReadDoubles(f, "/snapshots/000000/stress");
    const auto ids = Read<int64_t>(f, "/snapshots/000000/id", H5T_NATIVE_INT64);
    const auto materials = Read<int32_t>(f, "/snapshots/000000/material", H5T_NATIVE_INT32);
    ASSERT_EQ(pos.size(), 3 * n);
    ASSERT_EQ(stress.size(), 6 * n);
    ASSERT_EQ(ids.size(), n);
    for (size_t p = 0; p < n; ++p) {
      for (int d = 0; d < 3; ++d) {
        ASSERT_EQ(pos[3 * p + size_t(d)], s.particles.x[p][d]) << p;
        ASSERT_EQ(vel[3 * p + size_t(d)], s.particles.v[p][d]) << p;
      }
      for (int k = 0; k < 6; ++k)
        ASSERT_EQ(stress[6 * p + size_t(k)], s.particles.stress[p].v[k]) << p;
      ASSERT_EQ(ids[p], s.particles.id[p]) << p;
      ASSERT_EQ(materials[p], s.particles.material[p]) << p;
    }
    // The pipeline a reader sees: shuffle, then deflate; 16 384-row chunks; stored compressed.
    hid_t ds = H5Dopen2(f, "/snapshots/000000/stress", H5P_DEFAULT);
    hid_t plist = H5Dget_create_plist(ds);
    ASSERT_EQ(H5Pget_nfilters(plist), 2);
    unsigned flags = 0, values[4];
    size_t nvalues = 4;
    EXPECT_EQ(H5Pget_filter2(plist, 0, &flags, &nvalues, values, 0, nullptr, nullptr),
              H5Z_FILTER_SHUFFLE);
    nvalues = 4;
    EXPECT_EQ(H5Pget_filter2(plist, 1, &flags, &nvalues, values, 0, nullptr, nullptr),
              H5Z_FILTER_DEFLATE);
    hsize_t chunk[2] = {0, 0};
    EXPECT_EQ(H5Pget_chunk(plist, 2, chunk), 2);
    EXPECT_EQ(chunk[0], 16384u);
    EXPECT_LT(H5Dget_storage_size(ds), 6 * n * sizeof(double));
    H5Pclose(plist);
    H5Dclose(ds);
    H5Fclose(f);
  }
}

TEST_F(ResultsWriterTest, DestructorWithoutCloseKeepsSnapshotsAndEnergy) {
  {
    ResultsWriter w(dir_.string(), "unclosed", RunMetadata{}, TinyModel());
    w.WriteSnapshot(TinyState(2));
    w.AppendEnergy(EnergyRecord{});
    w.AppendEnergy(EnergyRecord{});
  }
  hid_t f = H5Fopen((dir_ / "unclosed.h5").c_str(), H5F_ACC_RDONLY, H5P_DEFAULT);
  ASSERT_GE(f, 0);
  EXPECT_EQ(ReadDoubles(f, "/energy/time").size(), 2u);
  EXPECT_EQ(H5Lexists(f, "/timing", H5P_DEFAULT), 0) << "no timing without Close";
  H5Fclose(f);
}

TEST_F(ResultsWriterTest, UseAfterCloseThrows) {
  ResultsWriter w(dir_.string(), "closed", RunMetadata{}, TinyModel());
  w.Close(StageSeconds{}, 0, 0, "completed");
  w.Close(StageSeconds{}, 0, 0, "completed");  // a second Close does nothing
  EXPECT_THROW(w.WriteSnapshot(TinyState(1)), IoError);
  EXPECT_THROW(w.AppendEnergy(EnergyRecord{}), IoError);
}

// The child writes and is killed without Close or destructors (_exit); the parent reads.
TEST_F(ResultsWriterTest, KilledRunKeepsCompletedSnapshotsAndEnergy) {
  const pid_t child = fork();
  ASSERT_GE(child, 0);
  if (child == 0) {
    ResultsWriter w(dir_.string(), "killed", RunMetadata{}, TinyModel());
    w.AppendEnergy(EnergyRecord{});
    w.WriteSnapshot(TinyState(3));
    // 1500 rows and no further snapshot: the first 1024 reach the file on their own.
    for (int i = 0; i < 1500; ++i) w.AppendEnergy(EnergyRecord{});
    _exit(0);
  }
  int status = 0;
  waitpid(child, &status, 0);
  ASSERT_TRUE(WIFEXITED(status));
  hid_t f = H5Fopen((dir_ / "killed.h5").c_str(), H5F_ACC_RDONLY, H5P_DEFAULT);
  ASSERT_GE(f, 0) << "the file of a killed run must stay readable";
  EXPECT_EQ(ReadDoubles(f, "/snapshots/000000/position").size(), 9u);
  EXPECT_EQ(ReadDoubles(f, "/energy/time").size(), 1u + kFlushRows);
  H5Fclose(f);
  EXPECT_EQ(Count(ReadText(dir_ / "killed.xmf"), "GridType=\"Uniform\""), 1u);
}

// SIGKILL at random moments, mostly in the middle of writing a snapshot: every snapshot that
// the .xmf lists must read back whole. A kill inside HDF5's flush can still break the file (see
// hdf5_writer.cpp, "Crash safety"); with 6000-particle snapshots, whose time goes to raw data,
// none of over 1000 kills by hand did, but a CI run met one (below).
TEST_F(ResultsWriterTest, SigkillDuringWritesLeavesListedSnapshotsReadable) {
  std::mt19937 rng(12345);
  std::uniform_int_distribution<int> delay_us(2000, 60000);
  const size_t n = 6000;  // above the compression threshold
  int trials_with_snapshots = 0, torn = 0;
  // 12 kills at 2-60 ms; on a loaded machine no snapshot may complete that soon, so up to 12 more
  // at 20-600 ms until one has.
  for (int trial = 0; trial < 24; ++trial) {
    if (trial >= 12 && trials_with_snapshots > 0) break;
    const std::string name = "run" + std::to_string(trial);
    const pid_t child = fork();
    ASSERT_GE(child, 0);
    if (child == 0) {
      ResultsWriter w(dir_.string(), name, RunMetadata{}, TinyModel());
      State s = TinyState(n);
      for (int k = 0;; ++k) {
        s.time = k;
        w.AppendEnergy(EnergyRecord{double(k), k, 1.0, 0, 0, 0, 0});
        w.WriteSnapshot(s);
      }
    }
    std::this_thread::sleep_for(std::chrono::microseconds(delay_us(rng) * (trial < 12 ? 1 : 10)));
    kill(child, SIGKILL);
    int status = 0;
    waitpid(child, &status, 0);
    const fs::path xmf = dir_ / (name + ".xmf");
    if (!fs::exists(xmf)) continue;  // killed before the first snapshot completed
    const size_t listed = Count(ReadText(xmf), "GridType=\"Uniform\"");
    ++trials_with_snapshots;
    // Every listed snapshot must read back whole. Read without the asserting helpers: a torn file
    // is counted, not failed, below.
    bool whole = true;
    hid_t f = H5Fopen((dir_ / (name + ".h5")).c_str(), H5F_ACC_RDONLY, H5P_DEFAULT);
    if (f < 0) whole = false;
    for (size_t k = 0; whole && k < listed; ++k) {
      char group[64];
      std::snprintf(group, sizeof group, "/snapshots/%06zu/", k);
      const std::string position = std::string(group) + "position", id = std::string(group) + "id";
      whole = Dims(f, position) == std::vector<hsize_t>{n, 3} &&
              Dims(f, id) == std::vector<hsize_t>{n};
      if (!whole) break;
      const auto pos = ReadDoubles(f, position);
      EXPECT_EQ(pos[3 * (n - 1)], double(n - 1)) << "trial " << trial << " snapshot " << k;
    }
    if (whole) {
      EXPECT_GE(ReadDoubles(f, "/energy/time").size(), listed) << "trial " << trial;
    }
    if (f >= 0) H5Fclose(f);
    if (!whole) {
      ++torn;
      std::printf("trial %d: a listed snapshot of %zu is unreadable after SIGKILL\n", trial,
                  listed);
    }
  }
  // A kill inside the flush or the close that commits a snapshot can still tear the file: HDF5
  // 1.10 has no journal (hdf5_writer.cpp, "Crash safety": a listed snapshot unreadable after 5
  // of 1200 kills of 2000-particle snapshots). A CI run on 2026-12-07 met it here: trial 1, the
  // one listed snapshot's name lookup failed ("bad heap free list"). So one torn trial per run is
  // tolerated and printed; two in one run (under 1 in 1000 at 5 in 1200 per kill) fail, as does
  // any systematic break.
  EXPECT_LE(torn, 1);
  EXPECT_GT(trials_with_snapshots, 0);
}

TEST_F(ResultsWriterTest, UnwritableFolderNamesThePath) {
  fs::create_directories(dir_);
  std::ofstream(dir_ / "plain_file") << "x";
  const std::string bad = (dir_ / "plain_file" / "sub").string();
  try {
    ResultsWriter w(bad, "x", RunMetadata{}, TinyModel());
    FAIL() << "expected IoError";
  } catch (const IoError& e) {
    EXPECT_NE(std::string(e.what()).find(bad), std::string::npos) << e.what();
  }
}

TEST_F(ResultsWriterTest, UncreatableFileNamesThePathAndCause) {
  fs::create_directories(dir_ / "x.h5");  // a folder where the file should go
  try {
    ResultsWriter w(dir_.string(), "x", RunMetadata{}, TinyModel());
    FAIL() << "expected IoError";
  } catch (const IoError& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find((dir_ / "x.h5").string()), std::string::npos) << what;
    EXPECT_NE(what.find("("), std::string::npos) << "HDF5's reason is appended: " << what;
  }
}

// --- Force series ---

std::vector<ForceChannel> ForceChannels() {
  return {ForceChannel{"domain", {"x-", "x+", "y-", "y+", "z-", "z+"}},
          ForceChannel{"pier-1", {"front", "back"}}};
}

// Row r of a synthetic series: values with full mantissas, both signs and magnitudes from 1e-100
// to 1e100 (the CSV must round-trip them; |F|^2 stays finite), steps beyond 2^32.
struct ForceRow {
  Real time = 0;
  int64_t step = 0;
  Real dt = 0;
  ContactReport report;
};

Real Synthetic(size_t r, size_t s, int k) {
  const Real scale = std::pow(10.0, double(int(r % 9) * 25 - 100) * (k % 3 == 0 ? 1 : 0));
  return std::sin(0.37 * double(r) + 1.1 * double(s) + 0.13 * k) * 1e3 / 3 * scale;
}

std::vector<ForceRow> ForceRows(const std::vector<ForceChannel>& channels, size_t n) {
  std::vector<ForceRow> rows(n);
  Real time = 0;
  for (size_t r = 0; r < n; ++r) {
    ForceRow& row = rows[r];
    row.dt = 1e-4 * (1 + 0.01 * std::sin(double(r)));
    time += row.dt;
    row.time = time;
    row.step = int64_t(r) + 1 + 10000000000;
    for (size_t s = 0; s < channels.size(); ++s) {
      ObstacleForce o;
      o.force = Vec3(Synthetic(r, s, 0), Synthetic(r, s, 1), Synthetic(r, s, 2));
      o.torque = Vec3(Synthetic(r, s, 3), Synthetic(r, s, 4), Synthetic(r, s, 5));
      o.contact_area = std::abs(Synthetic(r, s, 7));
      o.wetted_height = std::abs(Synthetic(r, s, 8));
      o.max_nodal_force = std::abs(Synthetic(r, s, 10));
      o.contact_nodes = int64_t(7 * r + s);
      for (size_t f = 0; f < channels[s].faces.size(); ++f) {
        const int k = 20 + 5 * int(f);
        o.faces.push_back(
            FaceForce{Vec3(Synthetic(r, s, k), Synthetic(r, s, k + 1), Synthetic(r, s, k + 2)),
                      std::abs(Synthetic(r, s, k + 4)), int64_t(3 * r + f)});
      }
      row.report.structures.push_back(o);
    }
  }
  return rows;
}

std::vector<std::string> ReadLines(const fs::path& path) {
  std::ifstream in(path);
  std::vector<std::string> lines;
  for (std::string line; std::getline(in, line);) lines.push_back(line);
  return lines;
}

std::vector<std::string> Split(const std::string& line) {
  std::vector<std::string> fields;
  std::stringstream in(line);
  for (std::string field; std::getline(in, field, ',');) fields.push_back(field);
  return fields;
}

// Every value of rows[0, n) is in /forces of `f` exactly.
void ExpectForcesInHdf5(hid_t f, const std::vector<ForceChannel>& channels,
                        const std::vector<ForceRow>& rows, size_t n) {
  for (size_t s = 0; s < channels.size(); ++s) {
    const std::string g = "/forces/" + channels[s].name + "/";
    SCOPED_TRACE(g);
    EXPECT_EQ(Dims(f, g + "time"), (std::vector<hsize_t>{n}));
    EXPECT_EQ(Dims(f, g + "force"), (std::vector<hsize_t>{n, 3}));
    EXPECT_EQ(Dims(f, g + "torque"), (std::vector<hsize_t>{n, 3}));
    const auto time = ReadDoubles(f, g + "time");
    const auto step = Read<int64_t>(f, g + "step", H5T_NATIVE_INT64);
    const auto dt = ReadDoubles(f, g + "dt");
    const auto force = ReadDoubles(f, g + "force");
    const auto torque = ReadDoubles(f, g + "torque");
    const auto area = ReadDoubles(f, g + "contact_area");
    const auto height = ReadDoubles(f, g + "wetted_height");
    const auto max_nodal = ReadDoubles(f, g + "max_nodal_force");
    const auto nodes = Read<int64_t>(f, g + "contact_nodes", H5T_NATIVE_INT64);
    ASSERT_EQ(time.size(), n);
    ASSERT_EQ(step.size(), n);
    ASSERT_EQ(dt.size(), n);
    ASSERT_EQ(force.size(), 3 * n);
    ASSERT_EQ(torque.size(), 3 * n);
    ASSERT_EQ(area.size(), n);
    ASSERT_EQ(height.size(), n);
    ASSERT_EQ(max_nodal.size(), n);
    ASSERT_EQ(nodes.size(), n);
    for (size_t r = 0; r < n; ++r) {
      const ObstacleForce& o = rows[r].report.structures[s];
      ASSERT_EQ(time[r], rows[r].time) << r;
      ASSERT_EQ(step[r], rows[r].step) << r;
      ASSERT_EQ(dt[r], rows[r].dt) << r;
      for (int d = 0; d < 3; ++d) {
        ASSERT_EQ(force[3 * r + d], o.force[d]) << r;
        ASSERT_EQ(torque[3 * r + d], o.torque[d]) << r;
      }
      ASSERT_EQ(area[r], o.contact_area) << r;
      ASSERT_EQ(height[r], o.wetted_height) << r;
      ASSERT_EQ(max_nodal[r], o.max_nodal_force) << r;
      ASSERT_EQ(nodes[r], o.contact_nodes) << r;
    }
    for (size_t k = 0; k < channels[s].faces.size(); ++k) {
      const std::string fg = g + "faces/" + channels[s].faces[k] + "/";
      const auto face_force = ReadDoubles(f, fg + "force");
      const auto face_area = ReadDoubles(f, fg + "contact_area");
      const auto face_nodes = Read<int64_t>(f, fg + "contact_nodes", H5T_NATIVE_INT64);
      EXPECT_EQ(Dims(f, fg + "force"), (std::vector<hsize_t>{n, 3})) << fg;
      ASSERT_EQ(face_area.size(), n) << fg;
      ASSERT_EQ(face_nodes.size(), n) << fg;
      for (size_t r = 0; r < n; ++r) {
        const FaceForce& face = rows[r].report.structures[s].faces[k];
        for (int d = 0; d < 3; ++d) ASSERT_EQ(face_force[3 * r + d], face.force[d]) << fg << r;
        ASSERT_EQ(face_area[r], face.contact_area) << fg << r;
        ASSERT_EQ(face_nodes[r], face.contact_nodes) << fg << r;
      }
    }
  }
}

// The CSV of structure s holds the header and exactly rows[0, n), every value round-tripped.
void ExpectForcesInCsv(const fs::path& csv, const ForceChannel& channel, size_t s,
                       const std::vector<ForceRow>& rows, size_t n) {
  SCOPED_TRACE(csv.string());
  const std::vector<std::string> lines = ReadLines(csv);
  ASSERT_EQ(lines.size(), n + 1);
  std::string header =
      "time_s,step,dt_s,fx_N,fy_N,fz_N,tx_Nm,ty_Nm,tz_Nm,contact_area_m2,wetted_height_m,"
      "max_nodal_force_N,contact_nodes";
  for (const std::string& face : channel.faces)
    header += "," + face + "_fx_N," + face + "_fy_N," + face + "_fz_N," + face +
              "_contact_area_m2," + face + "_contact_nodes";
  EXPECT_EQ(lines[0], header);
  for (size_t r = 0; r < n; ++r) {
    const std::vector<std::string> field = Split(lines[r + 1]);
    ASSERT_EQ(field.size(), 13 + 5 * channel.faces.size()) << r;
    const auto real = [&](size_t i) { return std::strtod(field[i].c_str(), nullptr); };
    const auto integer = [&](size_t i) {
      return int64_t(std::strtoll(field[i].c_str(), nullptr, 10));
    };
    const ObstacleForce& o = rows[r].report.structures[s];
    ASSERT_EQ(real(0), rows[r].time) << r;
    ASSERT_EQ(integer(1), rows[r].step) << r;
    ASSERT_EQ(real(2), rows[r].dt) << r;
    for (int d = 0; d < 3; ++d) {
      ASSERT_EQ(real(3 + d), o.force[d]) << r;
      ASSERT_EQ(real(6 + d), o.torque[d]) << r;
    }
    ASSERT_EQ(real(9), o.contact_area) << r;
    ASSERT_EQ(real(10), o.wetted_height) << r;
    ASSERT_EQ(real(11), o.max_nodal_force) << r;
    ASSERT_EQ(integer(12), o.contact_nodes) << r;
    for (size_t k = 0; k < channel.faces.size(); ++k) {
      const size_t at = 13 + 5 * k;
      for (int d = 0; d < 3; ++d) ASSERT_EQ(real(at + d), o.faces[k].force[d]) << r;
      ASSERT_EQ(real(at + 3), o.faces[k].contact_area) << r;
      ASSERT_EQ(integer(at + 4), o.faces[k].contact_nodes) << r;
    }
  }
}

// Peak attributes of one force group against the series itself (first maximum of |F|, sum F dt).
void ExpectPeakAttrs(hid_t group, const std::vector<Vec3>& force,
                     const std::vector<ForceRow>& rows) {
  size_t peak = 0;
  Vec3 impulse = Vec3::Zero();
  for (size_t r = 0; r < force.size(); ++r) {
    if (force[r].norm() > force[peak].norm()) peak = r;
    for (int d = 0; d < 3; ++d) impulse[d] += force[r][d] * rows[r].dt;
  }
  EXPECT_EQ(ReadAttr<double>(group, "peak_force", H5T_NATIVE_DOUBLE), force[peak].norm());
  EXPECT_EQ(ReadAttr<double>(group, "peak_time", H5T_NATIVE_DOUBLE), rows[peak].time);
  for (const char* name : {"impulse", "force_at_peak"}) {
    double v[3] = {0, 0, 0};
    const hid_t attr = H5Aopen(group, name, H5P_DEFAULT);
    ASSERT_GE(attr, 0) << name;
    EXPECT_GE(H5Aread(attr, H5T_NATIVE_DOUBLE, v), 0);
    H5Aclose(attr);
    const Vec3 expected = std::string(name) == "impulse" ? impulse : force[peak];
    for (int d = 0; d < 3; ++d) EXPECT_EQ(v[d], expected[d]) << name << d;
  }
}

TEST_F(ResultsWriterTest, ForceSeriesReadBackExactlyFromHdf5AndCsv) {
  const auto channels = ForceChannels();
  const size_t n = 300;
  const auto rows = ForceRows(channels, n);
  fs::path h5;
  {
    ResultsWriter w(dir_.string(), "forces", RunMetadata{}, TinyModel());
    w.BeginForces(channels);
    EXPECT_EQ(ReadLines(w.forces_csv_path("domain")).size(), 1u) << "the header is on disk";
    for (size_t r = 0; r < 140; ++r)
      w.AppendForces(rows[r].time, rows[r].step, rows[r].dt, rows[r].report);
    EXPECT_EQ(ReadLines(w.forces_csv_path("pier-1")).size(), 1u) << "rows are buffered";
    w.WriteSnapshot(TinyState(2));
    EXPECT_EQ(ReadLines(w.forces_csv_path("pier-1")).size(), 141u) << "a snapshot flushes them";
    for (size_t r = 140; r < n; ++r)
      w.AppendForces(rows[r].time, rows[r].step, rows[r].dt, rows[r].report);
    EXPECT_EQ(w.forces_csv_path("pier-1"), (dir_ / "forces_pier-1.csv").string());
    EXPECT_EQ(w.force_summary().samples(), int64_t(n));
    w.Close(StageSeconds{}, int64_t(n), 0, "completed");
    h5 = w.h5_path();
  }
  hid_t f = H5Fopen(h5.c_str(), H5F_ACC_RDONLY, H5P_DEFAULT);
  ASSERT_GE(f, 0);
  ExpectForcesInHdf5(f, channels, rows, n);

  // Names, units and the peak/impulse attributes.
  hid_t forces = H5Gopen2(f, "/forces", H5P_DEFAULT);
  ASSERT_GE(forces, 0);
  EXPECT_EQ(ReadStringAttr(forces, "structures"), "domain,pier-1");
  H5Gclose(forces);
  for (size_t s = 0; s < channels.size(); ++s) {
    const std::string g = "/forces/" + channels[s].name;
    hid_t group = H5Gopen2(f, g.c_str(), H5P_DEFAULT);
    ASSERT_GE(group, 0) << g;
    EXPECT_EQ(ReadStringAttr(group, "faces"), s == 0 ? "x-,x+,y-,y+,z-,z+" : "front,back");
    std::vector<Vec3> force;
    Real peak_height = 0;
    for (const ForceRow& row : rows) {
      force.push_back(row.report.structures[s].force);
      peak_height = std::max(peak_height, row.report.structures[s].wetted_height);
    }
    ExpectPeakAttrs(group, force, rows);
    EXPECT_EQ(ReadAttr<double>(group, "peak_wetted_height", H5T_NATIVE_DOUBLE), peak_height);
    for (size_t k = 0; k < channels[s].faces.size(); ++k) {
      const std::string fg = "faces/" + channels[s].faces[k];
      hid_t face = H5Gopen2(group, fg.c_str(), H5P_DEFAULT);
      ASSERT_GE(face, 0) << fg;
      std::vector<Vec3> face_force;
      for (const ForceRow& row : rows)
        face_force.push_back(row.report.structures[s].faces[k].force);
      ExpectPeakAttrs(face, face_force, rows);
      H5Gclose(face);
    }
    H5Gclose(group);
  }
  const std::pair<const char*, const char*> units[] = {{"time", "s"},
                                                       {"step", "-"},
                                                       {"dt", "s"},
                                                       {"force", "N"},
                                                       {"torque", "N m"},
                                                       {"contact_area", "m^2"},
                                                       {"wetted_height", "m"},
                                                       {"max_nodal_force", "N"},
                                                       {"contact_nodes", "-"},
                                                       {"faces/front/force", "N"},
                                                       {"faces/front/contact_area", "m^2"}};
  for (const auto& [name, unit] : units) {
    hid_t ds = H5Dopen2(f, (std::string("/forces/pier-1/") + name).c_str(), H5P_DEFAULT);
    ASSERT_GE(ds, 0) << name;
    EXPECT_EQ(ReadStringAttr(ds, "units"), unit) << name;
    H5Dclose(ds);
  }
  H5Fclose(f);

  for (size_t s = 0; s < channels.size(); ++s)
    ExpectForcesInCsv(dir_ / ("forces_" + channels[s].name + ".csv"), channels[s], s, rows, n);
}

TEST_F(ResultsWriterTest, ForceRowsAreFlushedEvery1000Rows) {
  const std::vector<ForceChannel> channels = {ForceChannel{"gate", {"upstream"}}};
  const auto rows = ForceRows(channels, 2 * kForceFlushRows + 5);
  ResultsWriter w(dir_.string(), "cadence", RunMetadata{}, TinyModel());
  w.BeginForces(channels);
  const fs::path csv = w.forces_csv_path("gate");
  size_t r = 0;
  const auto append = [&](size_t count) {
    for (size_t end = r + count; r < end; ++r)
      w.AppendForces(rows[r].time, rows[r].step, rows[r].dt, rows[r].report);
  };
  append(kForceFlushRows - 1);
  EXPECT_EQ(ReadLines(csv).size(), 1u);
  append(1);
  EXPECT_EQ(ReadLines(csv).size(), 1 + kForceFlushRows);
  append(kForceFlushRows - 1);
  EXPECT_EQ(ReadLines(csv).size(), 1 + kForceFlushRows);
  append(1);
  EXPECT_EQ(ReadLines(csv).size(), 1 + 2 * kForceFlushRows);
  append(5);
  w.Close(StageSeconds{}, 0, 0, "completed");
  ExpectForcesInCsv(csv, channels[0], 0, rows, rows.size());
  hid_t f = H5Fopen(w.h5_path().c_str(), H5F_ACC_RDONLY, H5P_DEFAULT);
  ASSERT_GE(f, 0);
  ExpectForcesInHdf5(f, channels, rows, rows.size());
  H5Fclose(f);
}

// The child appends, snapshots and is killed without Close or destructors (_exit): the .h5 and
// the CSV hold every row up to the last flush (1000 rows on their own, then 100 more with the
// snapshot), and nothing after it.
TEST_F(ResultsWriterTest, KilledRunKeepsForceRowsUpToTheLastFlush) {
  const auto channels = ForceChannels();
  const auto rows = ForceRows(channels, 1350);
  const pid_t child = fork();
  ASSERT_GE(child, 0);
  if (child == 0) {
    ResultsWriter w(dir_.string(), "killed", RunMetadata{}, TinyModel());
    w.BeginForces(channels);
    for (size_t r = 0; r < rows.size(); ++r) {
      w.AppendForces(rows[r].time, rows[r].step, rows[r].dt, rows[r].report);
      if (r + 1 == 1100) w.WriteSnapshot(TinyState(3));
    }
    _exit(0);
  }
  int status = 0;
  waitpid(child, &status, 0);
  ASSERT_TRUE(WIFEXITED(status));
  hid_t f = H5Fopen((dir_ / "killed.h5").c_str(), H5F_ACC_RDONLY, H5P_DEFAULT);
  ASSERT_GE(f, 0) << "the file of a killed run must stay readable";
  ExpectForcesInHdf5(f, channels, rows, 1100);
  EXPECT_EQ(H5Aexists_by_name(f, "/forces/domain", "peak_force", H5P_DEFAULT), 0)
      << "the summary is written on Close only";
  H5Fclose(f);
  for (size_t s = 0; s < channels.size(); ++s)
    ExpectForcesInCsv(dir_ / ("forces_" + channels[s].name + ".csv"), channels[s], s, rows, 1100);
}

TEST_F(ResultsWriterTest, DestructorWithoutCloseWritesPendingForceRows) {
  const std::vector<ForceChannel> channels = {ForceChannel{"gate", {}}};
  const auto rows = ForceRows(channels, 7);
  {
    ResultsWriter w(dir_.string(), "unclosed", RunMetadata{}, TinyModel());
    w.BeginForces(channels);
    for (const ForceRow& row : rows) w.AppendForces(row.time, row.step, row.dt, row.report);
  }
  hid_t f = H5Fopen((dir_ / "unclosed.h5").c_str(), H5F_ACC_RDONLY, H5P_DEFAULT);
  ASSERT_GE(f, 0);
  ExpectForcesInHdf5(f, channels, rows, rows.size());
  H5Fclose(f);
  ExpectForcesInCsv(dir_ / "forces_gate.csv", channels[0], 0, rows, rows.size());
}

TEST_F(ResultsWriterTest, PlaneRunsLabelForcesPerMetre) {
  {
    ResultsWriter w(dir_.string(), "plane", RunMetadata{}, TinyModel(/*dim=*/2));
    w.BeginForces({ForceChannel{"gate", {"upstream"}}});
    w.Close(StageSeconds{}, 0, 0, "completed");
  }
  hid_t f = H5Fopen((dir_ / "plane.h5").c_str(), H5F_ACC_RDONLY, H5P_DEFAULT);
  ASSERT_GE(f, 0);
  const std::pair<const char*, const char*> units[] = {{"force", "N/m"},
                                                       {"torque", "N m/m"},
                                                       {"contact_area", "m^2/m"},
                                                       {"wetted_height", "m"},
                                                       {"faces/upstream/force", "N/m"}};
  for (const auto& [name, unit] : units) {
    hid_t ds = H5Dopen2(f, (std::string("/forces/gate/") + name).c_str(), H5P_DEFAULT);
    ASSERT_GE(ds, 0) << name;
    EXPECT_EQ(ReadStringAttr(ds, "units"), unit) << name;
    H5Dclose(ds);
  }
  EXPECT_EQ(Dims(f, "/forces/gate/time"), (std::vector<hsize_t>{0}));
  hid_t g = H5Gopen2(f, "/forces/gate", H5P_DEFAULT);
  ASSERT_GE(g, 0);
  EXPECT_TRUE(std::isnan(ReadAttr<double>(g, "peak_time", H5T_NATIVE_DOUBLE))) << "no rows";
  H5Gclose(g);
  H5Fclose(f);
}

TEST_F(ResultsWriterTest, ForceSeriesMisuseThrows) {
  ResultsWriter w(dir_.string(), "misuse", RunMetadata{}, TinyModel());
  const auto channels = ForceChannels();
  const auto rows = ForceRows(channels, 1);
  EXPECT_THROW(w.AppendForces(0, 1, 1, rows[0].report), IoError) << "before BeginForces";
  w.AppendForces(0, 1, 1, ContactReport{});  // no channels: nothing to log, no BeginForces needed
  EXPECT_THROW(w.BeginForces({ForceChannel{"a/b", {}}}), IoError);
  EXPECT_THROW(w.BeginForces({ForceChannel{"", {}}}), IoError);
  EXPECT_THROW(w.BeginForces({ForceChannel{"a", {}}, ForceChannel{"a", {}}}), IoError);
  EXPECT_THROW(w.BeginForces({ForceChannel{"a", {"x+", "x+"}}}), IoError);
  EXPECT_THROW(w.BeginForces({ForceChannel{"a", {"top face"}}}), IoError);
  w.BeginForces(channels);  // the rejected calls left nothing behind
  EXPECT_THROW(w.BeginForces(channels), IoError) << "twice";
  ContactReport wrong = rows[0].report;
  wrong.structures.pop_back();
  EXPECT_THROW(w.AppendForces(0, 1, 1, wrong), std::logic_error);
  w.AppendForces(rows[0].time, rows[0].step, rows[0].dt, rows[0].report);
  w.Close(StageSeconds{}, 1, 0, "completed");
  EXPECT_THROW(w.AppendForces(0, 1, 1, rows[0].report), IoError);
  ExpectForcesInCsv(dir_ / "forces_domain.csv", channels[0], 0, rows, 1);
}

// --- Rigid-body series ---

const std::vector<std::string> kBodies = {"boulder", "log-2"};

struct RigidRow {
  Real time = 0;
  int64_t step = 0;
  std::vector<RigidBodyState> bodies;
};

// Row r: positions and velocities as the synthetic force values (full mantissas, 1e-100..1e100),
// rotations about a turning axis by angles that sweep 0..2 pi (w of Eigen's quaternion takes
// both signs), and the identity in row 0.
std::vector<RigidRow> RigidRows(size_t bodies, size_t n) {
  std::vector<RigidRow> rows(n);
  for (size_t r = 0; r < n; ++r) {
    RigidRow& row = rows[r];
    row.time = 1e-4 * double(r + 1) * (1 + 0.01 * std::sin(double(r)));
    row.step = int64_t(r) + 1 + 10000000000;
    for (size_t b = 0; b < bodies; ++b) {
      RigidBodyState s;
      s.position = Vec3(Synthetic(r, b, 0), Synthetic(r, b, 1), Synthetic(r, b, 2));
      s.velocity = Vec3(Synthetic(r, b, 3), Synthetic(r, b, 4), Synthetic(r, b, 5));
      s.angular_velocity = Vec3(Synthetic(r, b, 6), Synthetic(r, b, 7), Synthetic(r, b, 8));
      const Vec3 axis = Vec3(std::sin(double(r)), std::cos(double(r)), 0.3 + double(b));
      const Real angle = std::fmod(0.37 * double(r) + double(b), 2 * std::numbers::pi);
      s.rotation = r == 0 ? Mat3(Mat3::Identity())
                          : Mat3(Eigen::AngleAxis<Real>(angle, axis.normalized()));
      row.bodies.push_back(s);
    }
  }
  return rows;
}

void AppendRigidRows(ResultsWriter& w, const std::vector<RigidRow>& rows, size_t begin,
                     size_t end) {
  for (size_t r = begin; r < end; ++r) w.AppendRigid(rows[r].time, rows[r].step, rows[r].bodies);
}

// Every value of rows[0, n) is in /rigid of `f` exactly (the rotation as RotationQuaternion).
void ExpectRigidInHdf5(hid_t f, const std::vector<std::string>& names,
                       const std::vector<RigidRow>& rows, size_t n) {
  for (size_t b = 0; b < names.size(); ++b) {
    const std::string g = "/rigid/" + names[b] + "/";
    SCOPED_TRACE(g);
    EXPECT_EQ(Dims(f, g + "time"), (std::vector<hsize_t>{n}));
    EXPECT_EQ(Dims(f, g + "step"), (std::vector<hsize_t>{n}));
    EXPECT_EQ(Dims(f, g + "position"), (std::vector<hsize_t>{n, 3}));
    EXPECT_EQ(Dims(f, g + "rotation"), (std::vector<hsize_t>{n, 4}));
    EXPECT_EQ(Dims(f, g + "velocity"), (std::vector<hsize_t>{n, 3}));
    EXPECT_EQ(Dims(f, g + "angular_velocity"), (std::vector<hsize_t>{n, 3}));
    const auto time = ReadDoubles(f, g + "time");
    const auto step = Read<int64_t>(f, g + "step", H5T_NATIVE_INT64);
    const auto position = ReadDoubles(f, g + "position");
    const auto rotation = ReadDoubles(f, g + "rotation");
    const auto velocity = ReadDoubles(f, g + "velocity");
    const auto omega = ReadDoubles(f, g + "angular_velocity");
    ASSERT_EQ(time.size(), n);
    ASSERT_EQ(step.size(), n);
    ASSERT_EQ(position.size(), 3 * n);
    ASSERT_EQ(rotation.size(), 4 * n);
    ASSERT_EQ(velocity.size(), 3 * n);
    ASSERT_EQ(omega.size(), 3 * n);
    for (size_t r = 0; r < n; ++r) {
      const RigidBodyState& s = rows[r].bodies[b];
      ASSERT_EQ(time[r], rows[r].time) << r;
      ASSERT_EQ(step[r], rows[r].step) << r;
      for (int d = 0; d < 3; ++d) {
        ASSERT_EQ(position[3 * r + d], s.position[d]) << r;
        ASSERT_EQ(velocity[3 * r + d], s.velocity[d]) << r;
        ASSERT_EQ(omega[3 * r + d], s.angular_velocity[d]) << r;
      }
      const std::array<Real, 4> q = RotationQuaternion(s.rotation);
      for (int d = 0; d < 4; ++d) ASSERT_EQ(rotation[4 * r + d], q[d]) << r;
    }
  }
}

// The CSV of body b holds the header and exactly rows[0, n), every value round-tripped.
void ExpectRigidInCsv(const fs::path& csv, size_t b, const std::vector<RigidRow>& rows,
                      size_t n) {
  SCOPED_TRACE(csv.string());
  const std::vector<std::string> lines = ReadLines(csv);
  ASSERT_EQ(lines.size(), n + 1);
  EXPECT_EQ(lines[0],
            "time_s,step,x_m,y_m,z_m,qw,qx,qy,qz,vx_m_s,vy_m_s,vz_m_s,wx_rad_s,wy_rad_s,"
            "wz_rad_s");
  for (size_t r = 0; r < n; ++r) {
    const std::vector<std::string> field = Split(lines[r + 1]);
    ASSERT_EQ(field.size(), 15u) << r;
    const auto real = [&](size_t i) { return std::strtod(field[i].c_str(), nullptr); };
    const RigidBodyState& s = rows[r].bodies[b];
    ASSERT_EQ(real(0), rows[r].time) << r;
    ASSERT_EQ(int64_t(std::strtoll(field[1].c_str(), nullptr, 10)), rows[r].step) << r;
    const std::array<Real, 4> q = RotationQuaternion(s.rotation);
    for (int d = 0; d < 3; ++d) {
      ASSERT_EQ(real(2 + d), s.position[d]) << r;
      ASSERT_EQ(real(9 + d), s.velocity[d]) << r;
      ASSERT_EQ(real(12 + d), s.angular_velocity[d]) << r;
    }
    for (int d = 0; d < 4; ++d) ASSERT_EQ(real(5 + d), q[d]) << r;
  }
}

TEST_F(ResultsWriterTest, RigidSeriesReadBackExactlyFromHdf5AndCsv) {
  const size_t n = 300;
  const auto rows = RigidRows(kBodies.size(), n);
  fs::path h5;
  {
    ResultsWriter w(dir_.string(), "rigid", RunMetadata{}, TinyModel());
    w.BeginRigid(kBodies);
    EXPECT_EQ(ReadLines(w.rigid_csv_path("boulder")).size(), 1u) << "the header is on disk";
    AppendRigidRows(w, rows, 0, 140);
    EXPECT_EQ(ReadLines(w.rigid_csv_path("log-2")).size(), 1u) << "rows are buffered";
    w.WriteSnapshot(TinyState(2));
    EXPECT_EQ(ReadLines(w.rigid_csv_path("log-2")).size(), 141u) << "a snapshot flushes them";
    AppendRigidRows(w, rows, 140, n);
    EXPECT_EQ(w.rigid_csv_path("log-2"), (dir_ / "rigid_log-2.csv").string());
    w.Close(StageSeconds{}, int64_t(n), 0, "completed");
    h5 = w.h5_path();
  }
  hid_t f = H5Fopen(h5.c_str(), H5F_ACC_RDONLY, H5P_DEFAULT);
  ASSERT_GE(f, 0);
  ExpectRigidInHdf5(f, kBodies, rows, n);
  hid_t rigid = H5Gopen2(f, "/rigid", H5P_DEFAULT);
  ASSERT_GE(rigid, 0);
  EXPECT_EQ(ReadStringAttr(rigid, "bodies"), "boulder,log-2");
  H5Gclose(rigid);
  const std::pair<const char*, const char*> units[] = {{"time", "s"},          {"step", "-"},
                                                       {"position", "m"},      {"rotation", "-"},
                                                       {"velocity", "m/s"},
                                                       {"angular_velocity", "rad/s"}};
  for (const auto& [name, unit] : units) {
    hid_t ds = H5Dopen2(f, (std::string("/rigid/log-2/") + name).c_str(), H5P_DEFAULT);
    ASSERT_GE(ds, 0) << name;
    EXPECT_EQ(ReadStringAttr(ds, "units"), unit) << name;
    H5Dclose(ds);
  }
  // The stored quaternions are unit, w >= 0, and give back R.
  const auto q = ReadDoubles(f, "/rigid/boulder/rotation");
  ASSERT_EQ(q.size(), 4 * n);
  EXPECT_EQ(q[0], 1.0);  // row 0: identity
  for (size_t r = 0; r < n; ++r) {
    const Eigen::Quaternion<Real> quat(q[4 * r], q[4 * r + 1], q[4 * r + 2], q[4 * r + 3]);
    ASSERT_GE(quat.w(), 0.0) << r;
    ASSERT_NEAR(quat.norm(), 1.0, 4 * kEps) << r;
    ASSERT_LT((quat.toRotationMatrix() - rows[r].bodies[0].rotation).cwiseAbs().maxCoeff(),
              8 * kEps)
        << r;
  }
  H5Fclose(f);
  for (size_t b = 0; b < kBodies.size(); ++b)
    ExpectRigidInCsv(dir_ / ("rigid_" + kBodies[b] + ".csv"), b, rows, n);
}

TEST_F(ResultsWriterTest, RigidRowsAreFlushedEvery1000RowsAndAfterAKill) {
  const auto rows = RigidRows(kBodies.size(), 1350);
  // Cadence in this process.
  {
    ResultsWriter w(dir_.string(), "cadence", RunMetadata{}, TinyModel());
    w.BeginRigid({"boulder"});
    const fs::path csv = w.rigid_csv_path("boulder");
    std::vector<RigidRow> one = rows;
    for (RigidRow& row : one) row.bodies.resize(1);
    AppendRigidRows(w, one, 0, kForceFlushRows - 1);
    EXPECT_EQ(ReadLines(csv).size(), 1u);
    AppendRigidRows(w, one, kForceFlushRows - 1, kForceFlushRows);
    EXPECT_EQ(ReadLines(csv).size(), 1 + kForceFlushRows);
    AppendRigidRows(w, one, kForceFlushRows, kForceFlushRows + 7);
    w.Close(StageSeconds{}, 0, 0, "completed");
    ExpectRigidInCsv(csv, 0, one, kForceFlushRows + 7);
    hid_t f = H5Fopen(w.h5_path().c_str(), H5F_ACC_RDONLY, H5P_DEFAULT);
    ASSERT_GE(f, 0);
    ExpectRigidInHdf5(f, {"boulder"}, one, kForceFlushRows + 7);
    H5Fclose(f);
  }
  // A child appends, snapshots after 1100 rows and is killed without Close or destructors: both
  // files hold exactly the rows up to that flush.
  const pid_t child = fork();
  ASSERT_GE(child, 0);
  if (child == 0) {
    ResultsWriter w(dir_.string(), "killed", RunMetadata{}, TinyModel());
    w.BeginRigid(kBodies);
    for (size_t r = 0; r < rows.size(); ++r) {
      w.AppendRigid(rows[r].time, rows[r].step, rows[r].bodies);
      if (r + 1 == 1100) w.WriteSnapshot(TinyState(3));
    }
    _exit(0);
  }
  int status = 0;
  waitpid(child, &status, 0);
  ASSERT_TRUE(WIFEXITED(status));
  hid_t f = H5Fopen((dir_ / "killed.h5").c_str(), H5F_ACC_RDONLY, H5P_DEFAULT);
  ASSERT_GE(f, 0) << "the file of a killed run must stay readable";
  ExpectRigidInHdf5(f, kBodies, rows, 1100);
  H5Fclose(f);
  for (size_t b = 0; b < kBodies.size(); ++b)
    ExpectRigidInCsv(dir_ / ("rigid_" + kBodies[b] + ".csv"), b, rows, 1100);
}

TEST_F(ResultsWriterTest, DestructorWithoutCloseWritesPendingRigidRowsNextToForces) {
  const auto rows = RigidRows(1, 7);
  const std::vector<ForceChannel> channels = {ForceChannel{"gate", {}}};
  const auto force_rows = ForceRows(channels, 7);
  {
    ResultsWriter w(dir_.string(), "unclosed", RunMetadata{}, TinyModel());
    w.BeginForces(channels);
    w.BeginRigid({"boulder"});
    for (size_t r = 0; r < rows.size(); ++r) {
      w.AppendForces(force_rows[r].time, force_rows[r].step, force_rows[r].dt,
                     force_rows[r].report);
      w.AppendRigid(rows[r].time, rows[r].step, rows[r].bodies);
    }
  }
  hid_t f = H5Fopen((dir_ / "unclosed.h5").c_str(), H5F_ACC_RDONLY, H5P_DEFAULT);
  ASSERT_GE(f, 0);
  ExpectRigidInHdf5(f, {"boulder"}, rows, rows.size());
  ExpectForcesInHdf5(f, channels, force_rows, force_rows.size());
  H5Fclose(f);
  ExpectRigidInCsv(dir_ / "rigid_boulder.csv", 0, rows, rows.size());
  ExpectForcesInCsv(dir_ / "forces_gate.csv", channels[0], 0, force_rows, force_rows.size());
}

TEST_F(ResultsWriterTest, RigidSeriesMisuseThrows) {
  ResultsWriter w(dir_.string(), "misuse", RunMetadata{}, TinyModel());
  const auto rows = RigidRows(kBodies.size(), 1);
  EXPECT_THROW(w.AppendRigid(0, 1, rows[0].bodies), IoError) << "before BeginRigid";
  w.AppendRigid(0, 1, {});  // no bodies: nothing to log, no BeginRigid needed
  EXPECT_THROW(w.BeginRigid({"a/b"}), IoError);
  EXPECT_THROW(w.BeginRigid({""}), IoError);
  EXPECT_THROW(w.BeginRigid({"a", "a"}), IoError);
  EXPECT_THROW(w.BeginRigid({"big rock"}), IoError);
  w.BeginRigid(kBodies);  // the rejected calls left nothing behind
  EXPECT_THROW(w.BeginRigid(kBodies), IoError) << "twice";
  std::vector<RigidBodyState> wrong = rows[0].bodies;
  wrong.pop_back();
  EXPECT_THROW(w.AppendRigid(0, 1, wrong), std::logic_error);
  w.AppendRigid(rows[0].time, rows[0].step, rows[0].bodies);
  w.Close(StageSeconds{}, 1, 0, "completed");
  EXPECT_THROW(w.AppendRigid(0, 1, rows[0].bodies), IoError);
  ExpectRigidInCsv(dir_ / "rigid_log-2.csv", 1, rows, 1);
}

TEST(RotationQuaternionTest, KnownRotations) {
  const auto expect = [](const Mat3& R, std::array<Real, 4> want, Real tol) {
    const std::array<Real, 4> q = RotationQuaternion(R);
    for (int d = 0; d < 4; ++d) EXPECT_NEAR(q[d], want[d], tol) << d;
  };
  {
    const std::array<Real, 4> q = RotationQuaternion(Mat3::Identity());
    EXPECT_EQ(q, (std::array<Real, 4>{1, 0, 0, 0}));
  }
  // A rotation by theta about the unit axis a is q = (cos theta/2, sin theta/2 a) (Shoemake 1985).
  const Real theta = 0.8;
  expect(Mat3(Eigen::AngleAxis<Real>(theta, Vec3::UnitZ())),
         {std::cos(theta / 2), 0, 0, std::sin(theta / 2)}, 2 * kEps);
  // Half a turn about x: diag(1, -1, -1), trace -1 (Eigen's other branch).
  expect(Vec3(1, -1, -1).asDiagonal(), {0, 1, 0, 0}, 0.0);
  // theta = 4 rad > pi: cos(theta/2) < 0, so the stored one is -q (w >= 0).
  const Vec3 a = Vec3(1, -2, 0.5).normalized();
  const Real s = -std::sin(2.0);
  expect(Mat3(Eigen::AngleAxis<Real>(4.0, a)), {-std::cos(2.0), s * a.x(), s * a.y(), s * a.z()},
         4 * kEps);
}

TEST(RotationQuaternionTest, RandomRotationsRoundTrip) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<Real> u(-1, 1);
  Real worst = 0;
  for (int i = 0; i < 10000; ++i) {
    const Vec3 axis = Vec3(u(rng), u(rng), u(rng));
    if (axis.norm() < 1e-3) continue;
    const Real angle = std::numbers::pi * (1 + u(rng));
    const Mat3 R = Eigen::AngleAxis<Real>(angle, axis.normalized()).toRotationMatrix();
    const std::array<Real, 4> q = RotationQuaternion(R);
    const Eigen::Quaternion<Real> quat(q[0], q[1], q[2], q[3]);
    ASSERT_GE(q[0], 0.0) << i;
    ASSERT_NEAR(quat.norm(), 1.0, 4 * kEps) << i;
    worst = std::max(worst, (quat.toRotationMatrix() - R).cwiseAbs().maxCoeff());
  }
  EXPECT_LT(worst, 8 * kEps);
}

TEST(StrainInvariantsTest, IdentityIsUnstrained) {
  Real volumetric = 1, equivalent = 1;
  StrainInvariants(Mat3::Identity(), volumetric, equivalent);
  EXPECT_EQ(volumetric, 0.0);
  EXPECT_EQ(equivalent, 0.0);
}

TEST(StrainInvariantsTest, UniformDilationIsPurelyVolumetric) {
  Real volumetric = 0, equivalent = 1;
  StrainInvariants(1.2 * Mat3::Identity(), volumetric, equivalent);
  EXPECT_NEAR(volumetric, 3 * std::log(1.2), 8 * kEps);
  EXPECT_NEAR(equivalent, 0.0, 8 * kEps);
}

TEST(StrainInvariantsTest, RotationDoesNotChangeTheInvariants) {
  const Mat3 U = Vec3(1.3, 0.9, 1.05).asDiagonal();
  const Mat3 R = Eigen::AngleAxisd(0.7, Vec3(1, 2, 3).normalized()).toRotationMatrix();
  Real v_u = 0, e_u = 0, v_ru = 0, e_ru = 0;
  StrainInvariants(U, v_u, e_u);
  StrainInvariants(R * U, v_ru, e_ru);
  EXPECT_NEAR(v_ru, v_u, 16 * kEps);
  EXPECT_NEAR(e_ru, e_u, 16 * kEps);
  // Isochoric pure shear stretch diag(a, 1/a, 1): e = (ln a, -ln a, 0), equivalent 2/sqrt(3) ln a.
  const double a = 1.25;
  StrainInvariants(Vec3(a, 1 / a, 1).asDiagonal(), v_u, e_u);
  EXPECT_NEAR(v_u, 0.0, 8 * kEps);
  EXPECT_NEAR(e_u, 2 / std::sqrt(3.0) * std::log(a), 8 * kEps);
}

TEST(StrainInvariantsTest, InvertedElementGivesNaNVolumetricStrain) {
  Real volumetric = 0, equivalent = 0;
  StrainInvariants(Vec3(-1, 1, 1).asDiagonal(), volumetric, equivalent);
  EXPECT_TRUE(std::isnan(volumetric));
}

}  // namespace
}  // namespace surge
