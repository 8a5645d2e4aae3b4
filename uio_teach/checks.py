"""Checks for the lab of Practical Assignment 9: plain-words feedback on a student's work.

Each function takes what a lab group produced (matrices, a simulation, a
figure), never raises on a student mistake, and returns a :class:`CheckResult`:
a list of ✓ / ✗ messages that say what is right, what is not, and how to fix it.

* :func:`pa9_design` -- ``H``, ``T``, ``K1`` (and ``F``, ``K2``): the design
  equations (8) of the assignment and the stability of ``F``.
* :func:`pa9_simulation` -- a :func:`~uio_teach.simulate` response with a
  sinusoidal disturbance: the error does not depend on ``d`` and decays.
* :func:`pa9_plot` -- a matplotlib figure: labelled axes showing the error
  ``e`` and the residual ``r``.
* :func:`pa9_piecewise` -- a response with a piecewise-constant disturbance:
  the same error as with the sinusoid.

Examples
--------
>>> import numpy as np
>>> import uio_teach as ut
>>> from uio_teach import checks
>>> plant = ut.examples.pa9()
>>> H = plant.E @ np.linalg.pinv(plant.C @ plant.E)
>>> T = np.eye(3) - H @ plant.C
>>> K1 = ut.examples.PA9_PUBLISHED.K1
>>> checks.pa9_design(H, T, K1).passed
True
"""

from __future__ import annotations

import functools
import html
import math
import re
from collections.abc import Callable, Iterable, Sequence
from typing import Any, TypeVar

import numpy as np

from ._display import format_complex

__all__ = ["CheckResult", "pa9_design", "pa9_simulation", "pa9_plot", "pa9_piecewise"]

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

    Attributes
    ----------
    title : str
        What was checked.
    items : list of (bool or None, str)
        The verdicts, in the order they were made.

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

    def __init__(self, title: str, items: Iterable[tuple[bool | None, str]] = ()) -> None:
        self.title = str(title)
        self.items: list[tuple[bool | None, str]] = [(ok, str(msg)) for ok, msg in items]

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


def _never_raises(title: str) -> Callable[[_F], _F]:
    """Turn any unexpected exception of a check into a ✗ message instead of a traceback."""

    def decorate(func: _F) -> _F:
        @functools.wraps(func)
        def wrapper(*args: Any, **kwargs: Any) -> CheckResult:
            try:
                return func(*args, **kwargs)
            except Exception as exc:  # a student must never see a traceback here
                return CheckResult(
                    title,
                    [
                        (
                            False,
                            f"the check could not run with these arguments "
                            f"({type(exc).__name__}: {exc}). Compare your call with the "
                            f"example in help(checks.{func.__name__}).",
                        )
                    ],
                )

        return wrapper  # type: ignore[return-value]

    return decorate


# small helpers --------------------------------------------------------------------------------


def _fmt(M: np.ndarray) -> str:
    """A matrix on one line, 3 significant digits: ``[[0.941, 0.235], [0, 0]]``."""
    M = np.atleast_2d(np.asarray(M, dtype=float))
    scale = float(np.max(np.abs(M))) if M.size else 0.0
    M = np.where(np.abs(M) <= 1e-12 * max(scale, 1e-300), 0.0, M)
    return "[" + ", ".join("[" + ", ".join(f"{v:.3g}" for v in row) + "]" for row in M) + "]"


def _up_to(x: float, what: str) -> str:
    """`` (up to rounding)`` for a number that should be zero, else `` (<what> 3e-09)``."""
    return " (up to rounding)" if x <= 1e-12 else f" ({what} {x:.1g})"


def _plural(k: int, word: str) -> str:
    return f"{k} {word}" + ("" if k == 1 or word.endswith("s") else "s")


def _maxdiff(X: np.ndarray, Y: np.ndarray) -> tuple[float, tuple[int, ...]]:
    D = np.abs(np.asarray(X, float) - np.asarray(Y, float))
    idx = tuple(int(i) for i in np.unravel_index(int(np.argmax(D)), D.shape))
    return float(D[idx]), idx


def _close(X: np.ndarray, Y: np.ndarray, tol: float) -> bool:
    scale = max(1.0, float(np.max(np.abs(Y))) if np.size(Y) else 1.0)
    return np.shape(X) == np.shape(Y) and _maxdiff(X, Y)[0] <= tol * scale


def _chopped(M: np.ndarray, decimals: int = 2) -> np.ndarray:
    f = 10.0**decimals
    return np.trunc(f * np.asarray(M, float)) / f


def _looks_two_decimals(X: np.ndarray, exact: np.ndarray) -> bool:
    """True if ``X`` is ``exact`` rounded or chopped to 2 decimals (but not ``exact`` itself)."""
    return any(_close(X, Y, 1e-9) for Y in (np.round(exact, 2), _chopped(exact))) and not _close(
        X, exact, 1e-9
    )


def _read_matrix(
    result: CheckResult, name: str, value: Any, rows: int, cols: int, what: str
) -> np.ndarray | None:
    """``value`` as a ``rows x cols`` float array, or ``None`` after adding a ✗ that says why."""
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
        if np.all(np.abs(arr.imag) <= 1e-12 * max(1.0, float(np.max(np.abs(arr))))):
            arr = arr.real
        else:
            result.add(False, f"{name} has complex entries; it must be a real matrix.")
            return None
    try:
        arr = arr.astype(float)
    except (TypeError, ValueError):
        shown = repr(value) if len(repr(value)) <= 40 else repr(value)[:37] + "..."
        result.add(False, f"{name} must hold numbers, got {shown}; it must be {expected}.")
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
            f" It looks transposed: use {name}.T."
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


def _get_plant(result: CheckResult, plant: Any):
    from . import examples
    from .plant import Plant

    if plant is None:
        return examples.pa9()
    if not isinstance(plant, Plant):
        result.add(
            False,
            f"plant must be a uio_teach.Plant (e.g. ut.examples.pa9()), got "
            f"{type(plant).__name__}.",
        )
        return None
    return plant


def _stability(F: np.ndarray, discrete: bool) -> tuple[bool, np.ndarray, np.ndarray]:
    from .linalg import _sort, is_stable

    eig = _sort(np.linalg.eigvals(F))
    ok = is_stable(eig, discrete)
    return bool(np.all(ok)), eig, eig[~ok]


def _eigs(values: Iterable[complex]) -> str:
    """Eigenvalues as text, with round-off (below 1e-10) shown as 0."""
    values = np.asarray(list(values), complex)
    scale = max(1.0, float(np.max(np.abs(values)))) if values.size else 1.0
    tidy = np.where(np.abs(values.real) < 1e-10 * scale, 0, values.real) + 1j * np.where(
        np.abs(values.imag) < 1e-10 * scale, 0, values.imag
    )
    return ", ".join(format_complex(v, 4) for v in tidy)


# pa9_design -----------------------------------------------------------------------------------


@_never_raises("Practical Assignment 9: the observer design")
def pa9_design(
    H: Any,
    T: Any,
    K1: Any,
    F: Any = None,
    K2: Any = None,
    plant: Any = None,
    *,
    tol: float = 1e-6,
) -> CheckResult:
    """Check a decoupling-observer design against the equations (8) of the assignment.

    The checks, in order: the shapes; ``(I - HC)E = 0`` (the disturbance is
    cancelled); ``T = I - HC``; ``F = TA - K1C``; ``K2 = FH``; ``F`` stable
    (its eigenvalues in the open left half-plane, or in the unit disk for a
    discrete plant). Each relation is checked against your own ``H`` and
    ``K1``, the two matrices you are free to choose: any ``H`` with
    ``HCE = E`` is accepted, not only ``E (CE)^+``.

    Parameters
    ----------
    H : array_like, shape (n, p)
        Your ``H``.
    T : array_like, shape (n, n)
        Your ``T``.
    K1 : array_like, shape (n, p)
        Your output-injection gain ``K1``.
    F : array_like, shape (n, n), optional
        Your ``F``; when omitted, ``TA - K1C`` is computed from your ``H`` and
        ``K1`` and only its stability is checked.
    K2 : array_like, shape (n, p), optional
        Your ``K2``; when omitted, it is not checked.
    plant : Plant, optional
        The plant; the assignment's example :func:`uio_teach.examples.pa9` by
        default.
    tol : float, optional
        Relative tolerance of the equalities (entries are compared with
        ``tol * max(1, largest entry)``). Full-precision NumPy results agree to
        about 1e-15; numbers typed with 2 decimals do not pass.

    Returns
    -------
    CheckResult
        One ✓ or ✗ message per check; ``.passed`` is True when all hold.

    Examples
    --------
    >>> import numpy as np
    >>> import uio_teach as ut
    >>> from uio_teach import checks
    >>> plant = ut.examples.pa9()
    >>> A, C, E = plant.A, plant.C, plant.E
    >>> H = E @ np.linalg.pinv(C @ E)
    >>> T = np.eye(3) - H @ C
    >>> K1 = ut.examples.PA9_PUBLISHED.K1
    >>> F = T @ A - K1 @ C
    >>> print(checks.pa9_design(H, T, K1, F, F @ H))
    Practical Assignment 9: the observer design
      ✓ (I - HC)E = 0 (up to rounding): H cancels the disturbance.
      ✓ T = I - HC.
      ✓ F = TA - K1C.
      ✓ K2 = FH.
      ✓ F is stable: its eigenvalues -3.001, -1.991, -1 are in the open left half-plane, so the error e' = F e decays.
      => All 5 checks passed.

    A sign error in ``K2`` is named:

    >>> checks.pa9_design(H, T, K1, F, -F @ H).failures
    ['K2 is -FH: the sign is flipped. The condition (A - K1C - HCA)H - K2 = 0 of eq. (7) gives K2 = FH.']
    """  # noqa: E501
    result = CheckResult("Practical Assignment 9: the observer design")
    plant = _get_plant(result, plant)
    if plant is None:
        return result
    n, p = plant.n, plant.p
    A, C, E = plant.A, plant.C, plant.E
    what_np = f"n x p = {n} x {p}: one row per state, one column per output"
    what_nn = f"n x n = {n} x {n}"
    H = _read_matrix(result, "H", H, n, p, what_np)
    T = _read_matrix(result, "T", T, n, n, what_nn)
    K1 = _read_matrix(result, "K1", K1, n, p, what_np)
    F_given = F is not None
    K2_given = K2 is not None
    F = _read_matrix(result, "F", F, n, n, what_nn) if F_given else None
    K2 = _read_matrix(result, "K2", K2, n, p, what_np) if K2_given else None
    if H is None or T is None or K1 is None or (F_given and F is None) or (K2_given and K2 is None):
        result.add(None, "Fix the shapes first; the design equations are checked afterwards.")
        return result

    from .linalg import pinv

    eye = np.eye(n)
    H_ref = E @ pinv(C @ E)

    # (I - HC) E = 0 ---------------------------------------------------------------------------
    R = (eye - H @ C) @ E
    big = float(np.max(np.abs(R))) if R.size else 0.0
    if big <= tol * max(1.0, float(np.max(np.abs(E))) if E.size else 1.0):
        result.add(
            True,
            f"(I - HC)E = 0{_up_to(big, 'largest entry')}: H cancels the disturbance.",
        )
    else:
        if _looks_two_decimals(H, H_ref):
            hint = (
                " Your H has the 2 decimals printed in the assignment; those numbers are "
                "chopped, not exact, so the disturbance is not fully cancelled. Keep full "
                "precision: H = E @ np.linalg.pinv(C @ E)."
            )
        elif _close(H, -H_ref, 1e-6):
            hint = " Your H is -E(CE)^+: drop the minus sign."
        else:
            hint = (
                " H must solve HCE = E; the assignment's choice is H = E (CE)^+, in NumPy "
                "H = E @ np.linalg.pinv(C @ E) (pinv, because CE is not square)."
            )
        result.add(
            False,
            f"H does not satisfy (I - HC)E = 0: (I - HC)E = {_fmt(R)} (largest entry {big:.3g}), "
            f"so the disturbance d still drives the error.{hint}",
        )

    # T = I - HC -------------------------------------------------------------------------------
    T_ref = eye - H @ C
    T_ok = _close(T, T_ref, tol)
    if T_ok:
        result.add(True, "T = I - HC.")
    else:
        diff, idx = _maxdiff(T, T_ref)
        where = f"T[{idx[0]}, {idx[1]}] is {T[idx]:.4g} but (I - HC)[{idx[0]}, {idx[1]}] is "
        where += f"{T_ref[idx]:.4g}"
        if _close(T, -T_ref, tol):
            hint = " Your T is HC - I: the sign is flipped."
        elif _close(T, H @ C, tol):
            hint = " Your T is HC; it must be I - HC."
        elif _looks_two_decimals(T, T_ref) or _looks_two_decimals(T, eye - H_ref @ C):
            hint = " Your T has only 2 decimals; compute it as T = np.eye(n) - H @ C."
        else:
            hint = " Compute it from your H: T = np.eye(n) - H @ C."
        result.add(False, f"T is not I - HC: {where} (difference {diff:.3g}).{hint}")

    # F = TA - K1C -----------------------------------------------------------------------------
    F_ref = T_ref @ A - K1 @ C
    if F_given:
        if _close(F, F_ref, tol):
            result.add(True, "F = TA - K1C.")
        else:
            diff, idx = _maxdiff(F, F_ref)
            if not T_ok and _close(F, T @ A - K1 @ C, tol):
                hint = " It is TA - K1C with your T, but your T is wrong (see above): fix T first."
            elif _close(F, A - K1 @ C, tol):
                hint = " Your F is A - K1C: the T is missing, F = TA - K1C."
            elif _close(F, T_ref @ A + K1 @ C, tol):
                hint = " Your F is TA + K1C: the sign of K1C is flipped."
            else:
                hint = " Compute it as F = T @ A - K1 @ C."
            result.add(
                False,
                f"F is not TA - K1C: F[{idx[0]}, {idx[1]}] is {F[idx]:.4g} but "
                f"(TA - K1C)[{idx[0]}, {idx[1]}] is {F_ref[idx]:.4g} "
                f"(difference {diff:.3g}).{hint}",
            )
    else:
        result.add(None, "F not given: F = TA - K1C is computed from your H and K1.")

    # K2 = FH ----------------------------------------------------------------------------------
    if K2_given:
        K2_ref = F_ref @ H
        if _close(K2, K2_ref, tol):
            result.add(True, "K2 = FH.")
        elif _close(K2, -K2_ref, tol):
            result.add(
                False,
                "K2 is -FH: the sign is flipped. The condition (A - K1C - HCA)H - K2 = 0 of "
                "eq. (7) gives K2 = FH.",
            )
        elif F_given and _close(K2, F @ H, tol):
            result.add(False, "K2 = FH with your F, but your F is wrong (see above): fix F first.")
        else:
            diff, idx = _maxdiff(K2, K2_ref)
            hint = (
                " Your K2 is K1 - FH; K2 alone is FH."
                if _close(K2, K1 - K2_ref, tol)
                else " Compute it as K2 = F @ H."
            )
            result.add(
                False,
                f"K2 is not FH: K2[{idx[0]}, {idx[1]}] is {K2[idx]:.4g} but (FH)[{idx[0]}, "
                f"{idx[1]}] is {K2_ref[idx]:.4g} (difference {diff:.3g}).{hint}",
            )

    # stability of F ---------------------------------------------------------------------------
    F_used = F if F_given else F_ref
    which = "F" if F_given else "F = TA - K1C"
    stable, eig, bad = _stability(F_used, plant.is_discrete)
    region = "inside the unit circle" if plant.is_discrete else "in the open left half-plane"
    law = "e[k+1] = F e[k]" if plant.is_discrete else "e' = F e"
    if stable:
        result.add(
            True,
            f"{which} is stable: its eigenvalues {_eigs(eig)} are {region}, so the error "
            f"{law} decays.",
        )
    else:
        result.add(
            False,
            f"{which} is not stable: the eigenvalue{'s' if len(bad) > 1 else ''} {_eigs(bad)} "
            f"{'are' if len(bad) > 1 else 'is'} not {region}, so the error {law} does not "
            "decay. Choose K1 so that TA - K1C has the poles you want, e.g. "
            "K1 = ct.place((T @ A).T, C.T, [-1, -2, -3]).T.",
        )
    return result


# responses ------------------------------------------------------------------------------------


def _read_response(result: CheckResult, response: Any, name: str = "response"):
    needed = ("time", "states", "error", "residual", "inputs", "plant", "observer")
    if response is None or not all(hasattr(response, a) for a in needed):
        got = "None" if response is None else type(response).__name__
        result.add(
            False,
            f"{name} must be the result of ut.simulate(plant, observer, timepts, ...), got {got}.",
        )
        return None
    return response


def _disturbance(result: CheckResult, resp) -> np.ndarray | None:
    if resp.plant.q == 0:
        result.add(False, "the simulated plant has no unknown input (E has no columns).")
        return None
    d = np.asarray(resp.inputs.d, float)
    if not np.any(d):
        result.add(
            False,
            "d is zero during the whole simulation, so the test says nothing about the "
            "disturbance: pass one, e.g. ut.simulate(..., d=ut.signals.sinusoid(1.0, 2.0)).",
        )
        return None
    return d


def _noise_free(result: CheckResult, resp) -> bool:
    if np.any(np.asarray(resp.inputs.noise)):
        result.add(
            False,
            "the simulation has measurement noise; the error then depends on the noise too, so "
            "the disturbance test is not clean. Simulate without noise=.",
        )
        return False
    return True


def _initial_error(result: CheckResult, resp) -> float:
    e0 = float(np.max(np.abs(resp.error[:, 0])))
    if e0 <= 1e-12:
        result.add(
            False,
            "the error is zero at t = 0, so nothing can be seen decaying: start the plant from "
            "a nonzero state, e.g. initial_state=[1, -1, 0.5].",
        )
    return e0


def _same_without_d(result: CheckResult, resp) -> np.ndarray | None:
    """Re-simulate with ``d = 0``; add a ✓/✗ on whether the error is unchanged."""
    from .simulation import simulate

    quiet = simulate(
        resp.plant,
        resp.observer,
        resp.time,
        u=resp.inputs.u if resp.plant.m else None,
        v=resp.inputs.v if resp.plant.r else None,
        initial_state=resp.states[:, 0],
        observer_state=resp.observer_states[:, 0],
    )
    diff = float(np.max(np.abs(resp.error - quiet.error)))
    scale = max(1.0, float(np.max(np.abs(resp.states))))
    if diff <= 1e-8 * scale:
        result.add(
            True,
            f"the error does not depend on d: simulated again with d = 0, it is the same"
            f"{_up_to(diff, 'largest difference')}.",
        )
        return quiet.error
    if not resp.observer.decouples:
        hint = (
            f" Your observer is a {resp.observer.family}, which ignores d; design a decoupling "
            "observer with ut.design_uio(plant, ...)."
        )
    elif resp.plant != resp.observer.plant:
        hint = (
            " The simulated plant is not the plant the observer was designed for: use the same "
            "plant (the same E) in ut.design_uio and ut.simulate."
        )
    else:
        hint = ""
    result.add(
        False,
        f"the error depends on d: simulated again with d = 0, it changes by up to "
        f"{diff:.3g}.{hint}",
    )
    return None


def _decays(result: CheckResult, resp, e0: float, decay: float, decoupled: bool = True) -> None:
    if e0 <= 1e-12:
        return
    e_end = float(np.max(np.abs(resp.error[:, -1])))
    t0, t1 = float(resp.time[0]), float(resp.time[-1])
    unit = "" if resp.plant.dt is True else " s"
    if e_end <= decay * e0:
        result.add(
            True,
            f"the error decays: largest component {e0:.3g} at t = {t0:g}{unit}, "
            f"{e_end:.2g} at t = {t1:g}{unit}.",
        )
        return
    poles = resp.observer.poles()
    stable, _, bad = _stability(resp.observer.error_matrix, resp.plant.is_discrete)
    if not stable:
        result.add(
            False,
            f"the error does not decay: the observer's error dynamics are unstable (pole(s) "
            f"{_eigs(bad)}). Choose K1 so that F = TA - K1C is stable.",
        )
        return
    if not decoupled:
        result.add(
            False,
            f"the error does not decay: {e_end:.3g} at the end against {e0:.3g} at the start, "
            "because the disturbance keeps driving it (see above).",
        )
        return
    if resp.plant.is_discrete:
        rho = float(np.max(np.abs(poles)))
        need = math.log(decay) / math.log(rho) if 0 < rho < 1 else 1.0
        need_txt = f"about {math.ceil(need)} steps"
    else:
        sigma = float(-np.max(poles.real))
        need_txt = f"about {math.log(1 / decay) / sigma:.2g} s"
    result.add(
        False,
        f"the error has not decayed yet: {e_end:.3g} at the end against {e0:.3g} at the start. "
        f"With the slowest error pole {format_complex(poles[np.argmax(poles.real)])} it needs "
        f"{need_txt} to shrink to {decay:.0%}: simulate longer.",
    )


def _jumps(d: np.ndarray) -> np.ndarray:
    """Indices ``k`` where some channel of ``d`` changes between samples ``k`` and ``k + 1``."""
    scale = max(1.0, float(np.max(np.abs(d))))
    return np.flatnonzero(np.any(np.abs(np.diff(d, axis=1)) > 1e-9 * scale, axis=0))


@_never_raises("Practical Assignment 9: the test with a sinusoidal disturbance")
def pa9_simulation(response: Any, *, decay: float = 0.01) -> CheckResult:
    """Check a simulation with a sinusoidal disturbance: does the error ignore ``d`` and decay?

    The checks: the disturbance ``d`` is nonzero and oscillates; the
    simulation is noise-free and starts with a nonzero error; the error is
    unchanged when the simulation is run again with ``d = 0`` (the defining
    property of an unknown input observer); the error has shrunk to
    ``decay`` times its initial size by the end.

    Parameters
    ----------
    response : UIOResponse
        The result of :func:`uio_teach.simulate`.
    decay : float, optional
        The largest final error, relative to the initial one (1 %).

    Returns
    -------
    CheckResult

    Examples
    --------
    >>> import numpy as np
    >>> import uio_teach as ut
    >>> from uio_teach import checks
    >>> plant = ut.examples.pa9()
    >>> obs = ut.design_uio(plant, poles=[-1, -2, -3])
    >>> t = np.linspace(0, 10, 1001)
    >>> resp = ut.simulate(plant, obs, t, d=ut.signals.sinusoid(1.0, 2.0),
    ...                    initial_state=[1, -1, 0.5])
    >>> checks.pa9_simulation(resp).passed
    True
    >>> luen = ut.simulate(plant, ut.design_luenberger(plant, poles=[-1, -2, -3]), t,
    ...                    d=ut.signals.sinusoid(1.0, 2.0), initial_state=[1, -1, 0.5])
    >>> checks.pa9_simulation(luen).passed
    False
    """
    result = CheckResult("Practical Assignment 9: the test with a sinusoidal disturbance")
    resp = _read_response(result, response)
    if resp is None:
        return result
    d = _disturbance(result, resp)
    if d is not None:
        N = d.shape[1]
        changing = _jumps(d).size / max(1, N - 1)
        centred = d - d.mean(axis=1, keepdims=True)
        crossings = int(np.max(np.sum(np.diff(np.sign(centred), axis=1) != 0, axis=1)))
        if changing < 0.5:
            result.add(
                False,
                "d is piecewise constant, not a sinusoid: use d=ut.signals.sinusoid(amplitude, "
                "frequency) here (the piecewise-constant test is checked by pa9_piecewise).",
            )
        elif crossings < 2:
            result.add(
                False,
                "d does not oscillate within the simulated time: raise its frequency or "
                "simulate several periods.",
            )
        else:
            result.add(
                True, f"d oscillates like a sinusoid (it crosses its mean {crossings} times)."
            )
    if not _noise_free(result, resp):
        return result
    e0 = _initial_error(result, resp)
    decoupled = _same_without_d(result, resp) is not None
    _decays(result, resp, e0, decay, decoupled)
    return result


@_never_raises("Practical Assignment 9: the test with a piecewise-constant disturbance")
def pa9_piecewise(
    response: Any, sinusoidal: Any = None, *, decay: float = 0.01, max_jumps: float = 0.1
) -> CheckResult:
    """Check a simulation with a piecewise-constant disturbance, and compare with the sinusoid.

    The checks: ``d`` is piecewise constant (it jumps at least once, and at
    no more than ``max_jumps`` of the samples); the error does not depend on
    ``d`` (simulated again with ``d = 0``); when ``sinusoidal`` is given, the
    error equals the error of that simulation (same time grid and initial
    states); the error decays.

    Parameters
    ----------
    response : UIOResponse
        The simulation with the piecewise-constant disturbance.
    sinusoidal : UIOResponse, optional
        The simulation with the sinusoidal disturbance, to compare the errors.
    decay : float, optional
        The largest final error, relative to the initial one (1 %).
    max_jumps : float, optional
        The largest fraction of samples at which ``d`` may change.

    Returns
    -------
    CheckResult

    Examples
    --------
    >>> import numpy as np
    >>> import uio_teach as ut
    >>> from uio_teach import checks
    >>> plant = ut.examples.pa9()
    >>> obs = ut.design_uio(plant, poles=[-1, -2, -3])
    >>> t = np.linspace(0, 10, 1001)
    >>> sin = ut.simulate(plant, obs, t, d=ut.signals.sinusoid(1.0, 2.0),
    ...                   initial_state=[1, -1, 0.5])
    >>> pw = ut.simulate(plant, obs, t, d=ut.signals.piecewise_constant([0, 4], [1.0, -2.0]),
    ...                  initial_state=[1, -1, 0.5])
    >>> checks.pa9_piecewise(pw, sinusoidal=sin).passed
    True
    >>> checks.pa9_piecewise(sin).failures[0][:35]
    'd changes at 100% of the time steps'
    """
    result = CheckResult("Practical Assignment 9: the test with a piecewise-constant disturbance")
    resp = _read_response(result, response)
    if resp is None:
        return result
    d = _disturbance(result, resp)
    if d is not None:
        jumps = _jumps(d)
        frac = jumps.size / max(1, d.shape[1] - 1)
        if jumps.size == 0:
            result.add(
                False,
                "d is constant: a piecewise-constant test needs at least one jump, e.g. "
                "d=ut.signals.piecewise_constant([0, 4, 7], [1.0, -2.0, 0.5]).",
            )
        elif frac > max_jumps:
            result.add(
                False,
                f"d changes at {frac:.0%} of the time steps, so it is not piecewise constant "
                "(is it still the sinusoid?): use d=ut.signals.piecewise_constant(times, values).",
            )
        else:
            times = ", ".join(f"{resp.time[k + 1]:.3g}" for k in jumps[:6])
            more = ", ..." if jumps.size > 6 else ""
            unit = "" if resp.plant.dt is True else " s"
            result.add(
                True,
                f"d is piecewise constant: {_plural(jumps.size, 'jump')} (at t = "
                f"{times}{more}{unit}).",
            )
    if not _noise_free(result, resp):
        return result
    e0 = _initial_error(result, resp)
    decoupled = _same_without_d(result, resp) is not None
    if sinusoidal is None:
        result.add(
            None,
            "pass sinusoidal=<the response of the sinusoidal test> to check that both "
            "disturbances give the same error.",
        )
    else:
        other = _read_response(result, sinusoidal, "sinusoidal")
        if other is not None:
            _compare(result, resp, other)
    _decays(result, resp, e0, decay, decoupled)
    return result


def _compare(result: CheckResult, resp, other) -> None:
    if resp.time.shape != other.time.shape or not np.allclose(resp.time, other.time):
        result.add(
            False,
            "the two simulations use different time points, so their errors cannot be "
            "compared sample by sample: use the same timepts in both.",
        )
        return
    if not np.allclose(resp.states[:, 0], other.states[:, 0]) or not np.allclose(
        resp.estimates[:, 0], other.estimates[:, 0]
    ):
        result.add(
            False,
            "the two simulations start from different states, so their errors differ for that "
            "reason alone: use the same initial_state (and observer_state) in both.",
        )
        return
    diff = float(np.max(np.abs(resp.error - other.error)))
    scale = max(1.0, float(np.max(np.abs(resp.states))), float(np.max(np.abs(other.states))))
    if diff <= 1e-8 * scale:
        result.add(
            True,
            f"the error is the same as with the sinusoidal disturbance"
            f"{_up_to(diff, 'largest difference')}: the observer does not see which "
            "disturbance acts.",
        )
    else:
        result.add(
            False,
            f"the error differs from the sinusoidal test by up to {diff:.3g}: are both "
            "simulations made with the same decoupling observer?",
        )


# pa9_plot -------------------------------------------------------------------------------------

_ERROR = re.compile(r"error|\be(_\{?\w+\}?)?\b|x\s*-\s*\\?hat|x\s*-\s*x", re.IGNORECASE)
_RESIDUAL = re.compile(r"residual|\br(_\{?\w+\}?)?\b|y\s*-\s*c", re.IGNORECASE)
_TIME = re.compile(r"time|\bt\b|\(s\)|\[s\]|\bs\b|step|\bk\b|sec", re.IGNORECASE)


def _figure(result: CheckResult, fig: Any):
    from matplotlib.axes import Axes
    from matplotlib.figure import Figure, SubFigure

    if isinstance(fig, (Figure, SubFigure)):
        return fig
    if isinstance(fig, Axes):
        return fig.figure
    if isinstance(fig, (np.ndarray, list, tuple)):
        flat = [a for a in np.ravel(np.asarray(fig, dtype=object)) if isinstance(a, Axes)]
        if flat:
            return flat[0].figure
    result.add(
        False,
        f"fig must be a matplotlib figure (fig, ax = plt.subplots(...); or fig = resp.plot()), "
        f"got {type(fig).__name__}.",
    )
    return None


def _axes_name(i: int, ax) -> str:
    title = ax.get_title()
    return f"axes {i + 1}" + (f" ('{title}')" if title else "")


def _texts(fig, ax=None) -> list[str]:
    """Titles, axis labels, legend entries and line labels of one axes (or of the figure)."""
    axes = [ax] if ax is not None else list(fig.axes)
    out: list[str] = []
    if ax is None and getattr(fig, "_suptitle", None) is not None:
        out.append(fig._suptitle.get_text())
    for a in axes:
        out += [a.get_title(), a.get_ylabel(), a.get_title("left"), a.get_title("right")]
        legend = a.get_legend()
        if legend is not None:
            out += [t.get_text() for t in legend.get_texts()]
        out += [ln.get_label() for ln in a.get_lines() if not ln.get_label().startswith("_")]
    if ax is None:
        for legend in getattr(fig, "legends", []):
            out += [t.get_text() for t in legend.get_texts()]
    return [t for t in out if t]


def _has_xlabel(ax, axes: Sequence) -> bool:
    """An x-label of its own, or one below it in the same column over the same time range."""
    if ax.get_xlabel():
        return True
    shared = ax.get_shared_x_axes()
    box = ax.get_position()
    for other in axes:
        if other is ax or not other.get_xlabel():
            continue
        if shared.joined(ax, other):
            return True
        obox = other.get_position()
        same_column = abs(obox.x0 - box.x0) < 0.02 and abs(obox.x1 - box.x1) < 0.02
        if same_column and obox.y0 < box.y0 and np.allclose(other.get_xlim(), ax.get_xlim()):
            return True
    return False


def _match_rows(y: np.ndarray, M: np.ndarray, tol: float) -> list[int]:
    return [i for i in range(M.shape[0]) if np.allclose(y, M[i], rtol=0, atol=tol)]


@_never_raises("Practical Assignment 9: the plot of the error and the residual")
def pa9_plot(fig: Any, response: Any = None) -> CheckResult:
    """Check a figure of the error ``e`` and the residual ``r``: labelled axes, right curves.

    The checks: the figure has axes with data; every axes has a y-label and an
    x-label (a shared x-axis labelled once counts) that names time; some
    title, label or legend entry names the error and the residual. With
    ``response`` also: the curves are the rows of ``response.error`` and
    ``response.residual`` (not the states ``x`` or the outputs ``y``).

    Parameters
    ----------
    fig : matplotlib.figure.Figure
        The figure (an ``Axes`` or an array of axes is accepted too).
    response : UIOResponse, optional
        The simulation that was plotted, to check the curves themselves.

    Returns
    -------
    CheckResult

    Examples
    --------
    >>> import numpy as np
    >>> from matplotlib.figure import Figure
    >>> from uio_teach import checks
    >>> fig = Figure()
    >>> ax_e, ax_r = fig.subplots(2, 1, sharex=True)
    >>> t = np.linspace(0, 5, 51)
    >>> _ = ax_e.plot(t, np.exp(-t)); _ = ax_e.set_ylabel("error e")
    >>> _ = ax_r.plot(t, np.exp(-2 * t)); _ = ax_r.set_ylabel("residual r")
    >>> checks.pa9_plot(fig).failures
    ['axes 1, axes 2 have no x-label: label the time axis, e.g. ax.set_xlabel("time (s)").']
    >>> _ = ax_r.set_xlabel("time (s)")
    >>> checks.pa9_plot(fig).passed
    True
    """
    result = CheckResult("Practical Assignment 9: the plot of the error and the residual")
    fig = _figure(result, fig)
    if fig is None:
        return result
    axes = [ax for ax in fig.axes if ax.has_data()]
    if not axes:
        result.add(
            False,
            "the figure has no curves: did you plot into another figure? Plot with the axes "
            "of this figure, e.g. ax.plot(resp.time, resp.error.T).",
        )
        return result
    result.add(True, f"the figure has {_plural(len(axes), 'axes')} with curves.")

    # labels -----------------------------------------------------------------------------------
    no_y = [_axes_name(i, ax) for i, ax in enumerate(axes) if not ax.get_ylabel()]
    if no_y:
        result.add(
            False,
            f"{', '.join(no_y)} {'has' if len(no_y) == 1 else 'have'} no y-label: say what is "
            'plotted, e.g. ax.set_ylabel("error e").',
        )
    else:
        result.add(True, "every axes has a y-label.")
    no_x = [_axes_name(i, ax) for i, ax in enumerate(axes) if not _has_xlabel(ax, axes)]
    if no_x:
        result.add(
            False,
            f"{', '.join(no_x)} {'has' if len(no_x) == 1 else 'have'} no x-label: label the "
            'time axis, e.g. ax.set_xlabel("time (s)").',
        )
    else:
        not_time = sorted(
            {
                ax.get_xlabel()
                for ax in axes
                if ax.get_xlabel() and not _TIME.search(ax.get_xlabel())
            }
        )
        if not_time:
            result.add(
                False,
                f'the x-label {not_time[0]!r} does not say it is time: write e.g. "time (s)".',
            )
        else:
            result.add(True, "the x-axes are labelled with time.")

    texts = _texts(fig)
    has_e = any(_ERROR.search(t) for t in texts)
    has_r = any(_RESIDUAL.search(t) for t in texts)
    result.add(
        has_e,
        "the error is named in a label, title or legend."
        if has_e
        else 'no label, title or legend names the error: e.g. ax.set_ylabel("error e = x - x̂").',
    )
    result.add(
        has_r,
        "the residual is named in a label, title or legend."
        if has_r
        else 'no label, title or legend names the residual: e.g. ax.set_ylabel("residual r").',
    )

    # the curves themselves ----------------------------------------------------------------------
    if response is not None:
        resp = _read_response(result, response)
        if resp is not None:
            _check_curves(result, axes, resp)
    return result


def _check_curves(result: CheckResult, axes: Sequence, resp) -> None:
    N = resp.time.size
    err = np.asarray(resp.error, float)
    res = np.asarray(resp.residual, float)
    tol = 1e-9 * max(1.0, float(np.max(np.abs(resp.states))))
    found = {"e": set(), "r": set(), "x": set(), "y": set(), "enorm": False}
    for ax in axes:
        for line in ax.get_lines():
            y = np.asarray(line.get_ydata(), float)
            if y.shape != (N,):
                continue
            found["e"].update(_match_rows(y, err, tol))
            found["r"].update(_match_rows(y, res, tol))
            found["x"].update(_match_rows(y, np.asarray(resp.states, float), tol))
            found["y"].update(_match_rows(y, np.asarray(resp.outputs, float), tol))
            if np.allclose(y, np.linalg.norm(err, axis=0), rtol=0, atol=tol):
                found["enorm"] = True
    n, p = err.shape[0], res.shape[0]
    if found["enorm"] or len(found["e"]) == n:
        result.add(True, "the error curves are the error e = x - x̂ of the response.")
    elif found["e"]:
        missing = ", ".join(f"e{i + 1}" for i in range(n) if i not in found["e"])
        result.add(False, f"some error components are missing from the figure: {missing}.")
    elif found["x"]:
        result.add(
            False,
            "no curve is the error e = x - x̂, but some are the states x: plot resp.error, "
            "not resp.states.",
        )
    else:
        result.add(False, "no curve of the figure is the error of the response (resp.error).")
    if len(found["r"]) == p:
        result.add(True, "the residual curves are the residual r = y - C x̂ of the response.")
    elif found["r"]:
        missing = ", ".join(f"r{i + 1}" for i in range(p) if i not in found["r"])
        result.add(False, f"some residual components are missing from the figure: {missing}.")
    elif found["y"]:
        result.add(
            False,
            "no curve is the residual r = y - C x̂, but some are the outputs y: plot "
            "resp.residual, not resp.outputs.",
        )
    else:
        result.add(False, "no curve of the figure is the residual of the response (resp.residual).")
