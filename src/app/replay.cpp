#include "extwrench/app/replay.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <iostream>
#include <limits>
#include <optional>
#include <utility>
#include <vector>

#include "extwrench/app/joint_range.hpp"
#include "extwrench/core/error.hpp"
#include "extwrench/io/log.hpp"
#include "figures.hpp"
#include "log_columns.hpp"
#include "pipeline.hpp"
#include "progress.hpp"

namespace extwrench {
namespace {

std::string title_of(const ReplayOptions& o) {
  return o.name.empty() ? std::string("estimate") : o.name;
}

std::ostream& messages_of(const ReplayOptions& o) {
  return o.messages != nullptr ? *o.messages : std::cerr;
}

void note_ignored_columns(const LogReader& reader, std::ostream& messages) {
  if (reader.ignored_columns().empty()) return;
  // The first few names say enough; a log of 10 000 stray columns must not print them all.
  constexpr std::size_t kShown = 10;
  const auto& ignored = reader.ignored_columns();
  std::string list;
  for (std::size_t i = 0; i < std::min(ignored.size(), kShown); ++i)
    list += (list.empty() ? "" : ", ") + ignored[i];
  if (ignored.size() > kShown) list += " and " + std::to_string(ignored.size() - kShown) + " more";
  messages << "extwrench: note: " << reader.name()
           << ": ignoring columns not in the log format: " << list << "\n";
}

/// The estimate of each row. The first row (and each next one while the reset fails) resets the
/// estimator: its estimate is "free" with a zero residual.
class RowEstimator {
 public:
  RowEstimator(ContactEstimator estimator, int n) : estimator_(std::move(estimator)), n_(n) {
    first_.residual = VectorX::Zero(n);
    first_.torque_offset = estimator_.result().torque_offset;  // the configured offsets, or none
  }
  /// What every estimate looks like (sizes), for the pipeline's buffers.
  [[nodiscard]] const ContactEstimate& prototype() const { return first_; }
  /// The detector of the last update (its thresholds in force).
  [[nodiscard]] const ContactDetector& detector() const { return estimator_.detector(); }

  const ContactEstimate& update(const Sample& s) {
    if (started_) {
      (void)estimator_.update(s);  // the status is in the estimate's status column
      return estimator_.result();
    }
    const Status st = estimator_.reset(s);
    VectorX offset = std::move(first_.torque_offset);
    first_ = ContactEstimate{};
    first_.t = s.t;
    first_.residual = VectorX::Zero(n_);
    first_.torque_offset = std::move(offset);
    first_.status = st;
    started_ = st.ok();
    return first_;
  }

 private:
  ContactEstimator estimator_;
  int n_;
  bool started_ = false;
  ContactEstimate first_;
};

/// The metrics of every window (one over the whole log when none is given).
class WindowMetrics {
 public:
  explicit WindowMetrics(std::vector<ReplayWindow> windows) : windows_(std::move(windows)) {
    if (windows_.empty())
      windows_.push_back({"whole_log", "every sample of the log", sim::MetricsWindow{}});
    for (const auto& w : windows_) accumulators_.emplace_back(w.window);
  }
  void add(const Sample& s, const ContactEstimate& e) {
    for (auto& acc : accumulators_) acc.add(s.t, s.truth, e);
  }
  [[nodiscard]] std::vector<NamedMetrics> result() const {
    std::vector<NamedMetrics> out;
    for (std::size_t i = 0; i < windows_.size(); ++i)
      out.push_back({windows_[i].name, windows_[i].description, accumulators_[i].result()});
    return out;
  }

 private:
  std::vector<ReplayWindow> windows_;
  std::vector<sim::MetricsAccumulator> accumulators_;
};

// The report's header; the rows and time span are the tally's (every replayed estimate).
MetricsReport report_of(const ReplayOptions& o, const ContactTally& tally) {
  MetricsReport report;
  report.scheme = title_of(o);
  report.log = o.log.string();
  report.config = o.config_label;
  report.rows = tally.rows;
  report.t_begin = tally.t_begin;
  report.t_end = tally.t_end;
  report.surface_metrics = o.surface_metrics;
  return report;
}

// The figures, whose failure is a warning: the estimates and metrics are written and stand.
void draw_figures(const detail::FigureRecorder& figures, const Model& model,
                  const GeometryModel& geometry, const EstimatorOptions& e, const ReplayOptions& o,
                  OutputFiles& outputs, ReplayResult& result) {
  (void)model;
  detail::FigureOptions fo;
  fo.dir = o.out_dir;
  fo.title = title_of(o);
  fo.snapshots = o.snapshots;
  fo.p_WS = e.sensor.X_WS.translation;
  fo.max_condition = e.solver.max_condition;
  fo.format = o.figure_format;
  fo.geometry = &geometry;
  try {
    detail::DrawnFigures drawn = figures.draw(fo, outputs);
    result.figures = std::move(drawn.files);
    result.figure_failures = std::move(drawn.failures);
  } catch (const std::exception& x) {
    result.figure_failures.push_back(std::string("figures: ") + x.what());
  }
  for (const std::string& failure : result.figure_failures) {
    messages_of(o) << "extwrench: warning: " << fo.title
                   << ": figure not drawn (the estimates stand): " << failure << "\n";
  }
}

}  // namespace

ReplayResult replay_log(const Model& model, const GeometryModel& geometry,
                        const EstimatorOptions& estimator_options, const ReplayOptions& o) {
  LogReader reader(o.log, model);
  const LogLayout layout = reader.layout();  // a copy: the reader moves to its thread
  detail::check_joint_columns(reader, model.nq(), o.ignore_extra_joint_columns);
  if (o.warn_ignored_columns) note_ignored_columns(reader, messages_of(o));
  detail::check_sensor_columns(reader, estimator_options.sensor.type);
  OutputFiles own_outputs;
  OutputFiles& outputs = o.outputs != nullptr ? *o.outputs : own_outputs;
  outputs.create_directories(o.out_dir);
  RowEstimator estimator(ContactEstimator(model, geometry, estimator_options), model.nq());
  const std::filesystem::path estimates = o.out_dir / "estimates.csv";
  EstimatesWriter writer(outputs.stage(estimates), model, estimator_options.drift.has_value());
  WindowMetrics metrics(o.windows);
  std::optional<detail::FigureRecorder> figures;
  if (o.figures) {
    figures.emplace(model, layout.truth, estimator_options.sensor.type != SensorType::kNone,
                    o.plot_points, o.desired_trajectory);
  }
  const std::string title = title_of(o);
  detail::ProgressLine progress(o.progress, 1024, std::chrono::milliseconds(250));
  ContactTally contacts(model.num_bodies());
  JointRangeCheck joint_range(model);
  const std::string log_name = reader.name();  // the reader belongs to its thread from here on
  // cond(J) of the true link, for the figures, on the reader's thread when there is one.
  detail::RowHook true_condition;
  if (figures && layout.truth) true_condition = figures->true_condition();
  detail::Pipeline pipeline(reader, writer, Sample{}, estimator.prototype(), o.pipelined,
                            std::move(true_condition));
  while (const detail::PipelineRow* row = pipeline.next()) {
    const Sample& s = row->sample;
    const ContactEstimate& e = estimator.update(s);
    pipeline.push(e);
    contacts.add(s.t, e.contact, e.link, e.has(EstimateFlag::kDisagreement));
    joint_range.add(s);
    if (layout.truth) metrics.add(s, e);
    if (figures) figures->add(s, e, estimator.detector(), row->derived);
    progress.update(contacts.rows, "%s: replayed %ld rows (t = %.1f s)", title.c_str(),
                    contacts.rows, s.t);
  }
  progress.done();
  pipeline.finish();
  writer.close();
  if (contacts.rows == 0) throw Error(log_name + ": the log has a header but no rows");
  outputs.commit(estimates);

  ReplayResult result;
  result.rows = contacts.rows;
  result.has_truth = layout.truth;
  result.report = report_of(o, contacts);
  result.contacts = std::move(contacts);
  if (layout.truth) {
    result.report.windows = metrics.result();
    const std::filesystem::path json = o.out_dir / "metrics.json";
    write_metrics_json(outputs.stage(json), result.report);
    outputs.commit(json);
  } else if (std::error_code ec; std::filesystem::is_regular_file(o.out_dir / "metrics.json", ec)) {
    // An earlier run's, beside this run's estimates it would be read as theirs.
    std::filesystem::remove(o.out_dir / "metrics.json", ec);
    messages_of(o) << "extwrench: note: " << title << ": removed "
                   << (o.out_dir / "metrics.json").string()
                   << " of an earlier run (this log has no truth columns, so no metrics)\n";
  }
  if (o.figures) draw_figures(*figures, model, geometry, estimator_options, o, outputs, result);
  if (o.warn_disagreement) {
    const std::string warning = disagreement_warning(result.contacts);
    if (!warning.empty())
      messages_of(o) << "extwrench: warning: " << title << ": " << warning << "\n";
    const std::string base = base_contact_warning(result.contacts, model);
    if (!base.empty()) messages_of(o) << "extwrench: warning: " << title << ": " << base << "\n";
  }
  if (o.note_frequent_alarms && !result.has_truth) {
    const std::string note = frequent_alarms_note(result.contacts);
    if (!note.empty()) messages_of(o) << "extwrench: note: " << title << ": " << note << "\n";
  }
  if (const std::string note = time_step_note(result.contacts); !note.empty())
    messages_of(o) << "extwrench: note: " << title << ": " << note << "\n";
  if (const std::string note = time_gap_note(result.contacts); !note.empty())
    messages_of(o) << "extwrench: note: " << title << ": " << note << "\n";
  if (const std::string range = joint_range.note(); o.warn_joint_range && !range.empty())
    messages_of(o) << "extwrench: warning: " << title << ": " << range << "\n";
  own_outputs.keep();
  return result;
}

}  // namespace extwrench
