#!/usr/bin/env bash
# Instructions per solve for every pair of idcol_bench's set, cold and warm,
# under callgrind (deterministic, unlike wall-clock time on a shared machine).
#   scripts/callgrind_pairs.sh [build-dir] [pairs...]
# WALK=1 adds two columns: cold and warm on NWALK poses of a random walk;
# BATCH=1 two more: the cold and warm poses through solve_batch(threads = 1).
set -euo pipefail
B=${1:-build}; shift || true
PAIRS=${*:-"Poly-Poly Poly-TC Poly-SE Poly-SEC Poly-Ellip TC-TC TC-SE TC-SEC TC-Ellip SE-SE SE-SEC SE-Ellip SEC-SEC SEC-Ellip Ellip-Ellip"}
NCOLD=${NCOLD:-2000}
NWARM=${NWARM:-19999}
NWALK=${NWALK:-5000}
MODES="cold warm"; [ "${WALK:-0}" = 1 ] && MODES="$MODES walkcold walkwarm"
[ "${BATCH:-0}" = 1 ] && MODES="$MODES batchcold batchwarm"
tmp=$(mktemp -d)
printf "%-12s" pair
for m in $MODES; do
  case $m in cold) h=cold_Ir/solve ;; warm) h=warm_Ir/solve ;; walkcold) h=walk_cold ;; walkwarm) h=walk_warm ;; batchcold) h=batch_cold ;; batchwarm) h=batch_warm ;; esac
  printf " %12s" $h
done
printf "\n"
for p in $PAIRS; do
  out=""
  for m in $MODES; do
    case $m in cold|batchcold) n=$NCOLD ;; warm|batchwarm) n=$NWARM ;; *) n=$NWALK ;; esac
    valgrind --tool=callgrind --collect-atstart=no --callgrind-out-file=$tmp/cg.$p.$m "$B/core/idcol_prof" run $p $m $n >/dev/null 2>&1
    ir=$(grep -m1 '^summary:' $tmp/cg.$p.$m | awk '{print $2}')
    out="$out $(( ir / n ))"
  done
  printf "%-12s" $p; printf " %12s" $out; printf "\n"
done
rm -rf $tmp
