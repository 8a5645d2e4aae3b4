"""The observer base class: realization, poles, display (every family builds on it)."""

from __future__ import annotations

import warnings
from typing import TYPE_CHECKING, Any, NamedTuple

import numpy as np

from .._display import fit_lines, format_complex, matrices_html, matrices_text
from ..errors import UIOTeachWarning
from ..linalg import is_stable, sort_poles
from ..plant import Plant
from ..verify import PlacementAccuracyError

if TYPE_CHECKING:  # python-control is imported where a conversion needs it
    import control as ct

__all__ = ["Observer", "ObserverRealization", "UnstableObserverWarning"]


class UnstableObserverWarning(UIOTeachWarning):
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
        import control as ct  # deferred on purpose: python-control takes a second to import

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
    def refuse_if_unstable(self, requested: np.ndarray | None) -> None:
        """Refuse a design whose error poles leave the stability region when none requested did.

        The fixed modes (the invariant zeros) are decided inside the region by the existence
        check, and the requested poles are inside it: an error pole on or beyond the boundary
        then comes from round-off of the design, and the observer's error would not decay.
        Raises ``uio_teach.verify.PlacementAccuracyError`` naming the poles.
        """
        if requested is None:
            return
        discrete = self.plant.is_discrete
        if not np.all(is_stable(np.asarray(requested, complex), discrete, margin=0.0)):
            return  # unstable poles were asked for: warn_if_unstable says so
        bad = [p for p in self.poles() if not is_stable([p], discrete, margin=0.0)[0]]
        if not bad:
            return
        region = "unit disk" if discrete else "left half-plane"
        raise PlacementAccuracyError(
            f"the {self.family} design has error pole(s) "
            + ", ".join(format_complex(p) for p in bad)
            + f" on or outside the open {region}, although every requested pole and every "
            "fixed mode lies inside: round-off of the design moved them there, so the "
            "estimation error would not decay; no observer is returned"
        )

    def warn_if_unstable(self) -> None:
        """Warn (``UnstableObserverWarning``) when the error dynamics are not stable."""
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
        return fit_lines(self._title())

    def __str__(self) -> str:
        return fit_lines(matrices_text(self._title(), self._items()))

    def _repr_html_(self) -> str:
        return matrices_html(self._title(), self._items())
