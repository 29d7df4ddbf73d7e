#!/usr/bin/env bash
# Regenerates the results files of results/ (hours on a 2-core machine: the
# last run of each is in --list), from a Release build in build/.
#
#   scripts/regenerate_results.sh --list                 # each entry: its files, the revision and time of the checked-in one
#   scripts/regenerate_results.sh --dry-run [NAME...]    # the commands, each scene validated by `idcol_harness check`
#   scripts/regenerate_results.sh [--out DIR] [NAME...]  # run them (default DIR build/regen; every entry without NAME)
#
# With --out DIR (default build/regen) nothing under results/ is written: the
# new files land in DIR, and the summary compares each with the checked-in
# file (`idcol_harness compare`, --common-pairs) and says same, changed or
# worse. `--out results` replaces the checked-in files (the old ones are
# kept in build/regen-previous/ for the summary's comparison). Entries that
# write into results/ whatever the folder (random_bodies, baseline) run
# only with `--out results`.
#
# Progress: one line per command with the elapsed time; the summary at the
# end lists every entry with its time and what changed.
# Exit status: 0 every command succeeded (a worse result is reported, not an
# error); 1 a command failed (the others still run); 2 bad command line.
set -uo pipefail
cd "$(dirname "$0")/.."
H=build/harness/idcol_harness
out=build/regen
mode=run
names=()
while (($#)); do
  case $1 in
    --list) mode=list ;;
    --dry-run) mode=dry ;;
    --out) out=${2:?--out needs a folder}; shift ;;
    -h|--help) sed -n '2,20p' "$0" | sed 's/^# \{0,1\}//'; exit 0 ;;
    -*) echo "regenerate_results.sh: unknown option $1 (--help)" >&2; exit 2 ;;
    *) names+=("$1") ;;
  esac
  shift
done
out=${out%/}

ENTRIES=(paper_table1 paper_table2 uniform_so3 stress smoothing callgrind_pairs callgrind_batch throughput toi_vs_fcl python_batch plan_path multibody multibody_scaling random_bodies baseline)

# The commands of one entry, one a line, for the output folder $out.
commands() {
  local o=$out
  case $1 in
    paper_table1)
      echo "taskset -c 0 $H run configs/paper_table1.toml -o $o/paper_table1.json --pin 0 --no-progress"
      echo "$H table $o/paper_table1.json -o $o/paper_table1.md"
      echo "scripts/plot_run.py $o/paper_table1.json -o $o" ;;
    paper_table2)
      echo "taskset -c 0 $H run configs/paper_table2.toml -o $o/paper_table2.json --pin 0 --no-progress"
      echo "$H table $o/paper_table2.json -o $o/paper_table2.md" ;;
    uniform_so3)
      echo "$H run configs/uniform_so3.toml -o $o/uniform_so3.json --threads 2 --no-progress"
      echo "$H table $o/uniform_so3.json -o $o/uniform_so3.md" ;;
    stress)
      echo "$H stress configs/stress.toml -o $o/stress.json --threads 2 --max-failures 20 --no-progress"
      echo "$H table $o/stress.json -o $o/stress.md" ;;
    smoothing)
      for f in polytope cone superellipsoid cylinder; do
        echo "taskset -c 0 $H smoothing configs/smoothing_$f.toml -o $o/smoothing_$f.json --threads 2 --pin 0 --no-progress"
      done
      echo "scripts/plot_smoothing.py $o/smoothing_polytope.json $o/smoothing_cone.json $o/smoothing_superellipsoid.json $o/smoothing_cylinder.json -o $o --md $o/smoothing.md --combined $o/smoothing_error_vs_time.png" ;;
    callgrind_pairs) echo "scripts/callgrind_record.sh build $o/callgrind_pairs.md" ;;
    callgrind_batch) echo "scripts/callgrind_record.sh build $o/callgrind_batch.md --batch" ;;
    throughput) echo "build/core/idcol_bench_throughput --poses 100000 --reps 3 --cpu 0 --narrow avx2 --out $o/throughput" ;;
    toi_vs_fcl) echo "taskset -c 0 build/baselines/idcol_toi_vs_fcl --out $o/toi_vs_fcl" ;;
    python_batch) echo "PYTHONPATH=build/python /usr/bin/python3 scripts/bench_python_batch.py --reps 5 -o $o/python_batch.json" ;;
    plan_path) echo "PYTHONPATH=build/python /usr/bin/python3 scripts/examples/plan_path.py -o $o/plan_path.png" ;;
    multibody)
      echo "build/core/idcol_multibody --reps 5 -o $o/multibody.json"
      echo "scripts/plot_multibody.py $o/multibody.json -o $o/multibody.png" ;;
    multibody_scaling)
      echo "build/core/idcol_bench_multibody_scaling --steps 20 --reps 3 -o $o/multibody_scaling.json"
      echo "scripts/plot_multibody.py --scaling $o/multibody_scaling.json -o $o/multibody_scaling.png" ;;
    random_bodies) echo "scripts/random_bodies_full.sh 50000 both 2" ;;
    baseline) echo "scripts/ci_compare.sh --refresh" ;;
  esac
}
# The checked-in results file an entry is compared by, and whether the entry
# writes into results/ whatever --out says.
main_file() {
  case $1 in
    smoothing) echo smoothing_polytope.json ;;
    callgrind_pairs) echo callgrind_pairs.md ;;
    callgrind_batch) echo callgrind_batch.md ;;
    plan_path) echo plan_path.png ;;
    random_bodies) echo random_bodies_normal.json ;;
    baseline) echo baseline/ci.json ;;
    *) echo "$1.json" ;;
  esac
}
fixed_place() { [[ $1 == random_bodies || $1 == baseline ]]; }

# Revision and wall time of the checked-in file, from its own metadata.
provenance() {
  local f=results/$(main_file "$1")
  [[ $f == *.json && -f $f ]] || { echo "its provenance: results/README.md"; return; }
  /usr/bin/python3 - "$f" <<'PY'
import json, sys
d = json.load(open(sys.argv[1]))
m = d.get("metadata") or d.get("context") or d
rev = m.get("git_revision") or d.get("git_revision") or "?"
wall = d.get("wall_seconds")
print(f"made at {str(rev)[:7]}" + (f", {wall:.0f} s wall" if isinstance(wall, (int, float)) else ""))
PY
}

((${#names[@]})) || names=("${ENTRIES[@]}")
for n in "${names[@]}"; do
  [[ " ${ENTRIES[*]} " == *" $n "* ]] || { echo "regenerate_results.sh: unknown entry $n (--list names them)" >&2; exit 2; }
done

if [[ $mode == list ]]; then
  for n in "${names[@]}"; do
    printf '%-16s results/%-28s %s%s\n' "$n" "$(main_file "$n")" "$(provenance "$n")" \
      "$(fixed_place "$n" && echo '; writes results/ itself')"
  done
  exit 0
fi

if [[ $mode == dry ]]; then
  bad=0
  for n in "${names[@]}"; do
    echo "# $n ($(provenance "$n"))"
    while IFS= read -r c; do
      echo "$c"
      # Each program named must exist; each scene must be valid (check prints its cost).
      read -r -a w <<< "${c#taskset -c 0 }"
      [[ ${w[0]} == PYTHONPATH=* ]] && w=("${w[@]:1}")
      if [[ ! -x ${w[0]} ]]; then echo "#   missing: ${w[0]} (build it, or scripts/setup.sh)"; bad=1; fi
      if [[ ${w[0]} == "$H" && ${w[1]} =~ ^(run|stress|smoothing)$ ]]; then
        if [[ -x $H ]]; then
          "$H" check "${w[2]}" | grep '^#' | sed 's/^/#   /' || { echo "#   invalid scene ${w[2]}"; bad=1; }
        fi
      fi
    done < <(commands "$n")
  done
  exit $bad
fi

mkdir -p "$out"
previous=results
if [[ $(readlink -f "$out") == $(readlink -f results) ]]; then
  previous=build/regen-previous
  mkdir -p "$previous" && cp -a results/. "$previous"/
fi
failed=0 summary=()
total=${#names[@]} i=0 start_all=$SECONDS
for n in "${names[@]}"; do
  i=$((i + 1))
  if fixed_place "$n" && [[ $previous == results ]]; then
    summary+=("$(printf '%-16s skipped: writes results/ itself (use --out results)' "$n")")
    continue
  fi
  echo "[$i/$total] $n (last time: $(provenance "$n"))"
  start=$SECONDS rc=0
  while IFS= read -r c; do
    echo "  \$ $c"
    bash -c "$c" || { rc=$?; echo "  FAILED (exit $rc): $c"; }
    echo "  ... $((SECONDS - start)) s"
  done < <(commands "$n")
  verdict="ok"
  ((rc)) && { verdict="FAILED (exit $rc)"; failed=1; }
  f=$(main_file "$n")
  new=$out/$(basename "$f")
  fixed_place "$n" && new=results/$f
  if ((rc == 0)) && [[ $f == *.json && -f $previous/$f && -f $new ]] && [[ $n != throughput && $n != toi_vs_fcl && $n != python_batch && $n != multibody* ]]; then
    "$H" compare "$previous/$f" "$new" --common-pairs > "$out/$n.compare.txt" 2>&1
    case $? in
      0) if grep -q '^no metric changed' "$out/$n.compare.txt"; then verdict="same (every metric of compare)"
         else verdict="changed, within the guards: $(tail -n 1 "$out/$n.compare.txt") ($out/$n.compare.txt)"; fi ;;
      1) verdict="worse: a guarded metric regressed ($out/$n.compare.txt)" ;;
      *) verdict="not comparable ($out/$n.compare.txt)" ;;
    esac
  elif ((rc == 0)) && [[ -f $previous/$f && -f $new ]]; then
    cmp -s "$previous/$f" "$new" && verdict="same" || verdict="changed (not a harness file: diff it)"
  fi
  summary+=("$(printf '%-16s %6d s  %s' "$n" $((SECONDS - start)) "$verdict")")
done
echo "==== summary ($((SECONDS - start_all)) s, into $out)"
printf '%s\n' "${summary[@]}"
exit $failed
