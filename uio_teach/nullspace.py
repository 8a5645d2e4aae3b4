"""Fault detection filters by the nullspace method (Varga, *Solving Fault Diagnosis Problems*).

A plant with known inputs ``u``, disturbances ``d`` and faults ``f``::

    y = Gu(s) u + Gd(s) d + Gf(s) f

(a state-space realization ``x' = A x + Bu u + Bd d + Bf f``,
``y = C x + Du u + Dd d + Df f``, feedthrough allowed; ``s`` is the
derivative in continuous time, the forward shift in discrete time). A
residual generator ``r = Q(s) [y; u]`` must give ``r = Rf(s) f`` whatever
``u`` and ``d`` do, that is::

    Q(s) [[Gu, Gd], [I, 0]] = 0,        Rf(s) = Q(s) [[Gf], [0]]

The rows of ``Q`` therefore lie in the left nullspace of
``[[Gu, Gd], [I, 0]]``. Its dimension is ``p - rank Gd(s)`` (the normal rank)
and it has a basis of polynomial rows ``[w_y(s), w_u(s)]`` with
``w_y(s) Gd(s) = 0`` and ``w_u(s) = -w_y(s) Gu(s)``. A row of degree ``k``
is a vector ``w = [w_0 ... w_k]`` with::

    w [O_k, T_d,k] = 0,    O_k = [C; C A; ...; C A^k]

where ``T_d,k`` is the block Toeplitz matrix of the Markov parameters
``Dd, C Bd, C A Bd, ...`` (the parity relations of Chow and Willsky: the
``i``-th block row of ``O_k x + T_k [input; s input; ...]`` is ``s^i y``).
:func:`design_nullspace_filter` finds a basis of least degrees degree by
degree (``k = 0, 1, ...``), then divides each row of degree ``k`` by a
polynomial of degree ``k`` whose roots are the requested poles: a stable,
proper left coprime factorization of the polynomial basis, with every pole
placed. Because ``w O_k = 0``, the same row turns the fault's path into a
polynomial too (``w T_f,k``), so ``Rf`` shares ``Q``'s dynamics and order.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from numbers import Integral
from typing import Any

import numpy as np

from . import tolerances as tols
from ._display import fit_lines, format_complex
from ._validation import as_matrix, as_poles, read_only
from .detection import Fault
from .errors import UIOTeachError
from .linalg import is_stable, left_null, rank_decision, sort_poles
from .plant import Plant
from .simulation import check_timepts, input_samples, linear_response

__all__ = [
    "FaultModel",
    "NullspaceFilter",
    "NullspaceFilterError",
    "FilterResponse",
    "fault_model",
    "design_nullspace_filter",
    "decoupling_gap",
]


class NullspaceFilterError(UIOTeachError, ValueError):
    """No residual generator exists, or the data do not define one (says which and why).

    Examples
    --------
    >>> import uio_teach as ut
    >>> issubclass(ut.NullspaceFilterError, ValueError)
    True
    """


@dataclass(frozen=True)
class FaultModel:
    """A plant with known inputs, disturbances and faults, as matrices.

    ``x' = A x + Bu u + Bd d + Bf f``, ``y = C x + Du u + Dd d + Df f``
    (``x[k+1] = ...`` in discrete time). Build one with :func:`fault_model`.

    Attributes
    ----------
    A, Bu, Bd, Bf, C, Du, Dd, Df : numpy.ndarray
        The matrices (read-only).
    dt : None, True or float
        ``None`` for continuous time, else the sampling period (``True``: unspecified).
    fault_names : tuple of str
        One name per fault (column of ``Bf`` and ``Df``).

    Examples
    --------
    >>> import uio_teach as ut
    >>> model = ut.fault_model(ut.examples.pa9(), (ut.examples.pa9().B, None))
    >>> model.Bf.shape, model.Df.shape, model.fault_names
    ((3, 2), (2, 2), ('f[0]', 'f[1]'))
    """

    A: np.ndarray
    Bu: np.ndarray
    Bd: np.ndarray
    Bf: np.ndarray
    C: np.ndarray
    Du: np.ndarray
    Dd: np.ndarray
    Df: np.ndarray
    dt: float | bool | None
    fault_names: tuple[str, ...]

    @property
    def n(self) -> int:
        """Number of states."""
        return self.A.shape[0]

    @property
    def p(self) -> int:
        """Number of outputs."""
        return self.C.shape[0]

    @property
    def mu(self) -> int:
        """Number of known inputs."""
        return self.Bu.shape[1]

    @property
    def md(self) -> int:
        """Number of disturbances."""
        return self.Bd.shape[1]

    @property
    def mf(self) -> int:
        """Number of faults."""
        return self.Bf.shape[1]

    @property
    def is_discrete(self) -> bool:
        """True in discrete time."""
        return self.dt is not None

    def __repr__(self) -> str:
        kind = "discrete-time" if self.is_discrete else "continuous-time"
        return (
            f"FaultModel({kind}, n={self.n}, p={self.p}, mu={self.mu}, md={self.md}, mf={self.mf})"
        )


def _indices(name: str, value: Any, size: int) -> list[int]:
    if value is None:
        return []
    if isinstance(value, (bool, Integral)):
        value = [value]
    try:
        items = list(value)
    except TypeError:
        raise NullspaceFilterError(
            f"{name} must be a list of input indices, got {type(value).__name__}"
        ) from None
    out = []
    for i in items:
        if isinstance(i, bool) or not isinstance(i, Integral):
            raise NullspaceFilterError(f"{name} must hold integer input indices, got {i!r}")
        if not 0 <= int(i) < size:
            raise NullspaceFilterError(
                f"{name}: input {i} is out of range: the system has {size} inputs (0 to {size - 1})"
            )
        out.append(int(i))
    return out


def _from_plant(plant: Plant, faults: Any) -> FaultModel:
    n, p = plant.n, plant.p
    if isinstance(faults, Fault):
        faults = [faults]
    if (
        isinstance(faults, Sequence)
        and not isinstance(faults, (str, bytes))
        and len(faults)
        and all(isinstance(f, Fault) for f in faults)
    ):
        for f in faults:
            if f.state_direction.shape != (n,) or f.output_direction.shape != (p,):
                raise NullspaceFilterError(
                    f"fault {f.name!r} was built for a plant with n = {f.state_direction.size} "
                    f"and p = {f.output_direction.size}, but this plant has n = {n}, p = {p}"
                )
        Bf = np.column_stack([f.state_direction for f in faults])
        Df = np.column_stack([f.output_direction for f in faults])
        names = tuple(f.name for f in faults)
    elif isinstance(faults, tuple) and len(faults) == 2:
        R1, R2 = faults
        if R1 is None and R2 is None:
            raise NullspaceFilterError("faults: give the state or the output fault matrix")
        k = None
        if R1 is not None:
            R1 = as_matrix("R1 (state fault matrix)", R1, n, None, what="n x mf")
            k = R1.shape[1]
        if R2 is not None:
            R2 = as_matrix("R2 (output fault matrix)", R2, p, k, what="p x mf")
            k = R2.shape[1]
        Bf = np.zeros((n, k)) if R1 is None else R1
        Df = np.zeros((p, k)) if R2 is None else R2
        names = tuple(f"f[{j}]" for j in range(k))
    else:
        raise NullspaceFilterError(
            "faults must be a list of Fault objects (ut.actuator_fault, ut.sensor_fault, "
            "ut.process_fault) or a pair (R1, R2) of the state and output fault matrices, got "
            f"{type(faults).__name__}"
        )
    if Bf.shape[1] == 0:
        raise NullspaceFilterError("faults: no fault given (a filter must detect something)")
    return FaultModel(
        A=plant.A,
        Bu=plant.B,
        Bd=np.hstack([plant.E, np.zeros((n, plant.nv))]),
        Bf=read_only(Bf),
        C=plant.C,
        Du=np.zeros((p, plant.m)),
        Dd=np.hstack([np.zeros((p, plant.q)), plant.D]),
        Df=read_only(Df),
        dt=plant.dt,
        fault_names=names,
    )


def _from_lti(sys: Any, faults: Any, known: Any, disturbances: Any) -> FaultModel:
    import control as ct  # deferred on purpose: python-control takes a second to import

    ss = ct.ss(sys)
    m = ss.ninputs
    f_idx = _indices("faults", faults, m)
    u_idx = _indices("known", known, m)
    if disturbances is None:
        d_idx = [i for i in range(m) if i not in f_idx and i not in u_idx]
    else:
        d_idx = _indices("disturbances", disturbances, m)
    used = f_idx + u_idx + d_idx
    if len(set(used)) != len(used):
        raise NullspaceFilterError(
            "an input is listed twice among the faults, the known inputs and the disturbances"
        )
    if not f_idx:
        raise NullspaceFilterError("faults: no fault input given (a filter must detect something)")
    n = ss.nstates
    A = np.asarray(ss.A, float).reshape(n, n)
    B = np.asarray(ss.B, float).reshape(n, m)
    C = np.asarray(ss.C, float).reshape(ss.noutputs, n)
    D = np.asarray(ss.D, float).reshape(ss.noutputs, m)
    for name, M in (("A", A), ("B", B), ("C", C), ("D", D)):
        if not np.all(np.isfinite(M)):
            raise NullspaceFilterError(f"{name} of the system has a non-finite entry")
    dt = None if not ss.dt else (True if ss.dt is True else float(ss.dt))
    labels = list(ss.input_labels)
    return FaultModel(
        A=read_only(A),
        Bu=read_only(B[:, u_idx]),
        Bd=read_only(B[:, d_idx]),
        Bf=read_only(B[:, f_idx]),
        C=read_only(C),
        Du=read_only(D[:, u_idx]),
        Dd=read_only(D[:, d_idx]),
        Df=read_only(D[:, f_idx]),
        dt=dt,
        fault_names=tuple(labels[i] for i in f_idx),
    )


def fault_model(
    plant: Any,
    faults: Any,
    *,
    known: Any = None,
    disturbances: Any = None,
) -> FaultModel:
    """The plant, its known inputs, disturbances and faults as one :class:`FaultModel`.

    Parameters
    ----------
    plant : Plant or python-control system
        A :class:`~uio_teach.Plant` (known inputs through ``B``, disturbances
        through ``E`` and ``D``, no feedthrough of ``u``), or anything
        ``control.ss`` accepts (a ``StateSpace`` or ``TransferFunction``, with
        feedthrough), whose inputs are split by ``faults``, ``known`` and
        ``disturbances``.
    faults : list of Fault, pair of matrices, or input indices
        For a ``Plant``: a list of :class:`~uio_teach.Fault` objects, or a pair
        ``(R1, R2)`` of the state fault matrix (n x mf) and the output fault
        matrix (p x mf), either may be ``None``. For a python-control system:
        the indices of its fault inputs.
    known : list of int, optional
        For a python-control system: the indices of its known inputs.
    disturbances : list of int, optional
        For a python-control system: the indices of its disturbances; default
        every input that is neither a fault nor known.

    Returns
    -------
    FaultModel

    Raises
    ------
    NullspaceFilterError
        If the faults or the input indices do not fit the plant.

    Examples
    --------
    >>> import control as ct
    >>> import uio_teach as ut
    >>> sys = ct.ss([[-1.0]], [[1.0, 1.0, 0.0]], [[1.0], [1.0]], [[0, 0, 0], [0, 0, 1.0]])
    >>> ut.fault_model(sys, [2], known=[0])
    FaultModel(continuous-time, n=1, p=2, mu=1, md=1, mf=1)
    """
    if isinstance(plant, Plant):
        if known is not None or disturbances is not None:
            raise NullspaceFilterError(
                "known and disturbances select inputs of a python-control system; a Plant's "
                "known inputs are its B and its disturbances its E and D"
            )
        return _from_plant(plant, faults)
    if isinstance(plant, FaultModel):
        return plant
    if not hasattr(plant, "ninputs"):
        raise NullspaceFilterError(
            "plant must be a uio_teach Plant or a python-control system (StateSpace or "
            f"TransferFunction), got {type(plant).__name__}"
        )
    return _from_lti(plant, faults, known, disturbances)


# the nullspace basis ------------------------------------------------------------------------


def _toeplitz(A: np.ndarray, B: np.ndarray, C: np.ndarray, D: np.ndarray, k: int) -> np.ndarray:
    """Block rows ``i = 0..k`` of ``s^i y`` in terms of ``[in; s in; ...; s^k in]``."""
    p, m = D.shape
    markov = [D] + [C @ np.linalg.matrix_power(A, j) @ B for j in range(k)]
    T = np.zeros((p * (k + 1), m * (k + 1)))
    for i in range(k + 1):
        for j in range(i + 1):
            T[i * p : (i + 1) * p, j * m : (j + 1) * m] = markov[i - j]
    return T


def _observability(A: np.ndarray, C: np.ndarray, k: int) -> np.ndarray:
    blocks, M = [], C
    for _ in range(k + 1):
        blocks.append(M)
        M = M @ A
    return np.vstack(blocks) if blocks else np.zeros((0, A.shape[0]))


def _shift(w: np.ndarray, p: int, times: int, length: int) -> np.ndarray:
    out = np.zeros(length)
    out[times * p : times * p + w.size] = w
    return out


def _normal_rank(A: np.ndarray, B: np.ndarray, C: np.ndarray, D: np.ndarray, scale: float) -> int:
    """Normal rank of ``C (sI - A)^-1 B + D``: the pencil's rank at generic points, minus n."""
    n = A.shape[0]
    if B.shape[1] == 0:
        return 0
    best = 0
    # two fixed points of no special meaning, on the scale of A (generic for any data)
    for lam in (scale * (0.6180339887 + 0.7861513778j), scale * (-0.2360679775 + 1.3247179572j)):
        pencil = np.block([[A - lam * np.eye(n), B], [C, D]])
        best = max(best, rank_decision(pencil).rank - n)
    return best


@dataclass(frozen=True)
class _Basis:
    rows: list[np.ndarray]  # each w = [w_0 ... w_k] (scaled time), length p (k + 1)
    degrees: list[int]


def _least_degree_basis(A: np.ndarray, Bd: np.ndarray, C: np.ndarray, Dd: np.ndarray, count: int):
    """Polynomial rows ``w`` with ``w [O_k, T_d,k] = 0``, of least degrees, ``count`` of them."""
    n, p = A.shape[0], C.shape[0]
    rows: list[np.ndarray] = []
    degrees: list[int] = []
    for k in range(n + 1):
        M = np.hstack([_observability(A, C, k), _toeplitz(A, Bd, C, Dd, k)])
        N = left_null(M)  # orthonormal rows
        length = p * (k + 1)
        shifted = [
            _shift(w, p, t, length)
            for w, deg in zip(rows, degrees, strict=True)
            for t in range(k - deg + 1)
        ]
        new = N.shape[0] - len(shifted)
        if new > 0:
            if shifted:
                Qs, _ = np.linalg.qr(np.array(shifted).T)
                P = N.T - Qs @ (Qs.T @ N.T)
            else:
                P = N.T
            U, _, _ = np.linalg.svd(P, full_matrices=False)
            for j in range(min(new, count - len(rows))):
                rows.append(U[:, j].copy())
                degrees.append(k)
        if len(rows) >= count:
            return _Basis(rows, degrees)
    raise NullspaceFilterError(  # pragma: no cover - the minimal indices are at most n
        f"found {len(rows)} of the {count} rows of the nullspace basis up to degree {n}: the "
        "data are too badly conditioned for the parity relations"
    )


# the filter ---------------------------------------------------------------------------------


def _companion_row(num: np.ndarray, den: np.ndarray):
    """Observer canonical form of ``num(s) / den(s)``: num (m, k + 1) ascending, den monic."""
    k = den.size - 1
    D = num[:, k].copy()
    if k == 0:
        return np.zeros((0, 0)), np.zeros((0, num.shape[0])), np.zeros((1, 0)), D[None, :]
    a = den[::-1]  # ascending: a_0 ... a_k (= 1)
    rem = num[:, :k] - np.outer(D, a[:k])  # ascending coefficients of num - D den
    A = np.zeros((k, k))
    A[:, 0] = -a[k - 1 :: -1][:k]
    A[: k - 1, 1:] = np.eye(k - 1)
    B = rem[:, ::-1].T  # rows: s^(k-1) ... s^0
    C = np.zeros((1, k))
    C[0, 0] = 1.0
    return A, B, C, D[None, :]


def _blockdiag(blocks: list[np.ndarray]) -> np.ndarray:
    rows = sum(b.shape[0] for b in blocks)
    cols = sum(b.shape[1] for b in blocks)
    out = np.zeros((rows, cols))
    i = j = 0
    for b in blocks:
        out[i : i + b.shape[0], j : j + b.shape[1]] = b
        i, j = i + b.shape[0], j + b.shape[1]
    return out


@dataclass(frozen=True)
class FilterResponse:
    """A run of the plant with a nullspace filter (``NullspaceFilter.simulate``).

    Signals have one row per channel and one column per time point.

    Attributes
    ----------
    time : numpy.ndarray
        Shape (N,).
    states : numpy.ndarray
        Shape (n, N): the plant's state.
    outputs : numpy.ndarray
        Shape (p, N): the measurements ``y`` (noise included).
    residual : numpy.ndarray
        Shape (rows, N): ``r = Q [y; u]``.
    u, d, f, noise : numpy.ndarray
        The samples applied.

    Examples
    --------
    >>> import numpy as np
    >>> import uio_teach as ut
    >>> plant = ut.examples.pa9()
    >>> filt = ut.design_nullspace_filter(plant, (plant.B, None), poles=[-4, -5])
    >>> filt.simulate(np.linspace(0, 1, 11)).residual.shape
    (1, 11)
    """

    time: np.ndarray
    states: np.ndarray
    outputs: np.ndarray
    residual: np.ndarray
    u: np.ndarray
    d: np.ndarray
    f: np.ndarray
    noise: np.ndarray


class NullspaceFilter:
    """A fault detection filter ``r = Q(s) [y; u]`` designed by the nullspace method.

    Built by :func:`design_nullspace_filter`; read-only.

    Attributes
    ----------
    Q : control.StateSpace
        The filter, inputs ``[y; u]`` (named ``y[i]``, ``u[j]``), outputs ``r[i]``.
    Rf : control.StateSpace
        The faults' map to the residual, ``r = Rf(s) f`` (inputs named after the faults).
    degrees : tuple of int
        The degree of each row of the polynomial nullspace basis (each row of
        ``Q`` has that many states).
    basis : tuple of numpy.ndarray
        Each row of the polynomial basis ``[w_y(s), w_u(s)]`` as its
        coefficients, shape (k + 1, p + mu), row ``i`` the coefficient of ``s^i``.
    fault_basis : tuple of numpy.ndarray
        ``w_y(s) Gf(s)`` of each row, a polynomial: shape (k + 1, mf).
    structure : numpy.ndarray
        Boolean, shape (rows, faults): fault ``j`` reaches residual ``i``.
    detected : tuple of bool
        Per fault: it reaches the residual (a column of ``Rf`` that is not zero).
    fault_names : tuple of str
    model : FaultModel
        The plant the filter was designed for.

    Examples
    --------
    >>> import uio_teach as ut
    >>> plant = ut.examples.pa9()
    >>> step = ut.signals.step(0.5, 5.0)
    >>> filt = ut.design_nullspace_filter(
    ...     plant,
    ...     [ut.actuator_fault(plant, 0, step), ut.sensor_fault(plant, 1, step)],
    ...     poles=[-2, -3],
    ... )
    >>> filt.degrees, filt.detected, filt.poles().real.round(9).tolist()
    ((2,), (True, True), [-3.0, -2.0])
    """

    def __init__(self, *, model, Q, Rf, degrees, basis, fault_basis, structure, detected, scale):
        object.__setattr__(self, "_model", model)
        object.__setattr__(self, "_Q", Q)
        object.__setattr__(self, "_Rf", Rf)
        object.__setattr__(self, "_degrees", tuple(degrees))
        object.__setattr__(self, "_basis", tuple(read_only(b) for b in basis))
        object.__setattr__(self, "_fault_basis", tuple(read_only(b) for b in fault_basis))
        object.__setattr__(self, "_structure", read_only(structure))
        object.__setattr__(self, "_detected", tuple(bool(x) for x in detected))
        object.__setattr__(self, "_scale", float(scale))

    def __setattr__(self, key: str, value: Any) -> None:
        raise AttributeError(
            "NullspaceFilter is read-only: Q and Rf are derived from one basis; design a new "
            "filter (ut.design_nullspace_filter) or scale this one (.scaled)"
        )

    model = property(lambda self: self._model, doc="The plant the filter was designed for.")
    Q = property(lambda self: self._Q, doc="The filter, a control.StateSpace (inputs [y; u]).")
    Rf = property(lambda self: self._Rf, doc="The faults' map to the residual, a StateSpace.")
    degrees = property(lambda self: self._degrees, doc="Degrees of the basis rows.")
    basis = property(lambda self: self._basis, doc="Coefficients of [w_y(s), w_u(s)] per row.")
    fault_basis = property(lambda self: self._fault_basis, doc="Coefficients of w_y(s) Gf(s).")
    structure = property(lambda self: self._structure, doc="Fault j reaches residual i.")
    detected = property(
        lambda self: self._detected, doc="True for each fault that reaches the residual."
    )

    @property
    def fault_names(self) -> tuple[str, ...]:
        """The faults' names, one per column of ``Rf``."""
        return self._model.fault_names

    @property
    def order(self) -> int:
        """The number of states of ``Q`` (and of ``Rf``), the sum of the degrees."""
        return int(sum(self._degrees))

    @property
    def undetected(self) -> tuple[str, ...]:
        """The faults no residual sees."""
        return tuple(n for n, d in zip(self.fault_names, self._detected, strict=True) if not d)

    def poles(self) -> np.ndarray:
        """The poles of ``Q`` (those of ``Rf``), sorted.

        Examples
        --------
        >>> import uio_teach as ut
        >>> filt = ut.design_nullspace_filter(
        ...     ut.examples.pa9(), (ut.examples.pa9().B, None), poles=[-4, -5]
        ... )
        >>> filt.poles().real.round(9).tolist()
        [-5.0, -4.0]
        """
        return sort_poles(np.linalg.eigvals(np.asarray(self._Q.A))) if self.order else np.zeros(0)

    def scaled(self, factors: Any) -> NullspaceFilter:
        """The same filter with residual ``i`` divided by ``factors[i]`` (a number: every one).

        A basis row is defined up to a factor; Varga's examples divide by
        ``Rf``'s first entry at infinity, for instance.

        Parameters
        ----------
        factors : float or array_like, shape (rows,)
            Non-zero, finite.

        Returns
        -------
        NullspaceFilter

        Examples
        --------
        >>> import uio_teach as ut
        >>> filt = ut.design_nullspace_filter(ut.examples.pa9(), (ut.examples.pa9().B, None),
        ...                                   poles=[-4, -5])
        >>> float(filt.scaled(2.0).Rf.D[0, 0] * 2.0 - filt.Rf.D[0, 0]) == 0.0
        True
        """
        import control as ct  # deferred on purpose: python-control takes a second to import

        rows = self._Q.noutputs
        c = np.broadcast_to(np.asarray(factors, dtype=float), (rows,)).copy()
        if not np.all(np.isfinite(c)) or np.any(c == 0):
            raise NullspaceFilterError(f"factors must be finite and non-zero, got {factors!r}")
        S = np.diag(1.0 / c)

        def scale(sys):
            return ct.ss(
                sys.A, sys.B, S @ sys.C, S @ sys.D, sys.dt,
                inputs=sys.input_labels, outputs=sys.output_labels, name=sys.name,
            )  # fmt: skip

        return NullspaceFilter(
            model=self._model,
            Q=scale(self._Q),
            Rf=scale(self._Rf),
            degrees=self._degrees,
            basis=[b / ci for b, ci in zip(self._basis, c, strict=True)],
            fault_basis=[b / ci for b, ci in zip(self._fault_basis, c, strict=True)],
            structure=self._structure,
            detected=self._detected,
            scale=self._scale,
        )

    def decoupling_gap(self, points: Any = None) -> float:
        """Largest ``|Q(s) [[Gu, Gd], [I, 0]]|`` at ``points``, relative to its terms' size.

        The defining property of the filter, judged on the returned ``Q`` and
        the plant's own matrices (not on the basis that built it). Zero in
        exact arithmetic; rounding leaves about ``eps`` times the conditioning.

        Parameters
        ----------
        points : array_like of complex, optional
            Values of ``s`` (or ``z``); default five points on the imaginary
            axis (the unit circle) on the plant's time scale.

        Returns
        -------
        float

        Examples
        --------
        >>> import uio_teach as ut
        >>> filt = ut.design_nullspace_filter(ut.examples.pa9(), (ut.examples.pa9().B, None),
        ...                                   poles=[-4, -5])
        >>> filt.decoupling_gap() < 1e-12
        True
        """
        return decoupling_gap(self._Q, self._model, points)

    def residual(
        self, timepts: Any, outputs: Any, inputs: Any = None, *, initial_state: Any = None
    ) -> np.ndarray:
        """The residual ``r = Q [y; u]`` on a time grid (inputs linear between samples).

        Parameters
        ----------
        timepts : array_like, shape (N,)
        outputs : array_like, shape (p, N)
            The measurements ``y`` (for example ``response.outputs`` of
            :func:`uio_teach.simulate_fault`).
        inputs : array_like, shape (mu, N), optional
            The known inputs ``u`` (default zero).
        initial_state : array_like, shape (order,), optional
            The filter's state at ``timepts[0]`` (default zero).

        Returns
        -------
        numpy.ndarray, shape (rows, N)

        Examples
        --------
        >>> import numpy as np
        >>> import uio_teach as ut
        >>> plant = ut.examples.pa9()
        >>> filt = ut.design_nullspace_filter(plant, (plant.B, None), poles=[-4, -5])
        >>> t = np.linspace(0, 1, 11)
        >>> filt.residual(t, np.zeros((2, 11)), np.zeros((2, 11))).shape
        (1, 11)
        """
        t = check_timepts(timepts)
        model = self._model
        y = as_matrix("outputs", outputs, model.p, t.size, what="p x N: one row per output")
        u = (
            np.zeros((model.mu, t.size))
            if inputs is None
            else as_matrix("inputs", inputs, model.mu, t.size, what="mu x N: one row per input")
        )
        Q = self._Q
        sig = np.vstack([y, u])
        nq = self.order
        x0 = (
            np.zeros(nq)
            if initial_state is None
            else as_matrix("initial_state", initial_state, nq, 1, what="order")[:, 0]
        )
        A, B = np.asarray(Q.A, float), np.asarray(Q.B, float)
        out = np.hstack([np.asarray(Q.C, float), np.asarray(Q.D, float)])
        if nq == 0:
            return out @ sig
        return np.asarray(linear_response(A, B, t, sig, x0, discrete=model.is_discrete, output=out))

    def simulate(
        self,
        timepts: Any,
        *,
        u: Any = None,
        d: Any = None,
        f: Any = None,
        fault: Any = None,
        initial_state: Any = None,
        noise: Any = None,
        seed: Any = None,
    ) -> FilterResponse:
        """Simulate the plant and the filter together (inputs linear between samples).

        The plant's state and the filter's are one linear system driven by
        ``u``, ``d``, ``f`` and the noise, solved exactly over each step, so
        the residual's independence of ``u`` and ``d`` holds to rounding (a
        filter run afterwards on sampled ``y`` would add the error of taking
        ``y`` linear between samples).

        Parameters
        ----------
        timepts : array_like, shape (N,)
            Time points, as in :func:`uio_teach.simulate`.
        u, d, f : callable or array_like, optional
            Known inputs (mu), disturbances (md: for a ``Plant``, ``E``'s
            inputs then ``D``'s) and faults (mf), as in :func:`uio_teach.simulate`.
        fault : Fault, optional
            One of the faults the filter was designed with (matched by name):
            its own signal drives its column, the other faults stay zero.
        initial_state : array_like, shape (n,), optional
            The plant's state at ``timepts[0]`` (the filter starts at zero).
        noise : float, array_like of shape (p,) or (p, N), optional
            Standard deviation of white measurement noise per output (drawn
            as :func:`uio_teach.simulate_fault` draws it, so the same ``seed``
            gives the same noise), or the noise samples themselves.
        seed : int or numpy.random.Generator, optional
            Seed of the noise.

        Returns
        -------
        FilterResponse

        Examples
        --------
        >>> import numpy as np
        >>> import uio_teach as ut
        >>> plant = ut.examples.pa9()
        >>> filt = ut.design_nullspace_filter(plant, (plant.B, None), poles=[-4, -5])
        >>> t = np.linspace(0, 5, 501)
        >>> a = filt.simulate(t, d=ut.signals.sinusoid(1.0, 2.0), initial_state=[1, 0, 0])
        >>> b = filt.simulate(t, d=ut.signals.step(3.0, 1.0), initial_state=[1, 0, 0])
        >>> bool(np.abs(a.residual - b.residual).max() < 1e-9 * np.abs(a.outputs).max())
        True
        """
        model = self._model
        t = check_timepts(timepts)
        N = t.size
        n, p, mu, md, mf = model.n, model.p, model.mu, model.md, model.mf
        us = input_samples("u", u, mu, t)
        ds = input_samples("d", d, md, t)
        if fault is not None:
            if f is not None:
                raise NullspaceFilterError("give either f or fault, not both")
            name = getattr(fault, "name", None)
            if name not in model.fault_names:
                raise NullspaceFilterError(
                    f"fault {name!r} is not one of the filter's faults "
                    f"({', '.join(model.fault_names)})"
                )
            fs = np.zeros((mf, N))
            fs[model.fault_names.index(name)] = input_samples("f", fault.signal, 1, t)[0]
        else:
            fs = input_samples("f", f, mf, t)
        if noise is None:
            ns = np.zeros((p, N))
        else:
            arr = np.asarray(noise, dtype=float)
            if arr.ndim == 2:
                ns = as_matrix("noise", arr, p, N, what="p x N: one row per output")
            else:
                sd = np.broadcast_to(arr, (p,)) if arr.ndim == 0 else arr
                if sd.shape != (p,) or not np.all(np.isfinite(sd)) or np.any(sd < 0):
                    raise NullspaceFilterError(
                        f"noise must be one standard deviation, one per output (length {p}) "
                        f"or the samples (shape ({p}, {N})), got {noise!r}"
                    )
                ns = sd[:, None] * np.random.default_rng(seed).standard_normal((p, N))
        x0 = (
            np.zeros(n)
            if initial_state is None
            else as_matrix("initial_state", initial_state, n, 1, what="n: one entry per state")[
                :, 0
            ]
        )
        Q = self._Q
        nq = self.order
        Aq, Bq, Cq, Dq = (np.asarray(M, float).reshape(M.shape) for M in (Q.A, Q.B, Q.C, Q.D))
        Bqy, Bqu, Dqy, Dqu = Bq[:, :p], Bq[:, p:], Dq[:, :p], Dq[:, p:]
        Bcol = np.hstack([model.Bu, model.Bd, model.Bf, np.zeros((n, p))])
        Dcol = np.hstack([model.Du, model.Dd, model.Df, np.eye(p)])
        A = np.block([[model.A, np.zeros((n, nq))], [Bqy @ model.C, Aq]])
        B = np.vstack([Bcol, Bqy @ Dcol + np.hstack([Bqu, np.zeros((nq, md + mf + p))])])
        out = np.block(
            [
                [np.eye(n), np.zeros((n, nq + mu + md + mf + p))],
                [model.C, np.zeros((p, nq)), Dcol],
                [
                    Dqy @ model.C,
                    Cq,
                    Dqy @ Dcol + np.hstack([Dqu, np.zeros((Dq.shape[0], md + mf + p))]),
                ],
            ]
        )
        sig = np.vstack([us, ds, fs, ns])
        yr = np.asarray(
            linear_response(
                A, B, t, sig, np.concatenate([x0, np.zeros(nq)]),
                discrete=model.is_discrete, output=out,
            )
        )  # fmt: skip
        return FilterResponse(
            time=t,
            states=yr[:n],
            outputs=yr[n : n + p],
            residual=yr[n + p :],
            u=us,
            d=ds,
            f=fs,
            noise=ns,
        )

    # display ----------------------------------------------------------------------------------
    def report(self) -> str:
        """What the filter detects, in words.

        Examples
        --------
        >>> import uio_teach as ut
        >>> plant = ut.examples.pa9()
        >>> print(ut.design_nullspace_filter(plant, (plant.E, None), poles=[-4, -5]).report())
        nullspace filter: 1 residual, order 2 (basis degrees 2), poles {-5, -4}
          f[0]: not detected (annihilated with the disturbances)
        """
        poles = ", ".join(format_complex(p) for p in self.poles())
        rows = self._Q.noutputs
        lines = [
            f"nullspace filter: {rows} residual{'s' if rows != 1 else ''}, order {self.order} "
            f"(basis degrees {', '.join(map(str, self._degrees))}), poles {{{poles}}}"
        ]
        for j, name in enumerate(self.fault_names):
            if self._detected[j]:
                where = [str(i + 1) for i in np.flatnonzero(self._structure[:, j])]
                lines.append(f"  {name}: detected (residual {', '.join(where)})")
            else:
                lines.append(f"  {name}: not detected (annihilated with the disturbances)")
        return "\n".join(lines)

    def __repr__(self) -> str:
        return fit_lines(
            f"NullspaceFilter({self._Q.noutputs} residuals, order {self.order}, detects "
            f"{sum(self._detected)} of {len(self._detected)} faults)"
        )

    def __str__(self) -> str:
        return self.report()


def decoupling_gap(Q: Any, model: FaultModel, points: Any = None) -> float:
    """Largest entry of ``Q(s) [[Gu, Gd], [I, 0]]`` at ``points``, relative to its terms' size.

    The check of any residual generator ``r = Q [y; u]`` (a designed one, or
    one built by hand): zero in exact arithmetic when ``Q`` annihilates the
    known inputs and the disturbances, a few ``eps`` times the conditioning
    after rounding, of order 1 when it does not.

    Parameters
    ----------
    Q : control.StateSpace or control.TransferFunction
        Inputs ``[y; u]`` (p + mu of them).
    model : FaultModel
        The plant (:func:`fault_model`).
    points : array_like of complex, optional
        Values of ``s`` (or ``z``); default five generic points near the
        imaginary axis on the plant's time scale (near the unit circle in
        discrete time).

    Returns
    -------
    float

    Raises
    ------
    NullspaceFilterError
        If ``Q`` does not have ``p + mu`` inputs.

    Examples
    --------
    ``[I, -Gu]`` cancels the known inputs but not the disturbance:

    >>> import numpy as np
    >>> import control as ct
    >>> import uio_teach as ut
    >>> model = ut.fault_model(ut.examples.varga_5_4(), [2, 3], known=[0], disturbances=[1])
    >>> sys = ut.examples.varga_5_4()
    >>> I_minus_Gu = ct.ss(sys.A, np.hstack([np.zeros((3, 2)), -sys.B[:, :1]]), sys.C,
    ...                    np.hstack([np.eye(2), -sys.D[:, :1]]))
    >>> ut.decoupling_gap(I_minus_Gu, model) > 0.1
    True
    """
    import control as ct  # deferred on purpose: python-control takes a second to import

    Q = ct.ss(Q)
    if Q.ninputs != model.p + model.mu:
        raise NullspaceFilterError(
            f"Q has {Q.ninputs} inputs, expected p + mu = {model.p + model.mu} ([y; u])"
        )
    n = model.n
    scale = float(np.linalg.norm(model.A, 2)) if n else 1.0
    scale = scale or 1.0
    if points is None:  # generic points (no pole of the data sits on them), on the data's scale
        w = np.array([0.1, 0.5, 1.0, 2.0, 3.0])
        points = 0.9 * np.exp(1j * w) if model.is_discrete else scale * (0.05 + 1j * w)
    worst = 0.0
    nq = Q.nstates
    Aq, Bq, Cq, Dq = (
        np.asarray(M, float).reshape(shape)
        for M, shape in (
            (Q.A, (nq, nq)),
            (Q.B, (nq, Q.ninputs)),
            (Q.C, (Q.noutputs, nq)),
            (Q.D, (Q.noutputs, Q.ninputs)),
        )
    )
    for s in np.atleast_1d(np.asarray(points, dtype=complex)):
        G = np.hstack([model.Du, model.Dd]).astype(complex)
        if n:
            G = G + model.C @ np.linalg.solve(
                s * np.eye(n) - model.A, np.hstack([model.Bu, model.Bd])
            )
        big = np.vstack([G, np.hstack([np.eye(model.mu), np.zeros((model.mu, model.md))])])
        Qs = Dq + (Cq @ np.linalg.solve(s * np.eye(nq) - Aq, Bq) if nq else 0)
        size = np.linalg.norm(Qs, 2) * np.linalg.norm(big, 2)
        if size > 0:
            worst = max(worst, float(np.abs(Qs @ big).max() / size))
    return worst


def _allot(poles: np.ndarray, degrees: list[int], discrete: bool) -> list[np.ndarray]:
    order = sum(degrees)
    if poles.size == 1 and order != 1 and poles[0].imag == 0:
        poles = np.repeat(poles, order)
    if poles.size != order:
        raise NullspaceFilterError(
            f"poles: the filter has order {order} (basis rows of degrees "
            f"{', '.join(map(str, degrees))}), so it needs {order} poles (or one, repeated), "
            f"got {poles.size}"
        )
    bad = poles[~is_stable(poles, discrete)]
    if bad.size:
        region = "inside the unit circle" if discrete else "in the open left half-plane"
        raise NullspaceFilterError(
            "poles: a residual generator must be stable, so its poles must lie "
            f"{region}; {', '.join(format_complex(p) for p in bad)} does not"
        )
    groups, start = [], 0
    for k in degrees:
        group = poles[start : start + k]
        start += k
        if np.abs(np.sort_complex(group) - np.sort_complex(group.conj())).max(initial=0.0) > 0:
            raise NullspaceFilterError(
                f"poles: the {k} poles given to a basis row of degree {k} "
                f"({', '.join(format_complex(p) for p in group)}) split a conjugate pair; "
                "order the poles so that each row gets whole pairs"
            )
        groups.append(group)
    return groups


def design_nullspace_filter(
    plant: Any,
    faults: Any,
    *,
    poles: Any,
    known: Any = None,
    disturbances: Any = None,
) -> NullspaceFilter:
    r"""Design a fault detection filter by the nullspace method.

    Finds ``Q(s)`` with ``Q [[Gu, Gd], [I, 0]] = 0`` exactly (the known inputs
    and the disturbances cancel from the residual, whatever they are), of
    least order (a polynomial basis of least degrees of that left nullspace),
    with its poles placed, and ``Rf(s) = Q [[Gf], [0]]``, the faults' map to
    the residual. Varga, *Solving Fault Diagnosis Problems* (Springer, 2024),
    Procedure EFD; the nullspace is found from the parity relations of the
    state-space model (see the module's documentation).

    Parameters
    ----------
    plant : Plant or python-control system
        The plant (see :func:`fault_model`): a :class:`~uio_teach.Plant`, or
        a ``StateSpace`` / ``TransferFunction`` with feedthrough allowed.
    faults : list of Fault, pair (R1, R2), or input indices
        The faults (see :func:`fault_model`).
    poles : float or array_like
        The filter's poles, one per state (the order is the sum of the basis
        degrees; the error message says it when the count is wrong), or one
        value for every state. Stable; complex ones in conjugate pairs,
        each pair given to one basis row.
    known, disturbances : list of int, optional
        For a python-control system: which inputs are known and which are
        disturbances (default: every input that is neither known nor a fault).

    Returns
    -------
    NullspaceFilter
        ``.Q`` and ``.Rf`` are ``control.StateSpace`` systems; ``.detected``
        says which faults reach the residual.

    Raises
    ------
    NullspaceFilterError
        If no filter exists (the disturbances reach every output direction:
        ``rank Gd(s) = p``), the poles are not stable or not as many as the
        order, or the plant and faults do not fit together.

    Examples
    --------
    Varga's Example 5.4 (``ut.examples.varga_5_4``: inputs ``u, d, f1, f2``), pole at -3:

    >>> import uio_teach as ut
    >>> filt = ut.design_nullspace_filter(
    ...     ut.examples.varga_5_4(), [2, 3], known=[0], disturbances=[1], poles=[-3]
    ... )
    >>> filt.degrees, filt.detected, filt.poles().real.round(12).tolist()
    ((1,), (True, True), [-3.0])
    """
    model = fault_model(plant, faults, known=known, disturbances=disturbances)
    requested = as_poles("poles", poles)
    n, p, mu = model.n, model.p, model.mu
    discrete = model.is_discrete
    # scaled time: s = omega * s~, so that A / omega is of order 1 whatever the unit of time
    omega = 1.0
    if not discrete and n:
        omega = float(np.linalg.norm(model.A, 2)) or 1.0
    A = model.A / omega
    Bu, Bd, Bf = model.Bu / omega, model.Bd / omega, model.Bf / omega
    C = model.C
    rank_d = _normal_rank(A, Bd, C, model.Dd, 1.0)
    count = p - rank_d
    if count == 0:
        raise NullspaceFilterError(
            f"no residual generator exists: the disturbances reach every output direction "
            f"(the normal rank of Gd(s) is {rank_d} = p, the number of outputs), so every "
            "combination of the measurements carries them; measure more, or decouple fewer "
            "disturbances"
        )
    basis = _least_degree_basis(A, Bd, C, model.Dd, count)
    groups = _allot(requested, basis.degrees, discrete)

    import control as ct  # deferred on purpose: python-control takes a second to import

    blocks_q, blocks_f, coeff_rows, fault_rows, structure = [], [], [], [], []
    for w, k, group in zip(basis.rows, basis.degrees, groups, strict=True):
        Tu = _toeplitz(A, Bu, C, model.Du, k)
        Td = _toeplitz(A, Bd, C, model.Dd, k)
        Tf = _toeplitz(A, Bf, C, model.Df, k)
        wy = w.reshape(k + 1, p)  # row i: coefficient of s~^i on y
        wu = -(w @ Tu).reshape(k + 1, mu)
        wf = (w @ Tf).reshape(k + 1, model.mf)
        # the defining identity, judged against the size of its terms
        leak = np.abs(w @ Td).max(initial=0.0)
        terms = np.linalg.norm(Td, 2) if Td.size else 0.0
        if leak > tols.IDENTITY_RTOL * max(terms, np.finfo(float).tiny):
            raise NullspaceFilterError(  # pragma: no cover - a numerical failure
                f"the nullspace basis leaves {leak:.3g} of the disturbances (their terms are "
                f"{terms:.3g}): the data are too badly conditioned"
            )
        norm = np.linalg.norm(np.hstack([wy.ravel(), wu.ravel()]))
        sign = 1.0
        flat = np.hstack([wy.ravel(), wu.ravel()])
        if flat[np.argmax(np.abs(flat))] < 0:
            sign = -1.0
        wy, wu, wf = sign * wy / norm, sign * wu / norm, sign * wf / norm
        # fault j reaches this residual unless its polynomial vanishes against its terms
        ftermsize = np.array(
            [np.linalg.norm(Tf[:, j :: model.mf], 2) for j in range(model.mf)]
        ) * np.linalg.norm(wy)
        structure.append(np.abs(wf).max(axis=0) > tols.IDENTITY_RTOL * np.maximum(ftermsize, 0))
        den = np.real(np.poly(group / omega)) if k else np.ones(1)
        num = np.hstack([wy, wu]).T  # (p + mu, k + 1) ascending in s~
        blocks_q.append(_companion_row(num, den))
        blocks_f.append(_companion_row(wf.T, den))
        scale_pow = omega ** -np.arange(k + 1)
        coeff_rows.append(np.hstack([wy, wu]) * scale_pow[:, None])
        fault_rows.append(wf * scale_pow[:, None])
    structure = np.array(structure, dtype=bool)
    Aq = _blockdiag([b[0] for b in blocks_q]) * omega
    Bq = np.vstack([b[1] for b in blocks_q]) * omega
    Cq = _blockdiag([b[2] for b in blocks_q])
    Dq = np.vstack([b[3] for b in blocks_q])
    Bfq = np.vstack([b[1] for b in blocks_f]) * omega
    Dfq = np.vstack([b[3] for b in blocks_f])
    dt = 0 if model.dt is None else model.dt
    outputs = [f"r[{i}]" for i in range(len(basis.rows))]
    Q = ct.ss(
        Aq, Bq, Cq, Dq, dt,
        inputs=[f"y[{i}]" for i in range(p)] + [f"u[{j}]" for j in range(mu)],
        outputs=outputs, name="Q",
    )  # fmt: skip
    Rf = ct.ss(Aq, Bfq, Cq, Dfq, dt, inputs=list(model.fault_names), outputs=outputs, name="Rf")
    return NullspaceFilter(
        model=model,
        Q=Q,
        Rf=Rf,
        degrees=basis.degrees,
        basis=coeff_rows,
        fault_basis=fault_rows,
        structure=structure,
        detected=structure.any(axis=0),
        scale=omega,
    )
