#!/usr/bin/env bash
# Regression guard of the multibody example's step (core/bench/prof_multibody.cpp):
# the paper's ten bodies integrated through their first collisions (2.2 s,
# analytical Jacobians), counted by callgrind inside the integration, against
# the checked-in reference results/baseline/multibody_step.json:
#
#   instructions per accepted step   fails if it rises by more than
#                                    IDCOL_INSTRUCTIONS_MAX_RISE (default 0.03):
#                                    the counts are exact for one build, so a
#                                    rise is the code's (the narrow phase, the
#                                    integrator, the equations of motion)
#   accepted steps, contacts per     fail if either moves by more than 10%: the
#   step                             simulation itself changed (the integrator's
#                                    choices, the contact law, the scene)
#   momentum drift                   fails above 50 rtol (linear or angular, of
#                                    the bodies' total): whatever the code, no
#                                    gravity and no friction conserve it
#
# About 3 s under valgrind. Faster entries pass with a note to refresh.
#
#   scripts/ci_multibody.sh              # count and compare (CI); exit 0 pass, 1 regression, 2 bad input
#   scripts/ci_multibody.sh --refresh    # after a deliberate change: rewrite the reference
#
# The reference holds the compiler and flags it was counted with; a count of
# another toolchain is not comparable (exit 2, naming both) unless
# IDCOL_INSTRUCTIONS_ALLOW_MISMATCH=1. Environment: IDCOL_BUILD_DIR (default
# build), IDCOL_CI_OUT (default build/ci), IDCOL_MULTIBODY_REF.
set -euo pipefail
cd "$(dirname "$0")/.."
build="${IDCOL_BUILD_DIR:-build}"
out="${IDCOL_CI_OUT:-$build/ci}"
ref="${IDCOL_MULTIBODY_REF:-results/baseline/multibody_step.json}"
prof="$build/core/idcol_prof_multibody"
mode=${1:-}
if [[ -n "$mode" && "$mode" != "--refresh" ]]; then
  echo "usage: scripts/ci_multibody.sh [--refresh]" >&2
  exit 2
fi
if [[ ! -x "$prof" ]] || ! command -v valgrind > /dev/null; then
  echo "ci_multibody: needs $prof (IDCOL_BUILD_BENCHMARKS=ON and valgrind's callgrind.h) and valgrind" >&2
  exit 2
fi
mkdir -p "$out"
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
valgrind --tool=callgrind --collect-atstart=no --callgrind-out-file="$tmp/cg" "$prof" > "$tmp/run.json" 2> "$tmp/valgrind.txt" || {
  echo "ci_multibody: $prof failed under valgrind:" >&2
  cat "$tmp/run.json" "$tmp/valgrind.txt" >&2
  exit 1
}
ir=$(awk '/^summary:/ {print $2; exit}' "$tmp/cg")
compiler=$(sed -n 's/^CMAKE_CXX_COMPILER_ID:[A-Z]*=//p; s/^CMAKE_CXX_COMPILER_VERSION:[A-Z]*=//p' "$build/CMakeCache.txt" | paste -sd' ')
flags=$(sed -n 's/^CMAKE_CXX_FLAGS_RELEASE:[A-Z]*=//p' "$build/CMakeCache.txt")
rev=$(git rev-parse HEAD 2> /dev/null || echo "")
counts="$out/multibody_step.json"
IR="$ir" COMPILER="$compiler" FLAGS="$flags" REV="$rev" VG="$(valgrind --version)" /usr/bin/python3 - "$tmp/run.json" "$counts" <<'EOF'
import json, os, sys
run = json.load(open(sys.argv[1]))
ir = int(os.environ["IR"])
doc = {"schema": "idcol-multibody-step", "git_revision": os.environ["REV"], "valgrind": os.environ["VG"],
       "compiler": os.environ["COMPILER"], "flags": os.environ["FLAGS"],
       "driver": "core/idcol_prof_multibody: the ten-body example to t = %g s, callgrind Ir inside the integration" % run["t_end"],
       "instructions": ir, "instructions_per_step": round(ir / run["steps"]), **run}
tmp = sys.argv[2] + ".tmp"
with open(tmp, "w") as f:
    json.dump(doc, f, indent=1)
    f.write("\n")
os.replace(tmp, sys.argv[2])
EOF
if [[ "$mode" == "--refresh" ]]; then
  cp "$counts" "$ref"
  echo "ci_multibody: reference $ref rewritten"
  cat "$ref"
  exit 0
fi
[[ -f "$ref" ]] || { echo "ci_multibody: no reference $ref (scripts/ci_multibody.sh --refresh writes it)" >&2; exit 2; }
/usr/bin/python3 - "$ref" "$counts" <<'EOF'
import json, os, sys
ref, new = (json.load(open(p)) for p in sys.argv[1:3])
if (ref["compiler"], ref["flags"]) != (new["compiler"], new["flags"]) and os.environ.get("IDCOL_INSTRUCTIONS_ALLOW_MISMATCH") != "1":
    print(f"ci_multibody: the reference was counted with {ref['compiler']} '{ref['flags']}', this build is "
          f"{new['compiler']} '{new['flags']}': not comparable (IDCOL_INSTRUCTIONS_ALLOW_MISMATCH=1 compares anyway)")
    sys.exit(2)
rise = float(os.environ.get("IDCOL_INSTRUCTIONS_MAX_RISE", "0.03"))
failed = []
def line(name, r, n, ok, note=""):
    print(f"{name:24s} {r:>14.6g} {n:>14.6g} {n / r - 1 if r else 0:+8.2%}  {'ok' if ok else 'FAILED'}{note}")
    if not ok:
        failed.append(name)
print(f"{'':24s} {'reference':>14s} {'now':>14s}")
r, n = ref["instructions_per_step"], new["instructions_per_step"]
line("instructions per step", r, n, n <= r * (1 + rise),
     "  (faster: refresh the reference with --refresh)" if n < r * (1 - rise) else "")
for key in ("steps", "contacts_per_step"):
    line(key, ref[key], new[key], abs(new[key] - ref[key]) <= 0.1 * ref[key])
for key in ("momentum_drift_linear", "momentum_drift_angular"):
    line(key, ref[key], new[key], new[key] <= 50 * new["rtol"])
if new["status"] != "success":
    print(f"integration stopped: {new['status']}")
    failed.append("status")
print("ci_multibody: " + ("FAILED: " + ", ".join(failed) if failed else "pass"))
sys.exit(1 if failed else 0)
EOF
