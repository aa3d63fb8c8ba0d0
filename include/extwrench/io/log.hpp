// Robot logs as CSV (docs/log_format.md): reading them row by row in constant memory, writing
// them (the simulator's output), and the estimates file of `extwrench estimate`.
#pragma once

#include <cstdint>
#include <filesystem>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "extwrench/core/sample.hpp"
#include "extwrench/estimation/contact_estimate.hpp"
#include "extwrench/io/csv.hpp"
#include "extwrench/model/model.hpp"

namespace extwrench {

/// Which optional column groups a log has.
struct LogLayout {
  int n = 0;                  ///< joints: q1..qn, (dq1..dqn), tau1..taun
  bool velocity = true;       ///< dq1..dqn
  bool force = false;         ///< fs_x fs_y fs_z
  bool moment = false;        ///< ms_x ms_y ms_z (only with force)
  bool truth = false;         ///< true_link, true_f*, true_m*, true_p*
  bool true_tau_ext = false;  ///< true_tau_ext1..n
};

/// The column names of a layout, in the order the writer uses.
[[nodiscard]] std::vector<std::string> log_columns(const LogLayout& layout);

/// Streams a log: one Sample per row. Columns are found by name; missing required columns,
/// bad numbers and non-increasing t are errors naming file, line and column. Columns that are
/// not part of the format are ignored (ignored_columns() lists them, for one warning).
/// Without dq columns, q̇ is differentiated: (q_k − q_{k−1}) / (t_k − t_{k−1}), and on the first
/// row the forward difference to the second row.
class LogReader {
 public:
  /// `model` gives n and resolves true_link to body indices (unknown names are errors).
  LogReader(const std::filesystem::path& path, const Model& model);

  [[nodiscard]] const LogLayout& layout() const { return layout_; }
  [[nodiscard]] const std::vector<std::string>& ignored_columns() const { return ignored_; }
  [[nodiscard]] const std::string& name() const { return csv_.name(); }
  /// Line number of the row of the last sample returned.
  [[nodiscard]] std::size_t line() const { return sample_line_; }

  /// Next row into `out` (vectors sized once, then reused). False at the end of the file.
  bool next(Sample& out);

 private:
  bool read_row(Sample& out);  // parses the current CSV row
  void read_vector(const std::vector<int>& columns, VectorX& v) const;

  CsvReader csv_;
  const Model* model_;
  LogLayout layout_;
  std::vector<std::string> ignored_;
  int col_t_ = -1;
  std::vector<int> col_q_, col_dq_, col_tau_, col_fs_, col_ms_, col_f_, col_m_, col_p_,
      col_tau_ext_;
  int col_link_ = -1;
  bool have_prev_ = false;
  double prev_t_ = 0.0;
  std::size_t prev_line_ = 0;
  VectorX prev_q_;
  // One row of look-ahead, used for the first row's velocity when dq is not logged.
  std::optional<Sample> pending_;
  std::size_t pending_line_ = 0;
  std::size_t sample_line_ = 0;
  std::string last_link_;
  int last_body_ = -1;
  int last_contacts_ = 0;
};

/// Writes samples in the log format.
class LogWriter {
 public:
  LogWriter(const std::filesystem::path& path, const LogLayout& layout);
  void write(const Sample& s);
  void close() { csv_.close(); }

 private:
  LogLayout layout_;
  CsvWriter csv_;
};

/// The estimates file: t, contact, link, fx fy fz, mx my mz, px py pz, lx ly lz, status, cond,
/// r1..rn, link_candidates, sigma_f, sigma_m, sigma_line, sigma_point [, offset1..n,
/// bias_fx..bias_mz with drift tracking] (world frame; quantities not estimated are empty cells;
/// round-trip precision). link_candidates: the other links geometry isolation found consistent,
/// by name, '|'-separated (docs/estimator.md#geometry-consistent-isolation).
class EstimatesWriter {
 public:
  /// `model` gives n and the body names of the link column. `drift_columns`: append
  /// offset1..n and bias_fx..bias_mz (the estimator's drift tracking, EstimatorOptions::drift).
  EstimatesWriter(const std::filesystem::path& path, const Model& model,
                  bool drift_columns = false);
  void write(const ContactEstimate& e);
  void close() { csv_.close(); }

  /// The text of the status column: the Status when not ok ("non_finite:q[2]"), else the
  /// estimate's flags (describe_flags: "contact|force|line_of_action|...", "free").
  [[nodiscard]] static std::string status_text(const ContactEstimate& e);

 private:
  int n_;
  bool drift_columns_ = false;
  std::vector<std::string> body_names_;
  CsvWriter csv_;
  // The status text of the last ok row: flags change rarely, describe_flags() allocates.
  std::uint32_t cached_flags_ = 0;
  std::string cached_status_;
  std::uint64_t cached_candidates_ = 0;
  std::string cached_candidates_text_;
  void write_candidates(std::uint64_t candidates);
};

}  // namespace extwrench
