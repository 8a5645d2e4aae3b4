"""Observer gains from linear matrix inequalities (cvxpy), as in the discrete case study."""

from __future__ import annotations

import warnings
from numbers import Real
from typing import NamedTuple

import numpy as np
import scipy.linalg as sla

from . import tolerances as tols
from ._display import format_complex
from ._validation import as_matrix
from .balancing import BalancedPair, balanced_pair
from .errors import InputError, UIOTeachError
from .linalg import is_stable, pinv
from .placement import place_pair_poles

__all__ = [
    "LMIError",
    "LMIInfeasibleError",
    "LMISolverError",
    "LMIUndecidedError",
    "LMIResult",
    "lmi_gain",
]

#: Relative margin of a certified gain (``uio_teach.tolerances.STABILITY_MARGIN``): every pole
#: at least this far inside the boundary, so a certified observer is ``is_stable``.
STRICT_MARGIN = tols.STABILITY_MARGIN


class LMIError(UIOTeachError, ValueError):
    """Base class of the LMI errors; ``.status`` is the solver's word."""

    def __init__(self, message: str, status: str) -> None:
        super().__init__(message)
        self.status = status


class LMIInfeasibleError(LMIError):
    """The LMI has no solution: no gain of this form meets the bound (a proof, not a failure)."""


class LMISolverError(LMIError):
    """The solver failed (numerical trouble) or returned a gain that does not meet the bound.

    This says nothing about feasibility: scale the problem, try another ``solver``.
    """


class LMIUndecidedError(LMISolverError):
    """The solver could not decide: only inaccurate or failed answers, and no placed gain
    meets the bound either. Neither a gain nor a proof of infeasibility."""


class LMIResult(NamedTuple):
    """Gain ``L`` and Lyapunov certificate ``P`` (unpacks as ``L, P``).

    Examples
    --------
    >>> import uio_teach as ut
    >>> res = ut.lmi_gain([[0.5]], [[1.0]], dt=True)
    >>> res.L.shape, res.P.shape
    ((1, 1), (1, 1))
    """

    L: np.ndarray
    P: np.ndarray


def _check_dt(dt) -> bool:
    """True for discrete time; ``dt`` as for :class:`~uio_teach.Plant`."""
    if dt is None or dt is False:
        return False
    if dt is True:
        return True
    if isinstance(dt, Real) and not isinstance(dt, bool) and np.isfinite(dt) and dt >= 0:
        return dt != 0
    raise InputError(
        "dt must be None (continuous time), True (discrete time, unspecified period) or a "
        f"positive sampling period, got {dt!r}"
    )


def _check_decay(decay, discrete: bool) -> float | None:
    if decay is None:
        return None
    if isinstance(decay, bool) or not isinstance(decay, Real):
        raise InputError(f"decay must be a real number, got {decay!r}")
    decay = float(decay)
    if not np.isfinite(decay) or decay < 0 or (discrete and not 0 < decay <= 1):
        rng = "0 < decay <= 1 (a radius)" if discrete else "decay >= 0 (a rate)"
        raise InputError(f"decay must satisfy {rng}, got {decay!r}")
    return decay


_SDP_SOLVERS = ("CLARABEL", "SCS", "MOSEK", "CVXOPT", "COPT", "SDPA")


def _check_solver(solver) -> list[str]:
    if solver is None:
        return ["CLARABEL", "SCS"]
    import cvxpy as cp  # deferred on purpose: cvxpy takes half a second to import

    installed = [s for s in cp.installed_solvers() if s in _SDP_SOLVERS]
    if not isinstance(solver, str) or solver.upper() not in installed:
        raise InputError(
            "solver must be an installed cvxpy solver for semidefinite programs "
            f"({', '.join(installed) or 'none installed'}), got {solver!r}"
        )
    return [solver.upper()]


def _balance(A1: np.ndarray) -> np.ndarray:
    """Diagonal similarity (powers of 2, exact) that balances ``A1``."""
    if A1.shape[0] == 0:
        return np.ones(0)
    _, (scale, _) = sla.matrix_balance(A1, permute=False, separate=True)
    return np.asarray(scale, float)


def lmi_gain(
    A1,
    C,
    *,
    D=None,
    dt: float | bool | None = None,
    decay: float | None = None,
    solver: str | None = None,
    fixed_modes=None,
) -> LMIResult:
    r"""Observer gain ``L`` that makes ``A1 - L C`` stable, from an LMI.

    With ``Y = P L`` the conditions are linear in ``(P, Y)``.

    Discrete time (the script of the case study, a Schur complement of
    ``(A1 - LC)^T P (A1 - LC) - decay^2 P <= 0``)::

        [[-decay^2 P, A1^T P - C^T Y^T], [P A1 - Y C, -P]] <= 0,   P >= 0.01 I

    with ``decay = 1`` when not given (all poles in the closed unit disk).
    Continuous time (Lyapunov)::

        A1^T P + P A1 - C^T Y^T - Y C + 2 decay P <= -0.01 I,   P >= 0.01 I

    so all poles lie left of ``-decay`` (``decay = 0`` when not given).
    With ``D`` the constraint ``Y D = 0`` gives ``L D = 0``.

    Parameters
    ----------
    A1 : array_like, shape (n, n)
        Matrix of the error dynamics before output injection.
    C : array_like, shape (p, n)
        Output matrix.
    D : array_like, shape (p, nv), optional
        Measurement-disturbance matrix; adds ``L D = 0``.
    dt : None, True or float, optional
        ``None`` (or 0, False) for continuous time; ``True`` or a positive
        sampling period for discrete time.
    decay : float, optional
        Discrete: the poles' radius bound (0 < decay <= 1). Continuous: the
        minimum decay rate (decay >= 0).
    solver : str, optional
        An installed cvxpy solver (e.g. ``"CLARABEL"``, ``"SCS"``). By default
        Clarabel, then SCS when Clarabel returns no accurate solution (it fails,
        is inaccurate or reports infeasibility).
    fixed_modes : array_like, optional
        The modes no gain can move, when known (the designs pass the
        invariant zeros); by default the unobservable modes of the balanced
        pair ``(A1, N C)``.

    Returns
    -------
    LMIResult
        ``L`` (projected exactly onto ``L D = 0``: solvers meet equality
        constraints only to about 1e-8) and the certificate ``P``.

    Raises
    ------
    LMIInfeasibleError
        The LMI has no solution: no gain of this form achieves the bound
        (also when a mode that no gain can move lies on or beyond it; the
        message names the mode).
    ValueError
        ``uio_teach.lmi.LMISolverError`` (a ``ValueError``, not an
        ``LMIInfeasibleError``): the solver failed numerically or returned a
        gain that does not meet the bound; this is not a proof of infeasibility.
        Otherwise: a matrix of the wrong shape or with complex or non-finite entries,
        ``dt`` not None/True/a positive number, ``solver`` not installed,
        ``decay`` not a number in range.

    Notes
    -----
    **Scaling.** ``A1`` is first balanced by a diagonal similarity ``T`` of
    powers of 2 (:func:`scipy.linalg.matrix_balance`); the LMI is solved for
    ``(T^-1 A1 T, C T)`` and ``L = T L_s``, ``P = T^-1 P_s T^-1`` are returned.
    **Strict margin.** Every gain returned is verified: with ``decay`` given,
    all poles meet the bound (to ``1e-6``); without it, every pole lies at
    least ``STRICT_MARGIN = 1e-9`` (relative) inside the stability region. A
    solution on the boundary (the LMI in discrete time is non-strict) is
    solved again with ``... <= -0.01 I``.
    **When the solver fails.** A gain placed by pole placement that meets the
    bound, with its Lyapunov certificate (a solution of the LMI), is returned
    instead; only when there is none is the failure raised
    (``LMIUndecidedError``, an ``LMISolverError``) or the infeasibility.

    Examples
    --------
    >>> import numpy as np
    >>> import uio_teach as ut
    >>> L, P = ut.lmi_gain([[1.2, 0.0], [0.0, 0.5]], [[1.0, 0.0]], dt=True)
    >>> bool(np.max(np.abs(np.linalg.eigvals([[1.2, 0.0], [0.0, 0.5]] - L @ [[1.0, 0.0]]))) < 1)
    True
    """
    A1 = as_matrix("A1", A1)
    n = A1.shape[0]
    if A1.shape[1] != n:
        raise InputError(f"A1 has shape {A1.shape}, expected a square (n, n) matrix")
    C = as_matrix("C", C, None, n, vector="row", what="p x n")
    p = C.shape[0]
    D = None if D is None else as_matrix("D", D, p, None, what="p x nv")
    has_d = D is not None and D.shape[1] > 0
    discrete = _check_dt(dt)
    decay = _check_decay(decay, discrete)
    solvers = _check_solver(solver)
    if discrete:
        bound = f"poles inside radius {decay if decay is not None else 1}"
    else:
        bound = f"poles left of {-(decay or 0.0)}"
    with_d = " with L D = 0" if has_d else ""

    # modes no gain can move: on or beyond the bound, the LMI is infeasible (say which);
    # decided on the balanced pair, so that the verdict does not depend on the units
    pair = balanced_pair(A1, C, D if has_d else np.zeros((p, 0)))
    fixed = pair.fixed_modes if fixed_modes is None else np.asarray(fixed_modes, complex)
    bad = [z for z in fixed if not _meets(np.array([z]), discrete, decay)]
    if bad:
        raise LMIInfeasibleError(
            f"the LMI is infeasible: no observer gain achieves {bound}{with_d}: the mode(s) "
            + ", ".join(format_complex(z) for z in bad)
            + " cannot be moved by any gain (unobservable from the outputs"
            + (" that D leaves free" if has_d else "")
            + ") and lie on or beyond that bound",
            "infeasible",
        )

    # scale: a diagonal similarity (powers of 2) balances A1; undone on L and P below
    t = _balance(A1)
    As = A1 / t[:, None] * t[None, :]
    Cs = C * t[None, :]
    Dd = D if has_d else None
    try:
        L, P = _solve(As, Cs, Dd, discrete, decay, solvers, bound, with_d)
        if not _meets(np.linalg.eigvals(As - L @ Cs), discrete, decay):
            # a non-strict LMI may return a gain on the boundary: ask again with a strict margin
            L, P = _solve(As, Cs, Dd, discrete, decay, solvers, bound, with_d, strict=True)
        if not _meets(np.linalg.eigvals(As - L @ Cs), discrete, decay):
            raise LMISolverError("the solver's gain misses the bound", "inaccurate")
    except LMIError as err:
        # cross-check: a placed gain that meets the bound, with its Lyapunov certificate,
        # is a solution of the LMI; the solver's word is then not the last one
        placed = placed_solution(A1, C, Dd, discrete, decay, pair=pair)
        if placed is not None:
            # already in the plant's units: express it in the balanced ones undone below
            L, P = placed[0] / t[:, None], placed[1] * t[:, None] * t[None, :]
        elif isinstance(err, LMIInfeasibleError):
            raise
        else:
            raise LMIUndecidedError(
                f"the solver could not decide whether a gain achieves {bound}{with_d} "
                f"({err}); no placed gain meets the bound either. This is not a proof of "
                "infeasibility: try solver='SCS', another decay, or scale the system",
                err.status,
            ) from None
    # undo the scaling: A1 = T As T^-1 with T = diag(t), so L = T Ls and P = T^-1 Ps T^-1
    L = t[:, None] * L
    P = P / t[:, None] / t[None, :]
    if has_d:
        L = L - L @ D @ pinv(D)
    with np.errstate(all="ignore"):
        obtained = np.linalg.eigvals(A1 - L @ C) if np.all(np.isfinite(L)) else None
    if obtained is None or not _meets(obtained, discrete, decay):
        worst = (
            "a non-finite gain"
            if obtained is None
            else "poles "
            + ", ".join(
                format_complex(z) for z in obtained[~_meets_each(obtained, discrete, decay)]
            )
        )
        raise LMISolverError(
            f"the LMI solver returned a gain that does not achieve {bound}{with_d} ({worst}): "
            "a numerical failure, not a proof of infeasibility; try solver='SCS' or scale the "
            "system",
            "inaccurate",
        )
    return LMIResult(L=L, P=P)


def _meets_each(z: np.ndarray, discrete: bool, decay: float | None) -> np.ndarray:
    """Elementwise: the pole meets the bound (strictly stable when no decay is asked)."""
    z = np.asarray(z, complex)
    if decay is None:
        return is_stable(z, discrete)
    if discrete:
        return np.abs(z) <= decay + tols.DECAY_RTOL * max(1.0, decay)
    # relative to the decay rate and the pole's own size: the same in any unit of time
    return z.real <= -decay + tols.DECAY_RTOL * np.maximum(decay, np.abs(z))


def _meets(z: np.ndarray, discrete: bool, decay: float | None) -> bool:
    return bool(np.all(_meets_each(z, discrete, decay)))


def _solve(A1, C, D, discrete, decay, solvers, bound, with_d, strict=False):
    """One cvxpy solve of the LMI; returns ``(L, P)`` or raises an LMI error."""
    import cvxpy as cp  # deferred on purpose: cvxpy takes half a second to import

    n, p = C.shape[1], C.shape[0]
    P = cp.Variable((n, n), symmetric=True)
    Y = cp.Variable((n, p))
    eps = 0.01
    cons = [P >> eps * np.eye(n)]
    X = P @ A1 - Y @ C
    if discrete:
        rho2 = 1.0 if decay is None else float(decay) ** 2
        LMI = cp.bmat([[-rho2 * P, X.T], [X, -P]])
        margin = eps * np.eye(2 * n) if strict else 0
        cons.append(0.5 * (LMI + LMI.T) << -margin)
    else:
        alpha = 0.0 if decay is None else float(decay)
        LMI = X + X.T + 2 * alpha * P
        cons.append(0.5 * (LMI + LMI.T) << -eps * np.eye(n))
    if D is not None:
        cons.append(Y @ D == 0)
    prob = cp.Problem(cp.Minimize(0), cons)
    # Clarabel is the default; on infeasible LMIs it sometimes stops with a numerical
    # failure instead of a certificate, so SCS is asked next to classify the problem.
    # An inaccurate status ("optimal_inaccurate", "infeasible_inaccurate") decides nothing:
    # the next solver is asked. Only an accurate "infeasible" is a proof.
    errors = []
    inaccurate = None
    proof = None
    for name in solvers:
        try:
            with warnings.catch_warnings():
                warnings.simplefilter("ignore")  # "solution may be inaccurate": verified below
                prob.solve(solver=name)
        except cp.error.SolverError as exc:
            errors.append(f"{name}: {exc}")
            continue
        if prob.status == "optimal":
            return _gain_from(P.value, Y.value)
        if prob.status == "optimal_inaccurate" and inaccurate is None:
            inaccurate = _gain_from(P.value, Y.value)
        if prob.status == "infeasible":
            proof = name
        errors.append(f"{name}: status {prob.status}")
    if inaccurate is not None:
        return inaccurate  # verified by the caller
    if proof is not None:
        raise LMIInfeasibleError(
            f"the LMI is infeasible ({proof}): no observer gain achieves {bound}{with_d}",
            "infeasible",
        )
    raise LMISolverError(
        "the LMI solver failed (" + "; ".join(errors) + "): a numerical failure, not a "
        "proof of infeasibility; try another solver= or scale the system",
        "solver_error" if not any("status" in e for e in errors) else "inaccurate",
    )


def _gain_from(Pval: np.ndarray, Yval: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    Pv = 0.5 * (Pval + Pval.T)
    return np.linalg.solve(Pv, Yval), Pv


def placed_solution(
    A1: np.ndarray,
    C: np.ndarray,
    D: np.ndarray | None,
    discrete: bool,
    decay: float | None,
    pair: BalancedPair | None = None,
) -> tuple[np.ndarray, np.ndarray] | None:
    """A solution of the LMI from a placed gain and its Lyapunov certificate, or None.

    The movable poles are placed well inside the bound (distinct, real) on
    the balanced pair (:func:`uio_teach.placement.place_pair_poles`), the
    fixed modes are checked against it, and ``P`` solves the Lyapunov
    equation of ``A1 - L C``, scaled to meet ``P >= 0.01 I`` and the LMI's
    margin. Used to cross-check a solver that reports infeasibility or
    cannot decide.

    Parameters
    ----------
    A1, C, D : numpy.ndarray
        As for :func:`lmi_gain` (``D`` None when absent).
    discrete : bool
    decay : float or None
    pair : BalancedPair, optional
        The balanced pair of ``(A1, C, D)``, when already computed.

    Returns
    -------
    (L, P) or None

    Examples
    --------
    >>> import numpy as np
    >>> from uio_teach.lmi import placed_solution
    >>> L, P = placed_solution(np.array([[1.2]]), np.array([[1.0]]), None, True, None)
    >>> bool(abs(1.2 - L[0, 0]) < 1)
    True
    """
    n, p = A1.shape[0], C.shape[0]
    if pair is None:
        pair = balanced_pair(A1, C, D if D is not None else np.zeros((p, 0)))
    k = pair.movable
    if discrete:
        rho = 1.0 if decay is None else float(decay)
        poles = 0.5 * rho * np.linspace(0.2, 1.0, k)
    else:
        alpha = 0.0 if decay is None else float(decay)
        size = max(1.0, float(np.linalg.norm(A1, 2)))
        poles = -alpha - size * np.linspace(0.5, 1.0, k)
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            L = place_pair_poles(pair, poles)[0] if k else np.zeros((n, p))
        F = A1 - L @ C
        if not np.all(np.isfinite(F)) or not _meets(np.linalg.eigvals(F), discrete, decay):
            return None
        if discrete:
            P = sla.solve_discrete_lyapunov((F / rho).T, np.eye(n))
        else:
            P = sla.solve_continuous_lyapunov((F + alpha * np.eye(n)).T, -np.eye(n))
    except (ValueError, np.linalg.LinAlgError):
        return None
    P = 0.5 * (P + P.T)
    lo = float(np.min(np.linalg.eigvalsh(P))) if n else 1.0
    if not np.isfinite(lo) or lo <= 0:
        return None
    return L, P * max(0.01 / lo, 0.01)
