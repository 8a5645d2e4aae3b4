"""Variants of the labs, one per group, and their answer key.

:func:`draw_variants` draws distinct parameter sets of a lab, each a fair
exercise (see the ``problems()`` of each lab's parameter class, in its worked
example's module), from a seed; :func:`write_answer_key`
writes the expected matrices and numbers of every (lab, group) to a CSV file.

Examples
--------
>>> from uio_teach.instructor.lab_registry import LABS
>>> from uio_teach.instructor.variants import draw_variants
>>> [v.to_params()["poles"] for v in draw_variants(LABS["pa9"], 2, seed=5)] != []
True
"""

from __future__ import annotations

import csv
import hashlib
import json
from collections.abc import Sequence
from pathlib import Path
from typing import Any

import numpy as np

from .lab_registry import LabUsageError

__all__ = ["ANSWER_KEY", "draw_variants", "lab_stream", "write_answer_key"]

ANSWER_KEY = "answer_key.csv"
"""The file name of the answer key in the output folder."""


def lab_stream(lab_id: str) -> int:
    """The lab's own stream of random numbers under a seed: a stable hash of its id.

    The variants of a lab depend on the seed, this number and the group
    only, never on where the lab stands among the others: registering,
    removing or reordering another lab changes no group's numbers. The hash
    is SHA-256 of the id (not Python's ``hash``, which changes between runs).

    Parameters
    ----------
    lab_id : str
        The lab's id (``"pa9"``, ...).

    Returns
    -------
    int
        A non-negative 64-bit integer.

    Examples
    --------
    >>> from uio_teach.instructor.variants import lab_stream
    >>> lab_stream("pa9") == lab_stream("pa9") != lab_stream("missile")
    True
    """
    return int.from_bytes(hashlib.sha256(lab_id.encode("utf-8")).digest()[:8], "big")


def draw_variants(lab: Any, groups: int, seed: int, base: Any = None) -> list[Any]:
    """``groups`` distinct parameter sets of ``lab``, each a fair exercise, from ``seed``.

    Each variant is drawn by the lab's parameter class (``draw``) and kept
    only if it is a fair exercise (``problems()`` is empty: for the plant,
    the package's existence check and designs succeed) and shares nothing of
    its ``distinct()`` (poles, plant matrices that decide the answers) with
    a variant already kept, so that no two groups have the same answers.
    The draw depends on ``seed``, the lab's id (:func:`lab_stream`) and the
    number of groups drawn before, nothing else: the other labs of the
    course, their number and their order do not change a group's numbers.

    Parameters
    ----------
    lab : Lab
        The lab (an entry of :data:`~uio_teach.instructor.labs.LABS`).
    groups : int
        How many variants.
    seed : int
        Seed of the draw; the same seed gives the same variants.
    base : LabParams, optional
        What the variants keep (time grid, ...): the term's parameters.

    Returns
    -------
    list
        Parameter objects of ``lab.params``.

    Examples
    --------
    >>> from uio_teach.instructor.lab_registry import LABS
    >>> from uio_teach.instructor.variants import draw_variants
    >>> a, b = draw_variants(LABS["pa9"], 2, seed=5)
    >>> a != b and not a.problems() and not b.problems()
    True
    """
    rng = np.random.default_rng([int(seed), lab_stream(lab.id)])
    out: list[Any] = []
    # the course's own numbers (the book's solutions) are no group's
    seen: dict[str, set[Any]] = {k: {v} for k, v in lab.params().distinct().items()}
    # why draws were thrown away, by what collided (for the message when too few are left)
    refused: dict[str, int] = {}
    for _ in range(1000 * max(1, groups)):
        if len(out) == groups:
            break
        variant = lab.params.draw(rng, base)
        keys = {"params": repr(variant.to_params()), **variant.distinct()}
        clash = [name for name, value in keys.items() if value in seen.get(name, ())]
        if clash:
            for name in clash:
                refused[name] = refused.get(name, 0) + 1
            continue
        problems = variant.problems()
        if problems:
            for problem in problems:
                refused[problem] = refused.get(problem, 0) + 1
            continue
        for name, value in keys.items():
            seen.setdefault(name, set()).add(value)
        out.append(variant)
    if len(out) < groups:
        common = sorted(refused.items(), key=lambda item: -item[1])[:3]
        why = "; ".join(
            f"{count} draws shared their {name} with the book's or an earlier group's"
            if name in seen
            else f"{count} draws were no fair exercise ({name})"
            for name, count in common
        )
        raise LabUsageError(
            f"cannot draw {groups} distinct variants of the {lab.id} lab, only {len(out)} "
            f"({why or 'nothing was drawn'}); give fewer groups"
        )
    return out


def write_answer_key(path: Path, rows: Sequence[tuple[Any, str, Any]]) -> Path:
    """Write the answer key CSV: ``lab``, ``group``, ``params``, then one column per key number.

    Parameters
    ----------
    path : pathlib.Path
        The CSV file.
    rows : sequence of (Lab, str, LabParams)
        The lab, the group id and its parameters, in order.

    Returns
    -------
    pathlib.Path

    Examples
    --------
    >>> import tempfile, pathlib, csv
    >>> from uio_teach.instructor.lab_registry import LABS
    >>> from uio_teach.instructor.variants import write_answer_key
    >>> from uio_teach.worked.pa9 import PA9Params
    >>> with tempfile.TemporaryDirectory() as tmp:
    ...     key = write_answer_key(pathlib.Path(tmp) / "k.csv", [(LABS["pa9"], "g01", PA9Params())])
    ...     row = next(csv.DictReader(key.open()))
    >>> row["lab"], row["group"], row["pa9.K2"] != ""
    ('pa9', 'g01', True)
    """
    table = []
    columns: list[str] = []
    for lab, group, params in rows:
        answers = {f"{lab.id}.{k}": v for k, v in params.answers().items()}
        for k in answers:
            if k not in columns:
                columns.append(k)
        record = {"lab": lab.id, "group": group, "params": json.dumps(params.to_params())}
        record.update({k: json.dumps(v) for k, v in answers.items()})
        table.append(record)
    path.parent.mkdir(parents=True, exist_ok=True)
    with path.open("w", newline="", encoding="utf-8") as fh:
        writer = csv.DictWriter(fh, ["lab", "group", "params", *columns], lineterminator="\n")
        writer.writeheader()
        writer.writerows(table)
    return path
