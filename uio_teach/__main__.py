"""``python -m uio_teach``: the instructor's command line (:mod:`uio_teach.instructor.cli`)."""

from .instructor.cli import main

if __name__ == "__main__":
    raise SystemExit(main())
