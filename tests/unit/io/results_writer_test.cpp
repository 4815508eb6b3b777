// ResultsWriter: layout, values, verbatim scene text, energy rows, XDMF, crash safety, errors.
#include "io/results_writer.h"

#include <gtest/gtest.h>
#include <hdf5.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>

namespace surge {
namespace {

namespace fs = std::filesystem;

Model TinyModel() {
  Model m;
  m.name = "tiny";
  m.dim = 3;
  m.dx = 0.5;
  return m;
}

State TinyState(size_t n) {
  State s;
  s.particles.Resize(n);
  for (size_t p = 0; p < n; ++p) {
    Particles& P = s.particles;
    P.x[p] = Vec3(p, 2.0 * p, -1.0);
    P.v[p] = Vec3(1, 0, 0);
    P.F[p] = Mat3::Identity();
    P.stress[p] = Mat3::Zero();
    P.material[p] = 0;
    P.body[p] = int32_t(p % 2);
    P.id[p] = int64_t(100 + p);
  }
  // Particle 0: uniaxial stretch F = diag(1.1, 1, 1) and a hydrostatic compression of 3 Pa
  // plus a shear of 2 Pa.
  s.particles.F[0](0, 0) = 1.1;
  s.particles.stress[0] = -3.0 * Mat3::Identity();
  s.particles.stress[0](0, 1) = s.particles.stress[0](1, 0) = 2.0;
  return s;
}

std::vector<double> ReadDoubles(hid_t file, const std::string& path, std::vector<hsize_t>* dims = nullptr) {
  hid_t ds = H5Dopen2(file, path.c_str(), H5P_DEFAULT);
  EXPECT_GE(ds, 0) << path;
  if (ds < 0) return {};
  hid_t space = H5Dget_space(ds);
  const int rank = H5Sget_simple_extent_ndims(space);
  std::vector<hsize_t> d(rank);
  H5Sget_simple_extent_dims(space, d.data(), nullptr);
  hsize_t n = 1;
  for (hsize_t x : d) n *= x;
  std::vector<double> out(n);
  if (n) H5Dread(ds, H5T_NATIVE_DOUBLE, H5S_ALL, H5S_ALL, H5P_DEFAULT, out.data());
  H5Sclose(space);
  H5Dclose(ds);
  if (dims) *dims = d;
  return out;
}

std::string ReadString(hid_t file, const std::string& path) {
  hid_t ds = H5Dopen2(file, path.c_str(), H5P_DEFAULT);
  hid_t type = H5Dget_type(ds);
  std::string s(H5Tget_size(type), '\0');
  H5Dread(ds, type, H5S_ALL, H5S_ALL, H5P_DEFAULT, s.data());
  H5Tclose(type);
  H5Dclose(ds);
  while (!s.empty() && s.back() == '\0') s.pop_back();
  return s;
}

class ResultsWriterTest : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() / ("surge_io_test_" + std::to_string(getpid()));
    fs::remove_all(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }
  fs::path dir_;
};

TEST_F(ResultsWriterTest, WritesLayoutValuesAndXdmf) {
  RunMetadata meta;
  meta.scene_text = "name: tiny  # ünïcode ✓\nline two\n";
  meta.resolved_yaml = "name: tiny\n";
  meta.version = "0.1.0";
  meta.git_hash = "abc";
  meta.threads = 2;
  {
    ResultsWriter w(dir_.string(), "tiny", meta, TinyModel());
    State s = TinyState(5);
    w.AppendEnergy(EnergyRecord{0.0, 0, 0.0, 1.0, 2.0, 3.0, 0.0});
    w.WriteSnapshot(s);
    s.time = 0.5;
    s.step = 7;
    w.AppendEnergy(EnergyRecord{0.5, 7, 0.1, 1.5, 2.5, 3.5, -0.5});
    w.WriteSnapshot(s);
    EXPECT_EQ(w.snapshot_count(), 2);
    w.Close(StageSeconds{}, 7, 1.25, "completed");
  }
  hid_t f = H5Fopen((dir_ / "tiny.h5").c_str(), H5F_ACC_RDONLY, H5P_DEFAULT);
  ASSERT_GE(f, 0);
  EXPECT_EQ(ReadString(f, "/metadata/scene"), meta.scene_text);
  EXPECT_EQ(ReadString(f, "/metadata/resolved"), meta.resolved_yaml);
  std::vector<hsize_t> dims;
  const auto pos = ReadDoubles(f, "/snapshots/000001/position", &dims);
  ASSERT_EQ(dims.size(), 2u);
  EXPECT_EQ(dims[0], 5u);
  EXPECT_EQ(dims[1], 3u);
  EXPECT_DOUBLE_EQ(pos[3 * 4 + 1], 8.0);
  const auto stress = ReadDoubles(f, "/snapshots/000000/stress", &dims);
  EXPECT_EQ(dims[1], 6u);
  EXPECT_DOUBLE_EQ(stress[3], 2.0);  // xy
  EXPECT_DOUBLE_EQ(ReadDoubles(f, "/snapshots/000000/pressure")[0], 3.0);
  // q = sqrt(3/2 s:s) with s the deviator: only the shear pair remains, s:s = 8 -> q = sqrt(12).
  EXPECT_NEAR(ReadDoubles(f, "/snapshots/000000/von_mises")[0], std::sqrt(12.0), 1e-12);
  EXPECT_NEAR(ReadDoubles(f, "/snapshots/000000/strain_volumetric")[0], std::log(1.1), 1e-14);
  // Hencky e = (ln 1.1)(2/3, -1/3, -1/3): sqrt(2/3 e:e) = 2/3 ln 1.1.
  EXPECT_NEAR(ReadDoubles(f, "/snapshots/000000/strain_equivalent")[0], 2.0 / 3.0 * std::log(1.1), 1e-14);
  const auto time = ReadDoubles(f, "/energy/time");
  ASSERT_EQ(time.size(), 2u);
  EXPECT_DOUBLE_EQ(time[1], 0.5);
  EXPECT_DOUBLE_EQ(ReadDoubles(f, "/energy/total")[1], 1.5 + 2.5 + 3.5);
  H5Fclose(f);

  std::ifstream xmf(dir_ / "tiny.xmf");
  std::stringstream text;
  text << xmf.rdbuf();
  const std::string x = text.str();
  EXPECT_NE(x.find(">tiny.h5:/snapshots/000001/position<"), std::string::npos);
  EXPECT_EQ(x.find(dir_.string()), std::string::npos) << "no absolute paths in the .xmf";
  size_t grids = 0;
  for (size_t at = x.find("GridType=\"Uniform\""); at != std::string::npos;
       at = x.find("GridType=\"Uniform\"", at + 1))
    ++grids;
  EXPECT_EQ(grids, 2u);
}

TEST_F(ResultsWriterTest, KilledRunKeepsCompletedSnapshots) {
  const pid_t child = fork();
  ASSERT_GE(child, 0);
  if (child == 0) {
    ResultsWriter w(dir_.string(), "killed", RunMetadata{}, TinyModel());
    w.AppendEnergy(EnergyRecord{});
    w.WriteSnapshot(TinyState(3));
    _exit(0);  // no Close, no destructors: as if the process were killed
  }
  int status = 0;
  waitpid(child, &status, 0);
  hid_t f = H5Fopen((dir_ / "killed.h5").c_str(), H5F_ACC_RDONLY, H5P_DEFAULT);
  ASSERT_GE(f, 0) << "the file of a killed run must stay readable";
  EXPECT_EQ(ReadDoubles(f, "/snapshots/000000/position").size(), 9u);
  EXPECT_EQ(ReadDoubles(f, "/energy/time").size(), 1u);
  H5Fclose(f);
  EXPECT_TRUE(fs::exists(dir_ / "killed.xmf"));
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

}  // namespace
}  // namespace surge
