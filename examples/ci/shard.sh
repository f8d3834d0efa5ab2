#!/usr/bin/env bash
# Runs shard I of N of an mfh audit into OUT/shard-I (report.json, junit.xml, shard.json).
# Usage: shard.sh I N OUT [mfh audit options: --scene FILE --profile P --seed S …]
# The binary is $MFH (default: mfh on PATH). Exit status: mfh audit's (0 pass, 1 a check
# failed, 2 bad input); the merge step decides the audit, so CI should run it regardless.
set -euo pipefail
i="$1"; n="$2"; out="$3"; shift 3
"${MFH:-mfh}" audit --shard "$i/$n" --out "$out/shard-$i" "$@"
