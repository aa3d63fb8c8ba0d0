#!/usr/bin/env python3
"""Python bindings' speed against the C++ they call (issue 12, acceptance 3), in one process.

Google Benchmark cannot time Python calls, so each figure is a timeit of the Python call and,
beside it, the same C++ operation timed in C++ by a timing entry of the module
(python/bind_bench.cpp) in the same build and process:
  1. batch estimate of N samples (default 1 M): extwrench.estimate vs the C++ update loop over
     the same rows already in memory (CSV excluded on both sides), samples per second;
  2. one est.update from Python vs ContactEstimator::update in C++: the overhead per call;
  3. extwrench.rnea on the paper arm vs rnea in C++: per call.
Usage: PYTHONPATH=build/python python3 benchmarks/python_bench.py [--samples N] [--repeat R]
"""

import argparse
import pathlib
import tempfile
import timeit

import numpy as np

import extwrench
from extwrench import _extwrench

ROOT = pathlib.Path(__file__).resolve().parents[1]
CONFIG = {"sensor": {"type": "ft", "pose": {"xyz": [0, 0, -0.31], "rpy": [0, 0, 0]}},
          "contact": {"model": "pure_force"}, "observer": {"gain": 100},
          "detection": {"tau_min": 1.0, "f_min": 5.0}}


def paper_log(runs, samples):
    """The paper scenario's first seed (6000 rows), tiled in time to `samples` rows."""
    log = runs[0]["log"]
    rows = len(log["t"])
    reps = -(-samples // rows)
    dt = log["t"][1] - log["t"][0]
    t = np.arange(rows * reps) * dt
    tile = lambda a: np.tile(a, (reps, 1))[:samples]
    return (t[:samples], tile(log["q"]), tile(log["dq"]), tile(log["tau"]), tile(log["reading"]))


def best(fn, repeat, number=1):
    return min(timeit.repeat(fn, repeat=repeat, number=number)) / number


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--samples", type=int, default=1_000_000)
    ap.add_argument("--repeat", type=int, default=3)
    args = ap.parse_args()
    robot = extwrench.load_robot(ROOT / "models" / "paper_arm.urdf")
    est = extwrench.ContactEstimator(robot, CONFIG)
    # One seed is enough: the paper scenario with seeds: [1], in a temporary directory.
    with tempfile.TemporaryDirectory() as tmp:
        text = (ROOT / "scenarios" / "paper.yaml").read_text()
        text = text.replace("robot: ../models/paper_arm.urdf",
                            "robot: " + str(ROOT / "models" / "paper_arm.urdf"))
        text = text.replace("seeds: [1, 2, 3, 4, 5]", "seeds: [1]")
        scenario = pathlib.Path(tmp) / "paper1.yaml"
        scenario.write_text(text)
        runs = extwrench.simulate(scenario)
    t, q, dq, tau, reading = paper_log(runs, args.samples)
    n = len(t)

    py_batch = best(lambda: extwrench.estimate(est, t, q, dq, tau, reading), args.repeat)
    cpp_batch = min(_extwrench._time_update_loop(est, t, q, dq, tau, reading)
                    for _ in range(args.repeat))
    print("batch estimate, %d samples: Python %.3f s (%.0f samples/s), C++ loop %.3f s "
          "(%.0f samples/s): %.1f %% of the C++ rate"
          % (n, py_batch, n / py_batch, cpp_batch, n / cpp_batch, 100 * cpp_batch / py_batch))

    calls = 200_000
    k0 = 3000  # a sample in contact
    q0, dq0, tau0, r0 = q[k0], dq[k0], tau[k0], reading[k0]
    live = extwrench.ContactEstimator(robot, CONFIG)
    live.reset(0.0, q0, dq0, tau0)
    clock = iter(np.arange(1, 10 * calls * (args.repeat + 1)) * 1e-3)
    upd = live.update
    py_update = best(lambda: upd(next(clock), q0, dq0, tau0, r0), args.repeat, calls)
    cpp_update = min(_extwrench._time_update(est, 0.0, 1e-3, q0, dq0, tau0, r0, calls)
                     for _ in range(args.repeat))
    print("est.update: Python %.3f us per call, C++ update %.3f us: overhead %.3f us"
          % (1e6 * py_update, 1e6 * cpp_update, 1e6 * (py_update - cpp_update)))

    ddq0 = np.zeros(robot.nq)
    rnea = extwrench.rnea
    py_rnea = best(lambda: rnea(robot, q0, dq0, ddq0), args.repeat, calls)
    cpp_rnea = min(_extwrench._time_rnea(robot, q0, dq0, ddq0, calls) for _ in range(args.repeat))
    print("rnea (paper arm, 7 joints): Python %.3f us per call, C++ %.3f us"
          % (1e6 * py_rnea, 1e6 * cpp_rnea))


if __name__ == "__main__":
    main()
