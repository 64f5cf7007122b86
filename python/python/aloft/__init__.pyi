"""Type stubs of aloft: keyword arguments are the CLI's flags in snake_case."""

import os
from typing import Any, Dict, List, Literal, Optional, Sequence, Tuple, Union

import numpy as np
import numpy.typing as npt

__version__: str
POWER_KEYS: List[str]
DEMO_MISSION: str
DEFAULT_VEHICLE: str

PathLike = Union[str, os.PathLike[str]]
ArrayLike = npt.ArrayLike
Aoa = Literal["geometric", "paper"]
WindProfile = Literal["uniform", "power-law", "log"]

class AloftError(ValueError):
    """A request aloft refuses; the message is the one `aloft` prints."""

def mission(
    path: Optional[PathLike] = None,
    *,
    vehicle: str = ...,
    battery: Optional[str] = None,
    payload_kg: Optional[float] = None,
    wind_speed: Optional[float] = None,
    wind_from: Optional[float] = None,
    wind_profile: Optional[WindProfile] = None,
    wind_reference_height: Optional[float] = None,
    wind_exponent: Optional[float] = None,
    wind_roughness: Optional[float] = None,
    wind_field: Optional[PathLike] = None,
    gust_std: Optional[float] = None,
    gust_seed: Optional[int] = None,
    reserve_percent: Optional[float] = None,
    start_percent: Optional[float] = None,
    time_step: Optional[float] = None,
    speed: Optional[float] = None,
    rtl_altitude_m: Optional[float] = None,
    corners: Optional[Literal["pass", "stop"]] = None,
    aoa: Optional[Aoa] = None,
    no_ground_effect: bool = False,
    samples: Optional[int] = None,
    seed: Optional[int] = None,
    wind_speed_sd: Optional[float] = None,
    wind_from_sd: Optional[float] = None,
    payload_sd_kg: Optional[float] = None,
    capacity_sd_percent: Optional[float] = None,
    power_sd_percent: Optional[float] = None,
    threads: Optional[int] = None,
    **options: Any,
) -> Dict[str, Any]: ...
def timeseries(
    path: Optional[PathLike] = None,
    *,
    vehicle: str = ...,
    battery: Optional[str] = None,
    payload_kg: Optional[float] = None,
    wind_speed: Optional[float] = None,
    wind_from: Optional[float] = None,
    wind_profile: Optional[WindProfile] = None,
    wind_reference_height: Optional[float] = None,
    wind_exponent: Optional[float] = None,
    wind_roughness: Optional[float] = None,
    wind_field: Optional[PathLike] = None,
    gust_std: Optional[float] = None,
    gust_seed: Optional[int] = None,
    reserve_percent: Optional[float] = None,
    start_percent: Optional[float] = None,
    time_step: Optional[float] = None,
    speed: Optional[float] = None,
    rtl_altitude_m: Optional[float] = None,
    corners: Optional[Literal["pass", "stop"]] = None,
    aoa: Optional[Aoa] = None,
    no_ground_effect: bool = False,
    **options: Any,
) -> Any: ...
def endurance(
    *,
    vehicle: str = ...,
    battery: Optional[str] = None,
    payload_kg: Optional[float] = None,
    wind_speed: Optional[float] = None,
    wind_from: Optional[float] = None,
    wind_profile: Optional[WindProfile] = None,
    wind_reference_height: Optional[float] = None,
    wind_exponent: Optional[float] = None,
    wind_roughness: Optional[float] = None,
    course: Optional[float] = None,
    reserve_percent: Optional[float] = None,
    orbit_radius: Optional[float] = None,
    orbit_speed: Optional[float] = None,
    aoa: Optional[Aoa] = None,
    sweep_speed: Optional[float] = None,
    payload_sweep: Optional[Union[str, Tuple[float, float, float], Sequence[float]]] = None,
) -> Dict[str, Any]: ...
def log_info(
    path: PathLike,
    *,
    profile: Optional[str] = None,
    topics: Optional[Union[str, Sequence[str]]] = None,
    header_time: bool = False,
    battery_current_positive: bool = False,
    battery_instance: Optional[int] = None,
    max_lag: Optional[float] = None,
) -> Dict[str, Any]: ...
def fit(
    logs: Union[PathLike, Sequence[PathLike]],
    vehicle_template: str,
    *,
    free: Optional[Union[str, Sequence[str]]] = None,
    no_drag: bool = False,
    output: Optional[PathLike] = None,
    profile: Optional[str] = None,
    aoa: Optional[Aoa] = None,
    lag: Optional[float] = None,
    max_lag: Optional[float] = None,
    battery_instance: Optional[int] = None,
) -> Dict[str, Any]: ...
def validate(
    logs: Union[PathLike, Sequence[PathLike]],
    vehicle: str,
    *,
    calibrate_first: Optional[float] = None,
    battery: Optional[str] = None,
    payload_kg: Optional[float] = None,
    profile: Optional[str] = None,
    aoa: Optional[Aoa] = None,
    lag: Optional[float] = None,
    max_lag: Optional[float] = None,
    battery_instance: Optional[int] = None,
) -> Dict[str, Any]: ...
def power(
    airspeed: ArrayLike,
    roll: ArrayLike,
    pitch: ArrayLike,
    climb_rate: ArrayLike = 0.0,
    vehicle: str = ...,
    *,
    battery: Optional[str] = None,
    payload_kg: Optional[float] = None,
    without: Optional[Union[str, Sequence[str]]] = None,
    profile_cutoff: Optional[float] = None,
    aoa: Optional[Aoa] = None,
    air_direction_deg: Optional[ArrayLike] = None,
) -> Dict[str, npt.NDArray[np.float64]]: ...

def vehicles() -> List[Dict[str, Any]]: ...
def calibrate_vehicle(spec: PathLike, output: PathLike) -> Dict[str, Any]: ...
