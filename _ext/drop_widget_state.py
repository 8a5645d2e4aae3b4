"""Leave the saved ipywidgets state out of the book's pages.

The explorers display a live widget and pre-computed HTML frames in one bundle, and every builder
of the book takes the frames (``nb_mime_priority_overrides`` in ``_config.yml``). The state of the
widgets that executing a chapter creates is saved in the notebook all the same, and myst-nb would
put it into the page as a ``<script type="application/vnd.jupyter.widget-state+json">`` that
nothing reads. It is dropped once every page has been read, before any page is written.
"""

from __future__ import annotations

from typing import Any

from sphinx.application import Sphinx

STATE_KEY = "ipywidgets_state"  # myst-nb's key for the widget-state script of a page


def _drop_widget_state(app: Sphinx, env: Any) -> None:
    for data in getattr(env, "nb_metadata", {}).values():
        data.get("js_files", {}).pop(STATE_KEY, None)


def setup(app: Sphinx) -> dict[str, Any]:
    app.connect("env-updated", _drop_widget_state)
    return {"parallel_read_safe": True, "parallel_write_safe": True}
