#!/usr/bin/env python3
"""Samples per second through mfh's external protocol (docs/external-protocol.md; the last figures
are in docs/performance.md), per example and protocol version: `mfh chi2 --cmd "python3 <example> --protocol P"`
draws N samples in batches of 65 536 and reports sampling+binning samples/s; the bare child is
timed on the same batches without mfh (request in, sample, answer out; the request is encoded
once, the answer is read but not decoded) to show what the protocol costs the child.

    cargo build --release -p mfh-harness && python3 tools/external_throughput.py [--samples N]

Timings on a shared machine are noisy: run it alone, and read the numbers as +-20 %. The load
average is printed before and after.
"""
import base64
import json
import os
import subprocess
import sys
import time
from array import array

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
MFH = os.path.join(ROOT, "target", "release", "mfh")
args = sys.argv[1:]
N = int(args[args.index("--samples") + 1]) if "--samples" in args else 2_000_000
BATCH = 65_536


def command(example, protocol):
    path = os.path.join(ROOT, "examples", "external", example)
    return [sys.executable, path, "--protocol", str(protocol)]


def bare(example, protocol):
    """The child alone: one request of BATCH uniform pairs, answered N / BATCH / 4 times."""
    child = subprocess.Popen(command(example, protocol), stdin=subprocess.PIPE,
                             stdout=subprocess.PIPE)
    child.stdin.write(b'{"v":1,"id":0,"op":"describe","versions":[1,2]}\n')
    child.stdin.flush()
    chosen = json.loads(child.stdout.readline())["protocol"]
    assert chosen == protocol, (example, protocol, chosen)
    u = [((i * 0.618033988749895) % 1.0, (i + 0.5) / BATCH) for i in range(BATCH)]
    if protocol == 1:
        request = {"v": 1, "id": 1, "op": "sample_wm", "u": u}
    else:
        flat = array("d", (x for pair in u for x in pair))
        if sys.byteorder == "big":
            flat.byteswap()
        request = {"v": 2, "id": 1, "op": "sample_wm", "n": BATCH,
                   "u": base64.b64encode(flat.tobytes()).decode("ascii")}
    line = (json.dumps(request) + "\n").encode("ascii")
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


def through_mfh(example, protocol):
    cmd = " ".join(command(example, protocol))
    out = subprocess.run([MFH, "chi2", "--cmd", cmd, "--samples", str(N), "--resolution", "16",
                          "--json", "--quiet"], capture_output=True, text=True, check=False)
    if out.returncode not in (0, 1):
        sys.exit(f"mfh chi2 --cmd failed: {out.stderr}")
    result = json.loads(out.stdout)
    return result["samples_per_second"], result["verdict"]


def main():
    if not os.path.exists(MFH):
        sys.exit(f"{MFH} missing: cargo build --release -p mfh-harness")
    examples = ["ggx.py"]
    try:
        import numpy  # noqa: F401
        examples.append("ggx_numpy.py")
    except ImportError:
        print("ggx_numpy.py skipped: numpy is not installed")
    print(f"{N} samples, batches of {BATCH}; load average before: {os.getloadavg()[0]:.1f}")
    print(f"{'example':14s} {'protocol':>8s} {'through mfh chi2 --cmd':>24s} {'child alone':>14s}")
    for example in examples:
        for protocol in (1, 2):
            alone = bare(example, protocol)
            mfh, verdict = through_mfh(example, protocol)
            print(f"{example:14s} {protocol:8d} {mfh:17.3e} /s ({verdict}) {alone:11.3e} /s")
    print(f"load average after: {os.getloadavg()[0]:.1f}")


if __name__ == "__main__":
    main()
