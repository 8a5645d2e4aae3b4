"""A lab group's answers as plain data: out of the student's kernel, back as real objects.

The grader never trusts objects made by the student's code: it turns the named
answer variables of the kernel into plain data (:func:`to_data`, run inside
the kernel), carries them out as JSON (:func:`dumps` / :func:`loads`; arrays
as base64 bytes with their dtype and shape, never a pickle), and rebuilds, in
its own process, genuine objects of the package (:func:`from_data`), so the
check functions of :mod:`uio_teach.checks` run on them unchanged:

* numbers, strings, ``None``, lists, tuples and dicts (string keys);
* NumPy arrays (bool, integer, real and complex) and NumPy scalars;
* a :class:`~uio_teach.Plant` (its matrices, ``dt`` and name);
* observers (class name, plant and the matrices they are built from), rebuilt
  with the package's own constructors;
* simulation results (:class:`~uio_teach.UIOResponse`: time points, states,
  estimates, outputs, the inputs u, d, v and the noise, the observer's state,
  the observer and the plant) and reconstructions
  (:class:`~uio_teach.InputEstimate`);
* matplotlib figures: per axes its position, limits, scales, title, x- and
  y-label, legend texts and the x/y data and label of every line, rebuilt as
  a real Agg figure.

Anything else becomes a marker that :func:`from_data` turns into
:class:`Unsupported` (a check then says what it got). The data is untrusted:
:func:`from_data` accepts only the shapes above, refuses arrays with more than
:data:`MAX_ELEMENTS` entries and trees deeper than :data:`MAX_DEPTH`.

Examples
--------
>>> import numpy as np
>>> import uio_teach as ut
>>> from uio_teach.checks import answers
>>> plant = ut.examples.pa9()
>>> obs = ut.design_uio(plant, poles=[-1, -2, -3])
>>> text = answers.dumps({"H": obs.H, "observer": obs, "poles": [-1, -2, -3]})
>>> back = answers.loads(text)
>>> type(back["observer"]).__name__, bool(np.array_equal(back["H"], obs.H))
('UIO', True)
>>> bool(np.allclose(back["observer"].F, obs.F))
True
"""

from __future__ import annotations

import base64
import json
import math
from collections.abc import Mapping
from typing import Any

import numpy as np

from ..errors import UIOTeachError
from ..observers import PMO, UIO, GInverseObserver, LuenbergerObserver, Observer
from ..plant import Plant
from ..reconstruction import InputEstimate
from ..simulation import SimulationInputs, UIOResponse

__all__ = [
    "AnswerError",
    "Unsupported",
    "to_data",
    "from_data",
    "dumps",
    "loads",
    "parse",
    "MAX_DEPTH",
    "MAX_ELEMENTS",
    "FORMAT",
]

FORMAT = "uio-teach answers 1"
"""The ``format`` field of :func:`dumps`'s JSON."""
MAX_DEPTH = 32
"""The deepest nesting of lists and dicts accepted."""
MAX_ELEMENTS = 20_000_000
"""The largest array accepted (entries)."""

_DTYPES = {"bool": "?", "int64": "<i8", "float64": "<f8", "complex128": "<c16"}
_TAG = "__uio__"


class AnswerError(UIOTeachError, ValueError):
    """The data is not a valid answer export (one line, never the data itself)."""


class Unsupported:
    """An answer of a kind that is not carried out of the kernel (only its type is known).

    Parameters
    ----------
    type_name : str
        The type of the value in the student's kernel.

    Examples
    --------
    >>> from uio_teach.checks.answers import Unsupported
    >>> Unsupported("Generator")
    <a Generator (not carried out of the notebook)>
    """

    def __init__(self, type_name: str) -> None:
        self.type_name = type_name

    def __repr__(self) -> str:
        return f"<a {self.type_name} (not carried out of the notebook)>"


# to data (runs in the student's kernel) ---------------------------------------------------------


def _array(value: Any) -> dict[str, Any]:
    arr = np.asarray(value)
    if arr.dtype == bool:
        kind = "bool"
    elif np.issubdtype(arr.dtype, np.integer):
        kind = "int64"
    elif np.issubdtype(arr.dtype, np.complexfloating):
        kind = "complex128"
    elif np.issubdtype(arr.dtype, np.number):
        kind = "float64"
    else:
        return {_TAG: "unsupported", "type": f"array of {arr.dtype}"}
    data = np.ascontiguousarray(arr, dtype=_DTYPES[kind])
    return {
        _TAG: "array",
        "dtype": kind,
        "shape": list(arr.shape),
        "data": base64.b64encode(data.tobytes()).decode("ascii"),
    }


def _plant(plant: Plant) -> dict[str, Any]:
    return {
        _TAG: "plant",
        "A": _array(plant.A),
        "B": _array(plant.B),
        "C": _array(plant.C),
        "E": _array(plant.E),
        "D": _array(plant.D),
        "dt": plant.dt,
        "name": getattr(plant, "name", None),
    }


def _observer(obs: Observer) -> dict[str, Any]:
    kind = type(obs).__name__
    out: dict[str, Any] = {_TAG: "observer", "class": kind, "plant": _plant(obs.plant)}
    names = {
        "UIO": ("H", "K1"),
        "PMO": ("M", "L", "Mv", "lmi_certificate"),
        "GInverseObserver": ("Kv",),
        "LuenbergerObserver": ("L",),
    }.get(kind, ())
    for name in names:
        value = getattr(obs, name, None)
        out[name] = None if value is None else _array(value)
    out["F"] = _array(obs.error_matrix)
    return out


def _time_of(obj: Any) -> Any:
    return getattr(obj, "timepts", None) if hasattr(obj, "timepts") else obj.time


def _response(resp: UIOResponse) -> dict[str, Any]:
    inputs = resp.inputs
    return {
        _TAG: "response",
        "timepts": _array(_time_of(resp)),
        "states": _array(resp.states),
        "outputs": _array(resp.outputs),
        "estimates": _array(resp.estimates),
        "inputs": {name: _array(getattr(inputs, name)) for name in SimulationInputs._fields},
        "observer_states": _array(resp.observer_states),
        "observer": _observer(resp.observer),
        "plant": _plant(resp.plant),
    }


def _estimate(est: InputEstimate) -> dict[str, Any]:
    return {
        _TAG: "input_estimate",
        "timepts": _array(_time_of(est)),
        "estimates": _array(est.estimates),
        "actual": None if est.actual is None else _array(est.actual),
        "method": str(est.method),
        "tau": None if est.tau is None else float(est.tau),
        "dt": est.dt,
    }


def _texts(items: Any) -> list[str]:
    return [str(t.get_text()) for t in items]


def _figure(fig: Any) -> dict[str, Any]:
    axes = list(fig.axes)
    groups: list[int] = []
    for i, ax in enumerate(axes):
        shared = ax.get_shared_x_axes()
        # an axes that shares its x with none is its own group (joined(ax, ax) can be False)
        groups.append(next((j for j in range(i) if shared.joined(ax, axes[j])), i))
    out_axes = []
    for ax, group in zip(axes, groups, strict=True):
        legend = ax.get_legend()
        box = ax.get_position()
        out_axes.append(
            {
                "position": [box.x0, box.y0, box.width, box.height],
                "sharex": group,
                "title": [ax.get_title(loc) for loc in ("center", "left", "right")],
                "xlabel": ax.get_xlabel(),
                "ylabel": ax.get_ylabel(),
                "xscale": ax.get_xscale(),
                "yscale": ax.get_yscale(),
                "xlim": [float(v) for v in ax.get_xlim()],
                "ylim": [float(v) for v in ax.get_ylim()],
                "legend": None if legend is None else _texts(legend.get_texts()),
                "lines": [
                    {
                        "x": _array(np.asarray(line.get_xdata(), float)),
                        "y": _array(np.asarray(line.get_ydata(), float)),
                        "label": str(line.get_label()),
                    }
                    for line in ax.get_lines()
                ],
            }
        )
    return {
        _TAG: "figure",
        "size": [float(v) for v in fig.get_size_inches()],
        "suptitle": str(fig.get_suptitle()) or None,
        "legends": [_texts(leg.get_texts()) for leg in getattr(fig, "legends", [])],
        "axes": out_axes,
    }


def _is_figure(value: Any) -> bool:
    return any(
        cls.__module__ == "matplotlib.figure" and cls.__name__ == "Figure"
        for cls in type(value).__mro__
    )


def to_data(value: Any, _depth: int = 0) -> Any:
    """``value`` as JSON-ready plain data (see the module's list of what is carried).

    Parameters
    ----------
    value : object
        An answer of the student's kernel.

    Returns
    -------
    object
        Plain data: ``None``, bool, int, float, str, list, or a dict tagged
        with its kind.

    Examples
    --------
    >>> import numpy as np
    >>> from uio_teach.checks.answers import to_data
    >>> to_data((1, "a"))
    {'__uio__': 'tuple', 'items': [1, 'a']}
    >>> to_data(np.eye(2))["shape"]
    [2, 2]
    """
    if _depth > MAX_DEPTH:
        return {_TAG: "unsupported", "type": "structure nested too deeply"}
    if value is None or isinstance(value, (bool, str)):
        return value
    if isinstance(value, (int, np.integer)) and not isinstance(value, bool):
        return int(value)
    if isinstance(value, (float, np.floating)):
        return _float(float(value))
    if isinstance(value, (complex, np.complexfloating)):
        return {_TAG: "complex", "re": _float(value.real), "im": _float(value.imag)}
    if isinstance(value, np.bool_):
        return bool(value)
    if isinstance(value, np.ndarray):
        return _array(value)
    if isinstance(value, list):
        return [to_data(v, _depth + 1) for v in value]
    if isinstance(value, tuple):
        return {_TAG: "tuple", "items": [to_data(v, _depth + 1) for v in value]}
    if isinstance(value, Mapping):
        return {
            _TAG: "dict",
            "items": [[str(k), to_data(v, _depth + 1)] for k, v in value.items()],
        }
    try:
        if isinstance(value, UIOResponse):
            return _response(value)
        if isinstance(value, InputEstimate):
            return _estimate(value)
        if isinstance(value, Observer):
            return _observer(value)
        if isinstance(value, Plant):
            return _plant(value)
        if _is_figure(value):
            return _figure(value)
    except Exception as exc:  # a broken object: say what it was, not why
        return {_TAG: "unsupported", "type": f"{type(value).__name__} ({type(exc).__name__})"}
    return {_TAG: "unsupported", "type": type(value).__name__}


def _float(x: float) -> Any:
    return x if math.isfinite(x) else {_TAG: "float", "value": repr(x)}


def dumps(answers: Mapping[str, Any]) -> str:
    """The JSON of the answers ``name -> value`` (what the kernel writes out).

    Parameters
    ----------
    answers : mapping
        Variable name -> value.

    Returns
    -------
    str

    Examples
    --------
    >>> from uio_teach.checks.answers import dumps
    >>> dumps({"x": 2})
    '{"format": "uio-teach answers 1", "answers": {"x": 2}}'
    """
    body = {str(name): to_data(value) for name, value in answers.items()}
    return json.dumps({"format": FORMAT, "answers": body}, allow_nan=False)


# from data (runs in the grader's process) -------------------------------------------------------


def _need(data: Any, key: str, kind: type | tuple[type, ...]) -> Any:
    if not isinstance(data, dict) or key not in data or not isinstance(data[key], kind):
        raise AnswerError(f"malformed answer data: {key!r} missing or of the wrong kind")
    return data[key]


def _from_array(data: Any) -> np.ndarray:
    kind = _need(data, "dtype", str)
    if kind not in _DTYPES:
        raise AnswerError(f"malformed answer data: dtype {kind[:20]!r}")
    shape = _need(data, "shape", list)
    if len(shape) > 8 or not all(isinstance(s, int) and 0 <= s for s in shape):
        raise AnswerError("malformed answer data: an array shape")
    size = math.prod(shape)
    if size > MAX_ELEMENTS:
        raise AnswerError(f"an array of {size} entries is too large to grade")
    raw = base64.b64decode(_need(data, "data", str), validate=True)
    dtype = np.dtype(_DTYPES[kind])
    if len(raw) != size * dtype.itemsize:
        raise AnswerError("malformed answer data: array bytes do not match its shape")
    arr = np.frombuffer(raw, dtype=dtype).reshape(shape).astype(dtype.newbyteorder("="))
    return arr


def _opt_array(data: Any) -> np.ndarray | None:
    return None if data is None else _from_array(data)


def _array_at(data: Any, key: str) -> np.ndarray:
    """The array stored under ``key`` of ``data``."""
    return _from_array(_need(data, key, dict))


def _plant_of(data: Any, plant: Plant | None) -> Plant:
    """``plant``, or the plant stored in ``data`` when it is None."""
    return _from_plant(_need(data, "plant", dict)) if plant is None else plant


def _timed(cls: type, t: np.ndarray, kwargs: dict[str, Any]) -> Any:
    """``cls(timepts=t, **kwargs)``, or ``time=t`` where this version of the package names it so."""
    try:
        return cls(timepts=t, **kwargs)
    except TypeError:
        return cls(time=t, **kwargs)


def _from_plant(data: Any) -> Plant:
    dt = data.get("dt") if isinstance(data, dict) else None
    if not (dt is None or isinstance(dt, (bool, int, float))):
        raise AnswerError("malformed answer data: a plant's dt")
    name = data.get("name")
    matrices = {k: _array_at(data, k) for k in "ABCED"}
    kwargs: dict[str, Any] = {}
    for k in "BED":  # an empty matrix is an absent one
        if matrices[k].size:
            kwargs[k] = matrices[k]
    return Plant(
        matrices["A"],
        matrices["C"],
        dt=dt,
        name=name if isinstance(name, str) else None,
        **kwargs,
    )


def _from_observer(data: Any, plant: Plant | None) -> Observer:
    kind = _need(data, "class", str)
    plant = _plant_of(data, plant)
    if kind == "UIO":
        return UIO(plant, _array_at(data, "H"), _array_at(data, "K1"))
    if kind == "PMO":
        return PMO(
            plant,
            _array_at(data, "M"),
            _array_at(data, "L"),
            _opt_array(data.get("Mv")),
            _opt_array(data.get("lmi_certificate")),
        )
    if kind == "GInverseObserver":
        return GInverseObserver(plant, _array_at(data, "Kv"))
    if kind == "LuenbergerObserver":
        return LuenbergerObserver(plant, _array_at(data, "L"))
    raise AnswerError(f"an observer of an unknown kind ({kind[:40]})")


def _from_response(data: Any, plant: Plant | None) -> UIOResponse:
    plant = _plant_of(data, plant)
    observer = _from_observer(_need(data, "observer", dict), plant)
    raw_inputs = _need(data, "inputs", dict)
    inputs = SimulationInputs(
        **{name: _array_at(raw_inputs, name) for name in SimulationInputs._fields}
    )
    kwargs = {
        "states": _array_at(data, "states"),
        "outputs": _array_at(data, "outputs"),
        "estimates": _array_at(data, "estimates"),
        "inputs": inputs,
        "observer_states": _array_at(data, "observer_states"),
        "plant": plant,
        "observer": observer,
    }
    return _timed(UIOResponse, _array_at(data, "timepts"), kwargs)


def _from_estimate(data: Any) -> InputEstimate:
    tau = data.get("tau")
    dt = data.get("dt")
    if not (tau is None or isinstance(tau, (int, float))) or not (
        dt is None or isinstance(dt, (bool, int, float))
    ):
        raise AnswerError("malformed answer data: a reconstruction's tau or dt")
    kwargs = {
        "estimates": _array_at(data, "estimates"),
        "actual": _opt_array(data.get("actual")),
        "method": str(_need(data, "method", str)),
        "tau": tau,
        "dt": dt,
    }
    return _timed(InputEstimate, _array_at(data, "timepts"), kwargs)


def _strings(value: Any, what: str) -> list[str]:
    if not isinstance(value, list) or not all(isinstance(s, str) for s in value):
        raise AnswerError(f"malformed answer data: {what}")
    return value


def _from_figure(data: Any) -> Any:
    # deferred on purpose: matplotlib is needed only for answers that are figures
    from matplotlib.backends.backend_agg import FigureCanvasAgg  # deferred: see above
    from matplotlib.figure import Figure  # deferred: see above
    from matplotlib.lines import Line2D  # deferred: see above

    size = _need(data, "size", list)
    fig = Figure(figsize=tuple(float(v) for v in size[:2]) if len(size) >= 2 else None)
    FigureCanvasAgg(fig)
    made: list[Any] = []
    for spec in _need(data, "axes", list):
        position = [float(v) for v in _need(spec, "position", list)][:4]
        group = spec.get("sharex")
        share = made[group] if isinstance(group, int) and 0 <= group < len(made) else None
        ax = fig.add_axes(position, sharex=share)
        for line in _need(spec, "lines", list):
            label = _need(line, "label", str)
            ax.plot(_array_at(line, "x"), _array_at(line, "y"), label=label)
        titles = _strings(spec.get("title", ["", "", ""]), "a title")
        for loc, text in zip(("center", "left", "right"), titles, strict=False):
            if text:
                ax.set_title(text, loc=loc)
        ax.set_xlabel(str(_need(spec, "xlabel", str)))
        ax.set_ylabel(str(_need(spec, "ylabel", str)))
        for setter, key in ((ax.set_xscale, "xscale"), (ax.set_yscale, "yscale")):
            scale = spec.get(key, "linear")
            if scale in ("linear", "log", "symlog", "logit"):
                setter(scale)
        for setter, key in ((ax.set_xlim, "xlim"), (ax.set_ylim, "ylim")):
            lim = spec.get(key)
            if isinstance(lim, list) and len(lim) == 2:
                lo, hi = (float(v) for v in lim)
                if math.isfinite(lo) and math.isfinite(hi) and lo != hi:
                    setter(lo, hi)
        legend = spec.get("legend")
        if legend is not None:
            texts = _strings(legend, "a legend")
            ax.legend(handles=[Line2D([], []) for _ in texts], labels=texts)
        made.append(ax)
    suptitle = data.get("suptitle")
    if isinstance(suptitle, str):
        fig.suptitle(suptitle)
    for texts in data.get("legends", []) or []:
        texts = _strings(texts, "a figure legend")
        fig.legend(handles=[Line2D([], []) for _ in texts], labels=texts)
    return fig


def from_data(data: Any, *, plant: Plant | None = None, _depth: int = 0) -> Any:
    """Rebuild an answer from the plain data of :func:`to_data`, as genuine package objects.

    Parameters
    ----------
    data : object
        What :func:`to_data` made (untrusted: only its accepted shapes are read).
    plant : Plant, optional
        The plant to rebuild observers and responses on (the grader passes the
        group's plant from the answer key); the plant in the data otherwise.

    Returns
    -------
    object

    Raises
    ------
    AnswerError
        The data is malformed or too large.

    Examples
    --------
    >>> import numpy as np
    >>> from uio_teach.checks.answers import from_data, to_data
    >>> back = from_data(to_data({"K": np.array([[1 + 2j]]), "n": [1, 2.5]}))
    >>> back["K"].dtype, back["n"]
    (dtype('complex128'), [1, 2.5])
    """
    if _depth > MAX_DEPTH:
        raise AnswerError("answer data nested too deeply")
    if data is None or isinstance(data, (bool, int, float, str)):
        return data
    if isinstance(data, list):
        return [from_data(v, plant=plant, _depth=_depth + 1) for v in data]
    if not isinstance(data, dict) or not isinstance(data.get(_TAG), str):
        raise AnswerError("malformed answer data: an untagged object")
    kind = data[_TAG]
    if kind == "array":
        return _from_array(data)
    if kind == "float":
        value = _need(data, "value", str)
        if value not in ("nan", "inf", "-inf"):
            raise AnswerError("malformed answer data: a float")
        return float(value)
    if kind == "complex":
        re, im = (from_data(data.get(k), _depth=_depth + 1) for k in ("re", "im"))
        if not isinstance(re, (int, float)) or not isinstance(im, (int, float)):
            raise AnswerError("malformed answer data: a complex number")
        return complex(re, im)
    if kind == "tuple":
        items = _need(data, "items", list)
        return tuple(from_data(v, plant=plant, _depth=_depth + 1) for v in items)
    if kind == "dict":
        out = {}
        for pair in _need(data, "items", list):
            if not (isinstance(pair, list) and len(pair) == 2 and isinstance(pair[0], str)):
                raise AnswerError("malformed answer data: a dict entry")
            out[pair[0]] = from_data(pair[1], plant=plant, _depth=_depth + 1)
        return out
    if kind == "unsupported":
        return Unsupported(str(data.get("type", "object"))[:80])
    if kind == "plant":
        return _from_plant(data)
    if kind == "observer":
        return _from_observer(data, plant)
    if kind == "response":
        return _from_response(data, plant)
    if kind == "input_estimate":
        return _from_estimate(data)
    if kind == "figure":
        return _from_figure(data)
    raise AnswerError(f"malformed answer data: unknown kind {kind[:20]!r}")


def parse(text: str | bytes) -> dict[str, Any]:
    """The answers ``name -> plain data`` of a JSON text written by :func:`dumps` (not rebuilt).

    Parameters
    ----------
    text : str or bytes
        The JSON.

    Returns
    -------
    dict

    Raises
    ------
    AnswerError
        The text is not an answer export.

    Examples
    --------
    >>> from uio_teach.checks.answers import dumps, parse
    >>> parse(dumps({"x": 2.5}))
    {'x': 2.5}
    """
    try:
        doc = json.loads(text)
    except (ValueError, RecursionError):
        raise AnswerError("the answers are not valid JSON") from None
    if not isinstance(doc, dict) or doc.get("format") != FORMAT:
        raise AnswerError("the answers are not an export of this grader")
    body = doc.get("answers")
    if not isinstance(body, dict):
        raise AnswerError("malformed answer data: no answers")
    return {str(k): v for k, v in body.items()}


def loads(text: str | bytes, *, plant: Plant | None = None) -> dict[str, Any]:
    """The answers ``name -> object`` of a JSON text written by :func:`dumps`.

    Parameters
    ----------
    text : str or bytes
        The JSON.
    plant : Plant, optional
        See :func:`from_data`.

    Returns
    -------
    dict

    Raises
    ------
    AnswerError
        The text is not an answer export.

    Examples
    --------
    >>> from uio_teach.checks.answers import dumps, loads
    >>> loads(dumps({"x": (1, 2)}))
    {'x': (1, 2)}
    """
    return {k: from_data(v, plant=plant) for k, v in parse(text).items()}
