"""The course's figures under their former name; they live in :mod:`uio_teach.instructor`.

The registry and :func:`generate` are in :mod:`uio_teach.instructor.figures`, the
configuration in :mod:`uio_teach.instructor.config`, the file writing in
:mod:`uio_teach.instructor.output`.

Examples
--------
>>> from uio_teach import figures
>>> "pa9_sine" in figures.FIGURES
True
"""

from .instructor.config import ConfigError, FigureConfig, default_config_toml, load_config
from .instructor.figures import (
    CATCH_TOL,
    FIGURES,
    FigureResult,
    FigureSpec,
    generate,
    unknown_figure_message,
)
from .instructor.output import FORMATS, OutputError, prepare_output_dir, save_figure

__all__ = [
    "FORMATS",
    "FIGURES",
    "FigureSpec",
    "FigureResult",
    "FigureConfig",
    "ConfigError",
    "OutputError",
    "load_config",
    "default_config_toml",
    "prepare_output_dir",
    "save_figure",
    "generate",
    "unknown_figure_message",
    "CATCH_TOL",
]
