"""Unknown input observers designed from one recorded experiment, without a model.

In an offline experiment the known input ``u``, the outputs ``y`` and the states ``x`` of a
discrete-time plant ``x[k+1] = A x[k] + B u[k] + E d[k]``, ``y[k] = C x[k]`` are recorded; the
unknown input ``d`` acts but is not recorded, and none of ``A, B, C, E`` is known. With ``N``
samples the data matrices (one column per transition ``k = 0 ... N-2``) are::

    U_p = [u[0] ... u[N-2]],   Y_p = [y[0] ... y[N-2]],   X_p = [x[0] ... x[N-2]]
    Y_f = [y[1] ... y[N-1]],   X_f = [x[1] ... x[N-1]]

(past and future blocks of depth one, as in Turan & Ferrari-Trecate, *Data-driven unknown-input
observers and state estimation*, IEEE Control Systems Letters 6, 2022). A UIO exists in the data
when the next state is a fixed linear function of the past input, output, state and the next
output, ``ker [U_p; Y_p; X_p; Y_f] within ker X_f``; its coefficients are the observer's
``T B``, ``K1``, ``F`` and ``H``. With data rich enough this kernel condition is the rank
condition and the observer's fixed poles are the invariant zeros (Disarò & Valcher, *On the
equivalence of model-based and data-driven approaches to the design of unknown-input
observers*, arXiv 2311.00673).

The design here goes through a *data plant*: ``C = Y X^+``; the directions in which the next
state moves that the known input and the state do not explain span ``im E`` (the data's
``E``); and the least-squares model ``[B A] = X_f [U_p; X_p]^+``, wrong in the directions of
``E`` (the unknown input's share is folded into it), differs from the true one by ``E G`` only,
which ``T = I - H C`` removes (``T E = 0``). The invariant zeros and the rank condition do not
change under that difference, so :func:`check_data` reaches the model-based verdicts of
:func:`uio_teach.check_existence` and ``design_uio_from_data`` the observer of
:func:`uio_teach.design_uio`, from the data alone.
"""

from __future__ import annotations

import warnings
from dataclasses import dataclass, field
from typing import Any, NamedTuple

import numpy as np
import scipy.linalg

from ._display import fit_lines
from ._validation import as_real_array, as_real_number, as_seed
from .errors import InputError, UIOTeachError, UIOTeachWarning
from .existence import (
    Condition,
    ExistenceReport,
    check_existence,
    conditions_html,
    conditions_text,
)
from .linalg import pinv
from .observers import UIO, UnstableObserverWarning, design_uio
from .observers.projection import verify_projection
from .plant import Plant, check_plant

__all__ = [
    "DATA_MARGIN",
    "DataConditionError",
    "DataConditioningWarning",
    "DataMatrices",
    "DataReport",
    "Experiment",
    "check_data",
    "data_matrices",
    "design_uio_from_data",
    "NoiseStudy",
    "noise_study",
    "record_experiment",
    "sampled_plant",
]

DATA_MARGIN = 10.0
"""A singular value of the (row-scaled) data matrices that the design keeps must exceed the
rank threshold by this factor, else the data are too ill-conditioned to trust: the noise the
threshold stands for (a tenth of it, ``NOISE_EDGE``) would move the directions the design reads
from the data by more than a percent."""

NOISE_EDGE = 10.0
"""The rank threshold of an ``r x L`` data matrix whose rows are scaled to unit RMS is
``NOISE_EDGE * rtol * (sqrt(L) + sqrt(r))``: white noise of relative size ``rtol`` has singular
values up to ``rtol (sqrt(L) + sqrt(r))`` (the Marchenko-Pastur edge), with tenfold room."""

ROUND_OFF_RTOL = 1e3
"""The default ``rtol`` of noise-free (simulated) data is ``ROUND_OFF_RTOL * eps``, the rounding
of a state recorded after a thousand steps of a recursion, with room."""


class DataConditionError(UIOTeachError, ValueError):
    """The recorded data cannot give an unknown input observer; ``.report`` says which
    condition failed, why, and what to record instead."""

    def __init__(self, report: DataReport) -> None:
        self.report = report
        reasons = "; ".join(f"{c.name}: {c.reason}" for c in report.failed)
        super().__init__(f"cannot design an unknown input observer from these data: {reasons}")


class DataConditioningWarning(UIOTeachWarning):
    """The data matrices are too ill-conditioned to trust the design (noise, short data)."""


class DataMatrices(NamedTuple):
    """The data matrices of one experiment: past blocks ``U_p, Y_p, X_p`` (samples
    ``0 ... N-2``) and future blocks ``Y_f, X_f`` (samples ``1 ... N-1``), one column per
    transition.

    Examples
    --------
    >>> import numpy as np
    >>> from uio_teach.data_driven import data_matrices
    >>> mats = data_matrices(None, np.ones((1, 5)), np.arange(10.0).reshape(2, 5))
    >>> mats.X_p.shape, mats.X_f[:, 0].tolist(), mats.U_p.shape
    ((2, 4), [1.0, 6.0], (0, 4))
    """

    U_p: np.ndarray
    Y_p: np.ndarray
    X_p: np.ndarray
    Y_f: np.ndarray
    X_f: np.ndarray

    @property
    def transitions(self) -> int:
        """The number of columns ``L = N - 1``."""
        return self.X_p.shape[1]


class Experiment(NamedTuple):
    """A recorded experiment (:func:`record_experiment`): one row per channel, one column per
    sample. ``d`` is what acted but was not recorded: a design never reads it."""

    u: np.ndarray | None
    y: np.ndarray
    x: np.ndarray
    d: np.ndarray


@dataclass(frozen=True)
class DataReport:
    """Which conditions of the data-driven design hold, and why (:func:`check_data`).

    Attributes
    ----------
    conditions : tuple of Condition
        The data conditions (enough samples, excitation, ``y = C x``, the unknown input's
        directions), then the existence conditions of the data plant, each with a one-line
        reason; a condition that could not be evaluated has ``holds=None``.
    samples : int
        ``N``, the number of recorded samples.
    directions : int
        In how many independent directions the unknown input moved the state in the
        experiment (the rank of the data's ``E``).
    plant : Plant or None
        The data plant: ``C`` and ``im E`` as the data give them, ``[B A]`` fitted by least
        squares (exact up to ``E G``, which no UIO sees); ``None`` when the data conditions fail.
    existence : ExistenceReport or None
        :func:`uio_teach.check_existence` of the data plant.
    margin : float
        The smallest ratio of a kept singular value of the data matrices to its rank threshold
        (below ``DATA_MARGIN`` the design warns).

    Examples
    --------
    >>> import uio_teach as ut
    >>> from uio_teach.data_driven import check_data, record_experiment
    >>> rec = record_experiment(ut.examples.dt_case_study(), 20, seed=1)
    >>> report = check_data(rec.u, rec.y, rec.x, dt=1, unknown_inputs=1)
    >>> report.ok, report.directions
    (False, 1)
    >>> [c.name for c in report.failed]  # A = 0.5 I: the state stays in span{x(0), E}
    ['input and state exciting']
    """

    conditions: tuple[Condition, ...]
    samples: int
    directions: int
    plant: Plant | None = None
    existence: ExistenceReport | None = None
    margin: float = field(default=np.inf)

    @property
    def ok(self) -> bool:
        """True when every required condition holds, so that a UIO can be designed from the data."""
        return all(c.holds for c in self.conditions if c.required)

    @property
    def failed(self) -> tuple[Condition, ...]:
        """The required conditions that do not hold (or cannot be decided)."""
        return tuple(c for c in self.conditions if c.required and (c.holds is False or c.undecided))

    @property
    def verdict(self) -> str:
        """The conclusion in words."""
        if self.ok:
            return "a UIO can be designed from these data"
        if self.existence is not None and not self.existence.ok:
            return "the data show that no UIO with stable error dynamics exists"
        return "these data cannot decide: record again as the reasons say"

    def __getitem__(self, name: str) -> Condition:
        for c in self.conditions:
            if c.name == name:
                return c
        raise KeyError(f"no condition named {name!r}; have {[c.name for c in self.conditions]}")

    def __str__(self) -> str:
        head = f"Data conditions for an unknown input observer ({self.samples} samples)"
        return conditions_text(fit_lines(head), self.conditions, self.verdict)

    __repr__ = __str__

    def _repr_html_(self) -> str:
        title = f"<b>Data conditions for an unknown input observer</b> ({self.samples} samples)"
        return conditions_html(title, self.conditions, self.verdict)


# input checks -----------------------------------------------------------------------------------


def _signal(name: str, value: Any, N: int | None, what: str) -> np.ndarray:
    arr = as_real_array(name, value)
    if arr.ndim == 1:
        arr = arr.reshape(1, -1)
    if arr.ndim != 2:
        raise InputError(
            f"{name} must have one row per channel and one column per sample ({what}), got an "
            f"array of shape {arr.shape}"
        )
    if arr.shape[0] == 0:
        raise InputError(f"{name} has no channel: it must have one row per {what}")
    if N is not None and arr.shape[1] != N:
        raise InputError(
            f"{name} has {arr.shape[1]} samples (columns) but x has {N}: every recorded signal "
            "needs one column per sample of the same experiment"
        )
    return arr


def _recorded(u: Any, y: Any, x: Any) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    x = _signal("x", x, None, "state")
    N = x.shape[1]
    y = _signal("y", y, N, "output")
    u = np.zeros((0, N)) if u is None else _signal("u", u, N, "known input")
    if N < 2:
        raise InputError(f"x has {N} sample: a design from data needs at least two")
    return u, y, x


def _several(value: Any) -> bool:
    """Several experiments: a list or tuple of 2-D arrays (one per experiment)."""
    return (
        isinstance(value, (list, tuple))
        and len(value) > 0
        and all(isinstance(v, np.ndarray) and v.ndim == 2 for v in value)
    )


def _experiments(u: Any, y: Any, x: Any) -> list[tuple[np.ndarray, np.ndarray, np.ndarray]]:
    """One experiment, or several (lists of 2-D arrays, one per experiment), each checked."""
    if not _several(x):
        return [_recorded(u, y, x)]
    k = len(x)
    if not _several(y) or len(y) != k or (u is not None and (not _several(u) or len(u) != k)):
        raise InputError(
            f"x holds {k} experiments: y (and u, when given) must be lists of {k} 2-D arrays too"
        )
    runs = [_recorded(None if u is None else u[i], y[i], x[i]) for i in range(k)]
    for name, j in (("u", 0), ("y", 1), ("x", 2)):
        rows = {r[j].shape[0] for r in runs}
        if len(rows) > 1:
            raise InputError(
                f"the experiments' {name} have different numbers of rows: {sorted(rows)}"
            )
    return runs


def _discrete_dt(dt: Any) -> float | bool:
    if dt is True:
        return True
    if dt is None or isinstance(dt, bool) or dt == 0:
        raise InputError(
            f"dt must be True or the positive sampling period of the recorded samples, got "
            f"{dt!r}: the data-driven design is discrete-time (one column per sample)"
        )
    return as_real_number("dt", dt, low=0.0, strict=True)


def _unknown_inputs(value: Any, n: int) -> int | None:
    if value is None:
        return None
    if isinstance(value, bool) or not isinstance(value, (int, np.integer)) or not 0 <= value <= n:
        raise InputError(
            f"unknown_inputs must be None or the number of unknown inputs, an integer from 0 to "
            f"n = {n}, got {value!r}"
        )
    return int(value)


# data matrices and rank decisions ---------------------------------------------------------------


def data_matrices(u: Any, y: Any, x: Any) -> DataMatrices:
    """The past and future data matrices of a recorded experiment (depth one each).

    Parameters
    ----------
    u : array_like, shape (m, N), or None
        The known input (``None`` when there is none).
    y : array_like, shape (p, N)
        The recorded outputs.
    x : array_like, shape (n, N)
        The recorded states.

    Returns
    -------
    DataMatrices

    Examples
    --------
    >>> import numpy as np
    >>> from uio_teach.data_driven import data_matrices
    >>> data_matrices([[1, 2, 3]], [[0, 1, 0]], [[5, 6, 7]]).Y_f.tolist()
    [[1.0, 0.0]]
    """
    return _split(_experiments(u, y, x))


def _split(runs: list[tuple[np.ndarray, np.ndarray, np.ndarray]]) -> DataMatrices:
    """The blocks of every experiment side by side (no transition across two experiments)."""
    mats = DataMatrices(
        *(
            np.hstack(
                [
                    blocks[i]
                    for blocks in (
                        (u[:, :-1], y[:, :-1], x[:, :-1], y[:, 1:], x[:, 1:]) for u, y, x in runs
                    )
                ]
            )
            for i in range(5)
        )
    )
    for M in mats:
        M.setflags(write=False)
    return mats


def _unit_rows(M: np.ndarray) -> np.ndarray:
    """Each row scaled to unit RMS (a zero row stays zero): rank decisions in any units."""
    rms = np.sqrt(np.mean(M**2, axis=1)) if M.shape[1] else np.zeros(M.shape[0])
    return M / np.where(rms > 0, rms, 1.0)[:, None]


def _threshold(M: np.ndarray, rtol: float) -> float:
    r, L = M.shape
    return NOISE_EDGE * rtol * (np.sqrt(L) + np.sqrt(r))


def _rank(M: np.ndarray, rtol: float) -> tuple[int, np.ndarray, float]:
    """Rank of the row-scaled ``M``, its singular values, and the threshold."""
    S = _unit_rows(M)
    s = np.linalg.svd(S, compute_uv=False) if S.size else np.zeros(0)
    tol = _threshold(S, rtol)
    return int(np.sum(s > tol)), s, tol


def _row_space_residual(M: np.ndarray, basis: np.ndarray, rank: int) -> np.ndarray:
    """``M`` minus its projection on the row space of ``basis`` (its ``rank`` leading
    right singular vectors, taken in row-scaled units)."""
    if not rank:
        return M
    _, _, Vt = np.linalg.svd(_unit_rows(basis), full_matrices=False)
    V = Vt[:rank].T
    return M - (M @ V) @ V.T


# the report -------------------------------------------------------------------------------------


def _not_evaluated(why: str) -> list[Condition]:
    return [
        Condition("rank condition", None, why),
        Condition("invariant zeros stable", None, why),
    ]


def check_data(
    u: Any,
    y: Any,
    x: Any,
    *,
    dt: float | bool,
    unknown_inputs: int | None = None,
    rtol: float | None = None,
) -> DataReport:
    """Check whether a recorded experiment can give an unknown input observer, and why.

    The data conditions, in order:

    1. **enough samples**: the ``N - 1`` transitions outnumber the dimensions that the known
       input, the state and the next state span, so the data show which combinations of them
       the unknown input leaves alone (with ``unknown_inputs=q``: ``N >= m + n + q + 2``).
    2. **input and state exciting**: ``[U_p; X_p]`` has full row rank ``m + n`` (the known
       input and the state varied independently), so ``T A`` and ``T B`` are determined.
    3. **outputs a function of the state**: ``Y = C X`` for one matrix ``C`` (no feedthrough,
       no output disturbance), which the data then give as ``C = Y X^+``.
    4. **unknown input shows every direction** (with ``unknown_inputs=q``): the next state
       moved in ``q`` directions the known input and the state do not explain. A direction
       the unknown input never took in the experiment is not seen, hence not decoupled; without
       ``unknown_inputs`` this is reported as information only.

    Then the conditions of :func:`uio_teach.check_existence`, evaluated on the data plant
    (``C``, the data's ``E`` and the least-squares ``[B A]``): the **rank condition** (in the
    data: the kernel condition ``ker [U_p; Y_p; X_p; Y_f]`` within ``ker X_f``) and the
    **invariant zeros stable**, with the detectability of ``(TA, C)``. The data plant differs
    from the true one by ``E G`` in ``A`` and ``B``, which changes neither condition: with
    noise-free data rich enough, the verdicts are the model-based ones.

    Parameters
    ----------
    u : array_like, shape (m, N), or None
        The recorded known input, one row per channel; ``None`` when there is none.
    y : array_like, shape (p, N)
        The recorded outputs.
    x : array_like, shape (n, N)
        The recorded states.
    dt : True or float
        The sampling period (``True`` when unspecified); the design is discrete-time.
    unknown_inputs : int, optional
        How many unknown inputs act (``q``, with ``E`` of full column rank), when known: the
        check then refuses data in which they moved the state in fewer directions.
    rtol : float, optional
        The relative precision of the recorded data (e.g. the noise level, ``1e-3`` for noise
        of a thousandth of each signal's RMS). Default: round-off (simulated, noise-free data).

    Returns
    -------
    DataReport

    Raises
    ------
    ValueError
        Signals of inconsistent length, the wrong number of dimensions, non-finite values, a
        continuous ``dt``.

    Examples
    --------
    >>> import uio_teach as ut
    >>> from uio_teach.data_driven import check_data, record_experiment, sampled_plant
    >>> tank = sampled_plant(ut.examples.quadruple_tank("P+"), 5.0)
    >>> rec = record_experiment(tank, 40, seed=2)
    >>> report = check_data(rec.u, rec.y, rec.x, dt=5.0, unknown_inputs=2)
    >>> [c.name for c in report.failed]
    ['invariant zeros stable', 'detectable (TA, C)']
    """
    runs = _experiments(u, y, x)
    u, y, x = (np.hstack([r[i] for r in runs]) for i in range(3))
    dt = _discrete_dt(dt)
    m, n, N = u.shape[0], x.shape[0], x.shape[1]
    q = _unknown_inputs(unknown_inputs, n)
    eps = float(np.finfo(float).eps)
    rtol = ROUND_OFF_RTOL * eps if rtol is None else as_real_number("rtol", rtol, low=0.0)
    rtol = max(rtol, ROUND_OFF_RTOL * eps)
    mats = _split(runs)
    L = mats.transitions
    UX = np.vstack([mats.U_p, mats.X_p])
    r_ux, s_ux, tol_ux = _rank(UX, rtol)
    r_all, _, _ = _rank(np.vstack([UX, mats.X_f]), rtol)
    R = _row_space_residual(mats.X_f, UX, r_ux)
    # the unknown input's directions: what of the next state the input and state do not explain
    Ur, sr, _ = np.linalg.svd(R, full_matrices=False) if R.size else (np.zeros((n, 0)), [], 0)
    sr = np.asarray(sr)
    seen = r_all - r_ux
    conds: list[Condition] = []
    margins = [s_ux[r_ux - 1] / tol_ux] if r_ux else []

    need = m + n + (q if q is not None else max(seen, 1)) + 2
    short = L <= r_all or (q is not None and N < need)
    if short:
        conds.append(
            Condition(
                "enough samples",
                False,
                f"{N} samples give {L} transitions, but the known input, the state and the "
                f"next state span {r_all} dimensions: no transition is left to show what the "
                f"unknown input leaves alone; record at least {max(need, r_all + 2)} samples "
                f"(m + n + q + 2 with m = {m}, n = {n}"
                + (f", q = {q})" if q is not None else " and q the number of unknown inputs)"),
            )
        )
    else:
        conds.append(
            Condition(
                "enough samples",
                True,
                f"{L} transitions for {r_all} dimensions of known input, state and next state",
            )
        )
    if r_ux < m + n:
        r_x = _rank(mats.X_p, rtol)[0]
        r_u = _rank(mats.U_p, rtol)[0] if m else 0
        if r_x < n:
            what = (
                f"the state stayed in a subspace of dimension {r_x} < n = {n}: start it away "
                "from rest and excite it (a known input that varies, or several initial states)"
            )
        elif r_u < m:
            what = (
                f"the known input's {m} channels varied in only {r_u} independent ways: drive "
                "each channel with its own varying signal (e.g. random steps)"
            )
        else:
            what = (
                f"the known input followed the state (rank {r_ux} < m + n = {m + n}), as in "
                "feedback: add an independent excitation to the input"
            )
        conds.append(
            Condition("input and state exciting", False, f"rank [U_p; X_p] < m + n: {what}")
        )
    else:
        conds.append(
            Condition(
                "input and state exciting",
                True,
                f"rank [U_p; X_p] = m + n = {m + n}: the input and the state varied independently",
            )
        )
    # y = C x: the outputs must lie in the row space of the states (all samples)
    C = y @ pinv(x)
    resid = _row_space_residual(y, x, _rank(x, rtol)[0])
    scale = np.sqrt(np.mean(y**2, axis=1))
    worst = float(np.max(np.linalg.norm(resid, axis=1) / np.where(scale > 0, scale, 1.0)))
    worst /= np.sqrt(N)
    if worst > NOISE_EDGE * rtol:
        conds.append(
            Condition(
                "outputs a function of the state",
                False,
                f"y is not C x for any C: a part of {worst:.2g} of the outputs' RMS is not a "
                "linear function of the state (an input acting on y directly, an output "
                "disturbance, or noise: give rtol= the recorded data's relative noise level)",
            )
        )
    else:
        conds.append(Condition("outputs a function of the state", True, "y = C x with C = Y X^+"))
    # the unknown input's directions
    if short:
        directions = min(seen, q) if q is not None else seen
        conds.append(
            Condition(
                "unknown input shows every direction",
                None,
                "not evaluated: too few samples to tell the unknown input's directions",
                required=q is not None,
            )
        )
    elif q is not None:
        if seen < q:
            conds.append(
                Condition(
                    "unknown input shows every direction",
                    False,
                    f"the next state moved in {seen} direction(s) that the input and the state "
                    f"do not explain, but q = {q} unknown inputs act: the unknown input hid a "
                    "direction in this experiment (channels that moved together, or stood "
                    "still), and a direction never seen is never decoupled; record again with "
                    "every unknown input varying on its own",
                )
            )
        else:
            extra = (
                f" (the data show {seen}: the {seen - q} weakest, {sr[q] / sr[0]:.2g} of the "
                "strongest, are taken as noise)"
                if seen > q
                else ""
            )
            conds.append(
                Condition(
                    "unknown input shows every direction",
                    True,
                    f"the next state moved in the q = {q} directions of the unknown input{extra}",
                )
            )
        directions = min(seen, q)
    else:
        directions = seen
        conds.append(
            Condition(
                "unknown input shows every direction",
                seen < n,
                f"the next state moved in {seen} direction(s) that the input and the state do "
                "not explain; a direction the unknown input never took is not decoupled (give "
                "unknown_inputs= to check that none was hidden)"
                + (
                    ": in every direction, so nothing can be decoupled (noise? give rtol=)"
                    if seen >= n
                    else ""
                ),
                required=seen >= n,
            )
        )
    if directions and len(sr) > directions:
        margins.append(sr[directions - 1] / max(sr[directions], sr[0] * rtol))
    if any(c.holds is False for c in conds):
        conds.extend(_not_evaluated("not evaluated: the data conditions above fail"))
        return DataReport(tuple(conds), N, directions, margin=min(margins, default=np.inf))
    E = Ur[:, :directions]
    BA = mats.X_f @ pinv(UX)
    # C E as precise as the data: its singular values below what the data's precision (rtol,
    # amplified by the conditioning of [U_p; X_p]) can resolve are zero, so that the rank
    # condition is decided at the data's precision, not at the round-off of a given model
    if directions:
        G = C @ E
        Ug, sg, Vgt = np.linalg.svd(G, full_matrices=False)
        cond_ux = float(s_ux[0] / s_ux[r_ux - 1]) if r_ux else 1.0
        small = sg <= rtol * cond_ux * max(float(np.linalg.norm(C, 2)), 1e-300)
        if np.any(small):
            C = C - (Ug[:, small] * sg[small]) @ Vgt[small] @ E.T
    plant = Plant(BA[:, m:], C, B=BA[:, :m], E=E, dt=dt, name="identified from data")
    existence = check_existence(plant)
    conds.extend(existence.conditions)
    return DataReport(
        tuple(conds),
        N,
        directions,
        plant=plant,
        existence=existence,
        margin=float(min(margins, default=np.inf)),
    )


# the design -------------------------------------------------------------------------------------


def design_uio_from_data(
    u: Any,
    y: Any,
    x: Any,
    *,
    dt: float | bool,
    poles: Any = None,
    K1: Any = None,
    unknown_inputs: int | None = None,
    rtol: float | None = None,
) -> UIO:
    """Design a discrete-time unknown input observer from one recorded experiment.

    The known input, the outputs and the states were recorded; the unknown input acted but
    was not. The data conditions of :func:`check_data` are checked first. The observer is the
    decoupling UIO of the course, ``z[k+1] = F z[k] + T B u[k] + K y[k]``, ``xhat = z + H y``,
    with every matrix computed from the data:

    - ``poles=``: ``H = E (C E)^+`` and ``K1`` placing the movable error poles, as
      :func:`uio_teach.design_uio` gives them for the true plant (the fixed poles are the
      invariant zeros);
    - ``K1=``: that gain;
    - neither: the minimum-norm solution of ``X_f = M [U_p; Y_p; X_p; Y_f]`` (Turan &
      Ferrari-Trecate's estimator ``xhat[k+1] = X_f W [u; y; xhat; y+]``,
      ``W = [U_p; Y_p; X_p; Y_f]^+``), read as ``T B = M_u``, ``K1 = M_yp``, ``H = M_yf``.
      Its error poles are whatever that choice gives (it warns when they are unstable).

    Parameters
    ----------
    u : array_like, shape (m, N), or None
        The recorded known input, one row per channel, one column per sample (``None`` when
        there is none).
    y : array_like, shape (p, N)
        The recorded outputs.
    x : array_like, shape (n, N)
        The recorded states (used to design only: the observer runs on ``u`` and ``y``).
    dt : True or float
        The sampling period of the samples (``True`` when unspecified).
    poles : array_like, optional
        The movable error poles (as many as :func:`check_data` reports movable).
    K1 : array_like, shape (n, p), optional
        An explicit gain instead of ``poles``.
    unknown_inputs : int, optional
        The number of unknown inputs, when known (see :func:`check_data`).
    rtol : float, optional
        The relative precision (noise level) of the recorded data (see :func:`check_data`).

    Returns
    -------
    UIO
        An observer like :func:`uio_teach.design_uio`'s; its ``plant`` is the data plant.

    Raises
    ------
    DataConditionError
        A ``ValueError``: a data condition fails (too short, not exciting, ``y`` not a
        function of ``x``, a hidden direction of the unknown input) or an existence condition
        fails on the data (the rank condition, an unstable invariant zero); the message names
        it and what to record instead.
    ValueError
        Both ``poles`` and ``K1``, bad shapes, non-finite values, a continuous ``dt``.

    Warns
    -----
    DataConditioningWarning
        The data matrices are too ill-conditioned to trust the design.
    UnstableObserverWarning
        The error dynamics are unstable (the minimum-norm choice, or the ``K1`` given).

    Examples
    --------
    >>> import numpy as np
    >>> import uio_teach as ut
    >>> from uio_teach.data_driven import record_experiment
    >>> plant = ut.Plant([[0.5, 0.1], [0.0, 0.8]], [[1.0, 0.0]], E=[[1.0], [0.0]], dt=1)
    >>> rec = record_experiment(plant, 12, seed=0)
    >>> obs = ut.design_uio_from_data(rec.u, rec.y, rec.x, dt=1, poles=[0.2])
    >>> obs.poles().real.round(6).tolist()
    [0.2, 0.8]
    >>> bool(np.allclose(obs.H, ut.design_uio(plant, poles=[0.2]).H))
    True
    """
    if poles is not None and K1 is not None:
        raise InputError("give at most one of poles= (the movable error poles) or K1=")
    report = check_data(u, y, x, dt=dt, unknown_inputs=unknown_inputs, rtol=rtol)
    if not report.ok:
        raise DataConditionError(report)
    if report.margin < DATA_MARGIN:
        warnings.warn(
            "the data matrices are ill-conditioned: a singular value the design keeps is only "
            f"{report.margin:.3g} times the rank threshold of the data's precision, so the noise "
            "moves the observer noticeably; record longer, or with more excitation",
            DataConditioningWarning,
            stacklevel=2,
        )
    plant = report.plant
    assert plant is not None and report.existence is not None
    if poles is not None or K1 is not None:
        return design_uio(plant, poles, K1=K1)
    return _minimum_norm(u, y, x, report)


def _minimum_norm(u: Any, y: Any, x: Any, report: DataReport) -> UIO:
    plant = report.plant
    assert plant is not None and report.existence is not None
    mats = data_matrices(u, y, x)
    m, n, p = plant.m, plant.n, plant.p
    Phi = np.vstack([mats.U_p, mats.Y_p, mats.X_p, mats.Y_f])
    # the data's rank: m + n + rank(C E); beyond it the singular values are noise
    keep = m + n + report.directions
    Uphi, s, Vt = np.linalg.svd(Phi, full_matrices=False)
    keep = min(keep, int(np.sum(s > s[0] * Phi.shape[0] * np.finfo(float).eps)) if s.size else 0)
    W = (Vt[:keep].T / s[:keep]) @ Uphi[:, :keep].T
    M = mats.X_f @ W
    K1 = M[:, m : m + p]
    H = M[:, m + p + n :]
    E, C = plant.E, plant.C
    if E.size:
        # the identity H C E = E, exact on the data plant (noise leaves it approximate)
        CE = C @ E
        H = H + (E - H @ CE) @ pinv(CE)
    obs = UIO(plant, H, K1)
    verify_projection(obs, "the UIO from data", report.existence.fixed_modes)
    if not obs.is_stable:
        rho = float(np.max(np.abs(obs.poles())))
        warnings.warn(
            f"the minimum-norm observer of the data has unstable error dynamics (spectral "
            f"radius {rho:.3g}): its gain K1 is whatever the data's minimum-norm solution "
            "gives; give poles= to place the movable poles",
            UnstableObserverWarning,
            stacklevel=3,
        )
    return obs


# experiments ------------------------------------------------------------------------------------


def sampled_plant(plant: Plant, dt: float) -> Plant:
    """The continuous plant sampled with period ``dt``, inputs held between samples.

    ``A_d = exp(A dt)``, ``[B_d E_d] = int_0^dt exp(A s) ds [B E]`` (zero-order hold), the same
    ``C`` and ``D``.

    Parameters
    ----------
    plant : Plant
        A continuous-time plant.
    dt : float
        The sampling period.

    Returns
    -------
    Plant

    Examples
    --------
    >>> import uio_teach as ut
    >>> from uio_teach.data_driven import sampled_plant
    >>> ut.data_driven.sampled_plant(ut.examples.quadruple_tank("P-"), 5.0).dt
    5.0
    """
    plant = check_plant(plant)
    if plant.is_discrete:
        raise InputError(f"plant is already discrete-time (dt = {plant.dt!r})")
    h = as_real_number("dt", dt, low=0.0, strict=True)
    n, m, q = plant.n, plant.m, plant.q
    big = np.zeros((n + m + q, n + m + q))
    big[:n, :n] = plant.A * h
    big[:n, n:] = np.hstack([plant.B, plant.E]) * h
    Phi = scipy.linalg.expm(big)
    name = f"{plant.name or 'plant'}, sampled every {h:g}"
    return Plant(
        Phi[:n, :n],
        plant.C,
        B=Phi[:n, n : n + m],
        E=Phi[:n, n + m :],
        D=plant.D,
        dt=h,
        name=name,
    )


def record_experiment(
    plant: Plant,
    samples: int,
    *,
    seed: int | np.random.Generator | None = None,
    noise: float = 0.0,
    initial_state: Any = None,
    d: Any = None,
    u: Any = None,
) -> Experiment:
    """Record one experiment on a discrete plant: random known and unknown inputs.

    ``u`` and ``d`` default to independent standard normal samples, the initial state to a
    standard normal one; with ``noise`` every recorded channel of ``x`` and ``y`` gets white
    Gaussian noise of ``noise`` times that channel's RMS (``d`` is returned noise-free, for the
    teacher: the designs never read it).

    Parameters
    ----------
    plant : Plant
        A discrete-time plant (``plant.D`` is not used: the method assumes ``y = C x``).
    samples : int
        ``N``, the number of recorded samples.
    seed : int or numpy.random.Generator, optional
        The random samples' seed.
    noise : float
        The relative noise level of the recorded ``x`` and ``y``.
    initial_state : array_like, shape (n,), optional
    d, u : array_like, optional
        Samples to use instead of random ones, shapes ``(q, N)`` and ``(m, N)``.

    Returns
    -------
    Experiment

    Examples
    --------
    >>> import uio_teach as ut
    >>> from uio_teach.data_driven import record_experiment
    >>> rec = record_experiment(ut.examples.dt_case_study(), 10, seed=0)
    >>> rec.u is None, rec.y.shape, rec.x.shape, rec.d.shape  # no known input: u is None
    (True, (2, 10), (3, 10), (1, 10))
    """
    plant = check_plant(plant)
    if not plant.is_discrete:
        raise InputError("record_experiment needs a discrete-time plant (see sampled_plant)")
    if isinstance(samples, bool) or not isinstance(samples, (int, np.integer)) or samples < 2:
        raise InputError(f"samples must be an integer of at least 2, got {samples!r}")
    noise = as_real_number("noise", noise, low=0.0)
    rng = np.random.default_rng(as_seed("seed", seed))
    n, m, q, N = plant.n, plant.m, plant.q, int(samples)
    uu = rng.standard_normal((m, N)) if u is None else _signal("u", u, N, "known input")
    dd = rng.standard_normal((q, N)) if d is None else _signal("d", d, N, "unknown input")
    if uu.shape[0] != m or dd.shape[0] != q:
        raise InputError(f"u needs {m} and d {q} rows (channels), got {uu.shape[0]}, {dd.shape[0]}")
    x = np.empty((n, N))
    x[:, 0] = (
        rng.standard_normal(n)
        if initial_state is None
        else as_real_array("initial_state", initial_state).reshape(n)
    )
    for k in range(N - 1):
        x[:, k + 1] = plant.A @ x[:, k] + plant.B @ uu[:, k] + plant.E @ dd[:, k]
    y = plant.C @ x
    if noise:
        for sig in (x, y):
            rms = np.sqrt(np.mean(sig**2, axis=1, keepdims=True))
            sig += noise * rms * rng.standard_normal(sig.shape)
    return Experiment(uu if m else None, y, x, dd)


# noise and data length --------------------------------------------------------------------------


@dataclass(frozen=True)
class NoiseStudy:
    """How the data-driven observer's estimation error grows with the noise of the recorded data
    and shrinks with their length (:func:`noise_study`).

    Attributes
    ----------
    lengths : numpy.ndarray
        The numbers of recorded samples ``N``.
    noises : numpy.ndarray
        The relative noise levels of the recorded ``x`` and ``y``.
    error : numpy.ndarray
        Shape ``(len(noises), len(lengths))``: the RMS estimation error of the designed
        observer on a noise-free validation run, relative to the RMS of the state, averaged
        over the repeats; ``nan`` where the data were refused.
    model_error : float
        The same for the model-based :func:`uio_teach.design_uio` (round-off only).
    refused : int
        How many designs the data conditions refused.
    """

    lengths: np.ndarray
    noises: np.ndarray
    error: np.ndarray
    model_error: float
    refused: int


def noise_study(
    plant: Plant,
    poles: Any,
    *,
    noises: Any,
    lengths: Any = (20, 40, 80, 160),
    repeats: int = 2,
    steps: int = 200,
    seed: int = 0,
) -> NoiseStudy:
    """Design from noisy recorded data of several lengths; measure the estimation error.

    For every length and noise level, ``repeats`` experiments are recorded
    (:func:`record_experiment`, noise on ``x`` and ``y``), an observer is designed from each
    (``design_uio_from_data`` with ``poles``, ``unknown_inputs=plant.q`` and ``rtol`` the
    noise level), and run on the true plant for ``steps`` samples with a random unknown input
    and known input, the observer started at the true state (``z(0) = T x(0)``); the error is
    the RMS of ``x - xhat`` over the second half of the run, relative to the RMS of ``x``: what
    the design's errors let through of the inputs.

    Parameters
    ----------
    plant : Plant
        A discrete-time plant (``y = C x``).
    poles : array_like
        The movable error poles.
    noises : sequence of float
        The relative noise levels of the recorded ``x`` and ``y``.
    lengths : sequence of int
        The numbers of recorded samples.
    repeats : int
        Experiments per length and level.
    steps : int
        Samples of each validation run.
    seed : int
        The seed of every random sample.

    Returns
    -------
    NoiseStudy

    Examples
    --------
    >>> import uio_teach as ut
    >>> plant = ut.Plant([[0.5, 0.1], [0.0, 0.8]], [[1.0, 0.0]], E=[[1.0], [0.0]], dt=1)
    >>> study = noise_study(plant, [0.2], lengths=(20, 80), noises=(1e-4, 1e-2), repeats=1)
    >>> study.error.shape, bool(study.error[0, 1] < study.error[1, 1])
    ((2, 2), True)
    """
    plant = check_plant(plant)
    lengths = np.array([int(k) for k in lengths])
    noises = np.array([as_real_number("noise", v, low=0.0) for v in noises])
    rng = np.random.default_rng(as_seed("seed", seed))
    t = np.arange(steps) * (1 if plant.dt is True else plant.dt)
    runs = []
    for _ in range(repeats):
        u = rng.standard_normal((plant.m, steps)) if plant.m else None
        runs.append((u, rng.standard_normal((plant.q, steps)), rng.standard_normal(plant.n)))

    def error_of(obs: UIO) -> float:
        from .simulation import simulate  # the simulator only where it runs

        total = []
        for u, d, x0 in runs:
            # the observer starts at the true state (xhat(0) = z(0) + H y(0) = x0): what is
            # left is the unknown and known inputs leaking through the design's errors
            z0 = obs.T @ x0
            res = simulate(plant, obs, t, u=u, d=d, initial_state=x0, observer_state=z0)
            half = steps // 2
            e, x = res.error[:, half:], res.states[:, half:]
            total.append(float(np.sqrt(np.mean(e**2) / np.mean(x**2))))
        return float(np.mean(total))

    model_error = error_of(design_uio(plant, poles))
    error = np.full((noises.size, lengths.size), np.nan)
    refused = 0
    for i, level in enumerate(noises):
        for j, N in enumerate(lengths):
            values = []
            for _ in range(repeats):
                rec = record_experiment(plant, int(N), seed=rng, noise=float(level))
                try:
                    with warnings.catch_warnings():
                        warnings.simplefilter("ignore", UIOTeachWarning)
                        obs = design_uio_from_data(
                            rec.u,
                            rec.y,
                            rec.x,
                            dt=plant.dt,
                            poles=poles,
                            unknown_inputs=plant.q,
                            rtol=float(level),
                        )
                except ValueError:
                    refused += 1
                    continue
                values.append(error_of(obs))
            if values:
                error[i, j] = float(np.mean(values))
    return NoiseStudy(lengths, noises, error, model_error, refused)
