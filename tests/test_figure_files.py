"""The figures' pictures as files of the site (``_ext/figure_files.py``), on HTML as the kernel
writes it: a course figure (``uio_teach.figure_text.figure_html``) and a static explorer's
frame store. The pages of the built book are checked in a browser by ``test_page_weight.py``.
"""

from __future__ import annotations

import base64
import re
import sys
from pathlib import Path

import pytest
from sphinx.errors import ExtensionError

from uio_teach.figure_text import describe, figure_html
from uio_teach.plotting import new_figure

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "_ext"))

from figure_files import (  # noqa: E402 (the extension lives in _ext/)
    FIRST_SCREEN,
    lazy_pictures,
    picture_name,
    pictures_to_files,
)


def _figure_html() -> str:
    fig = new_figure(6, 3)
    left, right = fig.subplots(1, 2)
    left.plot([0, 1, 2], [1, 0.2, 0.0])
    right.plot([0, 1, 2], [0, 0.5, 1.0])
    return figure_html(describe(fig, "Two lines, one falling, one rising.", "Left falls."))


def _url(name: str) -> str:
    return f"../_images/{name}"


def _data_urls(text: str) -> list[bytes]:
    return [base64.b64decode(m) for m in re.findall(r"data:image/png;base64,([^\"]+)", text)]


def test_a_figure_becomes_files_with_its_words_intact(tmp_path: Path) -> None:
    text = _figure_html()
    pngs = _data_urls(text)
    assert len(pngs) == 2  # the phone version and the wide one
    body, moved = pictures_to_files(text, tmp_path, _url)
    assert moved == 2 and "data:" not in body
    for png in pngs:
        assert (tmp_path / picture_name(png)).read_bytes() == png
    narrow, wide = (picture_name(png) for png in pngs)
    assert f'srcset="../_images/{narrow}"' in body and f'src="../_images/{wide}"' in body
    # everything but the addresses as the kernel wrote it
    strip = re.compile(r'(src|srcset)="[^"]*"')
    assert strip.sub("", body) == strip.sub("", text)
    assert 'alt="Two lines, one falling, one rising."' in body
    assert "aria-describedby=" in body and "<details" in body


def test_the_same_picture_is_stored_once(tmp_path: Path) -> None:
    text = _figure_html()
    body, moved = pictures_to_files(text + text, tmp_path, _url)
    assert moved == 4
    assert len(list(tmp_path.iterdir())) == 2
    assert not list(tmp_path.glob("*.part"))


def test_explorer_frames_become_files_and_pictures_get_their_size(tmp_path: Path) -> None:
    png = _data_urls(_figure_html())[1]
    url = "data:image/png;base64," + base64.b64encode(png).decode("ascii")
    width, height = int.from_bytes(png[16:20], "big"), int.from_bytes(png[20:24], "big")
    text = (
        f'<picture><source media="(max-width:700px)" srcset="{url}">'
        f'<img class="uio-frame" src="{url}" alt="A frame."></picture>'
        f'<span data-k="0-0" data-src="{url}" data-narrow="{url}" data-alt="A frame."></span>'
    )
    body, moved = pictures_to_files(text, tmp_path, _url)
    assert moved == 4 and "data:" not in body
    name = picture_name(png)
    assert f'data-src="../_images/{name}" data-narrow="../_images/{name}"' in body
    # the picture keeps its place on the page while it loads
    assert body.count(f'width="{width}" height="{height}"') == 2
    assert 'data-alt="A frame."' in body


def test_a_broken_picture_is_named(tmp_path: Path) -> None:
    with pytest.raises(ExtensionError, match="srcset"):
        pictures_to_files('<source srcset="data:image/png;base64,AAAA">', tmp_path, _url)
    with pytest.raises(ExtensionError, match="src attribute holds broken base64"):
        pictures_to_files('<img src="data:image/png;base64,A">', tmp_path, _url)


def test_pictures_past_the_first_screen_load_lazily() -> None:
    words = "<p>" + "word " * (FIRST_SCREEN // 5 + 1) + "</p>"
    body = '<img src="a.png" alt="a">' + words + '<img src="b.png" alt="b">'
    body += '<img src="c.png" alt="c" loading="eager">'
    tags = re.findall(r"<img[^>]*>", lazy_pictures(body))
    assert "loading" not in tags[0]  # in the first screen
    assert 'loading="lazy"' in tags[1] and 'decoding="async"' in tags[1]
    assert tags[2] == '<img src="c.png" alt="c" loading="eager">'  # its own choice kept
