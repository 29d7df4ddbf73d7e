#!/usr/bin/env bash
# scripts/ci_compare.sh, judged on results made by hand from the checked-in
# references (--compare-only: no run): the references themselves pass; a
# regressed figure, a rise in instructions per solve, a missing results file
# and a run of other solver options each turn the stage's exit status to 1
# (regression) or 2 (bad input), with the failing row named; an unknown
# argument is refused (exit 2) before anything runs.
#   ci_compare_test.sh SOURCE_DIR BUILD_DIR
set -uo pipefail
src=$1
build=$2
work=$(mktemp -d /tmp/idcol_ci_compare_test.XXXXXX)
trap 'rm -rf "$work"' EXIT
out=$work/out
fails=0

reset() {
  rm -rf "$out"
  mkdir -p "$out"
  cp "$src"/results/baseline/{ci,stress,random_bodies,smoothing_polytope,paper_table2,uniform_so3,ci_toi,instructions}.json "$out/"
}
# expect RC WHAT [PATTERN]: runs the stage; its exit status must be RC and its output hold PATTERN.
expect() {
  local want=$1 what=$2 pattern=${3:-}
  IDCOL_BUILD_DIR="$build" IDCOL_CI_OUT="$out" "$src/scripts/ci_compare.sh" --compare-only > "$work/log" 2>&1
  local rc=$?
  if [[ $rc -ne $want ]]; then
    echo "FAIL: $what: exit $rc, expected $want"
    cat "$work/log"
    fails=1
  elif [[ -n "$pattern" ]] && ! grep -qE -- "$pattern" "$work/log"; then
    echo "FAIL: $what: the output does not show /$pattern/"
    cat "$work/log"
    fails=1
  else
    echo "ok: $what (exit $rc)"
  fi
}
edit() {  # edit FILE PYTHON-STATEMENTS (on the JSON as j)
  /usr/bin/python3 -c "import json,sys; p=sys.argv[1]; j=json.load(open(p)); $2; json.dump(j, open(p, 'w'))" "$out/$1"
}

# usage ARGS RC PATTERN: the stage's own arguments. An unknown one (a typo
# once ran every cut) and --help run nothing: no output folder appears, and
# no harness is needed (the build folder here has none).
usage() {
  local want=$2 pattern=$3
  IDCOL_BUILD_DIR="$work/no-build" IDCOL_CI_OUT="$work/usage-out" "$src/scripts/ci_compare.sh" $1 > "$work/log" 2>&1
  local rc=$?
  if [[ $rc -ne $want ]] || ! grep -qE -- "$pattern" "$work/log" || [[ -e $work/usage-out ]]; then
    echo "FAIL: ci_compare.sh $1: exit $rc (expected $want), output /$pattern/ expected, ran nothing expected"
    cat "$work/log"
    fails=1
  else
    echo "ok: ci_compare.sh $1 (exit $rc)"
  fi
}
usage "--help" 0 "^usage: scripts/ci_compare.sh|scripts/ci_compare.sh --refresh"
usage "-h" 0 "--compare-only"
usage "--hepl" 2 "unknown argument '--hepl' \\(nothing run\\); usage:"
usage "--refresh --compare-only" 2 "expected at most one argument"
usage "refresh" 2 "unknown argument 'refresh'"

reset
expect 0 "the references against themselves"

reset
edit ci.json "j['pairs'][0]['passes']['cold']['failures'] += 5"
expect 1 "five new failed solves in the CI sweep" "ci: Poly-Poly: cold.failures .* FAIL"

reset
edit stress.json "j['cases'][0]['passes']['cold']['genuine_rate'] = None"
expect 1 "a null genuine rate in the stress cut" "stress: .*cold.genuine_rate .* FAIL"

reset
edit instructions.json "j['pairs']['SE-SE']['cold'] *= 1.10"
expect 1 "10% more instructions per solve on one pair" "instructions: SE-SE +cold .*FAIL"

reset
rm "$out/random_bodies.json"
expect 2 "a missing results file"

reset
edit smoothing_polytope.json "j['solver']['tolerance'] = 1e-8"
expect 2 "a smoothing run with another solver tolerance" "solver.tolerance: OLD 1e-10, NEW 1e-08"

reset
edit instructions.json "j['toolchain'] = 'another compiler'"
expect 2 "instruction counts of another toolchain"

exit $fails
