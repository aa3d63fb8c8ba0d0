#include "extwrench/io/log.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <set>

#include "extwrench/core/error.hpp"
#include "extwrench/io/nearest_name.hpp"
#include "extwrench/io/number_text.hpp"

namespace extwrench {
namespace {

std::vector<std::string> numbered(const std::string& prefix, int n) {
  std::vector<std::string> out;
  for (int i = 1; i <= n; ++i) out.push_back(prefix + std::to_string(i));
  return out;
}

const char* const kFs[] = {"fs_x", "fs_y", "fs_z"};
const char* const kMs[] = {"ms_x", "ms_y", "ms_z"};
const char* const kTrueF[] = {"true_fx", "true_fy", "true_fz"};
const char* const kTrueM[] = {"true_mx", "true_my", "true_mz"};
const char* const kTrueP[] = {"true_px", "true_py", "true_pz"};

}  // namespace

std::vector<std::string> log_columns(const LogLayout& layout) {
  std::vector<std::string> c{"t"};
  auto append = [&](const std::vector<std::string>& v) { c.insert(c.end(), v.begin(), v.end()); };
  append(numbered("q", layout.n));
  if (layout.velocity) append(numbered("dq", layout.n));
  append(numbered("tau", layout.n));
  if (layout.force) c.insert(c.end(), std::begin(kFs), std::end(kFs));
  if (layout.force && layout.moment) c.insert(c.end(), std::begin(kMs), std::end(kMs));
  if (layout.truth) {
    c.emplace_back("true_link");
    c.insert(c.end(), std::begin(kTrueF), std::end(kTrueF));
    c.insert(c.end(), std::begin(kTrueM), std::end(kTrueM));
    c.insert(c.end(), std::begin(kTrueP), std::end(kTrueP));
  }
  if (layout.true_tau_ext) append(numbered("true_tau_ext", layout.n));
  return c;
}

// ---- reader -------------------------------------------------------------------------------

LogReader::LogReader(const std::filesystem::path& path, const Model& model)
    : csv_(path), model_(&model) {
  const int n = model.nq();
  layout_.n = n;
  std::set<int> known;
  // What a user sees of their own header when a name is missing: a near miss, then the names.
  const auto near_miss = [&](const std::string& name) {
    // Among the names the format does not know (q1 is no typo of q3).
    const std::vector<std::string> known_names =
        log_columns(LogLayout{n, true, true, true, true, true});
    std::vector<std::string> unknown;
    for (const std::string& h : csv_.header()) {
      if (std::find(known_names.begin(), known_names.end(), h) == known_names.end())
        unknown.push_back(h);
    }
    const std::string nearest = nearest_name(name, unknown);
    return nearest.empty() ? std::string() : "; the header has '" + nearest + "'";
  };
  const auto header_list = [&] {
    if (!csv_.separator_hint().empty()) return std::string();  // one long name: the hint says it
    constexpr std::size_t kShown = 16;
    const std::vector<std::string>& h = csv_.header();
    std::string list;
    for (std::size_t i = 0; i < std::min(h.size(), kShown); ++i) list += (i ? ", " : "") + h[i];
    if (h.size() > kShown) list += ", ... (" + std::to_string(h.size()) + " columns)";
    return ". Its header: " + list;
  };
  auto required = [&](const std::string& name) {
    const auto c = csv_.find_column(name);
    if (!c) {
      throw Error(csv_.name() + ":1: missing column '" + name + "'" + near_miss(name) +
                  " (robot '" + model.name + "' has " + std::to_string(n) +
                  " joints: the log needs t, q1..q" + std::to_string(n) + ", tau1..tau" +
                  std::to_string(n) + "; see docs/log_format.md)" + csv_.separator_hint() +
                  header_list());
    }
    known.insert(*c);
    return *c;
  };
  // A group is all-or-nothing: some of its columns without the others is an error.
  auto group = [&](const std::vector<std::string>& names, std::vector<int>& cols) {
    int found = 0;
    for (const auto& name : names) found += csv_.find_column(name).has_value();
    if (found == 0) return false;
    if (found != static_cast<int>(names.size())) {
      for (const auto& name : names) {
        if (!csv_.find_column(name)) {
          throw Error(csv_.name() + ":1: missing column '" + name + "' (the log has " +
                      names.front() + " but not all of " + names.front() + ".." + names.back() +
                      ")");
        }
      }
    }
    for (const auto& name : names) cols.push_back(required(name));
    return true;
  };
  col_t_ = required("t");
  for (const auto& name : numbered("q", n)) col_q_.push_back(required(name));
  for (const auto& name : numbered("tau", n)) col_tau_.push_back(required(name));
  layout_.velocity = group(numbered("dq", n), col_dq_);
  layout_.force = group({kFs[0], kFs[1], kFs[2]}, col_fs_);
  layout_.moment = group({kMs[0], kMs[1], kMs[2]}, col_ms_);
  if (layout_.moment && !layout_.force) {
    throw Error(
        csv_.name() +
        ":1: columns ms_x..ms_z need fs_x..fs_z too (a moment-only base sensor is not supported)");
  }
  const bool f = group({kTrueF[0], kTrueF[1], kTrueF[2]}, col_f_);
  const bool m = group({kTrueM[0], kTrueM[1], kTrueM[2]}, col_m_);
  const bool p = group({kTrueP[0], kTrueP[1], kTrueP[2]}, col_p_);
  const auto link = csv_.find_column("true_link");
  layout_.truth = link.has_value();
  if (layout_.truth) {
    col_link_ = required("true_link");
    if (!f) required("true_fx");  // throws: the force is the least a truth must give
  } else if (f || m || p) {
    required("true_link");  // throws
  }
  layout_.true_tau_ext = group(numbered("true_tau_ext", n), col_tau_ext_);
  for (int c = 0; c < csv_.num_columns(); ++c) {
    if (known.count(c) == 0) ignored_.push_back(csv_.header()[static_cast<std::size_t>(c)]);
  }
  prev_q_.setZero(n);
}

void LogReader::read_vector(const std::vector<int>& columns, VectorX& v) const {
  if (v.size() != static_cast<Eigen::Index>(columns.size()))
    v.resize(static_cast<Eigen::Index>(columns.size()));
  for (std::size_t i = 0; i < columns.size(); ++i)
    v[static_cast<Eigen::Index>(i)] = csv_.number(columns[i]);
}

bool LogReader::read_row(Sample& s) {
  if (!csv_.next_row()) return false;
  s.t = csv_.number(col_t_);
  if (have_prev_ && !(s.t > prev_t_)) {
    throw Error(csv_.where(col_t_) + "time must increase (" + std::string(csv_.cell(col_t_)) +
                " after " + format_number(prev_t_) + " on line " + std::to_string(prev_line_) +
                ")");
  }
  read_vector(col_q_, s.q);
  read_vector(col_tau_, s.tau);
  if (layout_.velocity) read_vector(col_dq_, s.dq);
  s.has_force = layout_.force;
  s.has_moment = layout_.moment;
  for (int k = 0; k < 3 && layout_.force; ++k)
    s.reading_S[k] = csv_.number(col_fs_[static_cast<std::size_t>(k)]);
  for (int k = 0; k < 3; ++k)
    s.reading_S[3 + k] = layout_.moment ? csv_.number(col_ms_[static_cast<std::size_t>(k)]) : 0.0;
  if (!layout_.force) s.reading_S.head<3>().setZero();
  s.has_truth = layout_.truth;
  s.has_true_tau_ext = layout_.true_tau_ext;
  if (layout_.truth) {
    Truth& tr = s.truth;
    const std::string_view link = csv_.cell(col_link_);
    if (link != last_link_) {
      // Resolve names only when they change (a log holds long runs of the same value).
      last_link_.assign(link);
      last_body_ = -1;
      last_contacts_ = 0;
      std::size_t start = 0;
      while (!link.empty() && start <= link.size()) {
        const std::size_t end = std::min(link.find('+', start), link.size());
        const std::string name(link.substr(start, end - start));
        const auto body = model_->find_body(name);
        if (!body) {
          throw Error(csv_.where(col_link_) + "'" + name + "' is not a link of robot '" +
                      model_->name + "'");
        }
        if (last_body_ < 0) last_body_ = *body;
        ++last_contacts_;
        start = end + 1;
      }
    }
    tr.link = last_link_;
    tr.body = last_body_;
    tr.contacts = last_contacts_;
    // Free samples may leave the truth's numbers empty: they read as zero.
    auto vec3 = [&](const std::vector<int>& cols, Vector3& v) {
      for (int k = 0; k < 3; ++k) {
        const double x = cols.empty() ? 0.0 : csv_.number_or_nan(cols[static_cast<std::size_t>(k)]);
        if (std::isinf(x))
          throw Error(csv_.where(cols[static_cast<std::size_t>(k)]) + "expected a finite number");
        if (std::isnan(x) && tr.body >= 0) {
          throw Error(csv_.where(cols[static_cast<std::size_t>(k)]) +
                      "expected a number (true_link is '" + last_link_ + "'), got an empty cell");
        }
        v[k] = std::isnan(x) ? 0.0 : x;
      }
    };
    vec3(col_f_, tr.force_W);
    vec3(col_m_, tr.moment_W);
    vec3(col_p_, tr.point_W);
    // Without true_p* columns the point is unknown, not the world origin: the metrics measured
    // from it (line of action, surface point) are then not evaluated.
    if (col_p_.empty()) tr.point_W.setConstant(std::numeric_limits<double>::quiet_NaN());
  }
  if (layout_.true_tau_ext) read_vector(col_tau_ext_, s.truth.tau_ext);
  return true;
}

bool LogReader::next(Sample& out) {
  if (pending_) {
    out = std::move(*pending_);
    pending_.reset();
    sample_line_ = pending_line_;
  } else {
    if (!read_row(out)) return false;
    sample_line_ = csv_.line();
  }
  if (!layout_.velocity) {
    if (!have_prev_) {
      // First row: forward difference to the next row (zero if there is none).
      Sample next_sample;
      prev_t_ = out.t;  // for the time check of the look-ahead row
      prev_line_ = sample_line_;
      have_prev_ = true;
      if (read_row(next_sample)) {
        out.dq = (next_sample.q - out.q) / (next_sample.t - out.t);
        pending_ = std::move(next_sample);
        pending_line_ = csv_.line();
      } else {
        out.dq.setZero(out.q.size());
      }
      prev_q_ = out.q;
      return true;
    }
    out.dq = (out.q - prev_q_) / (out.t - prev_t_);
  }
  prev_t_ = out.t;
  prev_line_ = sample_line_;
  prev_q_ = out.q;
  have_prev_ = true;
  return true;
}

// ---- writers ------------------------------------------------------------------------------

LogWriter::LogWriter(const std::filesystem::path& path, const LogLayout& layout)
    : layout_(layout), csv_(path, log_columns(layout)) {}

void LogWriter::write(const Sample& s) {
  csv_.add(s.t);
  for (Eigen::Index i = 0; i < layout_.n; ++i) csv_.add(s.q[i]);
  if (layout_.velocity)
    for (Eigen::Index i = 0; i < layout_.n; ++i) csv_.add(s.dq[i]);
  for (Eigen::Index i = 0; i < layout_.n; ++i) csv_.add(s.tau[i]);
  if (layout_.force)
    for (int k = 0; k < 3; ++k) csv_.add(s.reading_S[k]);
  if (layout_.force && layout_.moment)
    for (int k = 3; k < 6; ++k) csv_.add(s.reading_S[k]);
  if (layout_.truth) {
    csv_.add(std::string_view(s.truth.link));
    for (int k = 0; k < 3; ++k) csv_.add(s.truth.force_W[k]);
    for (int k = 0; k < 3; ++k) csv_.add(s.truth.moment_W[k]);
    // The point of a free sample means nothing: left empty.
    for (int k = 0; k < 3; ++k) {
      if (s.truth.body >= 0) {
        csv_.add(s.truth.point_W[k]);
      } else {
        csv_.add_empty();
      }
    }
  }
  if (layout_.true_tau_ext)
    for (Eigen::Index i = 0; i < layout_.n; ++i) csv_.add(s.truth.tau_ext[i]);
  csv_.end_row();
}

namespace {
std::vector<std::string> estimates_columns(int n, bool drift) {
  std::vector<std::string> c{"t",  "contact", "link", "fx", "fy", "fz", "mx",     "my",  "mz",
                             "px", "py",      "pz",   "lx", "ly", "lz", "status", "cond"};
  for (const auto& r : numbered("r", n)) c.push_back(r);
  c.push_back("link_candidates");  // issue 9: appended, so the older columns keep their places
  for (const char* sigma : {"sigma_f", "sigma_m", "sigma_line", "sigma_point"}) c.push_back(sigma);
  if (drift) {  // only with drift tracking on (EstimatorOptions::drift)
    for (const auto& o : numbered("offset", n)) c.push_back(o);
    for (const char* b : {"bias_fx", "bias_fy", "bias_fz", "bias_mx", "bias_my", "bias_mz"})
      c.push_back(b);
  }
  return c;
}
}  // namespace

EstimatesWriter::EstimatesWriter(const std::filesystem::path& path, const Model& model,
                                 bool drift_columns)
    : n_(model.nq()),
      drift_columns_(drift_columns),
      csv_(path, estimates_columns(model.nq(), drift_columns)),
      cached_status_(describe_flags(cached_flags_)) {
  for (const Body& b : model.bodies) body_names_.push_back(b.name);
}

std::string EstimatesWriter::status_text(const ContactEstimate& e) {
  if (!e.status.ok()) {
    std::string s(to_string(e.status.code));
    s += ':';
    s += to_string(e.status.channel);
    if (e.status.index >= 0) {
      // Appended piecewise: GCC 12 -O3 reports a false -Wrestrict on "[" + std::string.
      s += '[';
      s += std::to_string(e.status.index);
      s += ']';
    }
    return s;
  }
  return describe_flags(e.flags);
}

// The other consistent links by name, '|'-separated; empty when there are none.
void EstimatesWriter::write_candidates(std::uint64_t candidates) {
  if (candidates != cached_candidates_) {
    cached_candidates_ = candidates;
    cached_candidates_text_.clear();
    for (std::size_t l = 0; l < body_names_.size() && l < 64; ++l) {
      if ((candidates >> l & 1u) == 0) continue;
      if (!cached_candidates_text_.empty()) cached_candidates_text_ += '|';
      cached_candidates_text_ += body_names_[l];
    }
  }
  csv_.add(std::string_view(cached_candidates_text_));
}

void EstimatesWriter::write(const ContactEstimate& e) {
  csv_.add(e.t);
  csv_.add(e.contact ? 1 : 0);
  const bool named = e.contact && e.link >= 0 && e.link < static_cast<int>(body_names_.size());
  csv_.add(named ? std::string_view(body_names_[static_cast<std::size_t>(e.link)])
                 : std::string_view());
  for (int k = 0; k < 3; ++k) csv_.add(e.force_W[k]);
  for (int k = 0; k < 3; ++k) csv_.add(e.moment_W[k]);
  for (int k = 0; k < 3; ++k) csv_.add(e.point_W[k]);
  for (int k = 0; k < 3; ++k) csv_.add(e.line_point_W[k]);
  if (e.status.ok()) {
    if (e.flags != cached_flags_) {
      cached_flags_ = e.flags;
      cached_status_ = describe_flags(e.flags);
    }
    csv_.add(std::string_view(cached_status_));
  } else {
    csv_.add(std::string_view(status_text(e)));
  }
  csv_.add(e.condition_number);
  for (int i = 0; i < n_; ++i) {
    csv_.add(e.residual.size() == n_ ? e.residual[i] : std::nan(""));
  }
  write_candidates(e.link_candidates);
  csv_.add(e.sigma_force);
  csv_.add(e.sigma_moment);
  csv_.add(e.sigma_line);
  csv_.add(e.sigma_point);
  if (drift_columns_) {
    for (int i = 0; i < n_; ++i)
      csv_.add(e.torque_offset.size() == n_ ? e.torque_offset[i] : std::nan(""));
    for (int k = 0; k < 6; ++k) csv_.add(e.sensor_bias_S[k]);
  }
  csv_.end_row();
}

}  // namespace extwrench
