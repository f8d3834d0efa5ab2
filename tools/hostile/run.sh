#!/usr/bin/env bash
# The hostile cases of the trust work (oracle corners, transport laws, forged records, budgets,
# lost output), run against one mfh binary, one line each:
#
#     case <TAB> exit code <TAB> wall seconds <TAB> key number
#
# Usage: tools/hostile/run.sh /path/to/mfh [WORK_DIR [CASE_REGEX]]
#   WORK_DIR (default: a fresh /tmp/mfh-hostile.*) gets each case's stdout (.out), stderr (.err)
#   and output folders; CASE_REGEX (grep -E) runs only the cases whose names match.
# Each command runs under `timeout 420`; exit 124 is reported as "> 420 s, killed".
# Run one binary at a time: the times are wall times of a shared machine.
set -u
MFH=$(realpath "$1")
WORK=${2:-$(mktemp -d /tmp/mfh-hostile.XXXXXX)}
ONLY=${3:-}
HERE=$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)
KEYS="python3 $HERE/keys.py"
CHILD="python3 $HERE/bsdf_child.py"
LIMIT=420
mkdir -p "$WORK"
cd "$WORK" || exit 2

# want NAME: whether the case is selected.
want() { [ -z "$ONLY" ] || echo "$1" | grep -Eq "$ONLY"; }

# run NAME CMD...: CMD under the timeout, stdout to NAME.out, stderr to NAME.err; sets RC, SECS.
run() {
    local name=$1 t0 t1
    shift
    t0=$(date +%s.%N)
    timeout "$LIMIT" "$@" > "$name.out" 2> "$name.err"
    RC=$?
    t1=$(date +%s.%N)
    SECS=$(awk "BEGIN { printf \"%.2f\", $t1 - $t0 }")
}

# run_sh NAME SCRIPT: as run, for a shell line that redirects stdout itself (/dev/full, >&-).
run_sh() {
    local name=$1 t0 t1
    t0=$(date +%s.%N)
    timeout "$LIMIT" sh -c "$2" 2> "$name.err"
    RC=$?
    t1=$(date +%s.%N)
    SECS=$(awk "BEGIN { printf \"%.2f\", $t1 - $t0 }")
}

# row NAME KEY: the case's line.
row() {
    local key=$2
    [ "$RC" = 124 ] && key="> $LIMIT s, killed; $key"
    printf '%s\t%s\t%s\t%s\n' "$1" "$RC" "$SECS" "$key"
}

# first_err NAME: the first line of the case's stderr, at most 160 characters.
first_err() { head -n 1 "$1.err" | cut -c1-160; }

GGX03='"ndf":{"family":"ggx","alpha":0.3}'
COND='"bsdf":"conductor","n":0.2,"k":3.0'

# --- 1. the dielectric's transmission lobe as eta -> 1 (mfh chi2 --bsdf, theta_i 0.9) -------
for eta in 1.001 1.0001 1.00005; do
    name="1-chi2-dielectric-eta$eta"
    want "$name" || continue
    run "$name" "$MFH" chi2 --bsdf "{\"bsdf\":\"dielectric\",\"eta\":$eta,$GGX03}" \
        --incidence 0.9 --json --quiet
    row "$name" "$($KEYS chi2 "$name.out")"
done

# --- 2. near-delta and sphere-filling lobes (chi2), then the reference's own ci audit --------
chi2_case() {
    want "$1" || return 0
    run "$1" "$MFH" chi2 --bsdf "$2" "${@:3}" --json --quiet
    row "$1" "$($KEYS chi2 "$1.out")"
}
chi2_case 2-chi2-conductor-beckmann1e-4-phi0.3 \
    "{$COND,\"ndf\":{\"family\":\"beckmann\",\"alpha\":1e-4}}" --incidence 0.9 --azimuth 0.3
chi2_case 2-chi2-conductor-beckmann1e-7-phi0.3 \
    "{$COND,\"ndf\":{\"family\":\"beckmann\",\"alpha\":1e-7}}" --incidence 0.9 --azimuth 0.3
chi2_case 2-chi2-dielectric-ggx1e4-theta0.001 \
    '{"bsdf":"dielectric","eta":1.5,"ndf":{"family":"ggx","alpha":1e4}}' --incidence 0.001

# audit_bsdf NAME BSDF_FIELDS [CHECK...]: the ci audit of a scene holding the one reference BSDF.
audit_bsdf() {
    local name=$1 bsdf=$2
    shift 2
    want "$name" || return 0
    printf '{"name": "%s", "materials": [{"name": "m", "bsdf": {%s}}]}\n' "$name" "$bsdf" \
        > "$name.json"
    run "$name" "$MFH" audit --scene "$name.json" --profile ci --quiet --out "$name.d"
    row "$name" "$($KEYS report "$name.d" "$@")"
}
audit_bsdf 2-audit-ci-dielectric-eta1.00005 "\"type\":\"dielectric\",\"eta\":1.00005,$GGX03"
audit_bsdf 2-audit-ci-dielectric-eta1.0001 "\"type\":\"dielectric\",\"eta\":1.0001,$GGX03"
audit_bsdf 2-audit-ci-conductor-beckmann1e-7 \
    '"type":"conductor","n":0.2,"k":3.0,"ndf":{"family":"beckmann","alpha":1e-7}'
if want 2-albedo-conductor-beckmann1e-7 && [ -d 2-audit-ci-conductor-beckmann1e-7.d ]; then
    # bsdf.albedo of the previous audit: value (mean weight) vs the cubature's ∫ eval ± bound
    row 2-albedo-conductor-beckmann1e-7 \
        "$($KEYS record 2-audit-ci-conductor-beckmann1e-7.d bsdf.albedo oracle)"
fi
audit_bsdf 2-audit-ci-conductor-beckmann1e-4 \
    '"type":"conductor","n":0.2,"k":3.0,"ndf":{"family":"beckmann","alpha":1e-4}'
audit_bsdf 2-audit-ci-dielectric-ggx1e4 '"type":"dielectric","eta":1.5,"ndf":{"family":"ggx","alpha":1e4}'
if want 2-audit-ci-mitsuba-alpha0; then
    # Mitsuba's roughconductor with alpha 0 (read as 1e-4, as Mitsuba does; beckmann default)
    cat > 2-audit-ci-mitsuba-alpha0.xml <<'XML'
<scene version="3.0.0">
    <bsdf type="roughconductor" id="mirror">
        <float name="alpha" value="0"/>
    </bsdf>
</scene>
XML
    run 2-audit-ci-mitsuba-alpha0 "$MFH" audit --scene 2-audit-ci-mitsuba-alpha0.xml \
        --profile ci --quiet --out 2-audit-ci-mitsuba-alpha0.d
    row 2-audit-ci-mitsuba-alpha0 "$($KEYS report 2-audit-ci-mitsuba-alpha0.d)"
fi

# --- 3-5, 8, 11: external BSDF children (bsdf_child.py: the numpy GGX 0.3 dielectric) --------
# child NAME CHILD_OPTIONS [--against SPEC] -- [CHECK...]: its ci audit.
child() {
    local name=$1 opts=$2
    shift 2
    local extra=()
    while [ $# -gt 0 ] && [ "$1" != -- ]; do extra+=("$1"); shift; done
    [ $# -gt 0 ] && shift
    want "$name" || return 0
    run "$name" "$MFH" audit-external --cmd "$CHILD $opts" --profile ci --quiet \
        --out "$name.d" "${extra[@]}"
    local key
    key=$($KEYS report "$name.d" "$@")
    [ "$key" = "no report.json" ] && key="no report.json; stderr: $(first_err "$name")"
    row "$name" "$key"
}
child 3-control-child-eta1.0001 "--eta 1.0001" -- bsdf.failure_rate
child 3-child-eta1.0001-loss5.5pct "--eta 1.0001 --loss 0.055" -- bsdf.failure_rate
child 4-child-radiance-gain1.5 "--scale 1.5" -- bsdf.energy
child 4-child-radiance-gain1.05 "--scale 1.05" -- bsdf.energy
child 5-child-f32-declared-weight5e-4 "--precision f32 --weight-error 5e-4" -- audit.precision \
    bsdf.sample_consistency
child 5-control-child-f64-weight5e-4 "--weight-error 5e-4" -- bsdf.sample_consistency
child 8-control-child-eta1.5 "" --
child 8-child-eval-1e308 "--huge-eval" --
child 11-child-against-ndf-spec "" --against '{"family":"ggx","alpha":0.3}' --

# 8. the same 1e308 eval in the pure-Python examples/external/dielectric.py (its speed is the
# tracker's measurement's)
if want 8-pychild-eval-1e308; then
    run 8-pychild-eval-1e308 "$MFH" audit-external \
        --cmd "python3 $HERE/py_dielectric_child.py --huge-eval" --profile ci --quiet \
        --out 8-pychild-eval-1e308.d
    row 8-pychild-eval-1e308 "$($KEYS report 8-pychild-eval-1e308.d); $($KEYS slowest 8-pychild-eval-1e308.d)"
fi

# 8. NDF children whose D is slow to integrate (ndf_child.py): time per record
for kind in tabulated oscillating; do
    name="8-ndf-child-$kind"
    want "$name" || continue
    run "$name" "$MFH" audit-external --cmd "python3 $HERE/ndf_child.py --kind $kind" \
        --profile ci --quiet --out "$name.d"
    row "$name" "$($KEYS report "$name.d"); $($KEYS slowest "$name.d")"
done

# --- 6. --resume of a tampered report.jsonl (a tiny GGX scene, ci, seed 5) --------------------
cat > tiny.json <<'JSON'
{"name": "tiny", "materials": [{"name": "a", "model": {"family": "ggx", "alpha": 0.3},
  "masking": "height_correlated", "sampling": "normals"}]}
JSON
TINY=(--scene tiny.json --profile ci --seed 5 --quiet)
if want 6-resume; then
    rm -rf 6-whole
    run 6-whole "$MFH" audit "${TINY[@]}" --out 6-whole
    row 6-whole-untampered "$($KEYS report 6-whole)"
    for mode in xfail-to-pass error-0.5 renamed swapped; do
        name="6-resume-$mode"
        rm -rf "$name.d"
        tampered=$(python3 "$HERE/tamper_resume.py" 6-whole "$name.d" "$mode")
        run "$name" "$MFH" audit "${TINY[@]}" --out "$name.d" --resume "$name.d"
        notes=$(grep -c -E "not taken|re-judged|runs again|contradicts" "$name.err")
        row "$name" "$($KEYS find "$name.d" "$tampered"); $($KEYS report "$name.d" | cut -d';' -f1); stderr notes $notes"
    done
fi

# --- 7. mfh merge of tampered shards (the tiny scene in 2 shards) -----------------------------
if want 7-merge; then
    for i in 1 2; do
        rm -rf "7-shard-$i"
        run "7-shard-$i" "$MFH" audit "${TINY[@]}" --shard "$i/2" --out "7-shard-$i"
    done
    run 7-merge-untampered "$MFH" merge --out 7-merge-untampered.d 7-shard-1 7-shard-2
    row 7-merge-untampered "$($KEYS report 7-merge-untampered.d | cut -d';' -f1)"
    for mode in sanity-pass sanity-skipped indices renamed case; do
        name="7-merge-$mode"
        rm -rf "$name.d"
        tampered=$(python3 "$HERE/tamper_merge.py" 7-shard-1 7-shard-2 "$name.d" "$mode")
        run "$name" "$MFH" merge --out "$name.d/merged" "$name.d/shard-1" "$name.d/shard-2"
        key=$($KEYS report "$name.d/merged" | cut -d';' -f1)
        [ -n "$tampered" ] && [ -f "$name.d/merged/report.json" ] &&
            key="$($KEYS find "$name.d/merged" "$tampered"); $key"
        row "$name" "$key; $(grep -h -m1 -E 'edited|re-judged|refus|not ' "$name.err" "$name.out" | cut -c1-140)"
    done
fi

# --- 9. a Mitsuba scene of 61 000 shapes (1.04 MB): time to refusal, size of the error --------
if want 9-mitsuba-61000-shapes; then
    python3 "$HERE/gen_mitsuba.py" 9-shapes.xml 61000 > /dev/null
    run 9-mitsuba-61000-shapes "$MFH" audit --scene 9-shapes.xml --profile ci --quiet \
        --out 9-mitsuba.d
    row 9-mitsuba-61000-shapes "stderr $(wc -c < 9-mitsuba-61000-shapes.err) bytes"
fi

# --- 10. output that cannot arrive: > /dev/full and a closed stdout (>&-) --------------------
SELFTEST="$MFH selftest --only sg --seeds 1 --profile ci --quiet --out 10-selftest.d"
QUERY='{"model":{"family":"ggx","alpha":0.3},"quantity":"d","theta":0.5}'
for spec in \
    "10-selftest-devfull|$SELFTEST > /dev/full" \
    "10-cost-devfull|$MFH cost --quick --no-time --quiet --out 10-cost.d > /dev/full" \
    "10-help-devfull|$MFH --help > /dev/full" \
    "10-version-devfull|$MFH --version > /dev/full" \
    "10-audit-closed|$MFH audit ${TINY[*]} --out 10-audit.d >&-" \
    "10-eval-closed|echo '$QUERY' | $MFH eval >&-" \
    "10-selftest-closed|$SELFTEST >&-" \
    "10-version-closed|$MFH --version >&-"; do
    name=${spec%%|*}
    want "$name" || continue
    run_sh "$name" "${spec#*|}"
    row "$name" "$(first_err "$name")"
done

# --- the wrong-kind --against's refusal text (case 11 ran above with the children) -----------
if want 11-stderr && [ -f 11-child-against-ndf-spec.err ]; then
    row 11-stderr "$(grep -m1 -i against 11-child-against-ndf-spec.err | cut -c1-160)"
fi
