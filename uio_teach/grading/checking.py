"""Check a hand-in's answers in a child process, with caps on their size, time and memory.

The answers a notebook exported are untrusted data: a right solution may carry
a figure with thousands of empty axes, or an array of millions of entries,
that would keep the checks busy for minutes. So the grader never rebuilds
them in its own process. :func:`check_in_child` starts a fresh Python process
(``python -m uio_teach.grading.checking``) that

1. limits its own memory (address space) and CPU time;
2. parses each answer file and measures it against the caps of
   :data:`CAPS` (entries of an array and of all arrays, axes and lines of a
   figure, characters of a string, items of a list): an answer over a cap is
   not rebuilt, its checks fail saying why, and the row is "over limits";
3. rebuilds the rest as genuine objects of the package and runs the lab
   chapter's own check cells with the answer key's parameters
   (:mod:`uio_teach.grading.lab_checks`);
4. writes the results back as JSON.

The grader waits for it at most ``timeout`` seconds (then kills it: "over
limits"), and kills it at once when the grading run is interrupted.

Examples
--------
>>> from uio_teach.grading.checking import TooLarge, measure
>>> measure({"x": [1, 2, 3]})
>>> try:
...     measure({"__uio__": "figure", "axes": [{}] * 100})
... except TooLarge as err:
...     print(err)
a figure with 100 axes (at most 24)
"""

from __future__ import annotations

import ast
import json
import os
import re
import subprocess
import sys
import tempfile
import threading
import time
from collections.abc import Mapping
from dataclasses import dataclass, field
from typing import Any

from ..errors import UIOTeachError

__all__ = ["CAPS", "TooLarge", "CheckOutcome", "measure", "check_in_child", "check_answers"]

CAPS = {
    "array": 2_000_000,
    "arrays": 10_000_000,
    "axes": 24,
    "lines": 64,
    "string": 20_000,
    "items": 200_000,
}
"""The largest answer graded, far above any lab's answer.

The keys name what is counted: entries of one array and of all arrays of an answer, axes of a
figure, lines of an axes, characters of a string, items of a list."""
_TAG = "__uio__"


class TooLarge(UIOTeachError, ValueError):
    """An answer over one of the :data:`CAPS` (one line saying which)."""


@dataclass
class CheckOutcome:
    """What the checking process gave.

    Attributes
    ----------
    results : list of dict
        ``CheckResult.to_dict()`` of every check, in order.
    notes : list of str
        Answers over a cap, a check over its time or memory.
    over : bool
        Whether a limit was reached (the row is then "over limits").
    """

    results: list[dict[str, Any]] = field(default_factory=list)
    notes: list[str] = field(default_factory=list)
    over: bool = False


def measure(data: Any) -> None:
    """Raise :class:`TooLarge` if the plain answer data exceeds a cap of :data:`CAPS`.

    Parameters
    ----------
    data : object
        One answer as parsed JSON (see :mod:`uio_teach.checks.answers`).

    Raises
    ------
    TooLarge
    """
    total = 0
    stack = [data]
    while stack:
        item = stack.pop()
        if isinstance(item, str):
            if len(item) > CAPS["string"]:
                raise TooLarge(f"a text of {len(item)} characters (at most {CAPS['string']})")
        elif isinstance(item, list):
            if len(item) > CAPS["items"]:
                raise TooLarge(f"a list of {len(item)} items (at most {CAPS['items']})")
            stack.extend(item)
        elif isinstance(item, dict):
            kind = item.get(_TAG)
            if kind == "array":
                shape = item.get("shape")
                size = 1
                for s in shape if isinstance(shape, list) else []:
                    size *= s if isinstance(s, int) and s >= 0 else 1
                if size > CAPS["array"]:
                    raise TooLarge(f"an array of {size} entries (at most {CAPS['array']})")
                total += size
                if total > CAPS["arrays"]:
                    raise TooLarge(f"arrays of more than {CAPS['arrays']} entries in all")
                continue  # its base64 text is as long as its entries say (checked on rebuild)
            if kind == "figure":
                axes = item.get("axes")
                if isinstance(axes, list) and len(axes) > CAPS["axes"]:
                    raise TooLarge(f"a figure with {len(axes)} axes (at most {CAPS['axes']})")
                for ax in axes if isinstance(axes, list) else []:
                    lines = ax.get("lines") if isinstance(ax, dict) else None
                    if isinstance(lines, list) and len(lines) > CAPS["lines"]:
                        raise TooLarge(f"an axes with {len(lines)} lines (at most {CAPS['lines']})")
            stack.extend(item.values())


# in the child ----------------------------------------------------------------------------------


def _assigns(source: str, name: str) -> bool:
    """Whether the code ``source`` assigns ``name`` (at any depth; ``=``, ``for``, ``with``...)."""
    try:
        tree = ast.parse(source)
    except (SyntaxError, ValueError, RecursionError, MemoryError):
        return re.search(rf"^\s*{re.escape(name)}\s*=(?!=)", source, re.M) is not None
    return any(
        isinstance(node, ast.Name) and node.id == name and isinstance(node.ctx, ast.Store)
        for node in ast.walk(tree)
    )


def _missing(name: str, position: int | None, errors: list[dict[str, Any]]) -> Any:
    """Why ``name`` is absent at ``position``: the cell that raised before it, if any."""
    from .lab_checks import Missing  # deferred on purpose: the child imports the checks

    before = [e for e in errors if position is None or e["position"] < position]
    if not before:
        return Missing(name)
    culprit = next((e for e in reversed(before) if _assigns(e["source"], name)), None)
    if culprit is None:  # a check cell's error follows from an earlier one
        culprit = ([e for e in before if not e["is_check"]] or before)[-1]
    return Missing(name, culprit["cell"], culprit["ename"], culprit["evalue"])


def check_answers(request: Mapping[str, Any]) -> dict[str, Any]:
    """Parse, measure, rebuild and check the answers of one hand-in (what the child runs).

    Parameters
    ----------
    request : mapping
        ``checks`` (the lab's check cells, ``LabChecks.to_dict()``), ``params``,
        ``positions`` (capture tag -> cell), ``errors`` (the cells that raised,
        as dicts) and ``captures`` (tag -> answer text).

    Returns
    -------
    dict
        ``results`` (list of dict), ``notes`` (list of str), ``over`` (bool).
    """
    from ..checks.answers import AnswerError, from_data, parse  # deferred: the child only
    from .lab_checks import LabChecks, Missing, grade_answers, lab_plant, setup_namespace

    checks = LabChecks.from_dict(request["checks"])
    lab, params = checks.lab, request["params"]
    positions, errors = request["positions"], request["errors"]
    notes: list[str] = []
    over = False
    parsed: dict[str, dict[str, Any] | None] = {}
    for tag, text in request["captures"].items():
        try:
            parsed[tag] = parse(text)
        except AnswerError as err:
            notes.append(f"the answers after one check could not be read ({err})")
            parsed[tag] = None
    namespace = setup_namespace(checks, params)
    plant = namespace.get("plant")
    if plant is None:
        plant = lab_plant(lab, params)
    cache: dict[tuple[str, str], Any] = {}

    def rebuild(tag: str, name: str) -> Any:
        nonlocal over
        if (tag, name) not in cache:
            raw = parsed.get(tag) or {}
            if name not in raw:
                cache[(tag, name)] = _missing(name, positions.get(tag), errors)
            else:
                try:
                    measure(raw[name])
                    cache[(tag, name)] = from_data(raw[name], plant=plant)
                except TooLarge as err:
                    over = True
                    note = f"{name} is too large to grade: {err}"
                    if note not in notes:
                        notes.append(note)
                    cache[(tag, name)] = Missing(name, reason=f"it is too large to grade ({err})")
                except (AnswerError, ValueError, TypeError) as err:
                    why = err if isinstance(err, AnswerError) else type(err).__name__
                    cache[(tag, name)] = Missing(
                        name, reason=f"its value could not be read ({why})"
                    )
        return cache[(tag, name)]

    every = checks.names
    if parsed.get("final") is not None:
        final = {n: rebuild("final", n) for n in every}
    else:
        final = {n: _missing(n, None, errors) for n in every}
    per_check = []
    for index, check in enumerate(checks.checks):
        tag = str(index)
        if parsed.get(tag) is not None:
            per_check.append({n: rebuild(tag, n) for n in check.names})
        else:  # its check cell was deleted or never reached: what the notebook ended with
            per_check.append({n: final[n] for n in check.names})
    results = grade_answers(checks, final, params, per_check=per_check, namespace=namespace)
    return {"results": [r.to_dict() for r in results], "notes": notes, "over": over}


def _limit(memory_mb: int, cpu_seconds: int) -> None:
    import resource  # deferred on purpose: POSIX only

    for what, value in (
        (resource.RLIMIT_AS, memory_mb * 1024 * 1024),
        (resource.RLIMIT_CPU, cpu_seconds),
        (resource.RLIMIT_CORE, 0),
    ):
        _, hard = resource.getrlimit(what)
        if hard != resource.RLIM_INFINITY:
            value = min(value, hard)
        try:
            resource.setrlimit(what, (value, hard if what == resource.RLIMIT_CPU else value))
        except (ValueError, OSError):
            pass


def main(argv: list[str]) -> int:
    """The child: ``--check MEMORY_MB CPU_SECONDS``, the request on stdin, the answer on stdout.

    Parameters
    ----------
    argv : list of str

    Returns
    -------
    int
    """
    if len(argv) != 3 or argv[0] != "--check":
        print("usage: python -m uio_teach.grading.checking --check MEMORY_MB CPU_SECONDS")
        return 2
    _limit(int(argv[1]), int(argv[2]))
    request = json.loads(sys.stdin.buffer.read())
    try:
        answer = check_answers(request)
    except MemoryError:
        answer = {"memory": True}
    sys.stdout.write(json.dumps(answer))
    sys.stdout.flush()
    return 0


# in the grader ---------------------------------------------------------------------------------


def check_in_child(
    request: Mapping[str, Any],
    *,
    timeout: float,
    memory_mb: int,
    stop: threading.Event | None = None,
) -> CheckOutcome:
    """Run :func:`check_answers` in a child process under limits; never raises for the answers.

    Parameters
    ----------
    request : mapping
        See :func:`check_answers`.
    timeout : float
        Seconds the checks may take (then the child is killed).
    memory_mb : int
        Address space of the child (MiB).
    stop : threading.Event, optional
        When set (the grading run was interrupted), the child is killed at once.

    Returns
    -------
    CheckOutcome

    Raises
    ------
    InterruptedError
        ``stop`` was set while the checks ran.
    """
    env = dict(os.environ, OPENBLAS_NUM_THREADS="1", OMP_NUM_THREADS="1", MPLBACKEND="Agg")
    command = [sys.executable, "-m", "uio_teach.grading.checking", "--check"]
    command += [str(int(memory_mb)), str(int(timeout) + 5)]
    with tempfile.TemporaryFile() as data:  # the request, read by the child as its stdin
        data.write(json.dumps(request).encode())
        data.seek(0)
        proc = subprocess.Popen(
            command,
            stdin=data,
            stdout=subprocess.PIPE,
            stderr=subprocess.PIPE,
            env=env,
            start_new_session=True,
        )
    deadline = time.monotonic() + timeout
    out = err = b""
    try:
        while True:
            if stop is not None and stop.is_set():
                raise InterruptedError("the grading run was interrupted")
            left = deadline - time.monotonic()
            if left <= 0:
                return CheckOutcome(
                    notes=[f"checking the answers took longer than {timeout:g} s: stopped"],
                    over=True,
                )
            try:
                out, err = proc.communicate(timeout=min(left, 0.25))
                break
            except subprocess.TimeoutExpired:
                pass
    finally:
        if proc.poll() is None:
            proc.kill()
        proc.wait()
    try:
        answer = json.loads(out)
    except ValueError:
        answer = None
    if not isinstance(answer, dict) or answer.get("memory"):
        lines = [x for x in err.decode("utf-8", "replace").splitlines() if x.strip()]
        if answer or "MemoryError" in (lines[-1] if lines else ""):
            why = f"needed more than {memory_mb} MB of memory"
        else:
            why = f"stopped ({lines[-1][:160] if lines else f'exit status {proc.returncode}'})"
        return CheckOutcome(notes=[f"checking the answers {why}"], over=True)
    return CheckOutcome(
        results=list(answer.get("results", [])),
        notes=[str(n) for n in answer.get("notes", [])],
        over=bool(answer.get("over")),
    )


if __name__ == "__main__":  # pragma: no cover - the process check_in_child starts
    sys.exit(main(sys.argv[1:]))
