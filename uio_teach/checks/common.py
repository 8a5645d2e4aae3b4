"""What every lab check shares: the result (:class:`CheckResult`) and the helpers that read answers.

Examples
--------
>>> from uio_teach.checks import CheckResult
>>> r = CheckResult("Demo")
>>> r.add(True, "H has the right shape.")
>>> r.passed
True
"""

from __future__ import annotations

import functools
import html
from collections.abc import Callable, Iterable
from typing import Any, TypeVar

import numpy as np

from .. import examples
from .. import tolerances as tols
from ..linalg import is_stable, sort_poles
from ..plant import Plant
from ..simulation import simulate

__all__ = [
    "CheckResult",
    "collected",
    "clear_collected",
    "never_raises",
    "likely_cause",
    "numbers",
    "up_to",
    "plural",
    "maxdiff",
    "close",
    "chopped",
    "looks_two_decimals",
    "read_matrix",
    "get_plant",
    "stability",
    "read_response",
    "rerun_without_unknown_inputs",
    "same_plant",
    "check_plant_of",
    "same_poles",
    "same_observer",
    "as_poles",
]

_SYMBOL = {True: "✓", False: "✗", None: "•"}
_COLOUR = {True: "#1a7f37", False: "#cf222e", None: "#57606a"}


class CheckResult:
    """The outcome of a check: a list of messages, each marked ✓ (right), ✗ (wrong) or • (note).

    Parameters
    ----------
    title : str
        What was checked.
    items : iterable of (bool or None, str), optional
        The verdicts: ``True`` for a passed check, ``False`` for a failed one,
        ``None`` for a note that does not count either way.
    check_id : str, optional
        A stable name of the check (``"pa9.design"``), the column of a
        gradebook; the check functions set it.

    Attributes
    ----------
    title : str
        What was checked.
    items : list of (bool or None, str)
        The verdicts, in the order they were made.
    check_id : str or None
        The check's stable name.

    Notes
    -----
    A result is printable (``print(result)``), shows as a coloured list in a
    notebook, and is truthy exactly when :attr:`passed` is, so ``assert
    result`` works in a test.

    Examples
    --------
    >>> from uio_teach.checks import CheckResult
    >>> result = CheckResult("demo", [(True, "H is right."), (False, "T is not I - HC.")])
    >>> result.passed
    False
    >>> print(result)
    demo
      ✓ H is right.
      ✗ T is not I - HC.
      => 1 of 2 checks failed. Start with the first ✗: later ones often follow from it.
    """

    def __init__(
        self,
        title: str,
        items: Iterable[tuple[bool | None, str]] = (),
        check_id: str | None = None,
    ) -> None:
        self.title = str(title)
        self.items: list[tuple[bool | None, str]] = [(ok, str(msg)) for ok, msg in items]
        self.check_id = check_id

    def add(self, ok: bool | None, message: str) -> None:
        """Append a verdict.

        Parameters
        ----------
        ok : bool or None
            ``True`` for a passed check (✓), ``False`` for a failed one (✗),
            ``None`` for a note (•).
        message : str
            What was found, in plain words.

        Examples
        --------
        >>> from uio_teach.checks import CheckResult
        >>> result = CheckResult("demo")
        >>> result.add(True, "H is right.")
        >>> result.messages
        ['✓ H is right.']
        """
        self.items.append((None if ok is None else bool(ok), str(message)))

    @property
    def passed(self) -> bool:
        """True if at least one check was made and none failed."""
        verdicts = [ok for ok, _ in self.items if ok is not None]
        return bool(verdicts) and all(verdicts)

    @property
    def messages(self) -> list[str]:
        """Every message with its mark (``"✓ ..."``, ``"✗ ..."`` or ``"• ..."``)."""
        return [f"{_SYMBOL[ok]} {msg}" for ok, msg in self.items]

    @property
    def failures(self) -> list[str]:
        """The messages of the failed checks (without the mark)."""
        return [msg for ok, msg in self.items if ok is False]

    def _verdict(self) -> str:
        counted = [ok for ok, _ in self.items if ok is not None]
        failed = counted.count(False)
        if not counted:
            return "Nothing could be checked."
        if failed == 0:
            return f"All {len(counted)} checks passed."
        return (
            f"{failed} of {len(counted)} checks failed. "
            "Start with the first ✗: later ones often follow from it."
        )

    def to_dict(self) -> dict[str, Any]:
        """The result as JSON-compatible data: ``check_id``, ``title``, ``passed``, ``items``.

        Each item is ``{"ok": True, False or None, "message": str}``.

        Examples
        --------
        >>> from uio_teach.checks import CheckResult
        >>> CheckResult("demo", [(True, "H is right.")], check_id="pa9.design").to_dict()
        {'check_id': 'pa9.design', 'title': 'demo', 'passed': True, 'items': [{'ok': True, \
'message': 'H is right.'}]}
        """
        return {
            "check_id": self.check_id,
            "title": self.title,
            "passed": self.passed,
            "items": [{"ok": ok, "message": msg} for ok, msg in self.items],
        }

    def __bool__(self) -> bool:
        return self.passed

    def __str__(self) -> str:
        lines = [self.title] + [f"  {m}" for m in self.messages]
        lines.append(f"  => {self._verdict()}")
        return "\n".join(lines)

    __repr__ = __str__

    def _repr_html_(self) -> str:
        rows = "".join(
            f'<li style="list-style:none;color:{_COLOUR[ok]}">'
            f"<b>{_SYMBOL[ok]}</b> {html.escape(msg)}</li>"
            for ok, msg in self.items
        )
        colour = _COLOUR[True] if self.passed else _COLOUR[False]
        return (
            f'<div class="uio-check"><b>{html.escape(self.title)}</b>'
            f'<ul style="padding-left:0.5em;margin:0.3em 0">{rows}</ul>'
            f'<b style="color:{colour}">&rArr; {html.escape(self._verdict())}</b></div>'
        )


_F = TypeVar("_F", bound=Callable[..., CheckResult])

_COLLECTED: list[CheckResult] = []


def collected() -> list[CheckResult]:
    """Every result the check functions returned in this process, in order.

    A grader runs a notebook and reads this list at the end (see
    :func:`clear_collected`).

    Returns
    -------
    list of CheckResult
        A copy; the results themselves are shared.

    Examples
    --------
    >>> from uio_teach import checks
    >>> checks.clear_collected()
    >>> _ = checks.pa9_design(None, None, None)
    >>> [(r.check_id, r.passed) for r in checks.collected()]
    [('pa9.design', False)]
    """
    return list(_COLLECTED)


def clear_collected() -> None:
    """Forget the results :func:`collected` returns.

    Examples
    --------
    >>> from uio_teach import checks
    >>> checks.clear_collected()
    >>> checks.collected()
    []
    """
    _COLLECTED.clear()


def _default_check_id(name: str) -> str:
    """``pa9_design`` -> ``pa9.design``: the lab's id, a dot, the rest of the function's name.

    The ids are the worked examples' names, read from the registry (the
    longest first, so that ``case_study_lmi`` is the case study's).
    """
    # deferred: the registry is read once the first check is declared
    from ..worked import WORKED

    for prefix in sorted(WORKED, key=len, reverse=True):
        if name.startswith(prefix + "_"):
            return f"{prefix}.{name[len(prefix) + 1 :]}"
    return name


def likely_cause(exc: BaseException) -> str:
    """A plain-words guess at what in a student's answer made a check raise ``exc``.

    Parameters
    ----------
    exc : BaseException
        The exception a check raised while reading an answer.

    Returns
    -------
    str
        One sentence naming the likely mistake.

    Examples
    --------
    >>> from uio_teach.checks.common import likely_cause
    >>> likely_cause(ValueError("matmul: dimension mismatch"))[:36]
    'a matrix or signal of the wrong size'
    """
    text = str(exc).lower()
    if isinstance(exc, (ValueError, TypeError)) and any(
        w in text for w in ("string", "str'", "could not convert")
    ):
        return "text where numbers are expected (write numbers, or take them from PARAMS)"
    if isinstance(exc, AttributeError):
        return (
            "an argument is not the kind of object asked for (e.g. a matrix where a "
            "simulation result is expected, or the other way round)"
        )
    if isinstance(exc, (ValueError, IndexError)) and any(
        w in text for w in ("shape", "dimension", "broadcast", "size", "index", "mismatch")
    ):
        return "a matrix or signal of the wrong size (check the shapes of your answers)"
    if isinstance(exc, TypeError):
        return (
            "an argument of the wrong type (a function, a string or None where numbers or a "
            "result are expected)"
        )
    if isinstance(exc, (ValueError, ArithmeticError, np.linalg.LinAlgError)):
        return "numbers that cannot be used as given (not finite, singular or of the wrong size)"
    return "an argument that is not what the exercise asks for"


def never_raises(title: str, check_id: str | None = None) -> Callable[[_F], _F]:
    """Turn any unexpected exception of a check into a ✗ naming the likely cause.

    The result gets ``check_id`` (default: from the function's name, ``pa9_design`` ->
    ``pa9.design``) and is recorded for :func:`collected`.

    Parameters
    ----------
    title : str
        The title of the result made when the check raises.
    check_id : str, optional
        The check's stable name.

    Returns
    -------
    callable
        A decorator for a check function.

    Examples
    --------
    >>> from uio_teach.checks.common import CheckResult, never_raises
    >>> @never_raises("demo", check_id="demo.value")
    ... def check_value(x):
    ...     return CheckResult("demo", [(x + 1 == 3, "x is 2")])
    >>> print(check_value("two").failures[0][:45])
    the check could not read your answer: an argu
    """

    def decorate(func: _F) -> _F:
        ident = check_id or _default_check_id(func.__name__)

        @functools.wraps(func)
        def wrapper(*args: Any, **kwargs: Any) -> CheckResult:
            try:
                result = func(*args, **kwargs)
            except Exception as exc:  # a student must never see a traceback here
                result = CheckResult(
                    title,
                    [
                        (
                            False,
                            f"the check could not read your answer: {likely_cause(exc)}. "
                            f"({type(exc).__name__}: {str(exc)[:120]}) Compare your call "
                            f"with the example in help(checks.{func.__name__}).",
                        )
                    ],
                )
            if isinstance(result, CheckResult):
                if check_id or result.check_id is None:
                    result.check_id = ident
                _COLLECTED.append(result)
            return result

        wrapper.check_id = ident  # type: ignore[attr-defined]
        return wrapper  # type: ignore[return-value]

    return decorate


# small helpers --------------------------------------------------------------------------------


def numbers(values: Iterable[float]) -> str:
    """A list of real numbers as Python source: ``[1, -1, 0.5]``.

    Examples
    --------
    >>> from uio_teach.checks.common import numbers
    >>> numbers([1.0, -1, 0.5])
    '[1, -1, 0.5]'
    """
    return "[" + ", ".join(f"{float(np.real(x)):g}" for x in values) + "]"


def up_to(x: float, what: str) -> str:
    """`` (up to rounding)`` for a number that should be zero, else `` (<what> 3e-09)``.

    Examples
    --------
    >>> from uio_teach.checks.common import up_to
    >>> up_to(0.0, "largest entry"), up_to(3e-9, "largest entry")
    (' (up to rounding)', ' (largest entry 3e-09)')
    """
    return " (up to rounding)" if x <= tols.CHECK_ZERO_ATOL else f" ({what} {x:.1g})"


def plural(k: int, word: str) -> str:
    """``k word`` with an ``s`` unless ``k`` is 1.

    Examples
    --------
    >>> from uio_teach.checks.common import plural
    >>> plural(1, "jump"), plural(3, "jump")
    ('1 jump', '3 jumps')
    """
    return f"{k} {word}" + ("" if k == 1 or word.endswith("s") else "s")


def maxdiff(X: np.ndarray, Y: np.ndarray) -> tuple[float, tuple[int, ...]]:
    """The largest entry of ``|X - Y|`` and where it is.

    Examples
    --------
    >>> import numpy as np
    >>> from uio_teach.checks.common import maxdiff
    >>> maxdiff(np.eye(2), np.zeros((2, 2)))
    (1.0, (0, 0))
    """
    D = np.abs(np.asarray(X, float) - np.asarray(Y, float))
    idx = tuple(int(i) for i in np.unravel_index(int(np.argmax(D)), D.shape))
    return float(D[idx]), idx


def close(X: np.ndarray, Y: np.ndarray, tol: float) -> bool:
    """Same shape and every entry within ``tol * max(1, largest entry of Y)``.

    Examples
    --------
    >>> import numpy as np
    >>> from uio_teach.checks.common import close
    >>> close(np.eye(2), np.eye(2) + 1e-9, 1e-6)
    True
    """
    scale = max(1.0, float(np.max(np.abs(Y))) if np.size(Y) else 1.0)
    return np.shape(X) == np.shape(Y) and maxdiff(X, Y)[0] <= tol * scale


def chopped(M: np.ndarray, decimals: int = 2) -> np.ndarray:
    """``M`` with its digits after ``decimals`` cut off (not rounded), as printed in a document.

    Examples
    --------
    >>> from uio_teach.checks.common import chopped
    >>> chopped([[0.6667, -0.129]]).tolist()
    [[0.66, -0.12]]
    """
    f = 10.0**decimals
    return np.trunc(f * np.asarray(M, float)) / f


def looks_two_decimals(X: np.ndarray, exact: np.ndarray) -> bool:
    """True if ``X`` is ``exact`` rounded or chopped to 2 decimals (but not ``exact`` itself).

    Examples
    --------
    >>> import numpy as np
    >>> from uio_teach.checks.common import looks_two_decimals
    >>> looks_two_decimals(np.array([[0.33]]), np.array([[1 / 3]]))
    True
    """
    exact_rtol = tols.CHECK_EXACT_RTOL
    return any(close(X, Y, exact_rtol) for Y in (np.round(exact, 2), chopped(exact))) and not close(
        X, exact, exact_rtol
    )


def read_matrix(
    result: CheckResult, name: str, value: Any, rows: int, cols: int, what: str
) -> np.ndarray | None:
    """``value`` as a ``rows x cols`` float array, or ``None`` after adding a ✗ that says why.

    Examples
    --------
    >>> from uio_teach.checks.common import CheckResult, read_matrix
    >>> result = CheckResult("demo")
    >>> read_matrix(result, "H", [[1, 2, 3]], 3, 1, "one column") is None
    True
    >>> result.failures[0][-16:]
    'use H.T instead.'
    """
    expected = f"a {rows} x {cols} matrix ({what})"
    if value is None:
        result.add(False, f"{name} is missing: it must be {expected}.")
        return None
    try:
        arr = np.array(value)
    except Exception:  # ragged lists and odd objects
        arr = np.array(None, dtype=object)
    if arr.dtype == object:
        result.add(
            False,
            f"{name} could not be read as a matrix of numbers: are all its rows of the same "
            f"length? It must be {expected}.",
        )
        return None
    if np.iscomplexobj(arr):
        if np.all(np.abs(arr.imag) <= tols.CHECK_ZERO_ATOL * max(1.0, float(np.max(np.abs(arr))))):
            arr = arr.real
        else:
            result.add(False, f"{name} has complex entries; it must be a real matrix.")
            return None
    try:
        arr = arr.astype(float)
    except (TypeError, ValueError):
        got = "text" if isinstance(value, str) else type(value).__name__
        result.add(False, f"{name} must hold numbers, got {got}; it must be {expected}.")
        return None
    if arr.ndim == 0 and rows == cols == 1:
        arr = arr.reshape(1, 1)
    elif arr.ndim == 1 and arr.size == rows * cols and 1 in (rows, cols):
        arr = arr.reshape(rows, cols)
    if arr.ndim != 2:
        result.add(
            False,
            f"{name} is a {arr.ndim}-D array of shape {arr.shape}; it must be {expected}: "
            "write one inner list per row, e.g. np.array([[1, 2], [3, 4]]).",
        )
        return None
    if arr.shape != (rows, cols):
        hint = (
            f" It looks transposed: use {name}.T instead."
            if arr.shape == (cols, rows)
            else f" Check the order of the factors that make {name}."
        )
        result.add(False, f"{name} has shape {arr.shape} but must be {expected}.{hint}")
        return None
    if not np.all(np.isfinite(arr)):
        bad = tuple(int(i) for i in np.argwhere(~np.isfinite(arr))[0])
        result.add(False, f"{name}{list(bad)} is {arr[bad]}: every entry must be a finite number.")
        return None
    return arr


def get_plant(result: CheckResult, plant: Any, example: str = "pa9") -> Plant | None:
    """The plant a check works on: ``plant``, or the lab's example when it is None.

    Anything that is not a :class:`~uio_teach.Plant` is a ✗ that says what was expected.

    Examples
    --------
    >>> from uio_teach.checks.common import CheckResult, get_plant
    >>> get_plant(CheckResult("demo"), None, "missile_autopilot").n
    4
    """
    if plant is None:
        return getattr(examples, example)()
    if not isinstance(plant, Plant):
        result.add(
            False,
            f"plant must be a uio_teach.Plant (the plant of the set-up cell), got "
            f"{type(plant).__name__}.",
        )
        return None
    return plant


def stability(F: np.ndarray, discrete: bool) -> tuple[bool, np.ndarray, np.ndarray]:
    """Whether ``F`` is stable, its sorted eigenvalues, and the unstable ones.

    Examples
    --------
    >>> import numpy as np
    >>> from uio_teach.checks.common import stability
    >>> stability(np.diag([-1.0, 2.0]), discrete=False)[0]
    False
    """
    eig = sort_poles(np.linalg.eigvals(F))
    ok = is_stable(eig, discrete)
    return bool(np.all(ok)), eig, eig[~ok]


RESPONSE_FIELDS = ("time", "states", "error", "residual", "inputs", "plant", "observer")


def read_response(result: CheckResult, response: Any, name: str = "response") -> Any:
    """``response`` if it is a run of :func:`uio_teach.simulate`, else ``None`` and a ✗.

    Examples
    --------
    >>> from uio_teach.checks.common import CheckResult, read_response
    >>> result = CheckResult("demo")
    >>> read_response(result, [1, 2]) is None, result.failures[0][-9:]
    (True, 'got list.')
    """
    if response is None or not all(hasattr(response, a) for a in RESPONSE_FIELDS):
        got = "None" if response is None else type(response).__name__
        result.add(
            False,
            f"{name} must be the result of ut.simulate(plant, observer, timepts, ...), got {got}.",
        )
        return None
    return response


def rerun_without_unknown_inputs(resp: Any, *, keep_v: bool = False) -> tuple[float, bool]:
    """Simulate a run again without its unknown inputs: how much does its error change?

    The run is made again with the same plant, observer, time points, known
    input ``u`` and initial states (of the plant and of the observer), without
    ``d``, and without ``v`` unless ``keep_v``.

    Parameters
    ----------
    resp : UIOResponse
        The run, a result of :func:`uio_teach.simulate`.
    keep_v : bool, optional
        Keep the measurement disturbance ``v`` (leave out ``d`` alone).

    Returns
    -------
    change : float
        The largest change of the error ``e``.
    same : bool
        Whether the change is round-off: at most ``tolerances.CHECK_RUN_RTOL`` times the
        largest state in absolute value, or times 1 when every state stays below 1.

    Examples
    --------
    >>> import uio_teach as ut
    >>> from uio_teach.checks.common import rerun_without_unknown_inputs
    >>> from uio_teach.worked.pa9 import PA9
    >>> run = PA9.simulate(ut.design_uio(PA9.plant(), poles=PA9.poles), d=PA9.d_sine)
    >>> rerun_without_unknown_inputs(run)[1]
    True
    """
    quiet = simulate(
        resp.plant,
        resp.observer,
        resp.time,
        u=resp.inputs.u if resp.plant.m else None,
        v=resp.inputs.v if keep_v and resp.plant.nv else None,
        initial_state=resp.states[:, 0],
        observer_state=resp.observer_states[:, 0],
    )
    change = float(np.max(np.abs(resp.error - quiet.error)))
    return change, change <= tols.CHECK_RUN_RTOL * max(1.0, float(np.max(np.abs(resp.states))))


def same_plant(a: Any, b: Any) -> bool:
    """True if two plants have the same matrices and sampling time.

    Examples
    --------
    >>> import uio_teach as ut
    >>> from uio_teach.checks.common import same_plant
    >>> same_plant(ut.examples.pa9(), ut.examples.pa9())
    True
    """
    if a is b:
        return True
    try:
        return bool(a == b)
    except Exception:  # plants that cannot be compared are not the same
        return False


def check_plant_of(result: CheckResult, resp: Any, plant: Any) -> bool:
    """A ✗ (and False) if the run ``resp`` was not simulated on ``plant``; True otherwise.

    Examples
    --------
    >>> import uio_teach as ut
    >>> from uio_teach.checks.common import CheckResult, check_plant_of
    >>> from uio_teach.worked.pa9 import PA9
    >>> run = PA9.simulate(ut.design_uio(PA9.plant(), poles=PA9.poles))
    >>> check_plant_of(CheckResult("demo"), run, ut.examples.pa9())
    True
    """
    if plant is None or same_plant(resp.plant, plant):
        return True
    result.add(
        False,
        "the run was simulated on another plant than the one of the set-up cell: simulate "
        "the plant named plant there (your group's numbers).",
    )
    return False


def same_poles(got: Any, wanted: Any, rtol: float | None = None) -> bool:
    """True if ``got`` and ``wanted`` hold the same poles (as multisets), each to ``rtol``.

    ``rtol`` is by default ``tolerances.CHECK_RTOL``.

    Examples
    --------
    >>> from uio_teach.checks.common import same_poles
    >>> same_poles([-1, -2], [-2.0000000001, -1]), same_poles([-1, -2], [-1, -3])
    (True, False)
    """
    rtol = tols.CHECK_RTOL if rtol is None else rtol
    got = sort_poles(np.asarray(got, complex).ravel())
    wanted = np.asarray(wanted, complex).ravel()
    if got.size != wanted.size:
        return False
    used = [False] * got.size
    for w in wanted:
        k = next(
            (i for i, g in enumerate(got) if not used[i] and abs(g - w) <= rtol * max(1.0, abs(w))),
            None,
        )
        if k is None:
            return False
        used[k] = True
    return True


def as_poles(poles: Any) -> np.ndarray:
    """Poles as given in ``PARAMS`` (numbers, or strings such as ``"-1+2j"``) as a complex array.

    Examples
    --------
    >>> from uio_teach.checks.common import as_poles
    >>> as_poles([-1, "-1+2j"]).tolist()
    [(-1+0j), (-1+2j)]
    """
    return np.array([complex(p) for p in np.ravel(np.asarray(poles, dtype=object))])


def same_observer(a: Any, b: Any) -> bool:
    """True if two observers are of one family with the same matrices (``H``, ``K1``, ``M``, ``L``...).

    Examples
    --------
    >>> import uio_teach as ut
    >>> from uio_teach.checks.common import same_observer
    >>> plant = ut.examples.pa9()
    >>> same_observer(ut.design_uio(plant, poles=[-1, -2, -3]), ut.design_uio(plant, poles=[-1, -2, -3]))
    True
    """  # noqa: E501
    if a is b:
        return True
    if type(a) is not type(b) or getattr(a, "family", None) != getattr(b, "family", None):
        return False
    for name in ("F", "H", "T", "K1", "K2", "L", "M", "error_matrix"):
        x, y = getattr(a, name, None), getattr(b, name, None)
        if x is None and y is None:
            continue
        if x is None or y is None or np.shape(x) != np.shape(y) or not np.allclose(x, y):
            return False
    return True
