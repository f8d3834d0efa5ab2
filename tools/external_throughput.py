#!/usr/bin/env python3
"""Samples per second through mfh's external protocol (README, "Audit an implementation in any
language"): `mfh chi2 --cmd` draws N samples from each example child in batches of 65 536 and
reports sampling+binning samples/s; the bare child is timed on the same batches without mfh
(JSON in, compute, JSON out) to show what dominates.

    cargo build --release -p mfh-harness && python3 tools/external_throughput.py [--samples N]

Timings on a shared machine are noisy: run it alone, and read the numbers as ±20 %.
"""
import json
import os
import subprocess
import sys
import time

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
MFH = os.path.join(ROOT, "target", "release", "mfh")
args = sys.argv[1:]
N = int(args[args.index("--samples") + 1]) if "--samples" in args else 2_000_000
BATCH = 65_536


def bare(example):
    """The child alone: one request of BATCH uniform pairs, answered BATCH/… times."""
    child = subprocess.Popen([sys.executable, os.path.join(ROOT, "examples", "external", example)],
                             stdin=subprocess.PIPE, stdout=subprocess.PIPE, text=True)
    u = [[(i * 0.618033988749895) % 1.0, (i + 0.5) / BATCH] for i in range(BATCH)]
    line = json.dumps({"v": 1, "id": 0, "op": "sample_wm", "u": u}) + "\n"
    rounds = max(1, N // BATCH // 4)
    t = time.perf_counter()
    for _ in range(rounds):
        child.stdin.write(line)
        child.stdin.flush()
        child.stdout.readline()
    seconds = time.perf_counter() - t
    child.stdin.close()
    child.wait()
    return rounds * BATCH / seconds


def through_mfh(example):
    cmd = f"{sys.executable} {os.path.join(ROOT, 'examples', 'external', example)}"
    out = subprocess.run([MFH, "chi2", "--cmd", cmd, "--samples", str(N), "--resolution", "16",
                          "--json", "--quiet"], capture_output=True, text=True, check=False)
    if out.returncode not in (0, 1):
        sys.exit(f"mfh chi2 --cmd failed: {out.stderr}")
    return json.loads(out.stdout)["samples_per_second"]


def main():
    if not os.path.exists(MFH):
        sys.exit(f"{MFH} missing: cargo build --release -p mfh-harness")
    examples = ["ggx.py"]
    try:
        import numpy  # noqa: F401
        examples.append("ggx_numpy.py")
    except ImportError:
        print("ggx_numpy.py skipped: numpy is not installed")
    print(f"{N} samples, batches of {BATCH}")
    for example in examples:
        alone = bare(example)
        mfh = through_mfh(example)
        print(f"{example:14s} through mfh chi2 --cmd: {mfh:.3e} samples/s; the child alone "
              f"(JSON in, sample, JSON out): {alone:.3e} samples/s")


if __name__ == "__main__":
    main()
