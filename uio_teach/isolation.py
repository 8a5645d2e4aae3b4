"""Fault isolation with a bank of unknown input observers (Chen and Patton's observer schemes).

Member ``i`` of the bank is an unknown input observer that is *blind to fault
``i``* and to the disturbance ``d``, and sees every other fault:

* **actuator bank** (generalized observer scheme for actuators): member ``i``
  treats actuator ``i``'s input as unknown, ``E_i = [E, B[:, i]]``, and does
  not read ``u_i``;
* **sensor bank** (generalized observer scheme for sensors): member ``j``
  reads every output except ``y_j``.

A fault in actuator (sensor) ``i`` leaves residual ``i`` quiet while the
others fire: the pattern of alarms names the fault. Each member must exist
(``check_existence`` of its own model) and must keep a residual at all: with
as many measurements as decoupled inputs its residual obeys ``r' = -C K1 r``
and reads no data (see :attr:`BankMember.residual_size`).
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

from . import tolerances as tols
from ._display import call_repr, fit_lines, format_poles
from .detection import Threshold, detect, observer_residual, residual_threshold
from .errors import InputError
from .existence import ExistenceReport, check_existence
from .linalg import rank
from .observers import UIO, design_uio
from .plant import Plant, check_plant
from .simulation import UIOResponse

__all__ = ["BankMember", "UIOBank", "Isolation", "design_uio_bank"]


@dataclass(frozen=True)
class BankMember:
    """One observer of a bank: the model it uses and whether it exists.

    Attributes
    ----------
    fault : str
        The fault this member is blind to, e.g. ``"actuator 1"``.
    plant : Plant
        The member's model: which inputs are unknown, which outputs it reads.
    inputs : tuple of int
        The known inputs it reads (indices into ``u``).
    outputs : tuple of int
        The outputs it reads (indices into ``y``).
    report : ExistenceReport
        ``check_existence(plant)``.
    observer : UIO or None
        The designed observer; ``None`` when it does not exist.

    Examples
    --------
    >>> import uio_teach as ut
    >>> bank = ut.design_uio_bank(ut.examples.pa9(), "actuator", poles=[-2, -3, -4])
    >>> member = bank.members[0]
    >>> member.fault, member.exists, member.report.failed[0].name
    ('actuator 1', False, 'rank condition')
    """

    fault: str
    plant: Plant
    inputs: tuple[int, ...]
    outputs: tuple[int, ...]
    report: ExistenceReport
    observer: UIO | None

    def __repr__(self) -> str:
        state = "exists" if self.exists else "does not exist"
        return call_repr(
            "BankMember",
            [
                ("fault", self.fault),
                ("inputs", self.inputs),
                ("outputs", self.outputs),
                ("observer", state),
            ],
        )

    @property
    def exists(self) -> bool:
        """True if the member's existence conditions hold (it was designed)."""
        return self.observer is not None

    @property
    def residual_size(self) -> int:
        """The number of independent residual directions, ``rank(C_i) - rank(C_i E_i)``.

        Zero means the member has no residual worth the name: with as many
        independent measurements as decoupled inputs, ``C H = I``, so
        ``r = -C z`` obeys ``r' = -C K1 r`` whatever the data (faults included).
        """
        C, E = self.plant.C, self.plant.E
        return int(rank(C) - rank(C @ E)) if E.shape[1] else int(rank(C))

    @property
    def usable(self) -> bool:
        """True if the member exists and its residual can react to a fault."""
        return self.exists and self.residual_size > 0


@dataclass(frozen=True)
class Isolation:
    """Which residuals of a bank fired, and the fault this pattern points to.

    Attributes
    ----------
    faults : tuple of str
        The fault each member is blind to, in the bank's order.
    fired : tuple of bool or None
        Whether each member's residual raised an alarm; ``None`` for a member
        that is not usable.
    first_alarms : tuple of float or None
        Each member's first alarm time.
    suspect : str
        The isolated fault, ``"no fault"`` when nothing fired, or
        ``"not isolated"`` when the pattern matches no single fault.

    Examples
    --------
    >>> import numpy as np
    >>> import uio_teach as ut
    >>> iso = ut.Isolation(faults=("a", "b", "c"), fired=(True, False, True),
    ...                    first_alarms=(1.0, None, 1.2))
    >>> iso.suspect
    'b'
    """

    faults: tuple[str, ...]
    fired: tuple[bool | None, ...]
    first_alarms: tuple[float | None, ...]

    def __repr__(self) -> str:
        return call_repr(
            "Isolation",
            [("faults", self.faults), ("fired", self.fired), ("suspect", self.suspect)],
        )

    @property
    def suspect(self) -> str:
        """The single fault whose member stayed silent while every other usable one fired."""
        usable = [(f, s) for f, s in zip(self.faults, self.fired, strict=True) if s is not None]
        if not any(s for _, s in usable):
            return "no fault"
        silent = [f for f, s in usable if not s]
        if len(silent) == 1 and len(usable) == len(self.faults):
            return silent[0]
        return "not isolated"


class UIOBank:
    """A bank of unknown input observers, one per fault to isolate (see :func:`design_uio_bank`).

    Attributes
    ----------
    plant : Plant
        The monitored plant.
    kind : str
        ``"actuator"`` or ``"sensor"``.
    members : tuple of BankMember
        One member per actuator (sensor), in order.

    Examples
    --------
    >>> import uio_teach as ut
    >>> plant = ut.Plant(ut.examples.pa9().A, ut.examples.pa9().C, B=ut.examples.pa9().B)
    >>> bank = ut.design_uio_bank(plant, "sensor", poles=[-2, -3, -4])
    >>> [m.fault for m in bank.members]
    ['sensor 1', 'sensor 2']
    """

    def __init__(self, plant: Plant, kind: str, members: Sequence[BankMember]) -> None:
        self.plant = plant
        self.kind = kind
        self.members = tuple(members)

    @property
    def observers(self) -> list[UIO | None]:
        """The members' observers (``None`` for a member that does not exist)."""
        return [m.observer for m in self.members]

    @property
    def faults(self) -> tuple[str, ...]:
        """The fault each member is blind to."""
        return tuple(m.fault for m in self.members)

    def residuals(self, response: UIOResponse) -> list[np.ndarray | None]:
        """Run every member on the inputs and measurements of a simulation.

        Parameters
        ----------
        response : UIOResponse
            A simulation of the monitored plant (e.g. from
            :func:`uio_teach.simulate_fault`); its ``inputs.u`` and ``outputs``
            are the data.

        Returns
        -------
        list of numpy.ndarray or None
            One residual per member (``None`` for a member that does not exist).

        Examples
        --------
        >>> import numpy as np
        >>> import uio_teach as ut
        >>> pa9 = ut.examples.pa9()
        >>> plant = ut.Plant(pa9.A, np.eye(3), B=pa9.B, E=pa9.E)
        >>> bank = ut.design_uio_bank(plant, "actuator", poles=[-2, -3, -4])
        >>> t = np.linspace(0, 5, 501)
        >>> resp = ut.simulate_fault(plant, ut.design_uio(plant, poles=[-2, -3, -4]), t)
        >>> [r.shape for r in bank.residuals(resp)]
        [(3, 501), (3, 501)]
        """
        if not isinstance(response, UIOResponse):
            raise InputError(
                f"response must be a UIOResponse (from simulate or simulate_fault), got "
                f"{type(response).__name__}"
            )
        if (
            response.plant.n != self.plant.n
            or response.plant.p != self.plant.p
            or (response.plant.m != self.plant.m)
        ):
            raise InputError(
                f"response simulates a plant with n, m, p = {response.plant.n}, "
                f"{response.plant.m}, {response.plant.p}; the bank monitors one with "
                f"{self.plant.n}, {self.plant.m}, {self.plant.p}"
            )
        u, y = np.asarray(response.inputs.u), np.asarray(response.outputs)
        out: list[np.ndarray | None] = []
        for m in self.members:
            if m.observer is None:
                out.append(None)
                continue
            out.append(
                observer_residual(m.observer, response.time, u[list(m.inputs)], y[list(m.outputs)])
            )
        return out

    def thresholds(
        self,
        healthy: Sequence[UIOResponse],
        *,
        false_alarm_rate: float,
        window: float,
        start: float | None = None,
        per: str = "run",
    ) -> list[Threshold | None]:
        """One threshold per usable member, from fault-free simulations.

        Parameters
        ----------
        healthy : sequence of UIOResponse
            Fault-free runs with measurement noise, on one time grid.
        false_alarm_rate : float
            The design rate of each member's threshold (see
            :func:`uio_teach.residual_threshold`).
        window : float
            Window of :func:`uio_teach.residual_rms`.
        start : float, optional
            Monitoring starts here.
        per : {"run", "sample"}
            What the rate counts (see :func:`uio_teach.residual_threshold`);
            by default whole runs, so that a fault-free run rarely names a fault.

        Returns
        -------
        list of Threshold or None
            ``None`` for a member that is not usable.

        Examples
        --------
        >>> import numpy as np
        >>> import uio_teach as ut
        >>> pa9 = ut.examples.pa9()
        >>> plant = ut.Plant(pa9.A, np.eye(3), B=pa9.B, E=pa9.E)
        >>> bank = ut.design_uio_bank(plant, "actuator", poles=[-2, -3, -4])
        >>> t = np.linspace(0, 5, 501)
        >>> uio = ut.design_uio(plant, poles=[-2, -3, -4])
        >>> runs = [ut.simulate_fault(plant, uio, t, noise=0.01, seed=k) for k in range(3)]
        >>> [type(th).__name__ for th in bank.thresholds(runs, false_alarm_rate=0.01, window=0.5)]
        ['Threshold', 'Threshold']
        """
        runs = list(healthy)
        if not runs:
            raise InputError("healthy must hold at least one fault-free UIOResponse")
        t = runs[0].time
        for k, run in enumerate(runs):
            if not isinstance(run, UIOResponse):
                raise InputError(f"healthy[{k}] must be a UIOResponse, got {type(run).__name__}")
            if run.time.shape != t.shape or not np.array_equal(run.time, t):
                raise InputError(f"healthy[{k}] has another time grid than healthy[0]")
        per_run = [self.residuals(run) for run in runs]
        out: list[Threshold | None] = []
        for i, m in enumerate(self.members):
            if not m.usable:
                out.append(None)
                continue
            R = np.stack([res[i] for res in per_run])
            out.append(
                residual_threshold(
                    t, R, false_alarm_rate=false_alarm_rate, window=window, start=start, per=per
                )
            )
        return out

    def isolate(self, response: UIOResponse, thresholds: Sequence[Threshold | None]) -> Isolation:
        """Which members fire on this run, and which fault that points to.

        Parameters
        ----------
        response : UIOResponse
            A simulation of the monitored plant.
        thresholds : sequence of Threshold or None
            One per member, from :meth:`thresholds`.

        Returns
        -------
        Isolation

        Examples
        --------
        >>> import numpy as np
        >>> import uio_teach as ut
        >>> pa9 = ut.examples.pa9()
        >>> plant = ut.Plant(pa9.A, np.eye(3), B=pa9.B, E=pa9.E)
        >>> bank = ut.design_uio_bank(plant, "actuator", poles=[-2, -3, -4])
        >>> t = np.linspace(0, 10, 1001)
        >>> obs = ut.design_uio(plant, poles=[-2, -3, -4])  # the detector; the bank reads its data
        >>> healthy = [ut.simulate_fault(plant, obs, t, noise=0.01, seed=k) for k in range(20)]
        >>> ths = bank.thresholds(healthy, false_alarm_rate=0.05, window=0.5)
        >>> fault = ut.actuator_fault(plant, 1, ut.signals.step(0.5, 5.0))
        >>> bank.isolate(ut.simulate_fault(plant, obs, t, fault, noise=0.01, seed=7), ths).suspect
        'actuator 2'
        """
        ths = list(thresholds)
        if len(ths) != len(self.members):
            raise InputError(
                f"thresholds must hold one entry per member ({len(self.members)}), got {len(ths)}"
            )
        residuals = self.residuals(response)
        fired: list[bool | None] = []
        first: list[float | None] = []
        for m, th, r in zip(self.members, ths, residuals, strict=True):
            if not m.usable or th is None or r is None:
                fired.append(None)
                first.append(None)
                continue
            det = detect(response.time, r, th)
            fired.append(det.fired)
            first.append(det.first_alarm)
        return Isolation(faults=self.faults, fired=tuple(fired), first_alarms=tuple(first))

    def __repr__(self) -> str:
        pl = self.plant
        name = f"{pl.name!r}, " if pl.name else ""
        lines = [f"UIOBank({self.kind} faults of plant {name}n={pl.n}, m={pl.m}, p={pl.p})"]
        for m in self.members:
            if m.exists:
                state = f"residual of size {m.residual_size}" if m.usable else "residual blind"
            else:
                state = "does not exist: " + ", ".join(c.name for c in m.report.failed)
            lines.append(f"  blind to {m.fault}: {state}")
        return fit_lines("\n".join(lines))


def design_uio_bank(plant: Plant, kind: str, poles: Any) -> UIOBank:
    """Design a bank of UIOs, member ``i`` blind to fault ``i`` and to the disturbance.

    Parameters
    ----------
    plant : Plant
        The monitored plant (its ``E`` and ``D`` are decoupled by every member).
    kind : {"actuator", "sensor"}
        ``"actuator"``: member ``i`` adds ``B[:, i]`` to ``E`` and does not
        read ``u_i``. ``"sensor"``: member ``j`` does not read ``y_j``.
    poles : array_like
        Candidate error poles; each member places as many of the first ones
        as it can move (its report's ``movable``), skipping candidates on its
        fixed modes (no gain moves those); the rest of its poles are its
        fixed modes.

    Returns
    -------
    UIOBank
        Members whose existence conditions fail are kept, with
        ``observer=None`` and the report saying why.

    Raises
    ------
    ValueError
        ``plant`` is not a Plant, ``kind`` is unknown, the plant has a
        single actuator (sensor), or too few ``poles``.

    Examples
    --------
    >>> import uio_teach as ut
    >>> ut.design_uio_bank(ut.examples.pa9(), "actuator", poles=[-2, -3, -4])
    UIOBank(actuator faults of plant 'PA9', n=3, m=2, p=2)
      blind to actuator 1: does not exist: rank condition
      blind to actuator 2: residual blind
    """
    plant = check_plant(plant)
    if kind not in ("actuator", "sensor"):
        raise InputError(f"kind must be 'actuator' or 'sensor', got {kind!r}")
    try:
        cand = np.atleast_1d(np.array(poles, dtype=complex)).ravel()
    except (TypeError, ValueError) as exc:
        raise InputError(f"poles must be a list of numbers: {exc}") from None
    count = plant.m if kind == "actuator" else plant.p
    if count < 2:
        what = "actuators (columns of B)" if kind == "actuator" else "sensors (rows of C)"
        article = "an" if kind == "actuator" else "a"
        raise InputError(f"{article} {kind} bank needs at least 2 {what}; the plant has {count}")
    members = []
    for i in range(count):
        if kind == "actuator":
            keep = tuple(k for k in range(plant.m) if k != i)
            outputs = tuple(range(plant.p))
            model = Plant(
                plant.A,
                plant.C,
                B=plant.B[:, list(keep)],
                E=np.hstack([plant.E, plant.B[:, [i]]]),
                D=plant.D,
                dt=plant.dt,
                name=f"blind to actuator {i + 1}",
            )
            inputs = keep
        else:
            outputs = tuple(k for k in range(plant.p) if k != i)
            model = Plant(
                plant.A,
                plant.C[list(outputs)],
                B=plant.B,
                E=plant.E,
                D=plant.D[list(outputs)],
                dt=plant.dt,
                name=f"blind to sensor {i + 1}",
            )
            inputs = tuple(range(plant.m))
        report = check_existence(model)
        observer = None
        if report.ok:
            # a candidate on one of the member's fixed modes is skipped: no gain moves that
            # mode, so a pole requested there is refused by the design
            free = np.array(
                [
                    c
                    for c in cand
                    if np.all(
                        np.abs(report.fixed_modes - c) > tols.FIXED_POLE_RTOL * max(1.0, abs(c))
                    )
                ],
                dtype=complex,
            )
            if free.size < report.movable:
                raise InputError(
                    f"poles: the member blind to {kind} {i + 1} can place {report.movable} "
                    f"poles, but only {free.size} were given away from its fixed modes "
                    f"{format_poles(report.fixed_modes, braces=True, empty='none')}"
                )
            observer = design_uio(model, poles=free[: report.movable])
        members.append(
            BankMember(
                fault=f"{kind} {i + 1}",
                plant=model,
                inputs=inputs,
                outputs=outputs,
                report=report,
                observer=observer,
            )
        )
    return UIOBank(plant, kind, members)
