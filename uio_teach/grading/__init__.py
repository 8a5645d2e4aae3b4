"""The grader: hand-ins run in a sandbox, their answers checked, a gradebook written.

``uio-teach grade`` (:mod:`uio_teach.instructor.cli`) is this package's engine,
:func:`~uio_teach.grading.grade.grade`; its rooms:

* :mod:`~uio_teach.grading.grade` -- reading the hand-ins (links, names, groups,
  rosters, the answer key) and running a class, one row per hand-in;
* :mod:`~uio_teach.grading.sandbox` -- bubblewrap, with only the hand-in's own
  copy and what importing the package needs visible;
* :mod:`~uio_teach.grading.runner` -- one notebook run in a fresh kernel, its
  answers taken out as data;
* :mod:`~uio_teach.grading.checking` -- the answers checked in a limited child
  process, by the lab chapters' own check cells
  (:mod:`~uio_teach.grading.lab_checks`);
* :mod:`~uio_teach.grading.gradebook` -- the CSV, the feedback and the LMS exports.

The term's figures, lab notebooks and variants are :mod:`uio_teach.instructor`;
the grader needs the ``instructor`` extra (``pip install "uio-teach[instructor]"``).

Examples
--------
>>> from uio_teach.grading.grade import group_from_name
>>> group_from_name("pa9_g03.ipynb")
('pa9', 'g03')
"""
