"""Fleet sweep: every mission x payload x wind, flown by aloft on a Dask cluster.

Runs on a local cluster by default (2 worker processes, 1 thread each), or on a real cluster
when given its scheduler address (every worker needs `pip install ./python` and the mission
files at the same paths; the built-in demo mission, `None`, needs no file):

    python examples/python/fleet_sweep.py                      # LocalCluster, 2 workers
    python examples/python/fleet_sweep.py --workers 1          # one worker
    python examples/python/fleet_sweep.py --compare            # 1 worker, then 2: the speed-up
    python examples/python/fleet_sweep.py --scheduler tcp://10.0.0.5:8786

The workers call `aloft.mission` itself (`client.submit(aloft.mission, path, payload_kg=...)`):
aloft's functions are plain module functions, so they pickle by reference. A case aloft
refuses (a payload beyond the vehicle's take-off mass) comes back as a row with its `error`.
"""

from __future__ import annotations

import argparse
import itertools
import os
import time
from pathlib import Path
from typing import Any, Dict, List, Optional, Sequence

import pandas as pd

import aloft

REPO = Path(__file__).resolve().parents[2]
DATA = Path(os.environ.get("ALOFT_DATA_DIR", REPO.parent / "shared" / "data"))

#: The built-in demo, the repository's example mission and, when the shared data is there, a
#: QGroundControl survey plan.
MISSIONS: List[Optional[str]] = [None, str(REPO / "fixtures" / "missions" / "example.toml")]
if (DATA / "missions" / "neilvaltec_test.plan").exists():
    MISSIONS.append(str(DATA / "missions" / "neilvaltec_test.plan"))
PAYLOADS_KG = [0.0, 0.25, 0.5, 0.75, 1.0]
WIND_SPEEDS_MPS = [0.0, 2.0, 4.0, 6.0, 8.0]
WINDS_FROM_DEG = [0.0, 90.0, 180.0, 270.0]

#: The columns of the answer kept per case.
KEPT = ["mission", "feasible", "energy_wh", "duration_s", "end_soc", "takeoff_mass_kg"]


def cases(
    missions: Sequence[Optional[str]] = MISSIONS,
    payloads_kg: Sequence[float] = PAYLOADS_KG,
    wind_speeds_mps: Sequence[float] = WIND_SPEEDS_MPS,
    winds_from_deg: Sequence[float] = WINDS_FROM_DEG,
    vehicle: str = aloft.DEFAULT_VEHICLE,
) -> List[Dict[str, Any]]:
    """Every combination, as the keyword arguments of `aloft.mission` (plus `path`)."""
    return [
        dict(path=m, vehicle=vehicle, payload_kg=p, wind_speed=w, wind_from=d)
        for m, p, w, d in itertools.product(missions, payloads_kg, wind_speeds_mps, winds_from_deg)
    ]


def row(case: Dict[str, Any], answer: Optional[Dict[str, Any]], error: str = "") -> Dict[str, Any]:
    """One line of the table: the case and what aloft answered (or refused)."""
    out = {
        "path": case["path"] or "(built-in demo)",
        "payload_kg": case["payload_kg"],
        "wind_speed": case["wind_speed"],
        "wind_from": case["wind_from"],
    }
    for k in KEPT:
        out[k] = None if answer is None else answer[k]
    out["error"] = error
    return out


def serial(all_cases: Sequence[Dict[str, Any]]) -> pd.DataFrame:
    """The sweep in this process, one case after the other (the reference)."""
    rows = []
    for c in all_cases:
        kwargs = {k: v for k, v in c.items() if k != "path"}
        try:
            rows.append(row(c, aloft.mission(c["path"], **kwargs)))
        except aloft.AloftError as e:
            rows.append(row(c, None, str(e)))
    return pd.DataFrame(rows)


def sweep(client: Any, all_cases: Sequence[Dict[str, Any]]) -> pd.DataFrame:
    """The sweep on a Dask cluster: one task per case, `aloft.mission` on the workers."""
    from distributed import wait

    futures = [
        client.submit(
            aloft.mission,
            c["path"],
            **{k: v for k, v in c.items() if k != "path"},
            pure=False,
        )
        for c in all_cases
    ]
    wait(futures)
    rows = []
    for c, f in zip(all_cases, futures):
        if f.status == "error":
            rows.append(row(c, None, str(f.exception())))
        else:
            rows.append(row(c, f.result()))
    return pd.DataFrame(rows)


def local_sweep(all_cases: Sequence[Dict[str, Any]], workers: int) -> "tuple[pd.DataFrame, float]":
    """The sweep on a fresh LocalCluster of `workers` processes (1 thread each); the table and
    the wall time of the sweep alone (cluster start-up excluded)."""
    from distributed import Client, LocalCluster

    with LocalCluster(
        n_workers=workers, threads_per_worker=1, processes=True, dashboard_address=None
    ) as cluster, Client(cluster) as client:
        client.submit(aloft.mission, pure=False).result()  # warm up each import path once
        t0 = time.perf_counter()
        table = sweep(client, all_cases)
        return table, time.perf_counter() - t0


def main(argv: Optional[Sequence[str]] = None) -> pd.DataFrame:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--scheduler", help="address of a running Dask scheduler (default: LocalCluster)")
    ap.add_argument("--workers", type=int, default=2, help="LocalCluster worker processes (default 2)")
    ap.add_argument("--compare", action="store_true", help="time 1 worker, then 2, and print the speed-up")
    ap.add_argument("--csv", help="also write the table to this CSV")
    args = ap.parse_args(argv)
    all_cases = cases()
    print(f"{len(all_cases)} cases: {len(MISSIONS)} missions x {len(PAYLOADS_KG)} payloads x "
          f"{len(WIND_SPEEDS_MPS)} wind speeds x {len(WINDS_FROM_DEG)} directions")
    if args.scheduler:
        from distributed import Client

        with Client(args.scheduler) as client:
            t0 = time.perf_counter()
            table = sweep(client, all_cases)
            print(f"sweep on {args.scheduler}: {time.perf_counter() - t0:.2f} s")
    elif args.compare:
        one, t1 = local_sweep(all_cases, 1)
        table, t2 = local_sweep(all_cases, 2)
        assert one.equals(table), "1 and 2 workers disagree"
        print(f"1 worker: {t1:.2f} s, 2 workers: {t2:.2f} s, speed-up {t1 / t2:.2f}x")
    else:
        table, t = local_sweep(all_cases, args.workers)
        print(f"sweep on a LocalCluster of {args.workers} worker(s): {t:.2f} s")
    summary = (
        table.assign(mission=table["path"].map(lambda p: Path(p).name if p.startswith("/") else p),
                     refused=table["error"] != "", feasible=table["feasible"].fillna(False))
        .groupby(["mission", "payload_kg"])
        .agg(cases=("refused", "size"), refused=("refused", "sum"), feasible=("feasible", "sum"),
             energy_wh_min=("energy_wh", "min"), energy_wh_max=("energy_wh", "max"))
    )
    with pd.option_context("display.width", 120, "display.max_rows", 40, "display.max_columns", 10):
        print(summary.round(1))
    refused = table[table["error"] != ""]
    if len(refused):
        print(f"{len(refused)} case(s) refused, e.g.: {refused['error'].iloc[0]}")
    if args.csv:
        table.to_csv(args.csv, index=False)
    return table


if __name__ == "__main__":
    main()
