// ResultsWriter: layout, values, verbatim scene text, energy rows, timing, XDMF, crash safety
// (a child process killed after or during a snapshot), errors; StrainInvariants.
#include "io/results_writer.h"

#include <gtest/gtest.h>
#include <hdf5.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <limits>
#include <random>
#include <sstream>
#include <thread>

namespace surge {
namespace {

namespace fs = std::filesystem;

constexpr double kEps = std::numeric_limits<double>::epsilon();
// Energy rows the writer buffers before writing them without a snapshot (hdf5_writer.cpp).
constexpr size_t kFlushRows = 1024;

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
    P.stress[0] = -3.0 * Mat3::Identity();
    P.stress[0](0, 1) = P.stress[0](1, 0) = 2.0;
    P.stress[0](1, 2) = P.stress[0](2, 1) = 0.5;  // yz
    P.stress[0](0, 2) = P.stress[0](2, 0) = 0.25;  // xz
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
    w.AppendEnergy(EnergyRecord{0.5, 7, 0.1, 1.5, 2.5, 3.5, -0.5});
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
  for (const char* column : {"dt", "kinetic", "strain", "gravitational"})
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
// none of over 1000 kills did.
TEST_F(ResultsWriterTest, SigkillDuringWritesLeavesListedSnapshotsReadable) {
  std::mt19937 rng(12345);
  std::uniform_int_distribution<int> delay_us(2000, 60000);
  const size_t n = 6000;  // above the compression threshold
  int trials_with_snapshots = 0;
  for (int trial = 0; trial < 12; ++trial) {
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
    std::this_thread::sleep_for(std::chrono::microseconds(delay_us(rng)));
    kill(child, SIGKILL);
    int status = 0;
    waitpid(child, &status, 0);
    const fs::path xmf = dir_ / (name + ".xmf");
    if (!fs::exists(xmf)) continue;  // killed before the first snapshot completed
    const size_t listed = Count(ReadText(xmf), "GridType=\"Uniform\"");
    hid_t f = H5Fopen((dir_ / (name + ".h5")).c_str(), H5F_ACC_RDONLY, H5P_DEFAULT);
    ASSERT_GE(f, 0) << "trial " << trial << ": unreadable after SIGKILL";
    ++trials_with_snapshots;
    for (size_t k = 0; k < listed; ++k) {
      char group[64];
      std::snprintf(group, sizeof group, "/snapshots/%06zu/", k);
      const auto pos = ReadDoubles(f, std::string(group) + "position");
      ASSERT_EQ(pos.size(), 3 * n) << "trial " << trial << " snapshot " << k;
      EXPECT_EQ(pos[3 * (n - 1)], double(n - 1));
      EXPECT_EQ(Read<int64_t>(f, std::string(group) + "id", H5T_NATIVE_INT64).size(), n);
    }
    EXPECT_GE(ReadDoubles(f, "/energy/time").size(), listed);
    H5Fclose(f);
  }
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
