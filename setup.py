"""Build step of the wheel: it carries the book's chapters, table of contents and bibliography.

``uio-teach labs`` turns the lab chapters into notebooks and writes the book's
cross-references out as text, so it needs ``book/*.md``, ``_toc.yml`` and
``references.bib``. They are copied into ``uio_teach/_course/`` of the wheel (the
book's own files stay where they are); an editable install reads the checkout.
"""

import shutil
from pathlib import Path

from setuptools import setup
from setuptools.command.build_py import build_py

ROOT = Path(__file__).resolve().parent
COURSE_FILES = ("_toc.yml", "references.bib", "book/*.md")


class BuildWithCourse(build_py):
    """``build_py`` that also copies the course files into ``uio_teach/_course``."""

    def run(self) -> None:
        super().run()
        if getattr(self, "editable_mode", False):
            return
        target = Path(self.build_lib) / "uio_teach" / "_course"
        for pattern in COURSE_FILES:
            for source in sorted(ROOT.glob(pattern)):
                dest = target / source.relative_to(ROOT)
                dest.parent.mkdir(parents=True, exist_ok=True)
                shutil.copyfile(source, dest)


setup(cmdclass={"build_py": BuildWithCourse})
