"""Sphinx extension: the pictures of the pages' figures as files, each fetched only when shown.

A course figure reaches the page as the HTML its notebook shows (``uio_teach.figure_text``:
a ``<picture>`` with the phone version in a ``<source media>`` and the wide one in the
``<img>``, both ``data:`` URLs, so that a notebook opened in Jupyter is whole by itself); a
static explorer (``uio_teach.explorers.static``) carries every frame the same way, the wide and
the phone picture of each in ``data-src`` and ``data-narrow`` attributes that its slider puts
into the ``<img>`` and the ``<source>``. Left inline, every reader would download every picture
twice, inside the HTML: a phone the wide versions it never shows, a desktop the phone ones,
every explorer frame whether or not the slider visits it, nothing cached between pages and
nothing left for later.

When a page is written, every ``data:image/png`` URL in those attributes (``src``, ``srcset``,
``data-src``, ``data-narrow``) of its body becomes a file of the site, ``_images/fig-<hash>.png``
(named by its content: a picture drawn twice is stored once), and the attribute its relative URL
(``../_images/...`` from a chapter). The browser then fetches the one picture of a ``<picture>``
that its screen's media query selects, an explorer's frame only when the slider shows it, and
every picture lazily (``loading="lazy"``, ``decoding="async"``): a reader who stops halfway
never downloads the rest. Only a picture with less text before it than a phone's first screen
holds (:data:`FIRST_SCREEN`) loads at once, where a lazy one would arrive later. The URLs are
relative, so the site works from a copy of its folder opened from disk, and
``_ext/pdf_print.py`` loads every picture before it prints. Files no page refers to any more
are removed when the build finishes.
"""

from __future__ import annotations

import base64
import binascii
import hashlib
import re
import tempfile
from pathlib import Path
from typing import Any

from sphinx.application import Sphinx
from sphinx.errors import ExtensionError
from sphinx.util import logging

IMAGES = "_images"  # Sphinx's folder of the site's pictures
PREFIX = "fig-"  # the files this extension writes (and removes when no page refers to them)
ATTRIBUTES = ("src", "srcset", "data-src", "data-narrow")
# About the characters of text a phone's first screen shows (390 x 844 CSS pixels, some 45
# characters a line under the page's header): a picture with more text before it is further
# down on every screen, and loads lazily.
FIRST_SCREEN = 1200

# an attribute holding a whole PNG data URL (a single candidate: no descriptor in srcset)
_DATA_URL = re.compile(
    r"(?P<lead>\s(?P<name>" + "|".join(map(re.escape, ATTRIBUTES)) + r')=")'
    r"data:image/png;base64,(?P<data>[A-Za-z0-9+/=\s]+)(?P<end>\")"
)
_IMG = re.compile(r"<img\b[^>]*>", flags=re.IGNORECASE)
_PICTURE_TAG = re.compile(r"<(?:img|source)\b[^>]*>", flags=re.IGNORECASE)
_REFERENCE = re.compile(PREFIX + r"[0-9a-f]{20}\.png")

logger = logging.getLogger(__name__)


def picture_name(png: bytes) -> str:
    """The file name of a picture: its content's hash (the same picture, the same file)."""
    return f"{PREFIX}{hashlib.sha256(png).hexdigest()[:20]}.png"


def _write(folder: Path, png: bytes) -> str:
    name = picture_name(png)
    target = folder / name
    if not target.exists():
        folder.mkdir(parents=True, exist_ok=True)
        # whole or absent, when pages are written in parallel: a file of its own, then renamed
        with tempfile.NamedTemporaryFile(dir=folder, suffix=".part", delete=False) as partial:
            partial.write(png)
        Path(partial.name).replace(target)
    return name


def pictures_to_files(body: str, folder: Path, url_of: Any) -> tuple[str, int]:
    """``body`` with its PNG data URLs replaced by files in ``folder``; how many it moved.

    ``url_of(name)`` is the URL, from the page, of the file ``name`` in ``folder``.
    """
    moved = 0

    def sized(match: re.Match) -> str:
        # the picture's size, where the tag has none: the page keeps its layout while it loads
        tag = match[0]
        found = _DATA_URL.search(tag)
        if found is None or found["name"] not in ("src", "srcset") or " width=" in tag:
            return tag
        png = _decode(found)
        width, height = int.from_bytes(png[16:20], "big"), int.from_bytes(png[20:24], "big")
        end = "/>" if tag.endswith("/>") else ">"
        return tag[: -len(end)].rstrip() + f' width="{width}" height="{height}"' + end

    def replace(match: re.Match) -> str:
        nonlocal moved
        moved += 1
        return match["lead"] + url_of(_write(folder, _decode(match))) + match["end"]

    body = _PICTURE_TAG.sub(sized, body)
    return _DATA_URL.sub(replace, body), moved


def _decode(match: re.Match) -> bytes:
    try:
        png = base64.b64decode(re.sub(r"\s+", "", match["data"]), validate=True)
    except binascii.Error as exc:
        raise ExtensionError(f"a {match['name']} attribute holds broken base64: {exc}") from exc
    if not png.startswith(b"\x89PNG\r\n\x1a\n") or len(png) < 24:
        raise ExtensionError(f"a {match['name']} attribute's data:image/png is not a PNG")
    return png


def lazy_pictures(body: str, first_screen: int = FIRST_SCREEN) -> str:
    """Every ``<img>`` of ``body`` loads lazily, unless it says otherwise or less than
    ``first_screen`` characters of text come before it (it is likely in the first screen)."""

    def mark(match: re.Match) -> str:
        tag = match[0]
        if re.search(r"\sloading=", tag, flags=re.IGNORECASE):
            return tag
        if len(_text(body[: match.start()])) < first_screen:
            return tag
        end = "/>" if tag.endswith("/>") else ">"
        extra = ' loading="lazy"'
        if not re.search(r"\sdecoding=", tag, flags=re.IGNORECASE):
            extra += ' decoding="async"'
        return tag[: -len(end)].rstrip() + extra + end

    return _IMG.sub(mark, body)


def _text(html: str) -> str:
    """The words of some HTML, roughly: its scripts, styles and tags left out."""
    html = re.sub(r"<(script|style)\b.*?</\1>", "", html, flags=re.S | re.IGNORECASE)
    return re.sub(r"\s+", " ", re.sub(r"<[^>]*>", "", html))


def _page_context(
    app: Sphinx, pagename: str, templatename: str, context: dict, doctree: Any
) -> None:
    if app.builder.format != "html" or "body" not in context:
        return
    folder = Path(app.builder.outdir) / IMAGES
    pathto = context["pathto"]
    body, _ = pictures_to_files(context["body"], folder, lambda name: pathto(f"{IMAGES}/{name}", 1))
    context["body"] = lazy_pictures(body)


def _remove_unused(app: Sphinx, exception: Exception | None) -> None:
    """Remove the picture files that no page of the site refers to (left by earlier builds)."""
    if exception is not None or app.builder.format != "html":
        return
    out = Path(app.builder.outdir)
    folder = out / IMAGES
    if not folder.is_dir():
        return
    used: set[str] = set()
    for page in out.rglob("*.html"):
        used.update(_REFERENCE.findall(page.read_text(encoding="utf-8", errors="replace")))
    for file in folder.glob(f"{PREFIX}*"):
        if file.name not in used:
            file.unlink()


def setup(app: Sphinx) -> dict[str, Any]:
    app.connect("html-page-context", _page_context)
    app.connect("build-finished", _remove_unused)
    return {"parallel_read_safe": True, "parallel_write_safe": True, "version": "1"}
