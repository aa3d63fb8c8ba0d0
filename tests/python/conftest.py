"""Shared fixtures of the Python tests: paths from the ctest environment, the paper arm."""

import os
import pathlib
import subprocess

import numpy as np
import pytest

import extwrench

SOURCE_DIR = pathlib.Path(os.environ.get("EXTWRENCH_SOURCE_DIR",
                                         pathlib.Path(__file__).resolve().parents[2])).resolve()
PAPER_URDF = SOURCE_DIR / "models" / "paper_arm.urdf"
PAPER_SCENARIO = SOURCE_DIR / "scenarios" / "paper.yaml"


def tool(variable):
    path = os.environ.get(variable)
    if not path or not os.path.exists(path):
        pytest.skip(variable + " is not set (run the tests through ctest)")
    return path


@pytest.fixture(scope="session")
def cli():
    return tool("EXTWRENCH_CLI")


@pytest.fixture(scope="session")
def dynamics_reference():
    return tool("EXTWRENCH_DYNAMICS_REFERENCE")


@pytest.fixture()
def robot():
    return extwrench.load_robot(PAPER_URDF)


@pytest.fixture(scope="session")
def paper_run(tmp_path_factory, cli):
    """The paper scenario with one seed and no figures, simulated by the CLI: DIR/log.csv,
    DIR/<scheme>/{config.yaml, estimates.csv, metrics.json}."""
    tmp = tmp_path_factory.mktemp("paper")
    text = PAPER_SCENARIO.read_text()
    text = text.replace("robot: ../models/paper_arm.urdf", "robot: " + str(PAPER_URDF))
    text = text.replace("seeds: [1, 2, 3, 4, 5]", "seeds: [1]")
    assert "seeds: [1]" in text and str(PAPER_URDF) in text, "the scenario's lines changed"
    scenario = tmp / "paper_one_seed.yaml"
    scenario.write_text(text)
    out = tmp / "run"
    subprocess.run([cli, "simulate", str(scenario), "--out", str(out), "--no-figures"],
                   check=True, capture_output=True)
    return {"scenario": scenario, "dir": out}


def random_state(rng, n):
    return (rng.uniform(-1.5, 1.5, n), rng.uniform(-1.0, 1.0, n), rng.uniform(-2.0, 2.0, n))


def bits(a):
    """The IEEE bit patterns of a float64 array (NaN payloads compared too)."""
    return np.ascontiguousarray(a, dtype=np.float64).view(np.uint64)


def same(a, b):
    """Equal arrays, float ones bit for bit (NaN equal to the same NaN)."""
    a, b = np.asarray(a), np.asarray(b)
    if a.dtype.kind == "f" or b.dtype.kind == "f":
        return a.shape == b.shape and np.array_equal(bits(a), bits(b))
    return np.array_equal(a, b)
