#!/usr/bin/env bash
# The random-body scene at full size, as results/random_bodies_{normal,wide}.*
# were made: configs/random_bodies.toml split into its normal-range and
# wide-range halves (at its "# normal range" and "# wide range" comments), each
# run on its first N poses per case (default 50000, so 10^5 poses per ordered
# family pair over both ranges, each solved 4 times: cold, warm, and both
# again with the bodies swapped). The halves can run on two machines.
#   scripts/random_bodies_full.sh [N] [normal|wide|both] [THREADS] [ORACLE_EVERY]
# Cost on this machine class: normal ~3800 s, wide ~6000 s of CPU at N = 50000.
# ORACLE_EVERY = K (default 1) runs the support-function bracket, which costs
# more than the solves and the other checks together, on every K-th pose only;
# the surface and normal checks stay on every answer (stress --oracle-every).
set -euo pipefail
cd "$(dirname "$0")/.."
n=${1:-50000}
which=${2:-both}
threads=${3:-2}
oracle_every=${4:-1}
harness=${IDCOL_BUILD_DIR:-build}/harness/idcol_harness
tmp=$(mktemp -d "${TMPDIR:-/tmp}/idcol-rb.XXXXXX")
trap 'rm -rf "$tmp"' EXIT
/usr/bin/python3 - configs/random_bodies.toml "$tmp" <<'PY'
import sys
s = open(sys.argv[1]).read()
head, rest = s.split('# normal range', 1)
normal, wide = rest.split('# wide range', 1)
open(sys.argv[2] + '/rb_normal.toml', 'w').write(head + '# normal range' + normal)
open(sys.argv[2] + '/rb_wide.toml', 'w').write(head + '# wide range' + wide)
PY
for range in normal wide; do
  [[ $which == both || $which == "$range" ]] || continue
  "$harness" stress "$tmp/rb_$range.toml" -o "results/random_bodies_$range.json" \
    --failures "results/random_bodies_$range.failures.json" --threads "$threads" --max-poses "$n" --oracle-every "$oracle_every" --max-failures 20 --no-progress
  "$harness" stress-table "results/random_bodies_$range.json" -o "results/random_bodies_$range.md"
done
