#!/bin/sh
# Floating-point operations and instructions per element-step of the lattice
# cpu engine, counted by valgrind's callgrind: what a step computes, to set
# against the bytes of lattice_step's traffic model (its
# bytes_per_step_model). Issue 22 asks the RK4 step at 1e6 elements for 50 %
# of the triad bandwidth over that model; the count says how many flop/s that
# takes.
#
#   bench/lattice_flops.sh BUILD [SIZE]
#
# BUILD without -march=native (valgrind does not run AVX-512 code):
#   cmake -S . -B build/cg -DCMAKE_BUILD_TYPE=Release -DPX_NATIVE=OFF -DPX_BUILD_TESTS=OFF
#   cmake --build build/cg --target lattice_step
#
# For each configuration (RK4 and leapfrog, single and double, both link
# schemes), a SIZE^3 box (default 24) on one thread: the difference of two
# runs that differ only in their steps (set-up cancels). The flops are the
# SSE arithmetic instructions (add, sub, mul, div, sqrt) executed in the
# lattice_step binary, each weighted by its lanes (4 for packed float, 2 for
# packed double, 1 for scalar): the arithmetic of that build, rows of SIZE
# cells and all links (a link flagged absent is computed and multiplied by
# 0). The AVX-512 build computes the same per element, plus the idle lanes of
# a row's last vector. Comparisons, min/max and conversions are not counted.
# Prints one JSON line per configuration.
set -eu
[ $# -ge 1 ] || { sed -n 2,25p "$0"; exit 2; }
b=$1/bench/lattice_step
size=${2:-24}
[ -x "$b" ] || { echo "lattice_flops: no $b (build first)" >&2; exit 2; }
command -v valgrind >/dev/null || { echo "lattice_flops: no valgrind" >&2; exit 2; }
command -v objdump >/dev/null || { echo "lattice_flops: no objdump (binutils)" >&2; exit 2; }
tmp=$(mktemp -d) || exit 2
trap 'rm -rf "$tmp"' EXIT
export OMP_NUM_THREADS=1
objdump -d --no-show-raw-insn "$b" > "$tmp/dis"

run() { # STEPS OUT ARGS...: callgrind with per-instruction counts
  s=$1
  o=$2
  shift 2
  valgrind --tool=callgrind --dump-instr=yes --callgrind-out-file="$o" "$b" --sizes "$size" \
    --steps "$s" --threads 1 --no-opencl --no-baseline --no-triad "$@" > "$o.json" 2> /dev/null ||
    { echo "lattice_flops: failed under valgrind: $b $*" >&2; exit 1; }
}

for integ in rk4 leapfrog; do
  for prec in single double; do
    for scheme in link_once gather; do
      # lattice_step runs 4 leapfrog steps per step asked (a leapfrog step
      # evaluates the links once, an RK4 step four times)
      lo=2 hi=6 per=1
      [ "$integ" = leapfrog ] && per=4
      set -- --integrator "$integ" --precision "$prec" --scheme "$scheme"
      run "$lo" "$tmp/a" "$@"
      run "$hi" "$tmp/b" "$@"
      python3 - "$tmp" "$integ" "$prec" "$scheme" "$(((hi - lo) * per))" << 'PY'
import collections, json, re, sys

tmp, integ, prec, scheme, dsteps = sys.argv[1], sys.argv[2], sys.argv[3], sys.argv[4], int(sys.argv[5])


def counts(path):
    """Executions per instruction address of the lattice_step binary."""
    c = collections.Counter()
    names, obj, last, skip = {}, None, 0, False
    for line in open(path):
        if line.startswith(("ob=", "cob=")):
            m = re.match(r"c?ob=\((\d+)\)\s*(.*)", line.strip())
            if m.group(2):
                names[m.group(1)] = m.group(2)
            if line.startswith("ob="):
                obj = names.get(m.group(1), "")
            continue
        if line.startswith("calls="):
            skip = True  # the next cost line is the call's inclusive cost
            continue
        if not line or line[0] not in "0+-*":
            continue
        f = line.split()
        a = f[0]
        if a.startswith("0x"):
            last = int(a, 16)
        elif a[0] == "+":
            last += int(a[1:])
        elif a[0] == "-":
            last -= int(a[1:])
        if skip:
            skip = False
            continue
        if obj.endswith("/lattice_step") and len(f) >= 2:
            c[last] += int(f[-1])
    return c


mnem = {}
for line in open(tmp + "/dis"):
    m = re.match(r"\s+([0-9a-f]+):\s+(\S+)", line)
    if m:
        mnem[int(m.group(1), 16)] = m.group(2)
a, b = counts(tmp + "/a"), counts(tmp + "/b")
lanes = {"ps": 4, "ss": 1, "pd": 2, "sd": 1}
flops = insn = 0
for addr in set(a) | set(b):
    d = b[addr] - a[addr]
    insn += d
    m = re.match(r"v?(add|sub|mul|div|sqrt)(ps|ss|pd|sd)$", mnem.get(addr, ""))
    if m:
        flops += d * lanes[m.group(2)]
out = json.loads(open(tmp + "/b.json").read().strip().splitlines()[-1])
es = out["elements"] * dsteps
row = {
    "bench": "lattice_flops",
    "integrator": integ,
    "precision": prec,
    "scheme": scheme,
    "elements": out["elements"],
    "counted_steps": dsteps,
    "flops_per_element_step": round(flops / es, 1),
    "instructions_per_element_step": round(insn / es, 1),
    # the model at this size (padding makes it larger than at 1e6 elements)
    "bytes_per_element_step_model": round(out["bytes_per_step_model"] / out["elements"], 1),
}
row["flops_per_model_byte"] = round(row["flops_per_element_step"] / row["bytes_per_element_step_model"], 2)
print(json.dumps(row))
PY
    done
  done
done
