#!/usr/bin/env python3
"""The before/after table of tools/hostile/run.sh's lines, as Markdown.

    make_table.py BEFORE.tsv AFTER.tsv > table.md

One row per case: case | command | before: exit, seconds, key | after: the same.
"""
import sys

C = "python3 tools/hostile/bsdf_child.py"
GGX = '"ndf":{"family":"ggx","alpha":0.3}'
COND = '"bsdf":"conductor","n":0.2,"k":3.0,"ndf":{"family":"beckmann","alpha":%s}'
SCENE = "mfh audit --profile ci --scene S.json, S = {\"materials\":[{\"name\":\"m\",\"bsdf\":{%s}}]}"
EXT = "mfh audit-external --profile ci --cmd \"%s %s\""
TINY = "tiny.json = GGX 0.3, height_correlated, normals; mfh audit --scene tiny.json --profile ci --seed 5"
COMMANDS = {
    "1-chi2-dielectric-eta1.001":
        "mfh chi2 --bsdf '{\"bsdf\":\"dielectric\",\"eta\":1.001,%s}' --incidence 0.9 --json" % GGX,
    "1-chi2-dielectric-eta1.0001": "the same, eta 1.0001",
    "1-chi2-dielectric-eta1.00005": "the same, eta 1.00005",
    "2-chi2-conductor-beckmann1e-4-phi0.3":
        "mfh chi2 --bsdf '{%s}' --incidence 0.9 --azimuth 0.3 --json" % (COND % "1e-4"),
    "2-chi2-conductor-beckmann1e-7-phi0.3": "the same, alpha 1e-7",
    "2-chi2-dielectric-ggx1e4-theta0.001":
        "mfh chi2 --bsdf '{\"bsdf\":\"dielectric\",\"eta\":1.5,\"ndf\":{\"family\":\"ggx\","
        "\"alpha\":1e4}}' --incidence 0.001 --json",
    "2-audit-ci-dielectric-eta1.00005": SCENE % ("\"type\":\"dielectric\",\"eta\":1.00005,%s" % GGX),
    "2-audit-ci-dielectric-eta1.0001": "the same, eta 1.0001",
    "2-audit-ci-conductor-beckmann1e-7":
        SCENE % "\"type\":\"conductor\",\"n\":0.2,\"k\":3.0,\"ndf\":{\"family\":\"beckmann\",\"alpha\":1e-7}",
    "2-albedo-conductor-beckmann1e-7":
        "bsdf.albedo records of the audit above (mean weight vs ∫ eval ± bound; exit and time are the audit's)",
    "2-audit-ci-conductor-beckmann1e-4": "the same conductor, alpha 1e-4",
    "2-audit-ci-dielectric-ggx1e4":
        SCENE % "\"type\":\"dielectric\",\"eta\":1.5,\"ndf\":{\"family\":\"ggx\",\"alpha\":1e4}",
    "2-audit-ci-mitsuba-alpha0":
        "mfh audit --profile ci --scene x.xml: <bsdf type=\"roughconductor\"><float name=\"alpha\" value=\"0\"/></bsdf>",
    "3-control-child-eta1.0001": EXT % (C, "--eta 1.0001") + " (no loss: control)",
    "3-child-eta1.0001-loss5.5pct": EXT % (C, "--eta 1.0001 --loss 0.055"),
    "4-child-radiance-gain1.5": EXT % (C, "--scale 1.5") + " (radiance transport, eval and weight ×1.5)",
    "4-child-radiance-gain1.05": EXT % (C, "--scale 1.05"),
    "5-child-f32-declared-weight5e-4": EXT % (C, "--precision f32 --weight-error 5e-4")
        + " (float64 answers)",
    "5-control-child-f64-weight5e-4": EXT % (C, "--weight-error 5e-4") + " (declared f64: control)",
    "8-control-child-eta1.5": EXT % (C, "") + " (correct child: control)",
    "8-child-eval-1e308": EXT % (C, "--huge-eval") + " (timeout 420)",
    "8-pychild-eval-1e308": EXT % ("python3 tools/hostile/py_dielectric_child.py", "--huge-eval")
        + " (pure-Python examples/external/dielectric.py; timeout 420)",
    "8-ndf-child-tabulated": EXT % ("python3 tools/hostile/ndf_child.py", "--kind tabulated")
        + " (timeout 420)",
    "8-ndf-child-oscillating": EXT % ("python3 tools/hostile/ndf_child.py", "--kind oscillating")
        + " (timeout 420)",
    "11-child-against-ndf-spec": EXT % (C, "") + " --against '{\"family\":\"ggx\",\"alpha\":0.3}'",
    "6-whole-untampered": TINY + " --out D",
    "6-resume-xfail-to-pass": "its expected failure's verdict edited to pass; the same with --resume D",
    "6-resume-error-0.5": "a passing record's measured error edited to 0.5 (tolerance 1e-9); --resume",
    "6-resume-renamed": "a passing record's check renamed smith.no_such_check under its plan key; --resume",
    "6-resume-swapped": "two records' plan keys (\"planned\") swapped; --resume",
    "7-merge-untampered": TINY + " --shard i/2 (i = 1, 2); mfh merge --out M shard-1 shard-2",
    "7-merge-sanity-pass": "a chi-square record made a sanity failure (no p-value) and edited to pass; merge",
    "7-merge-sanity-skipped": "the same, edited to skipped; merge",
    "7-merge-indices": "shard-1/shard.json indices[0] and [1] swapped; merge",
    "7-merge-renamed": "a record's check renamed smith.no_such_check; merge",
    "7-merge-case": "a record's case value edited; merge",
    "9-mitsuba-61000-shapes":
        "python3 tools/hostile/gen_mitsuba.py x.xml 61000 (1 043 133 bytes); mfh audit --scene x.xml --profile ci",
    "10-selftest-devfull": "mfh selftest --only sg --seeds 1 --profile ci > /dev/full",
    "10-cost-devfull": "mfh cost --quick --no-time > /dev/full",
    "10-help-devfull": "mfh --help > /dev/full",
    "10-version-devfull": "mfh --version > /dev/full",
    "10-audit-closed": "mfh audit --scene tiny.json --profile ci >&-",
    "10-eval-closed": "echo '{…ggx 0.3 d θ 0.5}' | mfh eval >&-",
    "10-selftest-closed": "mfh selftest --only sg --seeds 1 --profile ci >&-",
    "10-version-closed": "mfh --version >&-",
}


def load(path):
    rows = {}
    order = []
    with open(path) as f:
        for line in f:
            parts = line.rstrip("\n").split("\t")
            if len(parts) < 3:
                continue
            name, code, secs = parts[:3]
            key = parts[3] if len(parts) > 3 else ""
            if name not in rows:
                order.append(name)
            rows[name] = (code, secs, key)
    return rows, order


def cell(row):
    if row is None:
        return "not run"
    code, secs, key = row
    key = key.replace("|", "\\|")
    return "exit %s, %s s%s" % (code, secs, "; " + key if key else "")


def main():
    before, order_b = load(sys.argv[1])
    after, order_a = load(sys.argv[2])
    order = order_a + [n for n in order_b if n not in after]
    # by case number (stable within a number); the wrong-kind --against's stderr is in the notes
    order = sorted((n for n in order if n != "11-stderr"), key=lambda n: int(n.split("-")[0]))
    print("| case | command | before | after |")
    print("|---|---|---|---|")
    for name in order:
        command = COMMANDS.get(name, "").replace("|", "\\|")
        print("| %s | `%s` | %s | %s |" % (name, command, cell(before.get(name)),
                                           cell(after.get(name))))


if __name__ == "__main__":
    main()
