#!/usr/bin/env python3
"""Tampers with an audit's report.jsonl as a hostile user would, for `mfh audit --resume`.

    tamper_resume.py SRC DST MODE

copies SRC/report.jsonl into DST (created) with one edit, and prints the JSON that identifies the
tampered record ({"check","model","case"} and the verdict it was given) for keys.py find:
    xfail-to-pass   the first expected failure's verdict edited to pass
    error-0.5       the first passing record with a measured error: error edited to 0.5
    renamed         that passing record's check renamed to smith.no_such_check (its plan key kept)
    swapped         the plan keys ("planned") of that record and of one of another check swapped
"""
import json
import os
import sys

src, dst, mode = sys.argv[1:4]
with open(os.path.join(src, "report.jsonl")) as f:
    header, *lines = f.read().splitlines()
records = [json.loads(line) for line in lines]
passing = next(i for i, r in enumerate(records)
               if r["verdict"] == "pass" and isinstance((r.get("measured") or {}).get("error"), float)
               and r["measured"]["error"] < 0.5)
target = passing
if mode == "xfail-to-pass":
    target = next(i for i, r in enumerate(records) if r["verdict"] == "expected_failure")
    records[target]["verdict"] = "pass"
elif mode == "error-0.5":
    records[target]["measured"]["error"] = 0.5
elif mode == "renamed":
    records[target]["check"] = "smith.no_such_check"
elif mode == "swapped":
    other = next(i for i, r in enumerate(records) if r["check"] != records[passing]["check"])
    if "planned" not in records[passing]:
        sys.exit("records carry no plan key (\"planned\"): nothing to swap")
    a, b = records[passing], records[other]
    a["planned"], b["planned"] = b["planned"], a["planned"]
else:
    sys.exit("unknown mode " + mode)
os.makedirs(dst, exist_ok=True)
with open(os.path.join(dst, "report.jsonl"), "w") as f:
    f.write(header + "\n")
    for r in records:
        f.write(json.dumps(r, ensure_ascii=False) + "\n")
r = records[target]
print(json.dumps({"check": r["check"], "model": r["model"], "case": r["case"]}))
