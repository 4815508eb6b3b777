// Force-signal analysis on plain arrays (issue #6; seed spec §5.4-5.6, Mast 2013 §7.4.2): peak,
// impulse, smoothing filters, the seed's impulse-preserving moving average with a plateau
// detector for the steady state, and the coefficients C_pk, C_ss (7.14), A_act, H_act (7.15),
// A_ratio (7.16), f_st (7.17-7.18), R_pk, R_ss (7.19). No I/O; used by `surge forces` and at
// the end of `surge run`. Formulas and choices: docs/forces.md.
#pragma once
#include <cstddef>
#include <limits>
#include <optional>
#include <string>
#include <vector>

#include "core/analysis.h"
#include "core/math.h"

namespace surge {

// One force series (a structure or one of its faces), one sample per step: sample k is the
// force of the step (time[k] - dt[k], time[k]] (docs/results-format.md, "Force series").
struct ForceSignal {
  std::vector<Real> time;          // end of the step [s]
  std::vector<Real> dt;            // length of the step [s]
  std::vector<Vec3> force;         // force on the structure [N] (2-D: N/m)
  std::vector<Real> contact_area;  // A_act, sum of h^(d-1) over contact nodes [m^2] (2-D: m^2/m)
};

inline constexpr Real kNaN = std::numeric_limits<Real>::quiet_NaN();

// The scalar series of `component`: F.e_x, F.e_y, F.e_z, |F|, or F.(-n) for kNormal with the
// face's outward unit normal n (so that material pushing on the face gives a positive value).
std::vector<Real> ComponentSeries(const std::vector<Vec3>& force, ForceComponent component,
                                  const Vec3& outward_normal = Vec3::UnitX());

// Outward normal of an axis face name ("x-" -> (-1, 0, 0), ..., "z+"), or nullopt.
std::optional<Vec3> AxisFaceNormal(const std::string& face);

const char* ComponentName(ForceComponent c);  // "x", "y", "z", "normal", "magnitude"
const char* SmoothingName(SmoothingKind k);   // "none", "moving_average", "exponential", "low_pass"

// The sample of largest |x| (the first of equal ones; NaN samples skipped). value keeps its
// sign. index == x.size() and NaNs when there is no finite sample.
struct Peak {
  Real value = kNaN;  // [N]
  Real time = kNaN;   // time[index] [s]
  size_t index = 0;
};
Peak FindPeak(const std::vector<Real>& time, const std::vector<Real>& x);

// Impulse sum_k x_k dt_k in sample order: the exact integral of the piecewise-constant force
// the steps applied, the same sum (and rounding) as ForceSummary in the results writer.
Real Impulse(const std::vector<Real>& dt, const std::vector<Real>& x);
Vec3 Impulse(const std::vector<Real>& dt, const std::vector<Vec3>& force);

// --- Smoothing filters (all return a series of x's length; Pre: equal lengths, dt > 0) ------

// Centred moving average over a time window of full width `window` [s]: the dt-weighted mean of
// the samples with |t_j - t_k| <= window / 2, truncated at the ends of the series. For a
// constant dt it is the seed's f~_k = 1/(2w+1) sum_{j=k-w}^{k+w} f_j (seed spec §5.5 [REC]),
// w = floor(window / (2 dt)). window <= 0 returns x.
std::vector<Real> MovingAverage(const std::vector<Real>& time, const std::vector<Real>& dt,
                                const std::vector<Real>& x, Real window);

// The seed's steady-state average (Mast 2013 §7.4.2, Fig. 7.35; seed spec §5.5 [REC]): the
// moving average f~ rescaled so that its impulse equals the raw one,
// f^_k = f~_k sum_j f_j dt_j / sum_j f~_j dt_j (no rescaling when sum f~ dt = 0).
std::vector<Real> ImpulsePreservingAverage(const std::vector<Real>& time,
                                           const std::vector<Real>& dt,
                                           const std::vector<Real>& x, Real window);

// First-order low-pass tau dy/dt + y = x, discretised exactly for the piecewise-constant input
// of each step (zero-order hold): y_k = y_{k-1} + (1 - exp(-dt_k / tau)) (x_k - y_{k-1}),
// y_0 = x_0 (Franklin, Powell & Workman, Digital Control of Dynamic Systems, 3rd ed., §6.2).
// Causal: it delays the signal by about tau. tau <= 0 returns x.
std::vector<Real> ExponentialSmooth(const std::vector<Real>& dt, const std::vector<Real>& x,
                                    Real time_constant);

// Zero-phase Butterworth low-pass of order 1 or 2, cut-off `cutoff` [Hz]: the digital filter
// from the analogue prototype by the bilinear transform with pre-warped cut-off (Oppenheim &
// Schafer, Discrete-Time Signal Processing, 3rd ed., §7.2), run forward and then backward
// (Gustafsson 1996, as scipy.signal.filtfilt: odd extension of 3 (order + 1) samples at each end,
// filter state started at rest on the first sample), so the phase cancels. Samples are taken
// as equally spaced when dt varies by less than 1e-6; otherwise the series is interpolated
// linearly onto as many equally spaced times, filtered and interpolated back. Throws
// std::invalid_argument when the cut-off is not below the Nyquist frequency 1 / (2 dt_mean).
std::vector<Real> ZeroPhaseLowPass(const std::vector<Real>& time, const std::vector<Real>& x,
                                   Real cutoff, int order);

// The filter chosen by `s`.
std::vector<Real> Smooth(const std::vector<Real>& time, const std::vector<Real>& dt,
                         const std::vector<Real>& x, const SmoothingSettings& s);

// --- Steady state ---------------------------------------------------------------------------

// The plateau of the averaged signal a: by default the longest final stretch [t0, t1] (t1 the
// end of the run) in which every sample lies within tolerance * |mean| of the stretch's
// dt-weighted mean (grown backwards from the last sample until a sample breaks it; seed spec
// §5.5 [REC]: "relative change below 2 % for at least 0.5 s"); it counts only when it lasts at
// least min_window. With an explicit window, the samples whose time lies in [t0, t1].
struct Plateau {
  bool found = false;        // a plateau of at least min_window (or the explicit window)
  bool explicit_window = false;
  Real t0 = kNaN, t1 = kNaN;  // the stretch, from the start of its first step to its last time [s]
  Real mean = kNaN;           // dt-weighted mean of a over the stretch [N]
  Real raw_mean = kNaN;       // the same of the raw signal [N]
  Real relative_std = kNaN;   // dt-weighted standard deviation of a / |mean| [-]
  Real max_relative_deviation = kNaN;  // max |a_k - mean| / |mean| [-]
  size_t begin = 0, end = 0;  // samples [begin, end)
  std::string note;           // why there is none, or a remark
};
Plateau FindPlateau(const std::vector<Real>& time, const std::vector<Real>& dt,
                    const std::vector<Real>& averaged, const std::vector<Real>& raw,
                    const SteadyStateSettings& s);

// --- Coefficients ---------------------------------------------------------------------------

// Seed eqs. (7.14)-(7.19), with the reference values in `ref` (unset ones leave the
// coefficients that need them unset, with a note). f_pk and f_ss are magnitudes [N];
// a_act_pk is the contact area at the peak, a_act_ss its mean over the plateau [m^2].
// H_act = A_act / w_c (7.15) is taken at the peak for R_pk and over the plateau for R_ss:
// f_st = 1/2 K0 rho0 |g| H_act^2 w_c (7.17-7.18) is the static force of the material that
// touches the face at that moment.
struct Coefficients {
  std::optional<Real> area;           // A of (7.13): ref.area, else w_c H_b [m^2]
  std::optional<Real> c_pk, c_ss;     // f / (rho0 v0^2 A) (7.14) [-]
  std::optional<Real> c_pk_smoothed;  // from the smoothed peak [-]
  std::optional<Real> c_pk_actual, c_ss_actual;  // with A = A_act (seed §7.4.2) [-]
  std::optional<Real> h_act_pk, h_act_ss;        // A_act / w_c (7.15) [m]
  std::optional<Real> a_ratio_pk, a_ratio_ss;    // A_act / (w_c H_b) (7.16) [-]
  std::optional<Real> f_st_pk, f_st_ss;          // 1/2 K0 rho0 |g| H_act^2 w_c (7.17-7.18) [N]
  std::optional<Real> r_pk, r_ss;                // f / f_st (7.19) [-]
  std::optional<Real> r_pk_smoothed;             // smoothed peak / f_st_pk [-]
  // The same with H_b for H_act: f_st of the undisturbed flow depth, independent of the
  // node-count contact area (which the grid inflates, docs/forces.md) [N], [-].
  std::optional<Real> f_st_hb, r_pk_hb, r_ss_hb;
  std::optional<Real> peak_to_steady;            // f_pk / f_ss [-]
  std::vector<std::string> notes;
};
Coefficients ComputeCoefficients(Real f_pk, Real f_pk_smoothed, std::optional<Real> f_ss,
                                 Real a_act_pk, std::optional<Real> a_act_ss,
                                 const ReferenceValues& ref);

// --- Everything at once ---------------------------------------------------------------------

struct ForceAnalysis {
  ForceComponent component = ForceComponent::kMagnitude;
  size_t samples = 0;
  Real duration = 0;  // sum of dt [s]
  // |F| (seed BReactionForce_Max).
  Peak magnitude_peak;
  Vec3 force_at_peak = Vec3::Constant(kNaN);  // F at magnitude_peak [N]
  Vec3 impulse = Vec3::Zero();                // sum F dt [N s]
  Real peak_contact_area = 0;                 // [m^2]
  // The analysed component: raw, and after the selected smoothing.
  Peak peak;
  Peak smoothed_peak;
  Real component_impulse = 0;  // [N s]
  Real a_act_pk = kNaN;        // contact area at the raw component peak [m^2]
  std::optional<Real> a_act_ss;
  Plateau steady;
  Coefficients coefficients;
  std::vector<std::string> notes;
};

// Pre: the signal's arrays have equal lengths. `outward_normal` is used by kNormal only.
// Throws std::invalid_argument for impossible filter settings (ZeroPhaseLowPass).
ForceAnalysis AnalyseForce(const ForceSignal& signal, ForceComponent component,
                           const Vec3& outward_normal, const AnalysisSettings& settings);

}  // namespace surge
