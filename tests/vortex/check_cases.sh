#!/bin/sh
# check_cases.sh PARTIX CASES_DIR: every shipped vortex case passes
# `partix check` without a warning (time step against the case's scales,
# the floor of eps* against nu dt, the ramp against dt), and a step too
# long for a shipped case is refused at time.dt with the recommended value.
set -u
partix=$1 cases=$2
fails=0 n=0
tmp=$(mktemp -d) || exit 1
trap 'rm -rf "$tmp"' EXIT
for f in "$cases"/*.yaml; do
  n=$((n + 1))
  if ! "$partix" check "$f" >"$tmp/out" 2>"$tmp/err"; then
    fails=$((fails + 1)); echo "FAIL: check $f:"; sed 's/^/  | /' "$tmp/err" | head -5
  elif grep -q "warning" "$tmp/err"; then
    fails=$((fails + 1)); echo "FAIL: check $f warns:"; grep "warning" "$tmp/err" | sed 's/^/  | /'
  fi
done
[ "$n" -ge 5 ] || { fails=$((fails + 1)); echo "FAIL: only $n vortex cases in $cases"; }
# The users' example: the NACA 0012 case (400 panels, mean panel length
# 0.0051 m) at dt = 0.5 s travels ~100 panel lengths per step.
if "$partix" check "$cases/naca0012_aoa5.yaml" --set time.dt=0.5 >"$tmp/out" 2>"$tmp/err"; then
  fails=$((fails + 1)); echo "FAIL: dt = 0.5 accepted for the NACA 0012 case"
elif ! grep -q "time.dt" "$tmp/err" || ! grep -q "Use dt <= 0.005099 s" "$tmp/err"; then
  fails=$((fails + 1)); echo "FAIL: the refusal names neither time.dt nor the recommended step:"
  sed 's/^/  | /' "$tmp/err" | head -5
fi
if [ "$fails" -ne 0 ]; then echo "check_cases: $fails failures"; exit 1; fi
echo "check_cases: $n cases checked without warnings; dt = 0.5 refused"
