// Scene parser: YAML text -> validated SceneSpec (strict: unknown keys, wrong types and
// out-of-range values are SceneErrors naming file, line, key path, range and unit), and the
// writer SceneSpecToYaml that emits the same fields in the same order with defaults filled in.
// The file format is documented in docs/scene-reference.md; keep the two in step.
#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <array>
#include <charconv>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <limits>
#include <map>
#include <numbers>
#include <type_traits>
#include <variant>
#include <set>

#include "core/hash.h"
#include "scene/scene.h"
#include "scene/scene_error.h"
#include "scene/scene_expressions.h"
#include "scene/scene_spec.h"

namespace surge {
namespace {

constexpr Real kInf = std::numeric_limits<Real>::infinity();

// Shortest decimal text that reads back to the same double.
std::string Num(Real v) {
  char buf[64];
  const auto r = std::to_chars(buf, buf + sizeof(buf), v);
  return std::string(buf, r.ptr);
}

template <class E>
struct EnumName {
  const char* name;
  E value;
};

constexpr EnumName<ShapeFunction> kShapeNames[] = {
    {"linear", ShapeFunction::kLinear},
    {"gimp", ShapeFunction::kGimp},
    {"quadratic_bspline", ShapeFunction::kQuadraticBspline},
    {"cubic_bspline", ShapeFunction::kCubicBspline}};
constexpr EnumName<TransferScheme> kTransferNames[] = {{"flip", TransferScheme::kFlip},
                                                       {"pic_flip", TransferScheme::kPicFlip},
                                                       {"apic", TransferScheme::kApic}};
constexpr EnumName<UpdateScheme> kUpdateNames[] = {{"usl", UpdateScheme::kUsl},
                                                   {"musl", UpdateScheme::kMusl}};
constexpr EnumName<ExitPolicy> kExitNames[] = {{"remove", ExitPolicy::kRemove},
                                               {"stop", ExitPolicy::kStop}};
constexpr EnumName<GhostNodes> kGhostNames[] = {{"mirror", GhostNodes::kMirror},
                                                {"mirror_velocity", GhostNodes::kMirrorVelocity},
                                                {"fold_all", GhostNodes::kFoldAll},
                                                {"constrain", GhostNodes::kConstrain}};
constexpr EnumName<bool> kFaceConstraintNames[] = {{"interpolated", true}, {"nodes", false}};
constexpr EnumName<AntiLockingMethod> kAntiLockingNames[] = {{"none", AntiLockingMethod::kNone},
                                                             {"node", AntiLockingMethod::kNode},
                                                             {"cell", AntiLockingMethod::kCell},
                                                             {"hybrid", AntiLockingMethod::kHybrid},
                                                             {"smoothing", AntiLockingMethod::kSmoothing}};
constexpr EnumName<AntiLockingApproach> kAntiLockingApproachNames[] = {
    {"volumetric", AntiLockingApproach::kVolumetric},
    {"volumetric_deviatoric", AntiLockingApproach::kVolumetricDeviatoric},
    {"constant_volumetric", AntiLockingApproach::kConstantVolumetric}};
constexpr EnumName<AntiLockingStrain> kAntiLockingStrainNames[] = {
    {"total", AntiLockingStrain::kTotal}, {"increment", AntiLockingStrain::kIncrement}};
constexpr EnumName<ForceComponent> kComponentNames[] = {{"x", ForceComponent::kX},
                                                        {"y", ForceComponent::kY},
                                                        {"z", ForceComponent::kZ},
                                                        {"normal", ForceComponent::kNormal},
                                                        {"magnitude", ForceComponent::kMagnitude}};

// "x-", "x+", ..., "z+": the faces whose normal is a coordinate axis.
bool AxisFace(const std::string& face) {
  return face.size() == 2 && (face[0] == 'x' || face[0] == 'y' || face[0] == 'z') &&
         (face[1] == '-' || face[1] == '+');
}

constexpr EnumName<WallKind> kWallNames[] = {{"open", WallKind::kOpen},
                                             {"slip", WallKind::kSlip},
                                             {"no_slip", WallKind::kNoSlip},
                                             {"friction", WallKind::kFriction}};

template <class E, size_t N>
const char* NameOf(const EnumName<E> (&table)[N], E value) {
  for (const auto& e : table) {
    if (e.value == value) return e.name;
  }
  return "?";
}

std::string Join(const std::vector<std::string>& items) {
  std::string s;
  for (size_t i = 0; i < items.size(); ++i) s += (i ? ", " : "") + items[i];
  return s;
}

std::string Child(const std::string& path, const std::string& key) {
  return path.empty() ? key : path + "." + key;
}
std::string Index(const std::string& path, size_t i) {
  return path + "[" + std::to_string(i) + "]";
}

// True if `path` is `prefix` or lies below it ("a.b" is under "a", "a[0]" is under "a").
bool IsUnder(const std::string& path, const std::string& prefix) {
  if (path.compare(0, prefix.size(), prefix) != 0) return false;
  return path.size() == prefix.size() || path[prefix.size()] == '.' || path[prefix.size()] == '[';
}

std::string Describe(const YAML::Node& n) {
  if (!n.IsDefined() || n.IsNull()) return "nothing";
  if (n.IsScalar()) return "\"" + n.Scalar() + "\"";
  if (n.IsSequence()) return "a list of " + std::to_string(n.size()) + " items";
  return "a map";
}

// A --set override after it has been applied: its text and the display path it set.
struct AppliedOverride {
  std::string text;  // "--set bodies.0.velocity=[2,0,0]"
  std::string path;  // "bodies[0].velocity"
};

// Applies "key.path=value" to the node tree (before validation). Map keys may be created;
// list indices must exist.
AppliedOverride ApplyOverride(YAML::Node root, const std::string& text) {
  const std::string where = "--set " + text;
  const size_t eq = text.find('=');
  if (eq == std::string::npos || eq == 0) {
    throw SceneError(where, 0, 0, "", "expected key.path=value, e.g. time.end=0.5");
  }
  const std::string key = text.substr(0, eq);
  std::vector<std::string> parts;
  for (size_t start = 0;;) {
    const size_t dot = key.find('.', start);
    parts.push_back(key.substr(start, dot == std::string::npos ? dot : dot - start));
    if (parts.back().empty()) throw SceneError(where, 0, 0, key, "empty component in key path");
    if (dot == std::string::npos) break;
    start = dot + 1;
  }
  YAML::Node value;
  try {
    value = YAML::Load(text.substr(eq + 1));
  } catch (const YAML::Exception& e) {
    throw SceneError(where, 0, 0, key, "cannot parse the value as YAML: " + e.msg);
  }

  YAML::Node cur(root);
  std::string path;
  for (size_t i = 0; i < parts.size(); ++i) {
    const std::string& part = parts[i];
    const bool last = i + 1 == parts.size();
    if (cur.IsSequence()) {
      const bool digits = std::all_of(part.begin(), part.end(), [](char c) { return c >= '0' && c <= '9'; });
      if (!digits || part.size() > 9) {
        throw SceneError(where, 0, 0, path, "expected a list index, got '" + part + "'");
      }
      const size_t index = std::stoul(part);
      path = Index(path, index);
      if (index >= cur.size()) {
        throw SceneError(where, 0, 0, path,
                         "list index " + part + " out of range (the list has " +
                             std::to_string(cur.size()) + " items)");
      }
      if (last) {
        cur[index] = value;
      } else {
        YAML::Node next = cur[index];
        cur.reset(next);
      }
    } else if (cur.IsMap() || cur.IsNull()) {
      path = Child(path, part);
      if (last) {
        cur[part] = value;
      } else {
        const YAML::Node existing = cur[part];
        if (!existing.IsDefined() || existing.IsNull()) cur[part] = YAML::Node(YAML::NodeType::Map);
        YAML::Node next = cur[part];
        cur.reset(next);
      }
    } else {
      throw SceneError(where, 0, 0, path, "cannot set key '" + part + "' inside a single value");
    }
  }
  return {where, path};
}

// Where a node came from, for errors raised before the Parser exists: its file position, or the
// --set override that wrote it.
SourceLoc NodeLoc(const YAML::Node& n, const std::string& path, const std::string& source,
                  const std::vector<AppliedOverride>& overrides) {
  for (auto it = overrides.rbegin(); it != overrides.rend(); ++it) {
    if (IsUnder(path, it->path)) return {it->text, 0, 0};
  }
  if (n.IsDefined() && n.Mark().line >= 0) return {source, n.Mark().line + 1, n.Mark().column + 1};
  return {source, 0, 0};
}

// Scene arithmetic (docs/scene-reference.md, "Parameters and expressions"): reads `parameters:`
// (a map of name -> number or ${expr} over earlier names), then replaces every scalar of the
// form ${expr} elsewhere in the tree by its value. Runs after --set, before validation.
class ExpressionResolver {
 public:
  ExpressionResolver(std::string source, const std::vector<AppliedOverride>& overrides)
      : source_(std::move(source)), overrides_(overrides) {}

  SceneParameters Resolve(YAML::Node root) {
    if (!root.IsMap()) return {};
    const YAML::Node params = root["parameters"];
    if (params) ReadParameters(params);
    for (auto kv : root) {
      const std::string key = kv.first.IsScalar() ? kv.first.Scalar() : std::string("?");
      if (key != "parameters") Substitute(kv.second, key);
    }
    return parameters_;
  }

 private:
  [[noreturn]] void Fail(const YAML::Node& n, const std::string& path, const std::string& msg) const {
    const SourceLoc loc = NodeLoc(n, path, source_, overrides_);
    throw SceneError(loc.source, loc.line, loc.column, path, msg);
  }

  static bool IsExpression(const std::string& s) {
    return s.size() >= 3 && s.compare(0, 2, "${") == 0 && s.back() == '}';
  }

  Real Evaluate(const YAML::Node& n, const std::string& path) const {
    const std::string& text = n.Scalar();
    Real value = 0;
    std::string error;
    if (!EvaluateSceneExpression(text.substr(2, text.size() - 3), parameters_, value, error)) {
      std::string names;
      for (const auto& p : parameters_) names += (names.empty() ? "" : ", ") + p.first;
      Fail(n, path, "cannot evaluate '" + text + "': " + error +
                        (names.empty() ? " (no parameters defined)" : " (parameters: " + names + ")"));
    }
    return value;
  }

  void ReadParameters(const YAML::Node& params) {
    if (!params.IsMap()) {
      Fail(params, "parameters", "expected a map of name -> number, got " + Describe(params));
    }
    for (const auto& kv : params) {
      const std::string name = kv.first.IsScalar() ? kv.first.Scalar() : std::string("?");
      const std::string path = Child("parameters", name);
      const bool identifier =
          !name.empty() && (std::isalpha(static_cast<unsigned char>(name[0])) || name[0] == '_') &&
          std::all_of(name.begin(), name.end(),
                      [](char c) { return std::isalnum(static_cast<unsigned char>(c)) || c == '_'; });
      if (!identifier) {
        Fail(kv.first, path, "a parameter name must be letters, digits and '_', not starting with a digit");
      }
      for (const auto& p : parameters_) {
        if (p.first == name) Fail(kv.first, path, "duplicate parameter '" + name + "'");
      }
      const YAML::Node v = kv.second;
      Real value = 0;
      if (v.IsScalar() && IsExpression(v.Scalar())) {
        value = Evaluate(v, path);
      } else {
        if (!v.IsScalar() || !YAML::convert<Real>::decode(v, value) || !std::isfinite(value)) {
          Fail(v, path, "expected a number or ${expression}, got " + Describe(v));
        }
      }
      parameters_.emplace_back(name, value);
    }
  }

  void Substitute(YAML::Node n, const std::string& path) {
    if (n.IsScalar()) {
      if (IsExpression(n.Scalar())) n = Num(Evaluate(n, path));
    } else if (n.IsSequence()) {
      for (size_t i = 0; i < n.size(); ++i) Substitute(n[i], Index(path, i));
    } else if (n.IsMap()) {
      for (auto kv : n) {
        const std::string key = kv.first.IsScalar() ? kv.first.Scalar() : std::string("?");
        Substitute(kv.second, Child(path, key));
      }
    }
  }

  std::string source_;
  const std::vector<AppliedOverride>& overrides_;
  SceneParameters parameters_;
};

// Validating reader over a YAML node tree. Every accessor takes the node and its display path.
class Parser {
 public:
  Parser(std::string source, std::string base_dir, std::vector<AppliedOverride> overrides)
      : source_(std::move(source)), base_dir_(std::move(base_dir)), overrides_(std::move(overrides)) {}

  SceneSpec Parse(const YAML::Node& root);

 private:
  SourceLoc Loc(const YAML::Node& node, const std::string& path) const {
    for (auto it = overrides_.rbegin(); it != overrides_.rend(); ++it) {
      if (IsUnder(path, it->path)) return {it->text, 0, 0};
    }
    if (node.IsDefined() && node.Mark().line >= 0) {
      return {source_, node.Mark().line + 1, node.Mark().column + 1};
    }
    for (auto it = overrides_.rbegin(); it != overrides_.rend(); ++it) {
      if (IsUnder(it->path, path)) return {it->text, 0, 0};
    }
    return {source_, 0, 0};
  }

  [[noreturn]] void Fail(const YAML::Node& node, const std::string& path,
                         const std::string& message) const {
    const SourceLoc loc = Loc(node, path);
    throw SceneError(loc.source, loc.line, loc.column, path, message);
  }

  // Map with only `allowed` keys, each at most once.
  void ExpectMap(const YAML::Node& n, const std::string& path,
                 const std::vector<std::string>& allowed) const {
    if (!n.IsMap()) Fail(n, path, "expected a map with keys " + Join(allowed) + ", got " + Describe(n));
    std::set<std::string> seen;
    for (const auto& kv : n) {
      const std::string key = kv.first.IsScalar() ? kv.first.Scalar() : std::string("?");
      if (std::find(allowed.begin(), allowed.end(), key) == allowed.end()) {
        Fail(kv.first, Child(path, key),
             "unknown key '" + key + "' (expected one of: " + Join(allowed) + ")");
      }
      if (!seen.insert(key).second) Fail(kv.first, Child(path, key), "duplicate key '" + key + "'");
    }
  }

  YAML::Node Need(const YAML::Node& map, const std::string& path, const std::string& key) const {
    const YAML::Node n = map[key];
    if (!n.IsDefined()) Fail(map, Child(path, key), "missing required key '" + key + "'");
    return n;
  }

  Real Number(const YAML::Node& n, const std::string& path, const std::string& unit) const {
    Real v = 0;
    if (!n.IsScalar() || !YAML::convert<Real>::decode(n, v) || !std::isfinite(v)) {
      Fail(n, path, "expected a number [" + unit + "], got " + Describe(n));
    }
    return v;
  }

  // A number in the interval (lo, hi) with open/closed ends; infinite ends print as > or >=.
  Real Ranged(const YAML::Node& n, const std::string& path, const std::string& unit, Real lo,
              bool lo_closed, Real hi, bool hi_closed) const {
    const Real v = Number(n, path, unit);
    const bool ok = (lo_closed ? v >= lo : v > lo) && (hi_closed ? v <= hi : v < hi);
    if (!ok) {
      std::string range;
      if (hi == kInf) {
        range = std::string(lo_closed ? ">= " : "> ") + Num(lo);
      } else {
        range = std::string("in ") + (lo_closed ? "[" : "(") + Num(lo) + ", " + Num(hi) +
                (hi_closed ? "]" : ")");
      }
      Fail(n, path, "must be " + range + " [" + unit + "], got " + n.Scalar());
    }
    return v;
  }
  Real Positive(const YAML::Node& n, const std::string& path, const std::string& unit) const {
    return Ranged(n, path, unit, 0, false, kInf, false);
  }
  Real NonNegative(const YAML::Node& n, const std::string& path, const std::string& unit) const {
    return Ranged(n, path, unit, 0, true, kInf, false);
  }

  int64_t Integer(const YAML::Node& n, const std::string& path, int64_t lo, int64_t hi) const {
    long long v = 0;
    if (!n.IsScalar() || !YAML::convert<long long>::decode(n, v)) {
      Fail(n, path, "expected an integer, got " + Describe(n));
    }
    if (v < lo || v > hi) {
      Fail(n, path,
           "must be an integer in [" + std::to_string(lo) + ", " + std::to_string(hi) + "], got " +
               n.Scalar());
    }
    return v;
  }

  bool Bool(const YAML::Node& n, const std::string& path) const {
    bool v = false;
    if (!n.IsScalar() || !YAML::convert<bool>::decode(n, v)) {
      Fail(n, path, "expected true or false, got " + Describe(n));
    }
    return v;
  }

  std::string String(const YAML::Node& n, const std::string& path) const {
    if (!n.IsScalar() || n.Scalar().empty()) Fail(n, path, "expected a string, got " + Describe(n));
    return n.Scalar();
  }

  // FNV-1a of a mesh file's bytes (core/hash.h), so the resolved scene, and with it the restart
  // and sweep checks, changes when the mesh does. "" when the file cannot be read: the builder's
  // mesh reader names that error. A `file_hash` in the map (as a resolved scene carries it) pins
  // the content: a different file is refused.
  std::string MeshFileHash(const YAML::Node& map, const std::string& path,
                           const std::string& file) const {
    std::string hash;
    std::error_code ec;
    if (std::filesystem::is_regular_file(file, ec)) {
      std::ifstream in(file, std::ios::binary);
      uint64_t h = kFnv1aBasis;
      std::array<char, 1 << 16> buf;
      while (in.read(buf.data(), buf.size()) || in.gcount() > 0) {
        h = Fnv1a(std::string_view(buf.data(), size_t(in.gcount())), h);
      }
      if (!in.bad()) hash = HashHex(h);
    }
    if (const YAML::Node pinned = map["file_hash"]) {
      const std::string want = String(pinned, Child(path, "file_hash"));
      if (!hash.empty() && want != hash) {
        Fail(pinned, Child(path, "file_hash"),
             "mesh file '" + file + "' has content hash " + hash + ", not " + want +
                 " as pinned here: the file changed since this scene was resolved");
      }
    }
    return hash;
  }

  // [A-Za-z0-9_-]+ : used in file names and HDF5 group names.
  std::string Identifier(const YAML::Node& n, const std::string& path) const {
    const std::string s = String(n, path);
    for (char c : s) {
      if (!std::isalnum(static_cast<unsigned char>(c)) && c != '_' && c != '-') {
        Fail(n, path, "'" + s + "' may contain only letters, digits, '_' and '-'");
      }
    }
    return s;
  }

  template <class E, size_t N>
  E Enum(const YAML::Node& n, const std::string& path, const EnumName<E> (&table)[N],
         size_t count = N) const {
    std::vector<std::string> names;
    for (size_t i = 0; i < count; ++i) names.push_back(table[i].name);
    if (!n.IsScalar()) Fail(n, path, "expected one of: " + Join(names) + ", got " + Describe(n));
    for (size_t i = 0; i < count; ++i) {
      if (n.Scalar() == table[i].name) return table[i].value;
    }
    Fail(n, path, "unknown value '" + n.Scalar() + "' (expected one of: " + Join(names) + ")");
  }

  // A point (`position`) or vector: 3 numbers in 3-D; 2 numbers, or 3 with z = 0, in 2-D.
  Vec3 Vector(const YAML::Node& n, const std::string& path, const std::string& unit) const {
    const bool two = dim_ == 2;
    const std::string expected = two ? "a list of 2 numbers (or 3 with z = 0) [" + unit + "]"
                                     : "a list of 3 numbers [" + unit + "]";
    const size_t size = n.IsSequence() ? n.size() : 0;
    if (!n.IsSequence() || !(size == 3 || (two && size == 2))) {
      Fail(n, path, "expected " + expected + ", got " + Describe(n));
    }
    Vec3 v = Vec3::Zero();
    for (size_t i = 0; i < size; ++i) v[i] = Number(n[i], Index(path, i), unit);
    if (two && v.z() != 0) Fail(n, path, "in 2-D the z component must be 0, got " + Num(v.z()));
    return v;
  }

  // `name` of list item `node` (list key[i]) is not among the names already in `items`.
  template <class T>
  void ExpectNewName(const std::vector<T>& items, const std::string& name, const YAML::Node& node,
                     const std::string& list_key, size_t i, const std::string& what) const {
    for (size_t j = 0; j < items.size(); ++j) {
      if (items[j].name == name) {
        Fail(node["name"], Child(Index(list_key, i), "name"),
             "duplicate " + what + " name '" + name + "' (also " + list_key + "[" +
                 std::to_string(j) + "])");
      }
    }
  }

  Wall ParseWall(const YAML::Node& n, const std::string& path) const;
  MaterialSpec ParseMaterial(const YAML::Node& n, const std::string& path) const;
  AntiLockingSpec ParseAntiLocking(const YAML::Node& al, const std::string& ap) const;
  void ParseElasticPair(const YAML::Node& n, const std::string& path, MaterialSpec& m) const;
  RegionShape ParseRegion(const YAML::Node& n, const std::string& path) const;
  BodySpec ParseBody(const YAML::Node& n, const std::string& path, const SceneSpec& spec) const;
  ObstacleSpec ParseObstacle(const YAML::Node& n, const std::string& path) const;
  AnalysisSpec ParseAnalysis(const YAML::Node& n, const SceneSpec& spec) const;
  ObstacleShapeSpec ParseObstacleShape(const YAML::Node& n, const std::string& path) const;

  std::string source_;
  std::string base_dir_;
  std::vector<AppliedOverride> overrides_;
  int dim_ = 3;
};

Wall Parser::ParseWall(const YAML::Node& n, const std::string& path) const {
  Wall wall;
  if (n.IsScalar()) {
    if (n.Scalar() == "friction") {
      Fail(n, path, "a friction wall needs a coefficient: write {friction: 0.3}");
    }
    wall.kind = Enum(n, path, kWallNames, 3);  // open, slip, no_slip
    return wall;
  }
  ExpectMap(n, path, {"type", "friction", "separable"});
  if (n["type"]) {
    wall.kind = Enum(n["type"], Child(path, "type"), kWallNames);
  } else if (n["friction"]) {
    wall.kind = WallKind::kFriction;
  } else {
    Fail(n, Child(path, "type"), "missing required key 'type'");
  }
  if (wall.kind == WallKind::kFriction) {
    wall.friction = NonNegative(Need(n, path, "friction"), Child(path, "friction"), "-");
  } else if (n["friction"]) {
    Fail(n["friction"], Child(path, "friction"),
         "friction applies only to walls of type friction (this wall is " +
             std::string(NameOf(kWallNames, wall.kind)) + ")");
  }
  if (n["separable"]) {
    if (wall.kind != WallKind::kSlip && wall.kind != WallKind::kFriction) {
      Fail(n["separable"], Child(path, "separable"),
           "separable applies only to slip and friction walls");
    }
    wall.separable = Bool(n["separable"], Child(path, "separable"));
  }
  return wall;
}

// Keys a material of `kind` accepts: model, density, the elastic pair (either (K, G) or (E, nu))
// when the kind is elastic, and the kind's own keys.
std::vector<std::string> MaterialKeys(const MaterialKind& kind) {
  std::vector<std::string> keys = {"model", "density"};
  if (kind.elastic) {
    keys.insert(keys.end(), {"youngs_modulus", "poisson_ratio", "bulk_modulus", "shear_modulus"});
  }
  for (const ParamDesc& d : kind.params) keys.push_back(d.key);
  keys.push_back("antilocking");
  keys.push_back("bulk_viscosity");
  keys.push_back("particle_shifting");
  return keys;
}

// antilocking: {method: none | node | cell | hybrid | smoothing, approach: volumetric |
// volumetric_deviatoric | constant_volumetric, fit: linear | constant, strain: total | increment,
// stress: false | true} (docs/antilocking.md), of a material or a body.
AntiLockingSpec Parser::ParseAntiLocking(const YAML::Node& al, const std::string& ap) const {
  AntiLockingSpec a;
  ExpectMap(al, ap, {"method", "approach", "fit", "strain", "stress"});
  a.method = Enum(Need(al, ap, "method"), Child(ap, "method"), kAntiLockingNames);
  const bool hybrid = *a.method == AntiLockingMethod::kHybrid;
  // Hybrid is node-based volumetric plus cell-based deviatoric (seed (4.33)-(4.35)): a full
  // tensor approximation by definition.
  a.approach =
      hybrid ? AntiLockingApproach::kVolumetricDeviatoric : AntiLockingApproach::kVolumetric;
  if (const YAML::Node an = al["approach"]) {
    a.approach = Enum(an, Child(ap, "approach"), kAntiLockingApproachNames);
    const bool full = a.approach != AntiLockingApproach::kVolumetric;
    if (hybrid && a.approach != AntiLockingApproach::kVolumetricDeviatoric) {
      Fail(an, Child(ap, "approach"),
           "method hybrid takes the trace from node-based and the deviator from cell-based "
           "control volumes (seed (4.33)-(4.35)): approach volumetric_deviatoric (or leave it out)");
    }
    if (full && *a.method == AntiLockingMethod::kSmoothing) {
      Fail(an, Child(ap, "approach"),
           "strain smoothing (Anura3D manual §6.7) smooths the volumetric strain only: approach "
           "volumetric (or leave it out)");
    }
    if (full && *a.method == AntiLockingMethod::kNone) {
      Fail(an, Child(ap, "approach"), "approach " + an.Scalar() +
                                         " needs a control volume: method node, cell or hybrid");
    }
  }
  if (const YAML::Node fit = al["fit"]) {
    // The seed's TriLinearAntiLocking (linear) or ConstantAntiLocking (constant) of a full-tensor
    // approach; AS1 is the constant one (spec §3.3).
    static constexpr EnumName<bool> kFitNames[] = {{"linear", false}, {"constant", true}};
    a.constant_fit = Enum(fit, Child(ap, "fit"), kFitNames);
    if (*a.method == AntiLockingMethod::kNone) {
      Fail(fit, Child(ap, "fit"), "fit needs a control volume: method node, cell or hybrid");
    }
    if (!a.constant_fit && a.approach == AntiLockingApproach::kVolumetric) {
      if (*a.method != AntiLockingMethod::kNode) {
        Fail(fit, Child(ap, "fit"),
             "the volumetric approach (AS1) projects a constant over each cell: fit constant (or "
             "leave it out); a linear fit of the trace alone needs method node, a cell's linear "
             "fit approach volumetric_deviatoric or constant_volumetric");
      }
      a.linear_trace = true;  // node-based AS1, each node's trace fitted linearly
    }
  }
  // Anura3D smooths the strain rate (manual (6.34)-(6.37)): the increment by default.
  if (*a.method == AntiLockingMethod::kSmoothing) a.strain = AntiLockingStrain::kIncrement;
  if (al["strain"]) {
    a.strain = Enum(al["strain"], Child(ap, "strain"), kAntiLockingStrainNames);
  }
  if (const YAML::Node st = al["stress"]) {
    a.stress = Bool(st, Child(ap, "stress"));
    if (a.stress && *a.method == AntiLockingMethod::kNone) {
      Fail(st, Child(ap, "stress"), "stress averaging needs a control volume: method node, cell or hybrid");
    }
    if (a.stress && *a.method == AntiLockingMethod::kSmoothing) {
      Fail(st, Child(ap, "stress"),
           "stress averaging is implemented for method node, cell or hybrid, not for smoothing");
    }
  }
  return a;
}

MaterialSpec Parser::ParseMaterial(const YAML::Node& n, const std::string& path) const {
  MaterialSpec m;
  m.loc = Loc(n, path);
  if (!n.IsMap()) Fail(n, path, "expected a map with keys model, density, ..., got " + Describe(n));
  const YAML::Node model = Need(n, path, "model");
  std::vector<std::string> names;
  for (const MaterialKind& k : MaterialKinds()) names.push_back(k.name);
  if (!model.IsScalar()) Fail(model, Child(path, "model"), "expected one of: " + Join(names));
  bool found = false;
  for (const MaterialKind& k : MaterialKinds()) {
    if (model.Scalar() == k.name) {
      m.model = k.model;
      found = true;
    }
  }
  if (!found) {
    Fail(model, Child(path, "model"),
         "unknown material model '" + model.Scalar() + "' (expected one of: " + Join(names) + ")");
  }
  const MaterialKind& kind = FindMaterialKind(m.model);
  ExpectMap(n, path, MaterialKeys(kind));
  m.density = Positive(Need(n, path, "density"), Child(path, "density"), "kg/m^3");
  if (kind.elastic) ParseElasticPair(n, path, m);
  for (const ParamDesc& d : kind.params) {
    const YAML::Node v = d.required ? Need(n, path, d.key) : n[d.key];
    if (!v) continue;
    const std::string vp = Child(path, d.key);
    if (d.choices.empty()) {
      m.values[d.key] = Ranged(v, vp, d.unit, d.min, !d.min_open, d.max, !d.max_open);
      continue;
    }
    std::vector<std::string> choices(d.choices.begin(), d.choices.end());
    const auto it = v.IsScalar() ? std::find(choices.begin(), choices.end(), v.Scalar())
                                 : choices.end();
    if (!v.IsScalar()) Fail(v, vp, "expected one of: " + Join(choices) + ", got " + Describe(v));
    if (it == choices.end()) {
      Fail(v, vp, "unknown value '" + v.Scalar() + "' (expected one of: " + Join(choices) + ")");
    }
    m.values[d.key] = static_cast<Real>(it - choices.begin());
  }
  if (const YAML::Node al = n["antilocking"]) {
    m.antilocking = ParseAntiLocking(al, Child(path, "antilocking"));
  }
  if (const YAML::Node ps = n["particle_shifting"]) {
    m.particle_shifting = Bool(ps, Child(path, "particle_shifting"));
  }
  if (const YAML::Node bv = n["bulk_viscosity"]) {
    // bulk_viscosity: {quadratic: c0, linear: c1} (docs/antilocking.md, "Artificial bulk
    // viscosity"); an empty map takes the LS-DYNA defaults 1.5 and 0.06.
    const std::string bp = Child(path, "bulk_viscosity");
    if (!bv.IsMap() && !(bv.IsNull())) {
      Fail(bv, bp, "expected a map {quadratic: c0, linear: c1}, got " + Describe(bv));
    }
    if (bv.IsMap()) ExpectMap(bv, bp, {"quadratic", "linear"});
    m.bulk_viscosity.enabled = true;
    if (bv.IsMap() && bv["quadratic"]) {
      m.bulk_viscosity.quadratic =
          Ranged(bv["quadratic"], Child(bp, "quadratic"), "-", 0, true, 10, true);
    }
    if (bv.IsMap() && bv["linear"]) {
      m.bulk_viscosity.linear = Ranged(bv["linear"], Child(bp, "linear"), "-", 0, true, 1, true);
    }
    if (m.bulk_viscosity.quadratic == 0 && m.bulk_viscosity.linear == 0) {
      Fail(bv, bp, "quadratic and linear are both 0: leave bulk_viscosity out to switch it off");
    }
  }
  if (kind.check) {
    if (const std::optional<ParamError> e = kind.check(m)) {
      const YAML::Node at = n[e->key];
      Fail(at ? at : n, at ? Child(path, e->key) : path, e->message);
    }
  }
  return m;
}

void Parser::ParseElasticPair(const YAML::Node& n, const std::string& path, MaterialSpec& m) const {
  const bool kg = n["bulk_modulus"] || n["shear_modulus"];
  const bool enu = n["youngs_modulus"] || n["poisson_ratio"];
  if (kg && enu) {
    Fail(n, path,
         "give either (bulk_modulus, shear_modulus) or (youngs_modulus, poisson_ratio), not both");
  }
  if (!kg && !enu) {
    Fail(n, path,
         "missing elastic constants: give (bulk_modulus, shear_modulus) or (youngs_modulus, "
         "poisson_ratio)");
  }
  if (kg) {
    m.bulk_modulus = Positive(Need(n, path, "bulk_modulus"), Child(path, "bulk_modulus"), "Pa");
    m.shear_modulus = Positive(Need(n, path, "shear_modulus"), Child(path, "shear_modulus"), "Pa");
  } else {
    m.given_as_youngs = true;
    m.youngs_modulus =
        Positive(Need(n, path, "youngs_modulus"), Child(path, "youngs_modulus"), "Pa");
    m.poisson_ratio = Ranged(Need(n, path, "poisson_ratio"), Child(path, "poisson_ratio"), "-",
                             -1, false, 0.5, false);
    // Isotropic elasticity: K = E / (3 (1 - 2 nu)), G = E / (2 (1 + nu))
    // (Bonet & Wood 2008, eqs. (6.36)-(6.37) in Lame form).
    m.bulk_modulus = m.youngs_modulus / (3.0 * (1.0 - 2.0 * m.poisson_ratio));
    m.shear_modulus = m.youngs_modulus / (2.0 * (1.0 + m.poisson_ratio));
  }
}

// Is the closed polyline simple (no two non-adjacent edges touch)? O(n^2), n is small.
bool IsSimplePolygon(const std::vector<std::array<Real, 2>>& p) {
  const size_t n = p.size();
  auto orient = [](const std::array<Real, 2>& a, const std::array<Real, 2>& b,
                   const std::array<Real, 2>& c) {
    const Real o = (b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0]);
    return (o > 0) - (o < 0);
  };
  auto on_segment = [](const std::array<Real, 2>& a, const std::array<Real, 2>& b,
                       const std::array<Real, 2>& c) {  // c collinear with ab: within its box?
    return std::min(a[0], b[0]) <= c[0] && c[0] <= std::max(a[0], b[0]) &&
           std::min(a[1], b[1]) <= c[1] && c[1] <= std::max(a[1], b[1]);
  };
  auto intersect = [&](const std::array<Real, 2>& a, const std::array<Real, 2>& b,
                       const std::array<Real, 2>& c, const std::array<Real, 2>& d) {
    const int o1 = orient(a, b, c), o2 = orient(a, b, d), o3 = orient(c, d, a), o4 = orient(c, d, b);
    if (o1 != o2 && o3 != o4) return true;
    return (o1 == 0 && on_segment(a, b, c)) || (o2 == 0 && on_segment(a, b, d)) ||
           (o3 == 0 && on_segment(c, d, a)) || (o4 == 0 && on_segment(c, d, b));
  };
  for (size_t i = 0; i < n; ++i) {
    for (size_t j = i + 1; j < n; ++j) {
      const bool adjacent = j == i + 1 || (i == 0 && j == n - 1);
      if (adjacent) {
        // Adjacent edges share one vertex; they must not fold back onto each other.
        const size_t a = i == 0 && j == n - 1 ? j : i;  // edge a ends where the next starts
        const auto& p0 = p[a];
        const auto& p1 = p[(a + 1) % n];
        const auto& p2 = p[(a + 2) % n];
        if (orient(p0, p1, p2) == 0 &&
            (p2[0] - p1[0]) * (p1[0] - p0[0]) + (p2[1] - p1[1]) * (p1[1] - p0[1]) <= 0) {
          return false;
        }
        continue;
      }
      if (intersect(p[i], p[(i + 1) % n], p[j], p[(j + 1) % n])) return false;
    }
  }
  return true;
}

RegionShape Parser::ParseRegion(const YAML::Node& n, const std::string& path) const {
  const std::vector<std::string> kinds = {"box", "sphere", "cylinder", "polygon", "mesh"};
  ExpectMap(n, path, kinds);
  if (n.size() != 1) {
    Fail(n, path,
         "expected exactly one of: " + Join(kinds) + ", got " + std::to_string(n.size()));
  }
  const std::string kind = n.begin()->first.Scalar();
  const YAML::Node s = n.begin()->second;
  const std::string p = Child(path, kind);
  if (kind == "box") {
    ExpectMap(s, p, {"min", "max"});
    BoxRegion box;
    box.min = Vector(Need(s, p, "min"), Child(p, "min"), "m");
    box.max = Vector(Need(s, p, "max"), Child(p, "max"), "m");
    for (int a = 0; a < dim_; ++a) {
      if (!(box.max[a] > box.min[a])) {
        Fail(s["max"], Child(p, "max"), "must exceed min in every component [m]");
      }
    }
    return box;
  }
  if (kind == "sphere") {
    ExpectMap(s, p, {"center", "radius"});
    SphereRegion sphere;
    sphere.center = Vector(Need(s, p, "center"), Child(p, "center"), "m");
    sphere.radius = Positive(Need(s, p, "radius"), Child(p, "radius"), "m");
    return sphere;
  }
  if (kind == "cylinder") {
    if (dim_ == 2) Fail(n.begin()->first, p, "cylinder regions are 3-D only (in 2-D use box, sphere or polygon)");
    ExpectMap(s, p, {"base", "top", "radius"});
    CylinderRegion cyl;
    cyl.base = Vector(Need(s, p, "base"), Child(p, "base"), "m");
    cyl.top = Vector(Need(s, p, "top"), Child(p, "top"), "m");
    cyl.radius = Positive(Need(s, p, "radius"), Child(p, "radius"), "m");
    if (cyl.top == cyl.base) Fail(s["top"], Child(p, "top"), "must differ from base");
    return cyl;
  }
  if (kind == "polygon") {
    ExpectMap(s, p, {"points", "z"});
    PolygonRegion poly;
    const YAML::Node pts = Need(s, p, "points");
    const std::string pp = Child(p, "points");
    if (!pts.IsSequence() || pts.size() < 3) {
      Fail(pts, pp, "expected a list of at least 3 [x, y] points [m], got " + Describe(pts));
    }
    for (size_t i = 0; i < pts.size(); ++i) {
      const YAML::Node q = pts[i];
      if (!q.IsSequence() || q.size() != 2) {
        Fail(q, Index(pp, i), "expected a list of 2 numbers [x, y] [m], got " + Describe(q));
      }
      poly.points.push_back({Number(q[0], Index(Index(pp, i), 0), "m"),
                             Number(q[1], Index(Index(pp, i), 1), "m")});
    }
    if (!IsSimplePolygon(poly.points)) {
      Fail(pts, pp, "the polygon must be simple (its edges may not cross or touch)");
    }
    if (dim_ == 2) {
      if (s["z"]) Fail(s["z"], Child(p, "z"), "z is not allowed in 2-D (particles lie in z = 0)");
    } else {
      const YAML::Node z = Need(s, p, "z");
      if (!z.IsSequence() || z.size() != 2) {
        Fail(z, Child(p, "z"), "expected a list of 2 numbers [z0, z1] [m], got " + Describe(z));
      }
      poly.z0 = Number(z[0], Index(Child(p, "z"), 0), "m");
      poly.z1 = Number(z[1], Index(Child(p, "z"), 1), "m");
      if (!(poly.z1 > poly.z0)) Fail(z, Child(p, "z"), "z1 must exceed z0 [m]");
    }
    return poly;
  }
  // mesh
  if (dim_ == 2) Fail(n.begin()->first, p, "mesh regions are 3-D only");
  ExpectMap(s, p, {"file", "file_hash", "scale", "translate"});
  MeshRegion mesh;
  const YAML::Node file = Need(s, p, "file");
  const std::filesystem::path f = String(file, Child(p, "file"));
  // Absolute, so that the resolved YAML (kept with the results) reads back from anywhere.
  mesh.file = std::filesystem::absolute(f.is_absolute() ? f : std::filesystem::path(base_dir_) / f)
                  .lexically_normal()
                  .string();
  mesh.file_loc = Loc(file, Child(p, "file"));
  mesh.file_hash = MeshFileHash(s, p, mesh.file);
  if (s["scale"]) mesh.scale = Positive(s["scale"], Child(p, "scale"), "-");
  if (s["translate"]) mesh.translate = Vector(s["translate"], Child(p, "translate"), "m");
  return mesh;
}

BodySpec Parser::ParseBody(const YAML::Node& n, const std::string& path,
                           const SceneSpec& spec) const {
  BodySpec b;
  b.loc = Loc(n, path);
  ExpectMap(n, path,
            {"name", "material", "region", "particles_per_cell", "jitter", "seed", "velocity",
             "initial_stress", "tractions", "antilocking"});
  b.name = Identifier(Need(n, path, "name"), Child(path, "name"));
  const YAML::Node mat = Need(n, path, "material");
  b.material = String(mat, Child(path, "material"));
  std::vector<std::string> defined;
  b.material_index = -1;
  for (size_t i = 0; i < spec.materials.size(); ++i) {
    defined.push_back(spec.materials[i].name);
    if (spec.materials[i].name == b.material) b.material_index = static_cast<int>(i);
  }
  if (b.material_index < 0) {
    Fail(mat, Child(path, "material"),
         "unknown material '" + b.material + "' (defined: " + Join(defined) + ")");
  }
  const YAML::Node region = Need(n, path, "region");
  b.region_loc = Loc(region, Child(path, "region"));
  b.region = ParseRegion(region, Child(path, "region"));
  if (n["particles_per_cell"]) {
    b.particles_per_cell = static_cast<int>(
        Integer(n["particles_per_cell"], Child(path, "particles_per_cell"), 1, 8));
  }
  if (n["jitter"]) b.jitter = Ranged(n["jitter"], Child(path, "jitter"), "-", 0, true, 1, false);
  if (n["seed"]) {
    b.seed = static_cast<uint64_t>(
        Integer(n["seed"], Child(path, "seed"), 0, std::numeric_limits<int64_t>::max()));
  }
  if (n["velocity"]) b.velocity = Vector(n["velocity"], Child(path, "velocity"), "m/s");
  if (const YAML::Node al = n["antilocking"]) {
    b.antilocking = ParseAntiLocking(al, Child(path, "antilocking"));
  }
  if (n["initial_stress"]) {
    const YAML::Node is = n["initial_stress"];
    const std::string ip = Child(path, "initial_stress");
    ExpectMap(is, ip, {"geostatic"});
    const YAML::Node geo = Need(is, ip, "geostatic");
    const std::string gp = Child(ip, "geostatic");
    ExpectMap(geo, gp, {"k0"});
    if (spec.gravity.norm() == 0) {
      Fail(geo, gp, "a geostatic initial stress needs a non-zero gravity");
    }
    const MaterialSpec& m = spec.materials[b.material_index];
    const MaterialKind& kind = FindMaterialKind(m.model);
    if (!kind.allows_geostatic) {
      Fail(geo, gp,
           "a geostatic initial stress is not available for material '" + m.name + "' (model " +
               kind.name + ": its stress follows from the deformation gradient)");
    }
    const YAML::Node k0 = Need(geo, gp, "k0");
    if (k0.IsScalar() && k0.Scalar() == "jaky") {
      if (!kind.friction_angle_deg) {
        Fail(k0, Child(gp, "k0"),
             "k0: jaky needs a material with a friction angle; model " + std::string(kind.name) +
                 " of material '" + m.name + "' has none (give k0 as a number)");
      }
      // Jaky (1944): K0 = 1 - sin(phi') for normally consolidated soil.
      b.geostatic_k0 = 1.0 - std::sin(kind.friction_angle_deg(m) * std::numbers::pi / 180.0);
      b.k0_from_friction = true;
    } else {
      b.geostatic_k0 = Positive(k0, Child(gp, "k0"), "- (or jaky)");
    }
  }
  if (n["tractions"]) {
    const YAML::Node ts = n["tractions"];
    const std::string tp = Child(path, "tractions");
    if (!ts.IsSequence()) Fail(ts, tp, "expected a list of {face, traction}, got " + Describe(ts));
    for (size_t i = 0; i < ts.size(); ++i) {
      const std::string ep = Index(tp, i);
      ExpectMap(ts[i], ep, {"face", "traction"});
      TractionSpec t;
      const YAML::Node face = Need(ts[i], ep, "face");
      std::vector<std::string> faces;
      for (int f = 0; f < 2 * dim_; ++f) faces.push_back(FaceName(static_cast<Face>(f)));
      const auto it = face.IsScalar() ? std::find(faces.begin(), faces.end(), face.Scalar())
                                      : faces.end();
      if (it == faces.end()) {
        Fail(face, Child(ep, "face"),
             "expected one of: " + Join(faces) + ", got " + Describe(face));
      }
      t.face = static_cast<Face>(it - faces.begin());
      t.traction = Vector(Need(ts[i], ep, "traction"), Child(ep, "traction"), "Pa");
      b.tractions.push_back(t);
    }
  }
  return b;
}

ObstacleShapeSpec Parser::ParseObstacleShape(const YAML::Node& n, const std::string& path) const {
  const std::vector<std::string> kinds = {"plane", "box", "sphere", "cylinder", "polygon", "mesh"};
  ExpectMap(n, path, kinds);
  if (n.size() != 1) {
    Fail(n, path, "expected exactly one of: " + Join(kinds) + ", got " + std::to_string(n.size()));
  }
  const std::string kind = n.begin()->first.Scalar();
  const YAML::Node s = n.begin()->second;
  const std::string p = Child(path, kind);
  if (kind == "plane") {
    ExpectMap(s, p, {"point", "normal"});
    PlaneShape plane;
    plane.point = Vector(Need(s, p, "point"), Child(p, "point"), "m");
    const Vec3 normal = Vector(Need(s, p, "normal"), Child(p, "normal"), "-");
    if (!(normal.norm() > 0)) Fail(s["normal"], Child(p, "normal"), "must not be the zero vector");
    // Kept as given; the builder normalises it. Normalising here would not round-trip: the
    // resolved YAML would hold the unit vector, and normalising that again can move it by an ulp.
    plane.normal = normal;
    return plane;
  }
  if (kind == "mesh") {
    if (dim_ == 2) Fail(n.begin()->first, p, "mesh obstacles are 3-D only (in 2-D use polygon)");
    ExpectMap(s, p, {"file", "file_hash", "scale", "rotate_deg", "translate", "one_sided", "faces"});
    ObstacleMeshSpec mesh;
    const YAML::Node file = Need(s, p, "file");
    const std::filesystem::path f = String(file, Child(p, "file"));
    mesh.file = std::filesystem::absolute(f.is_absolute() ? f : std::filesystem::path(base_dir_) / f)
                    .lexically_normal()
                    .string();
    mesh.file_loc = Loc(file, Child(p, "file"));
    mesh.file_hash = MeshFileHash(s, p, mesh.file);
    if (s["scale"]) mesh.scale = Positive(s["scale"], Child(p, "scale"), "-");
    if (s["rotate_deg"]) mesh.rotate_deg = Vector(s["rotate_deg"], Child(p, "rotate_deg"), "deg");
    if (s["translate"]) mesh.translate = Vector(s["translate"], Child(p, "translate"), "m");
    if (s["one_sided"]) mesh.one_sided = Bool(s["one_sided"], Child(p, "one_sided"));
    if (s["faces"]) {
      const YAML::Node f = s["faces"];
      if (!f.IsScalar() || (f.Scalar() != "parts" && f.Scalar() != "normal")) {
        Fail(f, Child(p, "faces"), "expected parts or normal, got " + Describe(f));
      }
      mesh.faces_by_normal = f.Scalar() == "normal";
    }
    return mesh;
  }
  // box, sphere, cylinder, polygon: the region shapes.
  if (kind == "cylinder" && dim_ == 2) {
    Fail(n.begin()->first, p,
         "cylinder obstacles are 3-D only (in 2-D a disk is a sphere: {sphere: {center, radius}})");
  }
  const RegionShape region = ParseRegion(n, path);
  return std::visit([](const auto& r) -> ObstacleShapeSpec {
    if constexpr (std::is_same_v<std::decay_t<decltype(r)>, MeshRegion>) {
      return ObstacleMeshSpec{};  // not reached: mesh is handled above
    } else {
      return r;
    }
  }, region);
}

ObstacleSpec Parser::ParseObstacle(const YAML::Node& n, const std::string& path) const {
  ObstacleSpec o;
  o.loc = Loc(n, path);
  ExpectMap(n, path, {"name", "shape", "motion", "contact", "reference_point"});
  o.name = Identifier(Need(n, path, "name"), Child(path, "name"));
  if (o.name == "domain") {
    Fail(n["name"], Child(path, "name"),
         "'domain' is reserved for the domain walls in the force log; choose another name");
  }
  const YAML::Node shape = Need(n, path, "shape");
  o.shape_loc = Loc(shape, Child(path, "shape"));
  o.shape = ParseObstacleShape(shape, Child(path, "shape"));
  if (n["motion"]) {
    const YAML::Node m = n["motion"];
    const std::string mp = Child(path, "motion");
    if (m.IsScalar()) {
      if (m.Scalar() == "prescribed") {
        Fail(m, mp, "a prescribed motion needs its velocities: write {prescribed: {velocity: [..]}}");
      }
      if (m.Scalar() != "fixed") {
        Fail(m, mp, "unknown motion '" + m.Scalar() +
                        "' (expected fixed, {prescribed: {...}} or {dynamic: {...}})");
      }
    } else {
      ExpectMap(m, mp, {"fixed", "prescribed", "dynamic"});
      if (m["fixed"]) Fail(m, mp, "write motion: fixed (a plain value)");
      if (m.size() != 1) Fail(m, mp, "expected exactly one of: prescribed, dynamic");
      if (m["dynamic"]) {
        const YAML::Node dn = m["dynamic"];
        const std::string dp = Child(mp, "dynamic");
        if (dim_ == 2) Fail(m.begin()->first, dp, "dynamic obstacles are 3-D only (Bullet bodies)");
        if (std::holds_alternative<PlaneShape>(o.shape)) {
          Fail(m.begin()->first, dp, "a plane is infinite and cannot be dynamic");
        }
        ExpectMap(dn, dp, {"mass", "density", "velocity", "angular_velocity_deg", "restitution"});
        o.motion = ObstacleMotionKind::kDynamic;
        if (dn["mass"].IsDefined() == dn["density"].IsDefined()) {
          Fail(dn, dp, "give exactly one of mass [kg] and density [kg/m^3]");
        }
        if (dn["mass"]) o.mass = Positive(dn["mass"], Child(dp, "mass"), "kg");
        if (dn["density"]) o.density = Positive(dn["density"], Child(dp, "density"), "kg/m^3");
        if (dn["velocity"]) o.velocity = Vector(dn["velocity"], Child(dp, "velocity"), "m/s");
        if (dn["angular_velocity_deg"]) {
          o.angular_velocity_deg =
              Vector(dn["angular_velocity_deg"], Child(dp, "angular_velocity_deg"), "deg/s");
        }
        if (dn["restitution"]) {
          o.restitution = Ranged(dn["restitution"], Child(dp, "restitution"), "-", 0, true, 1, true);
        }
      } else {
      const YAML::Node pr = Need(m, mp, "prescribed");
      const std::string pp = Child(mp, "prescribed");
      ExpectMap(pr, pp, {"velocity", "angular_velocity_deg", "center", "table"});
      o.motion = ObstacleMotionKind::kPrescribed;
      if (pr["table"]) {
        const YAML::Node tb = pr["table"];
        const std::string tp = Child(pp, "table");
        if (pr["velocity"] || pr["angular_velocity_deg"]) {
          Fail(tb, tp, "give either a table or velocity/angular_velocity_deg, not both");
        }
        const size_t cols = size_t(dim_) + 1;
        const std::string row = dim_ == 2 ? "[t, dx, dy]" : "[t, dx, dy, dz]";
        if (!tb.IsSequence() || tb.size() == 0) {
          Fail(tb, tp, "expected a list of " + row + " rows [s, m], got " + Describe(tb));
        }
        for (size_t i = 0; i < tb.size(); ++i) {
          const YAML::Node r = tb[i];
          if (!r.IsSequence() || r.size() != cols) {
            Fail(r, Index(tp, i), "expected a row " + row + " [s, m], got " + Describe(r));
          }
          std::array<Real, 4> v{};
          for (size_t c = 0; c < cols; ++c) v[c] = Number(r[c], Index(Index(tp, i), c), c ? "m" : "s");
          if (!o.table.empty() && !(v[0] > o.table.back()[0])) {
            Fail(r[0], Index(Index(tp, i), 0), "times must increase row by row");
          }
          o.table.push_back(v);
        }
      }
      if (pr["velocity"]) o.velocity = Vector(pr["velocity"], Child(pp, "velocity"), "m/s");
      if (pr["angular_velocity_deg"]) {
        const YAML::Node w = pr["angular_velocity_deg"];
        const std::string wp = Child(pp, "angular_velocity_deg");
        if (dim_ == 2) {  // rotation about z only: one number
          o.angular_velocity_deg = Vec3(0, 0, Number(w, wp, "deg/s (about z in 2-D)"));
        } else {
          o.angular_velocity_deg = Vector(w, wp, "deg/s");
        }
      }
      if (pr["center"]) o.center = Vector(pr["center"], Child(pp, "center"), "m");
      }
    }
  }
  if (n["contact"]) {
    const YAML::Node c = n["contact"];
    const std::string cp = Child(path, "contact");
    ExpectMap(c, cp, {"friction", "separable", "adhesion", "faces", "gap_test"});
    if (c["faces"]) {
      o.contact.interpolated_faces = Enum(c["faces"], Child(cp, "faces"), kFaceConstraintNames);
    }
    if (c["gap_test"]) o.contact.gap_test = Bool(c["gap_test"], Child(cp, "gap_test"));
    if (o.contact.interpolated_faces && !o.contact.gap_test) {
      Fail(c["gap_test"], Child(cp, "gap_test"),
           "faces: interpolated needs the gap test (without it a face column stops material up to "
           "two cells before the face); set faces: nodes to run without it");
    }
    if (c["friction"]) o.contact.friction = NonNegative(c["friction"], Child(cp, "friction"), "-");
    if (c["separable"]) o.contact.separable = Bool(c["separable"], Child(cp, "separable"));
    if (c["adhesion"]) {
      o.contact.adhesion = NonNegative(c["adhesion"], Child(cp, "adhesion"), "Pa");
      if (!o.contact.separable && o.contact.adhesion > 0) {
        Fail(c["adhesion"], Child(cp, "adhesion"),
             "adhesion applies only to separable contact (a sticky contact never releases)");
      }
    }
  }
  if (n["reference_point"]) {
    o.reference_point = Vector(n["reference_point"], Child(path, "reference_point"), "m");
  }
  return o;
}

// `analysis:` (docs/scene-reference.md). The structure must be in the force log (checked here);
// its face is checked by the builder, which knows every obstacle's face names.
AnalysisSpec Parser::ParseAnalysis(const YAML::Node& n, const SceneSpec& spec) const {
  AnalysisSpec a;
  a.present = true;
  a.loc = Loc(n, "analysis");
  AnalysisSettings& s = a.settings;
  ExpectMap(n, "analysis", {"structure", "face", "component", "reference", "smoothing", "steady_state"});
  if (n["structure"]) {
    s.structure = Identifier(n["structure"], "analysis.structure");
    a.structure_loc = Loc(n["structure"], "analysis.structure");
    std::vector<std::string> names = {"domain"};
    for (const ObstacleSpec& o : spec.obstacles) names.push_back(o.name);
    for (const SensorSpec& o : spec.sensors) names.push_back(o.name);
    for (const BodyContactSpec& c : spec.body_contacts) names.push_back(c.bodies[1] + "_on_" + c.bodies[0]);
    if (std::find(names.begin(), names.end(), s.structure) == names.end()) {
      Fail(n["structure"], "analysis.structure",
           "unknown structure '" + s.structure + "' (expected one of: " + Join(names) + ")");
    }
  }
  if (n["face"]) {
    s.face = String(n["face"], "analysis.face");
    a.face_loc = Loc(n["face"], "analysis.face");
  }
  if (n["component"]) {
    s.component = Enum(n["component"], "analysis.component", kComponentNames);
    if (*s.component == ForceComponent::kNormal && !AxisFace(s.face)) {
      Fail(n["component"], "analysis.component",
           "component normal needs an axis face (face: x-, x+, y-, y+, z- or z+)" +
               (s.face.empty() ? std::string() : ", got face '" + s.face + "'"));
    }
    if (*s.component == ForceComponent::kZ && dim_ == 2) {
      Fail(n["component"], "analysis.component", "2-D forces have no z component");
    }
  }
  if (n["reference"]) {
    const YAML::Node r = n["reference"];
    const std::string rp = "analysis.reference";
    ExpectMap(r, rp, {"velocity", "density", "width", "height", "area", "k0", "gravity"});
    ReferenceValues& v = s.reference;
    if (r["velocity"]) v.velocity = Positive(r["velocity"], Child(rp, "velocity"), "m/s");
    if (r["density"]) v.density = Positive(r["density"], Child(rp, "density"), "kg/m^3");
    if (r["width"]) {
      v.width = Positive(r["width"], Child(rp, "width"), "m");
      if (dim_ == 2 && *v.width != 1) {
        Fail(r["width"], Child(rp, "width"),
             "2-D forces are per metre of thickness: the width is 1 m (leave it out)");
      }
    }
    if (r["height"]) v.height = Positive(r["height"], Child(rp, "height"), "m");
    if (r["area"]) v.area = Positive(r["area"], Child(rp, "area"), dim_ == 2 ? "m^2/m" : "m^2");
    if (r["k0"]) v.k0 = Positive(r["k0"], Child(rp, "k0"), "-");
    if (r["gravity"]) v.gravity = Positive(r["gravity"], Child(rp, "gravity"), "m/s^2");
  }
  if (n["smoothing"]) {
    const YAML::Node m = n["smoothing"];
    const std::string mp = "analysis.smoothing";
    SmoothingSettings& f = s.smoothing;
    if (m.IsScalar() && m.Scalar() == "none") {
      f.kind = SmoothingKind::kNone;
    } else {
      const std::vector<std::string> kinds = {"moving_average", "exponential", "low_pass"};
      if (!m.IsMap()) {
        Fail(m, mp, "expected none or a map with one of: " + Join(kinds) + ", got " + Describe(m));
      }
      ExpectMap(m, mp, {"moving_average", "exponential", "low_pass", "order"});
      int given = 0;
      for (const std::string& k : kinds) given += bool(m[k]);
      if (given != 1) {
        Fail(m, mp, "expected exactly one of: " + Join(kinds) + " (got " + std::to_string(given) + ")");
      }
      if (m["moving_average"]) {
        f.kind = SmoothingKind::kMovingAverage;
        f.window = Positive(m["moving_average"], Child(mp, "moving_average"), "s");
      } else if (m["exponential"]) {
        f.kind = SmoothingKind::kExponential;
        f.time_constant = Positive(m["exponential"], Child(mp, "exponential"), "s");
      } else {
        f.kind = SmoothingKind::kLowPass;
        f.cutoff = Positive(m["low_pass"], Child(mp, "low_pass"), "Hz");
      }
      if (m["order"]) {
        if (f.kind != SmoothingKind::kLowPass) {
          Fail(m["order"], Child(mp, "order"), "order applies only to low_pass");
        }
        f.order = static_cast<int>(Integer(m["order"], Child(mp, "order"), 1, 2));
      }
    }
  }
  if (n["steady_state"]) {
    const YAML::Node m = n["steady_state"];
    const std::string mp = "analysis.steady_state";
    SteadyStateSettings& ss = s.steady_state;
    ExpectMap(m, mp, {"average", "min_window", "tolerance", "window"});
    if (m["average"]) ss.average = NonNegative(m["average"], Child(mp, "average"), "s");
    if (m["min_window"]) ss.min_window = Positive(m["min_window"], Child(mp, "min_window"), "s");
    if (m["tolerance"]) {
      ss.tolerance = Ranged(m["tolerance"], Child(mp, "tolerance"), "-", 0, false, 1, true);
    }
    if (m["window"]) {
      const YAML::Node w = m["window"];
      const std::string wp = Child(mp, "window");
      if (!w.IsSequence() || w.size() != 2) {
        Fail(w, wp, "expected a list of 2 times [t0, t1] [s], got " + Describe(w));
      }
      const Real t0 = NonNegative(w[0], Index(wp, 0), "s");
      const Real t1 = Number(w[1], Index(wp, 1), "s");
      if (!(t1 > t0)) Fail(w, wp, "t1 must exceed t0 [s]");
      ss.window = std::array<Real, 2>{t0, t1};
    }
  }
  return a;
}

SceneSpec Parser::Parse(const YAML::Node& root) {
  SceneSpec spec;
  const std::vector<std::string> top = {"name",   "dimension", "time",      "gravity", "gravity_ramp",
                                        "damping", "mass_scaling", "grid", "domain", "materials", "bodies",
                                        "obstacles", "sensors", "body_contact", "output", "analysis",
                                        "parameters"};
  if (!root.IsDefined() || root.IsNull()) {
    throw SceneError(source_, 0, 0, "", "the scene is empty (expected a map with keys " + Join(top) + ")");
  }
  ExpectMap(root, "", top);
  spec.name = Identifier(Need(root, "", "name"), "name");
  spec.dimension = dim_ = static_cast<int>(Integer(Need(root, "", "dimension"), "dimension", 2, 3));

  {
    const YAML::Node t = Need(root, "", "time");
    ExpectMap(t, "time", {"end", "cfl", "min_dt", "max_dt", "fixed_dt"});
    spec.time.end = Positive(Need(t, "time", "end"), "time.end", "s");
    if (t["cfl"]) spec.time.cfl = Ranged(t["cfl"], "time.cfl", "-", 0, false, 1, true);
    if (t["min_dt"]) spec.time.min_dt = NonNegative(t["min_dt"], "time.min_dt", "s");
    if (t["max_dt"]) spec.time.max_dt = Positive(t["max_dt"], "time.max_dt", "s");
    if (t["fixed_dt"]) spec.time.fixed_dt = NonNegative(t["fixed_dt"], "time.fixed_dt", "s");
    if (spec.time.max_dt < spec.time.min_dt) {
      Fail(t["max_dt"] ? t["max_dt"] : t, "time.max_dt",
           "must be >= time.min_dt (" + Num(spec.time.min_dt) + " s)");
    }
  }
  if (root["gravity"]) spec.gravity = Vector(root["gravity"], "gravity", "m/s^2");
  if (root["gravity_ramp"]) spec.gravity_ramp = NonNegative(root["gravity_ramp"], "gravity_ramp", "s");
  if (const YAML::Node d = root["damping"]) {
    // damping: {local: alpha, until: t, equilibrium: {force_ratio, energy_ratio}} (Anura3D manual
    // §6.3.1, §6.4; docs/scene-reference.md).
    ExpectMap(d, "damping", {"local", "until", "equilibrium"});
    spec.damping.loc = Loc(d, "damping");
    spec.damping.local = Ranged(Need(d, "damping", "local"), "damping.local", "-", 0, true, 1, false);
    if (d["until"]) spec.damping.until = Positive(d["until"], "damping.until", "s");
    if (const YAML::Node eq = d["equilibrium"]) {
      ExpectMap(eq, "damping.equilibrium", {"force_ratio", "energy_ratio"});
      spec.damping.equilibrium = true;
      if (eq["force_ratio"]) {
        spec.damping.force_ratio = Positive(eq["force_ratio"], "damping.equilibrium.force_ratio", "-");
      }
      if (eq["energy_ratio"]) {
        spec.damping.energy_ratio =
            Positive(eq["energy_ratio"], "damping.equilibrium.energy_ratio", "-");
      }
      if (spec.damping.local == 0) {
        Fail(eq, "damping.equilibrium", "the equilibrium rule releases the damping: needs local > 0");
      }
      if (spec.gravity.norm() == 0) {
        Fail(eq, "damping.equilibrium",
             "the force ratio (6.29) is measured against the gravity load: needs a non-zero gravity");
      }
    }
  }
  if (const YAML::Node ms = root["mass_scaling"]) {
    // mass_scaling: {factor: beta, until: t} (Anura3D manual §6.5; docs/scene-reference.md).
    ExpectMap(ms, "mass_scaling", {"factor", "until"});
    spec.mass_scaling.loc = Loc(ms, "mass_scaling");
    spec.mass_scaling.factor =
        Ranged(Need(ms, "mass_scaling", "factor"), "mass_scaling.factor", "-", 1, true, kInf, false);
    if (ms["until"]) spec.mass_scaling.until = Positive(ms["until"], "mass_scaling.until", "s");
  }

  {
    const YAML::Node g = Need(root, "", "grid");
    ExpectMap(g, "grid", {"cell_size", "shape_function", "transfer", "flip_ratio", "update"});
    spec.grid.cell_size = Positive(Need(g, "grid", "cell_size"), "grid.cell_size", "m");
    if (g["shape_function"]) {
      spec.grid.shape_function = Enum(g["shape_function"], "grid.shape_function", kShapeNames);
    }
    if (g["transfer"]) spec.grid.transfer = Enum(g["transfer"], "grid.transfer", kTransferNames);
    if (g["flip_ratio"]) {
      if (spec.grid.transfer != TransferScheme::kPicFlip) {
        Fail(g["flip_ratio"], "grid.flip_ratio",
             std::string("flip_ratio applies only to transfer: pic_flip (transfer is ") +
                 NameOf(kTransferNames, spec.grid.transfer) + ")");
      }
      spec.grid.flip_ratio = Ranged(g["flip_ratio"], "grid.flip_ratio", "-", 0, true, 1, true);
    }
    if (g["update"]) spec.grid.update = Enum(g["update"], "grid.update", kUpdateNames);
  }

  {
    const YAML::Node d = Need(root, "", "domain");
    ExpectMap(d, "domain", {"min", "max", "walls", "on_exit", "ghost_nodes", "gap_test"});
    spec.domain.min = Vector(Need(d, "domain", "min"), "domain.min", "m");
    spec.domain.max = Vector(Need(d, "domain", "max"), "domain.max", "m");
    for (int a = 0; a < dim_; ++a) {
      if (!(spec.domain.max[a] > spec.domain.min[a])) {
        Fail(d["max"], "domain.max", "must exceed domain.min in every component [m]");
      }
    }
    if (d["walls"]) {
      const YAML::Node w = d["walls"];
      std::vector<std::string> faces;
      for (int f = 0; f < kFaceCount; ++f) faces.push_back(FaceName(static_cast<Face>(f)));
      ExpectMap(w, "domain.walls", faces);
      for (const auto& kv : w) {
        const std::string face = kv.first.Scalar();
        const int f = static_cast<int>(std::find(faces.begin(), faces.end(), face) - faces.begin());
        if (dim_ == 2 && f >= 4) {
          Fail(kv.first, "domain.walls." + face,
               "z walls are not allowed in 2-D (plane strain has no z faces)");
        }
        spec.domain.walls[f] = ParseWall(kv.second, "domain.walls." + face);
      }
    }
    if (d["on_exit"]) spec.domain.on_exit = Enum(d["on_exit"], "domain.on_exit", kExitNames);
    if (d["gap_test"]) spec.domain.gap_test = Bool(d["gap_test"], "domain.gap_test");
    if (d["ghost_nodes"]) {
      spec.domain.ghost_nodes = Enum(d["ghost_nodes"], "domain.ghost_nodes", kGhostNames);
    }
  }

  {
    const YAML::Node ms = Need(root, "", "materials");
    if (!ms.IsMap() || ms.size() == 0) {
      Fail(ms, "materials", "expected a non-empty map of material name -> parameters, got " + Describe(ms));
    }
    std::set<std::string> seen;
    for (const auto& kv : ms) {
      const std::string name = Identifier(kv.first, "materials");
      const std::string p = Child("materials", name);
      if (!seen.insert(name).second) Fail(kv.first, p, "duplicate material name '" + name + "'");
      MaterialSpec m = ParseMaterial(kv.second, p);
      m.name = name;
      spec.materials.push_back(m);
    }
  }

  {
    const YAML::Node bs = Need(root, "", "bodies");
    if (!bs.IsSequence() || bs.size() == 0) {
      Fail(bs, "bodies", "expected a non-empty list of bodies, got " + Describe(bs));
    }
    for (size_t i = 0; i < bs.size(); ++i) {
      BodySpec b = ParseBody(bs[i], Index("bodies", i), spec);
      ExpectNewName(spec.bodies, b.name, bs[i], "bodies", i, "body");
      spec.bodies.push_back(std::move(b));
    }
  }

  if (root["obstacles"]) {
    const YAML::Node os = root["obstacles"];
    if (!os.IsSequence()) Fail(os, "obstacles", "expected a list of obstacles, got " + Describe(os));
    for (size_t i = 0; i < os.size(); ++i) {
      ObstacleSpec o = ParseObstacle(os[i], Index("obstacles", i));
      ExpectNewName(spec.obstacles, o.name, os[i], "obstacles", i, "obstacle");
      spec.obstacles.push_back(std::move(o));
    }
  }

  if (root["sensors"]) {
    const YAML::Node ss = root["sensors"];
    if (!ss.IsSequence()) Fail(ss, "sensors", "expected a list of sensors, got " + Describe(ss));
    for (size_t i = 0; i < ss.size(); ++i) {
      const std::string sp = Index("sensors", i);
      ExpectMap(ss[i], sp, {"name", "box"});
      SensorSpec sensor;
      sensor.loc = Loc(ss[i], sp);
      sensor.name = Identifier(Need(ss[i], sp, "name"), Child(sp, "name"));
      const YAML::Node box = Need(ss[i], sp, "box");
      const std::string bp = Child(sp, "box");
      ExpectMap(box, bp, {"min", "max"});
      sensor.min = Vector(Need(box, bp, "min"), Child(bp, "min"), "m");
      sensor.max = Vector(Need(box, bp, "max"), Child(bp, "max"), "m");
      for (int a = 0; a < dim_; ++a) {
        if (!(sensor.max[a] >= sensor.min[a])) {
          Fail(box["max"], Child(bp, "max"), "must not be below min in any component [m]");
        }
      }
      // One namespace with the obstacles: they share the force log.
      std::vector<std::string> taken = {"domain"};
      for (const ObstacleSpec& o : spec.obstacles) taken.push_back(o.name);
      for (const SensorSpec& o : spec.sensors) taken.push_back(o.name);
      if (std::find(taken.begin(), taken.end(), sensor.name) != taken.end()) {
        Fail(ss[i]["name"], Child(sp, "name"),
             "the name '" + sensor.name +
                 "' is taken (by 'domain', an obstacle or another sensor: they share the force log)");
      }
      spec.sensors.push_back(std::move(sensor));
    }
  }

  if (root["body_contact"]) {
    const YAML::Node cs = root["body_contact"];
    if (!cs.IsSequence()) {
      Fail(cs, "body_contact", "expected a list of body pairs, got " + Describe(cs));
    }
    for (size_t i = 0; i < cs.size(); ++i) {
      const std::string cp = Index("body_contact", i);
      ExpectMap(cs[i], cp, {"bodies", "friction", "separable", "gap_test"});
      BodyContactSpec c;
      c.loc = Loc(cs[i], cp);
      const YAML::Node names = Need(cs[i], cp, "bodies");
      const std::string np = Child(cp, "bodies");
      if (!names.IsSequence() || names.size() != 2) {
        Fail(names, np, "expected two body names, e.g. [debris, wall], got " + Describe(names));
      }
      for (int k = 0; k < 2; ++k) {
        c.bodies[k] = Identifier(names[k], Index(np, k));
        int found = -1;
        std::vector<std::string> valid;
        for (size_t b = 0; b < spec.bodies.size(); ++b) {
          valid.push_back(spec.bodies[b].name);
          if (spec.bodies[b].name == c.bodies[k]) found = int(b);
        }
        if (found < 0) {
          Fail(names[k], Index(np, k), "no body is called '" + c.bodies[k] + "' (bodies: " + Join(valid) + ")");
        }
        c.body_index[k] = found;
      }
      if (c.body_index[0] == c.body_index[1]) {
        Fail(names, np, "a body cannot be in contact with itself ('" + c.bodies[0] + "')");
      }
      for (const BodyContactSpec& o : spec.body_contacts) {
        if (std::min(o.body_index[0], o.body_index[1]) == std::min(c.body_index[0], c.body_index[1]) &&
            std::max(o.body_index[0], o.body_index[1]) == std::max(c.body_index[0], c.body_index[1])) {
          Fail(names, np, "the pair '" + c.bodies[0] + "', '" + c.bodies[1] + "' is listed twice");
        }
      }
      if (cs[i]["friction"]) c.friction = NonNegative(cs[i]["friction"], Child(cp, "friction"), "-");
      if (cs[i]["separable"]) c.separable = Bool(cs[i]["separable"], Child(cp, "separable"));
      c.gap_test = c.separable;
      if (const YAML::Node gt = cs[i]["gap_test"]) {
        c.gap_test = Bool(gt, Child(cp, "gap_test"));
        if (c.gap_test && !c.separable) {
          Fail(gt, Child(cp, "gap_test"),
               "the gap test lets separate bodies approach: it needs separable: true");
        }
      }
      // The pair's force-log channel shares one namespace with the other structures.
      const std::string channel = c.bodies[1] + "_on_" + c.bodies[0];
      std::vector<std::string> taken = {"domain"};
      for (const ObstacleSpec& o : spec.obstacles) taken.push_back(o.name);
      for (const SensorSpec& o : spec.sensors) taken.push_back(o.name);
      if (std::find(taken.begin(), taken.end(), channel) != taken.end()) {
        Fail(names, np, "the force log of this pair, '" + channel +
                            "', would have the name of an obstacle or sensor; rename one");
      }
      if (spec.grid.update == UpdateScheme::kMusl) {
        Fail(cs[i], cp, "body contact needs grid.update: usl (the MUSL re-map of per-body fields is not implemented)");
      }
      spec.body_contacts.push_back(std::move(c));
    }
  }

  if (root["output"]) {
    const YAML::Node o = root["output"];
    ExpectMap(o, "output", {"every", "vdb", "energy", "checkpoint_every", "checkpoints_keep"});
    if (o["every"]) spec.output.every = NonNegative(o["every"], "output.every", "s");
    if (o["vdb"]) spec.output.vdb = Bool(o["vdb"], "output.vdb");
    if (o["energy"]) spec.output.energy = Bool(o["energy"], "output.energy");
    if (o["checkpoint_every"])
      spec.output.checkpoint_every = NonNegative(o["checkpoint_every"], "output.checkpoint_every", "s");
    if (o["checkpoints_keep"]) {
      spec.output.checkpoints_keep =
          static_cast<int>(Integer(o["checkpoints_keep"], "output.checkpoints_keep", 1, 1000));
    }
  }
  if (root["analysis"]) spec.analysis = ParseAnalysis(root["analysis"], spec);
  return spec;
}

// --- Writer ---------------------------------------------------------------------------------

void EmitVector(YAML::Emitter& e, const Vec3& v, int dim) {
  e << YAML::Flow << YAML::BeginSeq;
  for (int i = 0; i < dim; ++i) e << Num(v[i]);
  e << YAML::EndSeq;
}

void EmitWall(YAML::Emitter& e, const Wall& w) {
  const char* kind = NameOf(kWallNames, w.kind);
  if (w.kind == WallKind::kOpen || w.kind == WallKind::kNoSlip ||
      (w.kind == WallKind::kSlip && w.separable)) {
    e << kind;
    return;
  }
  e << YAML::Flow << YAML::BeginMap << YAML::Key << "type" << YAML::Value << kind;
  if (w.kind == WallKind::kFriction) e << YAML::Key << "friction" << YAML::Value << Num(w.friction);
  e << YAML::Key << "separable" << YAML::Value << w.separable << YAML::EndMap;
}

void EmitRegion(YAML::Emitter& e, const RegionShape& region, int dim) {
  e << YAML::Flow << YAML::BeginMap;
  if (const auto* box = std::get_if<BoxRegion>(&region)) {
    e << YAML::Key << "box" << YAML::Value << YAML::BeginMap;
    e << YAML::Key << "min" << YAML::Value;
    EmitVector(e, box->min, dim);
    e << YAML::Key << "max" << YAML::Value;
    EmitVector(e, box->max, dim);
  } else if (const auto* sphere = std::get_if<SphereRegion>(&region)) {
    e << YAML::Key << "sphere" << YAML::Value << YAML::BeginMap;
    e << YAML::Key << "center" << YAML::Value;
    EmitVector(e, sphere->center, dim);
    e << YAML::Key << "radius" << YAML::Value << Num(sphere->radius);
  } else if (const auto* cyl = std::get_if<CylinderRegion>(&region)) {
    e << YAML::Key << "cylinder" << YAML::Value << YAML::BeginMap;
    e << YAML::Key << "base" << YAML::Value;
    EmitVector(e, cyl->base, dim);
    e << YAML::Key << "top" << YAML::Value;
    EmitVector(e, cyl->top, dim);
    e << YAML::Key << "radius" << YAML::Value << Num(cyl->radius);
  } else if (const auto* poly = std::get_if<PolygonRegion>(&region)) {
    e << YAML::Key << "polygon" << YAML::Value << YAML::BeginMap;
    e << YAML::Key << "points" << YAML::Value << YAML::Flow << YAML::BeginSeq;
    for (const auto& q : poly->points) {
      e << YAML::Flow << YAML::BeginSeq << Num(q[0]) << Num(q[1]) << YAML::EndSeq;
    }
    e << YAML::EndSeq;
    if (dim == 3) {
      e << YAML::Key << "z" << YAML::Value << YAML::Flow << YAML::BeginSeq << Num(poly->z0)
        << Num(poly->z1) << YAML::EndSeq;
    }
  } else if (const auto* mesh = std::get_if<MeshRegion>(&region)) {
    e << YAML::Key << "mesh" << YAML::Value << YAML::BeginMap;
    e << YAML::Key << "file" << YAML::Value << mesh->file;
    if (!mesh->file_hash.empty()) e << YAML::Key << "file_hash" << YAML::Value << mesh->file_hash;
    e << YAML::Key << "scale" << YAML::Value << Num(mesh->scale);
    e << YAML::Key << "translate" << YAML::Value;
    EmitVector(e, mesh->translate, dim);
  }
  e << YAML::EndMap << YAML::EndMap;
}

}  // namespace

SceneSpec ParseSceneSpec(const std::string& text, const std::string& source,
                         const std::string& base_dir, const std::vector<std::string>& overrides) {
  YAML::Node root;
  try {
    root = YAML::Load(text);
  } catch (const YAML::ParserException& e) {
    throw SceneError(source, e.mark.line + 1, e.mark.column + 1, "", "YAML syntax error: " + e.msg);
  } catch (const YAML::Exception& e) {
    throw SceneError(source, 0, 0, "", std::string("cannot parse YAML: ") + e.what());
  }
  std::vector<AppliedOverride> applied;
  for (const std::string& o : overrides) {
    if (!root.IsDefined() || root.IsNull()) root = YAML::Node(YAML::NodeType::Map);
    applied.push_back(ApplyOverride(root, o));
  }
  SceneParameters parameters = ExpressionResolver(source, applied).Resolve(root);
  Parser parser(source, base_dir, applied);
  try {
    SceneSpec spec = parser.Parse(root);
    spec.parameters = std::move(parameters);
    return spec;
  } catch (const YAML::Exception& e) {  // defensive: the parser checks types before converting
    throw SceneError(source, e.mark.line + 1, e.mark.column + 1, "", e.what());
  }
}

AntiLocking ResolvedAntiLocking(const MaterialSpec& m) {
  AntiLocking a;
  a.strain = m.antilocking.strain;
  a.approach = m.antilocking.approach;
  a.stress = m.antilocking.stress;
  a.constant_fit = m.antilocking.constant_fit;
  a.linear_trace = m.antilocking.linear_trace;
  if (m.antilocking.method) {
    a.method = *m.antilocking.method;
  } else {
    // Node-based for the nearly incompressible fluids (seed ch. 4 requires anti-locking for them,
    // §3.7 prefers node-based for wall forces); none for solids. The viscoplastic fluids project
    // the step's increment: at rest they sit on their viscous plateau mu_max, where projecting
    // the total volumetric strain every step makes the tank's pressure worse than none (21 %
    // against 14 %) and the increment better (8.8 %; antilocking_test, docs/antilocking.md).
    const MaterialParams params = FindMaterialKind(m.model).make_params(m);
    const bool fluid = std::visit([](const auto& p) { return kIsFluid<std::decay_t<decltype(p)>>; },
                                  params);
    const bool newtonian = std::holds_alternative<NewtonianFluidParams>(params);
    a.method = fluid ? AntiLockingMethod::kNode : AntiLockingMethod::kNone;
    if (fluid && !newtonian) a.strain = AntiLockingStrain::kIncrement;
  }
  return a;
}

AntiLocking ResolvedAntiLocking(const SceneSpec& spec, const BodySpec& b) {
  if (!b.antilocking) return ResolvedAntiLocking(spec.materials.at(size_t(b.material_index)));
  // A body's own setting always names its method (ParseAntiLocking requires it).
  return AntiLocking{*b.antilocking->method, b.antilocking->approach, b.antilocking->strain,
                     b.antilocking->stress, b.antilocking->constant_fit,
                     b.antilocking->linear_trace};
}

namespace {

// `antilocking: {method, approach, strain[, stress][, fit]}` in full (stress only when on, fit only
// when constant for a full-tensor approach or linear for node-based AS1).
void EmitAntiLocking(YAML::Emitter& e, const AntiLocking& al) {
  e << YAML::Key << "antilocking" << YAML::Value << YAML::Flow << YAML::BeginMap << YAML::Key
    << "method" << YAML::Value << NameOf(kAntiLockingNames, al.method) << YAML::Key
    << "approach" << YAML::Value << NameOf(kAntiLockingApproachNames, al.approach) << YAML::Key
    << "strain" << YAML::Value << NameOf(kAntiLockingStrainNames, al.strain);
  if (al.stress) e << YAML::Key << "stress" << YAML::Value << true;
  if (al.constant_fit && al.approach != AntiLockingApproach::kVolumetric) {
    e << YAML::Key << "fit" << YAML::Value << "constant";
  }
  if (al.linear_trace) e << YAML::Key << "fit" << YAML::Value << "linear";
  e << YAML::EndMap;
}

}  // namespace

void EmitObstacle(YAML::Emitter& e, const ObstacleSpec& o, int dim) {
  e << YAML::BeginMap;
  e << YAML::Key << "name" << YAML::Value << o.name;
  e << YAML::Key << "shape" << YAML::Value;
  if (const auto* plane = std::get_if<PlaneShape>(&o.shape)) {
    e << YAML::Flow << YAML::BeginMap << YAML::Key << "plane" << YAML::Value << YAML::BeginMap;
    e << YAML::Key << "point" << YAML::Value;
    EmitVector(e, plane->point, dim);
    e << YAML::Key << "normal" << YAML::Value;
    EmitVector(e, plane->normal, dim);
    e << YAML::EndMap << YAML::EndMap;
  } else if (const auto* mesh = std::get_if<ObstacleMeshSpec>(&o.shape)) {
    e << YAML::Flow << YAML::BeginMap << YAML::Key << "mesh" << YAML::Value << YAML::BeginMap;
    e << YAML::Key << "file" << YAML::Value << mesh->file;
    if (!mesh->file_hash.empty()) e << YAML::Key << "file_hash" << YAML::Value << mesh->file_hash;
    e << YAML::Key << "scale" << YAML::Value << Num(mesh->scale);
    e << YAML::Key << "rotate_deg" << YAML::Value;
    EmitVector(e, mesh->rotate_deg, dim);
    e << YAML::Key << "translate" << YAML::Value;
    EmitVector(e, mesh->translate, dim);
    e << YAML::Key << "one_sided" << YAML::Value << mesh->one_sided;
    e << YAML::Key << "faces" << YAML::Value << (mesh->faces_by_normal ? "normal" : "parts");
    e << YAML::EndMap << YAML::EndMap;
  } else {
    std::visit([&](const auto& r) {
      if constexpr (!std::is_same_v<std::decay_t<decltype(r)>, PlaneShape> &&
                    !std::is_same_v<std::decay_t<decltype(r)>, ObstacleMeshSpec>) {
        EmitRegion(e, RegionShape(r), dim);
      }
    }, o.shape);
  }
  e << YAML::Key << "motion" << YAML::Value;
  if (o.motion == ObstacleMotionKind::kFixed) {
    e << "fixed";
  } else if (o.motion == ObstacleMotionKind::kDynamic) {
    e << YAML::BeginMap << YAML::Key << "dynamic" << YAML::Value << YAML::BeginMap;
    if (o.mass > 0) e << YAML::Key << "mass" << YAML::Value << Num(o.mass);
    if (o.density > 0) e << YAML::Key << "density" << YAML::Value << Num(o.density);
    e << YAML::Key << "velocity" << YAML::Value;
    EmitVector(e, o.velocity, dim);
    e << YAML::Key << "angular_velocity_deg" << YAML::Value;
    EmitVector(e, o.angular_velocity_deg, dim);
    e << YAML::Key << "restitution" << YAML::Value << Num(o.restitution);
    e << YAML::EndMap << YAML::EndMap;
  } else {
    e << YAML::BeginMap << YAML::Key << "prescribed" << YAML::Value << YAML::BeginMap;
    if (!o.table.empty()) {
      e << YAML::Key << "table" << YAML::Value << YAML::BeginSeq;
      for (const auto& r : o.table) {
        e << YAML::Flow << YAML::BeginSeq;
        for (int c = 0; c <= dim; ++c) e << Num(r[size_t(c)]);
        e << YAML::EndSeq;
      }
      e << YAML::EndSeq;
    } else {
      e << YAML::Key << "velocity" << YAML::Value;
      EmitVector(e, o.velocity, dim);
      e << YAML::Key << "angular_velocity_deg" << YAML::Value;
      if (dim == 2) {
        e << Num(o.angular_velocity_deg.z());
      } else {
        EmitVector(e, o.angular_velocity_deg, dim);
      }
    }
    if (o.center) {
      e << YAML::Key << "center" << YAML::Value;
      EmitVector(e, *o.center, dim);
    }
    e << YAML::EndMap << YAML::EndMap;
  }
  e << YAML::Key << "contact" << YAML::Value << YAML::Flow << YAML::BeginMap << YAML::Key
    << "friction" << YAML::Value << Num(o.contact.friction) << YAML::Key << "separable"
    << YAML::Value << o.contact.separable << YAML::Key << "adhesion" << YAML::Value
    << Num(o.contact.adhesion) << YAML::Key << "faces" << YAML::Value
    << NameOf(kFaceConstraintNames, o.contact.interpolated_faces) << YAML::Key << "gap_test"
    << YAML::Value << o.contact.gap_test << YAML::EndMap;
  if (o.reference_point) {
    e << YAML::Key << "reference_point" << YAML::Value;
    EmitVector(e, *o.reference_point, dim);
  }
  e << YAML::EndMap;
}

std::string SceneSpecToYaml(const SceneSpec& spec) {
  const int dim = spec.dimension;
  YAML::Emitter e;
  e << YAML::BeginMap;
  e << YAML::Key << "name" << YAML::Value << spec.name;
  e << YAML::Key << "dimension" << YAML::Value << dim;

  e << YAML::Key << "time" << YAML::Value << YAML::BeginMap;
  e << YAML::Key << "end" << YAML::Value << Num(spec.time.end);
  e << YAML::Key << "cfl" << YAML::Value << Num(spec.time.cfl);
  e << YAML::Key << "min_dt" << YAML::Value << Num(spec.time.min_dt);
  e << YAML::Key << "max_dt" << YAML::Value << Num(spec.time.max_dt);
  e << YAML::Key << "fixed_dt" << YAML::Value << Num(spec.time.fixed_dt);
  e << YAML::EndMap;
  e << YAML::Key << "gravity" << YAML::Value;
  EmitVector(e, spec.gravity, dim);
  e << YAML::Key << "gravity_ramp" << YAML::Value << Num(spec.gravity_ramp);
  if (spec.damping.local > 0) {  // only when on: resolved scenes without it stay the same
    e << YAML::Key << "damping" << YAML::Value << YAML::Flow << YAML::BeginMap;
    e << YAML::Key << "local" << YAML::Value << Num(spec.damping.local);
    if (spec.damping.until) e << YAML::Key << "until" << YAML::Value << Num(*spec.damping.until);
    if (spec.damping.equilibrium) {
      e << YAML::Key << "equilibrium" << YAML::Value << YAML::BeginMap << YAML::Key
        << "force_ratio" << YAML::Value << Num(spec.damping.force_ratio) << YAML::Key
        << "energy_ratio" << YAML::Value << Num(spec.damping.energy_ratio) << YAML::EndMap;
    }
    e << YAML::EndMap;
  }
  if (spec.mass_scaling.factor > 1) {  // only when on: resolved scenes without it stay the same
    e << YAML::Key << "mass_scaling" << YAML::Value << YAML::Flow << YAML::BeginMap;
    e << YAML::Key << "factor" << YAML::Value << Num(spec.mass_scaling.factor);
    if (spec.mass_scaling.until) {
      e << YAML::Key << "until" << YAML::Value << Num(*spec.mass_scaling.until);
    }
    e << YAML::EndMap;
  }

  e << YAML::Key << "grid" << YAML::Value << YAML::BeginMap;
  e << YAML::Key << "cell_size" << YAML::Value << Num(spec.grid.cell_size);
  e << YAML::Key << "shape_function" << YAML::Value
    << NameOf(kShapeNames, spec.grid.shape_function);
  e << YAML::Key << "transfer" << YAML::Value << NameOf(kTransferNames, spec.grid.transfer);
  if (spec.grid.transfer == TransferScheme::kPicFlip) {
    e << YAML::Key << "flip_ratio" << YAML::Value << Num(spec.grid.flip_ratio);
  }
  e << YAML::Key << "update" << YAML::Value << NameOf(kUpdateNames, spec.grid.update);
  e << YAML::EndMap;

  e << YAML::Key << "domain" << YAML::Value << YAML::BeginMap;
  e << YAML::Key << "min" << YAML::Value;
  EmitVector(e, spec.domain.min, dim);
  e << YAML::Key << "max" << YAML::Value;
  EmitVector(e, spec.domain.max, dim);
  e << YAML::Key << "walls" << YAML::Value << YAML::BeginMap;
  for (int f = 0; f < 2 * dim; ++f) {
    e << YAML::Key << FaceName(static_cast<Face>(f)) << YAML::Value;
    EmitWall(e, spec.domain.walls[f]);
  }
  e << YAML::EndMap;
  e << YAML::Key << "on_exit" << YAML::Value << NameOf(kExitNames, spec.domain.on_exit);
  e << YAML::Key << "ghost_nodes" << YAML::Value << NameOf(kGhostNames, spec.domain.ghost_nodes);
  e << YAML::Key << "gap_test" << YAML::Value << spec.domain.gap_test;
  e << YAML::EndMap;

  e << YAML::Key << "materials" << YAML::Value << YAML::BeginMap;
  for (const MaterialSpec& m : spec.materials) {
    e << YAML::Key << m.name << YAML::Value << YAML::BeginMap;
    e << YAML::Key << "model" << YAML::Value << FindMaterialKind(m.model).name;
    e << YAML::Key << "density" << YAML::Value << Num(m.density);
    const MaterialKind& kind = FindMaterialKind(m.model);
    if (kind.elastic && m.given_as_youngs) {
      e << YAML::Key << "youngs_modulus" << YAML::Value << Num(m.youngs_modulus);
      e << YAML::Key << "poisson_ratio" << YAML::Value << Num(m.poisson_ratio);
    } else if (kind.elastic) {
      e << YAML::Key << "bulk_modulus" << YAML::Value << Num(m.bulk_modulus);
      e << YAML::Key << "shear_modulus" << YAML::Value << Num(m.shear_modulus);
    }
    for (const ParamDesc& d : kind.params) {
      const auto it = m.values.find(d.key);
      if (it == m.values.end()) continue;
      e << YAML::Key << d.key << YAML::Value;
      if (d.choices.empty()) {
        e << Num(it->second);
      } else {
        e << d.choices[static_cast<size_t>(it->second)];
      }
    }
    EmitAntiLocking(e, ResolvedAntiLocking(m));
    if (m.particle_shifting) e << YAML::Key << "particle_shifting" << YAML::Value << true;
    if (m.bulk_viscosity.enabled) {  // only when on (resolved scenes without it stay the same)
      e << YAML::Key << "bulk_viscosity" << YAML::Value << YAML::Flow << YAML::BeginMap
        << YAML::Key << "quadratic" << YAML::Value << Num(m.bulk_viscosity.quadratic)
        << YAML::Key << "linear" << YAML::Value << Num(m.bulk_viscosity.linear) << YAML::EndMap;
    }
    e << YAML::EndMap;
  }
  e << YAML::EndMap;

  e << YAML::Key << "bodies" << YAML::Value << YAML::BeginSeq;
  for (const BodySpec& b : spec.bodies) {
    e << YAML::BeginMap;
    e << YAML::Key << "name" << YAML::Value << b.name;
    e << YAML::Key << "material" << YAML::Value << b.material;
    e << YAML::Key << "region" << YAML::Value;
    EmitRegion(e, b.region, dim);
    e << YAML::Key << "particles_per_cell" << YAML::Value << b.particles_per_cell;
    e << YAML::Key << "jitter" << YAML::Value << Num(b.jitter);
    e << YAML::Key << "seed" << YAML::Value << b.seed;
    e << YAML::Key << "velocity" << YAML::Value;
    EmitVector(e, b.velocity, dim);
    if (b.geostatic_k0) {
      e << YAML::Key << "initial_stress" << YAML::Value << YAML::Flow << YAML::BeginMap
        << YAML::Key << "geostatic" << YAML::Value << YAML::BeginMap << YAML::Key << "k0"
        << YAML::Value << (b.k0_from_friction ? std::string("jaky") : Num(*b.geostatic_k0))
        << YAML::EndMap << YAML::EndMap;
    }
    if (b.antilocking) EmitAntiLocking(e, ResolvedAntiLocking(spec, b));  // only when overridden
    e << YAML::Key << "tractions" << YAML::Value;
    if (b.tractions.empty()) e << YAML::Flow;
    e << YAML::BeginSeq;
    for (const TractionSpec& t : b.tractions) {
      e << YAML::Flow << YAML::BeginMap << YAML::Key << "face" << YAML::Value << FaceName(t.face)
        << YAML::Key << "traction" << YAML::Value;
      EmitVector(e, t.traction, dim);
      e << YAML::EndMap;
    }
    e << YAML::EndSeq;
    e << YAML::EndMap;
  }
  e << YAML::EndSeq;

  if (!spec.obstacles.empty()) {
    e << YAML::Key << "obstacles" << YAML::Value << YAML::BeginSeq;
    for (const ObstacleSpec& o : spec.obstacles) EmitObstacle(e, o, dim);
    e << YAML::EndSeq;
  }

  if (!spec.sensors.empty()) {
    e << YAML::Key << "sensors" << YAML::Value << YAML::BeginSeq;
    for (const SensorSpec& s : spec.sensors) {
      e << YAML::Flow << YAML::BeginMap << YAML::Key << "name" << YAML::Value << s.name
        << YAML::Key << "box" << YAML::Value << YAML::BeginMap << YAML::Key << "min" << YAML::Value;
      EmitVector(e, s.min, dim);
      e << YAML::Key << "max" << YAML::Value;
      EmitVector(e, s.max, dim);
      e << YAML::EndMap << YAML::EndMap;
    }
    e << YAML::EndSeq;
  }

  if (!spec.body_contacts.empty()) {
    e << YAML::Key << "body_contact" << YAML::Value << YAML::BeginSeq;
    for (const BodyContactSpec& c : spec.body_contacts) {
      e << YAML::Flow << YAML::BeginMap << YAML::Key << "bodies" << YAML::Value << YAML::Flow
        << YAML::BeginSeq << c.bodies[0] << c.bodies[1] << YAML::EndSeq << YAML::Key << "friction"
        << YAML::Value << Num(c.friction) << YAML::Key << "separable" << YAML::Value << c.separable
        << YAML::Key << "gap_test" << YAML::Value << c.gap_test << YAML::EndMap;
    }
    e << YAML::EndSeq;
  }

  e << YAML::Key << "output" << YAML::Value << YAML::BeginMap;
  e << YAML::Key << "every" << YAML::Value << Num(spec.output.every);
  e << YAML::Key << "vdb" << YAML::Value << spec.output.vdb;
  e << YAML::Key << "energy" << YAML::Value << spec.output.energy;
  // Only when set: they do not change the results, and older resolved scenes (sweep digests,
  // docs/sweeps.md) stay the same.
  if (spec.output.checkpoint_every > 0)
    e << YAML::Key << "checkpoint_every" << YAML::Value << Num(spec.output.checkpoint_every);
  if (spec.output.checkpoints_keep != OutputSpec{}.checkpoints_keep)
    e << YAML::Key << "checkpoints_keep" << YAML::Value << spec.output.checkpoints_keep;
  e << YAML::EndMap;
  if (spec.analysis.present) {  // as written; smoothing and steady state with their defaults
    const AnalysisSettings& a = spec.analysis.settings;
    e << YAML::Key << "analysis" << YAML::Value << YAML::BeginMap;
    if (!a.structure.empty()) e << YAML::Key << "structure" << YAML::Value << a.structure;
    if (!a.face.empty()) e << YAML::Key << "face" << YAML::Value << a.face;
    if (a.component) {
      e << YAML::Key << "component" << YAML::Value << NameOf(kComponentNames, *a.component);
    }
    const ReferenceValues& r = a.reference;
    const std::pair<const char*, const std::optional<Real>*> refs[] = {
        {"velocity", &r.velocity}, {"density", &r.density}, {"width", &r.width},
        {"height", &r.height},     {"area", &r.area},       {"k0", &r.k0},
        {"gravity", &r.gravity}};
    e << YAML::Key << "reference" << YAML::Value << YAML::Flow << YAML::BeginMap;
    for (const auto& [key, value] : refs) {
      if (*value) e << YAML::Key << key << YAML::Value << Num(**value);
    }
    e << YAML::EndMap;
    const SmoothingSettings& f = a.smoothing;
    e << YAML::Key << "smoothing" << YAML::Value;
    switch (f.kind) {
      case SmoothingKind::kNone: e << "none"; break;
      case SmoothingKind::kMovingAverage:
        e << YAML::Flow << YAML::BeginMap << YAML::Key << "moving_average" << YAML::Value
          << Num(f.window) << YAML::EndMap;
        break;
      case SmoothingKind::kExponential:
        e << YAML::Flow << YAML::BeginMap << YAML::Key << "exponential" << YAML::Value
          << Num(f.time_constant) << YAML::EndMap;
        break;
      case SmoothingKind::kLowPass:
        e << YAML::Flow << YAML::BeginMap << YAML::Key << "low_pass" << YAML::Value
          << Num(f.cutoff) << YAML::Key << "order" << YAML::Value << f.order << YAML::EndMap;
        break;
    }
    const SteadyStateSettings& ss = a.steady_state;
    e << YAML::Key << "steady_state" << YAML::Value << YAML::Flow << YAML::BeginMap;
    e << YAML::Key << "average" << YAML::Value << Num(ss.average);
    e << YAML::Key << "min_window" << YAML::Value << Num(ss.min_window);
    e << YAML::Key << "tolerance" << YAML::Value << Num(ss.tolerance);
    if (ss.window) {
      e << YAML::Key << "window" << YAML::Value << YAML::Flow << YAML::BeginSeq
        << Num((*ss.window)[0]) << Num((*ss.window)[1]) << YAML::EndSeq;
    }
    e << YAML::EndMap;
    e << YAML::EndMap;
  }
  if (!spec.parameters.empty()) {  // values already substituted; kept for the record
    e << YAML::Key << "parameters" << YAML::Value << YAML::BeginMap;
    for (const auto& [name, value] : spec.parameters) e << YAML::Key << name << YAML::Value << Num(value);
    e << YAML::EndMap;
  }
  e << YAML::EndMap;
  return std::string(e.c_str()) + "\n";
}

namespace {
void CollectMeshFileHashes(const YAML::Node& n, std::vector<std::pair<std::string, std::string>>& out) {
  if (n.IsMap()) {
    const YAML::Node file = n["file"], hash = n["file_hash"];
    if (file && hash && file.IsScalar() && hash.IsScalar()) out.emplace_back(file.Scalar(), hash.Scalar());
    for (const auto& kv : n) CollectMeshFileHashes(kv.second, out);
  } else if (n.IsSequence()) {
    for (const auto& child : n) CollectMeshFileHashes(child, out);
  }
}
}  // namespace

std::vector<std::pair<std::string, std::string>> MeshFileHashes(const std::string& resolved_yaml) {
  std::vector<std::pair<std::string, std::string>> out;
  try {
    CollectMeshFileHashes(YAML::Load(resolved_yaml), out);
  } catch (const YAML::Exception&) {
    out.clear();
  }
  return out;
}

}  // namespace surge
