#!/usr/bin/env python3
"""The step benches say what ran (issue 22, bench/README.md "Fields").

Runs each bench of bench/ at a tiny size and checks that every JSON line
states the threads asked for and actually used, the machine, the load
average before and after, the precision of its sums, a traffic model, and
min <= median <= max of its timing over repetitions (or timed blocks).
The figures are not asserted (speed is measured by the benches, not by
tests), only that they are there, finite and ordered.

Usage: test_bench_fields.py BENCH_DIR
"""
import json
import math
import os
import subprocess
import sys

BENCH = sys.argv[1] if len(sys.argv) > 1 else "build/release/bench"
ENV_FIELDS = ("threads_requested", "threads_used", "cpu_model", "load1_before", "load1_after")

# bench name -> (arguments, the timed quantity with _min/_median/_max,
#                the precision field, the traffic field)
CASES = [
    ("lattice_step",
     ["--sizes", "12", "--steps", "5", "--threads", "1", "--no-opencl", "--no-baseline",
      "--no-triad", "--integrator", "rk4", "--precision", "single"],
     "element_steps_per_s", "sum_precision", "bytes_per_step_model"),
    ("granular_vibrobox", ["12", "12", "20", "100", "1", "double", "verlet", "fixed"],
     "disc_steps_per_s", "sum_precision", "bytes_per_step_model"),
    ("vortex_step", ["1500", "200", "cpu", "mixed", "1", "3", "fmm", "1e-6", "euler"],
     "step_s", "pair_sum_precision", "bytes_per_step_model"),
    ("vortex_fmm", ["--n", "2000", "--tol", "1e-6", "--precision", "double", "--threads", "1",
                    "--method", "fmm", "--reps", "3"],
     "seconds", "sum_precision", "bytes_per_sum_model"),
    ("nbody_direct", ["--n", "600", "--backend", "cpu", "--precision", "single", "--threads",
                      "1", "--reps", "3"],
     "seconds", "sum_precision", "bytes_per_sum_model"),
    ("grid_build", ["--n", "2000", "--dims", "2", "--backend", "cpu", "--threads", "1",
                    "--reps", "3"],
     "seconds", None, "bytes_per_build_model"),
]

failures = []


def fail(msg):
    failures.append(msg)
    print("FAIL", msg)


def finite_number(v):
    return isinstance(v, (int, float)) and not isinstance(v, bool) and math.isfinite(v)


for name, args, timed, prec, traffic in CASES:
    exe = os.path.join(BENCH, name)
    p = subprocess.run([exe] + args, capture_output=True, text=True, timeout=240)
    if p.returncode != 0:
        fail("%s exited %d: %s" % (name, p.returncode, p.stderr.strip()[-400:]))
        continue
    rows = [json.loads(l) for l in p.stdout.splitlines() if l.startswith("{")]
    rows = [r for r in rows if r.get("bench") == name]
    if not rows:
        fail("%s printed no line of its own" % name)
        continue
    for r in rows:
        where = "%s %s" % (name, {k: r[k] for k in ("precision", "scheme") if k in r})
        for k in ENV_FIELDS:
            if k not in r:
                fail("%s: no %s" % (where, k))
        if r.get("threads_used") != 1:
            fail("%s: threads_used %r on one thread asked" % (where, r.get("threads_used")))
        for k in ("load1_before", "load1_after"):
            if k in r and not (finite_number(r[k]) and r[k] >= 0):
                fail("%s: %s = %r" % (where, k, r[k]))
        trio = [r.get(timed + s) for s in ("_min", "_median", "_max")]
        if not all(finite_number(v) and v > 0 for v in trio):
            fail("%s: %s_min/_median/_max = %r" % (where, timed, trio))
        elif not trio[0] <= trio[1] <= trio[2]:
            fail("%s: %s min %g, median %g, max %g out of order" % ((where, timed) + tuple(trio)))
        # "float", "double" or a phrase ("float contact forces, double state")
        if prec and not (isinstance(r.get(prec), str) and
                         ("float" in r[prec] or "double" in r[prec])):
            fail("%s: %s = %r" % (where, prec, r.get(prec)))
        if not (finite_number(r.get(traffic)) and r[traffic] > 0):
            fail("%s: %s = %r" % (where, traffic, r.get(traffic)))
        if "parallel_step_fraction" in r and not 0 <= r["parallel_step_fraction"] <= 1:
            fail("%s: parallel_step_fraction %r" % (where, r["parallel_step_fraction"]))
    print("ok  %-18s %d line(s)" % (name, len(rows)))

if failures:
    print("%d failure(s)" % len(failures))
    sys.exit(1)
print("all bench lines state what ran")
