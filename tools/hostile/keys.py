#!/usr/bin/env python3
"""Key numbers for tools/hostile/run.sh: one short line from mfh's outputs.

    keys.py chi2 FILE               expected mass ± bound, p, verdict, failed samples (chi2 --json)
    keys.py report DIR [CHECK...]   verdict counts and the checks that did not pass; with CHECKs,
                                    each listed check's verdicts (and worst measured error)
    keys.py record DIR CHECK FIELD  the records of CHECK: incidence, verdict and FIELD ("-": the
                                    measured error; "oracle": value vs the oracle's ± bound)
    keys.py slowest DIR             the three records that took longest (check, wall seconds)
    keys.py find DIR JSON           the verdict of the record whose check, model and case are
                                    JSON's ({"check","model","case"}), or "absent"
"""
import json
import os
import sys
from collections import Counter


def load(path):
    with open(path) as f:
        return json.load(f)


def report(directory):
    path = os.path.join(directory, "report.json")
    return load(path) if os.path.exists(path) else None


def short(x):
    return "%.4g" % x if isinstance(x, float) else str(x)


def chi2(path):
    try:
        d = load(path)
    except (OSError, ValueError):
        return "no JSON output"
    n = d.get("samples") or 1
    return "mass %.7g ± %s, p %s, %s, failed samples %s (%s)" % (
        d.get("expected_mass") or 0.0, short(d.get("expected_error_bound")),
        short(d.get("p_value")), d.get("verdict"), d.get("failed_samples"),
        short((d.get("failed_samples") or 0) / n))


def counts(r):
    c = r["summary"]["counts"]
    return " ".join("%s %d" % (k, v) for k, v in c.items() if v)


def not_passed(r):
    bad = Counter(x["check"] for x in r["records"]
                  if x["verdict"] not in ("pass", "expected_failure", "skipped"))
    return ", ".join("%s×%d" % kv for kv in sorted(bad.items())) or "none"


def report_line(directory, checks):
    r = report(directory)
    if r is None:
        return "no report.json"
    line = "%s; not passed: %s" % (counts(r), not_passed(r))
    for check in checks:
        v = Counter(x["verdict"] for x in r["records"] if x["check"] == check)
        line += "; %s: %s" % (check, " ".join("%s %d" % kv for kv in sorted(v.items())) or "none")
    return line


def record_line(directory, check, field):
    r = report(directory)
    if r is None:
        return "no report.json"
    out = []
    for x in r["records"]:
        if x["check"] != check:
            continue
        m = x.get("measured") or {}
        where = x.get("case", {}).get("incidence", x.get("case", {}).get("theta_i", ""))
        if field == "-":
            value = short(m.get("error"))
        elif field == "oracle":
            o = x.get("oracle") or {}
            value = "%s vs %s ± %s" % (short(x.get("value")), short(o.get("value")),
                                      short(o.get("uncertainty")))
        else:
            value = short(x.get(field))
        out.append("%s %s %s" % (short(where), x["verdict"], value))
    return "; ".join(out) or "no %s record" % check


def find_line(directory, key):
    r = report(directory)
    if r is None:
        return "no report.json"
    want = json.loads(key)
    for x in r["records"]:
        if all(x.get(k) == v for k, v in want.items()):
            return "tampered record %s" % x["verdict"]
    return "tampered record absent"


def slowest_line(directory):
    r = report(directory)
    if r is None:
        # a killed audit: the records streamed so far
        path = os.path.join(directory, "report.jsonl")
        if not os.path.exists(path):
            return "no report"
        with open(path) as f:
            lines = f.read().splitlines()[1:]
        r = {"records": [json.loads(x) for x in lines if x.endswith("}")]}
        if not r["records"]:
            return "no record finished"
    records = sorted(r["records"], key=lambda x: -((x.get("cost") or {}).get("wall_seconds") or 0))
    return "slowest: " + ", ".join("%s %.0f s" % (x["check"], x["cost"]["wall_seconds"])
                                   for x in records[:3])


def main():
    kind, args = sys.argv[1], sys.argv[2:]
    if kind == "chi2":
        print(chi2(args[0]))
    elif kind == "report":
        print(report_line(args[0], args[1:]))
    elif kind == "record":
        print(record_line(*args))
    elif kind == "slowest":
        print(slowest_line(args[0]))
    elif kind == "find":
        print(find_line(*args))
    else:
        sys.exit("unknown kind " + kind)


if __name__ == "__main__":
    main()
