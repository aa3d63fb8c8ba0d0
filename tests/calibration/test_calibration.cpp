// Calibration (src/calibration/, io/calibration_file): the friction model against its published
// form, the least squares against the observer it stands for, bad logs, the calibration file
// through an estimator configuration, and the calibrated estimator's real-time contract.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>

#include "calibration_sim.hpp"
#include "extwrench/calibration/calibration.hpp"
#include "extwrench/core/error.hpp"
#include "extwrench/estimation/contact_estimator.hpp"
#include "extwrench/io/calibration_file.hpp"
#include "extwrench/io/estimator_config.hpp"
#include "extwrench/io/log.hpp"
#include "support/alloc_counter.hpp"
#include "support/random.hpp"

namespace extwrench {
namespace {

namespace fs = std::filesystem;

EstimatorOptions no_sensor() {
  EstimatorOptions o;
  o.observer_gain = VectorX::Constant(1, 50.0);
  return o;
}

std::vector<Sample> free_log(double seconds, std::vector<sim::ForceProfile> forces = {},
                             const sim::SinusoidalTrajectory& trajectory = test::free_motion(0.0,
                                                                                             1.0)) {
  return test::simulate_free_motion(paper_arm(), trajectory, test::paper_arm_friction(), seconds,
                                    Vector6::Zero(), 0.02, 5, std::move(forces));
}

// `cal` written to DIR/calib.yaml (DIR a temporary directory) and included by a configuration of
// the paper arm without a sensor, K = 50, DIR/config.yaml.
EstimatorConfig config_including(const Calibration& cal, const char* dir_name) {
  const fs::path dir = fs::temp_directory_path() / dir_name;
  fs::create_directories(dir);
  std::ofstream(dir / "calib.yaml") << calibration_to_yaml(cal, nullptr);
  const std::string robot = (fs::path(EXTWRENCH_SOURCE_DIR) / "models/paper_arm.urdf").string();
  return load_estimator_config_string(
      "robot: " + robot + "\nsensor: {type: none}\nobserver: {gain: 50}\ncalibration: calib.yaml\n",
      dir / "config.yaml");
}

// The residual of a MomentumObserver (K = 50) run over `log` with the calibrated friction, over
// the samples the calibration used (after its settle time, 5 / K), per joint: its RMS, its largest
// magnitude and when that came.
struct ObserverResidual {
  VectorX rms, peak, peak_t;
};
ObserverResidual observer_after_settling(const Model& model, const Calibration& cal,
                                         const std::vector<Sample>& log) {
  Data data(model);
  MomentumObserver observer(model, 50.0);
  observer.set_friction(cal.friction);
  EXPECT_TRUE(observer.reset(model, data, log[0].t, log[0].q, log[0].dq, log[0].tau).ok());
  const int n = model.nq();
  VectorX sum2 = VectorX::Zero(n);
  ObserverResidual out{
      .rms = VectorX::Zero(n), .peak = VectorX::Zero(n), .peak_t = VectorX::Zero(n)};
  int count = 0;
  for (std::size_t k = 1; k < log.size(); ++k) {
    EXPECT_TRUE(observer.update(model, data, log[k].t, log[k].q, log[k].dq, log[k].tau).ok());
    EXPECT_LE(observer.presliding_state().cwiseAbs().maxCoeff(), 1.0);
    if (log[k].t < 5.0 / 50.0 - 1e-9) continue;
    sum2 += observer.residual().cwiseAbs2();
    for (int i = 0; i < n; ++i) {
      if (std::abs(observer.residual()[i]) > out.peak[i]) {
        out.peak[i] = std::abs(observer.residual()[i]);
        out.peak_t[i] = log[k].t;
      }
    }
    ++count;
  }
  EXPECT_EQ(count, cal.samples_used);
  out.rms = (sum2 / std::max(count, 1)).cwiseSqrt();
  return out;
}

// Gaz et al. (2019): τ_f = A / (1 + e^{−α (q̇ + φ)}) − A / (1 + e^{−α φ}), here with A = 2 F_c
// and α = 2 / v_s.
TEST(FrictionModel, SigmoidIsTheFamilyOfGazEtAl) {
  const double A = 0.872, alpha = 9.07, phi = 0.0259;
  JointFriction f = JointFriction::none(1);
  f.sign = SmoothSign::kSigmoid;
  f.coulomb[0] = A / 2;
  f.joint_smoothing = VectorX::Constant(1, 2.0 / alpha);
  f.velocity_shift = VectorX::Constant(1, phi);
  for (const double dq : {-1.0, -0.1, -0.01, 0.0, 0.003, 0.05, 0.7}) {
    const double gaz = A / (1 + std::exp(-alpha * (dq + phi))) - A / (1 + std::exp(-alpha * phi));
    VectorX out(1);
    friction_torque(f, VectorX::Constant(1, dq), out);
    EXPECT_NEAR(out[0], gaz, 1e-12) << "dq = " << dq;
  }
}

TEST(FrictionModel, OffsetAndTanhAddUp) {
  JointFriction f = JointFriction::none(2);
  f.sign = SmoothSign::kTanh;
  f.viscous << 0.5, 0.0;
  f.coulomb << 1.0, 2.0;
  f.offset = Eigen::Vector2d(0.1, -0.3);
  f.joint_smoothing = Eigen::Vector2d(0.02, 0.05);
  VectorX out(2);
  friction_torque(f, Eigen::Vector2d(0.04, -0.1), out);
  EXPECT_NEAR(out[0], 0.5 * 0.04 + std::tanh(2.0) + 0.1, 1e-14);
  EXPECT_NEAR(out[1], 2.0 * std::tanh(-2.0) - 0.3, 1e-14);
  EXPECT_FALSE(f.is_zero());
}

// The Dahl sign's state against the solution of its equation dz/dq = (sign(Δq) − z) / δ for a
// motion of one direction, z = s + (z₀ − s) e^{−|q − q₀|/δ}: exact whatever the steps (one
// displacement or a thousand), and after a reversal it needs about δ ln 2 to cross zero.
TEST(FrictionModel, DahlStateIsTheSolutionOfItsEquationAtAnyStep) {
  const double delta = 0.004;
  double one_step = dahl_step(0.0, 0.01, delta), many = 0.0;
  for (int k = 0; k < 1000; ++k) many = dahl_step(many, 1e-5, delta);
  EXPECT_NEAR(one_step, 1.0 - std::exp(-0.01 / delta), 1e-15);
  EXPECT_NEAR(many, 1.0 - std::exp(-0.01 / delta), 1e-13);
  // A reversal from the steady state: -1 + 2 e^{-d/δ}, zero at d = δ ln 2.
  EXPECT_NEAR(dahl_step(1.0, -0.003, delta), -1.0 + 2.0 * std::exp(-0.003 / delta), 1e-15);
  EXPECT_NEAR(dahl_step(1.0, -delta * std::log(2.0), delta), 0.0, 1e-15);
  EXPECT_EQ(dahl_step(0.37, 0.0, delta), 0.37);  // at rest the state holds
  EXPECT_EQ(test::dahl_euler(0.37, 0.0, delta), 0.37);
  // The explicit Euler integration of the test's simulator agrees to its own accuracy.
  EXPECT_NEAR(test::dahl_euler(-0.5, 0.006, delta), dahl_step(-0.5, 0.006, delta), 1e-2);
  // τ_f with the state: D q̇ + F_c z + o; without a state its steady state, sign(q̇).
  JointFriction f = JointFriction::none(1);
  f.sign = SmoothSign::kDahl;
  f.viscous[0] = 0.2;
  f.coulomb[0] = 0.5;
  f.offset = VectorX::Constant(1, 0.1);
  f.presliding = VectorX::Constant(1, delta);
  EXPECT_NO_THROW(validate_friction(f, 1, "test"));
  VectorX out(1);
  friction_torque(f, VectorX::Constant(1, -0.3), VectorX::Constant(1, 0.25), out);
  EXPECT_NEAR(out[0], 0.2 * -0.3 + 0.5 * 0.25 + 0.1, 1e-15);
  friction_torque(f, VectorX::Constant(1, -0.3), out);
  EXPECT_NEAR(out[0], 0.2 * -0.3 - 0.5 + 0.1, 1e-15);
  // δ is required with the Dahl sign and refused without it.
  f.presliding.resize(0);
  EXPECT_THROW(validate_friction(f, 1, "test"), Error);
  f.sign = SmoothSign::kTanh;
  f.presliding = VectorX::Constant(1, delta);
  EXPECT_THROW(validate_friction(f, 1, "test"), Error);
}

// A robot whose Coulomb friction lags its reversals (a Dahl sign): calibrate --sign dahl finds
// its friction within acceptance 1's 5 % and its presliding displacement; a velocity sign (tanh)
// cannot follow it and takes the reversals for contacts, and the refusal says what they are.
// The observer run with the fitted friction leaves exactly the residual the fit reports.
TEST(Calibration, DahlFrictionIsIdentifiedWhereAVelocitySignCannotFollowIt) {
  const Model model = paper_arm();
  test::TrueFriction truth = test::paper_arm_friction();
  truth.presliding = VectorX::Constant(7, 0.003);
  const std::vector<Sample> log = test::simulate_free_motion(
      model, test::free_motion(0.0, 1.0), truth, 20.0, Vector6::Zero(), 0.02, 17);
  CalibrationOptions dahl;
  dahl.sign = SmoothSign::kDahl;
  const Calibration cal = calibrate(model, no_sensor(), log, dahl);
  ASSERT_EQ(cal.friction.sign, SmoothSign::kDahl);
  ASSERT_EQ(cal.friction.presliding.size(), 7);
  EXPECT_EQ(cal.friction.joint_smoothing.size(), 0);
  EXPECT_TRUE(cal.suspect_windows.empty());
  for (int i = 0; i < 7; ++i) {
    SCOPED_TRACE("joint " + std::to_string(i + 1));
    EXPECT_NEAR(cal.friction.coulomb[i], truth.coulomb[i], 0.05 * truth.coulomb[i]);
    EXPECT_NEAR(cal.friction.viscous[i], truth.viscous[i], 0.05 * truth.viscous[i]);
    EXPECT_NEAR(cal.friction.offset[i], truth.offset[i], 0.02);
    EXPECT_NEAR(cal.friction.presliding[i], 0.003, 1e-12);
    EXPECT_GT(cal.joints[static_cast<std::size_t>(i)].variance_explained, 0.9);
  }
  try {
    (void)calibrate(model, no_sensor(), log);
    FAIL() << "a velocity sign calibrated a lagging friction";
  } catch (const Error& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("does not look contact-free"), std::string::npos) << what;
    EXPECT_NE(what.find("--sign dahl"), std::string::npos) << what;
  }
  // δ fixed (calibrate --presliding-displacement) at the truth's: kept on every joint, the same
  // friction as where the grid chose it. (A δ off by a sixth, 3.5 mrad, leaves reversal peaks
  // that the suspect-window test refuses as contacts on this noise-free log.)
  CalibrationOptions fixed = dahl;
  fixed.smoothing_velocity = 0.003;
  const Calibration cal_fixed = calibrate(model, no_sensor(), log, fixed);
  EXPECT_EQ(cal_fixed.friction.presliding, VectorX::Constant(7, 0.003));
  EXPECT_EQ(cal_fixed.friction.coulomb, cal.friction.coulomb);
  // The observer with the fitted Dahl friction (its own state, from the positions) leaves the
  // residual the fit reports.
  const VectorX rms = observer_after_settling(model, cal, log).rms;
  for (int i = 0; i < 7; ++i)
    EXPECT_NEAR(rms[i], cal.joints[static_cast<std::size_t>(i)].rms_after, 1e-9);
  // Through CALIB.yaml: written, included by a configuration, the same friction.
  const EstimatorConfig cfg = config_including(cal, "extwrench_calibration_dahl");
  ASSERT_TRUE(cfg.options.friction.has_value());
  EXPECT_EQ(cfg.options.friction->sign, SmoothSign::kDahl);
  EXPECT_EQ(cfg.options.friction->presliding, cal.friction.presliding);
  EXPECT_EQ(cfg.options.friction->coulomb, cal.friction.coulomb);
  EXPECT_EQ(cfg.options.friction->joint_smoothing.size(), 0);
}

// The least squares works on r⁰ + Σ θ z (calibration.hpp); the observer itself, run with the
// fitted friction, must leave exactly the residual the fit reports.
TEST(Calibration, FitResidualIsTheObserverResidualWithTheFittedFriction) {
  const Model model = paper_arm();
  const auto log = free_log(12.0);
  const Calibration cal = calibrate(model, no_sensor(), log);
  const ObserverResidual r = observer_after_settling(model, cal, log);
  for (int i = 0; i < 7; ++i) {
    const JointFitReport& j = cal.joints[static_cast<std::size_t>(i)];
    EXPECT_NEAR(r.rms[i], j.rms_after, 1e-9);
    EXPECT_LT(j.rms_after, 0.2 * j.rms_before);
    // The largest residual and its time, which the report gives beside a threshold it sets.
    EXPECT_NEAR(r.peak[i], j.max_after, 1e-9);
    EXPECT_EQ(r.peak_t[i], j.max_after_t) << "joint " << i + 1;
  }
  // A moment in the log, not the first sample's default.
  EXPECT_GT(r.peak_t.maxCoeff(), 1.0);
}

TEST(CalibrationInput, ShortContactIsExcludedAndNamedWithItsWindow) {
  sim::ForceProfile push;
  push.frame = "link5";
  push.point_F = Vector3(0.1, 0, 0);
  push.force = Vector3(0, 30, 0);
  push.start = 6.0;
  push.end = 6.5;
  const Calibration cal = calibrate(paper_arm(), no_sensor(), free_log(12.0, {push}));
  ASSERT_FALSE(cal.suspect_windows.empty());
  EXPECT_LE(cal.suspect_windows.front().t_begin, 6.1);
  EXPECT_GE(cal.suspect_windows.front().t_end, 6.4);
  ASSERT_FALSE(cal.warnings.empty());
  EXPECT_NE(cal.warnings.front().find("possible contact"), std::string::npos);
  // Excluded, the push does not bias the friction of joint 5.
  EXPECT_NEAR(cal.friction.offset[4], test::paper_arm_friction().offset[4], 0.03);
}

// 2 s of contact in 8 s: refused (more than max_contact_fraction flagged) or at least warned
// about with a window inside the push, with or without the inertia correction (which could
// absorb the push's part that follows q̈: contacts are looked for before it is fitted). (A
// contact on the proximal links over half of a log is absorbed by the fit too well to be
// recognised: docs/calibration.md.)
class LongContact : public ::testing::TestWithParam<bool> {};
TEST_P(LongContact, IsRefusedOrWarnedWithItsWindow) {
  sim::ForceProfile push;
  push.frame = "link6";
  push.point_F = Vector3(0.1, 0, 0);
  push.force = Vector3(0, 20, 0);
  push.start = 3.0;
  push.end = 5.0;
  push.ramp = 0.05;
  CalibrationOptions co;
  co.inertia_correction = GetParam();
  try {
    const Calibration cal = calibrate(paper_arm(), no_sensor(), free_log(8.0, {push}), co);
    ASSERT_FALSE(cal.suspect_windows.empty()) << "a 2 s push went unnoticed";
    for (const SuspectWindow& w : cal.suspect_windows) {
      EXPECT_GE(w.t_end, push.start);
      EXPECT_LE(w.t_begin, push.end + 0.1);
    }
    ASSERT_FALSE(cal.warnings.empty());
    EXPECT_NE(cal.warnings.front().find("possible contact"), std::string::npos);
  } catch (const Error& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("contact-free"), std::string::npos) << what;
    EXPECT_NE(what.find("[3."), std::string::npos) << what;
  }
}
INSTANTIATE_TEST_SUITE_P(CalibrationInput, LongContact, ::testing::Bool(), [](const auto& info) {
  return info.param ? "InertiaCorrection" : "FrictionOnly";
});

TEST(CalibrationInput, JointThatDoesNotMoveIsNamed) {
  sim::SinusoidalTrajectory still = test::free_motion(0.0, 1.0);
  still.amplitude[2] = 0.0;
  try {
    (void)calibrate(paper_arm(), no_sensor(), free_log(6.0, {}, still));
    FAIL() << "joint 3 never moves, yet its friction was fitted";
  } catch (const Error& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("joint 3"), std::string::npos) << what;
    EXPECT_NE(what.find("not excited"), std::string::npos) << what;
  }
}

TEST(CalibrationInput, FewerSamplesThanParameters) {
  auto log = free_log(0.12);  // 0.1 s settle at K = 50 leaves 21 samples for 21 parameters - 1
  log.resize(log.size() - 1);
  try {
    (void)calibrate(paper_arm(), no_sensor(), log);
    FAIL();
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("parameters"), std::string::npos) << e.what();
  }
}

// The same free motion with t written in milliseconds: refused, naming seconds (the fit would
// integrate over steps a thousand times too long, and its warnings blamed a contact).
TEST(CalibrationInput, TimeInMillisecondsIsNamed) {
  auto log = free_log(8.0);
  const double step = log[1].t - log[0].t;
  for (Sample& s : log) s.t *= 1e3;
  try {
    (void)calibrate(paper_arm(), no_sensor(), log);
    FAIL();
  } catch (const Error& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("s apart on average"), std::string::npos) << what;
    EXPECT_NE(what.find("t must be in seconds"), std::string::npos) << what;
  }
  for (Sample& s : log) s.t *= 1e-3;  // in seconds again (the log's 1 kHz): calibrates
  EXPECT_NEAR(log[1].t - log[0].t, step, 1e-12);
  EXPECT_NO_THROW((void)calibrate(paper_arm(), no_sensor(), log));
}

TEST(CalibrationInput, NonFiniteSampleIsNamed) {
  auto log = free_log(1.0);
  log[123].tau[1] = std::nan("");
  try {
    (void)calibrate(paper_arm(), no_sensor(), log);
    FAIL();
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("sample 123"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("tau2"), std::string::npos) << e.what();
  }
}

TEST(CalibrationInput, NanRowOfALogIsNamedByLine) {
  const fs::path dir = fs::temp_directory_path() / "extwrench_calibration_nan";
  fs::create_directories(dir);
  const fs::path csv = dir / "free.csv";
  {
    std::ofstream o(csv);
    o << "t,q1,q2,q3,q4,q5,q6,q7,tau1,tau2,tau3,tau4,tau5,tau6,tau7\n";
    o << "0,0,0,0,0,0,0,0,0,0,0,0,0,0,0\n";
    o << "0.001,0,0,0,0,0,0,0,0,nan,0,0,0,0,0\n";
  }
  const Model model = paper_arm();
  try {
    LogReader reader(csv, model);
    Sample s;
    while (reader.next(s)) {
    }
    FAIL() << "a nan torque was read";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find(":3"), std::string::npos) << e.what();
  }
}

TEST(CalibrationFile, IncludedByAConfigurationGivesTheSameOptions) {
  const Model model = paper_arm();
  Calibration cal = calibrate(model, no_sensor(), free_log(8.0));
  cal.source = "free.csv";
  const fs::path dir = fs::temp_directory_path() / "extwrench_calibration_file";
  const std::string robot = (fs::path(EXTWRENCH_SOURCE_DIR) / "models/paper_arm.urdf").string();
  const EstimatorConfig cfg = config_including(cal, "extwrench_calibration_file");
  ASSERT_TRUE(cfg.options.friction.has_value());
  EXPECT_EQ(cfg.options.friction->sign, SmoothSign::kTanh);
  EXPECT_TRUE(cfg.options.friction->offset.isApprox(cal.friction.offset, 1e-15));
  EXPECT_TRUE(cfg.options.friction->coulomb.isApprox(cal.friction.coulomb, 1e-15));
  EXPECT_TRUE(cfg.options.friction->joint_smoothing.isApprox(cal.friction.joint_smoothing, 1e-15));
  EXPECT_TRUE(cfg.options.detection.tau_min.isApprox(cal.tau_threshold, 1e-15));
  // A configuration with another gain is told to recalibrate.
  try {
    (void)load_estimator_config_string(
        "robot: " + robot + "\nsensor: {type: none}\ncalibration: calib.yaml\n",
        dir / "config.yaml");
    FAIL();
  } catch (const Error& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("config.yaml:3: calibration"), std::string::npos) << what;
    EXPECT_NE(what.find("gain"), std::string::npos) << what;
  }
}

// A calibration read back and written again (a user's script that edits one value, say) is a
// file the loader accepts, with what a configuration takes from it: the friction, thresholds and
// the residual's noise levels (fit.joints[].noise_std). The written form is a fixed point from
// the first read on. It once wrote an empty fit.joints, which the loader refuses.
TEST(CalibrationFile, ReadBackAndWrittenAgainLoadsTheSame) {
  const Model model = paper_arm();
  Calibration cal = calibrate(model, no_sensor(), free_log(8.0));
  cal.source = "free.csv";
  const fs::path dir = fs::temp_directory_path() / "extwrench_calibration_written_again";
  fs::create_directories(dir);
  std::ofstream(dir / "first.yaml") << calibration_to_yaml(cal, nullptr);
  const Calibration read = load_calibration(dir / "first.yaml", 7);
  EXPECT_EQ(read.source, "free.csv");
  ASSERT_EQ(read.residual_noise.size(), 7);
  EXPECT_TRUE(read.residual_noise.isApprox(cal.residual_noise, 1e-5));  // the report's 6 digits
  const std::string second = calibration_to_yaml(read, nullptr);
  std::ofstream(dir / "second.yaml") << second;
  const Calibration again = load_calibration(dir / "second.yaml", 7);
  EXPECT_EQ(again.residual_noise, read.residual_noise);
  EXPECT_EQ(again.tau_threshold, read.tau_threshold);
  EXPECT_EQ(again.friction.coulomb, read.friction.coulomb);
  EXPECT_EQ(again.source, "free.csv");
  EXPECT_EQ(calibration_to_yaml(again, nullptr), second);
}

// The log a calibration came from may be named with any bytes (fuzz_calibration_file's finding:
// a source holding NUL bytes, read from a double-quoted scalar, was written back raw and read
// back otherwise). Written, read and written again, every such name is itself.
TEST(CalibrationFile, AnySourceNameReadsBackAsItself) {
  Calibration cal = calibrate(paper_arm(), no_sensor(), free_log(8.0));
  const fs::path dir = fs::temp_directory_path() / "extwrench_calibration_source_names";
  fs::create_directories(dir);
  using namespace std::string_literals;
  for (const std::string& source :
       {"free.csv"s, "a: b #c"s, "nul\0inside"s, "tab\tand\nnewline\r"s, "\x01\x1f\x7f"s,
        "quote \" and back\\slash"s, "ü"s, ""s, "- [x]"s}) {
    cal.source = source;
    std::ofstream(dir / "calib.yaml", std::ios::binary) << calibration_to_yaml(cal, nullptr);
    const Calibration read = load_calibration(dir / "calib.yaml", 7);
    EXPECT_EQ(read.source, source);
    std::ofstream(dir / "again.yaml", std::ios::binary) << calibration_to_yaml(read, nullptr);
    EXPECT_EQ(load_calibration(dir / "again.yaml", 7).source, source);
  }
}

TEST(CalibratedEstimator, UpdateAllocatesNothing) {
  if (!test::allocation_counting_available()) GTEST_SKIP() << "sanitizer build";
  const Model model = paper_arm();
  EstimatorOptions options = no_sensor();
  options.sensor.type = SensorType::kForceTorque;
  const auto log =
      test::simulate_free_motion(model, test::free_motion(0.0, 1.0), test::paper_arm_friction(),
                                 3.0, Vector6::Zero(), 0.02, 3);
  CalibrationOptions speed;
  speed.thresholds = ThresholdModel::kSpeed;  // thresholds a + b|q̇| on every joint
  // Constant thresholds, thresholds a + b|q̇|, constant ones with drift tracking on, and the
  // calibrated friction with a Dahl sign (the observer's state).
  for (int variant = 0; variant < 4; ++variant) {
    const Calibration cal =
        calibrate(model, options, log, variant == 1 ? speed : CalibrationOptions{});
    EstimatorOptions calibrated = apply_calibration(options, cal);
    if (variant == 2) calibrated.drift = DriftOptions{};
    if (variant == 3) {
      calibrated.friction->sign = SmoothSign::kDahl;
      calibrated.friction->joint_smoothing.resize(0);
      calibrated.friction->presliding = VectorX::Constant(7, 0.003);
    }
    ContactEstimator est(model, GeometryModel{}, calibrated);
    ASSERT_TRUE(est.reset(log.front()).ok());
    const test::AllocationCounter counter;
    for (std::size_t k = 1; k < log.size(); ++k) (void)est.update(log[k]);
    EXPECT_EQ(counter.count(), 0u);
  }
}

// Thresholds that follow |q̇| through CALIB.yaml: written, included, applied; a file without
// the key (written before it existed) still loads, with constant thresholds; a configuration
// that sets its own tau_min gets constant thresholds; a bad value is named with file and line.
TEST(CalibrationFile, SpeedThresholdsRoundTripAndOldFilesStillLoad) {
  const Model model = paper_arm();
  CalibrationOptions co;
  co.thresholds = ThresholdModel::kSpeed;
  // Torque noise that grows with the speed (0.2 N m s/rad), so that b > 0 comes out.
  Calibration cal = calibrate(
      model, no_sensor(),
      test::simulate_free_motion(model, test::free_motion(0.0, 1.0), test::paper_arm_friction(),
                                 8.0, Vector6::Zero(), 0.01, 5, {}, Pose(), 0.2),
      co);
  ASSERT_EQ(cal.tau_per_speed.size(), 7);
  EXPECT_GT(cal.tau_per_speed.maxCoeff(), 0.0);
  for (int i = 0; i < 7; ++i) {
    const JointFitReport& j = cal.joints[static_cast<std::size_t>(i)];
    EXPECT_EQ(j.speed_dependent, cal.tau_per_speed[i] > 0.0) << "joint " << i + 1;
    if (j.speed_dependent) {
      EXPECT_DOUBLE_EQ(cal.tau_threshold[i], j.threshold_at_rest);
    }
  }
  cal.source = "free.csv";
  const fs::path dir = fs::temp_directory_path() / "extwrench_calibration_speed";
  fs::create_directories(dir);
  const std::string text = calibration_to_yaml(cal, nullptr);
  ASSERT_NE(text.find("tau_per_speed"), std::string::npos);
  std::ofstream(dir / "calib.yaml") << text;
  const std::string robot = (fs::path(EXTWRENCH_SOURCE_DIR) / "models/paper_arm.urdf").string();
  const std::string head = "robot: " + robot + "\nsensor: {type: none}\nobserver: {gain: 50}\n";
  const EstimatorConfig cfg =
      load_estimator_config_string(head + "calibration: calib.yaml\n", dir / "config.yaml");
  EXPECT_TRUE(cfg.options.detection.tau_per_speed.isApprox(cal.tau_per_speed, 1e-15));
  EXPECT_TRUE(cfg.options.detection.tau_min.isApprox(cal.tau_threshold, 1e-15));
  // The residual's noise per joint becomes the uncertainty's (the report keeps 6 digits), unless
  // the configuration sets it.
  ASSERT_EQ(cfg.options.uncertainty.residual_sigma.size(), 7);
  EXPECT_GT(cal.residual_noise.minCoeff(), 0.0);
  EXPECT_TRUE(cfg.options.uncertainty.residual_sigma.isApprox(cal.residual_noise, 1e-5));
  const EstimatorConfig own_noise = load_estimator_config_string(
      head + "uncertainty: {residual_sigma: 0.2}\ncalibration: calib.yaml\n", dir / "config.yaml");
  EXPECT_EQ(own_noise.options.uncertainty.residual_sigma, VectorX::Constant(7, 0.2));
  // The configuration written back keeps the speed term (to_yaml) and reads back the same.
  const std::string written = to_yaml(cfg, dir);
  const EstimatorConfig again = load_estimator_config_string(written, dir / "written.yaml");
  EXPECT_TRUE(again.options.detection.tau_per_speed.isApprox(cal.tau_per_speed, 1e-15));
  EXPECT_EQ(to_yaml(again, dir), written);
  // Own tau_min: constant thresholds, the calibration's speed term dropped.
  const EstimatorConfig own = load_estimator_config_string(
      head + "detection: {tau_min: 2}\ncalibration: calib.yaml\n", dir / "config.yaml");
  EXPECT_FALSE((own.options.detection.tau_per_speed.array() > 0.0).any());
  // A file written before thresholds followed the speed: constant.
  cal.tau_per_speed = VectorX::Zero(7);
  const std::string old_text = calibration_to_yaml(cal, nullptr);
  EXPECT_EQ(old_text.find("tau_per_speed"), std::string::npos);
  std::ofstream(dir / "old.yaml") << old_text;
  const EstimatorConfig old =
      load_estimator_config_string(head + "calibration: old.yaml\n", dir / "config.yaml");
  EXPECT_FALSE((old.options.detection.tau_per_speed.array() > 0.0).any());
  ContactEstimator est(model, GeometryModel{}, old.options);
  EXPECT_FALSE(est.detector().speed_dependent());
  // A negative slope: the file, its line and the key.
  std::string bad = text;
  std::size_t at = bad.find("tau_per_speed: ") + std::string("tau_per_speed: ").size();
  if (bad[at] == '[') ++at;  // a list: its first value
  bad.replace(at, bad.find_first_of(",]}", at) - at, "-0.5");
  std::ofstream(dir / "bad.yaml") << bad;
  try {
    (void)load_estimator_config_string(head + "calibration: bad.yaml\n", dir / "config.yaml");
    FAIL() << "a negative tau_per_speed was accepted";
  } catch (const Error& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("bad.yaml:"), std::string::npos) << what;
    EXPECT_NE(what.find("detection.tau_per_speed"), std::string::npos) << what;
  }
}

// The estimator with a calibration applied, over the samples the fit used (after 5/K at K =
// 50): its residual's RMS per joint, which must be the report's rms_after (the fit's residual).
void expect_estimator_residual_is_the_fits(const Model& model, const EstimatorOptions& applied,
                                           const std::vector<Sample>& log, const Calibration& cal) {
  ContactEstimator est(model, GeometryModel{}, applied);
  ASSERT_TRUE(est.reset(log.front()).ok());
  VectorX sum2 = VectorX::Zero(model.nq());
  int count = 0;
  for (std::size_t k = 1; k < log.size(); ++k) {
    ASSERT_TRUE(est.update(log[k]).ok());
    if (log[k].t - log.front().t < 5.0 / 50.0 - 1e-9) continue;
    sum2 += est.result().residual.cwiseAbs2();
    ++count;
  }
  ASSERT_EQ(count, cal.samples_used);
  for (int i = 0; i < model.nq(); ++i) {
    EXPECT_NEAR(std::sqrt(sum2[i] / count), cal.joints[static_cast<std::size_t>(i)].rms_after, 1e-9)
        << "joint " << i + 1;
  }
}

// The configuration head of the paper arm without a sensor.
std::string paper_arm_head() {
  const std::string robot = (fs::path(EXTWRENCH_SOURCE_DIR) / "models/paper_arm.urdf").string();
  return "robot: " + robot + "\nsensor: {type: none}\n";
}

// A calibration made with a filter (observer.KEY = `cutoff`, as YAML), written to DIR/calib.yaml:
// a configuration that includes it takes the cutoff; another one there (`other`) is refused with
// the line and the calibration's value; a negative one is named; written back, it is kept.
void expect_cutoff_carried(const Calibration& cal, const std::string& key, const VectorX& cutoff,
                           const std::string& cutoff_text, const std::string& other,
                           const fs::path& dir) {
  fs::create_directories(dir);
  std::ofstream(dir / "calib.yaml") << calibration_to_yaml(cal, nullptr);
  const std::string head = paper_arm_head();
  const auto value = [&](const EstimatorConfig& c) {
    return key == "residual_cutoff" ? c.options.residual_cutoff : c.options.velocity_cutoff;
  };
  const EstimatorConfig cfg = load_estimator_config_string(
      head + "observer: {gain: 50}\ncalibration: calib.yaml\n", dir / "config.yaml");
  EXPECT_EQ(value(cfg), cutoff);
  try {
    (void)load_estimator_config_string(
        head + "observer: {gain: 50, " + key + ": " + other + "}\ncalibration: calib.yaml\n",
        dir / "config.yaml");
    ADD_FAILURE() << "another " << key << " than the calibration's was accepted";
  } catch (const Error& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("config.yaml:4: calibration"), std::string::npos) << what;
    EXPECT_NE(what.find(key + " " + cutoff_text), std::string::npos) << what;
  }
  try {
    (void)load_estimator_config_string(head + "observer: {gain: 50, " + key + ": -1}\n",
                                       dir / "config.yaml");
    ADD_FAILURE() << "a negative " << key << " was accepted";
  } catch (const Error& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("config.yaml:3"), std::string::npos) << what;
    EXPECT_NE(what.find("observer." + key), std::string::npos) << what;
  }
  const EstimatorConfig again = load_estimator_config_string(to_yaml(cfg, dir), dir / "w.yaml");
  EXPECT_EQ(value(again), cutoff);
}

// The residual filter (observer.residual_cutoff) through calibration: the thresholds and noise
// are those of the filtered residual, exactly the one the estimator's detector sees; CALIB.yaml
// carries the cutoff to the configuration that includes it; another cutoff there is refused; a
// negative one is named.
TEST(CalibrationFile, TheResidualFilterIsCalibratedAndCarriedWithItsThresholds) {
  const Model model = paper_arm();
  EstimatorOptions options = no_sensor();
  options.residual_cutoff = VectorX{{15, 15, 15, 15, 0, 0, 0}};
  // Torque noise on every sample: what the filter removes.
  const auto log = test::simulate_free_motion(
      model, test::free_motion(0.0, 1.0), test::paper_arm_friction(), 8.0, Vector6::Zero(), 0.2, 5);
  const Calibration plain = calibrate(model, no_sensor(), log);
  Calibration cal = calibrate(model, options, log);
  EXPECT_EQ(cal.residual_cutoff, options.residual_cutoff);
  // The estimator's residual is the fit's, through the same filter.
  expect_estimator_residual_is_the_fits(model, apply_calibration(options, cal), log, cal);
  for (int i = 0; i < 7; ++i) {
    const auto j = static_cast<std::size_t>(i);
    if (i < 4) {
      EXPECT_LT(cal.joints[j].noise_std, 0.8 * plain.joints[j].noise_std) << "joint " << i + 1;
    } else {
      EXPECT_EQ(cal.joints[j].noise_std, plain.joints[j].noise_std) << "joint " << i + 1;
    }
  }
  cal.source = "free.csv";
  const fs::path dir = fs::temp_directory_path() / "extwrench_calibration_filter";
  expect_cutoff_carried(cal, "residual_cutoff", options.residual_cutoff,
                        "[15, 15, 15, 15, 0, 0, 0]", "30", dir);
  const std::string head = paper_arm_head();
  const EstimatorConfig cfg = load_estimator_config_string(
      head + "observer: {gain: 50}\ncalibration: calib.yaml\n", dir / "config.yaml");
  const EstimatorConfig same = load_estimator_config_string(
      head +
          "observer: {gain: 50, residual_cutoff: [15, 15, 15, 15, 0, 0, 0]}\ncalibration: "
          "calib.yaml\n",
      dir / "config.yaml");
  EXPECT_EQ(same.options.residual_cutoff, options.residual_cutoff);
  // Without the key, as before the filter existed: none.
  const EstimatorConfig none =
      load_estimator_config_string(head + "observer: {gain: 50}\n", dir / "config.yaml");
  EXPECT_EQ(none.options.residual_cutoff, VectorX::Zero(1));
  // Written back, the configuration keeps the cutoff.
  const EstimatorConfig again = load_estimator_config_string(to_yaml(cfg, dir), dir / "w.yaml");
  EXPECT_EQ(again.options.residual_cutoff, options.residual_cutoff);
}

// The velocity filter (observer.velocity_cutoff) through calibration: the fit sees the log's q̇
// through it, as the estimator does, so the estimator's residual is the fit's; CALIB.yaml carries
// the cutoff to the configuration that includes it; another cutoff there is refused; a negative
// one is named; written back, the configuration keeps it.
TEST(CalibrationFile, TheVelocityFilterIsCalibratedAndCarriedWithItsThresholds) {
  const Model model = paper_arm();
  EstimatorOptions options = no_sensor();
  options.velocity_cutoff = VectorX{{25, 25, 25, 25, 0, 0, 0}};
  auto log = test::simulate_free_motion(model, test::free_motion(0.0, 1.0),
                                        test::paper_arm_friction(), 8.0, Vector6::Zero(), 0.02, 7);
  test::SeededRng rng(7);
  for (Sample& s : log) s.dq += rng.uniform_vector(7, -0.004, 0.004);  // a noisy velocity
  const Calibration plain = calibrate(model, no_sensor(), log);
  Calibration cal = calibrate(model, options, log);
  for (const std::string& w : cal.warnings) std::printf("warning: %s\n", w.c_str());
  EXPECT_EQ(cal.velocity_cutoff, options.velocity_cutoff);
  EXPECT_EQ(plain.velocity_cutoff, VectorX::Zero(7));
  expect_estimator_residual_is_the_fits(model, apply_calibration(options, cal), log, cal);
  for (int i = 0; i < 4; ++i) {
    const auto j = static_cast<std::size_t>(i);
    EXPECT_LT(cal.joints[j].noise_std, 0.8 * plain.joints[j].noise_std) << "joint " << i + 1;
  }
  cal.source = "free.csv";
  expect_cutoff_carried(cal, "velocity_cutoff", options.velocity_cutoff,
                        "[25, 25, 25, 25, 0, 0, 0]", "10",
                        fs::temp_directory_path() / "extwrench_calibration_velocity_filter");
}

// The inertia correction (observer.inertia_correction) through calibration: on an arm with a
// rotor the model lacks, the fitted δI enters the estimator's observer so that its residual is
// exactly the fit's (the regressor is the observer's own law); CALIB.yaml carries δI to the
// configuration that includes it; a configuration's own value wins; a bad one is named.
TEST(CalibrationFile, TheInertiaCorrectionIsTheEstimatorsResidual) {
  const Model model = paper_arm();
  Model rotors = model;
  // Joint 1 (joints[0] is the base's): its axis is vertical, so in this motion of one sine per
  // joint (q̈ follows q) no gravity error can look like its rotor, and the fit may apply it.
  rotors.joints[1].armature = 0.25;
  const auto log =
      test::simulate_free_motion(rotors, test::free_motion(0.0, 1.0), test::paper_arm_friction(),
                                 8.0, Vector6::Zero(), 0.02, 5);
  CalibrationOptions with_inertia;
  with_inertia.inertia_correction = true;
  Calibration cal = calibrate(model, no_sensor(), log, with_inertia);
  ASSERT_EQ(cal.inertia_correction.size(), 7);
  EXPECT_NEAR(cal.inertia_correction[0], 0.25, 0.005);
  EXPECT_EQ(cal.joints[0].inertia_correction, cal.inertia_correction[0]);
  EXPECT_GT(cal.joints[0].inertia_gain, 0.5);
  const EstimatorOptions applied = apply_calibration(no_sensor(), cal);
  EXPECT_EQ(applied.inertia_correction, cal.inertia_correction);
  expect_estimator_residual_is_the_fits(model, applied, log, cal);
  cal.source = "free.csv";
  const fs::path dir = fs::temp_directory_path() / "extwrench_calibration_inertia";
  fs::create_directories(dir);
  std::ofstream(dir / "calib.yaml") << calibration_to_yaml(cal, nullptr);
  EXPECT_EQ(load_calibration(dir / "calib.yaml", 7).inertia_correction, cal.inertia_correction);
  const std::string robot = (fs::path(EXTWRENCH_SOURCE_DIR) / "models/paper_arm.urdf").string();
  const std::string head = "robot: " + robot + "\nsensor: {type: none}\n";
  const EstimatorConfig cfg = load_estimator_config_string(
      head + "observer: {gain: 50}\ncalibration: calib.yaml\n", dir / "config.yaml");
  EXPECT_EQ(cfg.options.inertia_correction, cal.inertia_correction);
  const EstimatorConfig own = load_estimator_config_string(
      head + "observer: {gain: 50, inertia_correction: 0.1}\ncalibration: calib.yaml\n",
      dir / "config.yaml");
  EXPECT_EQ(own.options.inertia_correction, VectorX::Constant(7, 0.1));
  // Written back, the configuration keeps it.
  const EstimatorConfig again = load_estimator_config_string(to_yaml(cfg, dir), dir / "w.yaml");
  EXPECT_EQ(again.options.inertia_correction, cal.inertia_correction);
  for (const char* bad : {"[0, 0, 0]", ".nan", "heavy"}) {
    try {
      (void)load_estimator_config_string(
          head + "observer: {gain: 50, inertia_correction: " + bad + "}\n", dir / "config.yaml");
      FAIL() << "inertia_correction: " << bad << " was accepted";
    } catch (const Error& e) {
      const std::string what = e.what();
      EXPECT_NE(what.find("config.yaml:3"), std::string::npos) << what;
      EXPECT_NE(what.find("observer.inertia_correction"), std::string::npos) << what;
    }
  }
}

// With the velocity filter, the estimator adds δI to the filtered q̇ of its momentum: the fit's
// regressor is that q̇'s rate too, so the estimator's residual is still exactly the fit's (with
// the measured q̇'s, the fitted RMS and the estimator's differ by the noise δI passes), and the
// rotor is found through the noise.
TEST(CalibrationFile, TheInertiaCorrectionTakesTheFilteredVelocity) {
  const Model model = paper_arm();
  Model rotors = model;
  rotors.joints[1].armature = 0.25;  // joint 1: vertical axis, no gravity alias
  auto log = test::simulate_free_motion(rotors, test::free_motion(0.0, 1.0),
                                        test::paper_arm_friction(), 8.0, Vector6::Zero(), 0.02, 5);
  test::SeededRng rng(5);
  for (Sample& s : log) s.dq += rng.uniform_vector(7, -0.004, 0.004);  // a noisy velocity
  EstimatorOptions options = no_sensor();
  options.velocity_cutoff = VectorX{{25, 25, 25, 25, 0, 0, 0}};
  CalibrationOptions with_inertia;
  with_inertia.inertia_correction = true;
  const Calibration cal = calibrate(model, options, log, with_inertia);
  ASSERT_EQ(cal.inertia_correction.size(), 7);
  EXPECT_NEAR(cal.inertia_correction[0], 0.25, 0.01);
  EXPECT_GT(cal.joints[0].inertia_gain, 0.3);
  expect_estimator_residual_is_the_fits(model, apply_calibration(options, cal), log, cal);
}

// δI is the armature to every stage of the estimator that uses B(q): with a base F/T sensor
// (route (b): q̈̂ from B + δI, the base wrench's prediction from it) and a push on link 6, the
// estimator on the model without rotors but with δI = the rotors' armature gives what the
// estimator on the model with them gives (Model::joints[i].armature, added by the dynamics).
TEST(InertiaCorrection, IsTheArmatureToTheWholeEstimator) {
  const Model model = paper_arm();
  Model rotors = model;
  rotors.joints[2].armature = 0.3;
  rotors.joints[6].armature = 0.05;
  VectorX armature = VectorX::Zero(7);
  armature[1] = 0.3;
  armature[5] = 0.05;
  sim::ForceProfile push;
  push.frame = "link6";
  push.point_F = Vector3(0.1, 0, 0);
  push.force = Vector3(0, 15, 0);
  push.start = 1.0;
  push.end = 1.5;
  push.ramp = 0.02;
  const auto log =
      test::simulate_free_motion(rotors, test::free_motion(0.0, 1.0), test::paper_arm_friction(),
                                 2.0, Vector6::Zero(), 0.0, 5, {push});
  EstimatorOptions options;
  options.sensor.type = SensorType::kForceTorque;
  options.friction = JointFriction::none(7);
  ContactEstimator with_rotors(rotors, GeometryModel{}, options);
  options.inertia_correction = armature;
  ContactEstimator corrected(model, GeometryModel{}, options);
  ASSERT_TRUE(with_rotors.reset(log.front()).ok());
  ASSERT_TRUE(corrected.reset(log.front()).ok());
  double worst_residual = 0, worst_force = 0, peak_force = 0;
  int contacts = 0;
  for (std::size_t k = 1; k < log.size(); ++k) {
    ASSERT_TRUE(with_rotors.update(log[k]).ok());
    ASSERT_TRUE(corrected.update(log[k]).ok());
    const ContactEstimate& a = with_rotors.result();
    const ContactEstimate& b = corrected.result();
    worst_residual = std::max(worst_residual, (a.residual - b.residual).cwiseAbs().maxCoeff());
    EXPECT_EQ(a.contact, b.contact) << "t = " << log[k].t;
    if (!a.contact) continue;
    ++contacts;
    worst_force = std::max(worst_force, (a.force_W - b.force_W).norm());
    peak_force = std::max(peak_force, a.force_W.norm());
  }
  EXPECT_GT(contacts, 300);
  EXPECT_GT(peak_force, 10.0);
  EXPECT_LT(worst_residual, 1e-9);
  EXPECT_LT(worst_force, 1e-9 * peak_force);
}

}  // namespace
}  // namespace extwrench
