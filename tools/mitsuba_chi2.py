#!/usr/bin/env python3
"""Side-by-side throughput of the chi-square histogram (issue 15): Mitsuba 3's `chi2`
(`mitsuba.chi2.ChiSquareTest` with `MicrofacetAdapter`, GGX α = 0.3 normal sampling, JIT
llvm variant, float32) and `mfh chi2` (reference GGX α = 0.3, f64), both 10⁷ samples into
8192 cells (Mitsuba: 64 φ × 128 cos θ over the sphere; mfh: 128 φ × 64 cos θ over the
hemisphere), in one run; prints both samples/s and the ratio mfh / Mitsuba.

Mitsuba's figure is the time of `tabulate_histogram()` (uniforms, sampling, binning, the
histogram scatter) after a warm-up call that compiles and caches its kernels; mfh's is the
`sampling_seconds` of `mfh chi2 --json` (uniforms, sampling, binning). The runs alternate
(Mitsuba, mfh, Mitsuba, …) so that both see the same load; each figure is the best of
`--repeat` runs. The load average is printed with the figures: on a shared machine they are
noisy.

Skips cleanly (exit 0, a message) when Mitsuba or its llvm variant is not installed
(`pip install mitsuba`; the llvm variant needs an LLVM shared library, e.g. Debian's
`libllvm19`). Not part of CI.

mfh is run on all threads (rayon's default) and on one (RAYON_NUM_THREADS=1), so the 1 → 2
thread speed-up comes from the same sitting. With `--report PATH` (e.g.
reports/benchmarks-chi2.md) the figures are also written there as Markdown with the command,
date, commit and load averages: the report is generated, never edited by hand.

Usage: python3 tools/mitsuba_chi2.py [--mfh PATH] [--samples N] [--repeat K] [--report PATH]
"""

import argparse
import json
import os
import subprocess
import sys
import time


def mitsuba_test(samples):
    """The Mitsuba histogram tabulation, warmed up, or (None, why) when Mitsuba is absent."""
    try:
        import mitsuba as mi
        import drjit as dr
    except ImportError as e:
        return None, f"mitsuba not installed ({e})"
    try:
        mi.set_variant("llvm_ad_rgb")
    except Exception as e:  # noqa: BLE001 - any failure to load the variant is a skip
        return None, f"mitsuba llvm variant unavailable ({e})"
    from mitsuba.chi2 import ChiSquareTest, MicrofacetAdapter, SphericalDomain

    sample_func, pdf_func = MicrofacetAdapter(mi.MicrofacetType.GGX, 0.3)
    test = ChiSquareTest(
        domain=SphericalDomain(),
        sample_func=sample_func,
        pdf_func=pdf_func,
        sample_dim=2,
        sample_count=samples,
        res=128,
        seed=0,
    )
    test.tabulate_histogram()  # warm-up: kernel compilation and caching
    dr.sync_thread()

    def seconds():
        t = time.perf_counter()
        test.tabulate_histogram()
        dr.eval(test.histogram)
        dr.sync_thread()
        return time.perf_counter() - t

    cells = int(test.res.x) * int(test.res.y)
    return seconds, f"mitsuba {mi.__version__} llvm_ad_rgb, {cells} cells"


def mfh_seconds(mfh, samples, threads=None):
    env = dict(os.environ)
    if threads is not None:
        env["RAYON_NUM_THREADS"] = str(threads)
    out = subprocess.run(
        [
            mfh, "chi2", "--model", '{"family":"ggx","alpha":0.3}',
            "--samples", str(samples), "--resolution", "64", "--json",
        ],
        check=False, capture_output=True, text=True, env=env,
    )
    if out.returncode not in (0, 1):
        sys.exit(f"mfh chi2 failed ({out.returncode}): {out.stderr}")
    return json.loads(out.stdout)["sampling_seconds"]


def main():
    here = os.path.dirname(os.path.abspath(__file__))
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--mfh", default=os.path.join(here, "..", "target", "release", "mfh"))
    parser.add_argument("--samples", type=int, default=10_000_000)
    parser.add_argument("--repeat", type=int, default=3)
    parser.add_argument("--report", help="also write the figures as Markdown to this path")
    args = parser.parse_args()

    mitsuba, note = mitsuba_test(args.samples)
    if mitsuba is None:
        print(f"skipped: {note}")
        return 0
    if not os.path.exists(args.mfh):
        print(f"skipped: no mfh binary at {args.mfh} (cargo build --release -p mfh-harness)")
        return 0
    # Alternated, so that all see the same load; the best of each.
    load_before = os.getloadavg()
    theirs, ours, ours_one = float("inf"), float("inf"), float("inf")
    for _ in range(args.repeat):
        theirs = min(theirs, mitsuba())
        ours = min(ours, mfh_seconds(args.mfh, args.samples))
        ours_one = min(ours_one, mfh_seconds(args.mfh, args.samples, threads=1))
    load = os.getloadavg()
    theirs, ours, ours_one = (args.samples / t for t in (theirs, ours, ours_one))
    cpus = os.cpu_count()
    lines = [
        f"load average {load_before[0]:.2f} before, {load[0]:.2f} {load[1]:.2f} {load[2]:.2f} "
        f"after (1, 5, 15 min), {cpus} cpus: {cpu_description()}",
        f"mitsuba chi2 histogram: {theirs:.3e} samples/s ({note}, best of {args.repeat})",
        f"mfh chi2 sampling+binning, {cpus} threads: {ours:.3e} samples/s "
        f"(GGX α = 0.3, 64 × 128 cells, best of {args.repeat})",
        f"mfh chi2 sampling+binning, 1 thread: {ours_one:.3e} samples/s "
        f"(speed-up 1 → {cpus} threads: {ours / ours_one:.2f}×)",
        f"ratio mfh / mitsuba: {ours / theirs:.2f}",
    ]
    print("\n".join(lines))
    if args.report:
        write_report(args, note, load_before, load, theirs, ours, ours_one)
    return 0


def cpu_description():
    """The CPU's model name, family/model and widest SIMD level, from /proc/cpuinfo (Linux), or
    "unknown CPU": the rates depend on it (AVX-512 doubles mfh's f64 lanes)."""
    try:
        with open("/proc/cpuinfo", encoding="utf-8") as f:
            info = f.read()
    except OSError:
        return "unknown CPU"
    fields = {}
    for line in info.splitlines():
        key, _, value = line.partition(":")
        fields.setdefault(key.strip(), value.strip())
    flags = fields.get("flags", "").split()
    simd = "AVX-512" if "avx512f" in flags else "AVX2" if "avx2" in flags else "no AVX2"
    return (
        f"{fields.get('model name', 'unknown CPU')} (family {fields.get('cpu family', '?')}, "
        f"model {fields.get('model', '?')}), {simd}"
    )


def write_report(args, note, load_before, load, theirs, ours, ours_one):
    """The figures as Markdown at args.report (generated; overwritten on every run)."""
    here = os.path.dirname(os.path.abspath(__file__))
    commit = subprocess.run(
        ["git", "-C", here, "describe", "--always", "--dirty"],
        check=False, capture_output=True, text=True,
    ).stdout.strip() or "unknown"
    date = time.strftime("%Y-%m-%d %H:%M UTC", time.gmtime())
    cpus = os.cpu_count()
    command = " ".join(["python3", "tools/mitsuba_chi2.py"] + sys.argv[1:])
    text = f"""# Chi-square throughput: mfh vs Mitsuba 3 (issue 15)

Generated by `{command}` on {date}, commit {commit}. Do not edit by hand: rerun the command.

Load average {load_before[0]:.2f} before the runs, {load[0]:.2f} / {load[1]:.2f} / {load[2]:.2f}
(1 / 5 / 15 min) after, {cpus} cpus: {cpu_description()}. On a shared machine the rates are noisy: only figures of
one run are comparable.

{args.samples} samples, GGX α = 0.3 normal sampling; best of {args.repeat} alternated runs.

| what | samples/s |
|------|-----------|
| Mitsuba ({note}), `tabulate_histogram()` | {theirs:.3e} |
| `mfh chi2`, {cpus} threads (`sampling_seconds`) | {ours:.3e} |
| `mfh chi2`, 1 thread | {ours_one:.3e} |

Ratio mfh / Mitsuba: **{ours / theirs:.2f}** (target ≥ 2). Speed-up of mfh from 1 to {cpus}
threads: {ours / ours_one:.2f}×.

The harness overhead (sample + bin against the bare sampler loop, vectorized and scalar
samplers, 1 and {cpus} threads) is measured by `cargo bench -p mfh-harness --bench chi2`
(criterion; its figures are in its output and target/criterion/, not copied here).
"""
    with open(args.report, "w", encoding="utf-8") as f:
        f.write(text)
    print(f"wrote {args.report}")


if __name__ == "__main__":
    sys.exit(main())
