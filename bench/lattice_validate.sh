#!/bin/sh
# Long validations of the lattice solver (docs/lattice.md lists the numbers
# measured, docs/notes/lattice.md the studies behind them). One command per check; each prints one JSON line with a verdict:
#
#   bench/lattice_validate.sh plate [single|double]  cases/lattice/plate.yaml run to
#        its convergence criterion, against the stored CalculiX reference
#        (tests/lattice/data/plate_ccx.txt): corner deflection within 3 %, von Mises
#        at 8 interior cells within 10 % (test_lattice_plate; its run folder is
#        $OUT/lt_plate)
#   bench/lattice_validate.sh plate_poisson [single|double] [reuse]  the plate at
#        nu = 0.3 run to statics at h = 5/3, 5/4 and 1 mm, extrapolated in h, against
#        the stored CalculiX C3D20R reference (tests/lattice/data/plate_ccx_nu03.txt):
#        deflection and von Mises at interior points within 3 %
#        (test_lattice_plate_poisson; run folders $OUT/lt_plate_nu_0..2, kept and
#        reused with "reuse")
#   bench/lattice_validate.sh kirsch [32]  the hole in a strip (d/W = 1/4) at nu = 0.3,
#        a/h = 4, 8, 16 (and 32 with "32": a quarter of an hour), extrapolated in h,
#        against Howland's concentration factor (test_lattice_kirsch_long)
#   bench/lattice_validate.sh ccx [ARGS]  regenerate the CalculiX reference with
#        tests/lattice/ccx/plate_ccx.py into $OUT/plate_ccx.txt (ARGS go to the
#        script, e.g. "--type C3D8I --mesh 2") and compare it with the stored one
#   bench/lattice_validate.sh cantilever  run cases/lattice/cantilever.yaml and
#        compare the tip deflection with Timoshenko (within 1 %)
#   bench/lattice_validate.sh poisson_fronts  P- and S-wave fronts at nu = 0.3
#        in 8x8 and 16x16 bars, extrapolated in h, against c_p and c_s
#        (within 1 %; test_lattice_poisson fronts, docs/notes/lattice-poisson.md)
#
# Environment: BUILD (default build), OUT (default out).
# Exit status: 0 when the check passed, 1 otherwise.
set -u
cd "$(dirname "$0")/.."
BUILD=${BUILD:-build}
OUT=${OUT:-out}
mkdir -p "$OUT"

plate() {
  prec=${1:-single}
  log="$OUT/lattice_plate_$prec.log"
  test=$(cd "$BUILD" && pwd)/tests/lattice/test_lattice_plate
  start=$(date +%s)
  (cd "$OUT" && "$test" "$prec") >"$log" 2>&1
  rc=$?
  awk -v rc=$rc -v prec="$prec" -v wall=$(( $(date +%s) - start )) '
    /stopped at step/ { for (i = 1; i < NF; i++) if ($i == "step") steps = $(i + 1) }
    /^corner deflection/ { corner = $NF }
    /^von Mises at/ { r = $NF; n++; d = r > 1 ? r - 1 : 1 - r; if (d > worst) worst = d }
    END { printf "{\"check\":\"lattice_plate\",\"precision\":\"%s\",\"relax_steps\":%d,", prec, steps;
          printf "\"corner_ratio\":%s,\"von_mises_points\":%d,\"von_mises_worst_rel\":%.4f,", corner == "" ? "null" : corner, n, worst;
          printf "\"wall_s\":%d,\"pass\":%s}\n", wall, rc == 0 ? "true" : "false" }' "$log"
  return $rc
}

ccx() {
  command -v ccx >/dev/null || { echo '{"check":"lattice_ccx","error":"ccx not installed (scripts/deps.sh --bench)"}'; return 1; }
  /usr/bin/python3 tests/lattice/ccx/plate_ccx.py "$OUT/plate_ccx.txt" --keep "$OUT/plate_ccx" "$@" >/dev/null || return 1
  awk 'FNR == 1 { f++ } /^corner_uz/ { u[f] = $5 } END {
         r = u[2] / u[1]; printf "{\"check\":\"lattice_ccx\",\"stored_corner_uz_mm\":%s,\"new_corner_uz_mm\":%s,\"ratio\":%.5f}\n", u[1], u[2], r }' \
    tests/lattice/data/plate_ccx.txt "$OUT/plate_ccx.txt"
}

plate_poisson() {
  prec=${1:-single}
  log="$OUT/lattice_plate_poisson_$prec.log"
  test=$(cd "$BUILD" && pwd)/tests/lattice/test_lattice_plate_poisson
  start=$(date +%s)
  (cd "$OUT" && "$test" poisson "$prec" ${2:-}) >"$log" 2>&1
  rc=$?
  # von Mises: extrapolated / CalculiX; deflection: extrapolated and h = 1 mm
  awk -v rc=$rc -v prec="$prec" -v wall=$(( $(date +%s) - start )) '
    function dev(r) { return r > 1 ? r - 1 : 1 - r }
    /not checked/ { next }
    /^von Mises / { n++; if (dev($NF) > vm) vm = dev($NF) }
    /^uz / { for (i = 1; i < NF; i++) { if ($i == "lattice") f = $(i + 3); if ($i == "CalculiX") v = $(i + 1) }
             sub(",", "", f); nu_++; if (dev($NF) > ux) ux = dev($NF); if (dev(f / v) > u1) u1 = dev(f / v) }
    END { printf "{\"check\":\"lattice_plate_poisson\",\"nu\":0.3,\"precision\":\"%s\",\"von_mises_points\":%d,", prec, n;
          printf "\"von_mises_worst_rel_extrapolated\":%.4f,\"uz_points\":%d,\"uz_worst_rel_extrapolated\":%.4f,", vm, nu_, ux;
          printf "\"uz_worst_rel_h1mm\":%.4f,\"wall_s\":%d,\"pass\":%s}\n", u1, wall, rc == 0 ? "true" : "false" }' "$log"
  return $rc
}

kirsch() {
  what=kirsch_long
  [ "${1:-}" = 32 ] && what=kirsch_32
  log="$OUT/lattice_$what.log"
  start=$(date +%s)
  "$BUILD/tests/lattice/test_lattice_kirsch_long" $what >"$log" 2>&1
  rc=$?
  awk -v rc=$rc -v wall=$(( $(date +%s) - start )) '
    /Howland.s K/ { for (i = 1; i < NF; i++) if ($i == "1/4)") ref = $(i + 1) }
    /^  a\/h = / { k = $5 }
    /extrapolated from/ { for (i = 1; i < NF; i++) if ($i == "order") { o[++m] = $(i + 2); sub(",", "", o[m]) } }
    /observed order/ { p = $NF }
    END { if (k == "") k = "null"; if (p == "") p = "null"; if (ref == "") ref = "null";
          if (m < 2) o[1] = o[2] = "null";
          printf "{\"check\":\"lattice_kirsch\",\"nu\":0.3,\"K_finest\":%s,\"K_extrapolated_order_half\":%s,", k, o[1];
          printf "\"K_extrapolated_order_1\":%s,\"observed_order\":%s,\"K_howland\":%s,", o[2], p, ref;
          printf "\"wall_s\":%d,\"pass\":%s}\n", wall, rc == 0 ? "true" : "false" }' "$log"
  return $rc
}

cantilever() {
  rm -rf "${OUT:?}/lattice_cantilever" # a run refuses a folder holding another
  "$BUILD/partix" run cases/lattice/cantilever.yaml --out "$OUT/lattice_cantilever" --no-progress \
    >"$OUT/lattice_cantilever.log" 2>&1 || { echo '{"check":"lattice_cantilever","error":"run failed"}'; return 1; }
  # Timoshenko, G = E/2, kappa = 5/6: P L^3/(3 E I) + P L/(kappa G A)
  tail -n 1 "$OUT/lattice_cantilever/probes.csv" | awk -F, '{
    P = 10; L = 0.04; H = 0.004; E = 2.1e11; I = H^4 / 12; A = H * H;
    ref = P * L^3 / (3 * E * I) + P * L / (5 / 6 * E / 2 * A); r = -$4 / ref;
    printf "{\"check\":\"lattice_cantilever\",\"tip_uz_m\":%.6g,\"timoshenko_m\":%.6g,\"ratio\":%.5f,\"pass\":%s}\n",
      $4, ref, r, (r > 0.99 && r < 1.01) ? "true" : "false"; exit !(r > 0.99 && r < 1.01) }'
}

poisson_fronts() {
  log="$OUT/lattice_poisson_fronts.log"
  start=$(date +%s)
  "$BUILD/tests/lattice/test_lattice_poisson_fronts" fronts >"$log" 2>&1
  rc=$?
  awk -v rc=$rc -v wall=$(( $(date +%s) - start )) '
    /extrapolated in h/ { for (i = 1; i < NF; i++) if ($i == "(ratio") r[++n] = $(i + 1) + 0 }
    END { printf "{\"check\":\"lattice_poisson_fronts\",\"nu\":0.3,\"cp_ratio\":%s,\"cs_ratio\":%s,", (n >= 1 ? r[1] : "null"), (n >= 2 ? r[2] : "null");
          printf "\"wall_s\":%d,\"pass\":%s}\n", wall, rc == 0 ? "true" : "false" }' "$log"
  return $rc
}

case "${1:-}" in
  plate) shift; plate "$@" ;;
  plate_poisson) shift; plate_poisson "$@" ;;
  kirsch) shift; kirsch "$@" ;;
  poisson_fronts) poisson_fronts ;;
  ccx) shift; ccx "$@" ;;
  cantilever) cantilever ;;
  *) echo "usage: $0 plate [single|double] | plate_poisson [single|double] [reuse] | kirsch [32] | ccx [ARGS] | cantilever | poisson_fronts" >&2; exit 2 ;;
esac
