#!/usr/bin/env python3
"""Replays a robot log through the estimator and plots the estimated against the true force.

  PYTHONPATH=build/python python3 examples/python/replay_plot.py --out force.png
      simulates the paper scenario (one seed) and replays its log with the ft scheme;
  ... --config CONFIG.yaml --log LOG.csv --out force.png
      replays your own log (true_f* columns, when present, are drawn too).
"""

import argparse
import pathlib
import tempfile

import matplotlib

matplotlib.use("Agg")  # files only: no display needed
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

import extwrench  # noqa: E402

ROOT = pathlib.Path(__file__).resolve().parents[2]


def paper_run(tmp):
    """The paper scenario with one seed: DIR/log.csv and DIR/ft/config.yaml."""
    text = (ROOT / "scenarios" / "paper.yaml").read_text()
    text = text.replace("robot: ../models/paper_arm.urdf",
                        "robot: " + str(ROOT / "models" / "paper_arm.urdf"))
    text = text.replace("seeds: [1, 2, 3, 4, 5]", "seeds: [1]")
    scenario = pathlib.Path(tmp) / "paper1.yaml"
    scenario.write_text(text)
    (run,) = extwrench.simulate(scenario, pathlib.Path(tmp) / "run")
    return run["dir"] / "ft" / "config.yaml", run["dir"] / "log.csv"


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawTextHelpFormatter)
    ap.add_argument("--config")
    ap.add_argument("--log")
    ap.add_argument("--out", default="force.png")
    args = ap.parse_args()
    with tempfile.TemporaryDirectory() as tmp:
        config, log_path = (args.config, args.log) if args.log else paper_run(tmp)
        est = extwrench.ContactEstimator(None, config)
        log = extwrench.read_log(log_path, est)
    e = extwrench.estimate(est, log["t"], log["q"], log["dq"], log["tau"], log.get("reading"))

    fig, axes = plt.subplots(4, 1, sharex=True, figsize=(9, 9))
    for i, axis in enumerate("xyz"):
        ax = axes[i]
        if "true_force_W" in log:
            ax.plot(log["t"], log["true_force_W"][:, i], "k-", lw=2.5, alpha=0.35, label="true")
        ax.plot(e["t"], e["force_W"][:, i], "C0-", lw=1.0, label="estimated")
        ax.set_ylabel("F%s [N] (world)" % axis)
        ax.grid(alpha=0.3)
    axes[0].legend(loc="upper right")
    axes[0].set_title("%s: estimated vs true external force" % pathlib.Path(config).parent.name)
    if "true_force_W" in log:
        err = np.linalg.norm(np.nan_to_num(e["force_W"]) - log["true_force_W"], axis=1)
        axes[3].semilogy(e["t"], np.maximum(err, 1e-6), "C3-", lw=0.8)
        axes[3].set_ylabel("|F_est - F| [N]")
    else:
        axes[3].plot(e["t"], e["contact"], "C2-")
        axes[3].set_ylabel("contact")
    axes[3].set_xlabel("t [s]")
    axes[3].grid(alpha=0.3)
    fig.tight_layout()
    fig.savefig(args.out, dpi=110)
    print("wrote", args.out)


if __name__ == "__main__":
    main()
