// Force-signal analysis (issue #6): peak, impulse, filters, steady-state plateau and the seed's
// force coefficients (Mast 2013 §7.4.2, eqs. 7.13-7.19; seed spec §5.4-5.6). docs/forces.md.
#include "forces/force_analysis.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <numbers>
#include <stdexcept>
#include <string>

namespace surge {
namespace {

std::string Num(Real v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.4g", v);
  return buf;
}

// One pass of a direct-form II transposed filter of order <= 2 (b, a with a0 = 1) over x,
// started at rest on the value x[0] (state of a constant input x[0]; DC gain 1).
void FilterPass(const Real b[3], const Real a[3], std::vector<Real>& x) {
  if (x.empty()) return;
  const Real x0 = x[0];
  // Steady state of a constant input c with output c: z2 = (b2 - a2) c, z1 = (b1 - a1) c + z2.
  Real z2 = (b[2] - a[2]) * x0;
  Real z1 = (b[1] - a[1]) * x0 + z2;
  for (Real& v : x) {
    const Real in = v;
    const Real out = b[0] * in + z1;
    z1 = b[1] * in - a[1] * out + z2;
    z2 = b[2] * in - a[2] * out;
    v = out;
  }
}

// Forward-backward pass on equally spaced samples of spacing h.
std::vector<Real> FiltFilt(const std::vector<Real>& x, Real h, Real cutoff, int order) {
  const size_t n = x.size();
  const Real nyquist = 0.5 / h;
  if (!(cutoff > 0) || !(cutoff < nyquist)) {
    throw std::invalid_argument("low_pass cut-off " + Num(cutoff) +
                                " Hz must lie between 0 and the Nyquist frequency " +
                                Num(nyquist) + " Hz of the force series (dt = " + Num(h) + " s)");
  }
  if (order != 1 && order != 2) {
    throw std::invalid_argument("low_pass order must be 1 or 2, got " + std::to_string(order));
  }
  // Bilinear transform s = 2/h (1 - z^-1)/(1 + z^-1) of the Butterworth prototype with the
  // cut-off pre-warped, K = tan(pi fc h) (Oppenheim & Schafer 3rd ed. eqs. 7.26, 7.35).
  const Real K = std::tan(std::numbers::pi * cutoff * h);
  Real b[3] = {0, 0, 0}, a[3] = {1, 0, 0};
  if (order == 1) {  // H(s) = 1 / (1 + s/wc)
    b[0] = b[1] = K / (1 + K);
    a[1] = (K - 1) / (K + 1);
  } else {  // H(s) = 1 / (1 + sqrt2 s/wc + (s/wc)^2)
    const Real norm = 1 / (1 + std::numbers::sqrt2 * K + K * K);
    b[0] = K * K * norm;
    b[1] = 2 * b[0];
    b[2] = b[0];
    a[1] = 2 * (K * K - 1) * norm;
    a[2] = (1 - std::numbers::sqrt2 * K + K * K) * norm;
  }
  if (n < 2) return x;
  // Odd extension at both ends (scipy.signal.filtfilt, padtype 'odd', padlen 3 (order + 1)).
  const size_t pad = std::min<size_t>(3 * size_t(order + 1), n - 1);
  std::vector<Real> y;
  y.reserve(n + 2 * pad);
  for (size_t i = pad; i >= 1; --i) y.push_back(2 * x[0] - x[i]);
  y.insert(y.end(), x.begin(), x.end());
  for (size_t i = 1; i <= pad; ++i) y.push_back(2 * x[n - 1] - x[n - 1 - i]);
  FilterPass(b, a, y);
  std::reverse(y.begin(), y.end());
  FilterPass(b, a, y);
  std::reverse(y.begin(), y.end());
  return std::vector<Real>(y.begin() + long(pad), y.begin() + long(pad + n));
}

// Linear interpolation of (t, x) at s (t increasing; clamped at the ends).
Real Interpolate(const std::vector<Real>& t, const std::vector<Real>& x, Real s, size_t& hint) {
  if (s <= t.front()) return x.front();
  if (s >= t.back()) return x.back();
  while (hint + 1 < t.size() && t[hint + 1] < s) ++hint;
  const Real w = (s - t[hint]) / (t[hint + 1] - t[hint]);
  return x[hint] + w * (x[hint + 1] - x[hint]);
}

}  // namespace

std::vector<Real> ComponentSeries(const std::vector<Vec3>& force, ForceComponent component,
                                  const Vec3& outward_normal) {
  std::vector<Real> out(force.size());
  for (size_t k = 0; k < force.size(); ++k) {
    const Vec3& f = force[k];
    switch (component) {
      case ForceComponent::kX: out[k] = f.x(); break;
      case ForceComponent::kY: out[k] = f.y(); break;
      case ForceComponent::kZ: out[k] = f.z(); break;
      case ForceComponent::kNormal: out[k] = -f.dot(outward_normal); break;
      case ForceComponent::kMagnitude: out[k] = f.norm(); break;
    }
  }
  return out;
}

std::optional<Vec3> AxisFaceNormal(const std::string& face) {
  if (face.size() != 2 || (face[1] != '-' && face[1] != '+')) return std::nullopt;
  const int axis = face[0] == 'x' ? 0 : face[0] == 'y' ? 1 : face[0] == 'z' ? 2 : -1;
  if (axis < 0) return std::nullopt;
  Vec3 n = Vec3::Zero();
  n[axis] = face[1] == '+' ? 1 : -1;
  return n;
}

const char* ComponentName(ForceComponent c) {
  switch (c) {
    case ForceComponent::kX: return "x";
    case ForceComponent::kY: return "y";
    case ForceComponent::kZ: return "z";
    case ForceComponent::kNormal: return "normal";
    case ForceComponent::kMagnitude: return "magnitude";
  }
  return "?";
}

const char* SmoothingName(SmoothingKind k) {
  switch (k) {
    case SmoothingKind::kNone: return "none";
    case SmoothingKind::kMovingAverage: return "moving_average";
    case SmoothingKind::kExponential: return "exponential";
    case SmoothingKind::kLowPass: return "low_pass";
  }
  return "?";
}

Peak FindPeak(const std::vector<Real>& time, const std::vector<Real>& x) {
  Peak p;
  p.index = x.size();
  Real best = -1;
  for (size_t k = 0; k < x.size(); ++k) {
    const Real m = std::abs(x[k]);
    if (std::isnan(m) || m <= best) continue;
    best = m;
    p.index = k;
  }
  if (p.index < x.size()) {
    p.value = x[p.index];
    p.time = time[p.index];
  }
  return p;
}

Real Impulse(const std::vector<Real>& dt, const std::vector<Real>& x) {
  Real sum = 0;
  for (size_t k = 0; k < x.size(); ++k) sum += x[k] * dt[k];
  return sum;
}

Vec3 Impulse(const std::vector<Real>& dt, const std::vector<Vec3>& force) {
  Vec3 sum = Vec3::Zero();
  for (size_t k = 0; k < force.size(); ++k) sum += force[k] * dt[k];  // as ForceSummary::Accumulate
  return sum;
}

std::vector<Real> MovingAverage(const std::vector<Real>& time, const std::vector<Real>& dt,
                                const std::vector<Real>& x, Real window) {
  const size_t n = x.size();
  if (!(window > 0) || n == 0) return x;
  // Prefix sums in extended precision: a window sum is a difference of two of them.
  std::vector<long double> sum_fdt(n + 1, 0), sum_dt(n + 1, 0);
  for (size_t k = 0; k < n; ++k) {
    sum_fdt[k + 1] = sum_fdt[k] + (long double)x[k] * dt[k];
    sum_dt[k + 1] = sum_dt[k] + dt[k];
  }
  // 1e-9 relative slack so that a sample exactly window/2 away counts despite rounding of t.
  const Real half = 0.5 * window * (1 + 1e-9);
  std::vector<Real> out(n);
  size_t lo = 0, hi = 0;  // window [lo, hi)
  for (size_t k = 0; k < n; ++k) {
    while (time[k] - time[lo] > half) ++lo;
    if (hi < k + 1) hi = k + 1;
    while (hi < n && time[hi] - time[k] <= half) ++hi;
    if (hi - lo == 1) {
      out[k] = x[k];
      continue;
    }
    out[k] = Real((sum_fdt[hi] - sum_fdt[lo]) / (sum_dt[hi] - sum_dt[lo]));
  }
  return out;
}

std::vector<Real> ImpulsePreservingAverage(const std::vector<Real>& time,
                                           const std::vector<Real>& dt,
                                           const std::vector<Real>& x, Real window) {
  std::vector<Real> avg = MovingAverage(time, dt, x, window);
  // Seed spec §5.5 [REC]: f^_k = f~_k sum_j f_j dt_j / sum_j f~_j dt_j.
  long double raw = 0, smooth = 0;
  for (size_t k = 0; k < x.size(); ++k) {
    raw += (long double)x[k] * dt[k];
    smooth += (long double)avg[k] * dt[k];
  }
  if (smooth != 0 && std::isfinite(double(smooth))) {
    const Real scale = Real(raw / smooth);
    for (Real& v : avg) v *= scale;
  }
  return avg;
}

std::vector<Real> ExponentialSmooth(const std::vector<Real>& dt, const std::vector<Real>& x,
                                    Real time_constant) {
  if (!(time_constant > 0) || x.empty()) return x;
  std::vector<Real> y(x.size());
  y[0] = x[0];
  for (size_t k = 1; k < x.size(); ++k) {
    const Real alpha = -std::expm1(-dt[k] / time_constant);  // 1 - exp(-dt/tau), ZOH
    y[k] = y[k - 1] + alpha * (x[k] - y[k - 1]);
  }
  return y;
}

std::vector<Real> ZeroPhaseLowPass(const std::vector<Real>& time, const std::vector<Real>& x,
                                   Real cutoff, int order) {
  const size_t n = x.size();
  if (n < 2) {
    if (order != 1 && order != 2) throw std::invalid_argument("low_pass order must be 1 or 2");
    return x;
  }
  const Real h = (time.back() - time.front()) / Real(n - 1);
  Real min_step = time[1] - time[0], max_step = min_step;
  for (size_t k = 1; k + 1 < n; ++k) {
    min_step = std::min(min_step, time[k + 1] - time[k]);
    max_step = std::max(max_step, time[k + 1] - time[k]);
  }
  if (max_step - min_step <= 1e-6 * h) return FiltFilt(x, h, cutoff, order);
  // Uneven steps (CFL-controlled dt): filter on an equally spaced copy.
  std::vector<Real> even(n);
  size_t hint = 0;
  for (size_t k = 0; k < n; ++k) even[k] = Interpolate(time, x, time.front() + Real(k) * h, hint);
  const std::vector<Real> filtered = FiltFilt(even, h, cutoff, order);
  std::vector<Real> grid(n);
  for (size_t k = 0; k < n; ++k) grid[k] = time.front() + Real(k) * h;
  std::vector<Real> out(n);
  hint = 0;
  for (size_t k = 0; k < n; ++k) out[k] = Interpolate(grid, filtered, time[k], hint);
  return out;
}

std::vector<Real> Smooth(const std::vector<Real>& time, const std::vector<Real>& dt,
                         const std::vector<Real>& x, const SmoothingSettings& s) {
  switch (s.kind) {
    case SmoothingKind::kNone: return x;
    case SmoothingKind::kMovingAverage: return MovingAverage(time, dt, x, s.window);
    case SmoothingKind::kExponential: return ExponentialSmooth(dt, x, s.time_constant);
    case SmoothingKind::kLowPass: return ZeroPhaseLowPass(time, x, s.cutoff, s.order);
  }
  return x;
}

Plateau FindPlateau(const std::vector<Real>& time, const std::vector<Real>& dt,
                    const std::vector<Real>& averaged, const std::vector<Real>& raw,
                    const SteadyStateSettings& s) {
  Plateau p;
  const size_t n = averaged.size();
  if (n == 0) {
    p.note = "no force samples";
    return p;
  }
  const Real run = time.back() - (time.front() - dt.front());
  if (s.window) {
    p.explicit_window = true;
    const Real t0 = (*s.window)[0], t1 = (*s.window)[1];
    p.begin = n;
    for (size_t k = 0; k < n; ++k) {
      if (time[k] >= t0 && time[k] <= t1) {
        if (p.begin == n) p.begin = k;
        p.end = k + 1;
      }
    }
    if (p.begin == n) {
      p.begin = p.end = 0;
      p.note = "no force sample lies in the steady_state window [" + Num(t0) + ", " + Num(t1) +
               "] s (the series covers " + Num(time.front()) + " to " + Num(time.back()) + " s)";
      return p;
    }
  } else {
    // Grow the final stretch backwards while every sample stays within tolerance of its mean.
    long double sum = 0, sum_dt = 0;
    Real lo = averaged[n - 1], hi = averaged[n - 1];
    size_t begin = n;
    for (size_t k = n; k-- > 0;) {
      const long double s_new = sum + (long double)averaged[k] * dt[k];
      const long double dt_new = sum_dt + dt[k];
      const Real lo_new = std::min(lo, averaged[k]), hi_new = std::max(hi, averaged[k]);
      const Real mean = Real(s_new / dt_new);
      const Real deviation = std::max(hi_new - mean, mean - lo_new);
      if (!(deviation <= s.tolerance * std::abs(mean))) break;
      sum = s_new;
      sum_dt = dt_new;
      lo = lo_new;
      hi = hi_new;
      begin = k;
    }
    if (begin == n) begin = n - 1;  // even the last sample alone fails (NaN): report it
    p.begin = begin;
    p.end = n;
  }
  long double sum = 0, sum_raw = 0, sum_dt = 0;
  for (size_t k = p.begin; k < p.end; ++k) {
    sum += (long double)averaged[k] * dt[k];
    sum_raw += (long double)raw[k] * dt[k];
    sum_dt += dt[k];
  }
  p.mean = Real(sum / sum_dt);
  p.raw_mean = Real(sum_raw / sum_dt);
  long double var = 0;
  Real max_dev = 0;
  for (size_t k = p.begin; k < p.end; ++k) {
    const Real d = averaged[k] - p.mean;
    var += (long double)d * d * dt[k];
    max_dev = std::max(max_dev, std::abs(d));
  }
  const Real sd = Real(std::sqrt(var / sum_dt));
  const Real scale = std::abs(p.mean);
  p.relative_std = scale > 0 ? sd / scale : (sd == 0 ? 0 : kNaN);
  p.max_relative_deviation = scale > 0 ? max_dev / scale : (max_dev == 0 ? 0 : kNaN);
  p.t0 = time[p.begin] - dt[p.begin];
  p.t1 = time[p.end - 1];
  const Real length = p.t1 - p.t0;
  if (p.explicit_window) {
    p.found = true;
    p.note = "steady_state window given";
  } else if (run < s.min_window) {
    p.note = "no plateau: the run lasts " + Num(run) + " s, less than steady_state.min_window " +
             Num(s.min_window) + " s";
  } else if (length < s.min_window * (1 - 1e-9)) {
    p.note = "no plateau: the final stretch within " + Num(100 * s.tolerance) +
             " % of its mean lasts " + Num(length) + " s, less than steady_state.min_window " +
             Num(s.min_window) + " s";
  } else {
    p.found = true;
  }
  return p;
}

Coefficients ComputeCoefficients(Real f_pk, Real f_pk_smoothed, std::optional<Real> f_ss,
                                 Real a_act_pk, std::optional<Real> a_act_ss,
                                 const ReferenceValues& ref) {
  Coefficients c;
  std::vector<std::string> missing;
  const auto need = [&](const std::optional<Real>& v, const char* name) {
    if (!v) missing.push_back(name);
    return bool(v);
  };
  if (ref.area) {
    c.area = *ref.area;
  } else if (ref.width && ref.height) {
    c.area = *ref.width * *ref.height;  // A = w_c H_b (7.14)
  }
  // Dynamic pressure rho0 v0^2 (7.13; the usual 1/2 is absorbed into C).
  const bool dyn = need(ref.density, "density") & need(ref.velocity, "velocity");
  const Real q = dyn ? *ref.density * *ref.velocity * *ref.velocity : kNaN;
  if (dyn && c.area && q * *c.area > 0) {
    c.c_pk = f_pk / (q * *c.area);                    // C_pk (7.14)
    c.c_pk_smoothed = f_pk_smoothed / (q * *c.area);
    if (f_ss) c.c_ss = *f_ss / (q * *c.area);         // C_ss (7.14)
  } else if (!c.area) {
    missing.push_back("area (or width and height)");
  }
  if (dyn && q > 0) {
    if (a_act_pk > 0) c.c_pk_actual = f_pk / (q * a_act_pk);
    if (f_ss && a_act_ss && *a_act_ss > 0) c.c_ss_actual = *f_ss / (q * *a_act_ss);
  }
  if (need(ref.width, "width") && *ref.width > 0) {
    c.h_act_pk = a_act_pk / *ref.width;                   // H_act = A_act / w_c (7.15)
    if (a_act_ss) c.h_act_ss = *a_act_ss / *ref.width;
    if (ref.height && *ref.height > 0) {
      c.a_ratio_pk = a_act_pk / (*ref.width * *ref.height);  // A_ratio (7.16)
      if (a_act_ss) c.a_ratio_ss = *a_act_ss / (*ref.width * *ref.height);
    } else {
      missing.push_back("height");
    }
  }
  const bool stat = need(ref.k0, "k0") & need(ref.gravity, "gravity") & bool(ref.density) &
                    bool(c.h_act_pk);
  if (stat) {
    // f_st = b_st w_c, b_st = 1/2 K0 rho0 |g| H_act^2 (7.17)-(7.18).
    const Real per_h2 = 0.5 * *ref.k0 * *ref.density * *ref.gravity * *ref.width;
    c.f_st_pk = per_h2 * *c.h_act_pk * *c.h_act_pk;
    if (*c.f_st_pk > 0) {
      c.r_pk = f_pk / *c.f_st_pk;  // R_pk (7.19)
      c.r_pk_smoothed = f_pk_smoothed / *c.f_st_pk;
    } else {
      c.notes.push_back("no contact at the peak (H_act = 0): R_pk omitted");
    }
    if (c.h_act_ss) {
      c.f_st_ss = per_h2 * *c.h_act_ss * *c.h_act_ss;
      if (f_ss && *c.f_st_ss > 0) c.r_ss = *f_ss / *c.f_st_ss;  // R_ss (7.19)
    }
    if (ref.height && *ref.height > 0) {  // (7.17)-(7.18) with H_b for H_act
      c.f_st_hb = per_h2 * *ref.height * *ref.height;
      c.r_pk_hb = f_pk / *c.f_st_hb;
      if (f_ss) c.r_ss_hb = *f_ss / *c.f_st_hb;
    }
  }
  if (f_ss && *f_ss > 0) c.peak_to_steady = f_pk / *f_ss;
  if (!f_ss) c.notes.push_back("no steady state: C_ss, R_ss omitted");
  if (!missing.empty()) {
    std::sort(missing.begin(), missing.end());
    missing.erase(std::unique(missing.begin(), missing.end()), missing.end());
    std::string list;
    for (const std::string& m : missing) list += (list.empty() ? "" : ", ") + m;
    c.notes.push_back("reference values missing (" + list +
                      "): the coefficients that need them are omitted");
  }
  return c;
}

ForceAnalysis AnalyseForce(const ForceSignal& signal, ForceComponent component,
                           const Vec3& outward_normal, const AnalysisSettings& settings) {
  ForceAnalysis a;
  a.component = component;
  const std::vector<Real>& t = signal.time;
  const std::vector<Real>& dt = signal.dt;
  a.samples = t.size();
  for (Real h : dt) a.duration += h;
  const std::vector<Real> magnitude = ComponentSeries(signal.force, ForceComponent::kMagnitude);
  a.magnitude_peak = FindPeak(t, magnitude);
  if (a.magnitude_peak.index < a.samples) a.force_at_peak = signal.force[a.magnitude_peak.index];
  a.impulse = Impulse(dt, signal.force);
  for (Real area : signal.contact_area) a.peak_contact_area = std::max(a.peak_contact_area, area);

  const std::vector<Real> x = ComponentSeries(signal.force, component, outward_normal);
  a.peak = FindPeak(t, x);
  a.component_impulse = Impulse(dt, x);
  const std::vector<Real> smoothed = Smooth(t, dt, x, settings.smoothing);
  a.smoothed_peak = FindPeak(t, smoothed);
  if (a.peak.index < a.samples && a.peak.index < signal.contact_area.size())
    a.a_act_pk = signal.contact_area[a.peak.index];

  const std::vector<Real> averaged = ImpulsePreservingAverage(t, dt, x, settings.steady_state.average);
  a.steady = FindPlateau(t, dt, averaged, x, settings.steady_state);
  if (a.steady.end > a.steady.begin && signal.contact_area.size() == a.samples) {
    long double area = 0, span = 0;
    for (size_t k = a.steady.begin; k < a.steady.end; ++k) {
      area += (long double)signal.contact_area[k] * dt[k];
      span += dt[k];
    }
    if (a.steady.found) a.a_act_ss = Real(area / span);
  }
  if (a.samples == 0) {
    a.notes.push_back("the force series is empty");
    return a;
  }
  const std::optional<Real> f_ss =
      a.steady.found ? std::optional<Real>(std::abs(a.steady.mean)) : std::nullopt;
  a.coefficients = ComputeCoefficients(std::abs(a.peak.value), std::abs(a.smoothed_peak.value),
                                       f_ss, std::isnan(a.a_act_pk) ? 0 : a.a_act_pk, a.a_act_ss,
                                       settings.reference);
  if (!a.steady.found && !a.steady.note.empty()) a.notes.push_back(a.steady.note);
  if (a.steady.found && std::abs(a.steady.mean) <= 1e-3 * std::abs(a.peak.value)) {
    a.notes.push_back("the steady state is (nearly) zero: the load ended before the run did; "
                      "give steady_state.window for the flow phase");
  }
  return a;
}

}  // namespace surge
