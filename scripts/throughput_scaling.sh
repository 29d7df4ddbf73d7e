#!/usr/bin/env bash
# solve_batch's scaling with threads on this machine, and what bounds it:
#   scripts/throughput_scaling.sh BUILD OUTDIR [POSES] [MAXT] [CPU]
# writes into OUTDIR:
#   cpu.txt                  the processor: sockets, cores, threads a core, clocks
#   throughput.{json,md}     idcol_bench_throughput on POSES poses a pair (default
#                            10^5): batch against loop pinned to CPU (default 0), the splits' bounds
#                            (--balance MAXT) and solve_batch on 1..MAXT threads
#   large.{json,md}          the same scaling on 10^6 poses of Poly-Poly and
#                            Ellip-Ellip (longer calls: thread start-up amortised)
#   processes.md             the hardware's own bound: N independent single-thread
#                            processes, each pinned to its own CPU (CPU, CPU+1, ...), each timing
#                            the loop and solve_batch(threads = 1) on Poly-Poly
#                            and SE-SE; aggregate solves/s over N times one's
#   summary.json             the figures above that the documentation quotes
#                            (scripts/scaling_summary.py)
#   log.txt                  everything it printed
set -euo pipefail
build=${1:?build dir}
out=${2:?output dir}
poses=${3:-100000}
maxt=${4:-$(nproc)}
cpu=${5:-0}
bench="$build/core/idcol_bench_throughput"
mkdir -p "$out"
exec > >(tee "$out/log.txt") 2>&1
{
  lscpu 2>/dev/null || cat /proc/cpuinfo
  echo "--- MHz now, per CPU"
  grep "cpu MHz" /proc/cpuinfo || true
} >"$out/cpu.txt"
"$bench" --poses "$poses" --reps 5 --cpu "$cpu" --scaling "$maxt" --balance "$maxt" --out "$out/throughput"
"$bench" --poses 1000000 --reps 3 --cpu "$cpu" --pairs Poly-Poly,Ellip-Ellip --scaling "$maxt" --out "$out/large"
# N single-thread processes, one a CPU.
{
  echo "| processes | pair | mode | loop solves/s per process (median over processes) | batch solves/s per process | aggregate batch / one process's |"
  echo "|---|---|---|---|---|---|"
} >"$out/processes.md"
declare -A one
for N in $(printf "%s\n" 1 $((maxt / 2)) "$maxt" | sort -nu); do
  for ((i = 0; i < N; ++i)); do
    "$bench" --poses "$poses" --reps 3 --cpu $(((cpu + i) % $(nproc))) --pairs Poly-Poly,SE-SE --out "$out/p${N}_$i" >/dev/null &
  done
  wait
  for pm in "Poly-Poly cold" "Poly-Poly warm" "SE-SE cold" "SE-SE warm"; do
    set -- $pm
    l=$(for ((i = 0; i < N; ++i)); do grep -E "^\| $1 \| $2 \|" "$out/p${N}_$i.md" | awk -F'|' '{print $4}'; done | sort -n | awk '{a[NR]=$1} END {print a[int((NR+1)/2)]}')
    b=$(for ((i = 0; i < N; ++i)); do grep -E "^\| $1 \| $2 \|" "$out/p${N}_$i.md" | awk -F'|' '{print $5}'; done | sort -n | awk '{a[NR]=$1} END {print a[int((NR+1)/2)]}')
    s=$(for ((i = 0; i < N; ++i)); do grep -E "^\| $1 \| $2 \|" "$out/p${N}_$i.md" | awk -F'|' '{print $5}'; done | awk '{s+=$1} END {print s}')
    [ "$N" = 1 ] && one["$1 $2"]=$s
    echo "| $N | $1 | $2 | $l | $b | $(awk -v s="$s" -v o="${one["$1 $2"]}" 'BEGIN {printf "%.2f", s / o}') |" >>"$out/processes.md"
  done
  rm -f "$out"/p${N}_*.json "$out"/p${N}_*.md
done
cat "$out/processes.md"
# The figures the documentation quotes, in one JSON file.
if command -v python3 >/dev/null; then python3 "$(dirname "$0")/scaling_summary.py" "$out"; fi
