"""The figures of the data-driven design: the estimation error against noise and data length."""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

from .data_driven import NoiseStudy
from .figure_text import describe
from .plotting import channel_style, finish_panel, line_look, new_figure

if TYPE_CHECKING:
    from matplotlib.figure import Figure

__all__ = ["plot_noise_study"]

_MARKERS = ("o", "s", "^", "D", "v")


def plot_noise_study(study: NoiseStudy, *, title: str = "") -> Figure:
    """Draw the estimation error of the data-driven UIO against the data length, one curve per
    noise level (log-log), with its words (:func:`uio_teach.figure_text.describe`).

    Parameters
    ----------
    study : NoiseStudy
        From :func:`uio_teach.data_driven.noise_study`.
    title : str, optional
        A title for the panel.

    Returns
    -------
    matplotlib.figure.Figure

    Examples
    --------
    >>> import numpy as np
    >>> from uio_teach.data_driven import NoiseStudy
    >>> from uio_teach.data_plots import plot_noise_study
    >>> study = NoiseStudy(np.array([20, 80]), np.array([1e-3, 1e-2]),
    ...                    np.array([[2e-3, 1e-3], [2e-2, 1e-2]]), 1e-16, 0)
    >>> fig = plot_noise_study(study)
    >>> len(fig.axes[0].get_lines())
    2
    """
    fig = new_figure(7.0, 3.6)
    ax = fig.subplots()
    words = []
    for i, level in enumerate(study.noises):
        style = {**channel_style(i), "marker": _MARKERS[i % len(_MARKERS)]}
        (line,) = ax.plot(study.lengths, study.error[i], label=f"noise {level:.0e}", **style)
        row = study.error[i]
        ok = np.isfinite(row)
        if not ok.any():
            words.append(f"at noise {level:.0e} ({line_look(line)}) every design was refused")
            continue
        first, last = int(np.flatnonzero(ok)[0]), int(np.flatnonzero(ok)[-1])
        gap = (
            f", no point at {', '.join(str(n) for n in study.lengths[~ok])} samples (refused)"
            if not ok.all()
            else ""
        )
        words.append(
            f"at noise {level:.0e} ({line_look(line)}) the error falls from {row[first]:.1g} "
            f"with {study.lengths[first]} samples to {row[last]:.1g} with "
            f"{study.lengths[last]}{gap}"
        )
    ax.set_xscale("log")
    ax.set_yscale("log")
    ax.set_xticks(study.lengths, labels=[str(int(n)) for n in study.lengths])
    ax.minorticks_off()
    ax.set_xlabel("recorded samples N")
    if title:
        ax.set_title(title)
    finish_panel(ax, "relative RMS error")
    describe(
        fig,
        "The data-driven UIO's relative RMS estimation error against the number of recorded "
        "samples, log-log, one curve per noise level of the recorded data: "
        + "; ".join(words)
        + f". The model-based UIO's error, {study.model_error:.0e}, is round-off, far below "
        "the panel.",
    )
    return fig
