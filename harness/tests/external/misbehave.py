#!/usr/bin/env python3
"""A child that answers `describe` correctly, then misbehaves on its first `d` request in the
way named by its argument: crash, hang, garbage, nan, wrong_length, early_exit, bad_describe,
wrong_id. Writes its pid to the file named by the second argument (the test checks that mfh
leaves no child running)."""
import json
import sys
import time

mode = sys.argv[1]
with open(sys.argv[2], "w") as f:
    f.write(str(__import__("os").getpid()))


def send(obj):
    sys.stdout.write(json.dumps(obj) + "\n")
    sys.stdout.flush()


for line in sys.stdin:
    req = json.loads(line)
    if req["op"] == "describe":
        if mode == "early_exit":
            sys.exit(0)
        if mode == "bad_describe":
            send({"id": req["id"], "protocol": 1, "capabilities": ["lambda"]})
            continue
        send({"id": req["id"], "protocol": 1, "name": "misbehave-" + mode,
              "capabilities": ["d", "lambda", "sample_wm"], "parameters": {}})
        continue
    n = len(req.get("m", req.get("u", req.get("w", []))))
    if mode == "crash":
        raise RuntimeError("simulated crash in d")
    if mode == "hang":
        time.sleep(3600)
    if mode == "garbage":
        sys.stdout.write("computing D for %d normals...\n" % n)
        sys.stdout.flush()
        continue
    if mode == "nan":
        send({"id": req["id"], "values": [0.5] * (n - 1) + [float("nan")]})
        continue
    if mode == "wrong_length":
        send({"id": req["id"], "values": [0.5] * (n - 1)})
        continue
    if mode == "wrong_id":
        send({"id": req["id"] + 100, "values": [0.5] * n})
        continue
    send({"id": req["id"], "values": [0.5] * n})
