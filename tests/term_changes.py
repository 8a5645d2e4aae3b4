"""A changed, valid value for every key of the term config, derived from its schema.

No list of keys is written here: :func:`changed_values` walks
:func:`uio_teach.instructor.config.config_schema` (every declared field of every
worked example, and the shared keys) and, for each, tries a few changes of its
default by its kind until the config accepts one and every lab it reaches stays
a fair exercise. A key for which none works is returned with ``None`` and the
reason, so that a test names it.
"""

from __future__ import annotations

import functools
from typing import Any

from uio_teach.instructor.config import ConfigError, FigureConfig, config_schema
from uio_teach.instructor.lab_registry import LABS

FACTORS = (1.25, 0.8, 1.5, 0.5, 0.9)


def nested(changes: dict) -> dict:
    out: dict = {}
    for key, value in changes.items():
        *tables, name = key.split(".")
        where = out
        for table in tables:
            where = where.setdefault(table, {})
        where[name] = value
    return out


def leaves(value, path=()):
    if isinstance(value, dict):
        for k, v in value.items():
            yield from leaves(v, (*path, k))
    else:
        yield path, value


def _candidates(opt) -> list[Any]:
    default = opt.default
    kind = opt.kind
    if kind in ("style", "str"):
        return ["ggplot", "grayscale"]  # matplotlib's own styles
    if default is None:
        if kind in ("float", "int"):
            low = opt.minimum if opt.minimum is not None else 0.0
            return [low + 1, low + 0.5] if kind == "float" else [int(low) + 1]
        if kind == "poles":  # inside the unit circle, and stable in continuous time
            return [[-0.3], [0.1], [-2.0, -3.0]]
        return []
    if kind == "int":
        return [default + 1, default - 1, default * 2]
    if kind == "float":
        if default == 0:
            return [0.05, 0.1, 1.0]
        return [default * f for f in FACTORS]
    if kind == "poles":

        def scaled(p, f):
            if isinstance(p, str):
                return str(complex(p.replace(" ", "")) * f).strip("()")
            return p * f

        return [[scaled(p, f) for p in default] for f in FACTORS]
    if kind == "floats":
        return [[v * f for v in default] for f in FACTORS]
    return []


def reached(config: FigureConfig) -> dict[str, list[tuple[str, ...]]]:
    """The labs whose PARAMS ``config`` changes, with the changed PARAMS paths."""
    out = {}
    for lab_id, lab in LABS.items():
        before = dict(leaves(lab.params.from_config(FigureConfig()).to_params()))
        after = dict(leaves(lab.params.from_config(config).to_params()))
        changed = [p for p in after if after[p] != before.get(p)]
        if changed:
            out[lab_id] = changed
    return out


@functools.cache
def changed_values() -> dict[str, tuple[Any, str]]:
    """Every config key: a changed value the config and the labs accept, or ``None`` and why."""
    out: dict[str, tuple[Any, str]] = {}
    for key, opt in config_schema().items():
        why = f"no change of its default {opt.default!r} ({opt.kind}) was found"
        for value in _candidates(opt):
            try:
                config = FigureConfig.from_dict(nested({key: value}))
            except (ConfigError, ValueError) as err:
                why = str(err)
                continue
            problems = [
                p
                for lab_id in reached(config)
                for p in LABS[lab_id].params.from_config(config).problems()
            ]
            if problems:
                why = "; ".join(problems)
                continue
            out[key] = (value, "")
            break
        else:
            out[key] = (None, why)
    return out
