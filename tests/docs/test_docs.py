#!/usr/bin/env python3
"""The user documentation works as written.

    test_docs.py PARTIX SOURCE_DIR [DOC.md ...]

For README.md and every docs/*.md (or the files named):
  - every command of a ```sh fenced block runs, in order, from a scratch
    folder that looks like the repository root (cases/, bench/, scripts/,
    docs/ and examples/ linked in; outputs land in the scratch folder). The
    step count of `partix run` and `partix resume` lines is cut to a few
    steps (--steps/--more/time.steps/time.end given in the line are
    replaced), so that a doc may show a long run; everything else runs as
    written and must exit 0;
    `mpirun ... partix ...` lines run the same way, with --oversubscribe
    (the ranks may share few cores);
  - every command of a ```sh-long block (long validations, benchmarks) names
    a program that exists: `partix SUBCOMMAND` with a known subcommand, or a
    script/file of the repository;
  - every key path written in backticks that starts with a case section
    (`vortex.eps_min`, `time.dt`, `output.every=10`, `vortex.bodies[0].file`)
    is a key of `partix keys`.
Development notes (docs/notes/) are studies with dated measurements, not
instructions, and are not checked.
"""
import os
import re
import shlex
import subprocess
import sys
import tempfile

SECTIONS = ("solver", "title", "backend", "time", "output", "vortex", "lattice", "granular")
FILE_TYPES = ("pvd", "csv", "png", "vtu", "vti", "vtp", "yaml", "json", "log", "pxc", "dat",
              "dxf", "md", "py", "sh", "txt", "stl", "obj")
RUN_STEPS = "3"
RESUME_MORE = "2"
CUT_OPTIONS = ("--steps", "--more")
CUT_SETS = ("time.steps=", "time.end=")


def blocks(text):
    """(info, [lines]) of every fenced block."""
    out, info, lines = [], None, []
    for line in text.split("\n"):
        m = re.match(r"^\s*```(\S*)\s*$", line)
        if m and info is None:
            info, lines = m.group(1), []
        elif m:
            out.append((info, lines))
            info = None
        elif info is not None:
            lines.append(line)
    return out


def commands(lines):
    """Shell commands of a block: comments and blanks dropped, continuation
    lines joined, a leading "$ " prompt removed."""
    out, cur = [], ""
    for line in lines:
        s = line.strip()
        if s.startswith("$ "):
            s = s[2:]
        if not cur and (not s or s.startswith("#")):
            continue
        if s.endswith("\\"):
            cur += s[:-1] + " "
            continue
        out.append(cur + s)
        cur = ""
    if cur:
        out.append(cur)
    return out


def cut_steps(argv):
    """partix run/resume with a few steps instead of what the doc asks."""
    sub = next((a for a in argv[1:] if not a.startswith("-")), None)
    if sub not in ("run", "resume"):
        return argv
    out, i = [], 0
    while i < len(argv):
        a = argv[i]
        if a in CUT_OPTIONS:
            i += 2
            continue
        if any(a.startswith(o + "=") for o in CUT_OPTIONS):
            i += 1
            continue
        if a in ("--set", "-s") and i + 1 < len(argv) and argv[i + 1].startswith(CUT_SETS):
            i += 2
            continue
        if a.startswith("--set=") and a[6:].startswith(CUT_SETS):
            i += 1
            continue
        out.append(a)
        i += 1
    return out + (["--steps", RUN_STEPS] if sub == "run" else ["--more", RESUME_MORE])


def schema_keys(partix):
    text = subprocess.run([partix, "keys"], capture_output=True, text=True, check=True).stdout
    keys = set()
    for line in text.split("\n"):
        if not line or line[0] == " ":
            continue
        keys.add(line.split()[0].replace("[]", ""))
    return keys


def key_problems(text, keys, name):
    bad = []
    for span in re.findall(r"`([^`\n]+)`", text):
        token = span.strip().split("=", 1)[0].split(":", 1)[0].strip()
        if not re.fullmatch(r"[a-z_]+(\.[A-Za-z0-9_]+|\[\d*\])+", token):
            continue
        if token.split(".", 1)[0].split("[", 1)[0] not in SECTIONS:
            continue
        if token.rsplit(".", 1)[-1] in FILE_TYPES:  # a file name (`lattice.pvd`)
            continue
        path = re.sub(r"\[\d*\]", "", token)
        if path not in keys and not any(k.startswith(path + ".") for k in keys):
            bad.append("%s: `%s` is not a case key (partix keys)" % (name, span))
    return bad


def main():
    partix, src = os.path.abspath(sys.argv[1]), os.path.abspath(sys.argv[2])
    docs = sys.argv[3:] or (["README.md"] + sorted(
        os.path.join("docs", f) for f in os.listdir(os.path.join(src, "docs"))
        if f.endswith(".md")))
    keys = schema_keys(partix)
    # the commands `partix --help` lists
    usage = subprocess.run([partix, "--help"], capture_output=True, text=True).stdout
    listing = usage.split("commands:", 1)[-1].split("options:", 1)[0]
    subs = tuple(line.split()[0] for line in listing.splitlines() if line.strip())
    bad, ran, long_ok = [], 0, 0
    for doc in docs:
        text = open(os.path.join(src, doc), encoding="utf-8").read()
        bad += key_problems(text, keys, doc)
        with tempfile.TemporaryDirectory(prefix="px_docs_") as scratch:
            for d in ("cases", "bench", "scripts", "docs", "examples", "tests"):
                if os.path.exists(os.path.join(src, d)):
                    os.symlink(os.path.join(src, d), os.path.join(scratch, d))
            # Open MPI's session folder in the scratch folder: mpirun started
            # by another test at the same time (ctest -j) races to create the
            # shared /tmp/ompi.HOST.UID
            env = dict(os.environ, PATH=os.path.dirname(partix) + os.pathsep + os.environ["PATH"],
                       OMPI_MCA_orte_tmpdir_base=scratch)
            for info, lines in blocks(text):
                for cmd in commands(lines):
                    try:
                        argv = shlex.split(cmd, comments=True)
                    except ValueError as e:
                        if info in ("sh", "sh-long"):
                            bad.append("%s: `%s`: %s" % (doc, cmd, e))
                        continue
                    if not argv:
                        continue
                    if info == "sh-long":
                        if argv[0] == "partix":
                            ok = len(argv) > 1 and argv[1] in subs
                        else:
                            exe = next((a for a in argv if "/" in a or a.endswith((".sh", ".py"))),
                                       argv[0])
                            ok = os.path.exists(os.path.join(src, exe)) or exe in (
                                "cmake", "ctest", "python3", "sh", "mpirun")
                            if exe.startswith("build/"):  # a program built from bench/ or tests/
                                base = os.path.basename(exe)
                                ok = ok or any(os.path.exists(os.path.join(src, d, base + ext))
                                               for d in ("bench", "tests") for ext in (".c", ".sh"))
                        if not ok:
                            bad.append("%s: long command names nothing known: %s" % (doc, cmd))
                        long_ok += ok
                        continue
                    if info != "sh":
                        continue
                    if argv[0] == "partix":
                        argv = cut_steps([partix] + argv[1:])
                        shell = False
                    elif argv[0] == "mpirun" and "partix" in argv:
                        # one case over ranks: cut like partix's own line, the
                        # ranks may share this machine's cores
                        at = argv.index("partix")
                        root = ["--allow-run-as-root"] if os.geteuid() == 0 else []
                        argv = (["mpirun", "--oversubscribe"] + root + argv[1:at] +
                                cut_steps([partix] + argv[at + 1:]))
                        shell = False
                    else:
                        shell = True
                    r = subprocess.run(cmd if shell else argv, shell=shell, cwd=scratch, env=env,
                                       capture_output=True, text=True, timeout=600)
                    ran += 1
                    if r.returncode != 0:
                        bad.append("%s: `%s` exited %d:\n    %s" % (
                            doc, cmd, r.returncode,
                            "\n    ".join((r.stderr or r.stdout).strip().split("\n")[-6:])))
    if bad:
        print("test_docs: %d problems:" % len(bad))
        for b in bad:
            print("  " + b)
        return 1
    print("test_docs: %d commands ran, %d long commands named, every key exists (%d docs)" %
          (ran, long_ok, len(docs)))
    return 0


if __name__ == "__main__":
    sys.exit(main())
