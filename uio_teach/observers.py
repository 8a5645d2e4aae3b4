"""The observer designs: decoupling UIO (PA9), projection operator (PMO), g-inverse, Luenberger.

Every observer is a linear system driven by the known input ``u`` and the
measurement ``y``::

    w' = A_o w + B_u u + B_y y,        xhat = C_o w + D_y y

(``w[k+1] = ...`` in discrete time). :meth:`Observer.realization` returns
these matrices, :meth:`Observer.as_statespace` the python-control system, and
:meth:`Observer.poles` the eigenvalues of the estimation-error dynamics
``e' = error_matrix @ e``.
"""

from __future__ import annotations

import warnings
from typing import Any, NamedTuple

import control as ct
import numpy as np

from ._display import format_complex, matrices_html, matrices_text
from ._validation import as_matrix
from .existence import UIOExistenceError, check_existence, decoupling
from .linalg import is_stable, observability_decomposition, pinv, rank, sort_poles
from .lmi import lmi_gain
from .placement import place_observer_poles, place_pair_poles, requested_poles
from .plant import Plant
from .verify import check_identity, check_poles, product_bound

__all__ = [
    "Observer",
    "ObserverRealization",
    "UnstableObserverWarning",
    "UIO",
    "PMO",
    "GInverseObserver",
    "LuenbergerObserver",
    "design_uio",
    "design_pmo",
    "design_ginverse",
    "design_luenberger",
]


class UnstableObserverWarning(UserWarning):
    """The designed observer's error dynamics are not asymptotically stable."""


class ObserverRealization(NamedTuple):
    """``w' = A w + B_u u + B_y y``, ``xhat = C w + D_y y`` (no direct ``u`` term).

    Examples
    --------
    >>> import uio_teach as ut
    >>> real = ut.design_uio(ut.examples.pa9(), poles=[-1, -2, -3]).realization()
    >>> real.A.shape, real.B_y.shape, real.D_y.shape
    ((3, 3), (3, 2), (3, 2))
    """

    A: np.ndarray
    B_u: np.ndarray
    B_y: np.ndarray
    C: np.ndarray
    D_y: np.ndarray


class Observer:
    """Base class of the observers (not built directly; use the ``design_*`` functions).

    Attributes
    ----------
    plant : Plant
        The plant the observer was designed for.
    error_matrix : numpy.ndarray
        ``Ae`` in the error dynamics ``e' = Ae e`` (``e[k+1] = Ae e[k]``),
        which hold whatever the unknown input is for the UIO families.

    Examples
    --------
    >>> import uio_teach as ut
    >>> obs = ut.design_pmo(ut.examples.dt_case_study(), method="lmi")
    >>> isinstance(obs, ut.Observer), obs.decouples, obs.is_stable
    (True, True, True)
    """

    family = "observer"
    _display_names: tuple[str, ...] = ()
    _designer = "the design function"

    def __init__(self, plant: Plant) -> None:
        self._plant = plant

    def __setattr__(self, key: str, value: Any) -> None:
        if not key.startswith("_"):
            raise AttributeError(
                f"{type(self).__name__}.{key} is read-only: the observer's matrices are derived "
                f"from each other, so changing one would leave the others stale; design a new "
                f"observer instead ({self._designer})"
            )
        object.__setattr__(self, key, value)

    @property
    def plant(self) -> Plant:
        """The plant the observer was designed for."""
        return self._plant

    # interface --------------------------------------------------------------
    @property
    def error_matrix(self) -> np.ndarray:  # pragma: no cover - abstract
        raise NotImplementedError

    def realization(self) -> ObserverRealization:  # pragma: no cover - abstract
        """The observer's matrices ``(A, B_u, B_y, C, D_y)``."""
        raise NotImplementedError

    @property
    def decouples(self) -> bool:
        """True if the estimation error is independent of the unknown inputs."""
        return True

    def poles(self) -> np.ndarray:
        """Eigenvalues of the estimation-error dynamics, sorted.

        Examples
        --------
        >>> import uio_teach as ut
        >>> obs = ut.design_uio(ut.examples.pa9(), poles=[-1, -2, -3])
        >>> obs.poles().real.round(6).tolist()
        [-3.0, -2.0, -1.0]
        """
        return sort_poles(np.linalg.eigvals(self.error_matrix))

    @property
    def is_stable(self) -> bool:
        """True if every error pole is in the stability region."""
        return bool(np.all(is_stable(self.poles(), self.plant.is_discrete)))

    def as_statespace(self) -> ct.StateSpace:
        """The observer as a python-control system: inputs ``[u; y]``, outputs ``xhat``.

        Examples
        --------
        >>> import uio_teach as ut
        >>> sys = ut.design_uio(ut.examples.pa9(), poles=[-1, -2, -3]).as_statespace()
        >>> sys.ninputs, sys.noutputs
        (4, 3)
        """
        real = self.realization()
        pl = self.plant
        Bo = np.hstack([real.B_u, real.B_y])
        Do = np.hstack([np.zeros((pl.n, pl.m)), real.D_y])
        inputs = [f"u[{i}]" for i in range(pl.m)] + [f"y[{i}]" for i in range(pl.p)]
        outputs = [f"xhat[{i}]" for i in range(pl.n)]
        return ct.ss(
            real.A,
            Bo,
            real.C,
            Do,
            dt=pl.dt if pl.dt is not None else 0,
            inputs=inputs,
            outputs=outputs,
            name=f"{self.family}",
        )

    # helpers ----------------------------------------------------------------
    def _warn_if_unstable(self) -> None:
        if not self.is_stable:
            bad = [p for p in self.poles() if not is_stable([p], self.plant.is_discrete)[0]]
            region = "unit disk" if self.plant.is_discrete else "left half-plane"
            warnings.warn(
                f"the {self.family} error dynamics are unstable: pole(s) "
                + ", ".join(format_complex(p) for p in bad)
                + f" outside the open {region}; the estimation error will not decay",
                UnstableObserverWarning,
                stacklevel=3,
            )

    def _title(self) -> str:
        poles = ", ".join(format_complex(p) for p in self.poles())
        return f"{type(self).__name__} for {self.plant!r}, poles {{{poles}}}"

    def _items(self) -> list[tuple[str, np.ndarray]]:
        return [(k, getattr(self, k)) for k in self._display_names]

    def __repr__(self) -> str:
        return self._title()

    def __str__(self) -> str:
        return matrices_text(self._title(), self._items())

    def _repr_html_(self) -> str:
        return matrices_html(self._title(), self._items())


class _ProjectionObserver(Observer):
    """Shared algebra of the decoupling UIO and the PMO (they are the same observer).

    ``xhat = z + H y`` with ``H E``-decoupling, ``T = I - H C``,
    ``F = T A - K1 C``, ``K = K1 + F H`` and ``z' = F z + T B u + K y``.
    """

    def __init__(self, plant: Plant, H: np.ndarray, K1: np.ndarray) -> None:
        super().__init__(plant)
        n = plant.n
        self._H = _frozen(H)
        self._T = _frozen(np.eye(n) - H @ plant.C)
        self._K1 = _frozen(K1)
        self._F = _frozen(self._T @ plant.A - K1 @ plant.C)
        self._K2 = _frozen(self._F @ H)

    @property
    def error_matrix(self) -> np.ndarray:
        return self._F

    def realization(self) -> ObserverRealization:
        pl = self.plant
        return ObserverRealization(
            A=self._F,
            B_u=self._T @ pl.B,
            B_y=self._K1 + self._K2,
            C=np.eye(pl.n),
            D_y=self._H,
        )


class UIO(_ProjectionObserver):
    """Unknown-input decoupling observer of Practical Assignment 9.

    ``z' = F z + T B u + K y``, ``xhat = z + H y`` with ``H = E (CE)^+``,
    ``T = I - H C``, ``F = T A - K1 C``, ``K2 = F H``, ``K = K1 + K2``.
    Built by :func:`design_uio`.

    Examples
    --------
    >>> import numpy as np
    >>> import uio_teach as ut
    >>> uio = ut.design_uio(ut.examples.pa9(), poles=[-1, -2, -3])
    >>> bool(np.allclose(uio.T @ uio.plant.E, 0))
    True
    """

    family = "UIO"
    _display_names = ("H", "T", "K1", "K2", "K", "F")
    _designer = "design_uio(plant, poles=...) or design_uio(plant, K1=...)"

    @property
    def H(self) -> np.ndarray:
        """``E (CE)^+`` (``[E 0][CE D]^+`` with a measurement disturbance)."""
        return self._H

    @property
    def T(self) -> np.ndarray:
        """``I - H C``."""
        return self._T

    @property
    def K1(self) -> np.ndarray:
        """Output-injection gain that places the poles of ``F``."""
        return self._K1

    @property
    def K2(self) -> np.ndarray:
        """``F H``."""
        return self._K2

    @property
    def K(self) -> np.ndarray:
        """``K1 + K2``."""
        return _frozen(self._K1 + self._K2)

    @property
    def F(self) -> np.ndarray:
        """``T A - K1 C``: the error dynamics ``e' = F e``."""
        return self._F


class PMO(_ProjectionObserver):
    """Projection-operator full-order observer (Hui and Żak; case study; missile paper).

    ``q' = F q + G y + (I - MC) B u``, ``xhat = q + M y`` with
    ``A1 = (I - MC) A``, ``F = A1 - L C`` and ``G = (I - MC) A M + L - L C M``
    (eq. (13) of the missile paper). Built by :func:`design_pmo`.

    Examples
    --------
    >>> import numpy as np
    >>> import uio_teach as ut
    >>> pmo = ut.design_pmo(ut.examples.missile_autopilot(), poles=[-100, -120])
    >>> bool(np.allclose(pmo.projection @ pmo.plant.E, 0))
    True
    """

    family = "PMO"
    _display_names = ("M", "A1", "L", "F", "G")
    _designer = "design_pmo(plant, poles=...) or design_pmo(plant, L=...)"

    def __init__(
        self,
        plant: Plant,
        M: np.ndarray,
        L: np.ndarray,
        Mv: np.ndarray | None,
        certificate: np.ndarray | None,
    ) -> None:
        super().__init__(plant, M, L)
        self._Mv = None if Mv is None else _frozen(Mv)
        self._certificate = None if certificate is None else _frozen(certificate)

    @property
    def Mv(self) -> np.ndarray | None:
        """The free matrix of eq. (19) used, or None."""
        return self._Mv

    @property
    def lmi_certificate(self) -> np.ndarray | None:
        """The Lyapunov matrix ``P`` of :func:`lmi_gain` (``method="lmi"``), or None."""
        return self._certificate

    @property
    def M(self) -> np.ndarray:
        """``E (CE)^g + Mv (I - CE (CE)^g)`` (with ``D``: ``[E 0][CE D]^+``)."""
        return self._H

    @property
    def projection(self) -> np.ndarray:
        """``I - M C``: an oblique projection that annihilates ``E``."""
        return self._T

    @property
    def A1(self) -> np.ndarray:
        """``(I - M C) A``."""
        return _frozen(self._T @ self.plant.A)

    @property
    def L(self) -> np.ndarray:
        """Output-injection gain."""
        return self._K1

    @property
    def F(self) -> np.ndarray:
        """``A1 - L C``: the error dynamics."""
        return self._F

    @property
    def G(self) -> np.ndarray:
        """``(I - MC) A M + L - L C M``: the measurement gain of eq. (13)."""
        return _frozen(self._K1 + self._K2)


class GInverseObserver(Observer):
    """Generalized-matrix-inverse full-order observer (eqs. (20)-(23) of the missile paper).

    With ``Cg = C^g`` and the orthogonal projection ``Pc = I - Cg C``::

        K  = Pc E (CE)^g + Kv (I - CE (CE)^g)
        Av = Pc A Pc - Pc E (CE)^g C A Pc,   Cv = (I - CE (CE)^g) C A Pc
        q' = (Av - Kv Cv) q + G y + (Pc - K C) B u
        xhat = Pc q + (Cg + Pc K) y

    Built by :func:`design_ginverse`.

    Examples
    --------
    >>> import numpy as np
    >>> import uio_teach as ut
    >>> g = ut.design_ginverse(ut.examples.missile_autopilot())
    >>> bool(np.allclose(g.projection @ g.projection, g.projection))
    True
    """

    family = "g-inverse observer"
    _display_names = ("Cg", "K", "Av", "Cv", "Kv", "G")
    _designer = "design_ginverse(plant, Kv=...)"

    def __init__(self, plant: Plant, Kv: np.ndarray) -> None:
        super().__init__(plant)
        n, p = plant.n, plant.p
        A, C, E = plant.A, plant.C, plant.E
        Cg = pinv(C)
        Pc = np.eye(n) - Cg @ C
        CE = C @ E
        CEg = pinv(CE)
        W = np.eye(p) - CE @ CEg
        K = Pc @ E @ CEg + Kv @ W
        self._Cg = _frozen(Cg)
        self._Pc = _frozen(Pc)
        self._Kv = _frozen(Kv)
        self._K = _frozen(K)
        self._Av = _frozen(Pc @ A @ Pc - Pc @ E @ CEg @ C @ A @ Pc)
        self._Cv = _frozen(W @ C @ A @ Pc)
        self._G = _frozen(Pc @ A @ Cg - K @ C @ A @ Cg + Pc @ A @ Pc @ K - K @ C @ A @ Pc @ K)
        self._Ae = _frozen((Pc - Pc @ K @ C) @ A @ Pc)
        # orthonormal basis of range(Pc): the error lives there
        U, s, _ = np.linalg.svd(Pc)
        self._basis = U[:, : n - rank(C)]

    @property
    def Cg(self) -> np.ndarray:
        """``C^g``, the Moore-Penrose inverse of ``C``."""
        return self._Cg

    @property
    def projection(self) -> np.ndarray:
        """``Pc = I - C^g C``: the orthogonal projection onto the unmeasured directions."""
        return self._Pc

    @property
    def Kv(self) -> np.ndarray:
        """The free gain of eq. (23)."""
        return self._Kv

    @property
    def K(self) -> np.ndarray:
        """``Pc E (CE)^g + Kv (I - CE (CE)^g)``."""
        return self._K

    @property
    def Av(self) -> np.ndarray:
        """``Pc A Pc - Pc E (CE)^g C A Pc``."""
        return self._Av

    @property
    def Cv(self) -> np.ndarray:
        """``(I - CE (CE)^g) C A Pc``."""
        return self._Cv

    @property
    def G(self) -> np.ndarray:
        """The measurement gain of eq. (21)."""
        return self._G

    @property
    def F(self) -> np.ndarray:
        """``Av - Kv Cv``: the observer-state matrix of eq. (21)."""
        return _frozen(self.Av - self.Kv @ self.Cv)

    @property
    def error_matrix(self) -> np.ndarray:
        """``(Pc - Pc K C) A Pc``: ``e' = error_matrix e``, with ``e`` in range(Pc)."""
        return self._Ae

    def poles(self) -> np.ndarray:
        """Error poles: the eigenvalues of the error dynamics on range(Pc).

        The measured directions (``n - rank(C)`` of them are estimated, the rest
        read from ``y``) carry no error, so only ``n - rank(C)`` poles are
        listed; ``Av - Kv Cv`` also has ``rank(C)`` eigenvalues at 0 whose
        state never reaches ``xhat``.
        """
        V = self._basis
        return sort_poles(np.linalg.eigvals(V.T @ self._Ae @ V))

    def realization(self) -> ObserverRealization:
        pl = self.plant
        return ObserverRealization(
            A=self.F,
            B_u=(self.projection - self.K @ pl.C) @ pl.B,
            B_y=self.G,
            C=self.projection,
            D_y=self.Cg + self.projection @ self.K,
        )


class LuenbergerObserver(Observer):
    """Plain (Luenberger) observer ``xhat' = A xhat + B u + L (y - C xhat)``.

    It ignores the unknown inputs, so its error is driven by them:
    ``e' = (A - L C) e + E d - L D v``. Built by :func:`design_luenberger`.

    Examples
    --------
    >>> import uio_teach as ut
    >>> ut.design_luenberger(ut.examples.pa9(), poles=[-1, -2, -3]).decouples
    False
    """

    family = "Luenberger observer"
    _display_names = ("L", "F")
    _designer = "design_luenberger(plant, poles=...) or design_luenberger(plant, L=...)"

    def __init__(self, plant: Plant, L: np.ndarray) -> None:
        super().__init__(plant)
        self._L = _frozen(L)
        self._F = _frozen(plant.A - L @ plant.C)

    @property
    def L(self) -> np.ndarray:
        """The output-injection gain."""
        return self._L

    @property
    def F(self) -> np.ndarray:
        """``A - L C``: the error dynamics without unknown inputs."""
        return self._F

    @property
    def decouples(self) -> bool:
        return self.plant.q == 0 and self.plant.nv == 0

    @property
    def error_matrix(self) -> np.ndarray:
        return self.F

    def realization(self) -> ObserverRealization:
        pl = self.plant
        return ObserverRealization(
            A=self.F, B_u=pl.B, B_y=self.L, C=np.eye(pl.n), D_y=np.zeros((pl.n, pl.p))
        )


# design functions ---------------------------------------------------------------


def _frozen(M: np.ndarray) -> np.ndarray:
    """A read-only copy: an observer's matrices cannot be changed in place."""
    out = np.array(M, dtype=float)
    out.setflags(write=False)
    return out


def _norm(M: np.ndarray) -> float:
    return float(np.linalg.norm(M, 2)) if M.size else 0.0


def _verify_projection(obs: _ProjectionObserver, what: str) -> None:
    """UIO/PMO decoupling identities: ``H C E = E``, ``T E = 0``, ``H D = 0``, ``L D = 0``."""
    pl = obs.plant
    H, T, K1 = obs._H, obs._T, obs._K1
    # each identity against the entrywise size of its terms: the same verdict in any units
    if pl.q:
        HCE = product_bound((H, np.abs(pl.C) @ np.abs(pl.E)), pl.E)
        check_identity("H C E = E", H @ pl.C @ pl.E - pl.E, HCE, what=what)
        check_identity("T E = 0", T @ pl.E, HCE, what=what)
    if pl.nv:
        check_identity("H D = 0", H @ pl.D, product_bound((H, pl.D)), what=what)
        check_identity("L D = 0", K1 @ pl.D, product_bound((K1, pl.D)), what=what)


def _verify_ginverse(obs: GInverseObserver) -> None:
    pl = obs.plant
    Pc, K = obs.projection, obs.K
    if pl.q:
        check_identity(
            "(Pc - Pc K C) E = 0",
            (Pc - Pc @ K @ pl.C) @ pl.E,
            max(1.0, _norm(K) * _norm(pl.C)) * _norm(pl.E),
            what="the g-inverse observer",
        )


def _check_plant(plant: Any) -> Plant:
    if not isinstance(plant, Plant):
        raise ValueError(f"plant must be a uio_teach.Plant, got {type(plant).__name__}")
    return plant


def _decoupled_gain(name: str, plant: Plant, gain: Any) -> np.ndarray:
    """Check an explicit gain; one that meets ``gain D = 0`` only to printed precision
    (a gain copied from a document, rounded to 4 decimals) is projected onto it."""
    G = as_matrix(name, gain, plant.n, plant.p, what="n x p")
    if not plant.nv:
        return G
    scale = max(1.0, float(np.abs(G).max()))
    GD = G @ plant.D
    residual = float(np.abs(GD).max())
    if residual <= 1e-9 * scale:
        return G
    if residual <= 1e-3 * scale:
        warnings.warn(
            f"{name} D = {np.array2string(GD.ravel(), precision=2)} is not exactly 0 (a rounded "
            f"gain?); using the nearest gain with {name} D = 0",
            UserWarning,
            stacklevel=3,
        )
        return G - GD @ pinv(plant.D)
    raise ValueError(
        f"{name} D must be 0 so that the measurement disturbance does not enter the "
        f"error; got {name} D = {np.array2string(GD, precision=4)}"
    )


def _require(plant: Plant, what: str):
    report = check_existence(plant)
    if not report.ok:
        raise UIOExistenceError(report, what)
    return report


def design_uio(plant: Plant, poles: Any = None, *, K1: Any = None) -> UIO:
    """Design the unknown-input decoupling observer of Practical Assignment 9.

    ``H = E (CE)^+``, ``T = I - H C``, ``F = T A - K1 C``, ``K2 = F H``,
    ``K = K1 + K2``; the error obeys ``e' = F e`` whatever ``d`` is.
    With a measurement disturbance ``D``, ``H = [E 0][CE D]^+`` and ``K1 D = 0``.

    Parameters
    ----------
    plant : Plant
        Continuous or discrete plant.
    poles : array_like, optional
        The movable error poles: as many as the observable part of
        ``(TA, C)`` has (all ``n`` when the pair is observable). The other
        modes are fixed: they are the plant's invariant zeros (see
        :func:`check_existence`, ``fixed_modes``).
    K1 : array_like, shape (n, p), optional
        An explicit gain instead of ``poles`` (to reproduce a printed design).

    Returns
    -------
    UIO

    Raises
    ------
    UIOExistenceError
        A condition of :func:`check_existence` fails (rank condition, or an
        invariant zero outside the stability region).
    ValueError
        Neither or both of ``poles`` and ``K1`` given, a wrong number of
        poles, or ``K1`` of the wrong shape.
    ValueError
        ``uio_teach.verify.PlacementAccuracyError`` (a ``ValueError``): the
        computed design fails its own check, because the poles obtained differ
        from those requested beyond the tolerance or a decoupling identity
        (``T E = 0``, ``H C E = E``, ``L D = 0``) is lost to round-off.

    Warns
    -----
    UnstableObserverWarning
        If the chosen poles or ``K1`` leave the error dynamics unstable.
    PlacementAccuracyWarning
        The poles obtained are slightly off, more than round-off allows.

    Examples
    --------
    >>> import uio_teach as ut
    >>> plant = ut.examples.pa9()
    >>> obs = ut.design_uio(plant, poles=[-1, -2, -3])
    >>> obs.H.round(2)
    array([[0.94, 0.24],
           [0.  , 0.  ],
           [0.24, 0.06]])
    """
    plant = _check_plant(plant)
    if (poles is None) == (K1 is None):
        raise ValueError("give exactly one of poles= (the movable error poles) or K1=")
    _require(plant, "an unknown input observer")
    dec = decoupling(plant)
    requested = None
    if K1 is None:
        K1, requested = place_pair_poles(dec.pair, poles)
    else:
        K1 = _decoupled_gain("K1", plant, K1)
    obs = UIO(plant, dec.M, K1)
    _verify_projection(obs, "the UIO")
    if requested is not None:
        check_poles(obs.F, requested, what="the UIO", stacklevel=3)
    obs._warn_if_unstable()
    return obs


def design_pmo(
    plant: Plant,
    poles: Any = None,
    *,
    L: Any = None,
    method: str = "place",
    Mv: Any = None,
    decay: float | None = None,
) -> PMO:
    """Design the projection-operator full-order observer (PMO).

    ``M = E (CE)^g + Mv (I - CE (CE)^g)`` (eq. (19) of the missile paper;
    with ``D``: ``M = [E 0][CE D]^+`` as in the case study),
    ``A1 = (I - MC) A`` and the gain ``L`` of the error dynamics
    ``e' = (A1 - L C) e``.

    Parameters
    ----------
    plant : Plant
        Continuous or discrete plant.
    poles : array_like, optional
        Movable error poles, as in :func:`design_uio` (``method="place"``).
    L : array_like, shape (n, p), optional
        An explicit gain.
    method : {"place", "lmi"}
        ``"place"``: place ``poles``; ``"lmi"``: take ``L`` from
        :func:`lmi_gain` (as in the case study), with ``decay`` as its bound.
    Mv : array_like, shape (n, p), optional
        The free matrix of eq. (19); it has no effect when ``CE`` is square
        and invertible (the missile example).
    decay : float, optional
        With ``method="lmi"``: the LMI's decay bound (see :func:`lmi_gain`).

    Returns
    -------
    PMO

    Raises
    ------
    UIOExistenceError
        A condition of :func:`check_existence` fails.
    LMIInfeasibleError
        ``method="lmi"`` and the LMI has no solution.
    ValueError
        Inconsistent arguments, wrong pole count or shapes.
    ValueError
        ``uio_teach.verify.PlacementAccuracyError`` (a ``ValueError``): the
        computed design fails its own check, because the poles obtained differ
        from those requested beyond the tolerance or a decoupling identity
        (``T E = 0``, ``H C E = E``, ``L D = 0``) is lost to round-off.

    Warns
    -----
    UnstableObserverWarning
        If the error dynamics are unstable.
    PlacementAccuracyWarning
        The poles obtained are slightly off, more than round-off allows.

    Examples
    --------
    >>> import uio_teach as ut
    >>> pmo = ut.design_pmo(ut.examples.dt_case_study(), method="lmi")
    >>> pmo.L.round(4)
    array([[ 0.1667, -0.8333],
           [ 0.2833, -1.4167],
           [ 0.2667, -1.3333]])
    >>> pmo.poles().real.round(4).tolist()
    [0.0, 0.5, 0.5]
    """
    plant = _check_plant(plant)
    if method not in ("place", "lmi"):
        raise ValueError(f"method must be 'place' or 'lmi', got {method!r}")
    if method == "lmi" and (poles is not None or L is not None):
        raise ValueError("method='lmi' computes L itself: do not give poles= or L=")
    if method == "place" and (poles is None) == (L is None):
        raise ValueError("give exactly one of poles= or L= (or use method='lmi')")
    if decay is not None and method != "lmi":
        raise ValueError("decay= is the LMI's bound: use it with method='lmi'")
    _require(plant, "a projection-operator observer")
    if Mv is not None:
        if plant.nv:
            raise ValueError("Mv is not supported together with a measurement disturbance D")
        Mv = as_matrix("Mv", Mv, plant.n, plant.p, what="n x p")
    dec = decoupling(plant, Mv)
    certificate = None
    if method == "lmi":
        res = lmi_gain(dec.A1, plant.C, D=plant.D if plant.nv else None, dt=plant.dt, decay=decay)
        L, certificate = res.L, res.P
    requested = None
    if method == "lmi":
        pass
    elif L is None:
        L, requested = place_pair_poles(dec.pair, poles)
    else:
        L = _decoupled_gain("L", plant, L)
    obs = PMO(plant, dec.M, L, Mv, certificate)
    _verify_projection(obs, "the PMO")
    if requested is not None:
        check_poles(obs.F, requested, what="the PMO", stacklevel=3)
    obs._warn_if_unstable()
    return obs


def design_ginverse(plant: Plant, *, Kv: Any = None) -> GInverseObserver:
    """Design the generalized-matrix-inverse full-order observer (missile paper, eqs. (20)-(23)).

    Parameters
    ----------
    plant : Plant
        A plant without measurement disturbance, with ``C`` of full row rank.
    Kv : array_like, shape (n, p), optional
        The free gain of eq. (23), acting through ``Cv``; zero when omitted.
        It has no effect when ``CE`` is square and invertible (``Cv = 0``).

    Returns
    -------
    GInverseObserver

    Raises
    ------
    UIOExistenceError
        A condition of :func:`check_existence` fails.
    ValueError
        The plant has a measurement disturbance, ``C`` is rank deficient, or
        ``Kv`` has the wrong shape.
    ValueError
        ``uio_teach.verify.PlacementAccuracyError`` (a ``ValueError``): the
        computed design fails its own check, because the poles obtained differ
        from those requested beyond the tolerance or a decoupling identity
        (``T E = 0``, ``H C E = E``, ``L D = 0``) is lost to round-off.

    Examples
    --------
    >>> import uio_teach as ut
    >>> obs = ut.design_ginverse(ut.examples.missile_autopilot())
    >>> obs.poles().round(2)
    array([-105.6-142.09j, -105.6+142.09j])
    """
    plant = _check_plant(plant)
    if plant.nv:
        raise ValueError(
            "design_ginverse does not handle measurement disturbances (D); use design_pmo"
        )
    if rank(plant.C) < plant.p:
        raise ValueError(
            f"C has rank {rank(plant.C)} < p = {plant.p}: remove the redundant outputs first"
        )
    _require(plant, "a g-inverse observer")
    Kv = np.zeros((plant.n, plant.p)) if Kv is None else as_matrix("Kv", Kv, plant.n, plant.p)
    obs = GInverseObserver(plant, Kv)
    _verify_ginverse(obs)
    obs._warn_if_unstable()
    return obs


def design_luenberger(plant: Plant, poles: Any = None, *, L: Any = None) -> LuenbergerObserver:
    """Design a plain Luenberger observer, which ignores the unknown inputs.

    Parameters
    ----------
    plant : Plant
        Continuous or discrete plant.
    poles : array_like, optional
        Poles of ``A - L C`` (of its observable part).
    L : array_like, shape (n, p), optional
        An explicit gain instead of ``poles``.

    Returns
    -------
    LuenbergerObserver

    Raises
    ------
    ValueError
        ``uio_teach.verify.PlacementAccuracyError`` (a ``ValueError``): the
        computed design fails its own check, because the poles obtained differ
        from those requested beyond the tolerance or a decoupling identity
        (``T E = 0``, ``H C E = E``, ``L D = 0``) is lost to round-off.

    Examples
    --------
    >>> import uio_teach as ut
    >>> obs = ut.design_luenberger(ut.examples.pa9(), poles=[-1, -2, -3])
    >>> obs.decouples
    False
    """
    plant = _check_plant(plant)
    if (poles is None) == (L is None):
        raise ValueError("give exactly one of poles= or L=")
    requested = None
    if L is None:
        split = observability_decomposition(plant.A, plant.C)
        L = place_observer_poles(plant.A, plant.C, poles, split=split, verify=False)
        requested = requested_poles(poles, split.unobservable_modes, split.Ao.shape[0])
    else:
        L = as_matrix("L", L, plant.n, plant.p, what="n x p")
    obs = LuenbergerObserver(plant, L)
    if requested is not None:
        check_poles(obs.F, requested, what="the Luenberger observer", stacklevel=3)
    obs._warn_if_unstable()
    return obs
