"""The plant: a linear system with known inputs, unknown inputs and measurement disturbances."""

from __future__ import annotations

from collections.abc import Sequence
from numbers import Real
from typing import TYPE_CHECKING, Any

import numpy as np

from ._display import matrices_html, matrices_text
from ._validation import as_matrix
from .errors import InputError

if TYPE_CHECKING:  # python-control is imported where a conversion needs it
    import control as ct

__all__ = ["Plant", "check_plant"]

_ROWS = {
    "B": "n x m: one row per state",
    "E": "n x q: one row per state",
    "D": "p x nv: one row per output",
}


def _check_dt(dt: Any) -> float | bool | None:
    if dt is None or (isinstance(dt, Real) and not isinstance(dt, bool) and dt == 0):
        return None
    if dt is True:
        return True
    if isinstance(dt, bool) or not isinstance(dt, Real) or not np.isfinite(dt) or dt < 0:
        raise InputError(
            f"dt must be None (continuous time), True (discrete time, unspecified period) "
            f"or a positive sampling period, got {dt!r}"
        )
    return float(dt)


class Plant:
    r"""A linear plant with known inputs, unknown inputs and measurement disturbances.

    Continuous time (``dt=None``)::

        x' = A x + B u + E d,        y = C x + D v

    discrete time (``dt`` set)::

        x[k+1] = A x[k] + B u[k] + E d[k],   y[k] = C x[k] + D v[k]

    ``u`` are the known inputs, ``d`` the unknown inputs acting on the state
    and ``v`` the unknown disturbances acting on the measurements.

    Parameters
    ----------
    A : array_like, shape (n, n)
        State matrix.
    C : array_like, shape (p, n)
        Output matrix. A 1-D array is one output row.
    B : array_like, shape (n, m), optional
        Known-input matrix; omitted means no known input (``m = 0``).
    E : array_like, shape (n, q), optional
        Unknown-input matrix (``B2`` in the case-study script, ``E`` in
        Practical Assignment 9 and the missile paper). A 1-D array is a column.
    D : array_like, shape (p, nv), optional
        Measurement-disturbance matrix. A 1-D array is a column.
    dt : None, True or float, optional
        ``None`` (or 0) for continuous time, ``True`` for discrete time with an
        unspecified period, or the positive sampling period.
    name : str, optional
        A name used when the plant is displayed.

    Raises
    ------
    ValueError
        If a matrix has the wrong shape (the message names the matrix, its
        shape and the expected shape), has a non-finite entry, or ``dt`` is
        not valid.

    Notes
    -----
    A plant is immutable: its matrices are read-only arrays.

    Examples
    --------
    >>> import uio_teach as ut
    >>> plant = ut.Plant([[0, 1], [-2, -3]], [[1, 0]], E=[0, 1])
    >>> plant.n, plant.p, plant.q
    (2, 1, 1)
    >>> ut.Plant([[0, 1], [-2, -3]], [[1, 0]], E=[0, 1, 0])
    Traceback (most recent call last):
    ...
    uio_teach.errors.InputError: E has shape (3, 1), expected (2, ?) (n x q: one row per state)
    """

    __slots__ = ("_A", "_B", "_C", "_D", "_E", "_dt", "_name")

    def __init__(
        self,
        A: Any,
        C: Any,
        *,
        B: Any = None,
        E: Any = None,
        D: Any = None,
        dt: float | bool | None = None,
        name: str = "",
    ) -> None:
        A = as_matrix("A", A, what="n x n")
        if A.shape[0] != A.shape[1]:
            raise InputError(f"A has shape {A.shape}, expected a square (n, n) matrix")
        n = A.shape[0]
        if n == 0:
            raise InputError("A is empty: the plant needs at least one state")
        C = as_matrix("C", C, None, n, vector="row", what="p x n: one column per state")
        p = C.shape[0]
        if p == 0:
            raise InputError("C has no rows: the plant needs at least one output")
        B = as_matrix(
            "B", np.zeros((n, 0)) if B is None else B, n, None, what="n x m: one row per state"
        )
        E = as_matrix(
            "E", np.zeros((n, 0)) if E is None else E, n, None, what="n x q: one row per state"
        )
        D = as_matrix(
            "D", np.zeros((p, 0)) if D is None else D, p, None, what="p x nv: one row per output"
        )
        object.__setattr__(self, "_A", A)
        object.__setattr__(self, "_B", B)
        object.__setattr__(self, "_C", C)
        object.__setattr__(self, "_D", D)
        object.__setattr__(self, "_E", E)
        object.__setattr__(self, "_dt", _check_dt(dt))
        object.__setattr__(self, "_name", str(name))

    def __setattr__(self, key: str, value: Any) -> None:
        raise AttributeError("Plant is immutable; build a new one instead")

    # matrices -------------------------------------------------------------
    @property
    def A(self) -> np.ndarray:
        """State matrix, shape (n, n)."""
        return self._A

    @property
    def B(self) -> np.ndarray:
        """Known-input matrix, shape (n, m)."""
        return self._B

    @property
    def C(self) -> np.ndarray:
        """Output matrix, shape (p, n)."""
        return self._C

    @property
    def D(self) -> np.ndarray:
        """Measurement-disturbance matrix, shape (p, nv)."""
        return self._D

    @property
    def E(self) -> np.ndarray:
        """Unknown-input matrix, shape (n, q)."""
        return self._E

    @property
    def dt(self) -> float | bool | None:
        """The sampling period; None (continuous), True (unspecified) or a float."""
        return self._dt

    @property
    def name(self) -> str:
        """Display name."""
        return self._name

    # dimensions -----------------------------------------------------------
    @property
    def n(self) -> int:
        """Number of states."""
        return self._A.shape[0]

    @property
    def m(self) -> int:
        """Number of known inputs."""
        return self._B.shape[1]

    @property
    def q(self) -> int:
        """Number of unknown (state) inputs."""
        return self._E.shape[1]

    @property
    def p(self) -> int:
        """Number of outputs."""
        return self._C.shape[0]

    @property
    def nv(self) -> int:
        """Number of measurement disturbances."""
        return self._D.shape[1]

    @property
    def is_discrete(self) -> bool:
        """True for a discrete-time plant."""
        return self._dt is not None

    # conversions ----------------------------------------------------------
    @classmethod
    def from_statespace(
        cls,
        sys: ct.StateSpace,
        unknown: Sequence[int | str] = (),
        *,
        measurement: Sequence[int | str] = (),
        name: str = "",
    ) -> Plant:
        """Build a plant from a python-control system by splitting its inputs.

        Parameters
        ----------
        sys : control.StateSpace
            The system ``x' = A x + B w``, ``y = C x + D w``.
        unknown : sequence of int or str
            Inputs (indices or labels) that are unknown inputs acting on the
            state: their columns of ``sys.B`` form ``E``; their columns of
            ``sys.D`` must be zero.
        measurement : sequence of int or str, optional
            Inputs that are measurement disturbances: their columns of
            ``sys.D`` form ``D``; their columns of ``sys.B`` must be zero.
        name : str, optional
            Display name; defaults to the system's name.

        Returns
        -------
        Plant
            The remaining inputs are the known inputs (``B``); their columns
            of ``sys.D`` must be zero.

        Examples
        --------
        >>> import control as ct
        >>> import uio_teach as ut
        >>> sys = ct.ss([[0, 1], [-2, -3]], [[0, 1], [1, 0]], [[1, 0]], 0,
        ...             inputs=["u", "d"])
        >>> plant = ut.Plant.from_statespace(sys, unknown=["d"])
        >>> plant.B.ravel().tolist(), plant.E.ravel().tolist()
        ([0.0, 1.0], [1.0, 0.0])
        """
        import control as ct  # deferred on purpose: python-control takes a second to import

        if not isinstance(sys, ct.StateSpace):
            raise InputError(f"sys must be a control.StateSpace, got {type(sys).__name__}")
        labels = list(sys.input_labels)

        def index(item: int | str, arg: str) -> int:
            if isinstance(item, str):
                if item not in labels:
                    raise InputError(f"{arg}: no input named {item!r}; inputs are {labels}")
                return labels.index(item)
            i = int(item)
            if not -len(labels) <= i < len(labels):
                raise InputError(f"{arg}: input index {i} out of range for {len(labels)} inputs")
            return i % len(labels)

        unk = [index(i, "unknown") for i in unknown]
        meas = [index(i, "measurement") for i in measurement]
        if set(unk) & set(meas):
            raise InputError("an input cannot be both an unknown state input and a measurement one")
        known = [i for i in range(len(labels)) if i not in unk and i not in meas]
        Bs, Ds = np.asarray(sys.B, float), np.asarray(sys.D, float)
        for i in known + unk:
            if np.any(Ds[:, i] != 0):
                raise InputError(
                    f"input {labels[i]!r} feeds through to the output (nonzero column of sys.D); "
                    "only measurement disturbances may do so: list it in measurement="
                )
        for i in meas:
            if np.any(Bs[:, i] != 0):
                raise InputError(
                    f"measurement disturbance {labels[i]!r} also acts on the state "
                    "(nonzero column of sys.B)"
                )
        dt = sys.dt if sys.dt not in (0, None) else None
        return cls(
            sys.A,
            sys.C,
            B=Bs[:, known],
            E=Bs[:, unk],
            D=Ds[:, meas],
            dt=dt,
            name=name or sys.name,
        )

    def as_statespace(self) -> ct.StateSpace:
        """Return the plant as a python-control system with inputs ``[u; d; v]``.

        Examples
        --------
        >>> import uio_teach as ut
        >>> ut.examples.pa9().as_statespace().ninputs
        3
        """
        n, p = self.n, self.p
        Bfull = np.hstack([self.B, self.E, np.zeros((n, self.nv))])
        Dfull = np.hstack([np.zeros((p, self.m + self.q)), self.D])
        inputs = (
            [f"u[{i}]" for i in range(self.m)]
            + [f"d[{i}]" for i in range(self.q)]
            + [f"v[{i}]" for i in range(self.nv)]
        )
        kwargs = {"dt": self.dt if self.dt is not None else 0}
        if self.name:
            kwargs["name"] = self.name
        import control as ct  # deferred on purpose: python-control takes a second to import

        return ct.ss(self.A, Bfull, self.C, Dfull, inputs=inputs, **kwargs)

    # display --------------------------------------------------------------
    def _items(self) -> list[tuple[str, np.ndarray]]:
        items = [("A", self.A)]
        if self.m:
            items.append(("B", self.B))
        if self.q:
            items.append(("E", self.E))
        items.append(("C", self.C))
        if self.nv:
            items.append(("D", self.D))
        return items

    def _title(self) -> str:
        kind = (
            "continuous-time"
            if self.dt is None
            else ("discrete-time" if self.dt is True else f"discrete-time, dt={self.dt:g}")
        )
        name = f"{self.name!r}, " if self.name else ""
        return f"Plant({name}{kind}, n={self.n}, m={self.m}, q={self.q}, p={self.p}, nv={self.nv})"

    def __repr__(self) -> str:
        return self._title()

    def __str__(self) -> str:
        return matrices_text(self._title(), self._items())

    def _repr_html_(self) -> str:
        return matrices_html(self._title(), self._items())

    def __eq__(self, other: object) -> bool:
        if not isinstance(other, Plant):
            return NotImplemented
        return self.dt == other.dt and all(
            np.array_equal(a, b)
            for a, b in zip(
                (self.A, self.B, self.C, self.D, self.E),
                (other.A, other.B, other.C, other.D, other.E),
                strict=True,
            )
        )

    __hash__ = None  # type: ignore[assignment]


def check_plant(plant: Any) -> Plant:
    """Return ``plant`` if it is a :class:`Plant`; otherwise raise a clear ``ValueError``.

    Examples
    --------
    >>> import uio_teach as ut
    >>> ut.plant.check_plant(ut.examples.pa9()).n
    3
    >>> ut.plant.check_plant([[1.0]])
    Traceback (most recent call last):
    ...
    uio_teach.errors.InputError: plant must be a uio_teach.Plant, got list
    """
    if not isinstance(plant, Plant):
        raise InputError(f"plant must be a uio_teach.Plant, got {type(plant).__name__}")
    return plant
