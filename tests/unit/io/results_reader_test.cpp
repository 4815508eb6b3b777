// ReadResultForces (io/results_reader.h, `surge forces`): the force series, face series, scene
// text (UTF-8) and exit status read back bit for bit from what ResultsWriter wrote; a result
// without structures; errors naming the path for a missing, non-HDF5 or foreign file.
#include "io/results_reader.h"

#include <gtest/gtest.h>
#include <hdf5.h>

#include <cmath>
#include <filesystem>
#include <fstream>

#include "io/results_writer.h"

namespace surge {
namespace {

namespace fs = std::filesystem;

class ResultsReaderTest : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() /
           ("surge_reader_" + std::to_string(::testing::UnitTest::GetInstance()->random_seed()) +
            "_" + ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }
  fs::path dir_;
};

Model TinyModel() {
  Model m;
  m.name = "tiny";
  m.dim = 3;
  m.dx = 0.5;
  return m;
}

// Expects the IoError of reading `path` to contain `fragment` and the path.
void ExpectIoError(const std::string& path, const std::string& fragment) {
  try {
    ReadResultForces(path);
    ADD_FAILURE() << "no IoError for " << path;
  } catch (const IoError& e) {
    EXPECT_NE(std::string(e.what()).find(fragment), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find(path), std::string::npos) << e.what();
  }
}

TEST_F(ResultsReaderTest, ForceSeriesReadBackExactly) {
  const std::vector<ForceChannel> channels = {{"domain", {"x-", "y-"}}, {"pier", {"front"}}};
  RunMetadata meta;
  meta.scene_text = "name: tiny  # friction 20° ✓\n";
  meta.resolved_yaml = "name: tiny\n";
  std::vector<ContactReport> reports;
  std::vector<Real> times, dts;
  std::string h5;
  {
    ResultsWriter w(dir_.string(), "tiny", meta, TinyModel());
    w.BeginForces(channels);
    Real t = 0;
    for (int k = 0; k < 1234; ++k) {  // more than one flush of 1000 rows
      ContactReport r;
      r.structures.resize(2);
      for (size_t s = 0; s < 2; ++s) {
        ObstacleForce& o = r.structures[s];
        o.force = Vec3(std::sin(0.1 * k) * 1e3 + Real(s), 1.0 / (k + 1), -Real(k) / 3);
        o.contact_area = 0.25 * Real(k % 7);
        o.wetted_height = 0.1 * Real(k % 5) + Real(s);
        o.faces.resize(channels[s].faces.size());
        for (size_t f = 0; f < o.faces.size(); ++f) {
          o.faces[f].force = o.force * (0.5 + Real(f));
          o.faces[f].contact_area = o.contact_area / Real(f + 2);
        }
      }
      const Real dt = (k % 3 + 1) * 1e-3 / 3;
      t += dt;
      w.AppendForces(t, k + 1, dt, r);
      reports.push_back(r);
      times.push_back(t);
      dts.push_back(dt);
    }
    w.Close(StageSeconds{}, 1234, 0.5, "completed");
    h5 = w.h5_path();
  }
  const StoredResult r = ReadResultForces(h5);
  EXPECT_EQ(r.name, "tiny");
  EXPECT_EQ(r.scene_text, meta.scene_text);
  EXPECT_EQ(r.resolved_yaml, meta.resolved_yaml);
  EXPECT_EQ(r.dimension, 3);
  EXPECT_EQ(r.exit_status, "completed");
  ASSERT_EQ(r.structures.size(), 2u);
  size_t mismatches = 0;
  for (size_t s = 0; s < 2; ++s) {
    const StoredForceSeries& S = r.structures[s];
    EXPECT_EQ(S.name, channels[s].name);
    ASSERT_EQ(S.time.size(), reports.size());
    ASSERT_EQ(S.faces.size(), channels[s].faces.size());
    for (size_t k = 0; k < reports.size(); ++k) {
      const ObstacleForce& o = reports[k].structures[s];
      mismatches += S.time[k] != times[k] || S.dt[k] != dts[k] || S.force[k] != o.force ||
                    S.contact_area[k] != o.contact_area || S.wetted_height[k] != o.wetted_height;
      for (size_t f = 0; f < S.faces.size(); ++f) {
        mismatches += S.faces[f].force[k] != o.faces[f].force ||
                      S.faces[f].contact_area[k] != o.faces[f].contact_area;
      }
    }
    for (size_t f = 0; f < S.faces.size(); ++f) EXPECT_EQ(S.faces[f].name, channels[s].faces[f]);
  }
  EXPECT_EQ(mismatches, 0u);
}

TEST_F(ResultsReaderTest, ResultWithoutStructures) {
  std::string h5;
  {
    ResultsWriter w(dir_.string(), "bare", RunMetadata{}, TinyModel());
    w.Close(StageSeconds{}, 0, 0, "completed");
    h5 = w.h5_path();
  }
  const StoredResult r = ReadResultForces(h5);
  EXPECT_TRUE(r.structures.empty());
  EXPECT_EQ(r.scene_text, "");
}

TEST_F(ResultsReaderTest, ErrorsNameThePath) {
  ExpectIoError((dir_ / "none.h5").string(), "no such file");
  const std::string text = (dir_ / "text.h5").string();
  std::ofstream(text) << "not hdf5\n";
  ExpectIoError(text, "is not an HDF5 file");
  const std::string foreign = (dir_ / "foreign.h5").string();
  const hid_t f = H5Fcreate(foreign.c_str(), H5F_ACC_TRUNC, H5P_DEFAULT, H5P_DEFAULT);
  ASSERT_GE(f, 0);
  H5Fclose(f);
  ExpectIoError(foreign, "is not a Surge result");
  ExpectIoError(dir_.string(), "not a regular file");
}

}  // namespace
}  // namespace surge
