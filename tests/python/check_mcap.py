#!/usr/bin/env python3
"""Independent check of an MCAP file written by aloft, with the Python `mcap` package.

Usage: check_mcap.py FILE.mcap EXPECT.json

EXPECT.json:
  {"topics": {"/aloft/pose": {"count": 20, "schema": "foxglove.PoseInFrame"}, ...},
   "values": [{"topic": "/aloft/state", "index": 3, "path": "position_enu_m.x",
               "value": 1.5, "tol": 1e-9}, ...]}

Checks, for every message: CRCs, JSON encoding with a `jsonschema` schema that parses, the
schema's required keys present, no NaN or infinity, `timestamp` equal to the record's log_time;
per topic: message count and schema name (also against the summary statistics); and the listed
values. Exits 0 when everything holds, 1 with a message otherwise.
"""
import json
import math
import sys

from mcap.reader import make_reader


def fail(msg):
    print(f"check_mcap: FAIL: {msg}", file=sys.stderr)
    sys.exit(1)


def reject_constant(name):
    raise ValueError(f"non-finite JSON constant {name}")


def lookup(obj, path):
    for key in path.split("."):
        if isinstance(obj, list):
            obj = obj[int(key)]
        else:
            obj = obj[key]
    return obj


def main():
    if len(sys.argv) != 3:
        fail("usage: check_mcap.py FILE.mcap EXPECT.json")
    path, expect_path = sys.argv[1], sys.argv[2]
    with open(expect_path) as f:
        expect = json.load(f)
    counts = {}
    schemas = {}
    messages = {}
    with open(path, "rb") as f:
        reader = make_reader(f, validate_crcs=True)
        summary = reader.get_summary()
        if summary is None:
            fail("no summary section")
        for schema, channel, message in reader.iter_messages(log_time_order=False):
            topic = channel.topic
            if channel.message_encoding != "json":
                fail(f"{topic}: message encoding {channel.message_encoding!r}, expected 'json'")
            if schema is None or schema.encoding != "jsonschema":
                fail(f"{topic}: schema encoding is not jsonschema")
            js = json.loads(schema.data)
            if js.get("type") != "object":
                fail(f"{topic}: schema {schema.name} is not an object schema")
            try:
                msg = json.loads(message.data, parse_constant=reject_constant)
            except ValueError as e:
                fail(f"{topic}: message {counts.get(topic, 0)}: {e}")
            for key in js.get("required", []):
                if key not in msg:
                    fail(f"{topic}: message {counts.get(topic, 0)} lacks required key {key!r}")
            ts = msg["timestamp"]
            if ts["sec"] * 1_000_000_000 + ts["nsec"] != message.log_time:
                fail(f"{topic}: timestamp {ts} differs from log_time {message.log_time}")
            counts[topic] = counts.get(topic, 0) + 1
            schemas[topic] = schema.name
            messages.setdefault(topic, []).append(msg)
        stats = summary.statistics
        if stats is not None:
            total = sum(counts.values())
            if stats.message_count != total:
                fail(f"statistics say {stats.message_count} messages, read {total}")
            by_channel = {summary.channels[cid].topic: n for cid, n in stats.channel_message_counts.items()}
            if by_channel != counts:
                fail(f"statistics per channel {by_channel} differ from messages read {counts}")
    want = expect.get("topics", {})
    if set(want) != set(counts):
        fail(f"topics {sorted(counts)} differ from expected {sorted(want)}")
    for topic, w in want.items():
        if counts[topic] != w["count"]:
            fail(f"{topic}: {counts[topic]} messages, expected {w['count']}")
        if "schema" in w and schemas[topic] != w["schema"]:
            fail(f"{topic}: schema {schemas[topic]!r}, expected {w['schema']!r}")
    for v in expect.get("values", []):
        try:
            got = lookup(messages[v["topic"]][v["index"]], v["path"])
        except (KeyError, IndexError) as e:
            fail(f"{v['topic']}[{v['index']}].{v['path']}: missing ({e})")
        if "value" in v:
            if not math.isclose(got, v["value"], rel_tol=0.0, abs_tol=v.get("tol", 1e-9)):
                fail(f"{v['topic']}[{v['index']}].{v['path']} = {got}, expected {v['value']}")
        if v.get("absent") and got is not None:
            fail(f"{v['topic']}[{v['index']}].{v['path']} should be absent")
    print(f"check_mcap: OK: {path}: " + ", ".join(f"{t} {n}" for t, n in sorted(counts.items())))


if __name__ == "__main__":
    main()
