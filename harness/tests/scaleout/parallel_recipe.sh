#!/usr/bin/env bash
# Runs the README's GNU parallel sharding recipe as written (the block after
# the "recipe:gnu-parallel" marker), on a small scene instead of
# configs/uniform_so3.toml, and checks that
#   1. the merged results equal a single-process run's aggregates exactly;
#   2. a shard killed with SIGKILL leaves no results file, and merge then fails
#      naming the missing shard;
#   3. rerunning only that shard (the recipe's own command) and the merge
#      completes the run, equal again to the single-process run.
# Exit 77 (ctest SKIP) when GNU parallel is not installed.
#   parallel_recipe.sh HARNESS_EXE SOURCE_DIR SCENE
set -euo pipefail
harness=$(readlink -f "$1") src=$(readlink -f "$2") scene=$(readlink -f "$3")
here=$(cd "$(dirname "$0")" && pwd)
if ! command -v parallel > /dev/null || ! parallel --version 2> /dev/null | grep -q "GNU parallel"; then
  echo "SKIP: GNU parallel is not installed (scripts/setup.sh installs the Debian package 'parallel')"
  exit 77
fi

readme=$src/README.md
recipe=$(awk '/<!-- recipe:gnu-parallel/ {found = 1; next}
              found && /^```/ {if (inside) exit; inside = 1; next}
              inside {print}' "$readme")
[[ -n $recipe ]] || { echo "FAIL: no code block after '<!-- recipe:gnu-parallel' in $readme"; exit 1; }
for needed in configs/uniform_so3.toml build/harness/idcol_harness "merge -o build/out/uniform_so3.json"; do
  grep -qF -- "$needed" <<< "$recipe" ||
    { echo "FAIL: the README recipe no longer mentions '$needed'; adapt $0 to it"; printf '%s\n' "$recipe"; exit 1; }
done

work=$(mktemp -d "${TMPDIR:-/tmp}/idcol-parallel.XXXXXX")
cleanup() {
  local pid
  for pid in $(jobs -p); do kill -9 "$pid" 2> /dev/null || true; done
  rm -rf "$work"
}
trap cleanup EXIT
cd "$work"
mkdir -p build/harness
ln -s "$harness" build/harness/idcol_harness
# The only change to the recipe: the scene.
printf '%s\n' "$recipe" | sed "s|configs/uniform_so3.toml|$scene|g" > recipe.sh
echo "== the README recipe, scene replaced by $scene:"
cat recipe.sh

echo "== single-process reference"
build/harness/idcol_harness run "$scene" -o whole.json --failures whole.failures.json --no-progress > /dev/null
echo "== recipe"
timeout -s KILL 300 bash -euo pipefail recipe.sh < /dev/null
python3 "$here/same_aggregates.py" build/out/uniform_so3.json whole.json
shards=$(python3 -c 'import json,sys; print(len(json.load(open(sys.argv[1]))["shard"]["merged_from"]))' build/out/uniform_so3.json)
[[ $shards == 8 ]] || { echo "FAIL: merged from $shards shards, the recipe runs 8"; exit 1; }

echo "== kill -9 shard 3 mid-run"
# The recipe's own command line for one shard: the quoted template of its
# parallel line, with {} = 3.
template=$(grep -m1 '^parallel ' recipe.sh | sed -E "s/^[^']*'([^']*)'.*/\1/")
shard3=${template//\{\}/3}
rm -f build/out/shards/3.json build/out/uniform_so3.json
killed=0
for attempt in 1 2 3 4 5 6 7 8 9 10; do
  bash -c "exec $shard3" > /dev/null &
  pid=$!
  # The run creates its temporary outputs only when it writes them, at the
  # end: kill it while it is still solving.
  sleep "$(printf "0.%02d" "$attempt")"
  if kill -9 "$pid" 2> /dev/null; then
    wait "$pid" 2> /dev/null || true
    if [[ ! -e build/out/shards/3.json ]]; then
      if compgen -G 'build/out/shards/.3.json.idcol-tmp.*' > /dev/null || compgen -G 'build/out/.3.failures.json.idcol-tmp.*' > /dev/null; then
        # The kill landed while the run wrote its outputs (nothing can clean
        # up after SIGKILL; the temporary names are no results file, and
        # merge does not read them): try again, to kill it while it solves.
        echo "attempt $attempt: SIGKILL landed while the shard wrote; again"
        rm -f build/out/shards/.3.json.idcol-tmp.* build/out/.3.failures.json.idcol-tmp.*
        continue
      fi
      killed=1
      break
    fi
  fi
  wait "$pid" 2> /dev/null || true
  rm -f build/out/shards/3.json  # it finished before the kill; try again
done
((killed)) || { echo "FAIL: shard 3 always finished before SIGKILL reached it (10 attempts)"; exit 1; }
echo "killed shard 3 (attempt $attempt); no build/out/shards/3.json was written"
if compgen -G 'build/out/shards/.3.json.idcol-tmp.*' > /dev/null || compgen -G 'build/out/.3.failures.json.idcol-tmp.*' > /dev/null; then
  echo "FAIL: the killed shard left a temporary file"; ls -la build/out build/out/shards; exit 1
fi
merge_cmd=$(grep -m1 'idcol_harness merge' recipe.sh)
set +e
msg=$(bash -c "$merge_cmd" 2>&1)
rc=$?
set -e
echo "$msg"
[[ $rc -ne 0 ]] || { echo "FAIL: merge succeeded without shard 3"; exit 1; }
grep -qF "shard 3/8 is missing" <<< "$msg" || { echo "FAIL: merge's message does not name shard 3/8"; exit 1; }
[[ ! -e build/out/uniform_so3.json ]] || { echo "FAIL: a failed merge left build/out/uniform_so3.json"; exit 1; }

echo "== rerun shard 3 alone, then merge"
bash -c "$shard3"
bash -c "$merge_cmd"
python3 "$here/same_aggregates.py" build/out/uniform_so3.json whole.json
echo "PASS"
