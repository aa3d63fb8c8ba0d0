"""The Python examples (examples/python/) run as a user runs them: each exits 0, writes its PNG
and prints what its docstring promises, checked against the physics of its log (the paper
rule's right link on pushes that leave every joint up to the pushed link above the threshold;
a calibrated contact-free log is quiet). The real-arm example needs ../shared/realdata."""

import re
import subprocess
import sys

import pytest

from conftest import SOURCE_DIR

pytest.importorskip("matplotlib")

EXAMPLES = SOURCE_DIR / "examples" / "python"
PANDA = SOURCE_DIR.parent / "shared" / "realdata" / "franka_panda_free_motion"


def run_example(name, tmp_path, *args):
    png = tmp_path / (name + ".png")
    run = subprocess.run([sys.executable, str(EXAMPLES / (name + ".py")), "--out", str(png)]
                         + list(args), capture_output=True, text=True, cwd=tmp_path)
    assert run.returncode == 0, run.stderr
    data = png.read_bytes()
    assert data[:8] == b"\x89PNG\r\n\x1a\n" and len(data) > 20000, "%s: %d bytes" % (png, len(data))
    assert "wrote " + str(png) in run.stdout
    return run


def test_replay_plot(tmp_path):
    run_example("replay_plot", tmp_path)


def test_threshold_sweep(tmp_path):
    run = run_example("threshold_sweep", tmp_path)
    rows = [[float(v) for v in line.split()] for line in run.stdout.splitlines()
            if re.match(r"^\s+\d+\.\d+\s", line)]
    assert len(rows) == 12
    tau_min, false_alarms, missed, _, right_link = zip(*rows)
    # Low thresholds: both pushes on their links (joint 4 feels the link4 push with 0.4 N m);
    # above 0.4 N m the link4 push goes to link2, and false alarms fall as the threshold rises.
    assert all(r > 95 for t, r in zip(tau_min, right_link) if t < 0.3)
    assert all(r < 55 for t, r in zip(tau_min, right_link) if t > 0.5)
    assert list(false_alarms) == sorted(false_alarms, reverse=True)
    assert missed[-1] > 500  # at 4 N m the link4 push is missed


def test_calibrate_real_arm(tmp_path):
    if not (PANDA / "log.csv").exists():
        pytest.skip("../shared/realdata is absent")
    run = run_example("calibrate_real_arm", tmp_path, "--residual-cutoff", "20,20,20,20,0,0,0")
    assert "warning: contact declared on" in run.stdout
    assert re.search(r"held out \d+ samples: 0 false-alarm samples \(uncalibrated [1-9]",
                     run.stdout), run.stdout
    assert re.search(r"calibrated: +contact: 0 of \d+ samples", run.stdout), run.stdout
