"""extwrench: external forces and moments on a robot arm from joint torques and a base sensor.

Python bindings of the C++ library (docs/python.md). Arrays are numpy float64, one row per
sample; frames follow docs/conventions.md (``_W`` world = the robot's root frame, ``_S`` the
base sensor's frame, ``_L`` the contact link's frame). C++ errors raise :class:`Error` (a
``ValueError``) with the library's message (``file:line: key: what``).
"""

from __future__ import annotations

import os
import tempfile
import warnings
from typing import Any, Dict, List, Optional, Union

import numpy as np

from ._extwrench import (  # noqa: F401  (re-exported)
    ContactEstimator,
    Error,
    Estimate,
    ExternalWrench,
    Robot,
    __version__,
    bias,
    calibrate,
    coriolis_matrix,
    crba,
    forward_dynamics,
    forward_kinematics,
    frame_pose,
    gravity,
    jacobian,
    load_robot,
    metrics,
    read_log,
    rnea,
    sensor_reading,
    write_estimates,
)
from . import _extwrench

# The C++ names (dynamics/rnea.hpp) beside the short ones.
bias_torques = bias
gravity_torques = gravity

__all__ = [
    "ContactEstimator", "Error", "Estimate", "ExternalWrench", "Robot", "__version__", "bias",
    "EstimateWarning", "bias_torques", "calibrate", "contact_summary", "coriolis_matrix", "crba",
    "estimate", "forward_dynamics", "forward_kinematics", "frame_pose", "gravity",
    "gravity_torques", "jacobian", "load_robot", "metrics", "read_log", "rnea", "sensor_reading",
    "simulate", "write_estimates",
]

_AXES = ("x", "y", "z")


class EstimateWarning(UserWarning):
    """What `extwrench estimate` writes to stderr after a replay, for estimate()'s arrays: contacts
    that look like the model's error (a note to calibrate, for configurations without one), or
    contact samples that mostly carry 'disagreement' (docs/python.md). Silence it with
    ``warnings.simplefilter("ignore", extwrench.EstimateWarning)``."""


def _estimator_for(source: Any, reading: Any) -> ContactEstimator:
    if isinstance(source, ContactEstimator):
        return source
    if isinstance(source, Robot):
        # A robot alone: the sensor type follows the readings given (none, force or ft).
        if reading is None:
            sensor = "none"
        else:
            sensor = "force" if np.shape(reading)[-1] == 3 else "ft"
        return ContactEstimator(source, {"sensor": {"type": sensor}})
    return ContactEstimator(None, source)


def estimate(source: Union[ContactEstimator, Robot, Dict[str, Any], str, os.PathLike],
             t: Any, q: Any, dq: Any, tau: Any, reading: Any = None, *,
             notes: bool = True) -> Dict[str, np.ndarray]:
    """Runs a whole log through a fresh estimator (the loop is C++, the GIL released).

    source: a ContactEstimator (its configuration; the object itself is not changed), a
    configuration dict (with 'robot') or file, or a Robot (sensor type from `reading`).
    t: (N,) strictly increasing [s]; q, dq, tau: (N, n) (dq None: differentiated as the log
    reader does); reading: (N, 6) [f; n] or (N, 3) f in the sensor frame, or None.
    The first row resets the estimator and is reported free with a zero residual, as
    `extwrench estimate` does. Returns the columns of estimates.csv (docs/log_format.md):
    t, contact (bool), link (body index, -1 when no contact; names: source.bodies),
    fx fy fz, mx my mz, px py pz, lx ly lz (views of force_W, moment_W, point_W,
    line_point_W, each (N, 3), world frame), status (str), cond, r1..rn (views of residual
    (N, n)); besides: flags (uint32 bits), point_L, line_direction_W (N, 3), surface_distance.
    With notes, what `extwrench estimate` notes on stderr is an EstimateWarning: contacts that
    look like the model's error (when the configuration includes no calibration), mostly
    flagged 'disagreement', mostly on the base alone (the sensor's sign, pose or bias?), samples
    more than 50 ms apart on average (t not in seconds?), a gap in t, or positions far outside
    the joint limits (degrees? a glitch?).
    contact_summary() gives the counts.
    """
    est = _estimator_for(source, reading)
    out = _extwrench._estimate(est, t, q, dq, tau, reading)
    if notes:
        summary = _extwrench._contact_summary(est, out["t"], out["contact"], out["link"],
                                              out["flags"])
        if summary["disagreement_warning"]:
            warnings.warn(summary["disagreement_warning"], EstimateWarning, stacklevel=2)
        if summary["base_contact_warning"]:
            warnings.warn(summary["base_contact_warning"], EstimateWarning, stacklevel=2)
        if summary["time_step_note"]:
            warnings.warn(summary["time_step_note"], EstimateWarning, stacklevel=2)
        if summary["time_gap_note"]:
            warnings.warn(summary["time_gap_note"], EstimateWarning, stacklevel=2)
        joint_range = _extwrench._joint_range_note(est, t, q)
        if joint_range:
            warnings.warn(joint_range, EstimateWarning, stacklevel=2)
        if summary["note"] and est.calibration_path is None:
            warnings.warn(summary["note"] + "; in Python: extwrench.calibrate(estimator, "
                          "'FREE.csv', out='CALIB.yaml')", EstimateWarning, stacklevel=2)
    # An object array of the few distinct texts: 8 bytes a row, not a fixed-width string each.
    names = np.empty(len(out["status_names"]), dtype=object)
    names[:] = out.pop("status_names")
    out["status"] = names[out.pop("status_index")]
    for key, prefix in (("force_W", "f"), ("moment_W", "m"), ("point_W", "p"),
                        ("line_point_W", "l")):
        for i, axis in enumerate(_AXES):
            out[prefix + axis] = out[key][:, i]
    for i in range(out["residual"].shape[1]):
        out["r%d" % (i + 1)] = out["residual"][:, i]
    return out


def contact_summary(estimates: Dict[str, Any],
                    source: Union[ContactEstimator, Robot, Dict[str, Any], str, os.PathLike]
                    ) -> Dict[str, Any]:
    """The estimates at a glance, as `extwrench estimate` prints them after a replay.

    estimates: estimate()'s dict (or any dict with its t, contact, link and optionally flags).
    source: what names the links (a ContactEstimator, Robot, configuration dict or file).
    Returns samples, contact_samples, episodes (contacts declared anew), disagreement_samples,
    by_link {link name: contact samples}, duration [s], text (the command's line "contact: ..."),
    note (the note to calibrate when the contacts look like the model's error, else ""),
    disagreement_warning (else ""), base_contact_warning (most contact samples on the base
    alone, else ""), time_step_note (when the samples are more than 50 ms apart on average: t
    not in seconds?, else "") and time_gap_note (one step over 50 ms and 20 times the mean, else
    "").
    """
    est = _estimator_for(source, None)
    return _extwrench._contact_summary(est, estimates["t"], estimates["contact"],
                                       estimates["link"], estimates.get("flags"))


def simulate(scenario: Union[str, os.PathLike], out_dir: Optional[Union[str, os.PathLike]] = None,
             figures: bool = False, package_path: Optional[List[str]] = None) -> List[Dict[str, Any]]:
    """Runs a simulation scenario (docs/simulation.md) as `extwrench simulate` does.

    Files go to out_dir (a temporary directory, removed afterwards, when None). Returns one dict
    per seed: seed, dir, samples, peak_condition, peak_time, notes (the run's notes on the
    scenario, also on stderr), log (read_log's arrays, truth included) and estimates
    {scheme: estimate()'s arrays}, equal to each scheme's estimates.csv.
    """
    if out_dir is None:
        with tempfile.TemporaryDirectory(prefix="extwrench_") as tmp:
            return simulate(scenario, os.path.join(tmp, "run"), figures, package_path)
    runs = _extwrench._run_scenario(scenario, out_dir, figures, package_path or [])
    for run in runs:
        run["estimates"] = {}
        log_path = os.path.join(run["dir"], "log.csv")
        for scheme in run["schemes"]:
            est = ContactEstimator(None, os.path.join(run["dir"], scheme, "config.yaml"))
            if "log" not in run:
                run["log"] = read_log(log_path, est)
            log = run["log"]
            # The scenario's replay already printed its warnings; the logs carry truth.
            run["estimates"][scheme] = estimate(est, log["t"], log["q"], log["dq"], log["tau"],
                                                log.get("reading"), notes=False)
    return runs
