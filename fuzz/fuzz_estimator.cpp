// libFuzzer harness: the real-time ContactEstimator::update fed a sequence of samples decoded
// from the fuzz bytes (docs/testing.md "Fuzzing"). Each sample may carry NaN, ±Inf, denormals,
// huge values or raw bit patterns, a time that does not increase, vectors of the wrong size, or
// no base reading for a sensor that needs one; the estimator's configuration (sensor type, route,
// contact model, tare) comes from the first byte. Checked, with an oracle written here and not
// taken from the estimator:
//   - update() never throws (it is noexcept: an exception would terminate, a finding);
//   - a sample with a defect gets an input-error Status naming a channel and index that really is
//     at fault, result() carries that Status and the sample's time, and no estimate;
//   - a sample without a defect is accepted;
//   - bit-identical recovery: after every accepted sample, the estimator's outputs equal bit for
//     bit those of a twin that was given the accepted samples only.
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <limits>
#include <optional>

#include "extwrench/core/error.hpp"
#include "extwrench/core/input_checks.hpp"
#include "extwrench/core/time_step.hpp"
#include "extwrench/estimation/contact_estimator.hpp"
#include "extwrench/io/robot_loader.hpp"

namespace {

using namespace extwrench;

// Bytes consumed front to back; zeros once exhausted (so every input decodes to something).
class ByteReader {
 public:
  ByteReader(const std::uint8_t* data, std::size_t size) : data_(data), size_(size) {}
  [[nodiscard]] bool empty() const { return pos_ >= size_; }
  std::uint8_t byte() { return pos_ < size_ ? data_[pos_++] : 0; }
  double raw_double() {
    std::uint64_t bits = 0;
    for (int i = 0; i < 8; ++i) bits = (bits << 8) | byte();
    double d;
    std::memcpy(&d, &bits, sizeof d);
    return d;
  }
  // The values that break arithmetic: NaN, infinities, denormals, the extremes, signed zero.
  double special() {
    constexpr double kSpecial[] = {std::numeric_limits<double>::quiet_NaN(),
                                   std::numeric_limits<double>::infinity(),
                                   -std::numeric_limits<double>::infinity(),
                                   std::numeric_limits<double>::denorm_min(),
                                   -std::numeric_limits<double>::denorm_min(),
                                   std::numeric_limits<double>::min() / 3.0,
                                   std::numeric_limits<double>::max(),
                                   -std::numeric_limits<double>::max(),
                                   1e300,
                                   -1e200,
                                   1e-300,
                                   -0.0,
                                   std::numeric_limits<double>::signaling_NaN(),
                                   std::numeric_limits<double>::epsilon()};
    const std::uint8_t k = byte();
    if (k >= sizeof kSpecial / sizeof kSpecial[0]) return raw_double();
    return kSpecial[k];
  }

 private:
  const std::uint8_t* data_;
  std::size_t size_;
  std::size_t pos_ = 0;
};

const RobotDescription& robot() {
  static const RobotDescription r = [] {
    LoadOptions options;
    options.use_ros_package_path = false;
    return load_robot(EXTWRENCH_SOURCE_DIR "/models/paper_arm.urdf", options);
  }();
  return r;
}

// Sensor type, acceleration route, contact model and tare from one byte. The sensor frame is the
// root frame and the known point the link's origin (the defaults).
std::optional<ContactEstimator> make_estimator(std::uint8_t config) {
  const Model& model = robot().model;
  EstimatorOptions o;
  constexpr SensorType kTypes[] = {SensorType::kNone, SensorType::kForce, SensorType::kForceTorque,
                                   SensorType::kForceTorque};
  o.sensor.type = kTypes[config & 3];
  o.sensor.tare_samples = (config & 0x10) != 0 ? 3 : 0;
  if ((config & 4) != 0) o.acceleration = AccelerationRoute::kDifferentiation;
  if ((config & 8) != 0) {
    o.contact.model = ContactModel::kKnownPoint;
    o.contact.link = model.nq() - 1;
  }
  if ((config & 0x20) != 0) o.observer_gain = VectorX::Constant(model.nq(), 25.0);
  try {
    return ContactEstimator(model, robot().geometry, o);
  } catch (const Error&) {
    return std::nullopt;  // a combination validate() refuses: not the update under test
  }
}

enum class ReadingMode { kGiven, kOmitted, kSampleWithout };

// One decoded sample and what the oracle expects of it.
struct Decoded {
  double t = 0.0;
  VectorX q, dq, tau;
  Vector6 reading_S = Vector6::Zero();
  ReadingMode mode = ReadingMode::kGiven;
};

double time_of(ByteReader& in, std::uint8_t kind, double t_last, double dt) {
  switch (kind & 7) {
    case 4:
      return t_last;  // repeated time stamp
    case 5:
      return t_last - dt * (1 + (in.byte() & 3));  // going back
    case 6:
      return in.special();
    case 7:
      return in.raw_double();
    default:
      return t_last + dt * (1 + (kind & 3));
  }
}

// Plausible motion of step k (a different sinusoid per joint), scaled.
void smooth(Decoded& s, int n, long k, double scale) {
  s.q.resize(n);
  s.dq.resize(n);
  s.tau.resize(n);
  for (int i = 0; i < n; ++i) {
    const double w = 0.5 + 0.3 * i, phase = 0.001 * static_cast<double>(k) * w;
    s.q[i] = scale * 0.6 * std::sin(phase + i);
    s.dq[i] = scale * 0.6 * w * std::cos(phase + i);
    s.tau[i] = scale * (3.0 - 0.4 * i) * std::cos(phase);
  }
  s.reading_S << 1.0, -2.0, -40.0 * scale, 0.5, 0.2, -0.1;
}

VectorX& channel_vector(Decoded& s, std::uint8_t c) {
  switch (c % 3) {
    case 0:
      return s.q;
    case 1:
      return s.dq;
    default:
      return s.tau;
  }
}

Decoded decode_sample(ByteReader& in, int n, long k, double t_last) {
  const std::uint8_t control = in.byte();
  Decoded s;
  s.t = time_of(in, control, t_last, 1e-3);
  switch ((control >> 3) & 3) {
    case 0:
      smooth(s, n, k, 1.0);
      break;
    case 1: {  // one special value in one entry of one channel
      smooth(s, n, k, 1.0);
      const std::uint8_t c = in.byte();
      if (c % 4 == 3) {
        s.reading_S[in.byte() % 6] = in.special();
      } else {
        VectorX& v = channel_vector(s, c);
        v[in.byte() % n] = in.special();
      }
      break;
    }
    case 2:  // every entry a raw bit pattern
      smooth(s, n, k, 1.0);
      for (VectorX* v : {&s.q, &s.dq, &s.tau})
        for (int i = 0; i < n; ++i) (*v)[i] = in.raw_double();
      for (int i = 0; i < 6; ++i) s.reading_S[i] = in.raw_double();
      break;
    default:  // finite but extreme: the motion scaled by a special value (finite or not)
      smooth(s, n, k, in.special());
      break;
  }
  if ((control & 0x20) != 0) {  // wrong size: 0..n+2 entries, contents kept where they fit
    const std::uint8_t c = in.byte();
    VectorX& v = channel_vector(s, c);
    const int size = (c >> 2) % (n + 3);
    v.conservativeResize(size);
    if (size > n) v.tail(size - n).setZero();
  }
  s.mode = static_cast<ReadingMode>(((control >> 6) & 3) % 3);
  return s;
}

[[noreturn]] void finding(const char* what) {
  std::fprintf(stderr, "fuzz_estimator: %s\n", what);
  std::abort();
}

Status feed(ContactEstimator& e, const Decoded& s) {
  switch (s.mode) {
    case ReadingMode::kGiven:
      return e.update(s.t, s.q, s.dq, s.tau, s.reading_S);
    case ReadingMode::kOmitted:
      return e.update(s.t, s.q, s.dq, s.tau);
    case ReadingMode::kSampleWithout:
      break;
  }
  Sample sample;  // no has_force / has_moment: no base reading
  sample.t = s.t;
  sample.q = s.q;
  sample.dq = s.dq;
  sample.tau = s.tau;
  return e.update(sample);
}

bool is_input_error(StatusCode c) {
  return c == StatusCode::kWrongSize || c == StatusCode::kNonFinite ||
         c == StatusCode::kNonIncreasingTime || c == StatusCode::kNotInitialized;
}

// The oracle: what the estimator must refuse (docs/estimator.md "Input errors").
bool has_defect(const ContactEstimator& e, const Decoded& s, double t_last) {
  const int n = e.model().nq();
  const SensorType type = e.options().sensor.type;
  if (type != SensorType::kNone && s.mode != ReadingMode::kGiven) return true;
  if (!usable_time(s.t) || !(s.t - t_last >= kShortestTimeStep)) return true;
  for (const VectorX* v : {&s.q, &s.dq, &s.tau}) {
    if (v->size() != n) return true;
    for (Eigen::Index i = 0; i < n; ++i)
      if (!usable_input((*v)[i])) return true;
  }
  for (int i = 0; i < reading_size(type); ++i)
    if (!usable_input(s.reading_S[i])) return true;
  return false;
}

// The channel and index a rejection names are really at fault.
bool blame_is_right(const ContactEstimator& e, const Decoded& s, Status status, double t_last) {
  const int n = e.model().nq();
  const VectorX* v = status.channel == Channel::kPosition   ? &s.q
                     : status.channel == Channel::kVelocity ? &s.dq
                     : status.channel == Channel::kTorque   ? &s.tau
                                                            : nullptr;
  switch (status.code) {
    case StatusCode::kNonIncreasingTime:
      return status.channel == Channel::kTime && !(s.t - t_last >= kShortestTimeStep);
    case StatusCode::kWrongSize:
      if (status.channel == Channel::kBaseWrench) return s.mode != ReadingMode::kGiven;
      return v != nullptr && v->size() != n;
    case StatusCode::kNonFinite:
      if (status.channel == Channel::kTime) return !usable_time(s.t);
      if (status.channel == Channel::kBaseWrench)
        return status.index >= 0 && status.index < 6 && !usable_input(s.reading_S[status.index]);
      return v != nullptr && status.index >= 0 && status.index < v->size() &&
             !usable_input((*v)[status.index]);
    default:
      return false;
  }
}

bool same_bits(double a, double b) { return std::memcmp(&a, &b, sizeof a) == 0; }

template <typename Derived>
bool same_bits(const Eigen::MatrixBase<Derived>& a, const Eigen::MatrixBase<Derived>& b) {
  if (a.size() != b.size()) return false;
  for (Eigen::Index i = 0; i < a.size(); ++i)
    if (!same_bits(a.derived().data()[i], b.derived().data()[i])) return false;
  return true;
}

// A rejected sample's result: every number NaN; the declaration in force kept (contact and its
// link, the flag `contact` alone), or none.
bool all_nan(const ContactEstimate& out) {
  return out.force_W.array().isNaN().all() && out.moment_W.array().isNaN().all() &&
         out.point_W.array().isNaN().all() && out.residual.array().isNaN().all() &&
         out.flags == (out.contact ? EstimateFlag::kContact : 0u) &&
         (out.contact || out.link == -1);
}

void check_rejection(const ContactEstimator& e, const Decoded& s, Status status, double t_last) {
  if (!is_input_error(status.code)) finding("a sample with a defect was accepted");
  if (!blame_is_right(e, s, status, t_last)) finding("the Status blames a channel not at fault");
  const ContactEstimate& out = e.result();
  if (out.status.code != status.code || out.status.channel != status.channel ||
      out.status.index != status.index)
    finding("result().status differs from the Status returned");
  if (!same_bits(out.t, s.t)) finding("a rejected sample's result() has another time");
  if (!all_nan(out)) finding("a rejected sample left an estimate");
}

bool same_outputs(const ContactEstimate& a, const ContactEstimate& b) {
  return same_bits(a.t, b.t) && a.contact == b.contact && a.link == b.link &&
         same_bits(a.force_W, b.force_W) && same_bits(a.moment_W, b.moment_W) &&
         same_bits(a.point_W, b.point_W) && same_bits(a.point_L, b.point_L) &&
         same_bits(a.line_point_W, b.line_point_W) &&
         same_bits(a.line_direction_W, b.line_direction_W) &&
         same_bits(a.surface_distance, b.surface_distance) && same_bits(a.residual, b.residual) &&
         same_bits(a.condition_number, b.condition_number) && a.status.code == b.status.code &&
         a.flags == b.flags;
}

void check_same_outputs(const ContactEstimator& e, const ContactEstimator& twin) {
  if (!same_outputs(e.result(), twin.result()))
    finding("outputs differ from the twin's that never saw the rejected samples");
  if (!same_bits(e.acceleration(), twin.acceleration()))
    finding("acceleration differs from the twin's");
  if (!same_bits(e.sensor_bias(), twin.sensor_bias()))
    finding("sensor bias differs from the twin's");
}
}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  ByteReader in(data, size);
  std::optional<ContactEstimator> estimator = make_estimator(in.byte());
  if (!estimator) return 0;
  const int n = estimator->model().nq();
  Decoded first;
  smooth(first, n, 0, 1.0);
  if (!estimator->reset(first.t, first.q, first.dq, first.tau).ok()) finding("reset refused");
  ContactEstimator twin = *estimator;  // sees the accepted samples only
  double t_last = first.t;
  for (long k = 1; k <= 512 && !in.empty(); ++k) {
    const Decoded s = decode_sample(in, n, k, t_last);
    const bool defect = has_defect(*estimator, s, t_last);
    const Status status = feed(*estimator, s);
    if (defect) {
      check_rejection(*estimator, s, status, t_last);
      continue;
    }
    if (is_input_error(status.code)) finding("a sample without a defect was rejected");
    (void)feed(twin, s);
    t_last = s.t;
    check_same_outputs(*estimator, twin);
  }
  return 0;
}
