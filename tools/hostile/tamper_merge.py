#!/usr/bin/env python3
"""Tampers with the two shard folders of `mfh audit --shard i/2`, for `mfh merge`.

    tamper_merge.py SHARD1 SHARD2 DST MODE

copies report.json and shard.json of both shards into DST/shard-1 and DST/shard-2 with one edit
(as harness/tests/shard_merge.rs::merge_refuses_or_rejudges_every_tampered_shard edits them),
and prints the JSON that identifies the edited record for keys.py find (nothing for indices):
    sanity-pass     a chi-square record made a sanity failure (no p-value, the reason in its
                    case) whose verdict is pass
    sanity-skipped  the same, verdict skipped
    indices         the first two indices of shard 1's shard.json swapped
    renamed         shard 2's first record's check renamed to smith.no_such_check
    case            the first value of the case of shard 2's first record with a case edited
"""
import json
import os
import sys

one, two, dst, mode = sys.argv[1:5]
shards = []
for d in (one, two):
    with open(os.path.join(d, "report.json")) as f:
        report = json.load(f)
    with open(os.path.join(d, "shard.json")) as f:
        info = json.load(f)
    shards.append([report, info])

r = None
if mode in ("sanity-pass", "sanity-skipped"):
    records = [r for s in shards for r in s[0]["records"]]
    r = next(r for r in records if (r.get("measured") or {}).get("kind") == "p_value")
    r["measured"] = None
    r["case"]["sanity_failure"] = "pdf mass 0.9 != 1"
    r["verdict"] = mode.split("-")[1]
    r["reason"] = "edited"
elif mode == "indices":
    idx = shards[0][1]["indices"]
    idx[0], idx[1] = idx[1], idx[0]
elif mode == "renamed":
    r = shards[1][0]["records"][0]
    r["check"] = "smith.no_such_check"
elif mode == "case":
    r = next(r for r in shards[1][0]["records"] if r.get("case"))
    key = next(iter(r["case"]))
    r["case"][key] = "edited"
else:
    sys.exit("unknown mode " + mode)

for i, (report, info) in enumerate(shards, 1):
    d = os.path.join(dst, "shard-%d" % i)
    os.makedirs(d, exist_ok=True)
    with open(os.path.join(d, "report.json"), "w") as f:
        json.dump(report, f, ensure_ascii=False)
    with open(os.path.join(d, "shard.json"), "w") as f:
        json.dump(info, f, ensure_ascii=False)
if r is not None:
    print(json.dumps({"check": r["check"], "model": r["model"], "case": r["case"]}))
