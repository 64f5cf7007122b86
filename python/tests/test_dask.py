"""Everything a worker needs pickles; a two-worker LocalCluster sweep equals the serial one."""

from __future__ import annotations

import importlib.util
import pickle

import pytest

import aloft


def test_functions_answers_and_errors_pickle():
    for f in (aloft.mission, aloft.endurance, aloft.power, aloft.timeseries, aloft.log_info,
              aloft.fit, aloft.validate):
        assert pickle.loads(pickle.dumps(f)) is f
    answer = aloft.mission(payload_kg=0.2)
    assert pickle.loads(pickle.dumps(answer)) == answer
    e = pickle.loads(pickle.dumps(aloft.AloftError("unknown vehicle 'x'")))
    assert isinstance(e, aloft.AloftError) and str(e) == "unknown vehicle 'x'"
    power = aloft.power([1.0, 2.0], 0.0, -2.0)
    again = pickle.loads(pickle.dumps(power))
    assert all((again[k] == power[k]).all() for k in power)


def _example(repo):
    spec = importlib.util.spec_from_file_location("fleet_sweep", repo / "examples" / "python" / "fleet_sweep.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def test_two_worker_sweep_equals_serial(repo):
    pytest.importorskip("distributed")
    fleet = _example(repo)
    cases = fleet.cases(payloads_kg=[0.0, 0.6, 1.5], wind_speeds_mps=[0.0, 8.0], winds_from_deg=[90.0, 270.0])
    serial = fleet.serial(cases)
    table, _ = fleet.local_sweep(cases, workers=2)
    assert table.equals(serial)
    heavy = table[table["payload_kg"] == 1.5]
    # 2.355 kg + 1.5 kg is beyond the M100's 3.6 kg take-off mass: refused on the worker, the
    # AloftError's message in the row.
    assert heavy["error"].str.contains("beyond the vehicle's limit of 3.600 kg").all()
    calm = table[(table["payload_kg"] == 0.0) & (table["wind_speed"] == 0.0)]
    assert (calm["error"] == "").all() and calm["energy_wh"].gt(0).all()
