// Force-signal analysis (src/forces/force_analysis.h) on synthetic series with exact answers:
// peak and its time, rectangle-rule impulse (bit-equal to the writer's ForceSummary), the seed's
// impulse-preserving moving average, the filters (constants pass, zero phase keeps a symmetric
// pulse's peak time, the Butterworth magnitude response), the plateau detector on a
// step + ramp + constant signal, and the coefficients (seed eqs. 7.14-7.19) by hand.
#include "forces/force_analysis.h"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <stdexcept>

#include "contact/force_summary.h"

namespace surge {
namespace {

// n steps of length dt ending at dt, 2 dt, ...
void UniformTimes(size_t n, Real dt, std::vector<Real>& time, std::vector<Real>& steps) {
  time.resize(n);
  steps.assign(n, dt);
  for (size_t k = 0; k < n; ++k) time[k] = Real(k + 1) * dt;
}

// Steps of varying length (CFL-like), dyadic so that the times are exact.
void UnevenTimes(size_t n, std::vector<Real>& time, std::vector<Real>& steps) {
  time.resize(n);
  steps.resize(n);
  Real t = 0;
  for (size_t k = 0; k < n; ++k) {
    steps[k] = (k % 3 == 0 ? 1.0 : k % 3 == 1 ? 0.5 : 0.75) / 256;
    t += steps[k];
    time[k] = t;
  }
}

TEST(ForceAnalysisTest, PeakKeepsSignTimeAndFirstOfTies) {
  const std::vector<Real> t = {0.5, 0.75, 1.0, 1.5, 2.0};
  const Peak p = FindPeak(t, {1, -6, 6, std::nan(""), 2});
  EXPECT_EQ(p.value, -6);
  EXPECT_EQ(p.time, 0.75);
  EXPECT_EQ(p.index, 1u);
  const Peak none = FindPeak(t, std::vector<Real>(5, std::nan("")));
  EXPECT_EQ(none.index, 5u);
  EXPECT_TRUE(std::isnan(none.value));
}

TEST(ForceAnalysisTest, ComponentsAndFaceNormals) {
  const std::vector<Vec3> f = {Vec3(3, -4, 12)};
  EXPECT_EQ(ComponentSeries(f, ForceComponent::kMagnitude)[0], 13);
  EXPECT_EQ(ComponentSeries(f, ForceComponent::kY)[0], -4);
  // Material pushing on the x- face of a column pushes it towards +x: the normal part is > 0.
  EXPECT_EQ(ComponentSeries(f, ForceComponent::kNormal, *AxisFaceNormal("x-"))[0], 3);
  EXPECT_EQ(ComponentSeries(f, ForceComponent::kNormal, *AxisFaceNormal("y+"))[0], 4);
  EXPECT_FALSE(AxisFaceNormal("side"));
  EXPECT_FALSE(AxisFaceNormal("w-"));
}

TEST(ForceAnalysisTest, ImpulseOfAPiecewiseConstantSeriesIsExactAndAsTheWriter) {
  // F = 2, -4, 8, 1 over steps 0.5, 0.25, 0.25, 0.5: 1 - 1 + 2 + 0.5 = 2.5 exactly.
  const std::vector<Real> dt = {0.5, 0.25, 0.25, 0.5};
  EXPECT_EQ(Impulse(dt, {2, -4, 8, 1}), 2.5);
  // The same sum, bit for bit, as the results writer's ForceSummary on an uneven series.
  std::vector<Real> time, steps;
  UnevenTimes(1000, time, steps);
  std::vector<Vec3> force(time.size());
  ForceSummary summary({ForceChannel{"pier", {}}});
  for (size_t k = 0; k < time.size(); ++k) {
    force[k] = Vec3(std::sin(0.37 * Real(k)) * 1e5 + 3e4, 1.0 / Real(k + 3), -Real(k % 7) * 0.1);
    ContactReport r;
    r.structures.resize(1);
    r.structures[0].force = force[k];
    summary.Add(time[k], steps[k], r);
  }
  const Vec3 impulse = Impulse(steps, force);
  EXPECT_EQ(impulse, summary.structure(0).impulse);
}

TEST(ForceAnalysisTest, MovingAverageIsTheSeedFormulaForConstantSteps) {
  std::vector<Real> time, dt;
  UniformTimes(40, 0.01, time, dt);
  std::vector<Real> x(40);
  for (size_t k = 0; k < x.size(); ++k) x[k] = Real((k * 37) % 11) - 3;
  // Window 0.05 s = 2 w + 1 samples with w = 2: f~_k = 1/5 sum_{k-2}^{k+2} f_j (seed spec §5.5).
  const std::vector<Real> avg = MovingAverage(time, dt, x, 0.05);
  Real worst = 0;
  for (size_t k = 2; k + 2 < x.size(); ++k) {
    const Real seed = (x[k - 2] + x[k - 1] + x[k] + x[k + 1] + x[k + 2]) / 5;
    worst = std::max(worst, std::abs(avg[k] - seed));
  }
  EXPECT_LT(worst, 1e-13);
  EXPECT_NEAR(avg[0], (x[0] + x[1] + x[2]) / 3, 1e-13);  // truncated at the ends
}

TEST(ForceAnalysisTest, ConstantsPassEveryFilterUnchanged) {
  for (const bool uneven : {false, true}) {
    std::vector<Real> time, dt;
    if (uneven) {
      UnevenTimes(500, time, dt);
    } else {
      UniformTimes(500, 1.0 / 512, time, dt);
    }
    const std::vector<Real> c(time.size(), 1234.5);
    SmoothingSettings s;
    Real worst = 0;
    for (const SmoothingKind kind : {SmoothingKind::kNone, SmoothingKind::kMovingAverage,
                                     SmoothingKind::kExponential, SmoothingKind::kLowPass}) {
      for (const int order : {1, 2}) {
        s = SmoothingSettings{kind, 0.05, 0.02, 10.0, order};
        const std::vector<Real> y = Smooth(time, dt, c, s);
        ASSERT_EQ(y.size(), c.size());
        for (Real v : y) worst = std::max(worst, std::abs(v - 1234.5) / 1234.5);
      }
    }
    EXPECT_LT(worst, 1e-12) << (uneven ? "uneven" : "uniform") << " steps";
    const std::vector<Real> a = ImpulsePreservingAverage(time, dt, c, 0.1);
    for (Real v : a) worst = std::max(worst, std::abs(v - 1234.5) / 1234.5);
    EXPECT_LT(worst, 1e-12);
  }
}

TEST(ForceAnalysisTest, ImpulsePreservingAverageKeepsTheImpulse) {
  std::vector<Real> time, dt;
  UnevenTimes(3000, time, dt);
  std::vector<Real> x(time.size());
  for (size_t k = 0; k < x.size(); ++k) {
    // An impact spike, then a noisy plateau that stops short of the end (the ends matter).
    const Real t = time[k];
    x[k] = (t > 1 && t < 1.1 ? 5e4 : 0) + (t > 0.5 && t < 6 ? 2e4 : 0) +
           3e3 * std::sin(97.0 * t) * std::sin(3.1 * Real(k));
  }
  const Real raw = Impulse(dt, x);
  const std::vector<Real> plain = MovingAverage(time, dt, x, 0.25);
  const std::vector<Real> kept = ImpulsePreservingAverage(time, dt, x, 0.25);
  EXPECT_NEAR(Impulse(dt, kept), raw, 1e-12 * std::abs(raw));
  // The plain average loses some impulse at the truncated ends; the rescaled one does not.
  EXPECT_GT(std::abs(Impulse(dt, plain) - raw), 1e-9 * std::abs(raw));
}

TEST(ForceAnalysisTest, ExponentialIsTheExactFirstOrderStepResponse) {
  std::vector<Real> time, dt;
  UniformTimes(100, 0.01, time, dt);
  std::vector<Real> x(100, 0.0);
  for (size_t k = 10; k < x.size(); ++k) x[k] = 1;  // step at sample 10
  const Real tau = 0.05;
  const std::vector<Real> y = ExponentialSmooth(dt, x, tau);
  EXPECT_EQ(y[9], 0);
  // y after j steps of the step: 1 - exp(-j dt / tau).
  for (size_t j = 1; j < 50; j += 7)
    EXPECT_NEAR(y[9 + j], 1 - std::exp(-Real(j) * 0.01 / tau), 1e-14) << j;
}

TEST(ForceAnalysisTest, ZeroPhaseLowPassKeepsTheTimeOfASymmetricPulse) {
  std::vector<Real> time, dt;
  UniformTimes(2001, 1e-3, time, dt);
  std::vector<Real> x(time.size());
  const Real centre = time[1000];
  for (size_t k = 0; k < x.size(); ++k) {
    const Real u = (time[k] - centre) / 0.02;
    x[k] = 1e5 * std::exp(-u * u) + 2e4 * std::cos(2 * std::numbers::pi * 200 * (time[k] - centre));
  }
  for (const int order : {1, 2}) {
    const std::vector<Real> y = ZeroPhaseLowPass(time, x, 20.0, order);
    const Peak p = FindPeak(time, y);
    EXPECT_EQ(p.index, 1000u) << "order " << order;
    EXPECT_LT(p.value, 1e5);  // smoothed peak below the raw one
    EXPECT_GT(p.value, 0.5e5);
  }
  // A causal filter moves the peak later: the exponential one does.
  const Peak causal = FindPeak(time, ExponentialSmooth(dt, x, 0.01));
  EXPECT_GT(causal.index, 1002u);
}

TEST(ForceAnalysisTest, ButterworthMagnitudeResponse) {
  // Forward-backward Butterworth of order N: |H(f)|^2 = 1 / (1 + (f/fc)^(2N)) (the square of
  // one pass). A sine at f = fc is halved; at 10 fc order 2 leaves 1e-4.
  std::vector<Real> time, dt;
  UniformTimes(8000, 1e-3, time, dt);
  const Real fc = 10;
  for (const int order : {1, 2}) {
    for (const Real f : {1.0, 10.0, 100.0}) {
      std::vector<Real> x(time.size());
      for (size_t k = 0; k < x.size(); ++k) x[k] = std::sin(2 * std::numbers::pi * f * time[k]);
      const std::vector<Real> y = ZeroPhaseLowPass(time, x, fc, order);
      Real amp = 0;
      for (size_t k = 3000; k < 5000; ++k) amp = std::max(amp, std::abs(y[k]));
      // The bilinear transform maps f to tan(pi f dt) / tan(pi fc dt) on the analogue axis.
      const Real ratio = std::tan(std::numbers::pi * f * 1e-3) / std::tan(std::numbers::pi * fc * 1e-3);
      const Real expected = 1 / (1 + std::pow(ratio, 2 * order));
      EXPECT_NEAR(amp, expected, 2e-3 + 0.01 * expected) << "order " << order << ", f " << f;
    }
  }
  EXPECT_THROW(ZeroPhaseLowPass(time, std::vector<Real>(time.size(), 1.0), 600.0, 2),
               std::invalid_argument);
}

// Impact step to 2000 N at 0.5 s, held to 0.7 s, a ramp down to 1000 N at 1.2 s, then 1000 N.
std::vector<Real> StepRampConstant(const std::vector<Real>& time) {
  std::vector<Real> x(time.size());
  for (size_t k = 0; k < time.size(); ++k) {
    const Real t = time[k];
    x[k] = t <= 0.5 + 1e-12 ? 0 : t <= 0.7 + 1e-12 ? 2000 : t < 1.2 ? 2000 - 2000 * (t - 0.7) : 1000;
  }
  return x;
}

TEST(ForceAnalysisTest, PlateauOfAStepRampConstantSignal) {
  std::vector<Real> time, dt;
  UniformTimes(300, 0.01, time, dt);  // 0.01 .. 3.00 s
  const std::vector<Real> x = StepRampConstant(time);
  SteadyStateSettings s;  // average 0.1 s, min window 0.5 s, tolerance 2 %
  const std::vector<Real> avg = ImpulsePreservingAverage(time, dt, x, s.average);
  const Plateau p = FindPlateau(time, dt, avg, x, s);
  ASSERT_TRUE(p.found) << p.note;
  // The ramp is within 2 % of 1000 N from t = 1.19 s; the average widens the corner by 0.05 s.
  EXPECT_GE(p.t0, 1.13);
  EXPECT_LE(p.t0, 1.2);
  EXPECT_DOUBLE_EQ(p.t1, 3.0);
  EXPECT_NEAR(p.mean, 1000, 2.0);
  EXPECT_NEAR(p.raw_mean, 1000, 2.0);
  EXPECT_LE(p.max_relative_deviation, 0.02);
  EXPECT_LT(p.relative_std, 0.01);

  // The whole analysis: peak 2000 N first reached at 0.51 s, steady state 1000 N.
  ForceSignal signal{time, dt, {}, std::vector<Real>(time.size(), 2.0)};
  for (Real v : x) signal.force.push_back(Vec3(v, 0, 0));
  AnalysisSettings settings;
  settings.smoothing = SmoothingSettings{SmoothingKind::kMovingAverage, 0.05, 0, 0, 2};
  const ForceAnalysis a = AnalyseForce(signal, ForceComponent::kNormal, Vec3(-1, 0, 0), settings);
  EXPECT_EQ(a.peak.value, 2000);
  EXPECT_DOUBLE_EQ(a.peak.time, 0.51);
  EXPECT_NEAR(a.smoothed_peak.value, 2000, 1e-9);  // the hold lasts longer than the window
  // 20 samples of 2000 N, the ramp's 49 samples (mean 1500 N), 181 of 1000 N, dt = 0.01 s.
  EXPECT_NEAR(a.component_impulse, (20 * 2000 + 49 * 1500 + 181 * 1000) * 0.01, 1e-6);
  ASSERT_TRUE(a.steady.found);
  EXPECT_NEAR(a.steady.mean, 1000, 2.0);
}

TEST(ForceAnalysisTest, NoPlateauWhenTheRunIsTooShort) {
  std::vector<Real> time, dt;
  UniformTimes(150, 0.01, time, dt);  // ends at 1.5 s: 0.3 s of constant force
  const std::vector<Real> x = StepRampConstant(time);
  SteadyStateSettings s;
  const Plateau p = FindPlateau(time, dt, ImpulsePreservingAverage(time, dt, x, 0.1), x, s);
  EXPECT_FALSE(p.found);
  EXPECT_NE(p.note.find("less than steady_state.min_window"), std::string::npos) << p.note;
  EXPECT_NEAR(p.mean, 1000, 5.0);  // the stretch it measured is still reported
  UniformTimes(40, 0.01, time, dt);
  const Plateau q = FindPlateau(time, dt, std::vector<Real>(40, 7.0), std::vector<Real>(40, 7.0), s);
  EXPECT_FALSE(q.found);
  EXPECT_NE(q.note.find("the run lasts 0.4 s"), std::string::npos) << q.note;
  // An explicit window is taken as given.
  s.window = std::array<Real, 2>{1.295, 1.5};
  UniformTimes(150, 0.01, time, dt);
  const Plateau w = FindPlateau(time, dt, x, x, s);
  EXPECT_TRUE(w.found);
  EXPECT_NEAR(w.mean, 1000, 1e-9);
  EXPECT_NEAR(w.t0, 1.29, 1e-12);
}

TEST(ForceAnalysisTest, CoefficientsByHand) {
  ReferenceValues ref;
  ref.density = 2000;
  ref.velocity = 2;
  ref.width = 2;
  ref.height = 3;
  ref.k0 = 0.5;
  ref.gravity = 10;
  // rho v^2 w H = 2000 * 4 * 6 = 48000 N.
  const Coefficients c = ComputeCoefficients(96000, 72000, 24000.0, 8.0, 6.0, ref);
  EXPECT_EQ(*c.area, 6);
  EXPECT_EQ(*c.c_pk, 2);                       // (7.14)
  EXPECT_EQ(*c.c_pk_smoothed, 1.5);
  EXPECT_EQ(*c.c_ss, 0.5);                     // (7.14)
  EXPECT_EQ(*c.c_pk_actual, 96000.0 / 64000);  // A = A_act = 8
  EXPECT_EQ(*c.h_act_pk, 4);                   // (7.15)
  EXPECT_EQ(*c.h_act_ss, 3);
  EXPECT_DOUBLE_EQ(*c.a_ratio_pk, 8.0 / 6);    // (7.16)
  // f_st = 1/2 K0 rho |g| H_act^2 w_c (7.17)-(7.18): 1/2 0.5 2000 10 16 2 = 160000 N.
  EXPECT_EQ(*c.f_st_pk, 160000);
  EXPECT_EQ(*c.f_st_ss, 90000);
  EXPECT_EQ(*c.r_pk, 0.6);                     // (7.19)
  EXPECT_DOUBLE_EQ(*c.r_ss, 24000.0 / 90000);
  EXPECT_EQ(*c.peak_to_steady, 4);
  // With H_b = 3 m for H_act: 1/2 0.5 2000 10 9 2 = 90000 N.
  EXPECT_EQ(*c.f_st_hb, 90000);
  EXPECT_DOUBLE_EQ(*c.r_pk_hb, 96000.0 / 90000);
  EXPECT_DOUBLE_EQ(*c.r_ss_hb, 24000.0 / 90000);
  EXPECT_TRUE(c.notes.empty());

  // An explicit area wins over w_c H_b; no velocity: no C, but R still.
  ref.area = 12;
  ref.velocity.reset();
  const Coefficients d = ComputeCoefficients(96000, 72000, std::nullopt, 8.0, std::nullopt, ref);
  EXPECT_EQ(*d.area, 12);
  EXPECT_FALSE(d.c_pk);
  EXPECT_FALSE(d.c_ss);
  EXPECT_FALSE(d.r_ss);
  EXPECT_EQ(*d.r_pk, 0.6);
  EXPECT_FALSE(d.r_ss_hb);
  ASSERT_EQ(d.notes.size(), 2u);
  EXPECT_NE(d.notes[0].find("no steady state"), std::string::npos);
  EXPECT_NE(d.notes[1].find("velocity"), std::string::npos) << d.notes[1];
}

}  // namespace
}  // namespace surge
