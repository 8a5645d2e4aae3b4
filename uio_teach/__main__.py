"""``python -m uio_teach``: the instructor's command line (see :mod:`uio_teach.cli`)."""

from .cli import main

if __name__ == "__main__":
    raise SystemExit(main())
