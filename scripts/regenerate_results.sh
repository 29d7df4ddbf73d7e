#!/usr/bin/env bash
# Regenerates the results files of results/ (hours on a 2-core machine: the
# last run of each is in --list), from a Release build in build/.
#
#   scripts/regenerate_results.sh --list                 # each entry: its main file, its revision, age and time
#   scripts/regenerate_results.sh --files [NAME...]      # each entry's files under results/, one "ENTRY FILE" a line
#   scripts/regenerate_results.sh --dry-run [NAME...]    # the commands, each scene validated by `idcol_harness check`
#   scripts/regenerate_results.sh [--out DIR] [NAME...]  # run them (default DIR build/regen; every entry without NAME)
#
# A file's age is the number of commits that touch core since the revision
# it was made at; the documentation's check (scripts/check_doc_figures.py,
# ctest docs.figures) fails when a quoted file is older than its bound
# (MAX_CORE_COMMITS there) or when no entry here lists it in --files.
#
# With --out DIR (default build/regen) nothing under results/ is written: the
# new files land in DIR, and the summary compares each with the checked-in
# file (`idcol_harness compare`, --common-pairs) and says same, changed or
# worse. `--out results` replaces the checked-in files (the old ones are
# kept in build/regen-previous/ for the summary's comparison). Entries that
# write into results/ whatever the folder (random_bodies, baseline) run
# only with `--out results`. An entry that needs more CPUs than this
# machine has (scaling16: 16) is skipped, saying so, unless named.
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
    --files) mode=files ;;
    --out) out=${2:?--out needs a folder}; shift ;;
    -h|--help) sed -n '2,/^set -uo/{/^#/s/^# \{0,1\}//p}' "$0"; exit 0 ;;
    -*) echo "regenerate_results.sh: unknown option $1 (--help)" >&2; exit 2 ;;
    *) names+=("$1") ;;
  esac
  shift
done
out=${out%/}

ENTRIES=(paper_table1 paper_table2 uniform_so3 stress smoothing dcol_oracles dcol_random_bodies toi callgrind_pairs callgrind_batch throughput
         scaling16 toi_vs_fcl python_batch plan_path multibody multibody_scaling test_figures random_bodies baseline)

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
    dcol_oracles)
      echo "$H run configs/dcol_oracles.toml -o $o/dcol_oracles.json --threads 2 --no-progress"
      echo "$H table $o/dcol_oracles.json -o $o/dcol_oracles.md" ;;
    dcol_random_bodies)
      # The wide range at 5000 poses a pair: its oracles (GLPK's LP on
      # badly scaled polytopes) cost over ten times the normal range's per pose.
      echo "build/harness/idcol_check_dcol_random_bodies 20000 0 1 -o $o/dcol_random_bodies_normal.json"
      echo "build/harness/idcol_check_dcol_random_bodies 5000 1 1 -o $o/dcol_random_bodies_wide.json" ;;
    toi)
      echo "taskset -c 0 $H run configs/toi.toml -o $o/toi.json --pin 0 --no-progress"
      echo "$H table $o/toi.json -o $o/toi.md" ;;
    smoothing)
      for f in polytope cone superellipsoid cylinder; do
        echo "taskset -c 0 $H smoothing configs/smoothing_$f.toml -o $o/smoothing_$f.json --threads 2 --pin 0 --no-progress"
      done
      echo "scripts/plot_smoothing.py $o/smoothing_polytope.json $o/smoothing_cone.json $o/smoothing_superellipsoid.json $o/smoothing_cylinder.json -o $o --md $o/smoothing.md --combined $o/smoothing_error_vs_time.png" ;;
    callgrind_pairs) echo "scripts/callgrind_record.sh build $o/callgrind_pairs.md" ;;
    callgrind_batch) echo "scripts/callgrind_record.sh build $o/callgrind_batch.md --batch" ;;
    throughput) echo "build/core/idcol_bench_throughput --poses 100000 --reps 5 --cpu 0 --scaling 2 --balance 16 --narrow avx2 --out $o/throughput" ;;
    scaling16) echo "scripts/throughput_scaling.sh build $o/scaling16 100000 16 5" ;;
    toi_vs_fcl) echo "taskset -c 0 build/baselines/idcol_toi_vs_fcl --out $o/toi_vs_fcl" ;;
    python_batch) echo "PYTHONPATH=build/python /usr/bin/python3 scripts/bench_python_batch.py --reps 5 -o $o/python_batch.json" ;;
    plan_path) echo "PYTHONPATH=build/python /usr/bin/python3 scripts/examples/plan_path.py -o $o/plan_path.png" ;;
    multibody)
      echo "build/core/idcol_multibody --reps 5 -o $o/multibody.json"
      echo "scripts/plot_multibody.py $o/multibody.json -o $o/multibody.png" ;;
    multibody_scaling)
      echo "build/core/idcol_bench_multibody_scaling --steps 20 --reps 3 -o $o/multibody_scaling.json"
      echo "scripts/plot_multibody.py --scaling $o/multibody_scaling.json -o $o/multibody_scaling.png" ;;
    test_figures) echo "scripts/record_test_figures.py build -o $o/test_figures.json" ;;
    random_bodies) echo "scripts/random_bodies_full.sh 50000 both 2 40" ;;
    baseline)
      echo "scripts/ci_compare.sh --refresh"
      echo "scripts/ci_multibody.sh --refresh" ;;
  esac
}
# The files under results/ an entry makes (the failures files beside a
# harness run's results included). scripts/check_doc_figures.py reads this
# list: a quoted file that no entry makes fails the documentation's check.
files() {
  local r
  case $1 in
    paper_table1) r="paper_table1.json paper_table1.failures.json paper_table1.md paper_table1_times.png paper_table1_iterations.png" ;;
    paper_table2 | uniform_so3 | stress | dcol_oracles | toi) r="$1.json $1.failures.json $1.md" ;;
    smoothing)
      for f in polytope cone superellipsoid cylinder; do r+="smoothing_$f.json smoothing_$f.failures.json smoothing_$f.png "; done
      r+="smoothing.md smoothing_error_vs_time.png" ;;
    callgrind_pairs | callgrind_batch) r="$1.md" ;;
    throughput | toi_vs_fcl) r="$1.json $1.md" ;;
    scaling16) r="scaling16/cpu.txt scaling16/log.txt scaling16/throughput.json scaling16/throughput.md scaling16/large.json scaling16/large.md scaling16/processes.md scaling16/summary.json" ;;
    python_batch | test_figures) r="$1.json" ;;
    dcol_random_bodies) r="dcol_random_bodies_normal.json dcol_random_bodies_wide.json" ;;
    plan_path) r="plan_path.png" ;;
    multibody | multibody_scaling) r="$1.json $1.png" ;;
    random_bodies) for g in normal wide; do r+="random_bodies_$g.json random_bodies_$g.failures.json random_bodies_$g.md "; done ;;
    baseline)
      for f in ci stress random_bodies smoothing_polytope paper_table2 uniform_so3 ci_toi; do r+="baseline/$f.json baseline/$f.failures.json "; done
      r+="baseline/ci.md baseline/stress.md baseline/random_bodies.md baseline/ci_toi.md baseline/instructions.json baseline/multibody_step.json" ;;
  esac
  for f in $r; do echo "$1 results/$f"; done
}
# The CPUs an entry needs (it times 1..16 threads and 16 processes).
cpus_needed() { [[ $1 == scaling16 ]] && echo 16 || echo 1; }
# The checked-in results file an entry is compared by, and whether the entry
# writes into results/ whatever --out says.
main_file() {
  case $1 in
    smoothing) echo smoothing_polytope.json ;;
    scaling16) echo scaling16/summary.json ;;
    callgrind_pairs) echo callgrind_pairs.md ;;
    callgrind_batch) echo callgrind_batch.md ;;
    plan_path) echo plan_path.png ;;
    random_bodies) echo random_bodies_normal.json ;;
    baseline) echo baseline/ci.json ;;
    *) echo "$1.json" ;;
  esac
}
fixed_place() { [[ $1 == random_bodies || $1 == baseline ]]; }

# Revision, age and wall time of the checked-in file, from its own metadata
# (the revision and age as the documentation's check reads them).
provenance() {
  local f=results/$(main_file "$1") age wall=""
  [[ -f $f ]] || { echo "not made yet"; return; }
  [[ $f != *.png ]] || { echo "its provenance: results/README.md"; return; }
  age=$(/usr/bin/python3 scripts/check_doc_figures.py --age "$f")
  [[ $f == *.json ]] && wall=$(/usr/bin/python3 -c '
import json, sys
w = json.load(open(sys.argv[1])).get("wall_seconds")
print(f", {w:.0f} s wall" if isinstance(w, (int, float)) else "")' "$f")
  echo "${age#"$f: "}$wall"
}

named=("${names[@]}")
((${#names[@]})) || names=("${ENTRIES[@]}")
for n in "${names[@]}"; do
  [[ " ${ENTRIES[*]} " == *" $n "* ]] || { echo "regenerate_results.sh: unknown entry $n (--list names them)" >&2; exit 2; }
done

if [[ $mode == files ]]; then
  for n in "${names[@]}"; do files "$n"; done
  exit 0
fi

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
  if (($(cpus_needed "$n") > $(nproc))) && [[ " ${named[*]} " != *" $n "* ]]; then
    summary+=("$(printf '%-16s skipped: needs %d CPUs, this machine has %d (name it to run it anyway)' "$n" "$(cpus_needed "$n")" "$(nproc)")")
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
  new=$out/$f
  fixed_place "$n" && new=results/$f
  if ((rc == 0)) && [[ $f == *.json && -f $previous/$f && -f $new ]] && [[ " throughput scaling16 toi_vs_fcl python_batch test_figures multibody multibody_scaling " != *" $n "* ]]; then
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
