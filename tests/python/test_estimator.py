"""ContactEstimator and the batch estimate from Python: configurations as dicts and files, the
update loop against the C++ batch loop, flags, errors that leave the state untouched, leaks."""

import gc
import re
import sys

import numpy as np
import pytest

import extwrench
from conftest import PAPER_URDF, bits, same

CONFIG = {
    "sensor": {"type": "ft", "pose": {"xyz": [0, 0, -0.31], "rpy": [0, 0, 0]}},
    "contact": {"model": "pure_force"},
    "observer": {"gain": 100},
    "detection": {"tau_min": 1.0, "f_min": 5.0},
}


def synthetic_log(robot, rows=600, push=20.0, seed=5):
    """A consistent log without a simulator: tau = rnea(q, dq, ddq) minus a constant push on
    body 6 from t = 0.2 s, and the base reading the robot discharges (sensor_reading)."""
    rng = np.random.default_rng(seed)
    n = robot.nq
    t = np.arange(rows) * 1e-3
    amp, freq = rng.uniform(0.2, 0.6, n), rng.uniform(0.1, 0.4, n)
    w = 2 * np.pi * freq
    q = amp * np.sin(np.outer(t, w))
    dq = amp * w * np.cos(np.outer(t, w))
    ddq = -amp * w * w * np.sin(np.outer(t, w))
    X_WS = np.eye(4)
    X_WS[2, 3] = -0.31
    tau, reading = np.empty((rows, n)), np.empty((rows, 6))
    for k in range(rows):
        wr = [extwrench.ExternalWrench(6, [push, 0, 0], [0.0, 0.0, 0.5])] if t[k] >= 0.2 else []
        # The motor torque that produces ddq while the push acts: tau = rnea with the wrench.
        tau[k] = extwrench.rnea(robot, q[k], dq[k], ddq[k], wr)
        reading[k] = extwrench.sensor_reading(robot, q[k], dq[k], ddq[k], wr, X_WS)
    return t, q, dq, tau, reading


@pytest.fixture()
def log(robot):
    return synthetic_log(robot)


def test_dict_and_file_configs_agree(robot, log, tmp_path):
    path = tmp_path / "config.yaml"
    path.write_text("robot: %s\nsensor: {type: ft, pose: {xyz: [0, 0, -0.31], rpy: [0, 0, 0]}}\n"
                    "contact: {model: pure_force}\nobserver: {gain: 100}\n"
                    "detection: {tau_min: 1.0, f_min: 5.0}\n" % PAPER_URDF)
    a = extwrench.estimate(extwrench.ContactEstimator(robot, CONFIG), *log)
    b = extwrench.estimate(str(path), *log)
    c = extwrench.estimate(dict(CONFIG, robot=str(PAPER_URDF)), *log)
    for key in a:
        assert same(a[key], b[key]) and same(a[key], c[key]), key


def test_update_loop_equals_batch(robot, log):
    t, q, dq, tau, reading = log
    batch = extwrench.estimate(extwrench.ContactEstimator(robot, CONFIG), *log)
    est = extwrench.ContactEstimator(robot, CONFIG)
    est.reset(t[0], q[0], dq[0], tau[0])
    for k in range(1, len(t)):
        e = est.update(t[k], q[k], dq[k], tau[k], reading[k])
        assert e.t == batch["t"][k] and e.contact == batch["contact"][k]
        assert np.array_equal(bits(e.force_W), bits(batch["force_W"][k]))
        assert np.array_equal(bits(e.line_point_W), bits(batch["line_point_W"][k]))
        assert np.array_equal(bits(e.residual), bits(batch["residual"][k]))
        assert np.array_equal(bits([e.condition_number]), bits([batch["cond"][k]]))
        assert e.flag_bits == batch["flags"][k]
        assert e.status == "ok"  # the flags are e.flags (the batch column shows them instead)
        assert "|".join(sorted(e.flags)) == "|".join(sorted(
            batch["status"][k].split("|"))) or (not e.flags and batch["status"][k] == "free")
    # The push of 20 N along x on link 6 from t = 0.2 s is found (physics, not the code).
    late = batch["t"] > 0.3
    assert batch["contact"][late].all()
    assert (batch["link"][late] == 6).all()
    np.testing.assert_allclose(batch["force_W"][late], np.tile([20.0, 0, 0], (late.sum(), 1)),
                               atol=0.5)
    assert e.link_name == robot.bodies[6]
    assert {"contact", "force", "line"} <= e.flags


def test_warm_up_between_updates_changes_no_estimate(robot, log):
    # The paper arm's capsules: warm_up casts lines at them, the loop's results stay bit-identical.
    t, q, dq, tau, reading = log
    batch = extwrench.estimate(extwrench.ContactEstimator(robot, CONFIG), *log)
    est = extwrench.ContactEstimator(robot, CONFIG)
    est.warm_up()
    est.reset(t[0], q[0], dq[0], tau[0])
    for k in range(1, len(t)):
        if k % 100 == 0:
            est.warm_up()
        e = est.update(t[k], q[k], dq[k], tau[k], reading[k])
        assert np.array_equal(bits(e.force_W), bits(batch["force_W"][k]))
        assert np.array_equal(bits(e.residual), bits(batch["residual"][k]))
        assert e.flag_bits == batch["flags"][k]
        assert e.status == "ok"  # the flags are e.flags (the batch column shows them instead)


def test_batch_columns_and_views(robot, log):
    out = extwrench.estimate(extwrench.ContactEstimator(robot, CONFIG), *log)
    rows, n = len(log[0]), robot.nq
    csv_columns = ["t", "contact", "link", "fx", "fy", "fz", "mx", "my", "mz", "px", "py", "pz",
                   "lx", "ly", "lz", "status", "cond"] + ["r%d" % (i + 1) for i in range(n)]
    for c in csv_columns:
        assert c in out and out[c].shape == (rows,), c
    assert out["contact"].dtype == bool and out["link"].dtype == np.int32
    assert out["force_W"].shape == (rows, 3) and out["residual"].shape == (rows, n)
    assert same(out["fy"], out["force_W"][:, 1])
    # The first row resets the estimator: free, zero residual (as `extwrench estimate`).
    assert out["status"][0] == "free" and not out["residual"][0].any()


def test_thresholds_are_those_the_detector_compared(robot, log):
    # Thresholds that follow the joint speed: tau_thr,i = 2 + 0.5 |dq_i| (docs/calibration.md),
    # computed here from the log's dq, not read back from the library.
    t, q, dq, tau, reading = log
    config = dict(CONFIG, detection={"tau_min": 2.0, "tau_per_speed": 0.5, "f_min": 5.0})
    est = extwrench.ContactEstimator(robot, config)
    out = extwrench.estimate(est, *log)
    assert out["threshold"].shape == (len(t), robot.nq)
    np.testing.assert_allclose(out["threshold"][1:], 2.0 + 0.5 * np.abs(dq[1:]), rtol=0, atol=1e-12)
    est.reset(t[0], q[0], dq[0], tau[0])
    for k in (1, 250, len(t) - 1):  # the speed part depends on this sample's dq only
        est.update(t[k], q[k], dq[k], tau[k], reading[k])
        assert np.array_equal(bits(est.thresholds), bits(out["threshold"][k])), k
    # Constant thresholds by default: tau_min on every row.
    plain = extwrench.estimate(extwrench.ContactEstimator(robot, CONFIG), *log)
    assert (plain["threshold"] == 1.0).all()


def test_layouts_and_dtypes_give_the_same_estimates(robot, log):
    t, q, dq, tau, reading = log
    est = extwrench.ContactEstimator(robot, CONFIG)
    base = extwrench.estimate(est, *log)
    wide = np.zeros((len(t), 3 * robot.nq))
    wide[:, ::3] = q                                    # q as a strided view
    variants = [
        (t, wide[:, ::3], np.asfortranarray(dq), tau, reading),
        (list(t), q.tolist(), dq, np.asfortranarray(tau), np.asfortranarray(reading)),
        (t[::-1][::-1], q, dq, tau, reading[:, :6]),
    ]
    # Fields of a packed structured array (a log read by np.genfromtxt with an integer column):
    # byte strides of 12 and 60, no multiple of 8, and data not 8-byte aligned.
    packed = np.zeros(len(t), dtype=[("flag", "i4"), ("t", "f8"), ("q", "f8", robot.nq)])
    packed["t"], packed["q"] = t, q
    assert packed.strides[0] % 8 and not packed["t"].flags.aligned
    variants.append((packed["t"], packed["q"], dq, tau, reading))
    for v in variants:
        got = extwrench.estimate(est, *v)
        for key in ("force_W", "residual", "flags", "line_point_W"):
            assert np.array_equal(bits(got[key]), bits(base[key])), key


def test_batch_without_dq_differentiates_q(robot, log):
    t, q, dq, tau, reading = log
    est = extwrench.ContactEstimator(robot, CONFIG)
    got = extwrench.estimate(est, t, q, None, tau, reading)
    manual = np.empty_like(q)
    manual[0] = (q[1] - q[0]) / (t[1] - t[0])
    manual[1:] = (q[1:] - q[:-1]) / (t[1:] - t[:-1])[:, None]
    want = extwrench.estimate(est, t, q, manual, tau, reading)
    assert np.array_equal(bits(got["residual"]), bits(want["residual"]))


@pytest.mark.parametrize("change, words", [
    ({"detection": {"tau_minx": 1.0}}, ["tau_minx"]),
    ({"sensor": {"type": "laser"}}, ["sensor.type", "laser"]),
    ({"observer": {"gain": -1}}, ["gain"]),
    ({"bogus": 1}, ["bogus"]),
])
def test_config_errors_name_the_key(robot, change, words):
    config = dict(CONFIG, **change)
    with pytest.raises(extwrench.Error) as info:
        extwrench.ContactEstimator(robot, config)
    for w in words:
        assert w in str(info.value)
    assert isinstance(info.value, ValueError)


def test_config_yaml_loads_wherever_it_is_written(robot, log, tmp_path, monkeypatch):
    est = extwrench.ContactEstimator(robot, CONFIG)
    want = extwrench.estimate(est, *log)
    monkeypatch.chdir(tmp_path)
    for where, text in ((tmp_path / "x" / "y", est.config_yaml()),
                        (tmp_path / "z", est.config_yaml(tmp_path / "z")),
                        (tmp_path / "w", est.config_yaml("w"))):
        where.mkdir(parents=True)
        (where / "config.yaml").write_text(text)
        got = extwrench.estimate(str(where / "config.yaml"), *log)
        assert same(got["force_W"], want["force_W"]), where
    assert "robot: " + str(PAPER_URDF) in est.config_yaml()


def test_config_errors_match_the_file_loader(robot, tmp_path):
    # The dict goes through the project's loader: the same message as the file, but the name.
    path = tmp_path / "c.yaml"
    path.write_text("robot: %s\nsensor: {type: ft}\ndetection: {tau_minx: 1}\n" % PAPER_URDF)
    with pytest.raises(extwrench.Error) as from_file:
        extwrench.ContactEstimator(None, path)
    with pytest.raises(extwrench.Error) as from_dict:
        extwrench.ContactEstimator(robot, {"sensor": {"type": "ft"},
                                           "detection": {"tau_minx": 1}})
    tail = lambda e: str(e.value).split(": ", 1)[1]
    assert tail(from_file) == tail(from_dict)


def test_other_setup_errors(robot, tmp_path):
    with pytest.raises(extwrench.Error, match="nope.urdf"):
        extwrench.load_robot(tmp_path / "nope.urdf")
    with pytest.raises(ValueError, match="both"):
        extwrench.ContactEstimator(robot, dict(CONFIG, robot=str(PAPER_URDF)))
    with pytest.raises(TypeError, match="config"):
        extwrench.ContactEstimator(robot, 42)
    with pytest.raises(TypeError, match="config"):
        extwrench.ContactEstimator(robot, {"sensor": {"type": "ft"}, "observer": {"gain": object()}})


def test_an_estimator_from_a_robot_uses_that_robot(robot, tmp_path, monkeypatch):
    # The same file name in another directory, with another robot in it (the paper arm 1 kg
    # heavier on link 2): a relative path is resolved where the Robot was loaded, not where the
    # estimator is built.
    (tmp_path / "a" / "models").mkdir(parents=True)
    (tmp_path / "b" / "models").mkdir(parents=True)
    text = PAPER_URDF.read_text()
    (tmp_path / "a" / "models" / "arm.urdf").write_text(text)
    heavier = text.replace('<mass value="', '<mass value="1', 3)
    assert heavier != text
    (tmp_path / "b" / "models" / "arm.urdf").write_text(heavier)
    monkeypatch.chdir(tmp_path / "a")
    loaded = extwrench.load_robot("models/arm.urdf")
    monkeypatch.chdir(tmp_path / "b")
    est = extwrench.ContactEstimator(loaded, {"sensor": {"type": "none"}})
    assert str(est.robot_path) == str(tmp_path / "a" / "models" / "arm.urdf")
    q = np.full(loaded.nq, 0.3)
    zero = np.zeros(loaded.nq)
    tau = extwrench.gravity(loaded, q)
    est.reset(0.0, q, zero, tau)
    for k in range(1, 50):
        assert not est.update(1e-3 * k, q, zero, tau).contact
    # A configuration file of another robot with this Robot: refused, not merely nq compared.
    config = tmp_path / "b" / "config.yaml"
    config.write_text("robot: models/arm.urdf\nsensor: {type: none}\n")
    with pytest.raises(ValueError, match="the robot given was loaded from"):
        extwrench.ContactEstimator(loaded, str(config))
    assert extwrench.ContactEstimator(robot, str(_config_of(tmp_path, PAPER_URDF))).nq == 7


def _config_of(tmp_path, urdf):
    path = tmp_path / "same.yaml"
    path.write_text("robot: %s\nsensor: {type: none}\n" % urdf)
    return path


def run(est, log, skip_bad=None):
    t, q, dq, tau, reading = log
    est.reset(t[0], q[0], dq[0], tau[0])
    out = []
    for k in range(1, len(t)):
        if skip_bad is not None and k == 100:
            with pytest.raises((ValueError, TypeError)) as info:
                skip_bad(est, k)
            out.append(str(info.value))
        out.append(est.update(t[k], q[k], dq[k], tau[k], reading[k]))
    return out


BAD_UPDATES = {
    "nan_q": (lambda e, t, q, dq, tau, r: e.update(t, np.full(7, np.nan), dq, tau, r), "q[0]"),
    "short_dq": (lambda e, t, q, dq, tau, r: e.update(t, q, dq[:3], tau, r), "dq"),
    "int_strings": (lambda e, t, q, dq, tau, r: e.update(t, q, dq, ["x"] * 7, r), "tau"),
    "same_t": (lambda e, t, q, dq, tau, r: e.update(t - 1e-3, q, dq, tau, r), "t"),
    "nan_t": (lambda e, t, q, dq, tau, r: e.update(float("nan"), q, dq, tau, r), "t"),
    "no_reading": (lambda e, t, q, dq, tau, r: e.update(t, q, dq, tau), "reading"),
    "inf_reading": (lambda e, t, q, dq, tau, r: e.update(t, q, dq, tau, r + np.inf), "reading"),
    "short_reading": (lambda e, t, q, dq, tau, r: e.update(t, q, dq, tau, r[:3]), "reading"),
}


@pytest.mark.parametrize("name", sorted(BAD_UPDATES))
def test_bad_update_raises_and_leaves_the_state(robot, log, name):
    bad, word = BAD_UPDATES[name]
    t, q, dq, tau, reading = log
    clean = run(extwrench.ContactEstimator(robot, CONFIG), log)

    def inject(est, k):
        # At k the last good sample is k - 1: the bad one reuses sample k's values.
        bad(est, t[k], q[k], dq[k], tau[k], reading[k])

    dirty = run(extwrench.ContactEstimator(robot, CONFIG), log, inject)
    message = dirty.pop(99)
    assert word in message
    assert len(clean) == len(dirty)
    for a, b in zip(clean, dirty):
        assert np.array_equal(bits(a.residual), bits(b.residual))
        assert np.array_equal(bits(a.force_W), bits(b.force_W)) and a.flag_bits == b.flag_bits


@pytest.mark.parametrize("args, words", [
    (lambda t, q, dq, tau, r: (t[:-1], q, dq, tau, r), ["q", "shape"]),
    (lambda t, q, dq, tau, r: (t, q[:, :5], dq, tau, r), ["q", "(600, 7)", "(600, 5)"]),
    (lambda t, q, dq, tau, r: (t, q, dq, tau.astype(complex), r), ["tau", "complex"]),
    (lambda t, q, dq, tau, r: (t, q, dq, tau, None), ["reading"]),
    (lambda t, q, dq, tau, r: (t, q, dq, tau, r[:, :4]), ["reading"]),
    (lambda t, q, dq, tau, r: (np.r_[t[:10], t[9], t[11:]], q, dq, tau, r), ["t[10]", "increase"]),
    (lambda t, q, dq, tau, r: (t, np.where(np.arange(7) == 3, np.nan, q), dq, tau, r),
     ["q[0, 3]", "nan"]),
    (lambda t, q, dq, tau, r: (t, q, dq, tau, np.where(np.arange(6) == 4, np.inf, r)),
     ["reading[0, 4]", "inf"]),
])
def test_batch_bad_input(robot, log, args, words):
    est = extwrench.ContactEstimator(robot, CONFIG)
    with pytest.raises((ValueError, TypeError)) as info:
        extwrench.estimate(est, *args(*log))
    for w in words:
        assert w in str(info.value)


def test_reset_required_and_checked(robot, log):
    t, q, dq, tau, reading = log
    est = extwrench.ContactEstimator(robot, CONFIG)
    with pytest.raises(ValueError, match="reset"):
        est.update(t[1], q[1], dq[1], tau[1], reading[1])
    with pytest.raises(ValueError, match=r"q\[2\]"):
        est.reset(0.0, np.array([0, 0, np.nan, 0, 0, 0, 0]), dq[0], tau[0])


def test_no_reference_leak(robot, log):
    t, q, dq, tau, reading = log
    est = extwrench.ContactEstimator(robot, CONFIG)
    est.reset(t[0], q[0], dq[0], tau[0])
    watched = (q, dq, tau, reading, est)
    before = [sys.getrefcount(x) for x in watched]
    for k in range(1, len(t)):
        e = est.update(t[k], q[k], dq[k], tau[k], reading[k])
        e.flags, e.force_W, e.residual
    for _ in range(20):
        out = extwrench.estimate(est, t, q, dq, tau, reading)
    del out, e
    gc.collect()
    assert [sys.getrefcount(x) for x in watched] == before


def test_the_benchmark_loop_checks_its_arrays(robot):
    # benchmarks/python_bench.py's C++ loop read past short arrays and crashed on empty ones.
    from extwrench import _extwrench
    est = extwrench.ContactEstimator(robot, {"sensor": {"type": "none"}})
    t, z = np.arange(5) * 1e-3, np.zeros((5, 7))
    for args, words in (((t[:0], z[:0], z[:0], z[:0]), "t: expected at least one sample"),
                        ((t, z[:, :3], z, z), "q: expected shape (5, 7), got (5, 3)"),
                        ((t, z, z[:4], z), "dq: expected shape (5, 7), got (4, 7)")):
        with pytest.raises(ValueError, match=re.escape(words)):
            _extwrench._time_update_loop(est, *args, None)
    assert _extwrench._time_update_loop(est, t, z, z, z, None) >= 0.0


def test_write_estimates_reads_back_statuses_and_refuses_unknown_ones(robot, tmp_path):
    est = extwrench.ContactEstimator(robot, {"sensor": {"type": "none"}})
    t, z = np.arange(5) * 1e-3, np.zeros((5, 7))
    out = extwrench.estimate(est, t, z, z, z)
    out["status"] = list(out["status"])
    out["status"][2] = "non_finite:q[1]"
    extwrench.write_estimates(tmp_path / "e.csv", est, out)
    assert ",non_finite:q[1]," in (tmp_path / "e.csv").read_text().splitlines()[3]
    for bad, words in (("non_finite:q[x]", "the index is not a count in brackets"),
                       ("bogus:q[1]", "unknown code 'bogus'"),
                       ("non_finite:zz", "unknown channel 'zz'")):
        out["status"][2] = bad
        with pytest.raises(ValueError, match=re.escape("estimates['status'][2]: '%s': %s"
                                                       % (bad, words))):
            extwrench.write_estimates(tmp_path / "e.csv", est, out)


def test_small_argument_checks_and_reprs(robot):
    est = extwrench.ContactEstimator(robot, CONFIG)
    assert repr(est).startswith("<extwrench.ContactEstimator nq=7 sensor=ft contact=pure_force")
    w = extwrench.ExternalWrench(6, [20, 0, 0], [0, 0, 0.5])
    assert repr(w) == ("<extwrench.ExternalWrench body=6 force_W=(20.0, 0.0, 0.0) "
                       "point_W=(0.0, 0.0, 0.5) moment_W=(0.0, 0.0, 0.0)>")
    with pytest.raises(ValueError, match="samples must be >= 0"):
        est.request_tare(-1)  # once silently cancelled a pending tare
    z = np.zeros(7)
    est.reset(0.0, z, z, extwrench.gravity(robot, z))
    reading = extwrench.sensor_reading(robot, z, z, z, X_WS=np.array(
        [[1, 0, 0, 0], [0, 1, 0, 0], [0, 0, 1, -0.31], [0, 0, 0, 1]], dtype=float))
    e = est.update(1e-3, z, z, extwrench.gravity(robot, z), reading)
    assert e.force_covariance_W.flags.c_contiguous and e.force_covariance_W.shape == (3, 3)
    skewed = np.eye(4)
    skewed[3, 0] = 1.0
    with pytest.raises(ValueError, match=re.escape("X_WS: the bottom row of a homogeneous "
                                                   "transform must be [0, 0, 0, 1]")):
        extwrench.sensor_reading(robot, z, z, z, X_WS=skewed)
