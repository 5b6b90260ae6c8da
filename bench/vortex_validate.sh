#!/bin/sh
# Long validations of the vortex solver against the references of the spec
# (docs/vortex.md lists the numbers measured). One command runs a case and
# prints one JSON line of results with a pass/fail verdict:
#
#   bench/vortex_validate.sh cylinder550 [blasius] [cylinder100] [naca0012]
#   bench/vortex_validate.sh --analyse-only cylinder550   (reuse a finished run)
#
# Environment: PARTIX (default build/partix), OUT (default out), EXTRA (more
# partix options, e.g. "--threads 2" or "--set time.end=1.0").
# Exit status: 0 when every requested check passed, 1 otherwise.
set -u
cd "$(dirname "$0")/.."
PARTIX=${PARTIX:-build/partix}
OUT=${OUT:-out}
EXTRA=${EXTRA:-}
analyse_only=0
status=0

run() { # case-file out-dir
  if [ "$analyse_only" = 0 ]; then
    rm -rf "${OUT:?}/$2" # this script's own run: a run refuses a folder holding another
    # shellcheck disable=SC2086
    "$PARTIX" run "cases/vortex/$1" --out "$OUT/$2" --no-progress $EXTRA >"$OUT/$2.log" 2>&1 ||
      { echo "{\"case\":\"$2\",\"error\":\"run failed, see $OUT/$2.log\"}"; return 1; }
  fi
  [ -f "$OUT/$2/loads.csv" ] || { echo "{\"case\":\"$2\",\"error\":\"no loads.csv\"}"; return 1; }
}

# Koumoutsakos & Leonard 1995, Re = 550 (T = t V / R = 2 t): minimum 0.70 at
# T ~ 0.8, peak 1.29 at T ~ 3, 1.02 at T = 7; each within 5%. The values are
# averages over T +- 0.2 (the vortex method's C_D carries step-to-step noise).
cylinder550() {
  run cylinder_re550.yaml vortex_cylinder550 || return 1
  awk -F, 'NR > 1 { T = 2 * $1; c = $4;
      if (T > 0.6 && T < 1.0) { a += c; na++ }
      if (T > 2.8 && T < 3.2) { b += c; nb++ }
      if (T > 6.8 && T <= 7.0001) { d += c; nd++ } }
    function rel(x, r) { return (x - r) / r }
    END { if (!na || !nb || !nd) { print "{\"case\":\"cylinder550\",\"error\":\"run too short\"}"; exit 1 }
      a /= na; b /= nb; d /= nd;
      ok = (rel(a, 0.70) < 0.05 && rel(a, 0.70) > -0.05 && rel(b, 1.29) < 0.05 && rel(b, 1.29) > -0.05 &&
            rel(d, 1.02) < 0.05 && rel(d, 1.02) > -0.05);
      printf "{\"case\":\"cylinder550\",\"cd_T0.8\":%.4f,\"ref_T0.8\":0.70,\"err_T0.8\":%.3f,", a, rel(a, 0.70);
      printf "\"cd_T3\":%.4f,\"ref_T3\":1.29,\"err_T3\":%.3f,\"cd_T7\":%.4f,\"ref_T7\":1.02,\"err_T7\":%.3f,", b, rel(b, 1.29), d, rel(d, 1.02);
      printf "\"tolerance\":0.05,\"pass\":%s}\n", ok ? "true" : "false"; exit ok ? 0 : 1 }' \
    "$OUT/vortex_cylinder550/loads.csv"
}

# Blasius at Re_L = 1000: u at x = L/3 (probes above the upper surface, y = 0.01
# + d) against f'(eta), eta = d sqrt(V / (nu x)); drag of both sides within
# 10% of 0.084-0.089. Averages over the last 0.5 time units of the run
# (t = 2.5..3.0 for the case file): the impulsively started plate reaches its
# steady boundary layer only after the free stream has passed it about twice
# (before t ~ 2 the rear part is still a Rayleigh layer and the drag is higher).
# The profile is compared twice: u / V (the spec's wording) and u / U_e with
# U_e the measured velocity at the outermost probe (eta = 6.6, f' = 0.9998):
# Blasius' f' is u / U_e, and at Re_L = 1000 the displacement of the layer
# and the plate's thickness raise U_e above V by a few per cent at x = L/3.
# The verdict uses u / U_e; both errors are printed. The drag compared with
# Blasius' 2 * 1.328 / sqrt(Re) is the friction (`cd_friction`, column 7):
# that formula integrates the wall shear of a plate of zero thickness, while
# the plate here is 0.02 thick with round ends, whose pressure (form) drag
# adds about 0.018 (the total `cd` is printed too).
blasius() {
  run blasius_plate.yaml vortex_blasius || return 1
  t1=$(awk -F, 'NR > 1 { t = $1 } END { printf "%.6f", t - 0.5 }' "$OUT/vortex_blasius/loads.csv")
  cx=$(awk -F, -v t1="$t1" 'NR > 1 && $1 >= t1 { s += $4; f += $7; n++ }
    END { if (n) printf "%.5f %.5f", s / n, f / n }' "$OUT/vortex_blasius/loads.csv")
  awk -F, -v cx="${cx% *}" -v cf="${cx#* }" -v t1="$t1" '
    function fp(eta,   f, p, q, h, i, n, k1f, k1p, k1q, k2f, k2p, k2q, k3f, k3p, k3q, k4f, k4p, k4q) {
      f = 0; p = 0; q = 0.332057336215; h = 0.001; n = int(eta / h + 0.5)
      for (i = 0; i < n; i++) {
        k1f = p; k1p = q; k1q = -0.5 * f * q
        k2f = p + 0.5*h*k1p; k2p = q + 0.5*h*k1q; k2q = -0.5 * (f + 0.5*h*k1f) * (q + 0.5*h*k1q)
        k3f = p + 0.5*h*k2p; k3p = q + 0.5*h*k2q; k3q = -0.5 * (f + 0.5*h*k2f) * (q + 0.5*h*k2q)
        k4f = p + h*k3p; k4p = q + h*k3q; k4q = -0.5 * (f + h*k3f) * (q + h*k3q)
        f += h/6*(k1f+2*k2f+2*k3f+k4f); p += h/6*(k1p+2*k2p+2*k3p+k4p); q += h/6*(k1q+2*k2q+2*k3q+k4q)
      }
      return p }
    NR == 1 { np = (NF - 1) / 3; next }
    $1 >= t1 { for (i = 0; i < np; i++) u[i] += $(2 + 3*i); n++ }
    END {
      split("0.004 0.008 0.012 0.016 0.020 0.024 0.028 0.032 0.036 0.040 0.048 0.056 0.064 0.072 0.080 0.090 0.105 0.120", d, " ")
      if (!n) { print "{\"case\":\"blasius\",\"error\":\"run too short\"}"; exit 1 }
      ue = u[np - 1] / n / fp(d[np] * sqrt(3000.0))
      err = 0; erre = 0; prof = ""
      for (i = 0; i < np; i++) {
        eta = d[i+1] * sqrt(1.0 / (0.001 * (1.0/3.0))); ub = fp(eta); um = u[i] / n
        e = um - ub; if (e < 0) e = -e; if (e > err) err = e
        e = um / ue - ub; if (e < 0) e = -e; if (e > erre) erre = e
        prof = prof sprintf("%s[%.3f,%.4f,%.4f]", i ? "," : "", eta, um, ub)
      }
      okp = erre <= 0.03; okd = (cf >= 0.9 * 0.084 && cf <= 1.1 * 0.089)
      printf "{\"case\":\"blasius\",\"t_from\":%.3f,\"profile_max_err_over_V\":%.4f,\"U_e\":%.4f,\"profile_max_err_over_Ue\":%.4f,\"profile_tolerance\":0.03,", t1, err, ue, erre
      printf "\"cd\":%s,\"cd_friction\":%s,\"cd_ref\":[0.084,0.089],\"cd_tolerance\":0.10,", cx, cf
      printf "\"profile_eta_u_blasius\":[%s],\"pass\":%s}\n", prof, (okp && okd) ? "true" : "false"
      exit (okp && okd) ? 0 : 1 }' "$OUT/vortex_blasius/probes.csv"
}

# Re = 100 shedding over t = 100..150: mean C_D 1.32-1.36, lift amplitude
# 0.32-0.34, Strouhal 0.164-0.167.
cylinder100() {
  run cylinder_re100.yaml vortex_cylinder100 || return 1
  # C_L carries step-to-step noise of a few hundredths (each step's loads are
  # impulse differences), which makes the raw signal cross zero several times
  # per period: the period and the amplitude are read off C_L smoothed by a
  # centred moving average over 0.5 time units (1/12 of a period: attenuates
  # the shedding frequency by 1.1%); the period is the mean spacing of the
  # smoothed signal's upward crossings of its mean, the amplitude the mean
  # over those cycles of (max - min) / 2. Mean C_D from the raw signal.
  awk -F, 'NR == 2 { t0 = $1 } NR == 3 { dt = $1 - t0; w = int(0.25 / dt + 0.5) }
      NR > 1 { n++; t[n] = $1; cd[n] = $4; cl[n] = $5 }
    END {
      for (i = 1; i <= n; i++) {
        s = 0; c = 0
        for (j = i - w; j <= i + w; j++) if (j >= 1 && j <= n) { s += cl[j]; c++ }
        sm[i] = s / c
      }
      m = 0; scd = 0; mcl = 0
      for (i = 1; i <= n; i++) if (t[i] >= 100) { m++; scd += cd[i]; mcl += cl[i] }
      if (m < 10) { print "{\"case\":\"cylinder100\",\"error\":\"run too short\"}"; exit 1 }
      mcl /= m; nc = 0
      for (i = 2; i <= n; i++) if (t[i] >= 100 && sm[i - 1] < mcl && sm[i] >= mcl) up[++nc] = i
      if (nc < 3) { print "{\"case\":\"cylinder100\",\"error\":\"no periodic shedding found\"}"; exit 1 }
      amp = 0
      for (k = 1; k < nc; k++) {
        mx = -1e30; mn = 1e30
        for (i = up[k]; i < up[k + 1]; i++) { if (sm[i] > mx) mx = sm[i]; if (sm[i] < mn) mn = sm[i] }
        amp += (mx - mn) / 2
      }
      amp /= nc - 1; cdm = scd / m; st = (nc - 1) / (t[up[nc]] - t[up[1]])
      ok = cdm >= 1.32 && cdm <= 1.36 && amp >= 0.32 && amp <= 0.34 && st >= 0.164 && st <= 0.167
      printf "{\"case\":\"cylinder100\",\"cd_mean\":%.4f,\"cl_amplitude\":%.4f,\"strouhal\":%.4f,\"cycles\":%d,", cdm, amp, st, nc - 1
      printf "\"ref\":{\"cd_mean\":[1.32,1.36],\"cl_amplitude\":[0.32,0.34],\"strouhal\":[0.164,0.167]},\"pass\":%s}\n", ok ? "true" : "false"
      exit ok ? 0 : 1 }' "$OUT/vortex_cylinder100/loads.csv"
}

naca0012() {
  run naca0012_aoa5.yaml vortex_naca0012 || return 1
  awk -F, 'NR > 1 && $1 >= 4 { n++; cx += $4; cy += $5; cm += $6 }
    END { printf "{\"case\":\"naca0012_aoa5\",\"cx_mean\":%.4f,\"cy_mean\":%.4f,\"cm_mean\":%.4f,\"note\":\"no pass/fail: reported values\"}\n", cx/n, cy/n, cm/n }' \
    "$OUT/vortex_naca0012/loads.csv"
}

mkdir -p "$OUT"
[ $# -eq 0 ] && set -- cylinder550
for c in "$@"; do
  case "$c" in
    --analyse-only) analyse_only=1 ;;
    cylinder550) cylinder550 || status=1 ;;
    blasius) blasius || status=1 ;;
    cylinder100) cylinder100 || status=1 ;;
    naca0012) naca0012 || status=1 ;;
    *) echo "unknown case $c (cylinder550, blasius, cylinder100, naca0012)" >&2; status=2 ;;
  esac
done
exit $status
