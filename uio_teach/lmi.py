"""Observer gains from linear matrix inequalities (cvxpy), as in the discrete case study."""

from __future__ import annotations

from typing import NamedTuple

import cvxpy as cp
import numpy as np

from ._validation import as_matrix
from .linalg import pinv

__all__ = ["LMIInfeasibleError", "LMIResult", "lmi_gain"]


class LMIInfeasibleError(ValueError):
    """The LMI has no solution (or the solver failed); ``.status`` is the solver's word."""

    def __init__(self, message: str, status: str) -> None:
        super().__init__(message)
        self.status = status


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


def lmi_gain(
    A1,
    C,
    *,
    D=None,
    dt: float | bool | None = None,
    decay: float | None = None,
    solver: str | None = None,
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
    D : array_like, shape (p, r), optional
        Measurement-disturbance matrix; adds ``L D = 0``.
    dt : None, True or float, optional
        ``None`` for continuous time, otherwise discrete.
    decay : float, optional
        Discrete: the poles' radius bound (0 < decay <= 1). Continuous: the
        minimum decay rate (decay >= 0).
    solver : str, optional
        A cvxpy solver name. By default Clarabel, then SCS if Clarabel
        fails numerically (as it may on an infeasible LMI).

    Returns
    -------
    LMIResult
        ``L`` (projected exactly onto ``L D = 0``: solvers meet equality
        constraints only to about 1e-8) and the certificate ``P``.

    Raises
    ------
    LMIInfeasibleError
        The LMI has no solution: no gain of this form achieves the bound.

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
        raise ValueError(f"A1 has shape {A1.shape}, expected a square (n, n) matrix")
    C = as_matrix("C", C, None, n, vector="row", what="p x n")
    p = C.shape[0]
    D = None if D is None else as_matrix("D", D, p, None, what="p x r")
    discrete = dt is not None and dt is not False and dt != 0
    if decay is not None:
        if not np.isfinite(decay) or decay < 0 or (discrete and not 0 < decay <= 1):
            rng = "0 < decay <= 1 (a radius)" if discrete else "decay >= 0 (a rate)"
            raise ValueError(f"decay must satisfy {rng}, got {decay!r}")
    P = cp.Variable((n, n), symmetric=True)
    Y = cp.Variable((n, p))
    eps = 0.01
    cons = [P >> eps * np.eye(n)]
    if discrete:
        rho2 = 1.0 if decay is None else float(decay) ** 2
        X = P @ A1 - Y @ C
        LMI = cp.bmat([[-rho2 * P, X.T], [X, -P]])
        cons.append(0.5 * (LMI + LMI.T) << 0)
    else:
        alpha = 0.0 if decay is None else float(decay)
        X = P @ A1 - Y @ C
        LMI = X + X.T + 2 * alpha * P
        cons.append(0.5 * (LMI + LMI.T) << -eps * np.eye(n))
    if D is not None and D.shape[1]:
        cons.append(Y @ D == 0)
    prob = cp.Problem(cp.Minimize(0), cons)
    # Clarabel is the default; on infeasible LMIs it sometimes stops with a numerical
    # failure instead of a certificate, so SCS is asked next to classify the problem.
    errors = []
    for name in [solver] if solver else ["CLARABEL", "SCS"]:
        try:
            prob.solve(solver=name)
        except cp.error.SolverError as exc:
            errors.append(f"{name}: {exc}")
            continue
        break
    else:
        raise LMIInfeasibleError("the LMI solver failed: " + "; ".join(errors), "solver_error")
    if prob.status not in ("optimal", "optimal_inaccurate"):
        bound = (
            f"poles inside radius {decay if decay is not None else 1}"
            if discrete
            else f"poles left of {-(decay or 0.0)}"
        )
        with_d = " with L D = 0" if D is not None and D.shape[1] else ""
        raise LMIInfeasibleError(
            f"the LMI is {prob.status}: no observer gain achieves {bound}{with_d}", prob.status
        )
    Pv = 0.5 * (P.value + P.value.T)
    L = np.linalg.solve(Pv, Y.value)
    if D is not None and D.shape[1]:
        L = L - L @ D @ pinv(D)
    return LMIResult(L=L, P=Pv)
