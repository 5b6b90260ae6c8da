"""partix from Python: run a case, step it, read its results as NumPy arrays.

    import partix
    sim = partix.Simulation("cases/vortex/naca0012_aoa5.yaml",
                            set={"time.steps": 200}, out="run1")
    sim.run()
    print(sim.loads()["cy"][-1], sim.summary()["quantities"])

Results are NumPy arrays over the library's memory (no copy), read-only;
each keeps the memory it views alive, so it stays valid after later steps
(it shows the state at the step it was taken). See docs/python.md.
"""

import collections.abc
import json
import operator
import os
import re
import threading

from . import _core

__all__ = ["Simulation", "Results", "Error", "CaseError", "resume", "check", "version", "solvers"]


class Error(RuntimeError):
    """A partix failure: `status` (e.g. "NUMERIC", "IO") and `message`."""

    def __init__(self, status, message):
        super().__init__(message)
        self.status = status
        self.message = message


class CaseError(Error, ValueError):
    """A case that partix refuses: where (file, line, column: 0 when the
    error is in an override, then `file` names it) and which key.
    `errors` lists every problem found as (file, line, column, key, message)."""

    def __init__(self, status, message, errors):
        super().__init__(status, message)
        self.errors = errors
        self.file, self.line, self.column, self.key, self.message = errors[0]

    def __str__(self):
        # a message that starts with its key ("K cannot change ...") is not
        # prefixed with it again
        return "\n".join(
            (f"{f}:{l}:{c}: " if l else f"{f}: ") + (m if not k or m.startswith(k) else f"{k}: {m}")
            for f, l, c, k, m in self.errors
        )


_AT = re.compile(r"^(?P<file>.+?):(?P<line>\d+):(?P<col>\d+): (?P<rest>.*)$")
_SET = re.compile(r"^(?P<file>--set (?P<setkey>[^:=]*)[^:]*): (?P<rest>.*)$")
# a case key: "time.end", "vortex.bodies[0].angle"
_KEY = re.compile(r"^[A-Za-z_][A-Za-z0-9_]*(?:\[\d+\])*(?:\.[A-Za-z_][A-Za-z0-9_]*(?:\[\d+\])*)*$")


def _case_errors(message):
    """The lines "FILE:LINE:COL: KEY: MESSAGE" (or "--set K=V: KEY: MESSAGE")
    of a case error; None when the message has none of them. A line whose
    message is a sentence about a key ("K cannot change when a run is
    resumed: ...") has K as its key and the whole sentence as its message."""
    errors = []
    for text in message.splitlines():
        m = _AT.match(text) or _SET.match(text)
        if not m:
            continue
        d = m.groupdict()
        rest = d["rest"]
        key, _, msg = rest.partition(": ")
        if not msg or not _KEY.match(key):
            first = rest.split(" ", 1)[0]
            setkey = d.get("setkey") or ""
            key = first if _KEY.match(first) and "." in first else setkey if _KEY.match(setkey) else ""
            msg = rest
        errors.append((d["file"], int(d.get("line") or 0), int(d.get("col") or 0), key, msg))
    return errors or None


def _raise(err):
    status, message = err.args
    errors = _case_errors(message) if status == "CONFIG" else None
    if errors:
        raise CaseError(status, message, errors) from None
    raise Error(status, message) from None


def _overrides(set, out):
    """{key: value} -> ["key=value", ...] (lists as YAML flow lists)."""
    if set is not None and not isinstance(set, collections.abc.Mapping):
        raise TypeError(
            "set: a dict of case keys to values, e.g. set={'time.end': 1.0}, "
            f"not a {type(set).__name__}"
        )
    items = [f"{key}={_yaml(value)}" for key, value in (set or {}).items()]
    if out is not None:
        items.append(f"output.dir={_yaml(os.fspath(out))}")
    return items


def _yaml(value):
    """A Python value as the YAML text of an override: a str is text as
    given (double-quoted: 'run #2' keeps its '#', 'a: b' stays a string),
    None is null, lists are flow lists of such values."""
    if isinstance(value, bool):
        return "true" if value else "false"
    if value is None:
        return "null"
    if isinstance(value, str):
        out = []
        for ch in value:
            if ch in '"\\':
                out.append("\\" + ch)
            elif ord(ch) < 0x20 or ord(ch) == 0x7F:
                out.append("\\x%02x" % ord(ch))
            else:
                out.append(ch)
        return '"' + "".join(out) + '"'
    if isinstance(value, (list, tuple)):
        return "[" + ", ".join(_yaml(v) for v in value) + "]"
    return str(value)


class Results(dict):
    """Arrays by name (a dict), with `units` (by name), the `step` and the
    `time` [s] they were taken at."""

    def __init__(self, raw):
        arrays, units, step, time = raw
        super().__init__(arrays)
        self.units = units
        self.step = step
        self.time = time


_LOG_LEVELS = ("error", "warning", "info", "debug")


def _check_log(log):
    if not isinstance(log, str):
        raise TypeError(f"log: one of {', '.join(map(repr, _LOG_LEVELS))}, not a {type(log).__name__}")
    if log not in _LOG_LEVELS:
        raise ValueError(f"log: one of {', '.join(map(repr, _LOG_LEVELS))}, not {log!r}")


def _main_thread():
    return threading.current_thread() is threading.main_thread()


class Simulation:
    """A run of a case: Simulation(case, set={key: value}, out=folder).

    `set` overrides keys of the case (as `partix run --set`), `out` is the
    output folder (output.dir). `log` is the console's level ("error",
    "warning", "info", "debug")."""

    # None until __init__ succeeded (an object made by __new__ alone has no
    # run: its methods raise RuntimeError, not AttributeError)
    _sim = None

    def __init__(self, case, set=None, out=None, log="warning", _resume=False, _check=False):
        _check_log(log)
        try:
            self._sim = _core.Sim(os.fspath(case), _overrides(set, out), 1 if _check else 0, log,
                                  _resume)
        except _core.Error as e:
            _raise(e)

    def _call(self, name, *args):
        if self._sim is None:
            raise RuntimeError(
                "this Simulation has no run: create it as partix.Simulation(case, ...) "
                "(its __init__ was not called or failed)"
            )
        try:
            return getattr(self._sim, name)(*args)
        except _core.Error as e:
            _raise(e)

    def _info(self):
        return self._call("info")

    # -- running ---------------------------------------------------------
    def run(self, progress=False):
        """Run to the end. Ctrl-C writes a checkpoint and raises
        KeyboardInterrupt (continue with partix.resume)."""
        self._call("run", _main_thread(), progress)
        return self

    def step(self, n=1):
        """Advance n steps (fewer if the run ends), with the outputs that fall
        due; returns the steps done. Ctrl-C stops after the step in progress
        and raises KeyboardInterrupt: the state is that of a whole step."""
        try:
            n = operator.index(n)
        except TypeError:
            raise TypeError(f"step(n): n is a whole number of steps, not a {type(n).__name__}") from None
        if n < 0:
            raise ValueError(f"step(n): n is 0 or more steps, not {n}")
        return self._call("step", n, _main_thread())

    def checkpoint(self):
        """Write a checkpoint now; returns its path."""
        return self._call("checkpoint")

    def close(self):
        """Free the run (its arrays stay valid)."""
        if self._sim is not None:
            self._sim.close()

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.close()

    # -- where it stands -------------------------------------------------
    @property
    def time(self):
        """Simulated time [s]."""
        return self._info()[2]

    @property
    def step_index(self):
        """Steps done."""
        return self._info()[0]

    @property
    def steps(self):
        """Steps the run goes to."""
        return self._info()[1]

    @property
    def dt(self):
        """Time step [s]."""
        return self._info()[3]

    @property
    def out(self):
        """The output folder."""
        return self._info()[4]

    @property
    def solver(self):
        return self._info()[6]

    # -- results ---------------------------------------------------------
    def state(self):
        """The current state: a Results dict of arrays per particle, element
        or vortex (docs/python.md lists them by solver)."""
        return Results(self._call("results", 0))

    def segments(self):
        """Per-segment statistics of the reported contours (granular)."""
        return Results(self._call("results", 1))

    def series_names(self):
        """The time series written so far ("loads", "probes", "media", ...)."""
        return self._call("series_names")

    def series(self, name):
        """A time series (the CSV file `name`.csv in memory): a Results dict
        of columns, the units by column."""
        return Results(self._call("series", name))

    def loads(self):
        """The vortex solver's loads (loads.csv): t, cx, cy, cm, ..."""
        return self.series("loads")

    def probes(self):
        """The probes (probes.csv) of the vortex or lattice solver."""
        return self.series("probes")

    def summary(self):
        """summary.json of the run (written at checkpoints and at the end);
        partix.Error (status "NOT_FOUND") before the first of them."""
        path = os.path.join(self.out, "summary.json")
        try:
            with open(path, encoding="utf-8") as f:
                return json.load(f)
        except FileNotFoundError:
            raise Error(
                "NOT_FOUND",
                f"{path}: no summary.json yet: the run writes it at each checkpoint and at its "
                "end (sim.checkpoint() writes one now)",
            ) from None


def resume(path, set=None, out=None, log="warning"):
    """Continue a run from its checkpoint (a .pxc file or a run folder)."""
    path = os.fspath(path)
    if os.path.isdir(path):
        path = os.path.join(path, "checkpoint.pxc")
    return Simulation(path, set=set, out=out, log=log, _resume=True)


def check(case, set=None):
    """Validate a case and build its problem without running or writing
    anything; raises CaseError (file, line, column, key, message)."""
    sim = Simulation(case, set=set, _check=True)
    info = sim._info()
    sim.close()
    return {"solver": info[6], "steps": info[1], "dt": info[3]}


def version():
    return _core.version()


def solvers():
    return _core.solvers()
