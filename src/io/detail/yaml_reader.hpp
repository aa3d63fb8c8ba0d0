// The one layer every YAML format reads through (estimator configurations, scenarios, DH tables):
// typed getters that throw extwrench::Error "file:line: key: what", one wording for every
// message, and one number rule (io/number_text.hpp). Private to src/io.
#pragma once

#include <yaml-cpp/yaml.h>

#include <cstddef>
#include <filesystem>
#include <functional>
#include <initializer_list>
#include <ios>
#include <string>

#include "extwrench/core/error.hpp"
#include "extwrench/core/types.hpp"
#include "extwrench/estimation/base_sensor.hpp"
#include "extwrench/estimation/contact_estimate.hpp"
#include "extwrench/io/number_text.hpp"
#include "extwrench/io/robot_loader.hpp"
#include "extwrench/model/model.hpp"

namespace extwrench::io_detail {

/// An interval of accepted values and how messages write it ("> 0 [N]", "in (0, 1]").
struct Range {
  double lo;
  double hi;
  bool lo_open;
  const char* text;
};

/// "> 0" and ">= 0", with an optional unit for messages, e.g. positive(" [s]").
Range positive(const char* text = "> 0");
Range non_negative(const char* text = ">= 0");

/// Parses a whole YAML text; a syntax error becomes "name:line: YAML syntax error: ...".
YAML::Node load_yaml_string(const std::string& text, const std::string& name);
/// Runs `read`, turning what yaml-cpp or the standard library throws past the readers (a
/// conversion of a value of an unexpected kind, a stream error) into extwrench::Error
/// "file:line: what", so every message names the file: the loaders' boundary.
template <class F>
auto at_loader_boundary(const std::string& file, F&& read) -> decltype(read()) {
  try {
    return read();
  } catch (const YAML::Exception& e) {
    throw Error(file + ":" + std::to_string(e.mark.line < 0 ? 1 : e.mark.line + 1) + ": " + e.msg +
                " (a value of an unexpected kind)");
  } catch (const std::ios_base::failure& e) {
    throw Error(file + ": read error: " + e.what());
  }
}

/// Reads and parses a file; "path: cannot open the <what> file" when it cannot be read.
YAML::Node load_yaml_file(const std::filesystem::path& path, const std::string& what);

class YamlReader {
 public:
  /// `file` names the source in messages; `rules` say what its numbers may be beyond a finite
  /// number (white space around a number is always allowed, as YAML quoting can leave it).
  explicit YamlReader(std::string file, NumberRules rules = {});

  [[nodiscard]] const std::string& file() const { return file_; }
  /// "file:line", or "file" for a node that is not in the document.
  [[nodiscard]] std::string where(const YAML::Node& node) const;
  /// "prefix.key", or "key" without a prefix.
  [[nodiscard]] static std::string key(const std::string& prefix, const std::string& k);
  /// "key[i]".
  [[nodiscard]] static std::string item(const std::string& key, std::size_t i);

  /// Throws "file:line: key: what".
  [[noreturn]] void fail(const YAML::Node& node, const std::string& key,
                         const std::string& what) const;

  /// Throws unless `map` is a mapping whose keys are all in `allowed`; `context` is the key of
  /// the mapping ("" at the top level), and prefixes the unknown key in the message.
  void only_keys(const YAML::Node& map, const std::string& context,
                 std::initializer_list<const char*> allowed) const;
  /// Throws unless `map` is a mapping whose keys are names, each given once (any names: a
  /// mapping whose keys another reader checks, e.g. a scenario's scheme).
  void unique_keys(const YAML::Node& map, const std::string& context) const;
  /// map[k], or "context.k: missing (required)".
  [[nodiscard]] YAML::Node required(const YAML::Node& map, const std::string& context,
                                    const char* k) const;

  /// A non-empty scalar.
  [[nodiscard]] std::string string(const YAML::Node& node, const std::string& key) const;
  /// The index in `names` of the scalar; "expected one of a, b, got 'x'" otherwise.
  [[nodiscard]] std::size_t one_of(const YAML::Node& node, const std::string& key,
                                   std::initializer_list<const char*> names) const;
  /// A number with the reader's rules.
  [[nodiscard]] double number(const YAML::Node& node, const std::string& key) const;
  /// A number with the reader's rules, or a pi expression (DH angles: "-pi/2").
  [[nodiscard]] double angle(const YAML::Node& node, const std::string& key) const;
  /// A finite number in `range`.
  [[nodiscard]] double number_in(const YAML::Node& node, const std::string& key,
                                 const Range& range) const;
  /// Sets `out` to map[k] as number_in(range) when the key is there.
  void set_number_in(const YAML::Node& map, const std::string& context, const char* k,
                     const Range& range, double& out) const;
  /// A whole number in `range` (written as a number: "3", "3.0", "1e3").
  [[nodiscard]] long long integer(const YAML::Node& node, const std::string& key,
                                  const Range& range) const;
  /// true / True / yes or false / False / no.
  [[nodiscard]] bool boolean(const YAML::Node& node, const std::string& key) const;
  /// Whether the node is a boolean as boolean() reads it.
  [[nodiscard]] static bool is_boolean(const YAML::Node& node);

  /// A list of n numbers, or one number for all n; each in `range` when given.
  [[nodiscard]] VectorX vector(const YAML::Node& node, const std::string& key, int n,
                               const Range* range = nullptr) const;
  /// A list of exactly 3 numbers (angles when `angles`).
  [[nodiscard]] Vector3 vector3(const YAML::Node& node, const std::string& key,
                                bool angles = false) const;
  /// map[k] as vector3, or `fallback` when absent.
  [[nodiscard]] Vector3 vector3_or(const YAML::Node& map, const std::string& context, const char* k,
                                   const Vector3& fallback, bool angles = false) const;
  /// The keys xyz [m] and rpy [rad] of `map` (each zero when absent) as X = Trans(xyz) Rot(rpy);
  /// DH tables allow pi expressions in rpy (`angles`).
  [[nodiscard]] Pose xyz_rpy(const YAML::Node& map, const std::string& context,
                             bool angles = false) const;
  /// A mapping {xyz, rpy} and nothing else.
  [[nodiscard]] Pose pose(const YAML::Node& node, const std::string& key) const;

  /// ft | force | none.
  [[nodiscard]] SensorType sensor_type(const YAML::Node& node, const std::string& key) const;
  /// `locked_joints: {NAME: VALUE, ...}` [rad | m] added to `options` (entries already there,
  /// from the command line, win) with their file:line as the lock's source.
  void locked_joints(const YAML::Node& node, const std::string& key, LoadOptions& options) const;
  /// An MJCF scene's chain, `root_body:` and `tip_body:` of the mapping `root`, into `options`
  /// where it has none (the command line's --root-body, --tip-body win).
  void chain(const YAML::Node& root, LoadOptions& options) const;
  /// The index of the body named by the scalar.
  [[nodiscard]] int body(const Model& model, const YAML::Node& node, const std::string& key) const;

 private:
  /// The checks of only_keys and unique_keys: a mapping, name keys, each once; `check` sees each
  /// key first (only_keys: whether it is allowed).
  void keys_of(const YAML::Node& map, const std::string& context,
               const std::function<void(const YAML::Node&, const std::string&)>& check) const;
  [[nodiscard]] double parsed(const YAML::Node& node, const std::string& key,
                              NumberRules rules) const;

  std::string file_;
  NumberRules rules_;
};

}  // namespace extwrench::io_detail
