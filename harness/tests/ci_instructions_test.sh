#!/usr/bin/env bash
# scripts/ci_instructions.sh --compare, judged on counts made by hand from the
# checked-in reference (no callgrind run): the reference passes against
# itself; every entry of one path 10% higher (every path in turn: the loop,
# the batch, derivatives, shape sensitivities, time of impact's instructions
# and solves per query) fails on exactly that path's rows, for every pair;
# 2% higher passes; a path left uncounted, a reference of another schema or
# another batch instruction set is bad input (exit 2).
#   ci_instructions_test.sh SOURCE_DIR
set -uo pipefail
src=$1
work=$(mktemp -d /tmp/idcol_ci_instructions_test.XXXXXX)
trap 'rm -rf "$work"' EXIT
ref=$src/results/baseline/instructions.json
fails=0

# run REF COUNTS: the comparison's exit status in $rc, its output in $work/log.
run() {
  IDCOL_INSTRUCTIONS_REF="$1" IDCOL_CI_OUT="$work/out" "$src/scripts/ci_instructions.sh" --compare "$2" > "$work/log" 2>&1
  rc=$?
}
# counts FILE PYTHON: FILE is the reference edited by the statements (on the JSON as j).
counts() {
  /usr/bin/python3 -c "import json,sys; j=json.load(open(sys.argv[1])); $2; json.dump(j, open(sys.argv[2], 'w'))" "$ref" "$work/$1"
}
verdict() {  # verdict WHAT OK: prints ok or FAIL with the log
  if [[ $2 == yes ]]; then
    echo "ok: $1"
  else
    echo "FAIL: $1 (exit $rc)"
    cat "$work/log"
    fails=1
  fi
}

paths=$(/usr/bin/python3 -c "import json,sys; print(' '.join(json.load(open(sys.argv[1]))['units']))" "$ref")
pairs=$(/usr/bin/python3 -c "import json,sys; print(len(json.load(open(sys.argv[1]))['pairs']))" "$ref")
for want in cold warm batch_cold batch_warm deriv_solve deriv shape toi_translation toi_screw toi_translation_solves toi_screw_solves; do
  [[ " $paths " == *" $want "* ]] || { echo "FAIL: the reference has no path $want"; fails=1; }
done
[[ $pairs -eq 15 ]] || { echo "FAIL: the reference has $pairs pairs, not the paper's 15"; fails=1; }

run "$ref" "$ref"
verdict "the reference against itself passes" "$([[ $rc -eq 0 ]] && grep -q ' 0 FAIL .*PASS' "$work/log" && echo yes)"

for path in $paths; do
  counts "slow.json" "[e.__setitem__('$path', e['$path'] * 1.10) for e in j['pairs'].values()]"
  run "$ref" "$work/slow.json"
  # every pair's row of this path FAIL, no other row
  n_path=$(grep -cE "^[^ ]+ +$path +.* FAIL" "$work/log")
  n_all=$(grep -cE " FAIL  <<<" "$work/log")
  verdict "$path 10% higher on every pair: $n_path of $pairs rows FAIL, $n_all in all" \
    "$([[ $rc -eq 1 && $n_path -eq $pairs && $n_all -eq $pairs ]] && grep -q 'REGRESSION' "$work/log" && echo yes)"
  counts "near.json" "[e.__setitem__('$path', e['$path'] * 1.02) for e in j['pairs'].values()]"
  run "$ref" "$work/near.json"
  verdict "$path 2% higher on every pair passes" "$([[ $rc -eq 0 ]] && echo yes)"
done

counts "fast.json" "j['pairs']['SE-SE']['batch_cold'] *= 0.9"
run "$ref" "$work/fast.json"
verdict "10% faster passes with a note to refresh" "$([[ $rc -eq 0 ]] && grep -q '^note: faster .*SE-SE batch_cold' "$work/log" && echo yes)"

counts "dropped.json" "del j['pairs']['TC-SE']['toi_screw_solves']"
run "$ref" "$work/dropped.json"
verdict "a path left uncounted is bad input" "$([[ $rc -eq 2 ]] && grep -q 'TC-SE toi_screw_solves is in the reference .* but was not counted' "$work/log" && echo yes)"

counts "extra.json" "j['pairs']['TC-SE']['toi_new'] = 1.0"
run "$ref" "$work/extra.json"
verdict "a path the reference lacks is bad input" "$([[ $rc -eq 2 ]] && grep -q 'TC-SE toi_new is not in the reference' "$work/log" && echo yes)"

counts "v1.json" "j['schema_version'] = 1"
run "$work/v1.json" "$ref"
verdict "a reference of schema_version 1 is bad input" "$([[ $rc -eq 2 ]] && grep -q 'schema_version 1, this script reads 2' "$work/log" && echo yes)"

counts "isa.json" "j['batch_simd'] = 'sse2'"
run "$ref" "$work/isa.json"
verdict "counts of another batch instruction set are not comparable" "$([[ $rc -eq 2 ]] && grep -q 'batch_simd "avx2", this build with "sse2"' "$work/log" && echo yes)"

exit $fails
