"""Acceptance 2 of issue 12: extwrench.estimate on the paper scenario's log gives the same numbers
as `extwrench estimate` (bit for bit), and the log / estimates / metrics I/O agrees with the CLI's
files."""

import csv
import json
import re
import subprocess

import numpy as np
import pytest

import extwrench
from conftest import bits

SCHEMES = ["ft", "no_sensor"]


def read_csv(path):
    with open(path, newline="") as f:
        rows = list(csv.reader(f))
    return rows[0], rows[1:]


def number(text):
    return float(text) if text != "" else np.nan


def candidate_names(est, masks):
    """The estimates.csv cells of link_candidates from the batch's bit masks (bit l: body l)."""
    return ["|".join(est.bodies[l] for l in range(64) if int(m) >> l & 1) for m in masks]


@pytest.fixture(scope="module")
def cli_estimates(paper_run, cli, tmp_path_factory):
    """`extwrench estimate` on the simulated log, per scheme."""
    out = {}
    for scheme in SCHEMES:
        d = tmp_path_factory.mktemp("est_" + scheme)
        subprocess.run([cli, "estimate", "--config", str(paper_run["dir"] / scheme / "config.yaml"),
                        "--log", str(paper_run["dir"] / "log.csv"), "--out", str(d),
                        "--no-figures", "--metrics-from", "0.2"], check=True, capture_output=True)
        out[scheme] = d
    return out


@pytest.mark.parametrize("scheme", SCHEMES)
def test_estimate_is_bit_identical_to_the_cli(paper_run, cli_estimates, scheme, tmp_path):
    est = extwrench.ContactEstimator(None, paper_run["dir"] / scheme / "config.yaml")
    log = extwrench.read_log(paper_run["dir"] / "log.csv", est)
    got = extwrench.estimate(est, log["t"], log["q"], log["dq"], log["tau"], log.get("reading"))
    header, rows = read_csv(cli_estimates[scheme] / "estimates.csv")
    assert len(rows) == len(got["t"]) > 1000
    columns = list(zip(*rows))
    for name, cells in zip(header, columns):
        if name == "status":
            assert list(got["status"]) == list(cells)
        elif name == "link":
            names = [est.bodies[i] if i >= 0 else "" for i in got["link"]]
            assert names == list(cells)
        elif name == "link_candidates":
            assert candidate_names(est, got["link_candidates"]) == list(cells)
        elif name == "contact":
            assert [str(int(c)) for c in got["contact"]] == list(cells)
        else:
            want = np.array([number(c) for c in cells])
            assert np.array_equal(bits(got[name]), bits(want)), name
    # The contact of the scenario (20 N on link 6) is what the estimates show after 0.2 s.
    assert got["contact"][got["t"] > 0.2].mean() > 0.9
    # And written back, the file is the CLI's byte for byte.
    path = tmp_path / "estimates.csv"
    extwrench.write_estimates(path, est, got)
    assert path.read_bytes() == (cli_estimates[scheme] / "estimates.csv").read_bytes()
    # The scenario run's own estimates.csv (replayed inside `simulate`) too.
    assert path.read_bytes() == (paper_run["dir"] / scheme / "estimates.csv").read_bytes()


def test_metrics_equal_metrics_json(paper_run, cli_estimates):
    scheme = "ft"
    est = extwrench.ContactEstimator(None, paper_run["dir"] / scheme / "config.yaml")
    log = extwrench.read_log(paper_run["dir"] / "log.csv", est)
    got = extwrench.estimate(est, log["t"], log["q"], log["dq"], log["tau"], log.get("reading"))
    m = extwrench.metrics(log, got, start=0.2)
    window = json.loads((cli_estimates[scheme] / "metrics.json").read_text())["windows"][0]
    for key in ("samples", "contact_samples", "free_samples", "false_alarms",
                "false_alarms_release", "isolation_accuracy",
                "right_link_samples", "missed_detections", "force_not_estimated"):
        assert m[key] == window[key], key
    for key in ("force_error", "moment_error", "line_of_action_distance"):
        assert m[key]["samples"] == window[key]["samples"], key
        for stat in ("rms", "max"):
            w = window[key][stat]
            assert (np.isnan(m[key][stat]) and w is None) or m[key][stat] == w, (key, stat)
    # A window that would count every sample or exclude nothing without a word is refused, as
    # the CLI refuses --metrics-from nan and --exclude 2:1.
    for window, words in (({"start": float("nan")}, "start < stop, got nan, inf"),
                          ({"start": 2.0, "stop": 1.0}, "start < stop, got 2.0, 1.0"),
                          ({"exclude": [(0.5, 0.6), (2.0, 1.0)]},
                           "exclude[1]: expected (from, to) in seconds with from < to, got (2.0, 1.0)")):
        with pytest.raises(ValueError, match=re.escape(words)):
            extwrench.metrics(log, got, **window)


def test_read_log_matches_the_csv(paper_run, robot):
    log = extwrench.read_log(paper_run["dir"] / "log.csv", robot)
    header, rows = read_csv(paper_run["dir"] / "log.csv")
    col = {name: np.array([number(r[i]) if name != "true_link" else 0 for r in rows])
           for i, name in enumerate(header)}
    n = robot.nq
    assert np.array_equal(log["t"], col["t"])
    for i in range(n):
        assert np.array_equal(log["q"][:, i], col["q%d" % (i + 1)])
        assert np.array_equal(log["tau"][:, i], col["tau%d" % (i + 1)])
    for i, c in enumerate(["fs_x", "fs_y", "fs_z", "ms_x", "ms_y", "ms_z"]):
        assert np.array_equal(log["reading"][:, i], col[c])
    links = [r[header.index("true_link")] for r in rows]
    assert list(log["true_link"]) == links
    assert ((log["true_body"] >= 0) == (np.array(links) != "")).all()


def test_simulate_returns_the_files_numbers(paper_run):
    runs = extwrench.simulate(paper_run["scenario"])
    assert len(runs) == 1 and sorted(runs[0]["estimates"]) == sorted(SCHEMES)
    header, rows = read_csv(paper_run["dir"] / "ft" / "estimates.csv")
    fx = np.array([number(r[header.index("fx")]) for r in rows])
    assert np.array_equal(bits(runs[0]["estimates"]["ft"]["fx"]), bits(fx))
    log = runs[0]["log"]
    assert log["q"].shape == (len(rows), 7) and "true_force_W" in log


def test_simulate_notes_a_push_no_pusher_could_reach(paper_run, tmp_path):
    """The paper's scenario with geometry isolation: its point on link6 lies behind link7's
    capsule along the force (docs/simulation.md); with the paper's rule (the file's) no note."""
    assert extwrench.simulate(paper_run["scenario"])[0]["notes"] == []
    text = paper_run["scenario"].read_text().replace("duration: 6.0", "duration: 0.2")
    assert "duration: 0.2" in text and "isolation: residual" in text
    scenario = tmp_path / "geometry.yaml"
    scenario.write_text(text.replace("isolation: residual", "isolation: geometry"))
    (run,) = extwrench.simulate(scenario)
    assert len(run["notes"]) == 1, run["notes"]
    assert run["notes"][0].startswith("forces[0] (link6, point (0, 0, 0.1)): a pusher along the "
                                      "force meets link7 ")


def test_link_candidates_of_geometry_isolation_match_the_cli(paper_run, cli):
    # The scenario's push lies outside link 6's capsule: geometry isolation names link 7 and
    # keeps link 6 as a candidate, so the column is not empty.
    text = (paper_run["dir"] / "ft" / "config.yaml").read_text()
    assert "isolation: residual" in text
    config = paper_run["dir"] / "ft" / "geometry.yaml"  # beside config.yaml: its relative paths
    config.write_text(text.replace("isolation: residual", "isolation: geometry"))
    out = paper_run["dir"] / "ft_geometry"
    subprocess.run([cli, "estimate", "--config", str(config), "--log",
                    str(paper_run["dir"] / "log.csv"), "--out", str(out), "--no-figures"],
                   check=True, capture_output=True)
    est = extwrench.ContactEstimator(None, config)
    log = extwrench.read_log(paper_run["dir"] / "log.csv", est)
    got = extwrench.estimate(est, log["t"], log["q"], log["dq"], log["tau"], log["reading"])
    header, rows = read_csv(out / "estimates.csv")
    cells = [r[header.index("link_candidates")] for r in rows]
    assert candidate_names(est, got["link_candidates"]) == cells
    assert sum(c != "" for c in cells) > len(cells) // 2
    # One update at a time gives the same candidates as the batch.
    est.reset(log["t"][0], log["q"][0], log["dq"][0], log["tau"][0])
    for k in range(1, len(log["t"])):
        e = est.update(log["t"][k], log["q"][k], log["dq"][k], log["tau"][k], log["reading"][k])
        if k % 97 == 0:
            assert e.link_candidates == [l for l in range(64) if int(got["link_candidates"][k]) >> l & 1], k
    # And written back, the column is the CLI's.
    path = out / "again.csv"
    extwrench.write_estimates(path, est, got)
    assert path.read_bytes() == (out / "estimates.csv").read_bytes()
