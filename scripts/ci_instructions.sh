#!/usr/bin/env bash
# Speed guard that fails without noise: instructions per solve, counted by
# callgrind (deterministic: the same build on the same poses counts the same
# to the instruction, whatever the machine's load), for every pair of the
# paper's shapes, cold on $ncold poses spread over the paper's sweep and warm
# on its first $nwarm consecutive poses (build/core/idcol_prof, collecting
# only around the solves), compared with the checked-in reference
# results/baseline/instructions.json.
#
# A pair and mode whose instructions per solve rise by more than
# IDCOL_INSTRUCTIONS_MAX_RISE (default 0.03, i.e. 3%) fails. Why 3%: the
# counts are exact (two runs of one build agree to the tenth of an
# instruction), so any rise is the code's or the compiler's; 3% leaves room
# for incidental changes of the generated code from edits elsewhere (an
# inlining decision that moves), while a slower solver step moves every
# pair by far more: one extra evaluation of the KKT residual (both shapes'
# value, gradient and Hessian) per Newton iteration fails 28 of the 30
# pair-modes (scripts/mutations.sh slow_step shows it; Ellip-Ellip, which
# the ellipsoid closed form solves with almost no Newton steps, barely moves). Faster pairs pass, with a note
# to refresh the reference.
#
#   scripts/ci_instructions.sh              # count and compare (CI); exit 0 pass, 1 regression, 2 bad input
#   scripts/ci_instructions.sh --refresh    # after a deliberate change: rewrite the reference
#   scripts/ci_instructions.sh --compare COUNTS.json   # compare counts made before (no callgrind run)
#
# The reference holds the compiler and flags it was counted with; counts of
# another toolchain are not comparable (exit 2, naming both) unless
# IDCOL_INSTRUCTIONS_ALLOW_MISMATCH=1. Environment: IDCOL_BUILD_DIR (default
# build), IDCOL_CI_OUT (default build/ci), IDCOL_INSTRUCTIONS_REF.
set -euo pipefail
cd "$(dirname "$0")/.."
build="${IDCOL_BUILD_DIR:-build}"
out="${IDCOL_CI_OUT:-$build/ci}"
ref="${IDCOL_INSTRUCTIONS_REF:-results/baseline/instructions.json}"
prof="$build/core/idcol_prof"
ncold=200
nwarm=400
pairs="Poly-Poly Poly-TC Poly-SE Poly-SEC Poly-Ellip TC-TC TC-SE TC-SEC TC-Ellip SE-SE SE-SEC SE-Ellip SEC-SEC SEC-Ellip Ellip-Ellip"
mode=${1:-}
given=""
if [[ "$mode" == "--compare" ]]; then
  given=${2:?--compare needs a counts file}
  [[ -f "$given" ]] || { echo "ci_instructions: no counts file $given" >&2; exit 2; }
elif [[ -n "$mode" && "$mode" != "--refresh" ]]; then
  echo "usage: scripts/ci_instructions.sh [--refresh | --compare COUNTS.json]" >&2
  exit 2
fi
if [[ -z "$given" ]] && { [[ ! -x "$prof" ]] || ! command -v valgrind > /dev/null; }; then
  echo "ci_instructions: needs $prof (IDCOL_BUILD_BENCHMARKS=ON and valgrind's callgrind.h) and valgrind" >&2
  exit 2
fi
mkdir -p "$out"
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT

# One callgrind run per pair and mode, as many at a time as there are CPUs
# (the counts do not depend on it). Each input line: pair, mode, poses.
count() {
  local pair=$1 mode=$2 n=$3
  valgrind --tool=callgrind --collect-atstart=no --callgrind-out-file="$tmp/cg.$pair.$mode" \
    "$prof" run "$pair" "$mode" "$n" > "$tmp/log.$pair.$mode" 2>&1 || echo "callgrind failed on $pair $mode" >> "$tmp/errors"
}
export -f count
export tmp prof
touch "$tmp/errors"
[[ -n "$given" ]] || for p in $pairs; do
  echo "$p cold $ncold"
  echo "$p warm $nwarm"
done | xargs -P "$(nproc)" -L 1 bash -c 'count "$@"' _

compiler_id() {
  local cxx flags native
  [[ -f "$build/CMakeCache.txt" ]] || { echo unknown; return; }
  cxx=$(sed -n 's/^CMAKE_CXX_COMPILER:[A-Z]*=//p' "$build/CMakeCache.txt")
  flags=$(sed -n 's/^CMAKE_CXX_FLAGS_RELEASE:[A-Z]*=//p' "$build/CMakeCache.txt")
  native=$(sed -n 's/^IDCOL_NATIVE:[A-Z]*=//p' "$build/CMakeCache.txt")
  echo "$("$cxx" --version | head -1)|$flags|native=$native"
}

/usr/bin/python3 - "$tmp" "$ref" "$out/instructions.json" "$mode" "$(compiler_id)" "$ncold" "$nwarm" "$pairs" \
  "${IDCOL_INSTRUCTIONS_MAX_RISE:-0.03}" "${IDCOL_INSTRUCTIONS_ALLOW_MISMATCH:-0}" "$(git rev-parse HEAD 2> /dev/null || echo unknown)" \
  "$given" << 'EOF'
import json, os, re, sys
tmp, ref_path, out_path, mode, compiler, ncold, nwarm, pairs, max_rise, allow, rev, given = sys.argv[1:13]
counts = {"cold": int(ncold), "warm": int(nwarm)}
max_rise = float(max_rise)
res = {"schema": "idcol-instructions", "schema_version": 1, "toolchain": compiler, "git_revision": rev,
       "poses": counts, "max_rise": max_rise, "pairs": {}}
bad = []
for p in ([] if given else pairs.split()):
    res["pairs"][p] = {}
    for m, n in counts.items():
        f = os.path.join(tmp, "cg.%s.%s" % (p, m))
        ir = None
        if os.path.exists(f):
            for line in open(f):
                if line.startswith("summary:") or line.startswith("totals:"):
                    ir = int(line.split()[1])
                    break
        if ir is None:
            bad.append("%s %s: callgrind gave no count (%s)" % (p, m, open(os.path.join(tmp, "errors")).read().strip()[:300]))
            continue
        res["pairs"][p][m] = round(ir / n, 1)
if bad:
    print("ci_instructions: " + "; ".join(bad), file=sys.stderr)
    sys.exit(2)
if given:
    try:
        res = json.load(open(given))
        assert isinstance(res.get("pairs"), dict) and res.get("schema") == "idcol-instructions"
    except Exception as e:
        print("ci_instructions: %s is not a counts file of this script: %s" % (given, e), file=sys.stderr)
        sys.exit(2)
else:
    json.dump(res, open(out_path, "w"), indent=1)
if mode == "--refresh":
    json.dump(res, open(ref_path, "w"), indent=1)
    open(ref_path, "a").write("\n")
    print("reference %s rewritten: review with git diff and commit it" % ref_path)
    sys.exit(0)
try:
    ref = json.load(open(ref_path))
except Exception as e:
    print("ci_instructions: cannot read the reference %s: %s" % (ref_path, e), file=sys.stderr)
    sys.exit(2)
for key in ("toolchain", "poses"):
    if ref.get(key) != res[key] and not (key == "toolchain" and allow == "1"):
        print("ci_instructions: the reference was counted with %s %s, this build with %s: not comparable "
              "(refresh it with scripts/ci_instructions.sh --refresh on this toolchain, or "
              "IDCOL_INSTRUCTIONS_ALLOW_MISMATCH=1)" % (key, json.dumps(ref.get(key)), json.dumps(res[key])), file=sys.stderr)
        sys.exit(2)
failed, faster = [], []
print("%-12s %-5s %14s %14s %9s  %s" % ("pair", "mode", "reference", "now", "change", "verdict"))
for p, modes in res["pairs"].items():
    for m, v in modes.items():
        old = ref.get("pairs", {}).get(p, {}).get(m)
        if old is None:
            print("ci_instructions: %s %s is not in the reference %s" % (p, m, ref_path), file=sys.stderr)
            sys.exit(2)
        rise = v / old - 1.0
        verdict = "FAIL" if rise > max_rise else "faster" if rise < -max_rise else "same"
        if verdict == "FAIL":
            failed.append("%s %s" % (p, m))
        if verdict == "faster":
            faster.append("%s %s" % (p, m))
        print("%-12s %-5s %14.1f %14.1f %+8.2f%%  %s%s" % (p, m, old, v, 100 * rise, verdict, "  <<<" if verdict == "FAIL" else ""))
if faster:
    print("note: faster by more than %.0f%%: %s; refresh the reference (--refresh) so that it guards the new speed" % (100 * max_rise, ", ".join(faster)))
print("instructions per solve, %d pair-modes: %d FAIL (more than +%.0f%%) -> %s" %
      (sum(len(m) for m in res["pairs"].values()), len(failed), 100 * max_rise, "REGRESSION" if failed else "PASS"))
sys.exit(1 if failed else 0)
EOF
