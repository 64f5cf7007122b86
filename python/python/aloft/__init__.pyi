"""Type stubs of aloft: keyword arguments are the CLI's flags in snake_case."""

import os
from typing import Any, Dict, List, Literal, Optional, Sequence, Tuple, TypedDict, Union

from typing_extensions import Unpack

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

class VehicleKeywords(TypedDict, total=False):
    """The vehicle flown and what it carries."""

    vehicle: str
    battery: Optional[str]
    payload_kg: Optional[float]

class WindKeywords(TypedDict, total=False):
    """A steady wind and its profile with height."""

    wind_speed: Optional[float]
    wind_from: Optional[float]
    wind_profile: Optional[WindProfile]
    wind_reference_height: Optional[float]
    wind_exponent: Optional[float]
    wind_roughness: Optional[float]

class AirKeywords(TypedDict, total=False):
    """The day's air: elevation (m AMSL), temperature (C), humidity (%), QNH (hPa)."""

    elevation_m: Optional[float]
    temperature_c: Optional[float]
    humidity_percent: Optional[float]
    qnh_hpa: Optional[float]

class MissionKeywords(VehicleKeywords, WindKeywords, AirKeywords, total=False):
    """How a mission is flown (`aloft mission`'s flags)."""

    wind_field: Optional[PathLike]
    gust_std: Optional[float]
    gust_seed: Optional[int]
    reserve_percent: Optional[float]
    start_percent: Optional[float]
    start_voltage_v: Optional[float]
    time_step: Optional[float]
    speed: Optional[float]
    rtl_altitude_m: Optional[float]
    corners: Optional[Literal["pass", "stop"]]
    aoa: Optional[Aoa]
    no_ground_effect: bool
    low_voltage_v: Optional[float]
    critical_voltage_v: Optional[float]

class ScenarioKeywords(MissionKeywords, total=False):
    """A mission with Monte-Carlo scenarios around it (`--samples` and the spreads)."""

    samples: Optional[int]
    seed: Optional[int]
    wind_speed_sd: Optional[float]
    wind_from_sd: Optional[float]
    payload_sd_kg: Optional[float]
    capacity_sd_percent: Optional[float]
    power_sd_percent: Optional[float]
    threads: Optional[int]

class PlanKeywords(ScenarioKeywords, total=False):
    """`aloft plan`'s own flags beyond the mission's and its scenarios' (with a plan's defaults:
    400 samples, the forecast's spreads); the rest are arguments of `plan`."""

    camera_interval_s: Optional[float]
    keep_angle: bool
    loiter_unlimited_s: Optional[float]
    confidence: Optional[float]

class EnduranceKeywords(VehicleKeywords, WindKeywords, AirKeywords, total=False):
    """`aloft endurance`'s flags."""

    course: Optional[float]
    reserve_percent: Optional[float]
    orbit_radius: Optional[float]
    orbit_speed: Optional[float]
    aoa: Optional[Aoa]
    sweep_speed: Optional[float]
    payload_sweep: Optional[Union[str, Tuple[float, float, float], Sequence[float]]]

class FlightLogKeywords(TypedDict, total=False):
    """How flight logs are read and power aligned with motion (`aloft fit` and `validate`)."""

    profile: Optional[str]
    aoa: Optional[Aoa]
    lag: Optional[float]
    max_lag: Optional[float]
    battery_instance: Optional[int]

def mission(
    path: Optional[PathLike] = None, **options: Unpack[ScenarioKeywords]
) -> Dict[str, Any]: ...
def mission_map(
    path: Optional[PathLike] = None, **options: Unpack[ScenarioKeywords]
) -> Dict[str, Any]: ...
def plan(
    path: Optional[PathLike] = None,
    *,
    output: Optional[PathLike] = None,
    force: bool = False,
    overlap_m: Optional[float] = None,
    speeds: Optional[Literal["wind", "energy", "keep"]] = None,
    max_speed: Optional[float] = None,
    **options: Unpack[PlanKeywords],
) -> Dict[str, Any]: ...
def timeseries(path: Optional[PathLike] = None, **options: Unpack[MissionKeywords]) -> Any: ...
def endurance(**options: Unpack[EnduranceKeywords]) -> Dict[str, Any]: ...
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
    **logs_options: Unpack[FlightLogKeywords],
) -> Dict[str, Any]: ...
def validate(
    logs: Union[PathLike, Sequence[PathLike]],
    vehicle: str,
    *,
    calibrate_first: Optional[float] = None,
    battery: Optional[str] = None,
    payload_kg: Optional[float] = None,
    **logs_options: Unpack[FlightLogKeywords],
) -> Dict[str, Any]: ...
def live(
    replay: PathLike,
    vehicle: str,
    *,
    route: Optional[str] = None,
    mission: Optional[PathLike] = None,
    profile: Optional[str] = None,
    every: Optional[float] = None,
    battery: Optional[str] = None,
    payload_kg: Optional[float] = None,
    reserve_percent: Optional[float] = None,
    scenarios: Optional[int] = None,
    speed: Optional[str] = None,
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
    elevation_m: Optional[float] = None,
    temperature_c: Optional[float] = None,
    humidity_percent: Optional[float] = None,
    qnh_hpa: Optional[float] = None,
) -> Dict[str, npt.NDArray[np.float64]]: ...

def vehicles() -> List[Dict[str, Any]]: ...
def calibrate_vehicle(spec: PathLike, output: PathLike) -> Dict[str, Any]: ...
