"""Instructor tooling: the term's figures, lab notebooks and variants, from the command line.

* :mod:`~uio_teach.instructor.cli` -- ``uio-teach figures``, ``uio-teach labs`` and
  ``uio-teach grade`` (whose engine is the grader, :mod:`uio_teach.grading`);
* :mod:`~uio_teach.instructor.figures` -- the registry of the course's figures
  (:data:`~uio_teach.instructor.figures.FIGURES`) and
  :func:`~uio_teach.instructor.figures.generate`;
* :mod:`~uio_teach.instructor.config` -- the TOML configuration an instructor edits each
  term, validated against a schema;
* :mod:`~uio_teach.instructor.labs` -- the lab chapters as student and solution notebooks,
  with :mod:`~uio_teach.instructor.book` for the book's numbers, titles and references;
* :mod:`~uio_teach.instructor.output` -- reproducible figure files; the folders they go
  into are :mod:`uio_teach.folders`, shared with the grader.

The lab notebooks need the ``instructor`` extra (``pip install "uio-teach[instructor]"``:
jupytext, nbformat, PyYAML, pybtex); the figures need only the package.

Examples
--------
>>> from uio_teach.instructor import figures
>>> list(figures.FIGURES)[:2]
['pa9_sine', 'pa9_piecewise']
"""
