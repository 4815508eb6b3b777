// ForceSummary (src/contact/force_summary.h): peak |F| with its time and vector, rectangle-rule
// impulse, peak contact area and wetted height, per structure and per face, on a synthetic series
// whose values are dyadic, so that every answer is exact.
#include "contact/force_summary.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <stdexcept>

namespace surge {
namespace {

std::vector<ForceChannel> Channels() {
  return {ForceChannel{"pier", {"front", "back"}}, ForceChannel{"wall", {}}};
}

// Pier force F, split as front + back (back = F - front); the wall feels nothing.
ContactReport Report(const Vec3& force, const Vec3& front, Real area, Real height) {
  ContactReport r;
  ObstacleForce pier;
  pier.force = force;
  pier.torque = Vec3(0, 0, 1);
  pier.contact_area = area;
  pier.wetted_height = height;
  pier.faces = {FaceForce{front, area / 2, 1}, FaceForce{force - front, area / 4, 2}};
  r.structures = {pier, ObstacleForce{}};
  return r;
}

TEST(ForceSummaryTest, PeaksAndImpulsesOfASyntheticSeries) {
  ForceSummary summary(Channels());
  ASSERT_EQ(summary.size(), 2u);
  // Steps of dt = 0.5, 0.25, 0.25, 0.5 stamped with their end times.
  summary.Add(0.5, 0.5, Report(Vec3(3, 4, 0), Vec3(3, 0, 0), 1.0, 0.125));    // |F| = 5
  summary.Add(0.75, 0.25, Report(Vec3(0, 0, -6), Vec3(0, 0, -6), 3.0, 0.5));  // |F| = 6, peak
  summary.Add(1.0, 0.25, Report(Vec3(6, 0, 0), Vec3(0, 0, 0), 2.0, 0.25));    // |F| = 6, a tie
  summary.Add(1.5, 0.5, Report(Vec3(1, 0, 0), Vec3(1, 0, 0), 0.0, 0.0));      // |F| = 1
  EXPECT_EQ(summary.samples(), 4);

  const StructurePeak& pier = summary.structure(0);
  EXPECT_EQ(pier.peak_force, 6.0);
  EXPECT_EQ(pier.peak_time, 0.75) << "a tie keeps the first time";
  EXPECT_EQ(pier.force_at_peak, Vec3(0, 0, -6));
  // sum F dt = (3, 4, 0) 0.5 + (0, 0, -6) 0.25 + (6, 0, 0) 0.25 + (1, 0, 0) 0.5
  EXPECT_EQ(pier.impulse, Vec3(3.5, 2.0, -1.5));
  EXPECT_EQ(pier.peak_contact_area, 3.0);
  EXPECT_EQ(pier.peak_wetted_height, 0.5);

  const ForcePeak& front = summary.face(0, 0);
  EXPECT_EQ(front.peak_force, 6.0);
  EXPECT_EQ(front.peak_time, 0.75);
  EXPECT_EQ(front.impulse, Vec3(2.0, 0.0, -1.5));
  EXPECT_EQ(front.peak_contact_area, 1.5);
  const ForcePeak& back = summary.face(0, 1);  // (0, 4, 0), 0, (6, 0, 0), 0
  EXPECT_EQ(back.peak_force, 6.0);
  EXPECT_EQ(back.peak_time, 1.0);
  EXPECT_EQ(back.force_at_peak, Vec3(6, 0, 0));
  EXPECT_EQ(back.impulse, Vec3(1.5, 2.0, 0.0));
  EXPECT_EQ(back.peak_contact_area, 0.75);

  const StructurePeak& wall = summary.structure(1);  // zero force: the first sample is the peak
  EXPECT_EQ(wall.peak_force, 0.0);
  EXPECT_EQ(wall.peak_time, 0.5);
  EXPECT_EQ(wall.impulse, Vec3::Zero());
  EXPECT_TRUE(wall.faces.empty());

  EXPECT_EQ(summary.Find("wall"), 1);
  EXPECT_EQ(summary.Find("pier"), 0);
  EXPECT_EQ(summary.Find("nothing"), -1);
}

TEST(ForceSummaryTest, NoSamplesGiveNaNPeakTime) {
  const ForceSummary summary(Channels());
  EXPECT_EQ(summary.samples(), 0);
  EXPECT_TRUE(std::isnan(summary.structure(0).peak_time));
  EXPECT_TRUE(std::isnan(summary.face(0, 1).peak_time));
  EXPECT_EQ(summary.structure(0).peak_force, 0.0);
}

TEST(ForceSummaryTest, NaNSampleIsNeverThePeak) {
  const Real nan = std::numeric_limits<Real>::quiet_NaN();
  ForceSummary summary(Channels());
  summary.Add(1.0, 1.0, Report(Vec3(nan, 0, 0), Vec3::Zero(), 0, 0));
  EXPECT_TRUE(std::isnan(summary.structure(0).peak_time));
  summary.Add(2.0, 1.0, Report(Vec3(0, 2, 0), Vec3::Zero(), 0, 0));
  EXPECT_EQ(summary.structure(0).peak_time, 2.0);
  EXPECT_EQ(summary.structure(0).peak_force, 2.0);
  EXPECT_TRUE(std::isnan(summary.structure(0).impulse.x())) << "the impulse keeps the NaN";
  EXPECT_EQ(summary.face(0, 0).peak_time, 1.0) << "the front face had a finite force";
}

TEST(ForceSummaryTest, ReportOfTheWrongShapeThrows) {
  ForceSummary summary(Channels());
  ContactReport too_few;
  too_few.structures.resize(1);
  EXPECT_THROW(summary.Add(0, 1, too_few), std::logic_error);
  ContactReport missing_faces = Report(Vec3::Zero(), Vec3::Zero(), 0, 0);
  missing_faces.structures[0].faces.pop_back();
  EXPECT_THROW(summary.Add(0, 1, missing_faces), std::logic_error);
  ContactReport extra_face = Report(Vec3(1, 0, 0), Vec3::Zero(), 0, 0);
  extra_face.structures[1].faces.resize(1);  // the wall has no faces
  EXPECT_THROW(summary.Add(0, 1, extra_face), std::logic_error);
  EXPECT_EQ(summary.samples(), 0);
  EXPECT_EQ(summary.structure(0).impulse, Vec3::Zero()) << "a rejected report changes nothing";
}

}  // namespace
}  // namespace surge
