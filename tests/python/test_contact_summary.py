"""extwrench.contact_summary and estimate()'s EstimateWarning: the line and the notes of
`extwrench estimate` for estimate()'s arrays. The counts are checked against numpy, the text and
the notes against what the command prints for the same log; the real Panda's contact-free log
(../shared/realdata, skipped when absent) is the case the note is for."""

import subprocess
import warnings

import numpy as np
import pytest

import extwrench
from conftest import SOURCE_DIR

PANDA = SOURCE_DIR.parent / "shared" / "realdata" / "franka_panda_free_motion"


def numpy_counts(out, bodies):
    contact = np.asarray(out["contact"], dtype=bool)
    starts = contact & ~np.concatenate(([False], contact[:-1]))
    links = out["link"][contact]
    return {
        "samples": len(contact),
        "contact_samples": int(contact.sum()),
        "episodes": int(starts.sum()),
        "by_link": {bodies[l]: int((links == l).sum()) for l in np.unique(links)},
    }


def cli_lines(cli, cwd, args):
    run = subprocess.run([cli] + args, cwd=cwd, capture_output=True, text=True, check=True)
    return run.stdout, run.stderr


@pytest.fixture(scope="module")
def panda(tmp_path_factory):
    if not (PANDA / "log.csv").exists():
        pytest.skip("../shared/realdata is absent")
    tmp = tmp_path_factory.mktemp("panda")
    # The README's real-arm configuration without a calibration (K = 50, filter on joints 1-4).
    config = ("robot: %s\nsensor: {type: none}\n"
              "observer: {gain: 50, residual_cutoff: [20, 20, 20, 20, 0, 0, 0]}\n"
              % (PANDA / "panda.urdf"))
    (tmp / "panda.yaml").write_text(config)
    est = extwrench.ContactEstimator(None, tmp / "panda.yaml")
    log = extwrench.read_log(PANDA / "log.csv", est)
    return {"dir": tmp, "config": config, "est": est, "log": log}


def estimate(est, log, **kwargs):
    return extwrench.estimate(est, log["t"], log["q"], log["dq"], log["tau"], log.get("reading"),
                              **kwargs)


def test_the_uncalibrated_real_panda_gets_the_commands_line_and_note(panda, cli):
    est, log = panda["est"], panda["log"]
    assert est.calibration_path is None
    with pytest.warns(extwrench.EstimateWarning, match="contact declared on") as caught:
        out = estimate(est, log)
    assert len(caught) == 1
    note = str(caught[0].message)
    assert "extwrench calibrate" in note and caught[0].filename == __file__
    summary = extwrench.contact_summary(out, est)
    counts = numpy_counts(out, est.bodies)
    assert {k: summary[k] for k in counts} == counts
    assert summary["episodes"] >= 10 and note.startswith(summary["note"] + "; in Python: ")
    assert summary["duration"] == pytest.approx(log["t"][-1] - log["t"][0])
    # The command on the same file: the same line on stdout, the same note on stderr.
    stdout, stderr = cli_lines(cli, panda["dir"], [
        "estimate", "--no-figures", "--config", "panda.yaml", "--log", str(PANDA / "log.csv"),
        "--out", "plain"])
    assert "  " + summary["text"] + "\n" in stdout, stdout
    assert "extwrench: note: panda: " + summary["note"] + "\n" in stderr, stderr
    # Asked not to, estimate() stays silent and returns the same arrays.
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        quiet = estimate(est, log, notes=False)
    np.testing.assert_array_equal(quiet["residual"], out["residual"])


def test_a_calibrated_configuration_gets_no_note(panda):
    tmp = panda["dir"]
    extwrench.calibrate(panda["est"], PANDA / "log.csv", out=tmp / "calib.yaml")
    (tmp / "calibrated.yaml").write_text(panda["config"] + "calibration: calib.yaml\n")
    est = extwrench.ContactEstimator(None, tmp / "calibrated.yaml")
    assert est.calibration_path is not None
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        out = estimate(est, panda["log"])
    assert extwrench.contact_summary(out, est)["contact_samples"] == 0


def test_the_paper_push_gets_its_line_and_no_note(paper_run, cli):
    """One push held on one link: the command's line, numpy's counts, no warning."""
    run = paper_run["dir"]
    config = run / "ft" / "config.yaml"
    est = extwrench.ContactEstimator(None, config)
    log = extwrench.read_log(run / "log.csv", est)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        out = estimate(est, log)
    summary = extwrench.contact_summary(out, est)
    counts = numpy_counts(out, est.bodies)
    assert {k: summary[k] for k in counts} == counts
    assert summary["contact_samples"] > 0 and summary["note"] == ""
    assert summary["disagreement_warning"] == ""
    stdout, _ = cli_lines(cli, run, ["estimate", "--no-figures", "--config", str(config), "--log",
                                     str(run / "log.csv"), "--out", str(run / "again")])
    assert "  " + summary["text"] + "\n" in stdout, stdout


def test_bad_columns_are_named(robot):
    est = extwrench.ContactEstimator(robot, {"sensor": {"type": "none"}})
    t = np.arange(5) * 1e-3
    good = {"t": t, "contact": np.zeros(5, bool), "link": np.full(5, -1)}
    assert extwrench.contact_summary(good, est)["samples"] == 5
    with pytest.raises(ValueError, match="link: expected shape"):
        extwrench.contact_summary(dict(good, link=np.zeros(4)), est)
    with pytest.raises(ValueError, match=r"t\[2\] is nan"):
        extwrench.contact_summary(dict(good, t=np.array([0, 1, np.nan, 3, 4.0])), est)
    with pytest.raises(KeyError):
        extwrench.contact_summary({"t": t}, est)


def test_a_log_in_milliseconds_gets_the_time_step_note(paper_run, cli, tmp_path):
    """The paper's log with t written in milliseconds: estimate() warns that the samples are
    1 s apart and names seconds, and the command notes the same for the same file; in seconds
    (above) neither says a word."""
    run = paper_run["dir"]
    config = run / "ft" / "config.yaml"
    est = extwrench.ContactEstimator(None, config)
    lines = (run / "log.csv").read_text().splitlines()
    head = lines[0].split(",")
    assert head[0] == "t"
    rows = [line.split(",", 1) for line in lines[1:2001]]
    ms = tmp_path / "log_ms.csv"
    ms.write_text("\n".join([lines[0]] + ["%.12g,%s" % (1e3 * float(t), rest)
                                          for t, rest in rows]) + "\n")
    log = extwrench.read_log(ms, est)
    assert np.diff(log["t"]).mean() == pytest.approx(1.0)
    with pytest.warns(extwrench.EstimateWarning, match="t must be in seconds") as caught:
        out = estimate(est, log)
    messages = [str(w.message) for w in caught if "t must be in seconds" in str(w.message)]
    assert len(messages) == 1 and messages[0].startswith("the samples are 1 s apart")
    summary = extwrench.contact_summary(out, est)
    assert summary["time_step_note"] == messages[0]
    _, stderr = cli_lines(cli, tmp_path, ["estimate", "--no-figures", "--config", str(config),
                                          "--log", str(ms), "--out", "ms"])
    # (the title is the configuration's scheme, as for the other notes)
    assert "extwrench: note: ft: " + summary["time_step_note"] + "\n" in stderr, stderr


def test_a_log_in_degrees_gets_the_commands_joint_range_warning(paper_run, cli, tmp_path):
    """The paper's log with its positions written in degrees: estimate() warns that a joint lies
    outside its limits on most rows, with the text the command prints for the same file; the
    log in radians (above) gets no such word."""
    run = paper_run["dir"]
    config = run / "ft" / "config.yaml"
    est = extwrench.ContactEstimator(None, config)
    lines = (run / "log.csv").read_text().splitlines()
    head = lines[0].split(",")
    q_columns = [i for i, name in enumerate(head) if name[0] == "q" and name[1:].isdigit()]
    assert len(q_columns) == est.nq
    rows = [line.split(",") for line in lines[1:2001]]
    for row in rows:
        for i in q_columns:
            row[i] = "%.12g" % np.degrees(float(row[i]))
    degrees = tmp_path / "log_degrees.csv"
    degrees.write_text("\n".join([lines[0]] + [",".join(row) for row in rows]) + "\n")
    log = extwrench.read_log(degrees, est)
    with pytest.warns(extwrench.EstimateWarning, match="in degrees") as caught:
        estimate(est, log)
    messages = [str(w.message) for w in caught if "in degrees" in str(w.message)]
    assert len(messages) == 1 and "outside its limits" in messages[0]
    _, stderr = cli_lines(cli, tmp_path, ["estimate", "--no-figures", "--config", str(config),
                                          "--log", str(degrees), "--out", "degrees"])
    assert "extwrench: warning: ft: " + messages[0] + "\n" in stderr, stderr
    radians = extwrench.read_log(run / "log.csv", est)
    with warnings.catch_warnings(record=True) as quiet:
        warnings.simplefilter("always")
        estimate(est, radians)
    assert not [w for w in quiet if "outside its limits" in str(w.message)]
