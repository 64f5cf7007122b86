"""The compiled module behind aloft (use the functions of `aloft`)."""

from typing import Any, Dict, List, Mapping, Optional, Tuple

import numpy as np
import numpy.typing as npt

POWER_KEYS: List[str]
DEMO_MISSION: str
DEFAULT_VEHICLE: str

class AloftError(ValueError): ...

def version() -> str: ...
def mission_json(path: Optional[str] = None, options: Optional[Mapping[str, Any]] = None) -> str: ...
def mission_map_json(path: Optional[str] = None, options: Optional[Mapping[str, Any]] = None) -> str: ...
def plan_json(
    path: Optional[str] = None,
    options: Optional[Mapping[str, Any]] = None,
    output: Optional[str] = None,
    force: bool = False,
) -> Tuple[str, List[str]]: ...
def timeseries_columns(
    path: Optional[str] = None, options: Optional[Mapping[str, Any]] = None
) -> List[Tuple[str, npt.NDArray[Any]]]: ...
def endurance_json(options: Optional[Mapping[str, Any]] = None) -> str: ...
def log_info_json(path: str, options: Optional[Mapping[str, Any]] = None) -> str: ...
def fit_json(
    logs: List[str], vehicle_template: str, options: Optional[Mapping[str, Any]] = None
) -> str: ...
def validate_json(
    logs: List[str], vehicle: str, options: Optional[Mapping[str, Any]] = None
) -> str: ...
def live_json(
    replay: str, vehicle: str, options: Optional[Mapping[str, Any]] = None
) -> str: ...
def power(
    airspeed: npt.NDArray[np.float64],
    roll: npt.NDArray[np.float64],
    pitch: npt.NDArray[np.float64],
    climb_rate: npt.NDArray[np.float64],
    air_direction_deg: Optional[npt.NDArray[np.float64]] = None,
    options: Optional[Mapping[str, Any]] = None,
) -> Dict[str, npt.NDArray[np.float64]]: ...
