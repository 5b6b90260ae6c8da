#!/usr/bin/env python3
"""Weak- and strong-scaling model of one case over 1-64 nodes (issue 21).

    bench/mpi_model.py [--cores C] [--alpha S] [--beta B] [--poisson] [--json]

Each solver's time per step on P nodes (one rank per node, C threads each,
the layout docs/running.md recommends: the state is replicated on every rank)
is modelled as

    t(P) = t_split / P + t_repl + t_comm(P)

  t_split   the work the ranks divide (measured: one node's time per step
            times the split share below);
  t_repl    the work every rank repeats (replicated state: vortex's sheet,
            loads, moves and restructuring; granular's list rebuilds);
  t_comm    per step: n_p2p point-to-point messages of b_p2p bytes to the
            neighbours (latency alpha each, bandwidth beta), and collectives
            over P ranks: an allgather of B bytes in all costs
            alpha log2(P) + B (P - 1) / P / beta.

The message counts and sizes per step are the solvers' own (docs/lattice.md,
docs/granular.md, docs/vortex.md "over MPI ranks", and run.log's
"communication" line, which counts what rank 0 sent); the compute rates are
those measured on one core of the development machine (2 vCPU Xeon, AVX-512:
bench/mpi_ranks.sh, docs/notes) times C cores at the threading efficiency
`eff` of each solver. The network: alpha = 2 us, beta = 10 GB/s (an
InfiniBand HDR100-class link; pass --alpha/--beta for yours). The halo
messages of the lattice overlap the interior work (max of the two).
With --poisson the lattice has lattice.poisson != 0: each force pass also
exchanges the halo's volumetric coefficients (one real per halo entry, in
one packed message per neighbour and way, docs/lattice.md), overlapped as
well, and a step costs "poisson_cost" times the nu = 0 step (1.13-1.40
measured on 16 cores, docs/notes/lattice-poisson.md).

Strong scaling: the case of each row fixed; weak scaling: the case grown
with P (elements, discs or vortices per node fixed). Efficiency = t(1) /
(P t(P)) (strong) or t(1) / t(P) (weak). This is a model, not a
measurement: nothing here ran on more than one 2-core machine.
"""
import argparse
import json
import math

# Per-core rates of the development machine (2 vCPU Xeon AVX-512, gcc 12
# Release), from the measurements quoted in issue 22 and docs/notes (same
# kind of host, idle):
#   lattice: rk4 at 1e6 elements 8-10 M element-steps/s in float on the 2
#            cores, double about half: 2.5e6 per core in double;
#   granular: the 20,000-disc flagship bed, verlet mixed, 1 thread:
#            1.5e7 disc-steps/s (400 steps in 0.54 s, this session);
#   vortex: N = 50k, n = 2576, rk2 with the FMM: 112-120 ms per step on
#           1 thread, 2.3 us per vortex and step; the split parts are ~80%
#           of it (78-86%, bench/vortex_step blocks, docs/vortex.md).
SOLVERS = {
    "lattice": {
        "what": "plate-like body n x n x (n*P) elements (weak) / 200^3 (strong), rk4 double",
        "rate": 2.5e6,   # element-steps/s per core
        "eff": 0.9,      # threading efficiency on C cores
        "split": 1.0,    # share of the step the ranks divide
        "poisson_cost": 1.25,  # nu = 0.3 step / nu = 0 step (1.13-1.40)
    },
    "granular": {
        "what": "bed of 1e5 discs per node (weak) / 1e6 discs (strong), verlet mixed",
        "rate": 1.5e7,   # disc-steps/s per core
        "eff": 0.8,
        # the rest: every rank rebuilds the lists of all discs. Measured
        # 2026-11-27 (bench/granular_vibrobox, 1 thread, an AMD EPYC VM): a
        # rebuild costs 10.3 steps (9801 discs, settled, one every 171
        # steps: 6% of the run) to 14.1 steps (39,601, a looser bed, one
        # every 83: 17%); taken as 12 steps every 120
        "split": 0.90,
        "rebuild_every": 120.0,  # steps between neighbour-list rebuilds
    },
    "vortex": {
        "what": "wake of 50k vortices per node (weak) / 1e6 vortices (strong), rk2 FMM",
        "per_vortex": 2.3e-6,  # s per vortex and step per core, whole step
        "eff": 0.8,
        "split": 0.8,    # the split share of a step (78-86%, docs/vortex.md)
    },
}


def allgather(p, total_bytes, alpha, beta):
    if p < 2:
        return 0.0
    return alpha * math.log2(p) + total_bytes * (p - 1) / p / beta


def lattice_grid(n, p):
    """The rank grid (py, pz) lattice_ranks.c chooses for extents n over p
    ranks: the least halo area (pz - 1) n1 + (py - 1) n2 cut faces per x
    cell, ties to fewer z cuts, blocks at least one cell wide."""
    best = None
    for py in range(1, p + 1):
        if p % py:
            continue
        pz = p // py
        if py > n[1] or pz > n[2]:
            continue
        area = (pz - 1) * n[1] + (py - 1) * n[2]
        if best is None or area <= best[0]:
            best = (area, py, pz)
    return best[1], best[2]


def lattice(p, n_el, cores, alpha, beta, s):
    # a (y, z) rank grid (docs/lattice.md "Over MPI ranks"): a cube n^3
    # (strong) or n x n x (n P) (weak); 4 force passes per rk4 step, 13 reals
    # of 8 bytes per halo entry. A rank in the middle of the grid exchanges
    # across up to 2 y faces (n0 n2 / pz entries each) and 2 z faces
    # (n0 n1 / py); row blocks (py = 1) send 13 messages per face and pass,
    # a 2-D grid one (the components packed)
    if s["strong"]:
        n = [round(n_el ** (1.0 / 3.0))] * 3
    else:
        side = round(s["cross"] ** 0.5)
        n = [side, side, max(1, round(n_el / s["cross"]))]
    py, pz = lattice_grid(n, p)
    node = s["rate"] * cores * s["eff"]
    if s.get("poisson"):
        node /= s["poisson_cost"]
    t_comp = n_el / p / node
    msgs = 13 if py == 1 else 1
    faces = [(min(py - 1, 2), n[0] * n[2] / pz), (min(pz - 1, 2), n[0] * n[1] / py)]
    t_halo = 4 * sum(nf * (msgs * alpha + entries * 13 * 8 / beta) for nf, entries in faces)
    if s.get("poisson"):
        # the halo's coefficients P_a: one real per entry, one more message
        t_halo += 4 * sum(nf * (alpha + entries * 8 / beta) for nf, entries in faces)
    # halo messages overlap the interior work
    t = max(t_comp, t_halo) + 2 * alpha * math.log2(max(p, 1))  # + the step's agreement
    return t, n_el


def granular(p, n, cores, alpha, beta, s):
    node = s["rate"] * cores * s["eff"]
    t_split = s["split"] * n / node
    t_repl = (1 - s["split"]) * n / node * (1 if p > 1 else 0)
    width = math.sqrt(n)  # discs across a square bed: the ghosts of a cut
    nb = 0 if p < 2 else 2
    t_p2p = nb * 2 * (alpha + width * 60 / beta + 2 * width * 12 / beta)
    # one allgather of per-range results every step, and at each rebuild the
    # owners' state of all discs to every rank (about 70 bytes per disc)
    t_coll = allgather(p, 32 * 8 * p, alpha, beta) + \
        allgather(p, 70 * n, alpha, beta) / s["rebuild_every"]
    if p < 2:
        t_split, t_repl = n / node, 0.0
    return t_split / p + t_repl + t_p2p + t_coll, n


def vortex(p, n, cores, alpha, beta, s):
    t1 = n * s["per_vortex"] / (cores * s["eff"])
    # the allgathers of the split sums' results, merge partners and crossing
    # tests: 92 N bytes per rk2 step in all (docs/vortex.md; the sheet's and
    # loads' 24 n bytes for n panels are left out: n << N)
    t_coll = allgather(p, 92 * n, alpha, beta) + 5 * alpha * math.log2(max(p, 1))
    return s["split"] * t1 / p + (1 - s["split"]) * t1 + t_coll, n


MODELS = {"lattice": lattice, "granular": granular, "vortex": vortex}
STRONG = {"lattice": 200 ** 3, "granular": 1.0e6, "vortex": 1.0e6}
WEAK = {"lattice": 100 ** 3, "granular": 1.0e5, "vortex": 5.0e4}


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--cores", type=int, default=16, help="cores per node (default 16)")
    ap.add_argument("--alpha", type=float, default=2e-6, help="latency per message [s]")
    ap.add_argument("--beta", type=float, default=1e10, help="bandwidth [bytes/s]")
    ap.add_argument("--poisson", action="store_true",
                    help="lattice with lattice.poisson != 0 (the coefficients' halo too)")
    ap.add_argument("--json", action="store_true", help="one JSON line per row")
    a = ap.parse_args()
    nodes = [1, 2, 4, 8, 16, 32, 64]
    for name, model in MODELS.items():
        s = dict(SOLVERS[name])
        s["poisson"] = a.poisson
        rows = []
        for kind in ("strong", "weak"):
            s["strong"] = kind == "strong"
            s["cross"] = WEAK["lattice"] ** (2.0 / 3.0)
            base = None
            for p in nodes:
                size = STRONG[name] if kind == "strong" else WEAK[name] * p
                t, _ = model(p, size, a.cores, a.alpha, a.beta, s)
                if base is None:
                    base = t
                eff = base / (p * t) if kind == "strong" else base / t
                rows.append((kind, p, size, t, eff))
        if a.json:
            for kind, p, size, t, eff in rows:
                print(json.dumps({"model": "mpi_scaling", "solver": name, "scaling": kind,
                                  "nodes": p, "cores_per_node": a.cores, "size": size,
                                  "s_per_step": t, "efficiency": round(eff, 3),
                                  "lattice_poisson": a.poisson,
                                  "alpha_s": a.alpha, "beta_bytes_per_s": a.beta}))
            continue
        print("%s: %s" % (name, SOLVERS[name]["what"]))
        print("  nodes        " + " ".join("%7d" % p for p in nodes))
        for kind in ("strong", "weak"):
            r = [x for x in rows if x[0] == kind]
            print("  %-6s s/step " % kind + " ".join("%7.3g" % x[3] for x in r))
            print("  %-6s eff.   " % kind + " ".join("%7.2f" % x[4] for x in r))


if __name__ == "__main__":
    main()
