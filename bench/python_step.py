#!/usr/bin/python3
"""A vortex run through the Python module's sim.step() against `partix run`.

    /usr/bin/python3 bench/python_step.py [--partix build/release/partix]
        [--python-path build/release/python] [--steps 1000] [--repeat 3] [--threads T]

Runs cases/vortex/demo_cylinder.yaml for --steps steps (outputs as the case
has them, pictures off) both ways, alternately, --repeat times, and prints
one JSON object: the wall times of each (min, median), the overhead of the
Python loop over the CLI (median_python / median_cli - 1), and the load
average before and after. The Python side steps one step per call (the
worst case for the call overhead) and ends with the same end-of-run
products. Timings only mean something side by side on an idle machine
(bench/README.md).
"""
import argparse
import json
import os
import shutil
import statistics
import subprocess
import sys
import tempfile
import time

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(HERE)


def load1():
    with open("/proc/loadavg") as f:
        return float(f.read().split()[0])


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--partix", default=os.path.join(ROOT, "build", "release", "partix"))
    ap.add_argument("--python-path", default=os.path.join(ROOT, "build", "release", "python"))
    ap.add_argument("--case", default=os.path.join(ROOT, "cases", "vortex", "demo_cylinder.yaml"))
    ap.add_argument("--steps", type=int, default=1000)
    ap.add_argument("--repeat", type=int, default=3)
    ap.add_argument("--threads", type=int, default=None,
                    help="backend.threads for both (default: the case's; 0 or unset: the tuner "
                         "picks, whose choices differ between runs)")
    a = ap.parse_args()
    sys.path.insert(0, a.python_path)
    import partix

    settings = {"time.steps": a.steps, "output.png": False}
    if a.threads is not None:
        settings["backend.threads"] = a.threads
    sets = [x for k, v in settings.items() for x in ("--set", f"{k}={str(v).lower()}")]
    cli, py = [], []
    before = load1()
    with tempfile.TemporaryDirectory(prefix="px_bench_py_") as tmp:
        for r in range(a.repeat):
            out = os.path.join(tmp, f"cli{r}")
            t0 = time.perf_counter()
            subprocess.run([a.partix, "run", a.case, "-q", "--out", out] + sets, check=True)
            cli.append(time.perf_counter() - t0)
            shutil.rmtree(out)
            out = os.path.join(tmp, f"py{r}")
            t0 = time.perf_counter()
            sim = partix.Simulation(a.case, set=settings, out=out, log="error")
            while sim.step(1):
                pass
            sim.close()
            py.append(time.perf_counter() - t0)
            shutil.rmtree(out)
    print(json.dumps({
        "bench": "python_step", "case": os.path.relpath(a.case, ROOT), "steps": a.steps,
        "repeat": a.repeat, "threads": a.threads, "cli_seconds_min": min(cli), "cli_seconds_median": statistics.median(cli),
        "python_seconds_min": min(py), "python_seconds_median": statistics.median(py),
        "python_overhead": statistics.median(py) / statistics.median(cli) - 1.0,
        "load1_before": before, "load1_after": load1(), "partix": partix.version()}))


if __name__ == "__main__":
    main()
