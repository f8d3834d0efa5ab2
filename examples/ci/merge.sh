#!/usr/bin/env bash
# Merges OUT/shard-1 … OUT/shard-N into OUT/merged (report.json, junit.xml): the report of the
# unsharded audit. Usage: merge.sh N OUT [mfh merge options: --baseline old/report.json …]
# The binary is $MFH (default: mfh on PATH). Exit status: 0 pass, 1 a check failed (or a
# regression with --fail-on-regression), 2 a shard is missing or does not belong.
set -euo pipefail
n="$1"; out="$2"; shift 2
dirs=()
for i in $(seq 1 "$n"); do dirs+=("$out/shard-$i"); done
"${MFH:-mfh}" merge "${dirs[@]}" --out "$out/merged" "$@"
