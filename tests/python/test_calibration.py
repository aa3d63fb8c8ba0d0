"""extwrench.calibrate: the same calibration as `extwrench calibrate` (the CALIB.yaml text byte
for byte), its report as Python values, a calibrated estimator from the file, and bad options
named by their Python keyword. The real Panda's contact-free log (../shared/realdata) is used
where present; the simulated free motion of scenarios/paper_free_motion.yaml always."""

import re
import resource
import signal
import subprocess

import numpy as np
import pytest

import extwrench
from conftest import SOURCE_DIR

PANDA = SOURCE_DIR.parent / "shared" / "realdata" / "franka_panda_free_motion"


@pytest.fixture(scope="module")
def free_run(cli, tmp_path_factory):
    """8 s of the free-motion rehearsal (friction, offsets, 19-bit encoders), simulated by the
    CLI: DIR/log.csv and DIR/ft/config.yaml."""
    tmp = tmp_path_factory.mktemp("free")
    text = (SOURCE_DIR / "scenarios" / "paper_free_motion.yaml").read_text()
    text = text.replace("robot: ../models/paper_arm.urdf",
                        "robot: " + str(SOURCE_DIR / "models" / "paper_arm.urdf"))
    text = text.replace("duration: 60.0", "duration: 8.0")
    assert "duration: 8.0" in text, "the scenario's lines changed"
    (tmp / "free.yaml").write_text(text)
    subprocess.run([cli, "simulate", str(tmp / "free.yaml"), "--out", str(tmp / "run"),
                    "--no-figures"], check=True, capture_output=True)
    return tmp / "run"


def test_calibrate_writes_the_clis_file_and_reports_it(free_run, cli, tmp_path):
    config = free_run / "ft" / "config.yaml"
    log = free_run / "log.csv"
    run = subprocess.run([cli, "calibrate", "--config", str(config), "--log", str(log), "--out",
                          str(tmp_path / "cli.yaml"), "--holdout", "0.4"], check=True,
                         capture_output=True, text=True)
    est = extwrench.ContactEstimator(None, config)
    cal = extwrench.calibrate(est, log, holdout=0.4, out=tmp_path / "py.yaml")
    assert (tmp_path / "py.yaml").read_text() == (tmp_path / "cli.yaml").read_text()
    assert cal["yaml"] == (tmp_path / "cli.yaml").read_text()
    # The printed report: the command's stdout after its first line (rows, time, file).
    first, rest = run.stdout.split("\n", 1)
    assert first.startswith("extwrench calibrate: 8001 rows, fit on 4800 (")
    assert cal["report"] == rest and "holdout: 3201 samples" in rest
    # The report as values, against the scenario's friction (docs/calibration.md's rehearsal).
    n = est.nq
    assert cal["rows"] == 8001 and cal["fit_rows"] == int(8001 * 0.6)
    f = cal["friction"]
    assert f["sign"] == "tanh" and f["viscous"].shape == (n,)
    scenario = (free_run.parent / "free.yaml").read_text()
    # The friction the scenario put into the logged torques; 5 % over 12 s of fit is the CLI
    # rehearsal's (test_cli_replay.cpp), here 4.8 s fit joint 2's D to -4.8 %.
    for key in ("viscous", "coulomb"):
        line = re.search(r"^\s+%s: \[([^]]*)\]" % key, scenario, re.M)
        truth = [float(v) for v in line.group(1).split(",")]
        np.testing.assert_allclose(f[key], truth, rtol=0.1, err_msg=key)
    assert cal["tau_min"].shape == (n,) and np.all(cal["tau_min"] > 0)
    assert cal["sensor_bias"].shape == (6,) and cal["f_min"] > 0
    assert len(cal["joints"]) == n and all(j["rms_after"] < j["rms_before"] for j in cal["joints"])
    assert {p["kind"] for p in cal["patterns"]} >= {"coulomb"}
    h = cal["holdout"]
    assert h["false_alarms"] == 0 and h["uncalibrated_false_alarms"] > 0.9 * h["samples"]
    assert h["min_force_calibrated"].shape == (n,)
    # The file included in a configuration: the estimator is quiet on the same free motion.
    calibrated = extwrench.ContactEstimator(
        None, _with_calibration(config, tmp_path / "py.yaml", tmp_path))
    logd = extwrench.read_log(log, calibrated)
    out = extwrench.estimate(calibrated, logd["t"], logd["q"], logd["dq"], logd["tau"],
                             logd.get("reading"))
    assert not out["contact"][int(0.6 * len(out["contact"])):].any()


def _with_calibration(config, calib, tmp_path):
    text = config.read_text().replace("robot: ../model_estimator.urdf",
                                      "robot: " + str(config.parent.parent /
                                                      "model_estimator.urdf"))
    path = tmp_path / "calibrated.yaml"
    path.write_text(text + "calibration: %s\n" % calib)
    return path


def test_bad_options_are_named_by_their_keyword(free_run):
    est = extwrench.ContactEstimator(None, free_run / "ft" / "config.yaml")
    log = free_run / "log.csv"
    for kwargs, words in [({"sign": "coulomb"}, "sign: expected 'tanh', 'sigmoid' or 'dahl'"),
                          ({"thresholds": "fast"}, "thresholds: expected 'auto'"),
                          ({"sign": "dahl", "smoothing_velocity": 0.01},
                           "smoothing_velocity: not used with sign='dahl'"),
                          ({"presliding_displacement": 0.002}, "only with sign='dahl'"),
                          ({"false_alarms_per_hour": 0.0}, "false_alarms_per_hour"),
                          ({"holdout": 1.0}, "holdout: expected a fraction in [0, 1)")]:
        with pytest.raises(ValueError) as info:
            extwrench.calibrate(est, log, **kwargs)
        assert words in str(info.value), (kwargs, str(info.value))
    with pytest.raises(ValueError) as info:
        extwrench.calibrate(est, log.parent / "missing.csv")
    assert "missing.csv" in str(info.value)


@pytest.mark.skipif(not (PANDA / "log.csv").exists(), reason="../shared/realdata is absent")
def test_a_failed_write_keeps_the_previous_file(free_run, tmp_path):
    """A write that fails (a file size limit stands for a full disk) raises, naming the file, and
    leaves the calibration written before as it was: no truncated CALIB.yaml to include. The
    first write creates the missing directory."""
    est = extwrench.ContactEstimator(None, free_run / "ft" / "config.yaml")
    path = tmp_path / "calibrations" / "calib.yaml"
    extwrench.calibrate(est, free_run / "log.csv", out=path)
    previous = path.read_bytes()
    assert len(previous) > 1024
    handler = signal.signal(signal.SIGXFSZ, signal.SIG_IGN)
    limits = resource.getrlimit(resource.RLIMIT_FSIZE)
    resource.setrlimit(resource.RLIMIT_FSIZE, (1024, limits[1]))
    try:
        with pytest.raises(extwrench.Error, match="calib.yaml.partial: write failed"):
            extwrench.calibrate(est, free_run / "log.csv", holdout=0.4, out=path)
    finally:
        resource.setrlimit(resource.RLIMIT_FSIZE, limits)
        signal.signal(signal.SIGXFSZ, handler)
    assert path.read_bytes() == previous
    assert sorted(p.name for p in path.parent.iterdir()) == ["calib.yaml"]


def test_real_panda_holdout_is_quiet_with_calibration():
    est = extwrench.ContactEstimator(extwrench.load_robot(PANDA / "panda.urdf"),
                                     {"sensor": {"type": "none"},
                                      "observer": {"gain": 50,
                                                   "residual_cutoff": [20, 20, 20, 20, 0, 0, 0]}})
    cal = extwrench.calibrate(est, PANDA / "log.csv", holdout=0.4)
    h = cal["holdout"]
    assert h["false_alarms"] == 0 and h["uncalibrated_false_alarms"] > 1000
    # The model check names the wrist's friction as the real arm's (docs/calibration.md).
    assert any(p["kind"] == "coulomb" and p["joint"] == 7 for p in cal["patterns"])
