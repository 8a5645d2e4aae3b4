"""The generalized-matrix-inverse full-order observer of the missile paper (eqs. (20)-(23))."""

from __future__ import annotations

from typing import Any

import numpy as np

from .._validation import as_matrix, read_only
from ..errors import InputError
from ..linalg import one_blas_thread, pinv, rank, sort_poles
from ..plant import Plant, check_plant
from ..verify import check_decoupling, check_fixed_modes, check_identity, product_bound
from .base import Observer, ObserverRealization
from .projection import require_existence

__all__ = ["GInverseObserver", "design_ginverse", "verify_ginverse"]


class GInverseObserver(Observer):
    """Generalized-matrix-inverse full-order observer (eqs. (20)-(23) of the missile paper).

    With ``Cg = C^g`` and the orthogonal projection ``Pc = I - Cg C``::

        Kg = Pc E (CE)^g + Kv (I - CE (CE)^g)      (the paper's K)
        Av = Pc A Pc - Pc E (CE)^g C A Pc,   Cv = (I - CE (CE)^g) C A Pc
        z' = (Av - Kv Cv) z + G y + (Pc - Kg C) B u
        xhat = Pc z + (Cg + Pc Kg) y

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
    _display_names = ("Cg", "Kg", "Av", "Cv", "Kv", "G")
    _designer = "design_ginverse(plant, Kv=...)"

    def __init__(self, plant: Plant, Kv: np.ndarray) -> None:
        super().__init__(plant)
        n, p = plant.n, plant.p
        A, C, E = plant.A, plant.C, plant.E
        Cg = pinv(C)
        # the orthogonal projection onto ker C from an orthonormal basis of it: exactly 0 for an
        # invertible C (I - C^+ C would be round-off of size eps cond(C))
        Vn = _null_basis(C)
        Pc = Vn @ Vn.T
        CE = C @ E
        CEg = pinv(CE)
        W = np.eye(p) - CE @ CEg
        Kg = Pc @ E @ CEg + Kv @ W
        self._Cg = read_only(Cg)
        self._Pc = read_only(Pc)
        self._Kv = read_only(Kv)
        self._Kg = read_only(Kg)
        self._Av = read_only(Pc @ A @ Pc - Pc @ E @ CEg @ C @ A @ Pc)
        self._Cv = read_only(W @ C @ A @ Pc)
        self._G = read_only(Pc @ A @ Cg - Kg @ C @ A @ Cg + Pc @ A @ Pc @ Kg - Kg @ C @ A @ Pc @ Kg)
        self._Ae = read_only((Pc - Pc @ Kg @ C) @ A @ Pc)
        # orthonormal basis of range(Pc): the error lives there
        U, s, _ = np.linalg.svd(Pc)
        self._basis = U[:, : n - rank(C)]
        self._leak = None

    @property
    def leak(self):
        """How much of the unknown input can reach the estimation error, judged on the returned
        matrices (``uio_teach.verify.decoupling_leak``); set by the design."""
        return self._leak

    @property
    def Cg(self) -> np.ndarray:
        """``C^g``, the Moore-Penrose inverse of ``C``."""
        return self._Cg

    @property
    def projection(self) -> np.ndarray:
        """The orthogonal projection ``Pc = I - C^g C`` onto the unmeasured directions."""
        return self._Pc

    @property
    def Kv(self) -> np.ndarray:
        """The free gain of eq. (23)."""
        return self._Kv

    @property
    def Kg(self) -> np.ndarray:
        """The gain ``Kg = Pc E (CE)^g + Kv (I - CE (CE)^g)`` of condition (20), the
        paper's ``K``."""
        return self._Kg

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
    def Fv(self) -> np.ndarray:
        """The observer-state matrix ``Av - Kv Cv`` of eq. (21).

        Not the error matrix (``error_matrix``): it has ``rank(C)`` more eigenvalues, at 0.
        """
        return read_only(self.Av - self.Kv @ self.Cv)

    @property
    def error_matrix(self) -> np.ndarray:
        """The error dynamics ``e' = error_matrix e`` (``e`` in range(Pc)),
        ``(Pc - Pc Kg C) A Pc``."""
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
            A=self.Fv,
            B_u=(self.projection - self.Kg @ pl.C) @ pl.B,
            B_y=self.G,
            C=self.projection,
            D_y=self.Cg + self.projection @ self.Kg,
        )


def _null_basis(C: np.ndarray) -> np.ndarray:
    """Orthonormal basis (columns) of ker C, its dimension decided by ``rank``."""
    n = C.shape[1]
    _, _, Vt = np.linalg.svd(C, full_matrices=True)
    return Vt[rank(C) :].T.copy() if n else np.zeros((0, 0))


def verify_ginverse(obs: GInverseObserver, fixed: np.ndarray | None = None) -> None:
    """Verify a g-inverse observer on the data as given (identity and fixed modes)."""
    pl = obs.plant
    Pc, Kg = obs.projection, obs.Kg
    if pl.q:
        check_identity(
            "(Pc - Pc Kg C) E = 0",
            (Pc - Pc @ Kg @ pl.C) @ pl.E,
            product_bound((Pc, pl.E), (Pc @ Kg, np.abs(pl.C) @ np.abs(pl.E))),
            what="the g-inverse observer",
        )
    poles = obs.poles()
    if fixed is not None and len(fixed) <= len(poles):
        check_fixed_modes(poles, fixed, what="the g-inverse observer")
    # from first principles: the observer state tracks (I - Kg C) x, xhat = Pc w + Dy y
    real = obs.realization()
    obs._leak = check_decoupling(
        pl.A,
        pl.E,
        pl.C,
        real.A,
        real.B_y,
        real.C,
        real.D_y,
        Kg,
        discrete=pl.is_discrete,
        what="the g-inverse observer",
        stacklevel=4,
    )


@one_blas_thread()
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
    PlacementAccuracyError
        A ``ValueError``: the computed design fails its own check. The identity
        ``(Pc - Pc Kg C) E = 0`` holds only to more than round-off, a fixed
        mode is not an error pole, or the returned matrices let the unknown
        input reach the error (``uio_teach.verify.DecouplingError``).

    Warns
    -----
    DecouplingWarning
        ``uio_teach.verify.DecouplingWarning``: the design decouples only to a
        stated fraction, because it amplifies round-off (a small ``C E``).

    Examples
    --------
    >>> import uio_teach as ut
    >>> obs = ut.design_ginverse(ut.examples.missile_autopilot())
    >>> obs.poles().round(2)
    array([-105.6-142.09j, -105.6+142.09j])
    """
    plant = check_plant(plant)
    if plant.nv:
        raise InputError(
            "design_ginverse does not handle measurement disturbances (D); use design_pmo"
        )
    if rank(plant.C) < plant.p:
        raise InputError(
            f"C has rank {rank(plant.C)} < p = {plant.p}: remove the redundant outputs first"
        )
    report = require_existence(plant, "a g-inverse observer")
    Kv = np.zeros((plant.n, plant.p)) if Kv is None else as_matrix("Kv", Kv, plant.n, plant.p)
    obs = GInverseObserver(plant, Kv)
    verify_ginverse(obs, report.fixed_modes)
    obs.warn_if_unstable()
    return obs
