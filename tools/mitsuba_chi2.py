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

Usage: python3 tools/mitsuba_chi2.py [--mfh PATH] [--samples N] [--repeat K]
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


def mfh_seconds(mfh, samples):
    out = subprocess.run(
        [
            mfh, "chi2", "--model", '{"family":"ggx","alpha":0.3}',
            "--samples", str(samples), "--resolution", "64", "--json",
        ],
        check=False, capture_output=True, text=True,
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
    args = parser.parse_args()

    mitsuba, note = mitsuba_test(args.samples)
    if mitsuba is None:
        print(f"skipped: {note}")
        return 0
    if not os.path.exists(args.mfh):
        print(f"skipped: no mfh binary at {args.mfh} (cargo build --release -p mfh-harness)")
        return 0
    # Alternated, so that both see the same load; the best of each.
    theirs, ours = float("inf"), float("inf")
    for _ in range(args.repeat):
        theirs = min(theirs, mitsuba())
        ours = min(ours, mfh_seconds(args.mfh, args.samples))
    theirs, ours = args.samples / theirs, args.samples / ours
    load = os.getloadavg()
    print(f"load average {load[0]:.2f} {load[1]:.2f} {load[2]:.2f}, {os.cpu_count()} cpus")
    print(f"mitsuba chi2 histogram: {theirs:.3e} samples/s ({note}, best of {args.repeat})")
    print(
        f"mfh chi2 sampling+binning: {ours:.3e} samples/s "
        f"(GGX α = 0.3, 64 × 128 cells, best of {args.repeat})"
    )
    print(f"ratio mfh / mitsuba: {ours / theirs:.2f}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
