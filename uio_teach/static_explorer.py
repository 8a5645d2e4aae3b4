"""The static explorers under their former name; they now live in :mod:`uio_teach.explorers.static`.

Examples
--------
>>> from uio_teach.static_explorer import static_explorer
>>> callable(static_explorer)
True
"""

from .explorers.static import (
    StaticExplorer,
    StaticFrame,
    frame_settings,
    static_explorer,
    static_html,
)

__all__ = ["StaticFrame", "StaticExplorer", "frame_settings", "static_explorer", "static_html"]
