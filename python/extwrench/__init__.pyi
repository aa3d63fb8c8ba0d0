import os
from typing import Any, Dict, List, Optional, Union

import numpy as np
import numpy.typing as npt

from ._extwrench import (
    ContactEstimator as ContactEstimator,
    Error as Error,
    Estimate as Estimate,
    ExternalWrench as ExternalWrench,
    Robot as Robot,
    __version__ as __version__,
    bias as bias,
    calibrate as calibrate,
    coriolis_matrix as coriolis_matrix,
    crba as crba,
    forward_dynamics as forward_dynamics,
    forward_kinematics as forward_kinematics,
    frame_pose as frame_pose,
    gravity as gravity,
    jacobian as jacobian,
    load_robot as load_robot,
    metrics as metrics,
    read_log as read_log,
    rnea as rnea,
    sensor_reading as sensor_reading,
    write_estimates as write_estimates,
)

bias_torques = bias
gravity_torques = gravity

class EstimateWarning(UserWarning): ...

def estimate(source: Union[ContactEstimator, Robot, Dict[str, Any], str, os.PathLike],
             t: npt.ArrayLike, q: npt.ArrayLike, dq: Optional[npt.ArrayLike],
             tau: npt.ArrayLike, reading: Optional[npt.ArrayLike] = ..., *,
             notes: bool = ...) -> Dict[str, np.ndarray]: ...
def contact_summary(estimates: Dict[str, Any],
                    source: Union[ContactEstimator, Robot, Dict[str, Any], str, os.PathLike]
                    ) -> Dict[str, Any]: ...
def simulate(scenario: Union[str, os.PathLike],
             out_dir: Optional[Union[str, os.PathLike]] = ..., figures: bool = ...,
             package_path: Optional[List[str]] = ...) -> List[Dict[str, Any]]: ...
