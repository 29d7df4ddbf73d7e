#!/usr/bin/env bash
# Mutation check: breaks the solver, the checks and compare on purpose, one
# mutation at a time, in a scratch copy of the working tree, and expects the
# tests named for each mutation to FAIL. A mutation the tests do not catch
# ("SURVIVED") means a check that cannot fail: exit 1.
#
#   scripts/mutations.sh                 # every mutation
#   scripts/mutations.sh genuine merge   # the ones named
#   scripts/mutations.sh --list
#
# The scratch copy (IDCOL_MUTATION_DIR, default /tmp/idcol_mutations) keeps
# its build between runs: the first run builds idcol_core_tests,
# idcol_harness and idcol_harness_tests there (minutes, through ccache);
# later runs rebuild what each mutation touches. The working tree itself is
# never modified.
set -euo pipefail
cd "$(dirname "$0")/.."
src=$(pwd)
scratch="${IDCOL_MUTATION_DIR:-/tmp/idcol_mutations}"
jobs="${IDCOL_MUTATION_JOBS:-2}"

# name @ file @ text to find @ its replacement @ targets to build @ test binary:gtest filter
mutations=(
  "genuine@core/src/solver/solver_impl.hpp@return z[4] > 0.0 && z[5] > 0.0 && z[3] >= B.lo && z[3] <= B.hi;@return true;@idcol_core_tests@core/tests/idcol_core_tests:Solver.*"
  "genuine_call@core/src/solver/solver_impl.hpp@        const bool genuine = genuine_root(pt_->z, B);@        const bool genuine = true;@idcol_core_tests@core/tests/idcol_core_tests:Solver.*"
  "derivative_checker@core/src/derivatives/derivative_check.hpp@const bool agree = std::isfinite(err) && err <= tolerance;@const bool agree = true;@idcol_core_tests@core/tests/idcol_core_tests:Derivatives.*"
  "derivative_off@core/src/derivatives/derivatives.cpp@const Eigen::Matrix<double, 4, 6> ift = s.dz_dxi.topRows<4>();@Eigen::Matrix<double, 4, 6> ift = s.dz_dxi.topRows<4>(); ift.topRows<3>() *= 1.001;@idcol_core_tests@core/tests/idcol_core_tests:Derivatives.*"
  "checker_agrees_derivative_off@core/src/derivatives/derivatives.cpp@const Eigen::Matrix<double, 4, 6> ift = s.dz_dxi.topRows<4>();~~detail::record_checked_pose(rep, i, X, res.alpha, s.cond, err, o.tolerance);@Eigen::Matrix<double, 4, 6> ift = s.dz_dxi.topRows<4>(); ift.topRows<3>() *= 1.001;~~detail::record_checked_pose(rep, i, X, res.alpha, s.cond, err, 1e300);@idcol_core_tests@core/tests/idcol_core_tests:Derivatives.*"
  "merge_status@harness/src/studies/sweep/agreement.cpp@for (const auto& [k, v] : o.status) status[k].merge(v);@(void)o.status;@idcol_harness_tests@harness/tests/idcol_harness_tests:Agreement.*:Merge*"
  "compare_mismatch@harness/src/report/compare.cpp@  rep.mismatches = run_mismatches(o, n);@  rep.mismatches = {};@idcol_harness idcol_harness_tests@harness/tests/idcol_harness_tests:Compare*"
  "compare_vanished@harness/src/report/compare.cpp@row.verdict = row.guarded || row.unit == \"count\" ? \"FAIL\" : \"missing\";@row.verdict = \"missing\";@idcol_harness idcol_harness_tests@harness/tests/idcol_harness_tests:Compare*"
  "compare_replace@harness/src/report/compare.cpp@      if (f && f->replace) gs = {f};@      if (f) gs = {f};@idcol_harness idcol_harness_tests@harness/tests/idcol_harness_tests:Compare*"
  "compare_bad_input@harness/src/report/compare.cpp@  require_members(n, k, \"NEW\");@  (void)0;@idcol_harness idcol_harness_tests@harness/tests/idcol_harness_tests:Compare*"
  "slow_step@core/src/solver/solver_impl.hpp@      ++iters;@      ++iters; { KktPoint extra = *pt_; kkt_residual(P, pt_->z, extra); volatile double keep = extra.F[0]; (void)keep; }@idcol_prof@script:scripts/ci_instructions.sh"
  "slow_batch@core/src/batch/newton_lanes_kernel.hpp@    iters = sel(act, iters + 1.0, iters);@    iters = sel(act, iters + 1.0, iters); { Pt extra; M bb = M{}; residual(C, P, pt->z, extra, bb); __asm__ volatile(\"\" : : \"r\"(&extra) : \"memory\"); }@idcol_prof@script:scripts/ci_instructions.sh"
  "slow_deriv@core/src/derivatives/derivatives.cpp@  rhs = -in.lu.solve_many<6>(rhs);@  rhs = -in.lu.solve_many<6>(rhs); { Mat6 extra = in.lu.solve_many<6>(Mat6::Identity()); __asm__ volatile(\"\" : : \"r\"(&extra) : \"memory\"); }@idcol_prof@script:scripts/ci_instructions.sh"
  "slow_shape@core/src/shapes/shape_derivatives.cpp@  eval_params(B, y, e, d);@  eval_params(B, y, e, d); { ShapeParamEval extra; ShapeEval e2; eval_params(B, y, e2, extra); __asm__ volatile(\"\" : : \"r\"(&extra) : \"memory\"); }@idcol_prof@script:scripts/ci_instructions.sh"
  "slow_toi@core/src/toi/toi.cpp@    const Row6 ga = alpha_gradient(e.res);@    const Row6 ga = alpha_gradient(e.res); { Row6 extra = alpha_gradient(e.res); __asm__ volatile(\"\" : : \"r\"(&extra) : \"memory\"); }@idcol_prof@script:scripts/ci_instructions.sh"
  "simd_rounding@core/src/batch/newton_lanes_kernel.hpp@        for (int i = 0; i < 6; ++i) zt[i] = pt->z[i] + t * dz[i];@        for (int i = 0; i < 6; ++i) zt[i] = pt->z[i] + t * (dz[i] * (1.0 + 0x1p-52));@idcol_batch_simd_tests@core/tests/idcol_batch_simd_tests:*BatchSimd.*"
  "stress_guard@harness/src/studies/stress/stress_metrics.cpp@{\"worst_surface_error\", \"\", \"1\", B::Lower, M::Max, kSurface},@{\"worst_surface_error\", \"\", \"1\", B::Lower, M::Max},@idcol_harness idcol_harness_tests@harness/tests/idcol_harness_tests:Compare*"
)

if [[ "${1:-}" == "--list" ]]; then
  for m in "${mutations[@]}"; do IFS='@' read -r name file _ _ _ tests <<< "$m"; echo "$name: $file -> $tests"; done
  exit 0
fi
want=("$@")

# The scratch copy: the tracked files of the working tree as they are now
# (uncommitted edits included), mtimes kept so that a rerun rebuilds little.
mkdir -p "$scratch/src"
git ls-files -z | tar --null -T - -cf - | tar -xf - -C "$scratch/src"
# Benchmarks on for idcol_prof (slow_step); only the targets named are built.
if [[ ! -f "$scratch/build/CMakeCache.txt" ]] || ! grep -q '^IDCOL_BUILD_BENCHMARKS:BOOL=ON' "$scratch/build/CMakeCache.txt"; then
  cmake -S "$scratch/src" -B "$scratch/build" -DCMAKE_BUILD_TYPE=Release -DIDCOL_BUILD_PYTHON=OFF \
    -DIDCOL_BUILD_BENCHMARKS=ON > "$scratch/configure.log"
fi

# replace FILE FIND REPLACEMENT: each FIND (several separated by ~~, with as
# many REPLACEMENTs) exactly once, or the mutation no longer applies (exit 2).
replace() {
  /usr/bin/python3 - "$@" << 'EOF'
import sys
path, finds, repls = sys.argv[1:4]
s = open(path).read()
for find, repl in zip(finds.split("~~"), repls.split("~~")):
    if s.count(find) != 1:
        print("mutation does not apply: %d occurrences of %r in %s" % (s.count(find), find, path), file=sys.stderr)
        sys.exit(2)
    s = s.replace(find, repl)
open(path, "w").write(s)
EOF
}

survived=0
built=""
declare -a summary
for m in "${mutations[@]}"; do
  IFS='@' read -r name file find repl targets tests <<< "$m"
  if [[ ${#want[@]} -gt 0 && ! " ${want[*]} " == *" $name "* ]]; then continue; fi
  cp "$scratch/src/$file" "$scratch/orig"
  if ! replace "$scratch/src/$file" "$find" "$repl"; then
    summary+=("$(printf '%-28s %s' "$name" "DOES NOT APPLY (the code changed: update the mutation)")")
    survived=1
    continue
  fi
  echo "==== $name: $file"
  echo "     - $find"
  echo "     + $repl"
  verdict=""
  for t in $targets; do [[ " $built " == *" $t "* ]] || built="$built $t"; done
  # shellcheck disable=SC2086
  if ! cmake --build "$scratch/build" -j"$jobs" --target $targets > "$scratch/$name.build.log" 2>&1; then
    verdict="CAUGHT (does not compile)"
  else
    bin=${tests%%:*}
    filter=${tests#*:}
    if [[ "$bin" == script ]]; then
      # A CI check run on the mutated build, against the references of the
      # working tree (slow_*: instructions per solve, per pose, per query).
      set +e
      (cd "$scratch/src" && IDCOL_BUILD_DIR="$scratch/build" IDCOL_CI_OUT="$scratch/ci" \
        IDCOL_INSTRUCTIONS_REF="$src/results/baseline/instructions.json" $filter) > "$scratch/$name.test.log" 2>&1
      rc=$?
      set -e
      # Caught: the check found a regression (exit 1); bad input (2) is no verdict on the mutation.
      if [[ $rc -eq 0 ]]; then
        verdict="SURVIVED ($filter passed)"
        survived=1
      elif [[ $rc -ne 1 ]]; then
        verdict="NOT JUDGED ($filter exit $rc)"
        survived=1
      else
        verdict="CAUGHT by $filter: $(grep -E 'FAIL\)|-> ' "$scratch/$name.test.log" | tail -1)"
      fi
      # The rows that failed (the check's table is long), then its last lines.
      { grep -E ' FAIL' "$scratch/$name.test.log" | head -60; tail -3 "$scratch/$name.test.log"; } | sed 's/^/     | /'
    elif "$scratch/build/$bin" --gtest_filter="$filter" --gtest_brief=1 > "$scratch/$name.test.log" 2>&1; then
      verdict="SURVIVED (every test of $filter passed)"
      survived=1
    else
      failed=$(grep -E '^\[  FAILED  \] [A-Za-z]' "$scratch/$name.test.log" | grep -v 'listed below' | sed 's/^\[  FAILED  \] //; s/ (.*//' | sort -u | tr '\n' ' ')
      verdict="CAUGHT by ${failed:-a failing test}"
    fi
  fi
  cp "$scratch/orig" "$scratch/src/$file"
  touch "$scratch/src/$file"
  echo "     $verdict"
  summary+=("$(printf '%-28s %s' "$name" "$verdict")")
done
# Leave the scratch build matching the source again (the targets built above).
# shellcheck disable=SC2086
[[ -z "$built" ]] || cmake --build "$scratch/build" -j"$jobs" --target $built > "$scratch/restore.build.log" 2>&1 || true
echo "==== summary"
printf '%s\n' "${summary[@]}"
exit $survived
