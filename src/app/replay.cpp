#include "extwrench/app/replay.hpp"

#include <sys/resource.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <cerrno>
#include <chrono>
#include <cmath>
#include <condition_variable>
#include <cstdio>
#include <exception>
#include <fstream>
#include <iostream>
#include <memory>
#include <mutex>
#include <sstream>
#include <thread>

#include "extwrench/app/gnuplot.hpp"
#include "extwrench/core/error.hpp"
#include "extwrench/dynamics/kinematics.hpp"
#include "extwrench/io/log.hpp"

namespace extwrench {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

// ---- the pipeline -------------------------------------------------------------------------
// Three stages on their own threads: a reader parses rows into batches of samples, the calling
// thread runs the estimator, a writer formats and writes the estimates. Batches are allocated
// once and recycled (memory does not grow with the log); hand-offs are per batch, not per row.
constexpr std::size_t kBatches = 4;       // per ring: enough slack for the stages' jitter
constexpr std::size_t kBatchRows = 1024;  // rows per hand-off
// The estimating thread is the critical path: when the threads outnumber the free cores, the
// reader and the writer give way to it. Linux keeps a nice value per thread; theirs is raised
// by kHelperNice over the process's (never lowered; a failure only costs speed).
constexpr int kHelperNice = 5;

void give_way_to_the_estimator() {
  const auto tid = static_cast<id_t>(::gettid());
  errno = 0;
  const int nice = ::getpriority(PRIO_PROCESS, tid);
  if (errno == 0) (void)::setpriority(PRIO_PROCESS, tid, std::min(nice + kHelperNice, 19));
}

/// A bounded ring of batches from one producer thread to one consumer thread, in order.
template <class Item>
class BatchRing {
 public:
  struct Batch {
    std::vector<Item> items;   // kBatchRows slots, reused: their vectors keep their capacity
    std::size_t count = 0;     // items in use
    bool last = false;         // no batch follows (end of input, or the error below)
    std::exception_ptr error;  // the producer's failure, to rethrow after the items
  };

  explicit BatchRing(const Item& prototype) : ring_(kBatches) {
    for (Batch& b : ring_) b.items.assign(kBatchRows, prototype);
  }

  /// Producer: the next batch to fill (emptied), waiting for the consumer to free one;
  /// nullptr once cancelled.
  Batch* acquire_free() {
    std::unique_lock lock(mutex_);
    changed_.wait(lock, [&] { return cancelled_ || produced_ - consumed_ < kBatches; });
    if (cancelled_) return nullptr;
    Batch& b = ring_[produced_ % kBatches];
    b.count = 0;
    b.last = false;
    b.error = nullptr;
    return &b;
  }
  /// Producer: hands the batch acquired last to the consumer.
  void publish() {
    {
      const std::lock_guard lock(mutex_);
      ++produced_;
    }
    changed_.notify_all();
  }
  /// Consumer: the oldest published batch, waiting for one; nullptr once cancelled.
  Batch* acquire_full() {
    std::unique_lock lock(mutex_);
    changed_.wait(lock, [&] { return cancelled_ || consumed_ < produced_; });
    if (cancelled_) return nullptr;
    return &ring_[consumed_ % kBatches];
  }
  /// Consumer: gives the batch acquired last back to the producer.
  void release() {
    {
      const std::lock_guard lock(mutex_);
      ++consumed_;
    }
    changed_.notify_all();
  }
  /// Either side: wakes and stops the other one (it sees nullptr).
  void cancel() {
    {
      const std::lock_guard lock(mutex_);
      cancelled_ = true;
    }
    changed_.notify_all();
  }

 private:
  std::mutex mutex_;
  std::condition_variable changed_;  // produced_, consumed_ or cancelled_ changed
  std::vector<Batch> ring_;
  std::size_t produced_ = 0;
  std::size_t consumed_ = 0;
  bool cancelled_ = false;
};

/// The reader and writer threads around the estimator loop. Rows come out of next() in log
/// order; a malformed row's error comes out after every row before it, as it would from a
/// plain loop. Estimates go in through push(). The destructor (also on an exception) writes
/// every estimate pushed so far, then stops and joins both threads.
class Pipeline {
 public:
  Pipeline(LogReader& reader, EstimatesWriter& writer, const sim::Sample& sample_prototype,
           const ContactEstimate& estimate_prototype)
      : in_(sample_prototype), out_(estimate_prototype) {
    reader_thread_ = std::thread([this, &reader] { read_rows(reader); });
    try {
      writer_thread_ = std::thread([this, &writer] { write_rows(writer); });
    } catch (...) {
      stop_reader();
      throw;
    }
  }
  ~Pipeline() {
    finish_output();
    stop_reader();
  }
  Pipeline(const Pipeline&) = delete;
  Pipeline& operator=(const Pipeline&) = delete;

  /// The next sample, valid until the following call; nullptr at the end of the log. Rethrows
  /// the reader's error (a malformed row) at its place in the sequence.
  const sim::Sample* next() {
    for (;;) {
      if (in_batch_ == nullptr) {
        in_batch_ = in_.acquire_full();  // the reader is only cancelled by our destructor
        in_index_ = 0;
        if (in_batch_ == nullptr) return nullptr;
      }
      if (in_index_ < in_batch_->count) return &in_batch_->items[in_index_++];
      const bool last = in_batch_->last;
      const std::exception_ptr error = in_batch_->error;
      in_.release();
      in_batch_ = nullptr;
      if (error) fail(error);
      if (last) return nullptr;
    }
  }

  /// Queues an estimate for writing (copied: the estimator overwrites its result).
  void push(const ContactEstimate& e) {
    if (out_batch_ == nullptr) {
      out_batch_ = out_.acquire_free();
      if (out_batch_ == nullptr) fail(nullptr);  // the writer failed
    }
    out_batch_->items[out_batch_->count++] = e;
    if (out_batch_->count == kBatchRows) {
      out_.publish();
      out_batch_ = nullptr;
    }
  }

  /// Writes every estimate pushed, then joins the writer; rethrows its error (disk full...).
  void finish() {
    finish_output();
    if (write_error_) std::rethrow_exception(write_error_);
  }

 private:
  void read_rows(LogReader& reader) {
    give_way_to_the_estimator();
    for (;;) {
      auto* b = in_.acquire_free();
      if (b == nullptr) return;  // cancelled: the consumer has stopped
      try {
        while (b->count < kBatchRows) {
          if (!reader.next(b->items[b->count])) {
            b->last = true;
            break;
          }
          ++b->count;
        }
      } catch (...) {
        b->error = std::current_exception();
        b->last = true;
      }
      const bool last = b->last;
      in_.publish();
      if (last) return;
    }
  }

  void write_rows(EstimatesWriter& writer) {
    give_way_to_the_estimator();
    try {
      for (;;) {
        auto* b = out_.acquire_full();
        if (b == nullptr) return;
        for (std::size_t k = 0; k < b->count; ++k) writer.write(b->items[k]);
        const bool last = b->last;
        out_.release();
        if (last) return;
      }
    } catch (...) {
      write_error_ = std::current_exception();  // read by the main thread after join()
      out_.cancel();
    }
  }

  // A failure while estimates are still queued: those rows are written first, and an earlier
  // write failure takes precedence (in a plain loop it would have been thrown first).
  [[noreturn]] void fail(const std::exception_ptr& error) {
    finish_output();
    if (write_error_) std::rethrow_exception(write_error_);
    if (error) std::rethrow_exception(error);
    throw Error("replay: internal error: the writer stopped without an error");
  }

  void finish_output() {
    if (!writer_thread_.joinable()) return;
    if (out_batch_ == nullptr) out_batch_ = out_.acquire_free();  // nullptr if the writer failed
    if (out_batch_ != nullptr) {
      out_batch_->last = true;
      out_.publish();
      out_batch_ = nullptr;
    }
    writer_thread_.join();
  }

  void stop_reader() {
    if (!reader_thread_.joinable()) return;
    in_.cancel();
    reader_thread_.join();
  }

  BatchRing<sim::Sample> in_;
  BatchRing<ContactEstimate> out_;
  typename BatchRing<sim::Sample>::Batch* in_batch_ = nullptr;
  std::size_t in_index_ = 0;
  typename BatchRing<ContactEstimate>::Batch* out_batch_ = nullptr;
  std::exception_ptr write_error_;
  std::thread reader_thread_;
  std::thread writer_thread_;
};

// Columns of the decimated plot buffer.
enum Col : int {
  kT = 0,
  kContact,
  kF = 2,
  kFt = 5,
  kL = 8,
  kDir = 11,
  kP = 14,
  kPt = 17,
  kCond = 20,
  kCondTrue,
  kTrueContact,
  kErrF,
  kQ  // q1..qn follow
};

class Progress {
 public:
  Progress(bool on, std::string name) : on_(on), name_(std::move(name)) {}
  void update(long rows, double t) {
    if (!on_ || (rows & 1023) != 0) return;
    const auto now = std::chrono::steady_clock::now();
    if (now - last_ < std::chrono::milliseconds(250)) return;
    last_ = now;
    std::fprintf(stderr, "\r  %s: replayed %ld rows (t = %.1f s)   ", name_.c_str(), rows, t);
    std::fflush(stderr);
    shown_ = true;
  }
  void done() {
    if (shown_) std::fprintf(stderr, "\r%*s\r", 60, "");
  }

 private:
  bool on_;
  std::string name_;
  std::chrono::steady_clock::time_point last_{};
  bool shown_ = false;
};

std::string title_of(const ReplayOptions& o) {
  return o.name.empty() ? std::string("estimate") : o.name;
}

// Text for gnuplot's enhanced mode: '_' and '^' would start sub- and superscripts.
std::string enhanced(const std::string& text) {
  std::string out;
  for (const char c : text) {
    if (c == '_' || c == '^' || c == '@' || c == '&' || c == '~' || c == '{' || c == '}')
      out += '\\';
    out += c;
  }
  return out;
}

void write_script(const std::filesystem::path& path, const std::string& text) {
  std::ofstream out(path);
  if (!out) throw Error(path.string() + ": cannot create the file");
  out << text;
}

// ---- figures ------------------------------------------------------------------------------

// gnuplot draws on one core and the figures are independent: two at a time. A failure is
// reported for the first failing script in order, as a sequential run would report it.
void run_gnuplot_scripts(const std::vector<std::filesystem::path>& scripts) {
  std::vector<std::exception_ptr> errors(scripts.size());
  std::atomic<std::size_t> next{0};
  auto run_some = [&] {
    for (std::size_t k = next++; k < scripts.size(); k = next++) {
      try {
        run_gnuplot(scripts[k]);
      } catch (...) {
        errors[k] = std::current_exception();
      }
    }
  };
  std::thread helper(run_some);
  run_some();
  helper.join();
  for (const auto& error : errors) {
    if (error) std::rethrow_exception(error);
  }
}

std::vector<std::filesystem::path> make_figures(const Model& model, const Decimator& dec,
                                                const ReplayOptions& o, bool truth,
                                                const Vector3& p_WS) {
  std::vector<std::filesystem::path> pngs;
  std::vector<std::filesystem::path> scripts;  // run together at the end
  const std::filesystem::path dir = o.out_dir;
  const std::filesystem::path data = dir / "plot_data.txt";
  dec.write(data);
  const std::string d = gnuplot_quote(data.filename().string());
  const std::string title = gnuplot_quote(title_of(o));
  const int n = model.nq();
  auto col = [](int c) { return std::to_string(c + 1); };

  {  // Fig. 5: joint positions
    std::ostringstream s;
    s << gnuplot_png_preamble(dir / "joints.png") << "set title "
      << gnuplot_quote("Joint positions — " + enhanced(title_of(o)))
      << "\nset xlabel 't [s]'\nset ylabel 'q_i [rad]'\nplot ";
    for (int i = 0; i < n; ++i) {
      s << (i ? ", " : "") << d << " using 1:" << col(kQ + i) << " with lines lw 2 title 'q_"
        << i + 1 << "'";
    }
    s << "\n";
    write_script(dir / "joints.gp", s.str());
    scripts.push_back(dir / "joints.gp");
    pngs.push_back(dir / "joints.png");
  }
  const char* axis[] = {"x", "y", "z"};
  {  // Figs. 6 / 8: estimated and true force, and the error norm
    std::ostringstream s;
    s << gnuplot_png_preamble(dir / "force.png", 1000, 1000) << "set multiplot layout 4,1 title "
      << gnuplot_quote("External force, world frame — " + enhanced(title_of(o))) << "\n"
      << "set key inside right top horizontal\nset lmargin 10\n";
    for (int k = 0; k < 3; ++k) {
      s << "set ylabel 'F_" << axis[k] << " [N]'\nunset xlabel\nplot " << d
        << " using 1:" << col(kF + k) << " with lines lw 2 lc rgb '#1f77b4' title 'estimated'";
      if (truth)
        s << ", " << d << " using 1:" << col(kFt + k)
          << " with lines lw 2 dt 2 lc rgb '#d62728' title 'true'";
      s << "\n";
    }
    if (truth) {
      s << "set ylabel '|F_{est} - F| [N]'\nset xlabel 't [s]'\nset logscale y\nplot " << d
        << " using 1:" << col(kErrF)
        << " with lines lw 2 lc rgb '#2ca02c' title 'force error'\nunset logscale y\n";
    } else {
      s << "set ylabel 'contact'\nset xlabel 't [s]'\nset yrange [-0.1:1.1]\nplot " << d
        << " using 1:" << col(kContact) << " with steps lw 2 title 'contact detected'\n";
    }
    s << "unset multiplot\n";
    write_script(dir / "force.gp", s.str());
    scripts.push_back(dir / "force.gp");
    pngs.push_back(dir / "force.png");
  }
  {  // Figs. 7 / 9: p̂ of eq. (20) and the true contact point
    std::ostringstream s;
    s << gnuplot_png_preamble(dir / "line_point.png", 1000, 850)
      << "set multiplot layout 3,1 title "
      << gnuplot_quote("Point of the line of action p̂ (eq. 20), world frame — " +
                       enhanced(title_of(o)))
      << "\n"
      << "set key inside right top horizontal\nset lmargin 10\n";
    for (int k = 0; k < 3; ++k) {
      s << "set ylabel 'p_" << axis[k] << " [m]'\n"
        << (k == 2 ? "set xlabel 't [s]'\n" : "unset xlabel\n") << "plot " << d
        << " using 1:" << col(kL + k) << " with lines lw 2 lc rgb '#1f77b4' title 'estimated p̂'";
      if (truth)
        s << ", " << d << " using 1:" << col(kPt + k)
          << " with lines lw 2 dt 2 lc rgb '#d62728' title 'true point'";
      s << "\n";
    }
    s << "unset multiplot\n";
    write_script(dir / "line_point.gp", s.str());
    scripts.push_back(dir / "line_point.gp");
    pngs.push_back(dir / "line_point.png");
  }
  {  // Fig. 10: condition numbers
    std::ostringstream s;
    s << gnuplot_png_preamble(dir / "condition.png", 1000, 600) << "set title "
      << gnuplot_quote("Condition number — " + enhanced(title_of(o)))
      << "\nset xlabel 't [s]'\nset ylabel 'σ_{max} / σ_{min}'\nset logscale y\nset key inside "
         "left top\nplot "
      << d << " using 1:" << col(kCond)
      << " with lines lw 2 lc rgb '#1f77b4' title 'Jacobian inverted by the estimator'";
    if (truth) {
      s << ", " << d << " using 1:" << col(kCondTrue)
        << " with lines lw 2 dt 2 lc rgb '#d62728' title 'J of O_l (world frame, SI), l = true "
           "contact link'";
    }
    s << "\n";
    write_script(dir / "condition.gp", s.str());
    scripts.push_back(dir / "condition.gp");
    pngs.push_back(dir / "condition.png");
  }
  {  // 3-D view at a few instants
    std::vector<int> rows;
    const int available = dec.rows();
    const int count = std::max(1, std::min(o.snapshots, available));
    for (int k = 0; k < count && available > 0; ++k) {
      rows.push_back(
          static_cast<int>((static_cast<long long>(available - 1) * (2 * k + 1)) / (2 * count)));
    }
    Data data(model);
    std::ofstream out(dir / "robot3d.txt");
    // Blocks per snapshot (gnuplot index): 4k skeleton, 4k+1 true point, 4k+2 line, 4k+3 surface
    // point.
    double extent = 0.3;
    for (const int r : rows) {
      const double* row = dec.row(r);
      VectorX q(n);
      for (int i = 0; i < n; ++i) q[i] = row[kQ + i];
      forward_kinematics(model, data, q);
      out << p_WS.x() << " " << p_WS.y() << " " << p_WS.z() << "\n";  // the base sensor
      for (int b = 0; b < model.num_bodies(); ++b) {
        const Vector3& p = data.X_WB[b].translation;
        out << p.x() << " " << p.y() << " " << p.z() << "\n";
        extent = std::max(extent, p.cwiseAbs().maxCoeff());
      }
      out << "\n\n";
      if (truth && row[kTrueContact] > 0.5) {
        out << row[kPt] << " " << row[kPt + 1] << " " << row[kPt + 2] << "\n";
      } else {
        out << "NaN NaN NaN\n";
      }
      out << "\n\n";
      if (std::isfinite(row[kL]) && std::isfinite(row[kDir])) {
        for (const double lambda : {-0.3, 0.3}) {
          out << row[kL] + lambda * row[kDir] << " " << row[kL + 1] + lambda * row[kDir + 1] << " "
              << row[kL + 2] + lambda * row[kDir + 2] << "\n";
        }
      } else {
        out << "NaN NaN NaN\n";
      }
      out << "\n\n";
      if (std::isfinite(row[kP])) {
        out << row[kP] << " " << row[kP + 1] << " " << row[kP + 2] << "\n";
      } else {
        out << "NaN NaN NaN\n";
      }
      out << "\n\n";
    }
    out.close();
    std::ostringstream s;
    const int cols = rows.size() > 1 ? 2 : 1;
    const int lines = static_cast<int>((rows.size() + 1) / 2);
    s << gnuplot_png_preamble(dir / "robot3d.png", 1100, 550 * std::max(1, lines))
      << "set multiplot layout " << std::max(1, lines) << "," << cols << " title "
      << gnuplot_quote("Robot, true contact point and estimated line of action — " +
                       enhanced(title_of(o)))
      << "\n"
      << "set view 62,30,1.2\nset view equal xyz\n"
      << "set xrange [" << -extent << ":" << extent << "]\nset yrange [" << -extent << ":" << extent
      << "]\nset zrange [" << std::min(-0.35, p_WS.z() - 0.05) << ":" << extent + 0.1 << "]\n"
      << "set xlabel 'x [m]'\nset ylabel 'y [m]'\nset zlabel 'z [m]'\nset key at screen 0.99, "
         "screen 0.995 top right samplen 2\n"
      << "set ticslevel 0\n";
    for (std::size_t k = 0; k < rows.size(); ++k) {
      const double t = dec.row(rows[k])[kT];
      char buf[64];
      std::snprintf(buf, sizeof buf, "t = %.2f s", t);
      s << "set title '" << buf << "'\n"
        << "splot 'robot3d.txt' index " << 4 * k
        << " with linespoints lw 4 pt 7 ps 1 lc rgb '#555555' title "
        << (k == 0 ? "'links (sensor, joint frame origins)'" : "''") << ", "
        << "'' index " << 4 * k + 1 << " with points pt 7 ps 2 lc rgb '#d62728' title "
        << (k == 0 ? "'true point'" : "''") << ", "
        << "'' index " << 4 * k + 2 << " with lines lw 3 lc rgb '#1f77b4' title "
        << (k == 0 ? "'estimated line of action'" : "''") << ", "
        << "'' index " << 4 * k + 3 << " with points pt 9 ps 2 lc rgb '#2ca02c' title "
        << (k == 0 ? "'estimated surface point'" : "''") << "\n";
    }
    s << "unset multiplot\n";
    write_script(dir / "robot3d.gp", s.str());
    scripts.push_back(dir / "robot3d.gp");
    pngs.push_back(dir / "robot3d.png");
  }
  run_gnuplot_scripts(scripts);
  return pngs;
}

}  // namespace

ReplayResult replay_log(const Model& model, const GeometryModel& geometry,
                        const EstimatorOptions& estimator_options, const ReplayOptions& o) {
  LogReader reader(o.log, model);
  const LogLayout layout = reader.layout();  // a copy: the reader moves to its thread
  if (o.warn_ignored_columns && !reader.ignored_columns().empty()) {
    std::string list;
    for (const auto& c : reader.ignored_columns()) list += (list.empty() ? "" : ", ") + c;
    std::cerr << "extwrench: note: " << reader.name()
              << ": ignoring columns not in the log format: " << list << "\n";
  }
  const SensorType sensor = estimator_options.sensor.type;
  if (sensor == SensorType::kForceTorque && !(layout.force && layout.moment)) {
    throw Error(reader.name() + ":1: the configuration's sensor.type is 'ft' but the log has no " +
                (layout.force ? "ms_x, ms_y, ms_z" : "fs_x..fs_z, ms_x..ms_z") + " columns");
  }
  if (sensor == SensorType::kForce && !layout.force) {
    throw Error(reader.name() +
                ":1: the configuration's sensor.type is 'force' but the log has no fs_x, fs_y, "
                "fs_z columns");
  }
  std::filesystem::create_directories(o.out_dir);
  auto estimator = std::make_unique<ContactEstimator>(model, geometry, estimator_options);
  const int n = model.nq();
  EstimatesWriter writer(o.out_dir / "estimates.csv", n);

  std::vector<ReplayWindow> windows = o.windows;
  if (windows.empty())
    windows.push_back({"whole_log", "every sample of the log", sim::MetricsWindow{}});
  std::vector<sim::MetricsAccumulator> accumulators;
  for (const auto& w : windows) accumulators.emplace_back(w.window);

  Decimator dec(kQ + n, o.plot_points);
  std::vector<double> plot_row(static_cast<std::size_t>(kQ + n));
  Data plot_data(model);

  Progress progress(o.progress, title_of(o));
  ReplayResult result;
  result.has_truth = layout.truth;
  bool started = false;
  ContactEstimate first;
  first.residual = VectorX::Zero(n);
  double t_begin = kNaN, t_end = kNaN;
  const std::string log_name = reader.name();  // the reader belongs to its thread from here on
  Pipeline pipeline(reader, writer, sim::Sample{}, first);
  while (const sim::Sample* row = pipeline.next()) {
    const sim::Sample& s = *row;
    const ContactEstimate* e = nullptr;
    if (!started) {
      const Status st = estimator->reset(s.t, s.q, s.dq, s.tau);
      first = ContactEstimate{};
      first.t = s.t;
      first.residual = VectorX::Zero(n);
      first.status = st;
      started = st.ok();
      e = &first;
    } else {
      const Status st = sensor == SensorType::kNone
                            ? estimator->update(s.t, s.q, s.dq, s.tau)
                            : estimator->update(s.t, s.q, s.dq, s.tau, s.sensor);
      (void)st;  // reported in the status column
      e = &estimator->result();
    }
    pipeline.push(*e);
    if (std::isnan(t_begin)) t_begin = s.t;
    t_end = s.t;
    ++result.rows;
    if (layout.truth) {
      for (auto& acc : accumulators) acc.add(s.t, s.truth, *e);
    }
    if (o.figures) {
      if (dec.wants_next()) {
        double* r = plot_row.data();
        r[kT] = s.t;
        r[kContact] = e->contact ? 1.0 : 0.0;
        for (int k = 0; k < 3; ++k) {
          r[kF + k] = e->contact ? e->force_W[k] : kNaN;
          r[kL + k] = e->contact ? e->line_point_W[k] : kNaN;
          r[kDir + k] = e->contact ? e->line_direction_W[k] : kNaN;
          r[kP + k] = e->contact ? e->point_W[k] : kNaN;
          const bool touched = layout.truth && s.truth.body >= 0;
          r[kFt + k] = layout.truth ? (touched ? s.truth.force[k] : 0.0) : kNaN;
          r[kPt + k] = touched ? s.truth.point[k] : kNaN;
        }
        r[kCond] = e->condition_number;
        r[kTrueContact] = layout.truth && s.truth.body >= 0 ? 1.0 : 0.0;
        r[kCondTrue] = kNaN;
        if (layout.truth && s.truth.body > 0) {
          forward_kinematics(model, plot_data, s.q);
          r[kCondTrue] = jacobian_condition(model, plot_data, s.truth.body);
        }
        r[kErrF] = kNaN;
        if (layout.truth) {
          const Vector3 f_true = s.truth.body >= 0 ? s.truth.force : Vector3::Zero();
          const Vector3 f_est =
              e->contact && e->has(EstimateFlag::kForce) ? e->force_W : Vector3::Zero();
          r[kErrF] = (f_est - f_true).norm();
        }
        for (int i = 0; i < n; ++i) r[kQ + i] = s.q[i];
        dec.push(r);
      } else {
        dec.skip();
      }
    }
    progress.update(result.rows, s.t);
  }
  progress.done();
  pipeline.finish();
  writer.close();
  if (result.rows == 0) throw Error(log_name + ": the log has a header but no rows");

  MetricsReport& report = result.report;
  report.scheme = title_of(o);
  report.log = o.log.string();
  report.config = o.config_label;
  report.rows = result.rows;
  report.t_begin = t_begin;
  report.t_end = t_end;
  report.surface_metrics = o.surface_metrics;
  if (layout.truth) {
    for (std::size_t i = 0; i < windows.size(); ++i) {
      report.windows.push_back({windows[i].name, windows[i].description, accumulators[i].result()});
    }
    write_metrics_json(o.out_dir / "metrics.json", report);
  }
  if (o.figures)
    result.figures =
        make_figures(model, dec, o, layout.truth, estimator_options.sensor.pose.translation);
  return result;
}

}  // namespace extwrench
