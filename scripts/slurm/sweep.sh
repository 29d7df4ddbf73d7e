#!/usr/bin/env bash
# Submits a sharded harness sweep to Slurm: an array job with one shard per
# task (scripts/slurm/shard.sbatch) and a merge job (scripts/slurm/merge.sbatch)
# that runs once every task has ended.
#
#   scripts/slurm/sweep.sh SCENE OUT [--shards N] [--only I[,J...]] [-- SBATCH_ARGS...]
#
# SCENE   a scene file (checked with `idcol_harness check` before submitting)
# OUT     output directory: shards/I.json, failures/I.failures.json,
#         logs/shard-I.out, logs/merge-JOB.out, and merged.json
# --shards N    number of shards, i.e. array tasks (default 8)
# --only LIST   resubmit only these shards (after a task failed or was
#               killed), then merge again
# after --      extra sbatch arguments for both jobs, the array and its merge
#               (--partition, --account, --time, --qos, --hold, ...): the
#               merge runs where the shards ran, under the same account
# IDCOL_HARNESS the harness executable (default build/harness/idcol_harness
#               of this checkout); it must be visible from the compute nodes.
#
# Prints "array job A" and "merge job M" and, last, a line
# "IDCOL_SWEEP_JOBS A M" for scripts.
#
# The merge depends on the array with afterany, not afterok: with afterok a
# failed or cancelled task leaves the merge pending forever
# (DependencyNeverSatisfied) and nothing says which shard is lost; with
# afterany the merge runs and fails naming the missing shards.
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd)
repo=$(cd "$here/../.." && pwd)
usage="usage: scripts/slurm/sweep.sh SCENE OUT [--shards N] [--only I[,J...]] [-- SBATCH_ARGS...]"
die() {
  echo "sweep.sh: $*" >&2
  exit 2
}
positional=() shards=8 only="" extra=()
while (($#)); do
  case $1 in
    --shards) (($# >= 2)) || die "--shards needs a value; $usage"; shards=$2; shift 2 ;;
    --only) (($# >= 2)) || die "--only needs a value; $usage"; only=$2; shift 2 ;;
    --) shift; extra=("$@"); break ;;
    -*) die "unknown option $1; $usage" ;;
    *) positional+=("$1"); shift ;;
  esac
done
((${#positional[@]} == 2)) || die "expected SCENE and OUT, got ${#positional[@]} arguments; $usage"
scene=${positional[0]} out=${positional[1]}
[[ $shards =~ ^[1-9][0-9]*$ ]] || die "--shards '$shards': expected a positive integer"
array="0-$((shards - 1))"
if [[ -n $only ]]; then
  [[ $only =~ ^[0-9]+(,[0-9]+)*$ ]] || die "--only '$only': expected shard indices such as 3 or 1,5"
  IFS=, read -ra idx <<< "$only"
  for i in "${idx[@]}"; do ((10#$i < shards)) || die "--only: shard $i does not exist with --shards $shards (0..$((shards - 1)))"; done
  array=$only
fi
harness=${IDCOL_HARNESS:-$repo/build/harness/idcol_harness}
[[ -x $harness ]] || die "IDCOL_HARNESS '$harness': not an executable file (build it, or set IDCOL_HARNESS)"
[[ -f $scene ]] || die "scene '$scene': no such file"
command -v sbatch > /dev/null || die "sbatch not found: this submits to Slurm (Debian: slurm-client)"
"$harness" check "$scene" > /dev/null || die "scene '$scene' does not load (see the error above)"
harness=$(readlink -f "$harness") scene=$(readlink -f "$scene")
mkdir -p "$out/shards" "$out/failures" "$out/logs"
out=$(readlink -f "$out")
if [[ -n $only ]]; then
  for i in "${idx[@]}"; do rm -f "$out/shards/$((10#$i)).json"; done
fi
rm -f "$out/merged.json"
env_vars="ALL,IDCOL_HARNESS=$harness,IDCOL_SCENE=$scene,IDCOL_OUT=$out,IDCOL_SHARDS=$shards"
array_job=$(sbatch --parsable --array="$array" --output="$out/logs/shard-%a.out" --export="$env_vars" \
  "${extra[@]}" "$here/shard.sbatch")
array_job=${array_job%%;*}
# The merge job's message for missing shards is the command that resubmits
# them with these same sbatch arguments (shell-quoted, in the environment:
# --export's commas cannot carry them).
IDCOL_SWEEP_SBATCH_ARGS=$(((${#extra[@]})) && printf ' %q' "${extra[@]}" || true)
export IDCOL_SWEEP_SBATCH_ARGS
merge_job=$(sbatch --parsable --dependency="afterany:$array_job" --output="$out/logs/merge-%j.out" \
  --export="$env_vars" "${extra[@]}" "$here/merge.sbatch")
merge_job=${merge_job%%;*}
echo "array job $array_job (shards $array of $shards), logs in $out/logs/"
echo "merge job $merge_job (after the array ends): $out/merged.json"
echo "IDCOL_SWEEP_JOBS $array_job $merge_job"
