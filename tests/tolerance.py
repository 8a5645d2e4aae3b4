"""Tolerances of the tests, derived from the computation compared, never from this CPU's round-off.

Floating-point results differ in their last bits between CPU models, BLAS kernels and thread
counts (the order in which a sum is taken). A comparison of two floating-point results is
therefore bounded by what rounding *can* produce in the computation, estimated from its size:

    tolerance = MARGIN * eps * terms * steps * gain * size

``size``
    the largest term that enters the result (not the result: ``x - xhat`` is as uncertain as
    ``x`` is large, however small the difference);
``terms``
    the number of terms summed into each entry (``n`` for a product with an ``n``-vector, ``n**2``
    for a matrix exponential or a factorization of an ``n``-by-``n`` matrix);
``steps``
    the number of dependent stages (samples of a recursion, factors of a product);
``gain``
    how much the computation can amplify an error made on the way (the largest norm of the
    error dynamics' transition matrix, a condition number).

``eps * terms * steps * gain * size`` is the classical worst-case bound on the rounding of such a
computation (Higham, *Accuracy and Stability of Numerical Algorithms*, ch. 3); any IEEE-conforming
BLAS, whatever its summation order, stays within it. ``MARGIN`` leaves a hundredfold room above
it, so a failure means a wrong result, not another CPU.
"""

from __future__ import annotations

import numpy as np

EPS = float(np.finfo(float).eps)
MARGIN = 100.0


def roundoff(size: float, *, terms: float = 1, steps: float = 1, gain: float = 1.0) -> float:
    """``MARGIN`` times the worst rounding error of a computation of this ``size`` and shape."""
    return MARGIN * EPS * float(terms) * float(steps) * max(float(gain), 1.0) * float(size)


def size_of(*arrays: object) -> float:
    """The largest finite absolute entry of ``arrays`` (at least the smallest normal number)."""
    sizes = [np.abs(np.asarray(a, dtype=complex if np.iscomplexobj(a) else float)) for a in arrays]
    finite = [float(np.max(s[np.isfinite(s)], initial=0.0)) for s in sizes]
    return max([*finite, np.finfo(float).tiny])


def assert_rounding_close(
    actual: object,
    expected: object,
    *,
    size: float | None = None,
    terms: float = 1,
    steps: float = 1,
    gain: float = 1.0,
    what: str = "",
) -> None:
    """Assert that ``actual`` and ``expected`` differ by no more than rounding can explain.

    ``size`` defaults to the larger of the two compared arrays (give it when the terms that
    entered the computation were larger than its result).
    """
    actual = np.asarray(actual)
    expected = np.broadcast_to(np.asarray(expected), actual.shape)
    if size is None:
        size = size_of(actual, expected)
    tol = roundoff(size, terms=terms, steps=steps, gain=gain)
    gap = float(np.max(np.abs(actual - expected), initial=0.0))
    assert gap <= tol, (
        f"{what + ': ' if what else ''}differ by {gap:.3g}, more than rounding explains: "
        f"{tol:.3g} = {MARGIN:g} x eps x {terms:g} terms x {steps:g} steps x gain "
        f"{max(gain, 1.0):.3g} x size {size:.3g}"
    )


def eigenvector_condition(F: object) -> float:
    """``cond(V)`` of ``F = V diag(lambda) V^-1``: bounds ``||exp(F t)||`` (``||F^k||``) for a
    stable ``F``, and how far rounding in the state can be amplified on the way."""
    F = np.atleast_2d(np.asarray(F, float))
    if F.size == 0:
        return 1.0
    return float(np.linalg.cond(np.linalg.eig(F)[1]))


def assert_same_run(actual: object, expected: object, *runs: object, what: str = "") -> None:
    """Two simulations (or quantities drawn from them) that must agree to rounding.

    The size is the largest state or estimate of ``runs`` (errors and residuals are differences
    of those), each of the samples is a product with the ``n``-state transition matrix (itself an
    exponential: ``n**2`` terms), and the error dynamics amplify rounding by at most the
    condition of their eigenvectors.
    """
    first = runs[0]
    n = first.states.shape[0]
    size = size_of(*(r.states for r in runs), *(r.estimates for r in runs))
    observer = getattr(first, "observer", None)
    gain = eigenvector_condition(observer.error_matrix) if observer is not None else 1.0
    assert_rounding_close(
        actual, expected, size=size, terms=n * n, steps=first.time.size, gain=gain, what=what
    )


def assert_zero(residual: object, *factors: object, terms: float, gain: float = 1.0) -> None:
    """An identity ``R = 0`` whose residual is formed from products of ``factors``.

    The size of its terms is the product of the factors' 2-norms (the largest the entries of a
    product can be); ``gain`` is the condition number of whatever was solved to build them.
    """
    size = 1.0
    for factor in factors:
        size *= float(np.linalg.norm(np.atleast_2d(np.asarray(factor, float)), 2))
    assert_rounding_close(residual, 0.0, size=size, terms=terms, gain=gain)


def eigenvalue_roundoff(F: object) -> float:
    """``MARGIN`` times the worst rounding of ``F``'s computed eigenvalues (absolute).

    A backward-stable eigensolver returns the eigenvalues of ``F + dF`` with
    ``||dF|| <= n eps ||F||``; an eigenvalue moves by at most its condition number
    ``1 / |y^H x|`` (unit left and right eigenvectors) times that.
    """
    import scipy.linalg as sla

    F = np.atleast_2d(np.asarray(F, float))
    _, left, right = sla.eig(F, left=True, right=True)
    left = left / np.linalg.norm(left, axis=0)
    right = right / np.linalg.norm(right, axis=0)
    with np.errstate(divide="ignore"):
        kappa = 1.0 / np.abs(np.sum(left.conj() * right, axis=0))
    return roundoff(np.linalg.norm(F, 2), terms=F.shape[0], gain=float(np.max(kappa)))


def matched_distance(a: object, b: object) -> float:
    """Largest distance between two multisets of complex numbers (poles, zeros), each of ``a``
    matched greedily to the nearest not yet matched of ``b``; they must be as many."""
    a, b = list(np.asarray(a, complex).ravel()), list(np.asarray(b, complex).ravel())
    assert len(a) == len(b), (a, b)
    worst = 0.0
    for x in a:
        d = [abs(x - y) for y in b]
        i = int(np.argmin(d))
        worst = max(worst, d[i])
        b.pop(i)
    return worst
