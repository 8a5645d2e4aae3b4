"""``python -m uio_teach``: the instructor's command line (:mod:`uio_teach.instructor.cli`).

The same command as the ``uio-teach`` script, for an environment whose scripts folder is not
on the ``PATH`` (a notebook's kernel, an interpreter named by its full path); the book's
instructor page and the labs use this form.
"""

from .instructor.cli import main

if __name__ == "__main__":
    raise SystemExit(main())
