"""The explorers' words: what the simulated error does, and why, in sentences that agree with it.

Every sentence an explorer writes about the error -- the observer messages, the
notes under the figure, the static frames' captions and text alternatives --
is derived from one :class:`ErrorVerdict`, computed from the simulated error
itself: its size ``|e(t)|`` (the Euclidean norm over the channels) at the
start, at the end and at its peak. "Grows" is said only when the error ends
larger than it starts, "decays" only when it ends smaller, "does not yet
outgrow its start" only when it never rises above it; an error that stays
below the rounding level of the plant's own signals is "zero to rounding".

Examples
--------
>>> import numpy as np
>>> from uio_teach.explorers.messages import ErrorVerdict
>>> k = np.arange(41.0)
>>> ErrorVerdict.of(np.array([1.05**k])).words()
'grows from 1 to 7.04'
>>> ErrorVerdict.of(np.array([0.9**k])).words()
'decays from 1 to 0.0148'
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .. import tolerances as tols
from .._display import format_poles
from ..linalg import is_stable
from ..lmi import LMIInfeasibleError
from .model import STARTS, Scenario, Settings
from .modes import damping_ratio, match_poles, points_per_period, pole_rate, slowest_pole

__all__ = [
    "ErrorVerdict",
    "error_grows",
    "pace_words",
    "stability_message",
    "overflow_message",
    "lmi_message",
    "zero_notes",
    "unsettled_note",
    "sampling_notes",
    "clipped_notes",
    "explain",
    "describe_disturbance",
]

TOLERANCE = 0.01
"""Relative change below which the error counts as ending where it started."""

ROUNDING = tols.ROUNDING_RTOL
"""Size, relative to the plant's own signals, below which an error is zero to rounding
(``tolerances.ROUNDING_RTOL``)."""


@dataclass(frozen=True)
class ErrorVerdict:
    """What a simulated error does over the window: its size at the start, the end and the peak.

    The size is ``|e(t)|``, the Euclidean norm over the channels. An error
    that never exceeds ``rounding`` is zero to rounding; a non-finite one
    overflowed. Sizes within :data:`TOLERANCE` (relative) of each other count
    as equal, so that the numbers printed with three digits never contradict
    the verb.

    Attributes
    ----------
    start, end, peak : float
        ``|e(0)|``, ``|e(T)|`` and the largest ``|e(t)|`` (``inf`` if it
        overflowed).
    rounding : float
        The size below which the error is zero to rounding.

    Examples
    --------
    >>> import numpy as np
    >>> from uio_teach.explorers.messages import ErrorVerdict
    >>> v = ErrorVerdict.of(np.array([[1.0, 3.0, 0.5]]))
    >>> v.decays, v.grows, v.outgrows_start
    (True, False, True)
    >>> v.words()
    'rises to 3, then decays to 0.5 (from 1)'
    """

    start: float
    end: float
    peak: float
    rounding: float = 0.0

    @classmethod
    def of(cls, error: np.ndarray | None, scale: float = 1.0) -> ErrorVerdict | None:
        """The verdict on a simulated error (one row per channel); None without one.

        Parameters
        ----------
        error : numpy.ndarray or None
            The error, one row per channel, one column per time point.
        scale : float
            The size of the plant's own signals: an error below
            ``ROUNDING * scale`` is zero to rounding.

        Returns
        -------
        ErrorVerdict or None
        """
        if error is None or not np.size(error):
            return None
        err = np.asarray(error, dtype=float).reshape(-1, np.shape(error)[-1])
        with np.errstate(all="ignore"):
            size = np.sqrt(np.sum(err**2, axis=0))
        size = np.where(np.isfinite(size), size, np.inf)
        return cls(
            start=float(size[0]),
            end=float(size[-1]),
            peak=float(size.max()),
            rounding=tols.ROUNDING_RTOL * max(float(scale), 0.0),
        )

    @property
    def finite(self) -> bool:
        """False if the error overflowed."""
        return bool(np.isfinite(self.peak))

    @property
    def zero(self) -> bool:
        """The error is zero to rounding over the whole window."""
        return self.finite and self.peak <= self.rounding

    @property
    def grows(self) -> bool:
        """It ends larger than it starts (or overflows)."""
        if not self.finite:
            return True
        return not self.zero and self.end > (1 + TOLERANCE) * self.start

    @property
    def decays(self) -> bool:
        """It ends smaller than it starts."""
        return self.finite and not self.zero and self.end < (1 - TOLERANCE) * self.start

    @property
    def outgrows_start(self) -> bool:
        """It rises above its start somewhere in the window."""
        if not self.finite:
            return True
        return not self.zero and self.peak > (1 + TOLERANCE) * self.start

    def words(self, stable: bool = True) -> str:
        """What the error does, as the end of a sentence that starts "the error ...".

        Parameters
        ----------
        stable : bool
            Every pole of the error is stable. If not, an error that ends smaller
            than it starts "shrinks ... within the window": it does not decay.

        Returns
        -------
        str

        Examples
        --------
        >>> from uio_teach.explorers.messages import ErrorVerdict
        >>> ErrorVerdict(start=1.73, end=1.88, peak=1.88).words()
        'grows from 1.73 to 1.88'
        >>> ErrorVerdict(start=1.5, end=6.29, peak=7.1).words()
        'grows from 1.5 to 6.29, peaking at 7.1 on the way'
        >>> ErrorVerdict(start=0.0, end=1e-13, peak=1e-13, rounding=1e-9).words()
        'is zero to rounding'
        >>> ErrorVerdict(start=1.73, end=1.6, peak=1.73).words(stable=False)
        'shrinks from 1.73 to 1.6 within the window'
        """
        a, b, m = (f"{x:.3g}" for x in (self.start, self.end, self.peak))
        if not self.finite:
            return "overflows"
        if self.zero:
            return "is zero to rounding"
        if self.grows:  # a peak above the end is said: the curve rises and falls back
            peak = f", peaking at {m} on the way" if self.peak > (1 + TOLERANCE) * self.end else ""
            return f"grows from {a} to {b}{peak}"
        if self.decays and not stable:
            if self.outgrows_start:
                return f"rises to {m}, then shrinks to {b} (from {a}) within the window"
            return f"shrinks from {a} to {b} within the window"
        if self.decays:
            if self.outgrows_start:
                return f"rises to {m}, then decays to {b} (from {a})"
            return f"decays from {a} to {b}"
        text = f"ends about where it starts ({a} to {b})"
        return text + (f", peaking at {m}" if self.outgrows_start else "")


def pace_words(verdict: ErrorVerdict | None, span: float, unit: str = "s") -> str:
    """How fast the error changed over the window, on average, in words.

    The words follow the verdict's ("the error decays from 1.5 to 1.5e-05, ..."): from the
    sizes at the start and the end of the window and its length, the time the error took, on
    average, to fall (or grow) tenfold; a change of less than tenfold is said as a percentage
    over the window. An error that is zero to rounding, overflowed, starts or ends at zero, or
    ends where it started, has no pace ("").

    Parameters
    ----------
    verdict : ErrorVerdict or None
        The verdict on the simulated error.
    span : float
        The length of the simulated window.
    unit : str
        The unit of ``span``: ``"s"`` (seconds) or ``"steps"``.

    Returns
    -------
    str

    Examples
    --------
    >>> from uio_teach.explorers.messages import ErrorVerdict, pace_words
    >>> pace_words(ErrorVerdict(start=1.5, end=1.5e-5, peak=1.5), 10.0)
    'ten times smaller every 2 s on average'
    >>> pace_words(ErrorVerdict(start=1.0, end=7.04, peak=7.04), 40.0, "steps")
    'up by 604 % over 40 steps'
    >>> pace_words(ErrorVerdict(start=1.0, end=1.0, peak=1.0), 10.0)
    ''
    """
    if verdict is None or not verdict.finite or verdict.zero or not span > 0:
        return ""
    if not (verdict.start > 0 and verdict.end > 0) or not (verdict.grows or verdict.decays):
        return ""
    decades = float(np.log10(verdict.end / verdict.start))
    how = "larger" if decades > 0 else "smaller"
    if abs(decades) >= 1:
        every = float(f"{span / abs(decades):.2g}")  # two digits, never in exponent form
        return f"ten times {how} every {every:g} {unit} on average"
    change = 100 * abs(verdict.end / verdict.start - 1)
    return f"{'up' if decades > 0 else 'down'} by {change:.3g} % over {span:.3g} {unit}"


def error_grows(error: np.ndarray | None) -> bool:
    """Does the simulated error grow: does it end larger than it starts (or overflow)?

    The size ``|e(t)|`` at the end is compared with that at the start
    (:class:`ErrorVerdict`); a non-finite error (it overflowed) grows too.

    Parameters
    ----------
    error : numpy.ndarray or None
        The error, one row per channel.

    Returns
    -------
    bool

    Examples
    --------
    >>> import numpy as np
    >>> from uio_teach.explorers import error_grows
    >>> k = np.arange(41.0)
    >>> error_grows(np.array([1.05**k])), error_grows(np.array([0.9**k]))
    (True, False)
    """
    verdict = ErrorVerdict.of(error, scale=0.0)
    return bool(verdict is not None and verdict.grows)


def _where(discrete: bool) -> tuple[str, str]:
    if discrete:
        return "outside the unit circle", "on the unit circle"
    return "in the right half-plane", "on the imaginary axis"


def _pair(p: complex) -> str:
    """A conjugate pair as ``a ± bj``."""
    return format_poles([complex(p.real, abs(p.imag))], 3).replace(" + ", " ± ")


def _growing(poles: np.ndarray, discrete: bool) -> np.ndarray:
    bad = ~is_stable(poles, discrete)
    mag = np.abs(poles) - 1 if discrete else poles.real
    return bad & (mag > tols.STABILITY_MARGIN * np.maximum(1, np.abs(poles)))


def stability_message(
    name: str,
    poles: np.ndarray,
    excited: np.ndarray,
    verdict: ErrorVerdict | None,
    discrete: bool,
) -> str:
    r"""What the observer's poles do to the error, in words the simulated error agrees with.

    Parameters
    ----------
    name : str
        The observer's display name.
    poles : numpy.ndarray of complex
        Its error poles.
    excited : numpy.ndarray of bool
        For each pole: does the start excite its mode?
    verdict : ErrorVerdict or None
        What the simulated error does.
    discrete : bool
        Discrete time.

    Returns
    -------
    str
        ``""`` when every pole is stable.

    Examples
    --------
    >>> import numpy as np
    >>> from uio_teach.explorers.messages import ErrorVerdict, stability_message
    >>> v = ErrorVerdict(start=1.73, end=1.6, peak=1.73)
    >>> text = stability_message("UIO", np.array([0.02, -3.0]), np.array([True, True]), v, False)
    >>> print(*text.split("; "), sep="\n")
    pole 0.02 in the right half-plane: that mode grows, but slowly
    the error shrinks from 1.73 to 1.6 within the window, not yet above its start
    """
    if not poles.size or verdict is None:
        return ""
    bad = ~is_stable(poles, discrete)
    if not bad.any():
        return ""
    growing = _growing(poles, discrete)
    where, edge = _where(discrete)
    if growing.any():
        grow = poles[growing]
        listed = format_poles(grow, 3)
        word = "pole" if grow.size == 1 else "poles"
        if verdict.grows:
            this = "this pole makes" if grow.size == 1 else "these poles make"
            return (
                f"{this} the {name} unstable: the error grows ({word} {listed} {where}; "
                f"|e| {verdict.words(stable=False).removeprefix('grows ')})"
                if verdict.finite
                else f"{this} the {name} unstable: the error grows ({word} {listed} {where})"
            )
        if not excited[growing].any():
            it = "it" if grow.size == 1 else "them"
            return (
                f"{word} {listed} {where}, but this start does not excite {it}: the error "
                f"does not grow here (it {verdict.words(stable=False)}; noise or another start "
                "would make it grow)"
            )
        if not verdict.outgrows_start:
            return (
                f"{word} {listed} {where}: that mode grows, but slowly; the error "
                f"{verdict.words(stable=False)}, not yet above its start"
            )
        return (
            f"{word} {listed} {where}: that mode grows, but slowly; within this window the "
            f"error {verdict.words(stable=False)}, and grows later"
        )
    edge_poles = poles[bad]
    word = "pole" if edge_poles.size == 1 else "poles"
    if not excited[bad].any():
        return f"{word} {format_poles(edge_poles, 3)} {edge}, not excited from this start"
    return f"{word} {format_poles(edge_poles, 3)} {edge}: that part of the error does not decay"


def overflow_message(poles: np.ndarray, discrete: bool) -> str:
    """One line for a simulation that left the floating-point range.

    Parameters
    ----------
    poles : numpy.ndarray of complex
        The observer's error poles.
    discrete : bool
        Discrete time.

    Returns
    -------
    str

    Examples
    --------
    >>> import numpy as np
    >>> from uio_teach.explorers.messages import overflow_message
    >>> overflow_message(np.array([0.9, -1.0]), False)
    'unstable (pole 0.9 in the right half-plane): the error overflows within the window, no curve'
    """
    grow = poles[_growing(poles, discrete)] if poles.size else poles
    if not grow.size:
        return "the error overflows within the window, no curve"
    word = "pole" if grow.size == 1 else "poles"
    return (
        f"unstable ({word} {format_poles(grow, 3)} {_where(discrete)[0]}): the error "
        "overflows within the window, no curve"
    )


def lmi_message(scenario: Scenario, decay: float, exc: Exception) -> str:
    """An LMI that failed, in plain words (no solver status).

    Parameters
    ----------
    scenario : Scenario
        The explorer's scenario.
    decay : float
        The bound asked for.
    exc : Exception
        What the LMI design raised.

    Returns
    -------
    str

    Examples
    --------
    >>> from uio_teach.explorers import scenario_of
    >>> from uio_teach.explorers.messages import lmi_message
    >>> from uio_teach.lmi import LMIInfeasibleError
    >>> lmi_message(scenario_of("case_study"), 0.4, LMIInfeasibleError("no", "infeasible"))[:38]
    'no gain meets the bound radius 0.4: th'
    """
    discrete = scenario.discrete
    bound = f"radius {decay:.3g}" if discrete else f"decay rate {decay:.3g}"
    fixed = scenario.fixed_poles
    if isinstance(exc, LMIInfeasibleError):
        if fixed.size:
            worst = (
                f"radius {np.abs(fixed).max():.3g}"
                if discrete
                else f"decay rate {-fixed.real.max():.3g}"
            )
            return (
                f"no gain meets the bound {bound}: the fixed poles (invariant zeros, "
                f"{worst}) cannot move; choose a bound beyond them"
            )
        return f"no gain meets the bound {bound}"
    return (
        f"the LMI solver could not settle the bound {bound} numerically (this does not prove "
        "that no gain exists); try a slightly different bound"
    )


NEXT_TO = 0.02
"""A movable pole is "next to" an invariant zero within this fraction of the larger size."""


def zero_notes(scenario: Scenario, movable: np.ndarray) -> list[str]:
    """A note for each movable pole placed on (or next to) an invariant zero.

    "Next to" is relative: the gap is at most :data:`NEXT_TO` of the larger of
    ``|pole|`` and ``|zero|``. No note where no observer exists.

    Parameters
    ----------
    scenario : Scenario
        The explorer's scenario.
    movable : numpy.ndarray of complex
        The movable poles asked for.

    Returns
    -------
    list of str

    Examples
    --------
    >>> import numpy as np
    >>> from uio_teach.explorers import scenario_of
    >>> from uio_teach.explorers.messages import zero_notes
    >>> zero_notes(scenario_of("case_study"), np.array([0.5]))[0][:36]
    'pole 0.5 sits on the invariant zero '
    """
    zeros = scenario.invariant_zeros
    out: list[str] = []
    if scenario.existence is not None and not scenario.existence.ok:
        return out  # no observer: no pole of it sits anywhere
    for p in movable:
        if not zeros.size:
            break
        gaps = np.abs(zeros - p)
        j = int(np.argmin(gaps))
        z = zeros[j]
        # relative: "next to" means within NEXT_TO of the larger of the two sizes
        size = max(abs(z), abs(p))
        if gaps[j] > NEXT_TO * size:
            continue
        where = (
            "sits on"
            if gaps[j] <= tols.ROUNDING_RTOL * max(size, np.finfo(float).tiny)
            else "is next to"
        )
        text = (
            f"pole {format_poles([p], 3)} {where} the invariant zero {format_poles([z], 3)}, "
            "where a fixed pole already is: the error there decays no faster than that fixed "
            "mode, and a repeated pole is sensitive to small model errors"
        )
        if text not in out:
            out.append(text)
    return out


def unsettled_note(
    verdict: ErrorVerdict | None,
    error: np.ndarray,
    poles: np.ndarray,
    excited: np.ndarray,
    fixed: np.ndarray,
    discrete: bool,
    t: np.ndarray,
) -> str:
    """A note when the error has not settled by the end of the window: which pole holds it up.

    When that pole is fixed, the note says that no gain moves it, so moving
    the movable poles cannot make the error settle sooner (and, for a
    lightly damped pair, that it is one).

    Parameters
    ----------
    verdict : ErrorVerdict or None
        What the simulated error does.
    error : numpy.ndarray
        The simulated error.
    poles, excited, fixed : numpy.ndarray
        The observer's poles, which of them the start excites, and the fixed ones.
    discrete : bool
        Discrete time.
    t : numpy.ndarray
        The time grid.

    Returns
    -------
    str
        ``""`` when the error has settled (its last tenth is below 5 % of its peak).
    """
    if verdict is None or verdict.zero or not verdict.finite or not error.size:
        return ""
    N = error.shape[-1]
    size = np.sqrt(np.sum(np.asarray(error, float) ** 2, axis=0))
    tail = float(size[-max(1, N // 10) :].max())
    if not tail > 0.05 * verdict.peak:
        return ""
    live = poles[excited]
    stable = live[is_stable(live, discrete)] if live.size else live
    slow = slowest_pole(stable, discrete)
    text = "the error has not settled by the end of the window"
    if slow is None:
        return text
    factor = float(pole_rate(slow, discrete, t)[-1])
    if factor <= 0.05:
        return text
    is_fixed = bool(match_poles(np.array([slow]), fixed).any())
    kind = "fixed" if is_fixed else "movable"
    text += (
        f": its slowest {kind} pole, {format_poles([slow], 3)}, shrinks it only to "
        f"{100 * factor:.2g} % over the window"
    )
    if is_fixed:
        light = not discrete and slow.imag != 0 and damping_ratio(slow) < 0.1
        if light:
            text += f" (a lightly damped pair, damping ratio {damping_ratio(slow):.2g})"
        text += "; no gain moves it, so the movable poles cannot make the error settle sooner"
    return text


def sampling_notes(
    poles: np.ndarray, excited: np.ndarray, discrete: bool, t: np.ndarray
) -> list[str]:
    """A note for each excited oscillation that the time grid samples too coarsely to draw.

    A mode sampled with fewer than 8 points a period is drawn with wiggles
    that are not its own (aliasing); continuous time only.

    Parameters
    ----------
    poles, excited : numpy.ndarray
        The observer's poles and which of them the start excites.
    discrete : bool
        Discrete time (no note: the steps are the signal).
    t : numpy.ndarray
        The time grid.

    Returns
    -------
    list of str

    Examples
    --------
    >>> import numpy as np
    >>> from uio_teach.explorers.messages import sampling_notes
    >>> sampling_notes(np.array([-1 + 40j, -1 - 40j]), np.array([True, True]), False,
    ...                np.linspace(0, 31.4, 1001))[0][:58]
    'the pair -1 ± 40j oscillates with a period of 0.157, only '
    """
    if discrete or t.size < 2:
        return []
    out = []
    for p in poles[excited] if excited.size == poles.size else poles:
        if p.imag <= 0:
            continue
        n = points_per_period(p, t)
        visible = float(pole_rate(p, False, t)[min(t.size - 1, int(3 * n) + 1)]) > 1e-3
        if n < 8 and visible:
            out.append(
                f"the pair {_pair(p)} "
                f"oscillates with a period of {2 * np.pi / p.imag:.3g}, only {n:.2g} samples: "
                "the wiggles drawn between the samples are not its own (aliasing)"
            )
    return out


def clipped_notes(clipped: dict[str, set[str]], observer_name: str) -> list[str]:
    """A note for each observer whose curves leave the plotted range (and are cut off there).

    Parameters
    ----------
    clipped : dict
        ``"uio"`` or ``"lb"``: the kinds of curve (``"error"``, ``"residual"``,
        ``"input"``) that lasting leave their range.
    observer_name : str
        The unknown input observer's display name.

    Returns
    -------
    list of str

    Examples
    --------
    >>> from uio_teach.explorers.messages import clipped_notes
    >>> clipped_notes({"lb": {"error"}}, "UIO")[0][:44]
    'Luenberger observer: the error leaves the pl'
    """
    out = []
    for key, whats in clipped.items():
        whats = whats - {"input"}  # the input panels are zoomed on the true input anyway
        if not whats:
            continue
        who = observer_name if key == "uio" else "Luenberger observer"
        which = " and ".join(sorted(whats))
        verb, be = ("leaves", "is") if len(whats) == 1 else ("leave", "are")
        out.append(
            f"{who}: the {which} {verb} the plotted range (ten times the plant's own signals) "
            f"and {be} cut off there"
        )
    return out


def explain(
    scenario: Scenario,
    s: Settings,
    movable: np.ndarray,
    fixed: np.ndarray,
    poles: np.ndarray,
    excited: np.ndarray,
    zero_residual: bool = False,
) -> str:
    """Which poles the controls move, which stay fixed, which modes the start excites.

    Parameters
    ----------
    scenario : Scenario
        The explorer's scenario.
    s : Settings
        The control values.
    movable, fixed, poles : numpy.ndarray of complex
        The movable poles, the fixed ones and all of them.
    excited : numpy.ndarray of bool
        For each entry of ``poles``: does the start excite its mode?
    zero_residual : bool
        The unknown input observer's residual is zero to rounding.

    Returns
    -------
    str
    """
    name = scenario.observer_name
    exists = scenario.existence is None or scenario.existence.ok
    parts = []
    if scenario.family == "ginverse":
        parts.append(f"The {name} has no gain to tune: its poles are set by its structure.")
    elif not exists:
        parts.append(f"No {name} exists for this plant; its message says why.")
    elif movable.size:
        what = "The LMI bound picks" if s.mode == "lmi" else "The pole controls move"
        parts.append(f"{what} the {name} poles {format_poles(movable, 3)}.")
    elif scenario.movable == 0:
        parts.append(f"No pole of the {name} can be moved.")
    elif not poles.size:  # the design failed for these settings: its message says why
        parts.append(f"No {name} could be designed for these settings; its message says why.")
    if fixed.size and exists:
        parts.append(
            f"Fixed whatever the gain: {format_poles(fixed, 3)} (the invariant zeros, o on "
            "the pole map)."
        )
    elif fixed.size:
        parts.append(f"The invariant zeros: {format_poles(fixed, 3)} (o on the pole map).")
    if scenario.reconstruct:
        parts.append(
            "The input panels are zoomed on the true input (grey): larger swings of a "
            "reconstruction run off the panel."
        )
    if poles.size and excited.size == poles.size:
        start = STARTS.get(s.start, s.start)
        quiet = poles[~excited]
        quiet = quiet[match_poles(quiet, movable)] if quiet.size and movable.size else quiet[:0]
        if not quiet.size:
            parts.append(f"Start: {start}; the error has a part in every movable mode.")
        else:
            parts.append(
                f"Start: {start}; the error has no part in the movable modes "
                f"{format_poles(quiet, 3)}, so moving them changes nothing here."
            )
    if zero_residual:
        parts.append(f"The {name}'s residual is zero to rounding.")
    parts += _window_reason(scenario, fixed)
    return " ".join(parts)


def _window_reason(scenario: Scenario, fixed: np.ndarray) -> list[str]:
    """Why the window is shorter than the slowest fixed mode needs (a lightly damped pair)."""
    t = scenario.timepts
    if scenario.discrete or t.size < 2 or not fixed.size:
        return []
    stable = fixed[fixed.real < 0]
    slow = slowest_pole(stable, False)
    if slow is None or slow.imag == 0 or float(pole_rate(slow, False, t)[-1]) <= 0.05:
        return []
    span = float(t[-1] - t[0])
    need = float(np.log(100.0) / -slow.real)
    per = points_per_period(slow, t)
    return [
        f"The window, {span:.3g} time units, is set by the lightly damped fixed pair "
        f"{_pair(slow)}: {per:.2g} samples a "
        f"period of its oscillation; shrinking its part of the error to 1 % would take "
        f"{need:.3g}."
    ]


def describe_disturbance(kind: str, settings: Settings, discrete: bool) -> str:
    """The disturbance of the settings in a few words (the figure title).

    Parameters
    ----------
    kind : str
        The disturbance type.
    settings : Settings
        The control values.
    discrete : bool
        Discrete time (steps, rad/step).

    Returns
    -------
    str

    Examples
    --------
    >>> from uio_teach.explorers import Settings
    >>> from uio_teach.explorers.messages import describe_disturbance
    >>> describe_disturbance("sinusoid", Settings(), False)
    'sinusoid, amplitude 1, frequency 1 rad/s'
    """
    unit = "steps" if discrete else "s"
    a = f"{settings.amplitude:.3g}"
    if kind in ("sinusoid", "damped sinusoid"):
        per = "rad/step" if discrete else "rad/s"
        return f"{kind}, amplitude {a}, frequency {settings.frequency:.3g} {per}"
    return f"{kind}, amplitude {a}, switching every {settings.period:.3g} {unit}"
