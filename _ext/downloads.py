"""What a reader takes away from the built book: the package, and each page printed as a PDF.

**The package.** Every build of the book writes the wheel of the companion package,
``_downloads/uio_teach-<version>-py3-none-any.whl``, into the site (built from a copy of the
sources, without the network; again only when a source it holds has changed). The directive
``package-install``, in the introduction, links it and shows the commands that install it with
what the notebooks need, the file named as the build named it. A student holding only the built
book can so run every chapter and lab.

**The PDFs.** With ``UIO_TEACH_PDF=1`` in the environment of ``jupyter-book build`` (``make pdf``
and ``make pdf-instructor``), every page links its own PDF and the whole book's, in the download
menu at the top of the page (in place of the theme's "print this page", which printed the
site's buttons) and under its title; once the pages are written, ``_ext/pdf_print.py`` prints
them into ``pdf/`` beside the site's folder (``_build/pdf`` for ``_build/html``) and they are
copied into the site's ``_pdf/``, where the links point (so they work offline, from a copy of
the folder). A build without it has no PDF link and removes ``_pdf/`` from the site: a link is
in a page only when the build that wrote the page also printed it. Switching between the two
rewrites every page (the setting ``uio_teach_pdf`` is part of the pages' configuration).
"""

from __future__ import annotations

import hashlib
import os
import posixpath
import shutil
import subprocess
import sys
import tempfile
import tomllib
from pathlib import Path
from typing import Any

from docutils import nodes
from docutils.parsers.rst import directives
from pdf_print import BOOK_NAME, pdf_name
from sphinx.application import Sphinx
from sphinx.config import Config
from sphinx.errors import ExtensionError
from sphinx.util import logging
from sphinx.util.docutils import SphinxDirective

PDF_VAR = "UIO_TEACH_PDF"
DOWNLOADS = "_downloads"  # the wheel, in the site
PDF_DIR = "_pdf"  # the printed pages, in the site
# What the wheel is built from (the tests install the wheel build_wheel makes, too).
WHEEL_SOURCES = ["uio_teach", "book", "setup.py", "pyproject.toml", "MANIFEST.in", "README.md"]
WHEEL_SOURCES += ["_toc.yml", "references.bib", "LICENSE", "LICENSE-BOOK.md"]
WHEEL_LIMIT = 600  # seconds: a limit against a hung build, not a timing
PRINT_LIMIT = 3600
EXTRA = "explorers"  # what the notebooks need besides the algorithms: the live explorers

logger = logging.getLogger(__name__)


def project_root(app: Sphinx) -> Path:
    return Path(app.confdir)


def wheel_name(root: Path) -> str:
    """The file name of the package's wheel, from ``pyproject.toml`` (a pure-Python wheel)."""
    project = tomllib.loads((root / "pyproject.toml").read_text(encoding="utf-8"))["project"]
    name = project["name"].replace("-", "_").replace(".", "_").lower()
    return f"{name}-{project['version']}-py3-none-any.whl"


def _sources_digest(root: Path) -> str:
    digest = hashlib.sha256()
    for name in sorted(WHEEL_SOURCES):
        path = root / name
        files = sorted(path.rglob("*")) if path.is_dir() else [path]
        for file in files:
            if file.is_file() and "__pycache__" not in file.parts:
                digest.update(file.relative_to(root).as_posix().encode())
                digest.update(file.read_bytes())
    return digest.hexdigest()


def build_wheel(root: Path, target: Path, stamps: Path) -> Path:
    """Build the package's wheel from a copy of the sources into ``target``; no network.

    Nothing is written into the sources (setuptools builds in the copy), and a wheel that is
    already there, built from the same sources (their digest is kept in ``stamps``, outside the
    site), is kept.
    """
    name = wheel_name(root)
    wheel, stamp = target / name, stamps / f"{name}.sha256"
    digest = _sources_digest(root)
    if wheel.is_file() and stamp.is_file() and stamp.read_text().strip() == digest:
        return wheel
    target.mkdir(parents=True, exist_ok=True)
    with tempfile.TemporaryDirectory() as tmp:
        src, dist = Path(tmp) / "src", Path(tmp) / "dist"
        for source in WHEEL_SOURCES:
            path = root / source
            if path.is_dir():
                shutil.copytree(path, src / source, ignore=shutil.ignore_patterns("__pycache__"))
            else:
                src.mkdir(exist_ok=True)
                shutil.copy2(path, src / source)
        command = [sys.executable, "-m", "pip", "--disable-pip-version-check", "-q", "wheel"]
        command += ["--no-deps", "--no-build-isolation", "--no-index", "-w", str(dist), str(src)]
        proc = subprocess.run(command, capture_output=True, text=True, timeout=WHEEL_LIMIT)
        built = dist / name
        if proc.returncode or not built.is_file():
            raise ExtensionError(
                f"the package's wheel ({name}) could not be built: {proc.stderr[-2000:]}"
            )
        for old in target.glob("*.whl"):
            old.unlink()
        shutil.move(built, wheel)
    stamps.mkdir(parents=True, exist_ok=True)
    stamp.write_text(digest + "\n")
    return wheel


class PackageInstall(SphinxDirective):
    """The package's wheel to download, and the commands that install it for the notebooks.

    ``:extra:`` names the package's extra the notebooks need (default ``explorers``).
    """

    has_content = False
    option_spec = {"extra": directives.unchanged}

    def run(self) -> list[nodes.Node]:
        name = self.config.uio_teach_wheel
        extra = self.options.get("extra", EXTRA)
        here = posixpath.dirname(self.env.docname)
        href = posixpath.relpath(f"{DOWNLOADS}/{name}", here or ".")
        link = nodes.reference("", "", refuri=href, classes=["download", "package-wheel"])
        link += nodes.literal(name, name)
        para = nodes.paragraph()
        para += nodes.Text("Download ")
        para += link
        para += nodes.Text(
            " into the folder of your notebooks; then, in a terminal in that folder:"
        )
        commands = (
            f'pip install "{name}[{extra}]" jupyterlab\n'
            "jupyter lab    # then open a chapter's notebook (.ipynb) and run it"
        )
        block = nodes.literal_block(commands, commands, language="bash")
        return [para, block]


# --- the PDFs ------------------------------------------------------------------------------------


def read_pdf_setting(app: Sphinx, config: Config) -> None:
    value = os.environ.get(PDF_VAR, "").strip().lower()
    if value not in ("", "0", "1", "no", "yes", "false", "true"):
        raise ExtensionError(f"{PDF_VAR}={value!r}: expected 1 (print the pages) or 0")
    config.uio_teach_pdf = value in ("1", "yes", "true")
    config.uio_teach_wheel = wheel_name(project_root(app))


def _edition(app: Sphinx) -> str:
    return getattr(app.config, "uio_teach_edition", "student")


def book_pdf_name(app: Sphinx) -> str:
    """The whole book's PDF: ``uio-teach.pdf``, the instructor edition's marked as such."""
    return BOOK_NAME if _edition(app) == "student" else f"{BOOK_NAME}-{_edition(app)}"


def page_downloads(
    app: Sphinx, pagename: str, templatename: str, context: dict[str, Any], doctree: Any
) -> None:
    """Link the page's PDF and the whole book's, in the download menu and under the title.

    Runs after the theme made the menu and after ``chapter_notebooks`` linked the notebook.
    """
    if not app.config.uio_teach_pdf or app.builder.format != "html":
        return
    pathto = context["pathto"]
    page = pathto(f"{PDF_DIR}/{pdf_name(app.config.root_doc, pagename)}.pdf", 1)
    book = pathto(f"{PDF_DIR}/{book_pdf_name(app)}.pdf", 1)
    for group in context.get("header_buttons", []):
        if group.get("label") != "download-buttons":
            continue
        kept = [b for b in group.get("buttons", []) if b.get("label") != "download-pdf-button"]
        kept.append(
            {
                "type": "link",
                "url": page,
                "text": ".pdf",
                "icon": "fas fa-file-pdf",
                "tooltip": "Download this page as a PDF",
                "label": "download-pdf-button",
            }
        )
        kept.append(
            {
                "type": "link",
                "url": book,
                "text": "book .pdf",
                "icon": "fas fa-book",
                "tooltip": "Download the whole book as a PDF",
                "label": "download-book-pdf-button",
            }
        )
        group["buttons"] = kept
    if "body" not in context:
        return
    line = (
        '<p class="page-downloads">Print version: '
        f'<a class="reference download" href="{page}" download>this page (PDF)</a>, '
        f'<a class="reference download" href="{book}" download>the whole book (PDF)</a></p>'
    )
    body = context["body"]
    end = body.find("</h1>")
    if end < 0:
        context["body"] = line + body
        return
    cut = end + len("</h1>")
    notebook = '<p class="chapter-notebook">'
    if body.startswith(notebook, cut):
        cut = body.index("</p>", cut) + len("</p>")
    context["body"] = body[:cut] + line + body[cut:]


def print_pages(app: Sphinx, exception: Exception | None) -> None:
    """After a good build: the wheel into the site; with PDFs on, every page printed."""
    if exception is not None or app.builder.format != "html":
        return
    outdir = Path(app.outdir)
    wheel = build_wheel(project_root(app), outdir / DOWNLOADS, Path(app.doctreedir))
    logger.info(f"the package's wheel: {wheel.relative_to(outdir)}")
    site_pdfs = outdir / PDF_DIR
    if not app.config.uio_teach_pdf:
        shutil.rmtree(site_pdfs, ignore_errors=True)  # no page links them
        return
    pdfs = outdir.parent / "pdf"
    subtitle = "" if _edition(app) == "student" else f"{_edition(app).capitalize()} edition"
    command = [sys.executable, str(Path(__file__).with_name("pdf_print.py")), str(outdir)]
    command += [str(pdfs), "--book-name", book_pdf_name(app), "--subtitle", subtitle]
    logger.info(f"printing every page and the whole book into {pdfs} ...")
    proc = subprocess.run(command, capture_output=True, text=True, timeout=PRINT_LIMIT)
    if proc.returncode:
        shutil.rmtree(site_pdfs, ignore_errors=True)
        raise ExtensionError(f"printing the pages failed:\n{proc.stdout}\n{proc.stderr[-4000:]}")
    logger.info(proc.stdout.strip())
    shutil.rmtree(site_pdfs, ignore_errors=True)
    shutil.copytree(pdfs, site_pdfs)


def setup(app: Sphinx) -> dict[str, Any]:
    # the pages' content depends on both: a change re-reads (the wheel's name) or rewrites them
    app.add_config_value("uio_teach_pdf", False, "html", types=[bool])
    app.add_config_value("uio_teach_wheel", "", "env", types=[str])
    app.connect("config-inited", read_pdf_setting)
    app.add_directive("package-install", PackageInstall)
    app.connect("html-page-context", page_downloads, priority=700)
    app.connect("build-finished", print_pages)
    return {"version": "1.0", "parallel_read_safe": True, "parallel_write_safe": True}
