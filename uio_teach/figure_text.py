"""A figure in words and on a phone: its text alternative, its long description, its narrow layout.

Whoever makes a figure says what it shows: :func:`describe` attaches a
:class:`FigureDescription` to a Matplotlib figure, a short text alternative (what is plotted and
what the reader should see) and, where a sentence is not enough, a longer description. The
course's drawing functions (:mod:`uio_teach.plotting`) describe their figures from the numbers
they draw; a chapter's own figure is described in the cell that draws it.

In a notebook (IPython) a described figure is shown as HTML (:func:`figure_html`): the picture
with its text alternative, a narrow version for phones (the panels stacked in one column,
:func:`narrow_layout`, the text at the size it was drawn) chosen by the browser below
:data:`NARROW_SCREEN_PX`, and the long description in a ``<details>`` element under it, which
the picture names with ``aria-describedby``. A figure with no description is shown as before,
a plain PNG. ``uio-teach figures`` writes the text beside each picture
(:func:`description_text`) and into the file's own metadata.

Examples
--------
>>> from uio_teach.figure_text import describe, description
>>> from uio_teach.plotting import new_figure
>>> fig = new_figure(6, 3)
>>> _ = fig.subplots().plot([0, 1, 2], [1, 0.1, 0.0])
>>> _ = describe(fig, "An error that decays to zero within two seconds.")
>>> description(fig).alt
'An error that decays to zero within two seconds.'
"""

from __future__ import annotations

import base64
import html
import io
import itertools
import sys
import textwrap
from collections.abc import Iterator
from contextlib import contextmanager
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

from .errors import InputError

if TYPE_CHECKING:  # pragma: no cover
    from matplotlib.figure import Figure

__all__ = [
    "FigureDescription",
    "describe",
    "description",
    "description_text",
    "figure_html",
    "narrow_layout",
    "NARROW_WIDTH",
    "NARROW_SCREEN_PX",
]

NARROW_WIDTH = 3.6
"""Width (inches) of a figure's phone version, 360 px at 100 dpi (a phone's column)."""
NARROW_SCREEN_PX = 600
"""Screens up to this width (CSS px) get the phone version of a figure."""
_PANEL_HEIGHT = 2.4  # inches per panel of the phone version
_ATTRIBUTE = "_uio_teach_description"
_ids = itertools.count(1)


@dataclass(frozen=True)
class FigureDescription:
    """What a figure shows, in words.

    Attributes
    ----------
    alt : str
        The text alternative: what is plotted and what the reader should see, in a sentence or
        two (a screen reader reads it in place of the picture).
    details : str
        A longer description, panel by panel (empty when the text alternative says it all).

    Examples
    --------
    >>> from uio_teach.figure_text import FigureDescription
    >>> FigureDescription("The error decays to zero.").details
    ''
    """

    alt: str
    details: str = ""


def describe(fig: Figure, alt: str, details: str | None = None) -> Figure:
    """Attach a text alternative (and a long description) to a figure; return the figure.

    Parameters
    ----------
    fig : matplotlib.figure.Figure
        The figure.
    alt : str
        What is plotted and what the reader should see (not a file name, not "a figure").
    details : str, optional
        A longer description; ``None`` keeps the one the figure has (e.g. the panel-by-panel
        description the course's drawing functions write), ``""`` removes it.

    Returns
    -------
    matplotlib.figure.Figure
        ``fig``, so that ``describe(res.plot(), "...")`` reads in one line.

    Raises
    ------
    ValueError
        An empty text alternative.

    Examples
    --------
    >>> from uio_teach.figure_text import describe, description
    >>> from uio_teach.plotting import new_figure
    >>> fig = describe(new_figure(), "Both errors decay.", "The UIO's error reaches zero first.")
    >>> description(fig).details
    "The UIO's error reaches zero first."
    """
    alt = " ".join(str(alt).split())
    if not alt:
        raise InputError("alt must say what the figure shows, got an empty text")
    old = description(fig)
    if details is None:
        details = old.details if old is not None else ""
    setattr(fig, _ATTRIBUTE, FigureDescription(alt, " ".join(str(details).split())))
    _install_display()
    return fig


def description(fig: Figure) -> FigureDescription | None:
    """The figure's description (:func:`describe`), or ``None``.

    Parameters
    ----------
    fig : matplotlib.figure.Figure
        The figure.

    Returns
    -------
    FigureDescription or None

    Examples
    --------
    >>> from uio_teach.figure_text import description
    >>> from uio_teach.plotting import new_figure
    >>> description(new_figure()) is None
    True
    """
    found = getattr(fig, _ATTRIBUTE, None)
    return found if isinstance(found, FigureDescription) else None


def description_text(fig: Figure) -> str:
    """The description as plain text, for a file beside the picture (empty if none).

    Parameters
    ----------
    fig : matplotlib.figure.Figure
        The figure.

    Returns
    -------
    str
        The text alternative, a blank line and the long description, wrapped at 88 columns.

    Examples
    --------
    >>> from uio_teach.figure_text import describe, description_text
    >>> from uio_teach.plotting import new_figure
    >>> description_text(describe(new_figure(), "Short.", "Long."))
    'Short.\\n\\nLong.\\n'
    """
    found = description(fig)
    if found is None:
        return ""
    parts = [found.alt] + ([found.details] if found.details else [])
    return "\n\n".join(textwrap.fill(p, 88) for p in parts) + "\n"


# --- the phone version -------------------------------------------------------------------------


def _panels(fig: Figure) -> list:
    """The figure's panels laid out on a grid, in reading order: column by column."""
    panels = []
    for ax in fig.axes:
        spec = ax.get_subplotspec()
        if spec is None or not ax.get_visible():
            continue  # an inset or a colour bar placed by hand goes with its panel
        panels.append((spec.colspan.start, spec.rowspan.start, ax))
    return [ax for _, _, ax in sorted(panels, key=lambda p: (p[0], p[1]))]


@contextmanager
def narrow_layout(fig: Figure, width: float = NARROW_WIDTH) -> Iterator[Figure]:
    """The figure laid out for a phone while the block runs: one column of panels.

    The panels are stacked in reading order (the left column, then the right one), every
    panel shows its tick labels, a legend beside a panel moves above it, and long titles wrap.
    The text keeps its size. Everything is put back afterwards.

    Parameters
    ----------
    fig : matplotlib.figure.Figure
        The figure (on a grid: ``subplots``, ``subplot_mosaic``, a ``GridSpec``).
    width : float, optional
        Width in inches (default :data:`NARROW_WIDTH`).

    Yields
    ------
    matplotlib.figure.Figure
        ``fig``.

    Examples
    --------
    >>> from uio_teach.figure_text import narrow_layout
    >>> from uio_teach.plotting import new_figure
    >>> fig = new_figure(9, 4)
    >>> left, right = fig.subplots(1, 2)
    >>> with narrow_layout(fig):
    ...     right.get_subplotspec().rowspan.start, fig.get_size_inches().round(1).tolist()
    (1, [3.6, 4.9])
    >>> right.get_subplotspec().colspan.start
    1
    """
    from matplotlib.gridspec import GridSpec  # deferred: matplotlib only when drawing
    from matplotlib.layout_engine import ConstrainedLayoutEngine  # deferred: as above

    panels = _panels(fig)
    size = fig.get_size_inches().copy()
    engine = fig.get_layout_engine()
    specs = [(ax, ax.get_subplotspec()) for ax in panels]
    ticks = [(ax, ax.xaxis.get_tick_params(), ax.yaxis.get_tick_params()) for ax in panels]
    legends = [(ax, ax.get_legend()) for ax in panels]
    titles = [(ax, ax.get_title(), _font(ax.title)) for ax in panels]
    suptitle = fig.get_suptitle() if hasattr(fig, "get_suptitle") else ""
    figure_legends = list(fig.legends)
    try:
        for old in figure_legends:  # a legend of the whole figure: one column above the panels
            fig.legends.remove(old)
            texts = old.get_texts()
            fig.legend(
                old.legend_handles,
                [t.get_text() for t in texts],
                loc="outside upper center",
                ncols=1,
                fontsize=texts[0].get_fontsize() if texts else None,
                frameon=False,
            )
        if len(panels) > 1:
            grid = GridSpec(len(panels), 1, figure=fig)
            for k, ax in enumerate(panels):
                ax.set_subplotspec(grid[k])
        rows = 0
        for ax in panels:
            ax.tick_params(labelbottom=True, labelleft=True)
            ax.title.set_text(textwrap.fill(ax.get_title(), 40))
            rows += _legend_above(ax)
        if suptitle:
            fig.suptitle(textwrap.fill(suptitle, 36))
        if not isinstance(engine, ConstrainedLayoutEngine):
            fig.set_layout_engine("constrained")  # tight_layout ran once: lay out the column
        height = _PANEL_HEIGHT * len(panels) if len(panels) > 1 else width * size[1] / size[0]
        height = max(height, _PANEL_HEIGHT) + 0.28 * rows
        height += 0.3 * (1 + textwrap.fill(suptitle, 36).count("\n")) if suptitle else 0.1
        fig.set_size_inches(width, height, forward=False)
        yield fig
    finally:
        fig.set_size_inches(size, forward=False)
        for ax, spec in specs:
            ax.set_subplotspec(spec)
        for ax, x, y in ticks:
            ax.xaxis.set_tick_params(**_label_params(x))
            ax.yaxis.set_tick_params(**_label_params(y))
        for ax, legend in legends:
            ax.legend_ = legend
        for ax, title, font in titles:
            ax.set_title(title, **font)
        if suptitle:
            fig.suptitle(suptitle)
        fig.legends[:] = figure_legends
        if fig.get_layout_engine() is not engine:
            fig.set_layout_engine(engine if engine is not None else "none")


def _font(text: Any) -> dict:
    """The font of a title, to set it again as it was."""
    return {"fontsize": text.get_fontsize(), "fontweight": text.get_fontweight()}


def _label_params(params: dict) -> dict:
    keys = ("labelbottom", "labeltop", "labelleft", "labelright")
    return {k: v for k, v in params.items() if k in keys}


def _legend_above(ax: Any) -> int:
    """The panel's legend moves above the panel, clear of its curves; returns its rows."""
    legend = ax.get_legend()
    if legend is None or not legend.get_visible():
        return 0
    handles = legend.legend_handles
    texts = legend.get_texts()
    labels = [t.get_text() for t in texts]
    longest = max((len(_spoken(label)) for label in labels), default=0)
    ncols = 3 if longest <= 10 else 2 if longest <= 18 else 1
    ncols = max(1, min(ncols, len(labels)))
    ax.legend(
        handles,
        labels,
        loc="lower left",
        bbox_to_anchor=(0.0, 1.02),
        borderaxespad=0.0,
        ncols=ncols,
        fontsize=texts[0].get_fontsize() if texts else None,
        frameon=False,
    )
    rows = -(-len(labels) // ncols)
    if ax.get_title():  # the title goes above the legend
        size = texts[0].get_fontsize() if texts else 10.0
        ax.set_title(ax.get_title(), pad=8 + rows * 1.45 * size, **_font(ax.title))
    return rows


def _spoken(label: str) -> str:
    """A legend label as the characters it shows (mathtext markup left out)."""
    for mark in ("$", "\\hat", "\\", "{", "}", "_", "^"):
        label = label.replace(mark, "")
    return label


# --- the HTML a notebook shows -------------------------------------------------------------------


def _png(fig: Figure) -> tuple[str, int, int]:
    """The figure as a PNG data URL at its own resolution, with its size in pixels."""
    from matplotlib.backends.backend_agg import FigureCanvasAgg  # deferred: only when drawing

    buffer = io.BytesIO()
    canvas = fig.canvas if hasattr(fig.canvas, "print_png") else FigureCanvasAgg(fig)
    canvas.print_figure(buffer, format="png", dpi=fig.dpi, bbox_inches="tight")
    data = buffer.getvalue()
    width = int.from_bytes(data[16:20], "big")
    height = int.from_bytes(data[20:24], "big")
    return "data:image/png;base64," + base64.b64encode(data).decode("ascii"), width, height


def figure_html(fig: Figure, *, narrow: bool = True) -> str:
    """The figure as self-contained HTML: the picture, its phone version, its words.

    Parameters
    ----------
    fig : matplotlib.figure.Figure
        A described figure (:func:`describe`).
    narrow : bool, optional
        Include the phone version (:func:`narrow_layout`), shown below
        :data:`NARROW_SCREEN_PX` CSS pixels.

    Returns
    -------
    str
        A ``<figure class="uio-figure">`` element.

    Raises
    ------
    ValueError
        The figure has no description.

    Examples
    --------
    >>> from uio_teach.figure_text import describe, figure_html
    >>> from uio_teach.plotting import new_figure
    >>> fig = new_figure(4, 3)
    >>> _ = fig.subplots().plot([0, 1], [1, 0])
    >>> text = figure_html(describe(fig, "A falling line.", "From 1 to 0."))
    >>> 'alt="A falling line."' in text, "<details" in text, "<source media=" in text
    (True, True, True)
    """
    found = description(fig)
    if found is None:
        raise InputError("the figure has no description: call describe(fig, alt, details) first")
    wide, width, height = _png(fig)
    source = ""
    if narrow and _panels(fig):
        with narrow_layout(fig):
            small, w, h = _png(fig)
        source = (
            f'<source media="(max-width: {NARROW_SCREEN_PX}px)" srcset="{small}" '
            f'width="{w}" height="{h}">'
        )
    alt = html.escape(found.alt)
    described = ""
    details = ""
    if found.details:
        ident = f"uio-figure-{next(_ids)}"
        described = f' aria-describedby="{ident}"'
        details = (
            '<details class="uio-figure-details"><summary>What the figure shows, in words'
            f'</summary><p id="{ident}">{html.escape(found.details)}</p></details>'
        )
    # the pairs of curves only a hue tells apart, for the book's tests (none in the course)
    from .colour_vision import curves_apart_by_hue_alone  # deferred: only when drawing

    apart = "; ".join(
        f"{panel}: {a} / {b} ({reader})" for panel, a, b, reader in curves_apart_by_hue_alone(fig)
    )
    flag = f' data-hue-alone="{html.escape(apart)}"' if apart else ""
    return (
        f'<figure class="uio-figure" style="margin:0"{flag}>'
        f"<picture>{source}"
        f'<img src="{wide}" alt="{alt}" width="{width}" height="{height}"{described} '
        'style="max-width:100%;height:auto"></picture>'
        f"{details}</figure>"
    )


def _mimebundle(fig: Figure) -> tuple[dict, dict] | None:
    found = description(fig)
    if found is None:
        return None
    return {"text/html": figure_html(fig)}, {"image/png": {"alt": found.alt}}


def _install_display() -> None:
    """Show described figures as :func:`figure_html` in IPython (once per kernel)."""
    ipython = sys.modules.get("IPython")  # running inside IPython: it is loaded already
    if ipython is None or not hasattr(ipython, "get_ipython"):
        return
    shell = ipython.get_ipython()
    if shell is None or not hasattr(shell, "display_formatter"):
        return
    from matplotlib.figure import Figure  # deferred: only when a figure was described

    shell.display_formatter.mimebundle_formatter.for_type(Figure, _mimebundle)
