#!/usr/bin/env python3
"""A vehicle on a UDP link, written with pymavlink (the independent MAVLink implementation), for
tests/it/live_udp_reply.rs:

    python3 tests/python/mavlink_vehicle.py PORT SECONDS [wrapped-count] [px4]

From an ephemeral port of 127.0.0.1 it sends to 127.0.0.1:PORT, for SECONDS, what an armed
ArduCopter quadrotor hovering in LOITER 20 m above its home sends (MAVLink 2, system 1,
component 1): GLOBAL_POSITION_INT and ATTITUDE at 5 Hz; HEARTBEAT, SYS_STATUS,
EXTENDED_SYS_STATE and HOME_POSITION at 1 Hz. It answers a mission download (MISSION_COUNT 2,
then each MISSION_ITEM_INT asked for). Then it listens one second more and prints, as one JSON
line, what it received from aloft, whose ids are (255, 190) as a ground station and (1, 191) as
a component of the vehicle's system: messages by type, the senders of each type, the messages a
QGroundControl-like filter takes (those of the vehicle's system id, as its
Vehicle::_mavlinkMessageReceived), the NAMED_VALUE_FLOAT names, the STATUSTEXT texts and their
severities, the BATTERY_STATUS fields, the names of the PARAM_REQUEST_READ, and messages from any
other sender.

It answers PARAM_REQUEST_READ of its failsafe parameters with PARAM_VALUE as the autopilot
does: ArduPilot casts every value to the float (BATT_LOW_VOLT REAL32 10.5, BATT_FS_LOW_ACT INT8
2); with `px4` the vehicle is a PX4 (HEARTBEAT autopilot MAV_AUTOPILOT_PX4) that copies an
integer's bytes into the float (BAT1_N_CELLS INT32 3, BAT_LOW_THR REAL32 0.15).

With `wrapped-count` it reports 70 % left (SYS_STATUS and BATTERY_STATUS) and sends
BATTERY_STATUS at 1 Hz with a count of the charge drawn (`current_consumed`) that counts 14 A
from 500 mAh for 3 s, then jumps to INT32_MAX for 2 s, then wraps to INT32_MIN and counts on
for 2 s, then goes back to 10 mAh and counts on from there.
"""
import json
import os
import struct
import sys
import time

os.environ.setdefault("MAVLINK20", "1")
from pymavlink import mavutil  # noqa: E402
from pymavlink.dialects.v20 import ardupilotmega as mav  # noqa: E402

HOME = (473_977_000, 85_456_000, 488_000)  # 1e-7 deg, 1e-7 deg, mm
UP_MM = 20_000
PERIOD_S = 0.2

# name: (value as sent in param_value, MAV_PARAM_TYPE)
ARDUPILOT_PARAMS = {
    "BATT_LOW_VOLT": (10.5, mav.MAV_PARAM_TYPE_REAL32),
    "BATT_FS_LOW_ACT": (2.0, mav.MAV_PARAM_TYPE_INT8),
}
PX4_PARAMS = {
    # The INT32 3 copied bytewise into the float (PX4's encoding).
    "BAT1_N_CELLS": (struct.unpack("<f", struct.pack("<i", 3))[0], mav.MAV_PARAM_TYPE_INT32),
    "BAT_LOW_THR": (0.15, mav.MAV_PARAM_TYPE_REAL32),
}


# aloft's senders: a ground station's ids, and its display component on the vehicle's system.
ALOFT = {(255, 190), (1, 191)}
VEHICLE_SYSTEM = 1

INT32_MAX = 2**31 - 1
INT32_MIN = -(2**31)


def wrapped_count(t):
    """The count of the charge drawn at t seconds, mAh: on track, jumping, wrapping, back."""
    drawn = round(14_000 * t / 3600)
    if t < 3:
        return 500 + drawn
    if t < 5:
        return INT32_MAX
    if t < 7:
        return INT32_MIN + drawn
    return 10 + drawn


def send_telemetry(m, k, boot_ms, wrapped, px4):
    """The k-th 0.2 s step of the hover."""
    if k % 5 == 0:
        m.mav.heartbeat_send(
            mav.MAV_TYPE_QUADROTOR,
            mav.MAV_AUTOPILOT_PX4 if px4 else mav.MAV_AUTOPILOT_ARDUPILOTMEGA,
            mav.MAV_MODE_FLAG_SAFETY_ARMED | mav.MAV_MODE_FLAG_CUSTOM_MODE_ENABLED,
            5,  # LOITER
            mav.MAV_STATE_ACTIVE,
        )
        # 22.8 V, 14 A, 80 % left (70 % with the wrapped count).
        left = 70 if wrapped else 80
        m.mav.sys_status_send(0, 0, 0, 0, 22_800, 1_400, left, 0, 0, 0, 0, 0, 0)
        if wrapped:
            cells = [3_800] * 6 + [65_535] * 4
            count = wrapped_count(k * PERIOD_S)
            m.mav.battery_status_send(0, 0, 0, 0, cells, 1_400, count, -1, 70)
        m.mav.extended_sys_state_send(0, mav.MAV_LANDED_STATE_IN_AIR)
        m.mav.home_position_send(HOME[0], HOME[1], HOME[2], 0, 0, 0, [1, 0, 0, 0], 0, 0, 0)
    m.mav.global_position_int_send(boot_ms, HOME[0], HOME[1], HOME[2] + UP_MM, UP_MM, 0, 0, 0, 0)
    m.mav.attitude_send(boot_ms, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0)


def answer(m, msg, params):
    """The mission download: two items, home and a waypoint 50 m north, 20 m up; the failsafe
    parameters this vehicle has."""
    t = msg.get_type()
    if t == "PARAM_REQUEST_READ" and msg.param_id in params:
        value, kind = params[msg.param_id]
        m.mav.param_value_send(msg.param_id.encode(), value, kind, 900, 7)
    elif t == "MISSION_REQUEST_LIST":
        m.mav.mission_count_send(msg.get_srcSystem(), msg.get_srcComponent(), 2, 0)
    elif t in ("MISSION_REQUEST_INT", "MISSION_REQUEST"):
        north = 0 if msg.seq == 0 else 4_500
        frame = 0 if msg.seq == 0 else 3
        m.mav.mission_item_int_send(
            msg.get_srcSystem(), msg.get_srcComponent(), msg.seq, frame, 16, 0, 1,
            0, 0, 0, 0, HOME[0] + north, HOME[1], 0 if msg.seq == 0 else 20.0, 0,
        )


def main():
    port, seconds = int(sys.argv[1]), float(sys.argv[2])
    wrapped = "wrapped-count" in sys.argv[3:]
    px4 = "px4" in sys.argv[3:]
    params = PX4_PARAMS if px4 else ARDUPILOT_PARAMS
    m = mavutil.mavlink_connection(
        f"udpout:127.0.0.1:{port}", source_system=1, source_component=1, dialect="ardupilotmega"
    )
    counts, names, texts, others, senders, shown = {}, {}, [], {}, {}, {}
    severities, batteries, asked = [], [], []
    start = time.monotonic()
    k = 0
    while time.monotonic() - start < seconds + 1.0:
        now = time.monotonic() - start
        if now < seconds and now >= k * PERIOD_S:
            send_telemetry(m, k, 60_000 + int(now * 1000), wrapped, px4)
            k += 1
        msg = m.recv_msg()
        if msg is None:
            time.sleep(0.005)
            continue
        t = msg.get_type()
        if t == "BAD_DATA":
            continue
        src = (msg.get_srcSystem(), msg.get_srcComponent())
        if src not in ALOFT:
            others[t] = others.get(t, 0) + 1
            continue
        counts[t] = counts.get(t, 0) + 1
        senders.setdefault(t, set()).add(src)
        # QGroundControl's vehicle takes a message of its system id, whatever the component.
        if src[0] == VEHICLE_SYSTEM:
            shown[t] = shown.get(t, 0) + 1
        if t == "NAMED_VALUE_FLOAT":
            names[msg.name] = names.get(msg.name, 0) + 1
        elif t == "STATUSTEXT":
            texts.append(msg.text)
            severities.append([msg.text, msg.severity])
        elif t == "BATTERY_STATUS":
            batteries.append({
                "system": msg.get_srcSystem(),
                "component": msg.get_srcComponent(),
                "id": msg.id,
                "battery_remaining": msg.battery_remaining,
                "voltages": list(msg.voltages),
                "current_battery": msg.current_battery,
                "current_consumed": msg.current_consumed,
                "energy_consumed": msg.energy_consumed,
                "temperature": msg.temperature,
                "time_remaining": msg.time_remaining,
                "charge_state": msg.charge_state,
                "battery_function": msg.battery_function,
                "type": msg.type,
            })
        elif t == "PARAM_REQUEST_READ":
            asked.append([msg.param_id, msg.param_index, msg.target_system, msg.target_component])
        if now < seconds:
            answer(m, msg, params)
    print(json.dumps({
        "counts": counts, "names": names, "texts": texts, "others": others,
        "severities": severities, "batteries": batteries, "asked": asked,
        "senders": {t: sorted(list(x) for x in v) for t, v in senders.items()}, "shown": shown,
    }))


if __name__ == "__main__":
    main()
