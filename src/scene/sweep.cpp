// Sweep files: YAML -> SweepSpec (strict, like the scene parser), the per-case record and the
// summary.json flattener of `surge sweep`. Format: docs/sweeps.md.
#include "scene/sweep.h"

#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <cctype>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <set>
#include <stdexcept>

#include "scene/scene_error.h"

namespace surge {
namespace {

namespace fs = std::filesystem;

// Most cases a sweep may expand to: a typo such as a 1000-item list should fail, not start
// a million runs.
constexpr size_t kMaxCases = 100000;

std::string Describe(const YAML::Node& n) {
  if (!n.IsDefined() || n.IsNull()) return "nothing";
  if (n.IsScalar()) return "\"" + n.Scalar() + "\"";
  if (n.IsSequence()) return "a list of " + std::to_string(n.size()) + " items";
  return "a map";
}

// Value as `--set key=value` takes it: flow YAML, quoted where needed, so it parses back to the
// same node.
std::string FlowText(const YAML::Node& n) {
  YAML::Emitter e;
  e.SetSeqFormat(YAML::Flow);
  e.SetMapFormat(YAML::Flow);
  e << n;
  return e.c_str();
}

// Value as a person reads it (CSV cell, folder name): the scalar as written, lists as flow YAML.
std::string DisplayText(const YAML::Node& n) { return n.IsScalar() ? n.Scalar() : FlowText(n); }

// A value in a folder name: letters, digits and . + - kept, runs of anything else become one
// '_'; at most 32 characters.
std::string FolderSafe(const std::string& s) {
  std::string out;
  for (char c : s) {
    const bool keep = std::isalnum(static_cast<unsigned char>(c)) || c == '.' || c == '+' || c == '-';
    if (keep) {
      out += c;
    } else if (!out.empty() && out.back() != '_') {
      out += '_';
    }
  }
  while (!out.empty() && out.back() == '_') out.pop_back();
  if (out.size() > 32) out.resize(32);
  return out.empty() ? "_" : out;
}

// "case_007" for index 7 and width 3 (zero padded so that folders sort in case order).
std::string CaseNumber(size_t index, size_t width) {
  const std::string digits = std::to_string(index);
  return "case_" + std::string(width > digits.size() ? width - digits.size() : 0, '0') + digits;
}

bool IsIdentifier(const std::string& s) {
  return !s.empty() && (std::isalpha(static_cast<unsigned char>(s[0])) || s[0] == '_') &&
         std::all_of(s.begin(), s.end(),
                     [](char c) { return std::isalnum(static_cast<unsigned char>(c)) || c == '_'; });
}

// The short name of a column in case folder names: a scene parameter's name, or the last
// component of a key path with the list indices after it ("obstacles.0.shape.box.max.2" ->
// "max2", "materials.sand.friction_angle_deg" -> "friction_angle_deg").
std::string ShortName(const std::string& column) {
  std::vector<std::string> parts;
  size_t start = 0;
  for (size_t dot; (dot = column.find('.', start)) != std::string::npos; start = dot + 1)
    parts.push_back(column.substr(start, dot - start));
  parts.push_back(column.substr(start));
  std::string tail;
  for (auto it = parts.rbegin(); it != parts.rend(); ++it) {
    tail = *it + tail;
    const bool index = !it->empty() && std::all_of(it->begin(), it->end(), [](char c) {
      return c >= '0' && c <= '9';
    });
    if (!index) break;
  }
  return tail;
}

struct Param {
  std::string column;  // the sweep key: a scene parameter name or a key path
  std::string target;  // the key path its value is set at
  YAML::Node values;   // the list of values
  std::vector<std::pair<std::string, YAML::Node>> linked;  // extra overrides with every value
};

class SweepParser {
 public:
  SweepParser(std::string source, std::string base_dir)
      : source_(std::move(source)), base_dir_(std::move(base_dir)) {}

  SweepSpec Parse(const YAML::Node& root) {
    if (!root.IsMap()) Fail(root, "", "expected a map with base, parameters or cases, got " + Describe(root));
    CheckKeys(root, "", {"base", "out", "mode", "parameters", "cases", "set", "threads_per_case", "jobs"});
    SweepSpec spec;
    spec.path = source_;
    const YAML::Node base = root["base"];
    if (!base) Fail(root, "base", "missing: the base scene file (relative to the sweep file)");
    const fs::path base_path = String(base, "base");
    spec.base = (base_path.is_absolute() ? base_path : fs::path(base_dir_) / base_path).lexically_normal().string();
    spec.out = root["out"] ? String(root["out"], "out")
                           : (fs::path("results") / fs::path(source_).stem()).string();
    if (const YAML::Node n = root["threads_per_case"]) spec.threads_per_case = PositiveInt(n, "threads_per_case");
    if (const YAML::Node n = root["jobs"]) spec.jobs = PositiveInt(n, "jobs");

    const YAML::Node params = root["parameters"], cases = root["cases"];
    if (const YAML::Node m = root["mode"]) {
      const std::string mode = String(m, "mode");
      if (mode == "product") {
        spec.mode = SweepMode::kProduct;
      } else if (mode == "list") {
        spec.mode = SweepMode::kList;
      } else {
        Fail(m, "mode", "expected product or list, got " + Describe(m));
      }
    } else {
      spec.mode = cases && !params ? SweepMode::kList : SweepMode::kProduct;
    }
    if (spec.mode == SweepMode::kProduct) {
      if (cases) Fail(cases, "cases", "only in mode: list (this sweep is a product of parameters)");
      if (!params) Fail(root, "parameters", "missing: a map of key.path or parameter name -> list of values");
    } else {
      if (params) Fail(params, "parameters", "only in mode: product (this sweep is a list of cases)");
      if (!cases) Fail(root, "cases", "missing: a list of {name, set} maps");
    }

    std::vector<SweepOverride> common;
    if (const YAML::Node set = root["set"]) common = OverrideMap(set, "set");

    if (spec.mode == SweepMode::kProduct) {
      ExpandProduct(params, common, spec);
    } else {
      ExpandList(cases, common, spec);
    }
    return spec;
  }

 private:
  [[noreturn]] void Fail(const YAML::Node& n, const std::string& key, const std::string& msg) const {
    const bool has_mark = n.IsDefined() && n.Mark().line >= 0;
    throw SceneError(source_, has_mark ? n.Mark().line + 1 : 0, has_mark ? n.Mark().column + 1 : 0,
                     key, msg);
  }

  void CheckKeys(const YAML::Node& map, const std::string& path,
                 const std::vector<std::string>& allowed) const {
    for (const auto& kv : map) {
      const std::string key = kv.first.IsScalar() ? kv.first.Scalar() : "?";
      if (std::find(allowed.begin(), allowed.end(), key) == allowed.end()) {
        std::string list;
        for (const std::string& a : allowed) list += (list.empty() ? "" : ", ") + a;
        Fail(kv.first, path.empty() ? key : path + "." + key,
             "unknown key '" + key + "' (expected one of: " + list + ")");
      }
    }
  }

  std::string String(const YAML::Node& n, const std::string& key) const {
    if (!n.IsScalar() || n.Scalar().empty()) Fail(n, key, "expected a text value, got " + Describe(n));
    return n.Scalar();
  }

  int PositiveInt(const YAML::Node& n, const std::string& key) const {
    int v = 0;
    if (!n.IsScalar() || !YAML::convert<int>::decode(n, v) || v < 1 || v > 4096) {
      Fail(n, key, "expected a whole number from 1 to 4096, got " + Describe(n));
    }
    return v;
  }

  // A map of key.path -> value.
  std::vector<SweepOverride> OverrideMap(const YAML::Node& map, const std::string& key) const {
    if (!map.IsMap()) Fail(map, key, "expected a map of key.path -> value, got " + Describe(map));
    std::vector<SweepOverride> out;
    for (const auto& kv : map) {
      const std::string path = kv.first.IsScalar() ? kv.first.Scalar() : "";
      if (path.empty()) Fail(kv.first, key, "expected a key.path");
      out.push_back(Override(path, kv.second));
    }
    return out;
  }

  SweepOverride Override(const std::string& path, const YAML::Node& value) const {
    const bool has_mark = value.Mark().line >= 0;
    return {path + "=" + FlowText(value), has_mark ? value.Mark().line + 1 : 0,
            has_mark ? value.Mark().column + 1 : 0};
  }

  void ExpandProduct(const YAML::Node& params, const std::vector<SweepOverride>& common,
                     SweepSpec& spec) const {
    if (!params.IsMap() || params.size() == 0) {
      Fail(params, "parameters", "expected a map of key.path or parameter name -> list of values, got " +
                                     Describe(params));
    }
    std::vector<Param> list;
    size_t count = 1;
    for (const auto& kv : params) {
      Param p;
      p.column = kv.first.IsScalar() ? kv.first.Scalar() : "";
      const std::string key = "parameters." + p.column;
      if (p.column.empty()) Fail(kv.first, "parameters", "expected a key.path or a parameter name");
      // A name without dots is a scene parameter (the scene's `parameters:` map, used by its
      // ${...} expressions); anything else is a key path as --set takes it.
      const bool scene_parameter = p.column.find('.') == std::string::npos;
      if (scene_parameter && !IsIdentifier(p.column)) {
        Fail(kv.first, key, "a scene parameter name must be letters, digits and '_' (or give a key.path)");
      }
      p.target = scene_parameter ? "parameters." + p.column : p.column;
      YAML::Node v = kv.second;
      if (v.IsMap()) {  // linked: {values: [...], set: {key.path: value or ${expression}}}
        CheckKeys(v, key, {"values", "set"});
        if (!v["values"]) Fail(v, key + ".values", "missing: the list of values");
        if (const YAML::Node set = v["set"]) {
          if (!set.IsMap()) Fail(set, key + ".set", "expected a map of key.path -> value, got " + Describe(set));
          for (const auto& s : set) {
            const std::string path = s.first.IsScalar() ? s.first.Scalar() : "";
            if (path.empty()) Fail(s.first, key + ".set", "expected a key.path");
            p.linked.emplace_back(path, s.second);
          }
        }
        v = v["values"];
      }
      if (!v.IsSequence() || v.size() == 0) {
        Fail(v, key, "expected a non-empty list of values, got " + Describe(v));
      }
      for (size_t i = 0; i < v.size(); ++i) {
        if (v[i].IsMap() || v[i].IsNull()) {
          Fail(v[i], key, "values must be numbers, text or lists (for several linked overrides use "
                          "{values: [...], set: {...}}), got " + Describe(v[i]));
        }
      }
      for (const Param& q : list) {
        if (q.target == p.target) Fail(kv.first, key, "sets " + p.target + " as '" + q.column + "' does");
      }
      p.values = v;
      count *= v.size();
      if (count > kMaxCases) Fail(kv.first, key, "the sweep has more than " + std::to_string(kMaxCases) + " cases");
      list.push_back(std::move(p));
    }

    // Folder names use short column names unless two collide.
    std::vector<std::string> shorts;
    for (const Param& p : list) shorts.push_back(ShortName(p.column));
    for (size_t i = 0; i < list.size(); ++i) {
      if (std::count(shorts.begin(), shorts.end(), shorts[i]) > 1) shorts[i] = list[i].column;
    }
    for (const Param& p : list) spec.columns.push_back(p.column);

    // Cartesian product, the first parameter varying slowest (nested loops in file order).
    const size_t width = std::max<size_t>(3, std::to_string(count - 1).size());
    std::vector<size_t> at(list.size(), 0);
    for (size_t c = 0; c < count; ++c) {
      size_t rest = c;
      for (size_t k = list.size(); k-- > 0;) {
        at[k] = rest % list[k].values.size();
        rest /= list[k].values.size();
      }
      SweepCase sc;
      sc.index = static_cast<int>(c);
      sc.name = CaseNumber(c, width);
      sc.overrides = common;
      for (size_t k = 0; k < list.size(); ++k) {
        const YAML::Node value = list[k].values[at[k]];
        sc.values.push_back(DisplayText(value));
        // append(): GCC 12 warns falsely (-Wrestrict, PR 105329) on chained operator+.
        sc.name.append("_").append(FolderSafe(shorts[k])).append("=").append(FolderSafe(DisplayText(value)));
        sc.overrides.push_back(Override(list[k].target, value));
        for (const auto& [path, linked] : list[k].linked) sc.overrides.push_back(Override(path, linked));
      }
      spec.cases.push_back(std::move(sc));
    }
  }

  void ExpandList(const YAML::Node& cases, const std::vector<SweepOverride>& common,
                  SweepSpec& spec) const {
    if (!cases.IsSequence() || cases.size() == 0) {
      Fail(cases, "cases", "expected a non-empty list of {name, set} maps, got " + Describe(cases));
    }
    if (cases.size() > kMaxCases) Fail(cases, "cases", "more than " + std::to_string(kMaxCases) + " cases");
    // Columns: every key path that some case sets, in order of first appearance.
    std::vector<std::vector<std::pair<std::string, YAML::Node>>> sets;
    std::set<std::string> names;
    const size_t width = std::max<size_t>(3, std::to_string(cases.size() - 1).size());
    for (size_t i = 0; i < cases.size(); ++i) {
      const YAML::Node c = cases[i];
      const std::string key = "cases[" + std::to_string(i) + "]";
      if (!c.IsMap()) Fail(c, key, "expected a map {name, set}, got " + Describe(c));
      CheckKeys(c, key, {"name", "set"});
      SweepCase sc;
      sc.index = static_cast<int>(i);
      sc.name = CaseNumber(i, width);
      if (const YAML::Node n = c["name"]) {
        const std::string name = String(n, key + ".name");
        if (!names.insert(name).second) Fail(n, key + ".name", "duplicate case name '" + name + "'");
        sc.name += "_" + FolderSafe(name);
      }
      sc.overrides = common;
      std::vector<std::pair<std::string, YAML::Node>> set;
      if (const YAML::Node s = c["set"]) {
        if (!s.IsMap()) Fail(s, key + ".set", "expected a map of key.path -> value, got " + Describe(s));
        for (const auto& kv : s) {
          const std::string path = kv.first.IsScalar() ? kv.first.Scalar() : "";
          if (path.empty()) Fail(kv.first, key + ".set", "expected a key.path");
          set.emplace_back(path, kv.second);
          sc.overrides.push_back(Override(path, kv.second));
          if (std::find(spec.columns.begin(), spec.columns.end(), path) == spec.columns.end()) {
            spec.columns.push_back(path);
          }
        }
      }
      sets.push_back(std::move(set));
      spec.cases.push_back(std::move(sc));
    }
    for (size_t i = 0; i < spec.cases.size(); ++i) {
      for (const std::string& column : spec.columns) {
        std::string text;
        for (const auto& [path, value] : sets[i]) {
          if (path == column) text = DisplayText(value);
        }
        spec.cases[i].values.push_back(text);
      }
    }
  }

  std::string source_, base_dir_;
};

void Flatten(const YAML::Node& n, const std::string& path,
             std::vector<std::pair<std::string, std::string>>& out) {
  if (!n.IsDefined() || n.IsNull()) {
    out.emplace_back(path, "");
  } else if (n.IsScalar()) {
    out.emplace_back(path, n.Scalar());
  } else if (n.IsSequence()) {
    const bool vector = (n.size() == 2 || n.size() == 3) &&
                        std::all_of(n.begin(), n.end(), [](const YAML::Node& c) { return c.IsScalar(); });
    static const char* const kAxes[] = {"x", "y", "z"};
    for (size_t i = 0; i < n.size(); ++i) {
      const std::string item = vector ? kAxes[i] : std::to_string(i);
      Flatten(n[i], path.empty() ? item : path + "." + item, out);
    }
  } else {
    for (const auto& kv : n) {
      const std::string key = kv.first.IsScalar() ? kv.first.Scalar() : "?";
      Flatten(kv.second, path.empty() ? key : path + "." + key, out);
    }
  }
}

}  // namespace

SweepSpec ParseSweepText(const std::string& text, const std::string& source,
                         const std::string& base_dir) {
  YAML::Node root;
  try {
    root = YAML::Load(text);
  } catch (const YAML::ParserException& e) {
    throw SceneError(source, e.mark.line + 1, e.mark.column + 1, "", "YAML syntax error: " + e.msg);
  }
  try {
    return SweepParser(source, base_dir).Parse(root);
  } catch (const YAML::Exception& e) {  // defensive: the parser checks types before converting
    throw SceneError(source, e.mark.line + 1, e.mark.column + 1, "", e.what());
  }
}

SweepSpec LoadSweepFile(const std::string& path) {
  std::ifstream in(path);
  std::error_code ec;
  if (!in || !fs::is_regular_file(path, ec)) throw SceneError(path, 0, 0, "", "cannot read the sweep file");
  const std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  const std::string dir = fs::path(path).parent_path().string();
  return ParseSweepText(text, path, dir.empty() ? "." : dir);
}

void WriteSweepCaseRecord(const std::string& path, const SweepCaseRecord& r) {
  YAML::Emitter e;
  e.SetDoublePrecision(9);
  e << YAML::BeginMap;
  e << YAML::Key << "case" << YAML::Value << r.name;
  e << YAML::Key << "index" << YAML::Value << r.index;
  e << YAML::Key << "scene" << YAML::Value << r.scene;
  e << YAML::Key << "overrides" << YAML::Value << YAML::BeginSeq;
  for (const std::string& o : r.overrides) e << YAML::DoubleQuoted << o;
  e << YAML::EndSeq;
  e << YAML::Key << "scene_digest" << YAML::Value << r.scene_digest;
  e << YAML::Key << "status" << YAML::Value << r.status;
  e << YAML::Key << "exit_code" << YAML::Value << r.exit_code;
  e << YAML::Key << "wall_seconds" << YAML::Value << r.wall_seconds;
  e << YAML::EndMap;
  // Write then rename, so that a reader never sees half a record.
  const std::string tmp = path + ".tmp";
  {
    std::ofstream out(tmp, std::ios::trunc);
    out << "# surge sweep: how this case last ran (docs/sweeps.md)\n" << e.c_str() << "\n";
    if (!out) throw std::runtime_error("cannot write " + tmp);
  }
  std::error_code ec;
  fs::rename(tmp, path, ec);
  if (ec) throw std::runtime_error("cannot write " + path + ": " + ec.message());
}

bool ReadSweepCaseRecord(const std::string& path, SweepCaseRecord& r) {
  std::error_code ec;
  if (!fs::is_regular_file(path, ec)) return false;
  try {
    const YAML::Node n = YAML::LoadFile(path);
    if (!n.IsMap() || !n["case"] || !n["overrides"]) return false;
    r.name = n["case"].as<std::string>();
    r.index = n["index"].as<int>(0);
    r.scene = n["scene"].as<std::string>("");
    r.overrides.clear();
    for (const auto& o : n["overrides"]) r.overrides.push_back(o.as<std::string>());
    r.scene_digest = n["scene_digest"] ? n["scene_digest"].as<std::string>("") : "";
    r.status = n["status"].as<std::string>("");
    r.exit_code = n["exit_code"].as<int>(-1);
    r.wall_seconds = n["wall_seconds"].as<double>(0);
    return true;
  } catch (const YAML::Exception&) {
    return false;
  }
}

std::vector<std::pair<std::string, std::string>> FlattenJsonFile(const std::string& path) {
  std::vector<std::pair<std::string, std::string>> out;
  std::error_code ec;
  if (!fs::is_regular_file(path, ec)) return out;
  YAML::Node root;
  try {
    root = YAML::LoadFile(path);  // JSON is YAML (1.2) for what a summary holds
  } catch (const YAML::ParserException& e) {
    throw SceneError(path, e.mark.line + 1, e.mark.column + 1, "", "cannot parse: " + e.msg);
  } catch (const YAML::Exception& e) {
    throw SceneError(path, 0, 0, "", std::string("cannot read: ") + e.what());
  }
  Flatten(root, "", out);
  return out;
}

}  // namespace surge
