// `surge forces` and summary.json (issue #6): reads the force series of a results file, takes the
// analysis settings from the scene stored in it (the resolved YAML, so --set overrides count)
// and the command line, and reports the analysis (src/forces) as JSON or as a table. The table
// is drawn from the JSON, so the two always agree. Layout: docs/results-format.md, "summary.json".
#include "app/forces_command.h"

#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>

#include <cmath>
#include <cstdio>
#include <stdexcept>

#include "app/run.h"
#include "forces/force_analysis.h"
#include "io/results_reader.h"
#include "scene/scene_error.h"
#include "scene/scene_spec.h"

namespace surge {
namespace {

using Json = nlohmann::ordered_json;

// summary.json layout version: bump when a key changes meaning or moves.
constexpr int kSummaryFormatVersion = 1;

Json Number(Real v) { return std::isfinite(v) ? Json(v) : Json(nullptr); }
Json Number(const std::optional<Real>& v) { return v ? Number(*v) : Json(nullptr); }
Json Vector(const Vec3& v) { return Json::array({Number(v.x()), Number(v.y()), Number(v.z())}); }

std::string Join(const std::vector<std::string>& items, const char* sep = ", ") {
  std::string s;
  for (const std::string& i : items) s += (s.empty() ? "" : sep) + i;
  return s;
}

ForceComponent ParseComponent(const std::string& name) {
  for (ForceComponent c : {ForceComponent::kX, ForceComponent::kY, ForceComponent::kZ,
                           ForceComponent::kNormal, ForceComponent::kMagnitude}) {
    if (name == ComponentName(c)) return c;
  }
  throw std::invalid_argument("unknown component '" + name +
                              "' (expected one of: x, y, z, normal, magnitude)");
}

// --smooth none | moving_average=S | exponential=TAU | low_pass=HZ
SmoothingSettings ParseSmoothing(const std::string& text, SmoothingSettings s) {
  if (text == "none") return SmoothingSettings{};
  const size_t eq = text.find('=');
  const std::string kind = text.substr(0, eq);
  Real value = 0;
  try {
    size_t used = 0;
    if (eq == std::string::npos) throw std::invalid_argument("no value");
    value = std::stod(text.substr(eq + 1), &used);
    if (used != text.size() - eq - 1 || !(value > 0)) throw std::invalid_argument("bad value");
  } catch (const std::exception&) {
    throw std::invalid_argument("--smooth '" + text +
                                "': expected none, moving_average=S, exponential=TAU or "
                                "low_pass=HZ with a positive number");
  }
  const int order = s.order;
  s = SmoothingSettings{};
  s.order = order;
  if (kind == "moving_average") {
    s.kind = SmoothingKind::kMovingAverage;
    s.window = value;
  } else if (kind == "exponential") {
    s.kind = SmoothingKind::kExponential;
    s.time_constant = value;
  } else if (kind == "low_pass") {
    s.kind = SmoothingKind::kLowPass;
    s.cutoff = value;
  } else {
    throw std::invalid_argument("--smooth '" + text + "': unknown filter '" + kind +
                                "' (expected none, moving_average, exponential, low_pass)");
  }
  return s;
}

Json SmoothingJson(const SmoothingSettings& s) {
  Json j;
  j["kind"] = SmoothingName(s.kind);
  if (s.kind == SmoothingKind::kMovingAverage) j["window"] = s.window;
  if (s.kind == SmoothingKind::kExponential) j["time_constant"] = s.time_constant;
  if (s.kind == SmoothingKind::kLowPass) {
    j["cutoff"] = s.cutoff;
    j["order"] = s.order;
  }
  return j;
}

Json PlateauJson(const Plateau& p, const SteadyStateSettings& s, bool full) {
  Json j;
  j["status"] = p.found ? (p.explicit_window ? "window" : "found") : "none";
  j["value"] = p.found ? Number(p.mean) : Json(nullptr);
  j["t0"] = Number(p.t0);
  j["t1"] = Number(p.t1);
  if (!full) return j;
  j["duration"] = Number(p.t1 - p.t0);
  j["mean"] = Number(p.mean);
  j["raw_mean"] = Number(p.raw_mean);
  j["relative_std"] = Number(p.relative_std);
  j["max_relative_deviation"] = Number(p.max_relative_deviation);
  j["average"] = s.average;
  j["min_window"] = s.min_window;
  j["tolerance"] = s.tolerance;
  j["note"] = p.note;
  return j;
}

// Overview entry of a structure or face: |F| peak, impulse, steady |F|.
Json OverviewJson(const ForceAnalysis& a, const SteadyStateSettings& s) {
  Json j;
  j["peak"] = {{"value", Number(a.magnitude_peak.value)}, {"time", Number(a.magnitude_peak.time)}};
  j["force_at_peak"] = Vector(a.force_at_peak);
  j["impulse"] = Vector(a.impulse);
  j["peak_contact_area"] = Number(a.peak_contact_area);
  j["steady_state"] = PlateauJson(a.steady, s, false);
  return j;
}

ForceSignal Signal(const StoredForceSeries& s, int face) {
  ForceSignal sig;
  sig.time = s.time;
  sig.dt = s.dt;
  sig.force = face < 0 ? s.force : s.faces[size_t(face)].force;
  sig.contact_area = face < 0 ? s.contact_area : s.faces[size_t(face)].contact_area;
  return sig;
}

// lenient (the end of `surge run`): impossible filter settings drop the detailed analysis with a
// note instead of failing, so that summary.json is still written.
Json Build(const ForcesCommandOptions& o, bool lenient) {
  const StoredResult r = ReadResultForces(o.result_path);
  std::vector<std::string> notes;

  // The scene's analysis section, from the resolved YAML (--set overrides included).
  SceneSpec spec;
  bool have_spec = false;
  const std::string& text = r.resolved_yaml.empty() ? r.scene_text : r.resolved_yaml;
  try {
    spec = ParseSceneSpec(text, o.result_path + ":/metadata/" +
                                    (r.resolved_yaml.empty() ? "scene" : "resolved"),
                          ".", {});
    have_spec = true;
  } catch (const SceneError& e) {
    notes.push_back(std::string("the stored scene could not be read, so its analysis section and "
                                "defaults are not used (") + e.what() + ")");
    spec.dimension = r.dimension;
  }
  AnalysisSettings written = spec.analysis.settings;
  if (!o.structure.empty() && o.structure != written.structure) {  // another structure
    written.structure = o.structure;
    written.face.clear();
    written.component.reset();
  }
  if (!have_spec && written.structure.empty()) {
    for (const StoredForceSeries& s : r.structures) {
      if (s.name != "domain") {
        written.structure = s.name;
        break;
      }
    }
  }
  if (!o.face.empty()) written.face = o.face;
  if (!o.component.empty()) written.component = ParseComponent(o.component);
  const ReferenceValues& c = o.reference;
  ReferenceValues& w = written.reference;
  for (auto [from, to] : {std::pair{&c.velocity, &w.velocity}, {&c.density, &w.density},
                          {&c.width, &w.width}, {&c.height, &w.height}, {&c.area, &w.area},
                          {&c.k0, &w.k0}, {&c.gravity, &w.gravity}}) {
    if (*from) {
      if (!(**from > 0)) throw std::invalid_argument("reference values must be > 0");
      *to = *from;
    }
  }
  if (o.order) {
    if (*o.order != 1 && *o.order != 2) throw std::invalid_argument("--order must be 1 or 2");
    written.smoothing.order = *o.order;
  }
  if (!o.smooth.empty()) written.smoothing = ParseSmoothing(o.smooth, written.smoothing);
  SteadyStateSettings& ss = written.steady_state;
  if (o.average) ss.average = *o.average;
  if (o.min_window) ss.min_window = *o.min_window;
  if (o.tolerance) ss.tolerance = *o.tolerance;
  if (!o.window.empty()) {
    if (o.window.size() != 2 || !(o.window[1] > o.window[0]))
      throw std::invalid_argument("--window needs two times T0 < T1 [s]");
    ss.window = std::array<Real, 2>{o.window[0], o.window[1]};
  }
  if (!(ss.average >= 0) || !(ss.min_window > 0) || !(ss.tolerance > 0 && ss.tolerance <= 1))
    throw std::invalid_argument("need --average >= 0, --min-window > 0, 0 < --tolerance <= 1");
  const ResolvedAnalysis resolved = ResolveAnalysis(spec, written);
  const AnalysisSettings& settings = resolved.settings;

  Json j;
  j["format"] = "surge-summary";
  j["format_version"] = kSummaryFormatVersion;
  j["scene"] = r.name;
  j["result"] = r.path;
  j["exit_status"] = r.exit_status;
  j["dimension"] = r.dimension;
  j["force_unit"] = r.dimension == 2 ? "N/m" : "N";
  const StoredForceSeries* first = r.structures.empty() ? nullptr : &r.structures.front();
  j["steps"] = first ? first->time.size() : 0;
  j["end_time"] = first && !first->time.empty() ? Number(first->time.back()) : Json(nullptr);

  // The analysed structure and face.
  std::vector<std::string> names;
  const StoredForceSeries* target = nullptr;
  for (const StoredForceSeries& s : r.structures) {
    names.push_back(s.name);
    if (s.name == settings.structure) target = &s;
  }
  int face = -1;
  if (r.structures.empty()) {
    notes.push_back("the run logged no structures (no walls, obstacles or sensors)");
  } else if (!target) {
    throw std::invalid_argument("no structure '" + settings.structure + "' in '" + r.path +
                                "' (structures: " + Join(names) + ")");
  }
  if (target && !settings.face.empty()) {
    std::vector<std::string> faces;
    for (size_t f = 0; f < target->faces.size(); ++f) {
      faces.push_back(target->faces[f].name);
      if (target->faces[f].name == settings.face) face = int(f);
    }
    if (face < 0) {
      throw std::invalid_argument(
          "structure '" + target->name + "' has no face '" + settings.face + "' (" +
          (faces.empty() ? std::string("it has no faces") : "faces: " + Join(faces)) + ")");
    }
  }
  ForceAnalysis a;
  ForceComponent a_component = ForceComponent::kMagnitude;
  if (target) {
    const std::optional<Vec3> normal = AxisFaceNormal(settings.face);
    ForceComponent component =
        settings.component ? *settings.component
                           : (normal ? ForceComponent::kNormal : ForceComponent::kMagnitude);
    if (component == ForceComponent::kNormal && !normal) {
      throw std::invalid_argument("component normal needs an axis face (x-, x+, y-, y+, z-, z+)" +
                                  (settings.face.empty() ? std::string()
                                                         : ", got '" + settings.face + "'"));
    }
    a_component = component;
    try {
      a = AnalyseForce(Signal(*target, face), component, normal.value_or(Vec3::UnitX()), settings);
    } catch (const std::invalid_argument& e) {
      if (!lenient) throw;
      notes.push_back(std::string("no analysis of '") + target->name + "': " + e.what());
      target = nullptr;
    }
  }
  if (target) {
    const ForceComponent component = a_component;
    Json m;
    m["structure"] = target->name;
    m["face"] = settings.face;
    m["component"] = ComponentName(component);
    m["samples"] = a.samples;
    m["duration"] = Number(a.duration);
    m["peak"] = {{"value", Number(a.peak.value)}, {"time", Number(a.peak.time)}};
    m["peak_smoothed"] = {{"value", Number(a.smoothed_peak.value)},
                          {"time", Number(a.smoothed_peak.time)}};
    m["smoothing"] = SmoothingJson(settings.smoothing);
    m["impulse"] = Number(a.component_impulse);
    m["magnitude"] = {{"peak", Number(a.magnitude_peak.value)},
                      {"time", Number(a.magnitude_peak.time)},
                      {"force_at_peak", Vector(a.force_at_peak)},
                      {"impulse", Vector(a.impulse)}};
    m["steady_state"] = PlateauJson(a.steady, settings.steady_state, true);
    m["contact"] = {{"a_act_peak", Number(a.a_act_pk)},
                    {"a_act_steady", Number(a.a_act_ss)},
                    {"peak_contact_area", Number(a.peak_contact_area)}};
    const ReferenceValues& ref = settings.reference;
    m["reference"] = {{"velocity", Number(ref.velocity)}, {"density", Number(ref.density)},
                      {"width", Number(ref.width)},       {"height", Number(ref.height)},
                      {"area", Number(a.coefficients.area)}, {"k0", Number(ref.k0)},
                      {"gravity", Number(ref.gravity)},   {"defaults", resolved.reference_source}};
    const Coefficients& k = a.coefficients;
    m["coefficients"] = {{"c_pk", Number(k.c_pk)},
                         {"c_pk_smoothed", Number(k.c_pk_smoothed)},
                         {"c_ss", Number(k.c_ss)},
                         {"c_pk_actual", Number(k.c_pk_actual)},
                         {"c_ss_actual", Number(k.c_ss_actual)},
                         {"h_act_pk", Number(k.h_act_pk)},
                         {"h_act_ss", Number(k.h_act_ss)},
                         {"a_ratio_pk", Number(k.a_ratio_pk)},
                         {"a_ratio_ss", Number(k.a_ratio_ss)},
                         {"f_st_pk", Number(k.f_st_pk)},
                         {"f_st_ss", Number(k.f_st_ss)},
                         {"r_pk", Number(k.r_pk)},
                         {"r_pk_smoothed", Number(k.r_pk_smoothed)},
                         {"r_ss", Number(k.r_ss)},
                         {"f_st_hb", Number(k.f_st_hb)},
                         {"r_pk_hb", Number(k.r_pk_hb)},
                         {"r_ss_hb", Number(k.r_ss_hb)},
                         {"peak_to_steady", Number(k.peak_to_steady)}};
    std::vector<std::string> all = notes;
    for (const std::string& n : a.notes) all.push_back(n);
    for (const std::string& n : k.notes) all.push_back(n);
    m["notes"] = Join(all, "; ");
    j["analysis"] = m;
  } else {
    j["notes"] = Join(notes, "; ");
  }

  // Overview: |F| of every structure and face, with the same steady-state settings (the
  // smoothing plays no part in it).
  AnalysisSettings overview = settings;
  overview.smoothing = SmoothingSettings{};
  Json all = Json::object();
  for (const StoredForceSeries& s : r.structures) {
    const ForceAnalysis sa = AnalyseForce(Signal(s, -1), ForceComponent::kMagnitude,
                                          Vec3::UnitX(), overview);
    Json e = OverviewJson(sa, settings.steady_state);
    Real wetted = 0;
    for (Real h : s.wetted_height) wetted = std::max(wetted, h);
    e["peak_wetted_height"] = wetted;
    Json faces = Json::object();
    for (size_t f = 0; f < s.faces.size(); ++f) {
      const ForceAnalysis fa = AnalyseForce(Signal(s, int(f)), ForceComponent::kMagnitude,
                                            Vec3::UnitX(), overview);
      faces[s.faces[f].name] = OverviewJson(fa, settings.steady_state);
    }
    e["faces"] = faces;
    all[s.name] = e;
  }
  j["structures"] = all;
  return j;
}

// "%.5g" of a JSON number, "-" for null.
std::string G(const Json& v, const char* format = "%.5g") {
  if (!v.is_number()) return "-";
  char buf[64];
  std::snprintf(buf, sizeof buf, format, v.get<double>());
  return buf;
}

std::string Percent(const Json& v) { return v.is_number() ? G(100 * v.get<double>(), "%.2g") : "-"; }

std::vector<std::string> AnalysisLines(const Json& j) {
  std::vector<std::string> out;
  if (!j.contains("analysis")) return out;
  const Json& m = j["analysis"];
  const std::string unit = j["force_unit"];
  char buf[512];
  const std::string what = m["structure"].get<std::string>() +
                           (m["face"].get<std::string>().empty() ? "" : " face " + m["face"].get<std::string>()) +
                           ", component " + m["component"].get<std::string>();
  out.push_back("force analysis: " + what);
  const Json& sm = m["smoothing"];
  std::string filter = sm["kind"];
  if (sm.contains("window")) filter += " " + G(sm["window"]) + " s";
  if (sm.contains("time_constant")) filter += " " + G(sm["time_constant"]) + " s";
  if (sm.contains("cutoff")) filter += " " + G(sm["cutoff"]) + " Hz, order " + G(sm["order"]);
  std::snprintf(buf, sizeof buf, "  peak          %s %s at t = %s s (smoothed, %s: %s %s at t = %s s)",
                G(m["peak"]["value"]).c_str(), unit.c_str(), G(m["peak"]["time"]).c_str(),
                filter.c_str(), G(m["peak_smoothed"]["value"]).c_str(), unit.c_str(),
                G(m["peak_smoothed"]["time"]).c_str());
  out.push_back(buf);
  const Json& s = m["steady_state"];
  if (s["status"] != "none") {
    std::snprintf(buf, sizeof buf,
                  "  steady state  %s %s over [%s, %s] s (%s; rel. std %s %%, max dev %s %%)",
                  G(s["value"]).c_str(), unit.c_str(), G(s["t0"]).c_str(), G(s["t1"]).c_str(),
                  s["status"] == "window" ? "given window" : "plateau found",
                  Percent(s["relative_std"]).c_str(), Percent(s["max_relative_deviation"]).c_str());
  } else {
    std::snprintf(buf, sizeof buf, "  steady state  none: %s", s["note"].get<std::string>().c_str());
  }
  out.push_back(buf);
  std::snprintf(buf, sizeof buf, "  impulse       %s %s s", G(m["impulse"]).c_str(), unit.c_str());
  out.push_back(buf);
  const Json& k = m["coefficients"];
  std::snprintf(buf, sizeof buf,
                "  coefficients  C_pk %s  C_ss %s  R_pk %s  R_ss %s  H_act %s / %s m  f_st %s / %s %s",
                G(k["c_pk"], "%.4g").c_str(), G(k["c_ss"], "%.4g").c_str(),
                G(k["r_pk"], "%.4g").c_str(), G(k["r_ss"], "%.4g").c_str(),
                G(k["h_act_pk"], "%.4g").c_str(), G(k["h_act_ss"], "%.4g").c_str(),
                G(k["f_st_pk"]).c_str(), G(k["f_st_ss"]).c_str(), unit.c_str());
  out.push_back(buf);
  return out;
}

void PrintTable(const Json& j) {
  const std::string unit = j["force_unit"];
  std::printf("result      %s (%s), %d-D, %s steps to t = %s s\n", j["result"].get<std::string>().c_str(),
              j["exit_status"].get<std::string>().empty() ? "not closed"
                                                          : j["exit_status"].get<std::string>().c_str(),
              j["dimension"].get<int>(), G(j["steps"], "%.0f").c_str(), G(j["end_time"]).c_str());
  std::printf("\n%-22s %13s %10s %34s %13s %s\n", "structure / face", ("peak |F| [" + unit + "]").c_str(),
              "at t [s]", ("impulse [" + unit + " s]").c_str(), ("steady |F| [" + unit + "]").c_str(), "window [s]");
  const auto row = [&](const std::string& label, const Json& e) {
    const Json& ss = e["steady_state"];
    const std::string window =
        ss["status"] == "none" ? "none" : "[" + G(ss["t0"], "%.4g") + ", " + G(ss["t1"], "%.4g") + "]";
    const Json& i = e["impulse"];
    std::printf("%-22s %13s %10s %34s %13s %s\n", label.c_str(), G(e["peak"]["value"]).c_str(),
                G(e["peak"]["time"], "%.4g").c_str(),
                ("(" + G(i[0], "%.4g") + ", " + G(i[1], "%.4g") + ", " + G(i[2], "%.4g") + ")").c_str(),
                G(ss["value"]).c_str(), window.c_str());
  };
  for (const auto& [name, e] : j["structures"].items()) {
    row(name, e);
    for (const auto& [face, f] : e["faces"].items()) row("  " + face, f);
  }
  if (!j.contains("analysis")) {
    std::printf("\n%s\n", j.value("notes", std::string()).c_str());
    return;
  }
  std::printf("\n");
  for (const std::string& line : AnalysisLines(j)) std::printf("%s\n", line.c_str());
  const Json& m = j["analysis"];
  const Json& ref = m["reference"];
  std::printf("  reference     v0 %s m/s, rho0 %s kg/m^3, w_c %s m, H_b %s m, A %s %s, K0 %s, |g| %s m/s^2\n",
              G(ref["velocity"]).c_str(), G(ref["density"]).c_str(), G(ref["width"]).c_str(),
              G(ref["height"]).c_str(), G(ref["area"]).c_str(),
              j["dimension"].get<int>() == 2 ? "m^2/m" : "m^2", G(ref["k0"]).c_str(),
              G(ref["gravity"]).c_str());
  if (!ref["defaults"].get<std::string>().empty())
    std::printf("                (defaults: %s)\n", ref["defaults"].get<std::string>().c_str());
  const Json& k = m["coefficients"];
  const std::string area_unit = j["dimension"].get<int>() == 2 ? "m^2/m" : "m^2";
  std::printf("  contact       A_act %s %s at the peak, %s %s steady; A_ratio %s / %s\n",
              G(m["contact"]["a_act_peak"]).c_str(), area_unit.c_str(),
              G(m["contact"]["a_act_steady"]).c_str(), area_unit.c_str(),
              G(k["a_ratio_pk"], "%.4g").c_str(), G(k["a_ratio_ss"], "%.4g").c_str());
  std::printf("  also          C_pk smoothed %s, C_pk/C_ss on A_act %s / %s, R_pk smoothed %s, f_pk/f_ss %s\n",
              G(k["c_pk_smoothed"], "%.4g").c_str(), G(k["c_pk_actual"], "%.4g").c_str(),
              G(k["c_ss_actual"], "%.4g").c_str(), G(k["r_pk_smoothed"], "%.4g").c_str(),
              G(k["peak_to_steady"], "%.4g").c_str());
  std::printf("  with H_b      f_st %s %s, R_pk %s, R_ss %s\n", G(k["f_st_hb"]).c_str(), unit.c_str(),
              G(k["r_pk_hb"], "%.4g").c_str(), G(k["r_ss_hb"], "%.4g").c_str());
  if (!m["notes"].get<std::string>().empty())
    std::printf("  notes         %s\n", m["notes"].get<std::string>().c_str());
}

}  // namespace

CLI::App* AddForcesSubcommand(CLI::App& app, ForcesCommandOptions& o) {
  CLI::App* c = app.add_subcommand(
      "forces", "Force analysis of a result: peak, steady state, impulse, coefficients");
  c->add_option("result", o.result_path, "Results file <out>/<name>.h5")->required();
  c->add_option("--obstacle,--structure", o.structure,
                "Structure to analyse (an obstacle, sensor or 'domain'; default: the scene's analysis.structure)");
  c->add_option("--face", o.face, "One of its faces (default: the scene's analysis.face, else the whole structure)");
  c->add_option("--component", o.component, "x, y, z, normal (axis faces) or magnitude")
      ->check(CLI::IsMember({"x", "y", "z", "normal", "magnitude"}));
  c->add_flag("--json", o.json, "Print the JSON document (as summary.json)");
  const auto real = [&](const char* name, std::optional<Real>& target, const char* help) {
    c->add_option_function<double>(name, [&target](const double& v) { target = v; }, help);
  };
  real("--velocity", o.reference.velocity, "Reference velocity v0 [m/s]");
  real("--density", o.reference.density, "Reference density rho0 [kg/m^3]");
  real("--width", o.reference.width, "Column width w_c [m]");
  real("--height", o.reference.height, "Flow depth H_b [m]");
  real("--area", o.reference.area, "Reference area A [m^2] (default w_c H_b)");
  real("--k0", o.reference.k0, "At-rest earth pressure coefficient K0 [-]");
  real("--gravity", o.reference.gravity, "|g| [m/s^2]");
  c->add_option("--smooth", o.smooth,
                "Filter for the smoothed peak: none, moving_average=S, exponential=TAU, low_pass=HZ");
  c->add_option_function<int>("--order", [&o](const int& v) { o.order = v; },
                              "Butterworth order of low_pass (1 or 2)");
  real("--average", o.average, "Width of the impulse-preserving average for the steady state [s]");
  real("--min-window", o.min_window, "Shortest plateau [s]");
  real("--tolerance", o.tolerance, "Plateau tolerance, max relative deviation [-]");
  c->add_option("--window", o.window, "Steady-state window T0 T1 [s] instead of detection")
      ->expected(2);
  return c;
}

std::string ForcesSummaryJson(const ForcesCommandOptions& options, std::vector<std::string>* lines) {
  const Json j = Build(options, /*lenient=*/true);
  if (lines) *lines = AnalysisLines(j);
  return j.dump(2) + "\n";
}

int ForcesCommand(const ForcesCommandOptions& options) {
  try {
    const Json j = Build(options, /*lenient=*/false);
    if (options.json) {
      std::printf("%s\n", j.dump(2).c_str());
    } else {
      PrintTable(j);
    }
    return kExitOk;
  } catch (const IoError& e) {
    std::fprintf(stderr, "error: %s\n", e.what());
    return kExitBadInput;
  } catch (const std::invalid_argument& e) {
    std::fprintf(stderr, "error: %s\n", e.what());
    return kExitBadInput;
  }
}

}  // namespace surge
