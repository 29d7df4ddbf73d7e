#!/usr/bin/env bash
# Speed guard that fails without noise: instructions counted by callgrind
# (deterministic: the same build on the same inputs counts the same to the
# instruction, whatever the machine's load) on every path a user calls, for
# every pair of the paper's shapes, compared with the checked-in reference
# results/baseline/instructions.json. One callgrind run per pair
# (build/core/idcol_prof guard PAIR $ncold $nwarm $nmotions, collecting only
# around each path and dumping each path's count on its own) counts:
#
#   cold, warm             the loop of solve(): cold on $ncold poses spread
#                          over the paper's sweep, warm on its first $nwarm
#                          consecutive poses (instructions per solve)
#   batch_cold, batch_warm the same poses through solve_batch on one thread,
#                          its SIMD lanes (under valgrind the AVX2 kernels, 4
#                          lanes; the reference names the instruction set)
#   deriv_solve            the cold poses solved with SolverOptions::derivatives
#                          (per solve)
#   deriv                  alpha_gradient and solution_sensitivity of each of
#                          those solves (per pose, the solve not counted)
#   shape                  shape_sensitivity of body 1 and of body 2 of each
#                          of those solves (per pose, the solve not counted)
#   toi_translation,       time_of_impact on $nmotions seeded motions of each
#   toi_screw              kind (instructions per query), and the
#                          *_solves beside them: solves per query
#
# An entry that rises by more than IDCOL_INSTRUCTIONS_MAX_RISE (default 0.03,
# i.e. 3%) fails. Why 3%: the counts are exact (two runs of one build agree
# to the instruction), so any rise is the code's or the compiler's; 3% leaves
# room for incidental changes of the generated code from edits elsewhere (an
# inlining decision that moves), while a slower solver step moves every pair
# by far more: one extra evaluation of the KKT residual (both shapes' value,
# gradient and Hessian) per Newton iteration fails every pair the loop solves
# by Newton steps (scripts/mutations.sh slow_step shows it and one slowed
# step of each other path: slow_batch, slow_deriv, slow_shape, slow_toi;
# Ellip-Ellip, which the ellipsoid closed form solves with almost no Newton
# steps, barely moves). Perturbing every time-of-impact motion's end points
# by 1e-6 of their size moved no pair's solves per query by more than 0.7%.
# Faster entries pass, with a note to refresh the reference.
#
#   scripts/ci_instructions.sh              # count and compare (CI); exit 0 pass, 1 regression, 2 bad input
#   scripts/ci_instructions.sh --refresh    # after a deliberate change: rewrite the reference
#   scripts/ci_instructions.sh --compare COUNTS.json   # compare counts made before (no callgrind run)
#
# The reference holds the compiler and flags it was counted with and the
# batch's instruction set; counts of another toolchain or instruction set are
# not comparable (exit 2, naming both) unless IDCOL_INSTRUCTIONS_ALLOW_MISMATCH=1.
# An entry of the reference that was not counted, or one counted that the
# reference lacks, is bad input (exit 2): a path cannot leave the guard
# silently. Environment: IDCOL_BUILD_DIR (default build), IDCOL_CI_OUT
# (default build/ci), IDCOL_INSTRUCTIONS_REF.
set -euo pipefail
cd "$(dirname "$0")/.."
build="${IDCOL_BUILD_DIR:-build}"
out="${IDCOL_CI_OUT:-$build/ci}"
ref="${IDCOL_INSTRUCTIONS_REF:-results/baseline/instructions.json}"
prof="$build/core/idcol_prof"
ncold=200
nwarm=400
nmotions=20
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

# One callgrind run per pair, as many at a time as there are CPUs (the
# counts do not depend on it); each path's count lands in its own dump,
# $tmp/cg.PAIR.N, named inside by the path.
count() {
  local pair=$1
  valgrind --tool=callgrind --collect-atstart=no --callgrind-out-file="$tmp/cg.$pair" \
    "$prof" guard "$pair" "$ncold" "$nwarm" "$nmotions" > "$tmp/log.$pair" 2> "$tmp/err.$pair" ||
    { echo "callgrind failed on $pair: $(tail -3 "$tmp/err.$pair" | tr '\n' ' ')" >> "$tmp/errors"; }
}
export -f count
export tmp prof ncold nwarm nmotions
touch "$tmp/errors"
[[ -n "$given" ]] || printf '%s\n' $pairs | xargs -P "$(nproc)" -L 1 bash -c 'count "$@"' _

compiler_id() {
  local cxx flags native
  [[ -f "$build/CMakeCache.txt" ]] || { echo unknown; return; }
  cxx=$(sed -n 's/^CMAKE_CXX_COMPILER:[A-Z]*=//p' "$build/CMakeCache.txt")
  flags=$(sed -n 's/^CMAKE_CXX_FLAGS_RELEASE:[A-Z]*=//p' "$build/CMakeCache.txt")
  native=$(sed -n 's/^IDCOL_NATIVE:[A-Z]*=//p' "$build/CMakeCache.txt")
  echo "$("$cxx" --version | head -1)|$flags|native=$native"
}

/usr/bin/python3 - "$tmp" "$ref" "$out/instructions.json" "$mode" "$(compiler_id)" "$ncold" "$nwarm" "$nmotions" "$pairs" \
  "${IDCOL_INSTRUCTIONS_MAX_RISE:-0.03}" "${IDCOL_INSTRUCTIONS_ALLOW_MISMATCH:-0}" "$(git rev-parse HEAD 2> /dev/null || echo unknown)" \
  "$given" << 'EOF'
import glob, json, os, re, sys
tmp, ref_path, out_path, mode, compiler, ncold, nwarm, nmotions, pairs, max_rise, allow, rev, given = sys.argv[1:14]
ncold, nwarm, nmotions, max_rise = int(ncold), int(nwarm), int(nmotions), float(max_rise)
# Each path: what its count is divided by, and the unit of the quotient.
paths = {"cold": (ncold, "Ir/solve"), "warm": (nwarm, "Ir/solve"),
         "batch_cold": (ncold, "Ir/solve"), "batch_warm": (nwarm, "Ir/solve"),
         "deriv_solve": (ncold, "Ir/solve"), "deriv": (ncold, "Ir/pose"), "shape": (ncold, "Ir/pose"),
         "toi_translation": (nmotions, "Ir/query"), "toi_screw": (nmotions, "Ir/query")}
solves = ("toi_translation", "toi_screw")  # their solves per query, as <path>_solves
units = {m: u for m, (_, u) in paths.items()}
units.update({m + "_solves": "solves/query" for m in solves})
res = {"schema": "idcol-instructions", "schema_version": 2, "toolchain": compiler, "batch_simd": None, "git_revision": rev,
       "per": {m: n for m, (n, _) in paths.items()}, "units": units, "max_rise": max_rise, "pairs": {}}
bad = []
errors = open(os.path.join(tmp, "errors")).read().strip()[:600]
for p in ([] if given else pairs.split()):
    counts = {}
    for f in glob.glob(os.path.join(tmp, "cg.%s.*" % p)):
        name = ir = None
        for line in open(f):
            m = re.match(r"desc: Trigger: Client Request: (\S+)", line)
            if m:
                name = m.group(1)
            if line.startswith("summary:") or line.startswith("totals:"):
                ir = int(line.split()[1])
                break
        if name in paths and ir is not None:
            counts[name] = ir
    log = open(os.path.join(tmp, "log.%s" % p)).read() if os.path.exists(os.path.join(tmp, "log.%s" % p)) else ""
    entry = {}
    for m, (n, _) in paths.items():
        if m not in counts:
            bad.append("%s %s: callgrind gave no count (%s)" % (p, m, errors or "no dump named %s" % m))
            continue
        entry[m] = round(counts[m] / n, 1)
    for m in solves:
        s = re.search(r"^solves %s (\S+)$" % m, log, re.M)
        if not s:
            bad.append("%s %s_solves: idcol_prof printed no solves per query" % (p, m))
            continue
        entry[m + "_solves"] = float(s.group(1))
    isa = re.search(r" simd (\S+) ", log)
    if isa:
        res["batch_simd"] = isa.group(1)
    res["pairs"][p] = entry
if bad:
    print("ci_instructions: " + "; ".join(bad), file=sys.stderr)
    sys.exit(2)
if given:
    try:
        res = json.load(open(given))
        assert isinstance(res.get("pairs"), dict) and res.get("schema") == "idcol-instructions", "not an idcol-instructions file"
        assert res.get("schema_version") == 2, "schema_version %s, this script reads 2" % json.dumps(res.get("schema_version"))
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
if ref.get("schema_version") != 2:
    print("ci_instructions: the reference %s has schema_version %s, this script reads 2 (refresh it with "
          "scripts/ci_instructions.sh --refresh)" % (ref_path, json.dumps(ref.get("schema_version"))), file=sys.stderr)
    sys.exit(2)
for key in ("toolchain", "batch_simd", "per"):
    if ref.get(key) != res.get(key) and not (key != "per" and allow == "1"):
        print("ci_instructions: the reference was counted with %s %s, this build with %s: not comparable "
              "(refresh it with scripts/ci_instructions.sh --refresh on this toolchain, or "
              "IDCOL_INSTRUCTIONS_ALLOW_MISMATCH=1)" % (key, json.dumps(ref.get(key)), json.dumps(res.get(key))), file=sys.stderr)
        sys.exit(2)
ref_pairs = ref.get("pairs", {})
for p, modes in ref_pairs.items():
    for m in modes:
        if m not in res["pairs"].get(p, {}):
            print("ci_instructions: %s %s is in the reference %s but was not counted" % (p, m, ref_path), file=sys.stderr)
            sys.exit(2)
failed, faster = [], []
print("%-12s %-22s %-13s %14s %14s %9s  %s" % ("pair", "path", "unit", "reference", "now", "change", "verdict"))
for p, modes in res["pairs"].items():
    for m, v in modes.items():
        old = ref_pairs.get(p, {}).get(m)
        if old is None:
            print("ci_instructions: %s %s is not in the reference %s" % (p, m, ref_path), file=sys.stderr)
            sys.exit(2)
        rise = v / old - 1.0
        verdict = "FAIL" if rise > max_rise else "faster" if rise < -max_rise else "same"
        if verdict == "FAIL":
            failed.append("%s %s" % (p, m))
        if verdict == "faster":
            faster.append("%s %s" % (p, m))
        unit = res["units"].get(m, "?")
        row = "%-12s %-22s %-13s %14.1f %14.1f %+8.2f%%  %s%s" if unit != "solves/query" else "%-12s %-22s %-13s %14.2f %14.2f %+8.2f%%  %s%s"
        print(row % (p, m, unit, old, v, 100 * rise, verdict, "  <<<" if verdict == "FAIL" else ""))
if faster:
    print("note: faster by more than %.0f%%: %s; refresh the reference (--refresh) so that it guards the new speed" % (100 * max_rise, ", ".join(faster)))
n = sum(len(m) for m in res["pairs"].values())
print("instructions per solve, per pose, per query and solves per query, %d entries (%d pairs, %d paths): "
      "%d FAIL (more than +%.0f%%) -> %s" % (n, len(res["pairs"]), n // max(1, len(res["pairs"])), len(failed), 100 * max_rise,
                                              "REGRESSION" if failed else "PASS"))
sys.exit(1 if failed else 0)
EOF
