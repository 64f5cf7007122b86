#!/usr/bin/env python3
"""Message counts of the shared .tlog files by pymavlink, the independent reader that
crates/link/tests/tlog_data.rs compares aloft-link's reader with.

    python3 -m venv /work/pmvenv && /work/pmvenv/bin/pip install pymavlink==2.4.50
    /work/pmvenv/bin/python crates/link/tests/pymavlink_counts.py ../shared/data/telemetry

Prints, per file, the number of messages of each type of interest (CRC-checked, ardupilotmega
dialect, any system), every decoded message, and the BAD_DATA pymavlink reports; then the
first GLOBAL_POSITION_INT with a fix and the first and last SYS_STATUS battery of the vehicle.
"""
import os
import sys

os.environ.setdefault("MAVLINK20", "1")  # parse MAVLink 2 frames as well as 1
from pymavlink import mavutil  # noqa: E402

TYPES = [
    "HEARTBEAT", "SYS_STATUS", "BATTERY_STATUS", "GLOBAL_POSITION_INT", "ATTITUDE", "VFR_HUD",
    "WIND", "HOME_POSITION", "EXTENDED_SYS_STATE", "MISSION_CURRENT", "MISSION_COUNT",
    "MISSION_ITEM", "MISSION_ITEM_INT", "SYSTEM_TIME",
]


def counts(path):
    m = mavutil.mavlink_connection(path, dialect="ardupilotmega", robust_parsing=True)
    c = {t: 0 for t in TYPES}
    total = bad = 0
    first_fix = None
    batt = []
    while True:
        msg = m.recv_msg()
        if msg is None:
            break
        t = msg.get_type()
        if t == "BAD_DATA":
            bad += 1
            continue
        total += 1
        if t in c:
            c[t] += 1
        if t == "GLOBAL_POSITION_INT" and first_fix is None and (msg.lat != 0 or msg.lon != 0):
            first_fix = (msg.lat / 1e7, msg.lon / 1e7, msg.alt / 1e3, msg.relative_alt / 1e3)
        if t == "SYS_STATUS" and msg.get_srcSystem() == 1 and msg.voltage_battery not in (0, 65535):
            batt.append((msg.voltage_battery / 1e3, msg.current_battery / 1e2, msg.battery_remaining))
    return c, total, bad, first_fix, (batt[0], batt[-1]) if batt else None


def main():
    folder = sys.argv[1] if len(sys.argv) > 1 else "../shared/data/telemetry"
    for name in sorted(os.listdir(folder)):
        if not name.endswith(".tlog"):
            continue
        c, total, bad, fix, batt = counts(os.path.join(folder, name))
        print(f"{name}: messages={total} bad_data={bad}")
        print("  " + " ".join(f"{k}={v}" for k, v in c.items()))
        print(f"  first_fix={fix} battery(first,last)={batt}")


if __name__ == "__main__":
    main()
