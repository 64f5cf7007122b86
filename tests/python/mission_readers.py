#!/usr/bin/env python3
"""Mission files read by readers that are not aloft, for tests/it/missions_writers.rs:

    python3 tests/python/mission_readers.py mavsdk --autopilot px4|ardupilot FILE.plan...
    python3 tests/python/mission_readers.py mavwp FILE.waypoints...

`mavsdk`: MAVSDK's own QGroundControl importer (PyPI `mavsdk` 4.1.0, the native binding:
`MissionRaw.import_qgroundcontrol_mission`, which runs MAVSDK's C++ `MissionImport::parse_json`
in this process; 4.x has no `mavsdk_server`). MissionRaw needs a system, so a pymavlink vehicle
(system 1, component 1) sends a HEARTBEAT every 0.1 s from an ephemeral port of 127.0.0.1 to the
port of 127.0.0.1 where MAVSDK listens, as a PX4 or ArduPilot autopilot: the importer puts the
plan's home first for ArduPilot. Nothing leaves the loopback; the vehicle thread is stopped and
MAVSDK destroyed before the script exits.

`mavwp`: pymavlink's `mavwp.MAVWPLoader().load()`, the reader MAVProxy uses.

Prints one JSON object: {"reader": ..., "files": {FILE: [item, ...]}} where an item is
{"seq", "frame", "command", "current", "autocontinue", "params": [p1..p4], "x", "y", "z"}: for
MAVSDK, MISSION_ITEM_INT's fields (x, y int32, latitude and longitude in 1e-7 deg), for mavwp
MISSION_ITEM's (x, y, z as parsed); NaN is written null. A file a reader refuses is
{"error": "..."} in place of its list. With `mavsdk --airspace`, each file's answer is
{"items": [...], "fence": [...], "rally": [...]}: the importer's mission, geofence and rally items
(the fence as MAV_CMD_NAV_FENCE_* items, a polygon's vertices each with the vertex count in
param1, a circle with its radius in param1; the rally points as MAV_CMD_NAV_RALLY_POINT).
"""
import argparse
import json
import math
import os
import socket
import sys
import threading

os.environ.setdefault("MAVLINK20", "1")

# MAV_AUTOPILOT values of the vehicle's HEARTBEAT.
AUTOPILOTS = {"px4": 12, "ardupilot": 3}
# Seconds to wait for MAVSDK to see the vehicle.
DISCOVERY_S = 10.0


def number(v):
    """A float for JSON: NaN as null."""
    return None if isinstance(v, float) and math.isnan(v) else v


def item_json(seq, frame, command, current, autocontinue, params, x, y, z):
    return {
        "seq": seq,
        "frame": frame,
        "command": command,
        "current": current,
        "autocontinue": autocontinue,
        "params": [number(p) for p in params],
        "x": number(x),
        "y": number(y),
        "z": number(z),
    }


def free_udp_port():
    """A port of 127.0.0.1 nobody uses now."""
    s = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
    s.bind(("127.0.0.1", 0))
    port = s.getsockname()[1]
    s.close()
    return port


def vehicle(port, autopilot, stop):
    """HEARTBEATs to 127.0.0.1:port until `stop`."""
    from pymavlink import mavutil

    m = mavutil.mavlink_connection(
        f"udpout:127.0.0.1:{port}", source_system=1, source_component=1
    )
    try:
        while not stop.is_set():
            m.mav.heartbeat_send(2, autopilot, 0, 0, 4)  # quadrotor, standby
            stop.wait(0.1)
    finally:
        m.close()


def read_with_mavsdk(files, autopilot, airspace=False):
    import mavsdk
    from mavsdk.plugins.mission_raw.mission_raw import MissionRaw

    config = mavsdk.Configuration.create_with_component_type(mavsdk.ComponentType.GROUND_STATION)
    sdk = mavsdk.Mavsdk(config)
    stop = threading.Event()
    thread = None
    try:
        port = free_udp_port()
        result = sdk.add_any_connection(f"udpin://127.0.0.1:{port}")
        if result != mavsdk.ConnectionResult.SUCCESS:
            raise SystemExit(f"MAVSDK cannot listen on 127.0.0.1:{port}: {result}")
        thread = threading.Thread(target=vehicle, args=(port, AUTOPILOTS[autopilot], stop))
        thread.start()
        system = sdk.first_autopilot(DISCOVERY_S)
        if system is None:
            raise SystemExit(f"MAVSDK saw no autopilot on 127.0.0.1:{port} in {DISCOVERY_S} s")
        plugin = MissionRaw(system)
        out = {}
        for path in files:
            try:
                data = plugin.import_qgroundcontrol_mission(path)
            except mavsdk.MavsdkError as e:
                out[path] = {"error": str(e)}
                continue
            def items(kind):
                return [
                    item_json(
                        i.seq, i.frame, i.command, i.current, i.autocontinue,
                        [i.param1, i.param2, i.param3, i.param4], i.x, i.y, i.z,
                    )
                    for i in kind
                ]

            if airspace:
                out[path] = {
                    "items": items(data.mission_items),
                    "fence": items(data.geofence_items),
                    "rally": items(data.rally_items),
                }
            else:
                out[path] = items(data.mission_items)
        return {"reader": f"mavsdk {mavsdk.__version__} ({sdk.version()})", "files": out}
    finally:
        stop.set()
        if thread is not None:
            thread.join()
        sdk.destroy()


def read_with_mavwp(files):
    import pymavlink
    from pymavlink import mavwp

    out = {}
    for path in files:
        loader = mavwp.MAVWPLoader()
        try:
            loader.load(path)
        except Exception as e:  # mavwp raises MAVWPError, ValueError, ...
            out[path] = {"error": f"{type(e).__name__}: {e}"}
            continue
        out[path] = [
            item_json(
                w.seq, w.frame, w.command, w.current, w.autocontinue,
                [w.param1, w.param2, w.param3, w.param4], w.x, w.y, w.z,
            )
            for w in (loader.wp(k) for k in range(loader.count()))
        ]
    return {"reader": f"pymavlink {pymavlink.__version__} mavwp", "files": out}


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    sub = parser.add_subparsers(dest="reader", required=True)
    m = sub.add_parser("mavsdk")
    m.add_argument("--autopilot", choices=sorted(AUTOPILOTS), required=True)
    m.add_argument("--airspace", action="store_true", help="the fence and rally items too")
    m.add_argument("files", nargs="+")
    w = sub.add_parser("mavwp")
    w.add_argument("files", nargs="+")
    args = parser.parse_args()
    if args.reader == "mavsdk":
        answer = read_with_mavsdk(args.files, args.autopilot, args.airspace)
    else:
        answer = read_with_mavwp(args.files)
    json.dump(answer, sys.stdout, allow_nan=False)
    sys.stdout.write("\n")


if __name__ == "__main__":
    main()
