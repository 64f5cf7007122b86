"""aloft from Python: the energy and feasibility of multirotor flights.

The same engine as the ``aloft`` command line and its C ABI: for the same request every function
here answers what ``aloft <command> --format json`` prints, with the same keys and the same
numbers bit for bit (the engine's JSON parsed with :mod:`json`).

Keyword arguments are the CLI's flags in snake_case (``--payload-kg`` is ``payload_kg=``,
``--no-ground-effect`` is ``no_ground_effect=True``); ``None`` means "flag not given". An unknown
keyword raises :class:`AloftError` naming it. Every refusal raises :class:`AloftError` (a
``ValueError``) whose message is the line ``aloft`` prints after ``aloft: error:``.

The functions are plain module-level functions taking and returning plain values, so they
pickle by reference: ``client.submit(aloft.mission, path, payload_kg=0.5)`` runs on any Dask
worker that has aloft installed (see ``examples/python/fleet_sweep.py``).
"""

from __future__ import annotations

import json
import os
from typing import Any, Dict, List, Optional, Sequence, Union

import numpy as np

from . import _native
from ._native import AloftError

__all__ = [
    "AloftError",
    "calibrate_vehicle",
    "DEFAULT_VEHICLE",
    "DEMO_MISSION",
    "POWER_KEYS",
    "__version__",
    "endurance",
    "fit",
    "live",
    "log_info",
    "mission",
    "mission_map",
    "plan",
    "power",
    "timeseries",
    "validate",
    "vehicles",
]

__version__: str = _native.version()

#: The result keys of :func:`power`, in order (``aloft power``'s CSV/JSON keys).
POWER_KEYS: List[str] = list(_native.POWER_KEYS)
#: The built-in demonstration mission (TOML), flown when a mission's ``path`` is ``None``.
DEMO_MISSION: str = _native.DEMO_MISSION
#: The vehicle every function uses when none is named.
DEFAULT_VEHICLE: str = _native.DEFAULT_VEHICLE

PathLike = Union[str, "os.PathLike[str]"]


def _path(p: Optional[PathLike]) -> Optional[str]:
    return None if p is None else os.fspath(p)


def mission(path: Optional[PathLike] = None, **options: Any) -> Dict[str, Any]:
    """Fly a mission file (or, with ``path=None``, the built-in demo): ``aloft mission --format json``.

    Args:
        path: An aloft mission (TOML or JSON), a QGroundControl ``.plan`` or a ``.waypoints``
            file, recognised from its content; ``None`` for the built-in demonstration survey.
        **options: The flags of ``aloft mission`` in snake_case: ``vehicle`` (built-in name or
            vehicle TOML path, default ``"dji-m100"``), ``battery``, ``payload_kg``,
            ``wind_speed`` and ``wind_from`` (m/s and degrees the wind blows FROM; give both),
            ``wind_profile`` (``"uniform"``, ``"power-law"``, ``"log"``),
            ``wind_reference_height``, ``wind_exponent``, ``wind_roughness``, ``wind_field``
            (CSV path), ``gust_std``, ``gust_seed``, ``reserve_percent``, ``start_percent`` (or
            ``start_voltage_v``, the rested voltage),
            ``time_step``, ``speed``, ``rtl_altitude_m``, ``corners`` (``"pass"``, ``"stop"``),
            ``aoa`` (``"geometric"``, ``"paper"``), ``no_ground_effect``; the day's air:
            ``elevation_m`` (m above mean sea level; default the mission's home altitude),
            ``temperature_c`` (C; default ISA's at the elevation), ``humidity_percent``,
            ``qnh_hpa`` (the answer carries ``air_density_kg_m3``, ``density_source``,
            ``elevation_m``, ``temperature_c`` and where each came from); and the Monte-Carlo
            options of ``--samples N``: ``samples``, ``seed``, ``wind_speed_sd``,
            ``wind_from_sd``, ``payload_sd_kg``, ``capacity_sd_percent``, ``power_sd_percent``,
            ``threads`` (the spreads need ``samples``).

    Returns:
        The CLI's JSON answer as a dict: ``feasible``, ``energy_wh``, ``duration_s``,
        ``segments``, ``point_of_no_return``... (with ``samples``, also ``uncertainty``:
        ``p_feasible`` and percentiles). An infeasible mission is an answer
        (``feasible`` is False; the CLI exits 1), not an error.

    Raises:
        AloftError: What ``aloft mission`` refuses with exit code 2 (unknown vehicle, a mission
            the vehicle cannot fly, a bad option), with its message.
    """
    return json.loads(_native.mission_json(_path(path), options))


def mission_map(path: Optional[PathLike] = None, **options: Any) -> Dict[str, Any]:
    """The map of a mission, as the page of ``aloft serve`` draws it (its ``/api/map``).

    Args:
        path: As :func:`mission`.
        **options: As :func:`mission` (with ``samples``, the band of the state of charge).

    Returns:
        ``segments`` (per segment: ``index``, ``kind``, ``item``, ``points_m`` east-north-up
        from home and, for a mission with a geographic home, ``points_deg``), ``home``,
        ``point_of_no_return``, ``battery`` (``time_s``, ``soc``: the state of charge over time)
        and with ``samples`` its ``band`` (``p5``, ``p50``, ``p95``). The segments are those of
        :func:`mission` with the same options.

    Raises:
        AloftError: As :func:`mission`.
    """
    return json.loads(_native.mission_map_json(_path(path), options))


def plan(
    path: Optional[PathLike] = None,
    *,
    output: Optional[PathLike] = None,
    force: bool = False,
    overlap_m: Optional[float] = None,
    speeds: Optional[str] = None,
    max_speed: Optional[float] = None,
    **options: Any,
) -> Dict[str, Any]:
    """The missions to fly, one file per battery: ``aloft plan PATH -o OUTPUT --format json``.

    Each sortie is used to the reserve (cut inside a leg where its pack reaches it) and the next
    resumes ``overlap_m`` back along the route; legs are flown at the ground speed of least
    energy per metre in their wind; a QGroundControl survey is turned to the wind; of the
    candidates the one with the fewest batteries, then the least energy, is kept (never more
    than the mission as given). Each file is a complete
    mission in the input's format, which :func:`mission` flies with the same options to its
    sortie's figures.

    Args:
        path: The mission, as :func:`mission` takes it (aloft TOML or JSON, a QGroundControl
            ``.plan``, a ``.waypoints`` file); ``None`` for the built-in demonstration survey.
        output: The folder to write the files into (created if missing), named
            ``MISSION-K-of-N.EXT``; the answer's ``files`` are then their paths. ``None``: no
            file is written (``files`` are the names they would have; ``texts`` holds them).
        force: Overwrite files that exist in ``output`` (without it an existing file is refused
            before any file is written).
        overlap_m: How far back along the route a sortie resumes, m (``--overlap-m``, default
            10; from 0 to 1000).
        speeds: Which legs get the wind's speed (``--speeds``): ``"wind"`` (default: the legs
            without a speed of their own), ``"energy"`` (every leg) or ``"keep"`` (none).
        max_speed: Highest ground speed a leg is given, m/s (``--max-speed``; the vehicle's
            own limits apply anyway).
        **options: ``aloft plan``'s ``camera_interval_s`` (s: the camera's shortest time
            between photos; a leg where it triggers every D m is given at most D / this;
            default a ``.plan`` survey's ``MinTriggerInterval``, else 2), ``keep_angle``
            (True: keep every survey's grid angle; else a QGroundControl survey is turned to the
            wind where that saves energy) and ``loiter_unlimited_s`` (s, default 60: how long an
            unlimited loiter is flown before the items after it); how sure each sortie must be:
            ``confidence`` (default 0.95: each sortie lands with the reserve in that share of the
            day's scenarios; 0.5 cuts for the forecast alone), ``samples`` (default 400), ``seed``
            and the spreads ``wind_speed_sd`` (m/s, default 25 % of the forecast and at least
            1.5), ``wind_from_sd`` (deg, default 25), ``payload_sd_kg`` (default 0),
            ``capacity_sd_percent`` (default 3), ``power_sd_percent`` (default 3), ``threads``;
            and the mission's options, as :func:`mission`'s without the Monte-Carlo ones: ``vehicle``, ``battery``, ``payload_kg`` (kg),
            ``wind_speed`` (m/s) and ``wind_from`` (deg, blowing FROM), ``wind_profile``,
            ``wind_field``, ``gust_std``, ``reserve_percent`` (% of the usable capacity at
            landing), ``start_percent``, ``time_step`` (s), ``speed`` (m/s),
            ``rtl_altitude_m`` (m), ``corners``, ``aoa``, ``no_ground_effect``, and the day's
            air ``elevation_m``, ``temperature_c``, ``humidity_percent``, ``qnh_hpa``.

    Returns:
        The CLI's JSON answer as a dict: ``files`` (in flight order), ``batteries``,
        ``energy_wh`` (Wh, all sorties), ``duration_s`` (s, all sorties), ``sorties`` (per
        file: ``file``, ``first_item`` and ``last_item`` of a planner file,
        ``ends_inside_leg_fraction`` where it turns home inside a leg, ``energy_wh``,
        ``duration_s``, ``end_soc`` (0-1, for the forecast), ``landing_soc`` (``p5``, ``p50``,
        ``p95`` over the day's scenarios, 0-1), ``p_reserve`` (the share of the scenarios that
        land with the reserve), ``point_of_no_return_s``), ``confidence`` and ``scenarios``
        (``samples``, ``seed``, ``spreads``), ``as_given`` (the
        mission split at whole items: ``batteries``, ``energy_wh``, ``duration_s``), ``changes``
        (``speeds``: the legs given another speed, m/s; ``angles``: the surveys turned, deg;
        ``cut_inside_legs``), ``notes`` when there is something the plan could not do (a
        survey it could not draw again); and ``texts``, the files' texts in flight order. When no way of cutting the route keeps the reserve
        (the CLI exits 1) the answer is ``{"feasible": False, "reason": ..., "texts": []}``,
        not an error, and no file is written.

    Raises:
        AloftError: What ``aloft plan`` refuses with exit code 2 (an unknown vehicle, a
            mission that does not read, a bad option, named), with its message; a file in
            ``output`` that exists without ``force=True``.
    """
    opts = dict(options, overlap_m=overlap_m, speeds=speeds, max_speed=max_speed)
    answer_json, texts = _native.plan_json(_path(path), opts, _path(output), force)
    answer = json.loads(answer_json)
    answer["texts"] = list(texts)
    return answer


def timeseries(path: Optional[PathLike] = None, **options: Any) -> Any:
    """Every sample of a mission: the table ``aloft mission --timeseries`` writes.

    Takes the arguments of :func:`mission`. Returns a ``pandas.DataFrame`` when pandas is
    installed, else a dict of numpy arrays, with the CSV's columns in its order (``time_s``,
    ``segment`` (int64), ``east_m``, ... ``power_w``, ``soc``, the power terms; a term the
    model does not have is NaN where the CSV cell is empty).
    """
    columns = dict(_native.timeseries_columns(_path(path), options))
    try:
        import pandas as pd
    except ImportError:
        return columns
    return pd.DataFrame(columns)


def endurance(**options: Any) -> Dict[str, Any]:
    """Hover and orbit endurance, best-endurance and best-range speeds: ``aloft endurance --format json``.

    Args:
        **options: ``vehicle``, ``battery``, ``payload_kg`` (default 0), ``wind_speed``,
            ``wind_from``, ``wind_profile``, ``wind_reference_height``, ``wind_exponent``,
            ``wind_roughness``, ``course`` (deg, default 0), ``reserve_percent`` (default 0),
            ``orbit_radius`` and ``orbit_speed`` (together), ``aoa``, the day's air
            (``elevation_m``, ``temperature_c``, ``humidity_percent``, ``qnh_hpa``; default the
            vehicle file's density); ``sweep_speed`` (m/s) for
            the power curve instead (``aloft endurance --sweep-speed S --format json``), or
            ``payload_sweep`` (``"START:STOP:STEP"`` in kg, or a tuple of the three numbers) for
            endurance against payload, one curve per pack, instead
            (``aloft endurance --payload-sweep START:STOP:STEP --format json``; not with
            ``payload_kg`` or ``sweep_speed``).

    Returns:
        The CLI's JSON answer as a dict.
    """
    return json.loads(_native.endurance_json(options))


def vehicles() -> List[Dict[str, Any]]:
    """The built-in vehicles: ``aloft vehicles --format json``.

    Returns:
        One dict per vehicle: ``name``, ``description``, ``takeoff_mass_kg`` (airframe +
        default pack, or a power model's own mass), ``models``, ``batteries``
        (the pack names for ``battery=``, default first) and, for the DJI vehicles, ``source``
        (``figures``, ``calibrated_on``, ``published``).
    """
    return json.loads(_native.vehicles_json())


def calibrate_vehicle(spec: PathLike, output: PathLike, force: bool = False) -> Dict[str, Any]:
    """A vehicle file from a spec sheet: ``aloft vehicles calibrate SPEC -o OUTPUT --format json``.

    Args:
        spec: The spec sheet (TOML: ``name``, ``rotors``, ``rotor_diameter_m``,
            ``frame_mass_kg``, ``[battery]``, ``[published_hover]``; see docs/guide.md).
        output: Where to write the vehicle file; every function accepts it as ``vehicle=``.
        force: Replace ``output`` when it exists (a regular file, or a link itself; never a
            device, a FIFO or a folder). Without it an existing file is kept (``AloftError``).

    Returns:
        The calibration: ``efficiency``, ``hover_power_w``, ``max_minutes_at_unit_efficiency``,
        ``battery``, ``takeoff_mass_kg``, ``published_minutes``, ``defaults`` (the class defaults
        used, in words).
    """
    return json.loads(
        _native.calibrate_vehicle_json(os.fspath(spec), os.fspath(output), force)
    )


def log_info(path: PathLike, **options: Any) -> Dict[str, Any]:
    """Summarise a flight log: ``aloft log info PATH --format json``.

    Args:
        path: A CSV file (or PX4 CSV tables' prefix), MCAP, PX4 ULog or ArduPilot DataFlash log.
        **options: ``profile`` (``"kaist"``, ``"px4"`` or a column-map TOML), ``topics`` (MCAP),
            ``header_time``, ``battery_current_positive``, ``battery_instance``, ``max_lag``
            (search window of the power lag estimate, s; ``--max-lag``).
    """
    return json.loads(_native.log_info_json(os.fspath(path), options))


def fit(
    logs: Union[PathLike, Sequence[PathLike]],
    vehicle_template: Optional[str] = None,
    **options: Any,
) -> Dict[str, Any]:
    """Fit a vehicle to flight logs: ``aloft fit --format json``.

    Args:
        logs: One log or a list of logs (``--log``); ``"FILE:payload_kg=0.5"`` for a flight
            that carried a payload.
        vehicle_template: The vehicle to start from, built-in name or TOML path (default: the
            generic template, which needs ``mass_kg`` and ``rotor_diameter_m``).
        **options: ``mass_kg`` (take-off mass without payload), ``rotor_diameter_m``,
            ``battery_capacity_mah`` (when the logs' capacity parameter is unset),
            ``battery_mass_kg``, ``max_takeoff_mass_kg``, ``free`` (list or comma-separated
            text, default ``["k"]``), ``no_drag``, ``output`` (write the fitted vehicle TOML
            there; the CLI requires it, here it is optional), ``force`` (replace an existing
            ``output``; without it the file is kept and the fit refused), ``profile``, ``aoa``, ``lag``,
            ``max_lag`` (default 10), ``battery_instance``.
    """
    return json.loads(_native.fit_json(_paths(logs), vehicle_template, options))


def validate(
    logs: Union[PathLike, Sequence[PathLike]], vehicle: str, **options: Any
) -> Dict[str, Any]:
    """Validate a vehicle's power model against flight logs: ``aloft validate --format json``.

    Args:
        logs: One log or a list of logs.
        vehicle: Built-in name or TOML path of a vehicle with a ``[power]`` table.
        **options: ``calibrate_first`` (s), ``battery`` and ``payload_kg`` (the take-off mass
            the flights carried: airframe + pack + payload; a vehicle without an airframe flies
            its ``[power]`` mass + payload), ``profile``, ``aoa``, ``lag``, ``max_lag``,
            ``battery_instance``.
    """
    return json.loads(_native.validate_json(_paths(logs), vehicle, options))


def live(replay: PathLike, vehicle: str, **options: Any) -> Dict[str, Any]:
    """Follow a flight log as if live: ``aloft live --replay LOG --format json``.

    Returns ``{"updates": [...], "check": {...}}`` for ``route="log"`` (the validation replay:
    each prediction against the energy the log measured from then to the end), else
    ``{"updates": [...], "summary": {...}}``. Each update is the command's JSON line.

    Args:
        replay: The flight log (CSV with ``profile``, MCAP, ULog, DataFlash).
        vehicle: Built-in name or TOML path of a vehicle with a ``[power]`` table.
        **options: ``route`` (``"mission"``, the default, or ``"log"``), ``mission`` (a mission
            file), ``profile``, ``every`` (s), ``battery``, ``payload_kg``,
            ``reserve_percent``, ``scenarios``, ``speed``, ``low_voltage_v`` and
            ``critical_voltage_v`` (pack volts: the failsafes flown on the rest, in place of the
            vehicle's own). Telemetry logs and MAVLink links
            (``tlog``, ``connect``) need the command line: this package is built without them.
    """
    return json.loads(_native.live_json(str(replay), vehicle, options))


def _paths(logs: Union[PathLike, Sequence[PathLike]]) -> List[str]:
    if isinstance(logs, (str, os.PathLike)):
        return [os.fspath(logs)]
    return [os.fspath(p) for p in logs]


def power(
    airspeed: Any,
    roll: Any,
    pitch: Any,
    climb_rate: Any = 0.0,
    vehicle: str = DEFAULT_VEHICLE,
    *,
    battery: Optional[str] = None,
    payload_kg: Optional[float] = None,
    without: Optional[Union[str, Sequence[str]]] = None,
    profile_cutoff: Optional[float] = None,
    aoa: Optional[str] = None,
    air_direction_deg: Any = None,
    elevation_m: Optional[float] = None,
    temperature_c: Optional[float] = None,
    humidity_percent: Optional[float] = None,
    qnh_hpa: Optional[float] = None,
) -> Dict[str, np.ndarray]:
    """The four-term power model over arrays of flight states: ``aloft power`` vectorised.

    The inputs broadcast against each other (numpy rules); each output has the broadcast shape.
    The work is done in compiled code with the GIL released (the power crate's batch kernels,
    identical bit for bit to ``aloft power`` for each state).

    Args:
        airspeed: Airspeed, m/s (``--airspeed``).
        roll: Roll, degrees, positive right side down (``--roll``).
        pitch: Pitch, degrees, positive nose up (``--pitch``; forward flight is negative).
        climb_rate: Vertical speed, m/s, positive up (``--climb-rate``).
        vehicle: Built-in name or vehicle TOML path.
        battery: Pack by name (``--battery``; default the vehicle's default pack).
        payload_kg: Payload, kg (``--payload-kg``; default 0). The model flies the vehicle's
            take-off mass, airframe + pack + payload, as ``aloft power``, ``aloft endurance``
            and ``aloft mission`` do (a vehicle without an airframe, such as
            ``"dji-m100-paper"``, its ``[power]`` table's mass + payload).
        without: Terms removed (``"induced"``, ``"parasitic"``, ``"profile"``, ``"climb"``).
        profile_cutoff: Drop the profile term above this airspeed, m/s.
        aoa: ``"paper"`` (default) or ``"geometric"`` (needs ``air_direction_deg``).
        air_direction_deg: Direction of the air-relative velocity from the nose, degrees
            (array or scalar); selects the geometric angle of attack.
        elevation_m, temperature_c, humidity_percent, qnh_hpa: The day's air (``--elevation-m``
            m, ``--temperature-c`` C, ``--humidity-percent`` %, ``--qnh-hpa`` hPa; default the
            vehicle file's density, ISA sea level 1.225 kg/m^3): the density of the
            International Standard Atmosphere at the elevation with the given temperature,
            humidity and QNH.

    Returns:
        A dict of float64 arrays keyed by :data:`POWER_KEYS`: ``thrust_n``,
        ``induced_velocity_mps``, ``hover_induced_velocity_mps``, ``induced_w``,
        ``parasitic_w``, ``profile_w``, ``acceleration_w``, ``climb_w``, ``aero_w``,
        ``electrical_w``.

    Raises:
        AloftError: A state the model refuses (the CLI's message, with the element's flat
            index), a non-finite input, a vehicle without a ``[power]`` table, an unknown pack,
            a take-off mass above the vehicle's limit.
    """
    inputs = [airspeed, roll, pitch, climb_rate]
    if air_direction_deg is not None:
        inputs.append(air_direction_deg)
    arrays = [np.asarray(x, dtype=np.float64) for x in inputs]
    try:
        shape = np.broadcast_shapes(*(a.shape for a in arrays))
    except ValueError as e:
        raise AloftError(f"aloft.power: the inputs do not broadcast together: {e}") from None
    flat = [np.ascontiguousarray(np.broadcast_to(a, shape)).reshape(-1) for a in arrays]
    options = {
        "vehicle": vehicle,
        "battery": battery,
        "payload_kg": payload_kg,
        "without": without,
        "profile_cutoff": profile_cutoff,
        "aoa": aoa,
        "elevation_m": elevation_m,
        "temperature_c": temperature_c,
        "humidity_percent": humidity_percent,
        "qnh_hpa": qnh_hpa,
    }
    direction = flat[4] if air_direction_deg is not None else None
    out = _native.power(flat[0], flat[1], flat[2], flat[3], direction, options)
    return {k: out[k].reshape(shape) for k in POWER_KEYS}
