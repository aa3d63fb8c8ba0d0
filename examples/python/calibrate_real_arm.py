#!/usr/bin/env python3
"""A real arm's contact-free log, before and after calibration (docs/calibration.md), in Python.

Replays the log uncalibrated (estimate() warns when its contacts look like the model's error),
calibrates on the first 60 % and judges the rest (false alarms, thresholds), replays it again
with the calibration included, and draws each joint's residual against its thresholds, both
times, to one PNG.

  PYTHONPATH=build/python python3 examples/python/calibrate_real_arm.py \\
      --robot panda.urdf --log free.csv --out calibration.png
      (the Panda of ../shared/realdata/franka_panda_free_motion when it is beside the project)
  ... --residual-cutoff 20,20,20,20,0,0,0
      the README's real-arm configuration: the residual of joints 1-4 low-passed at 20 Hz
"""

import argparse
import pathlib
import tempfile
import warnings

import matplotlib

matplotlib.use("Agg")  # files only: no display needed
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

import extwrench  # noqa: E402

ROOT = pathlib.Path(__file__).resolve().parents[2]
PANDA = ROOT.parent / "shared" / "realdata" / "franka_panda_free_motion"


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawTextHelpFormatter)
    ap.add_argument("--robot", default=str(PANDA / "panda.urdf"), help="URDF of the arm")
    ap.add_argument("--log", default=str(PANDA / "log.csv"), help="contact-free log (CSV)")
    ap.add_argument("--gain", type=float, default=50.0, help="observer gain K [1/s]")
    ap.add_argument("--residual-cutoff", help="observer.residual_cutoff per joint [Hz], "
                    "comma-separated (0: no filter)")
    ap.add_argument("--holdout", type=float, default=0.4, help="share of the log judged")
    ap.add_argument("--out", default="calibration.png")
    args = ap.parse_args()

    with tempfile.TemporaryDirectory() as tmp:
        tmp = pathlib.Path(tmp)
        # Joint torques only (no base sensor); every other setting is the configuration's default.
        config = {"robot": args.robot, "sensor": {"type": "none"},
                  "observer": {"gain": args.gain}}
        if args.residual_cutoff:
            config["observer"]["residual_cutoff"] = [
                float(v) for v in args.residual_cutoff.split(",")]
        plain = extwrench.ContactEstimator(None, config)
        log = extwrench.read_log(args.log, plain)
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always", extwrench.EstimateWarning)
            before = extwrench.estimate(plain, log["t"], log["q"], log["dq"], log["tau"])
        print("uncalibrated:", extwrench.contact_summary(before, plain)["text"])
        for w in caught:
            print("  warning:", str(w.message)[:160], "...")

        # Fit on the first part, judge on the rest; then include the file in the configuration.
        cal = extwrench.calibrate(plain, args.log, holdout=args.holdout, out=tmp / "calib.yaml")
        h = cal["holdout"]
        print("calibrated on %d of %d rows; held out %d samples: %d false-alarm samples "
              "(uncalibrated %d)" % (cal["fit_rows"], cal["rows"], h["samples"],
                                     h["false_alarms"], h["uncalibrated_false_alarms"]))
        print("thresholds [N m]:", np.array2string(cal["tau_min"], precision=3))
        calibrated = extwrench.ContactEstimator(
            None, dict(config, calibration=str(tmp / "calib.yaml")))
        after = extwrench.estimate(calibrated, log["t"], log["q"], log["dq"], log["tau"])
        print("calibrated:  ", extwrench.contact_summary(after, calibrated)["text"])

    n = plain.nq
    t = log["t"]
    t_split = t[cal["fit_rows"]] if cal["fit_rows"] < len(t) else t[-1]
    fig, axes = plt.subplots(n, 2, sharex=True, figsize=(11, 1.6 * n + 1), squeeze=False)
    for col, (title, e) in enumerate((("uncalibrated", before), ("calibrated", after))):
        for i in range(n):
            ax = axes[i, col]
            ax.fill_between(t, -e["threshold"][:, i], e["threshold"][:, i], color="C2", alpha=0.2,
                            lw=0, label="threshold")
            ax.plot(t, e["residual"][:, i], "C0-", lw=0.6, label="residual")
            above = np.abs(e["residual"][:, i]) > e["threshold"][:, i]
            ax.plot(t[above], e["residual"][above, i], "r.", ms=1.5, label="above: contact")
            ax.axvline(t_split, color="k", lw=0.8, ls="--")
            ax.set_ylabel("r%d [N m]" % (i + 1))
            ax.grid(alpha=0.3)
        axes[0, col].set_title("%s: %.1f %% of the samples in contact"
                               % (title, 100.0 * np.mean(e["contact"])))
        axes[-1, col].set_xlabel("t [s] (dashed: end of the fit, held out after)")
    axes[0, 0].legend(loc="upper right", fontsize=7)
    fig.suptitle("%s: residuals against the detector's thresholds" % pathlib.Path(args.log).name)
    fig.tight_layout()
    fig.savefig(args.out, dpi=100)
    print("wrote", args.out)


if __name__ == "__main__":
    main()
