#include "yaml_reader.hpp"

#include <algorithm>
#include <cmath>
#include <fstream>
#include <limits>
#include <map>
#include <sstream>

#include "extwrench/core/error.hpp"
#include "extwrench/io/input_file.hpp"

namespace extwrench::io_detail {
namespace {

// What a node that should have been a mapping is, for the message: an empty file reads as null,
// a CSV given as a configuration as one long scalar.
std::string what_instead(const YAML::Node& node, bool top_level) {
  if (!node.IsDefined() || node.IsNull())
    return top_level ? "got nothing: the file is empty (or only comments)" : "got nothing";
  if (node.IsSequence()) return "got a list";
  constexpr std::size_t kShown = 40;
  const std::string& text = node.Scalar();
  return "got the text '" + text.substr(0, kShown) + (text.size() > kShown ? "..." : "") + "'";
}

std::string listed(std::initializer_list<const char*> names) {
  std::string list;
  for (const char* a : names) list += std::string(list.empty() ? "" : ", ") + a;
  return list;
}

bool in_range(double v, const Range& r) {
  return std::isfinite(v) && (r.lo_open ? v > r.lo : v >= r.lo) && v <= r.hi;
}

}  // namespace

Range positive(const char* text) { return {0.0, std::numeric_limits<double>::max(), true, text}; }
Range non_negative(const char* text) {
  return {0.0, std::numeric_limits<double>::max(), false, text};
}

YAML::Node load_yaml_string(const std::string& text, const std::string& name) {
  try {
    return YAML::Load(text);
  } catch (const YAML::Exception& e) {
    throw Error(name + ":" + std::to_string(e.mark.line + 1) + ": YAML syntax error: " + e.msg);
  }
}

YAML::Node load_yaml_file(const std::filesystem::path& path, const std::string& what) {
  const std::string text = read_input_file(path, what);
  // A robot file given where YAML belongs (`--config arm.urdf`) would read as "illegal map value"
  // on some line of it: say what the file is instead. No YAML document begins with '<'.
  const std::size_t first = text.find_first_not_of(" \t\r\n\xEF\xBB\xBF");
  if (first != std::string::npos && text[first] == '<') {
    const auto line =
        std::count(text.begin(), text.begin() + static_cast<std::ptrdiff_t>(first), '\n') + 1;
    const bool names_robot = what == "configuration" || what == "scenario";
    const std::string kind = what == "robot" ? "DH robot table" : what;
    throw Error(
        path.string() + ":" + std::to_string(line) + ": " +
        xml_given_instead("a " + kind + " is YAML" +
                          (names_robot ? ", which names the robot file under 'robot:'" : "")));
  }
  return load_yaml_string(text, path.string());
}

YamlReader::YamlReader(std::string file, NumberRules rules)
    : file_(std::move(file)), rules_(rules) {
  rules_.trim_space = true;
}

std::string YamlReader::where(const YAML::Node& node) const {
  if (!node.IsDefined() || node.Mark().line < 0) return file_;
  return file_ + ":" + std::to_string(node.Mark().line + 1);
}

std::string YamlReader::key(const std::string& prefix, const std::string& k) {
  return prefix.empty() ? k : prefix + "." + k;
}

std::string YamlReader::item(const std::string& key, std::size_t i) {
  return key + "[" + std::to_string(i) + "]";
}

void YamlReader::fail(const YAML::Node& node, const std::string& key,
                      const std::string& what) const {
  throw Error(where(node) + ": " + key + ": " + what);
}

void YamlReader::only_keys(const YAML::Node& map, const std::string& context,
                           std::initializer_list<const char*> allowed) const {
  keys_of(map, context, [&](const YAML::Node& key_node, const std::string& k) {
    if (std::find_if(allowed.begin(), allowed.end(), [&](const char* a) { return k == a; }) ==
        allowed.end())
      fail(key_node, key(context, k), "unknown key (expected one of: " + listed(allowed) + ")");
  });
}

void YamlReader::unique_keys(const YAML::Node& map, const std::string& context) const {
  keys_of(map, context, [](const YAML::Node&, const std::string&) {});
}

void YamlReader::keys_of(
    const YAML::Node& map, const std::string& context,
    const std::function<void(const YAML::Node&, const std::string&)>& check) const {
  if (!map.IsMap()) {
    fail(map, context.empty() ? "(top level)" : context,
         "expected a mapping (key: value), " + what_instead(map, context.empty()));
  }
  // YAML forbids a key twice in one mapping; yaml-cpp keeps both and map[k] reads the first, so
  // a second `detection:` appended to a file would be ignored without a word.
  std::map<std::string, YAML::Node> seen;
  for (const auto& kv : map) {
    if (!kv.first.IsScalar()) {
      fail(kv.first, context.empty() ? "(top level)" : context,
           std::string("a key must be a name, got a ") + (kv.first.IsMap()        ? "mapping"
                                                          : kv.first.IsSequence() ? "list"
                                                                                  : "null"));
    }
    const std::string k = kv.first.Scalar();
    // `<<: *base` (YAML 1.1's merge key, for sweeps of schemes) is a plain key to yaml-cpp: the
    // merged keys would be missing, reported as such far from the cause.
    if (k == "<<") {
      fail(kv.first, key(context, k),
           "YAML merge keys (<<: *anchor) are not supported by this YAML reader (yaml-cpp): "
           "write the keys out, or alias whole values (sensor: *ft_sensor)");
    }
    check(kv.first, k);
    const auto [first, inserted] = seen.emplace(k, kv.first);
    if (!inserted) {
      fail(kv.first, key(context, k),
           "given twice in one mapping (first at " + where(first->second) +
               "): merge the two or delete one");
    }
  }
}

YAML::Node YamlReader::required(const YAML::Node& map, const std::string& context,
                                const char* k) const {
  const YAML::Node n = map[k];
  if (!n) fail(map, key(context, k), "missing (required)");
  return n;
}

std::string YamlReader::string(const YAML::Node& node, const std::string& key) const {
  if (!node.IsScalar() || node.Scalar().empty()) fail(node, key, "expected a non-empty string");
  return node.Scalar();
}

std::size_t YamlReader::one_of(const YAML::Node& node, const std::string& key,
                               std::initializer_list<const char*> names) const {
  const std::string s = string(node, key);
  std::size_t i = 0;
  for (const char* name : names) {
    if (s == name) return i;
    ++i;
  }
  fail(node, key, "expected one of " + listed(names) + ", got '" + s + "'");
}

double YamlReader::parsed(const YAML::Node& node, const std::string& key, NumberRules rules) const {
  if (!node.IsScalar()) fail(node, key, "expected a number");
  const std::string& s = node.Scalar();
  const auto v = parse_number(s, rules);
  if (!v) {
    fail(node, key,
         std::string("expected a finite number") + (rules.pi ? " (or pi expression)" : "") +
             ", got '" + s + "'");
  }
  return *v;
}

double YamlReader::number(const YAML::Node& node, const std::string& key) const {
  return parsed(node, key, rules_);
}

double YamlReader::angle(const YAML::Node& node, const std::string& key) const {
  NumberRules rules = rules_;
  rules.pi = true;
  return parsed(node, key, rules);
}

double YamlReader::number_in(const YAML::Node& node, const std::string& key,
                             const Range& range) const {
  const double v = number(node, key);
  if (!in_range(v, range))
    fail(node, key, std::string("expected a value ") + range.text + ", got " + node.Scalar());
  return v;
}

void YamlReader::set_number_in(const YAML::Node& map, const std::string& context, const char* k,
                               const Range& range, double& out) const {
  if (const YAML::Node n = map[k]) out = number_in(n, key(context, k), range);
}

long long YamlReader::integer(const YAML::Node& node, const std::string& key,
                              const Range& range) const {
  const double v = number(node, key);
  if (!in_range(v, range) || v != std::floor(v)) {
    fail(node, key,
         std::string("expected a whole number ") + range.text + ", got " + node.Scalar());
  }
  return static_cast<long long>(v);
}

bool YamlReader::is_boolean(const YAML::Node& node) {
  if (!node.IsScalar()) return false;
  const std::string& s = node.Scalar();
  return s == "true" || s == "True" || s == "yes" || s == "false" || s == "False" || s == "no";
}

bool YamlReader::boolean(const YAML::Node& node, const std::string& key) const {
  if (!is_boolean(node)) fail(node, key, "expected true or false");
  const std::string& s = node.Scalar();
  return s == "true" || s == "True" || s == "yes";
}

VectorX YamlReader::vector(const YAML::Node& node, const std::string& key, int n,
                           const Range* range) const {
  const auto one = [&](const YAML::Node& nd, const std::string& k) {
    return range ? number_in(nd, k, *range) : number(nd, k);
  };
  if (node.IsScalar()) return VectorX::Constant(n, one(node, key));
  if (!node.IsSequence() || static_cast<int>(node.size()) != n) {
    fail(node, key,
         "expected " + std::to_string(n) + " values (or one for all)" +
             (node.IsSequence() ? ", got " + std::to_string(node.size()) : ""));
  }
  VectorX v(n);
  for (int i = 0; i < n; ++i) {
    const auto k = static_cast<std::size_t>(i);
    v[i] = one(node[k], item(key, k));
  }
  return v;
}

Vector3 YamlReader::vector3(const YAML::Node& node, const std::string& key, bool angles) const {
  if (!node.IsSequence() || node.size() != 3) fail(node, key, "expected a list of 3 numbers");
  Vector3 v;
  for (std::size_t i = 0; i < 3; ++i) {
    v[static_cast<Eigen::Index>(i)] =
        angles ? angle(node[i], item(key, i)) : number(node[i], item(key, i));
  }
  return v;
}

Vector3 YamlReader::vector3_or(const YAML::Node& map, const std::string& context, const char* k,
                               const Vector3& fallback, bool angles) const {
  const YAML::Node n = map[k];
  return n ? vector3(n, key(context, k), angles) : fallback;
}

Pose YamlReader::xyz_rpy(const YAML::Node& map, const std::string& context, bool angles) const {
  return Pose::from_xyz_rpy(vector3_or(map, context, "xyz", Vector3::Zero()),
                            vector3_or(map, context, "rpy", Vector3::Zero(), angles));
}

Pose YamlReader::pose(const YAML::Node& node, const std::string& key) const {
  only_keys(node, key, {"xyz", "rpy"});
  return xyz_rpy(node, key);
}

SensorType YamlReader::sensor_type(const YAML::Node& node, const std::string& key) const {
  constexpr SensorType kTypes[] = {SensorType::kForceTorque, SensorType::kForce, SensorType::kNone};
  return kTypes[one_of(node, key, {"ft", "force", "none"})];
}

int YamlReader::body(const Model& model, const YAML::Node& node, const std::string& key) const {
  const std::string name = string(node, key);
  const std::optional<int> b = model.find_body(name);
  if (!b) fail(node, key, "no link named '" + name + "' in robot '" + model.name + "'");
  return *b;
}

void YamlReader::locked_joints(const YAML::Node& node, const std::string& key,
                               LoadOptions& options) const {
  if (!node.IsMap()) fail(node, key, "expected a mapping joint name -> value [rad | m]");
  for (const auto& kv : node) {
    const std::string name = kv.first.Scalar();
    const std::string k = YamlReader::key(key, name);
    const double value = number(kv.second, k);
    if (options.locked_joints.emplace(name, value).second)
      options.locked_joint_sources[name] = where(kv.second) + ": " + k;
  }
}

void YamlReader::chain(const YAML::Node& root, LoadOptions& options) const {
  if (root["root_body"] && options.root_body.empty())
    options.root_body = string(root["root_body"], "root_body");
  if (root["tip_body"] && options.tip_body.empty())
    options.tip_body = string(root["tip_body"], "tip_body");
}

}  // namespace extwrench::io_detail
