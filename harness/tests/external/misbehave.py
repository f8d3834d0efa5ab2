#!/usr/bin/env python3
"""A child that answers `describe` correctly, then misbehaves on its first `d` request in the
way named by its argument: crash, hang, garbage, nan, wrong_length, early_exit, bad_describe,
wrong_id (protocol version 1); bad_base64, short_array, ragged_array, nan_binary, oversized
(version 2: it chooses "protocol":2 at describe); base64_in_v1 (a version-1 child answering a
version-2 array); bsdf_nan (a BSDF whose answers hold NaN: the last eval or pdf value; the
weight of the first sample; the wo of the second sample, a failed one with pdf 0). Writes its pid to the file named by the second argument (the test checks that mfh
leaves no child running)."""
import base64
import json
import struct
import sys
import time

mode = sys.argv[1]
V2 = mode in ("bad_base64", "short_array", "ragged_array", "nan_binary", "oversized")
with open(sys.argv[2], "w") as f:
    f.write(str(__import__("os").getpid()))


def send(obj):
    sys.stdout.write(json.dumps(obj) + "\n")
    sys.stdout.flush()


def binary(values):
    """Version 2's array encoding: base64 of little-endian float64."""
    return base64.b64encode(struct.pack("<%dd" % len(values), *values)).decode("ascii")


for line in sys.stdin:
    req = json.loads(line)
    if req["op"] == "describe":
        if mode == "early_exit":
            sys.exit(0)
        if mode == "bad_describe":
            send({"id": req["id"], "protocol": 1, "capabilities": ["lambda"]})
            continue
        if mode == "bsdf_nan":
            send({"id": req["id"], "protocol": 1, "name": "misbehave-" + mode,
                  "capabilities": ["bsdf_eval", "bsdf_pdf", "bsdf_sample"], "parameters": {}})
            continue
        send({"id": req["id"], "protocol": 2 if V2 else 1, "name": "misbehave-" + mode,
              "capabilities": ["d", "lambda", "sample_wm"], "parameters": {}})
        continue
    if mode == "bsdf_nan":
        nan = float("nan")
        if req["op"] == "bsdf_sample":
            n = len(req["u"])
            wo = [[0.0, 0.0, 1.0]] * n
            pdf = [1.0] * n
            weight = [0.5] * n
            weight[0] = nan
            if n > 1:
                wo[1], pdf[1], weight[1] = [nan, nan, nan], 0.0, 0.0
            send({"id": req["id"], "wo": wo, "pdf": pdf, "weight": weight})
        else:
            n = len(req["wo"])
            send({"id": req["id"], "values": [0.5] * (n - 1) + [nan]})
        continue
    n = req["n"] if V2 else len(req.get("m", req.get("u", req.get("w", []))))

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
    if mode == "bad_base64":
        send({"id": req["id"], "values": "0.5, 0.5, 0.5"})
        continue
    if mode == "short_array":
        send({"id": req["id"], "values": binary([0.5] * (n - 1))})
        continue
    if mode == "ragged_array":  # 798 bytes: not a whole number of 8-byte values
        send({"id": req["id"], "values": binary([0.5] * n)[:-8] + "AAAA"})
        continue
    if mode == "nan_binary":
        send({"id": req["id"], "values": binary([0.5] * (n - 1) + [float("nan")])})
        continue
    if mode == "oversized":  # 65 MiB of base64 without an end of line: over mfh's 64 MiB limit
        sys.stdout.write('{"id": %d, "values": "' % req["id"])
        chunk = "A" * (1 << 20)
        for _ in range(65):
            sys.stdout.write(chunk)
        sys.stdout.flush()
        time.sleep(3600)
    if mode == "base64_in_v1":
        send({"id": req["id"], "values": binary([0.5] * n)})
        continue
    send({"id": req["id"], "values": [0.5] * n})
