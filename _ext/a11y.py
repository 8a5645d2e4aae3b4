"""Sphinx extension: the pages' HTML meets WCAG 2.1 AA where the writers fall short.

* The bibliography: docutils writes each entry of a citation list with the role
  ``doc-biblioentry``, deprecated in DPUB-ARIA 1.1 and not an item of the ``list`` that holds it
  (screen readers announce a list with no items); the entries are written as ``listitem``.
* Headings and links that hold mathematics: MathJax's formula inside a heading or a link (the
  page's contents, the sidebars, the previous and next page) leaves the element's accessible
  name without it ("4.5.1. and , and how the assignment printed them"). Once the pages are
  written, every ``<h1>`` ... ``<h6>`` and ``<a>`` of every page that holds a formula is given
  an ``aria-label``: its text with each formula in words (:func:`tex_words`, "H and T, and how
  the assignment printed them", "The verdict flips at gamma sub 1 plus gamma sub 2 equals 1").
  The heading's own link mark ("#") is left out of it.

The rest lives in ``_static/`` (added to every page): ``a11y.js`` the keyboard's way through the
page (formulas out of the Tab order, reached with M), the scrolling frames' names and their cue,
the code cells' names; ``a11y.css`` the link colour, the focus ring and the cue of cut content.
The figures' text alternatives come from the kernel (``uio_teach.figure_text``), the explorers'
from ``uio_teach.explorers.static``.
"""

from __future__ import annotations

import html
import re
from pathlib import Path
from typing import Any

from docutils import nodes
from sphinx.application import Sphinx
from sphinx.writers.html5 import HTML5Translator


def visit_citation(self: HTML5Translator, node: nodes.citation) -> None:
    """A bibliography entry: an item of the citation list (role ``listitem``)."""
    if not isinstance(node.previous_sibling(), type(node)):
        self.body.append('<div role="list" class="citation-list">\n')
    self.body.append(self.starttag(node, "div", classes=[node.tagname], role="listitem"))


# --- mathematics in words ------------------------------------------------------------------------

GREEK = {
    "alpha", "beta", "gamma", "delta", "epsilon", "varepsilon", "zeta", "eta", "theta",
    "vartheta", "iota", "kappa", "lambda", "mu", "nu", "xi", "pi", "rho", "sigma", "tau",
    "upsilon", "phi", "varphi", "chi", "psi", "omega", "Gamma", "Delta", "Theta", "Lambda",
    "Xi", "Pi", "Sigma", "Phi", "Psi", "Omega",
}  # fmt: skip
SYMBOLS = {
    "=": "equals", "+": "plus", "-": "minus", "<": "less than", ">": "greater than",
    "\\neq": "is not equal to", "\\ne": "is not equal to", "\\le": "is at most",
    "\\leq": "is at most", "\\ge": "is at least", "\\geq": "is at least", "\\in": "in",
    "\\notin": "not in", "\\cdot": "times", "\\times": "times", "\\to": "to",
    "\\rightarrow": "to", "\\infty": "infinity", "\\approx": "is about", "\\pm": "plus or minus",
    "\\mid": "such that", "\\subset": "subset of", "\\subseteq": "subset of", "\\ldots": "dots",
    "\\dots": "dots", "\\cdots": "dots", "\\|": "norm", "|": "absolute value", "'": "prime",
    "\\emptyset": "empty set", "\\perp": "perpendicular", "\\top": "transpose",
}  # fmt: skip
ACCENTS = {"hat": "hat", "widehat": "hat", "bar": "bar", "overline": "bar", "tilde": "tilde",
           "widetilde": "tilde", "dot": "dot", "ddot": "double dot", "vec": "vector"}  # fmt: skip
WORDS = {"mathbf", "mathrm", "mathit", "mathsf", "boldsymbol", "bm", "mathcal", "mathbb",
         "operatorname", "text", "textrm", "textit", "mbox", "rm", "bf"}  # fmt: skip
TEXT = {"operatorname", "text", "textrm", "textit", "mbox"}
SPACES = {"\\,", "\\;", "\\:", "\\!", "\\ ", "\\quad", "\\qquad", "~", "&", "\\\\"}
SIZES = {"left", "right", "big", "Big", "bigg", "Bigg", "bigl", "bigr", "Bigl", "Bigr",
         "displaystyle", "textstyle", "limits", "nolimits"}  # fmt: skip
POWERS = {"T": "transpose", "\\top": "transpose", "-1": "inverse", "+": "pseudo-inverse",
          "\\dagger": "pseudo-inverse", "2": "squared", "3": "cubed", "*": "star",
          "\\star": "star", "\\prime": "prime", "'": "prime"}  # fmt: skip

_TOKEN = re.compile(r"\\[A-Za-z]+|\\.|[A-Za-z]|\d+(?:\.\d+)?|\S")


def _group(tokens: list[str], i: int) -> tuple[list[str], int]:
    """The argument at ``tokens[i]``: a braced group or one token; and the index after it."""
    if i >= len(tokens):
        return [], i
    if tokens[i] != "{":
        return [tokens[i]], i + 1
    depth, j = 0, i
    while j < len(tokens):
        depth += {"{": 1, "}": -1}.get(tokens[j], 0)
        if depth == 0:
            return tokens[i + 1 : j], j + 1
        j += 1
    return tokens[i + 1 :], len(tokens)


def _words(tokens: list[str]) -> list[str]:
    out: list[str] = []
    i = 0
    while i < len(tokens):
        tok = tokens[i]
        name = tok[1:] if tok.startswith("\\") and tok[1:].isalpha() else ""
        if tok in ("{", "}") or tok in SPACES or name in SIZES:
            i += 1
        elif name in WORDS:
            arg, i = _group(tokens, i + 1)
            if name in TEXT:  # a word as written: "rank", "no fault"
                out.append("".join(t if t not in SPACES else " " for t in arg))
            else:  # a style of letters: the letters
                out += _words(arg)
        elif name in ACCENTS:
            arg, i = _group(tokens, i + 1)
            out += [*_words(arg), ACCENTS[name]]
        elif name in ("frac", "dfrac", "tfrac"):
            top, i = _group(tokens, i + 1)
            bottom, i = _group(tokens, i)
            out += [*_words(top), "over", *_words(bottom)]
        elif name == "sqrt":
            arg, i = _group(tokens, i + 1)
            out += ["square root of", *_words(arg)]
        elif tok in ("_", "^"):
            arg, i = _group(tokens, i + 1)
            key = "".join(arg)
            if tok == "^" and key in POWERS:
                out.append(POWERS[key])
            elif tok == "^":
                out += ["to the power", *_words(arg)]
            else:
                out += ["sub", *_words(arg)]
        elif name in GREEK:
            out.append(name.removeprefix("var"))
            i += 1
        elif tok in SYMBOLS:
            out.append(SYMBOLS[tok])
            i += 1
        elif name:  # another command: its name
            out.append(name)
            i += 1
        else:
            out.append(tok)
            i += 1
    return out


def tex_words(tex: str) -> str:
    """A formula in words, as a screen reader's speech text says it.

    Letters are read one by one (variables), Greek letters by name, subscripts as "sub",
    ``^T``, ``^{-1}`` and ``^+`` as transpose, inverse and pseudo-inverse, relations and
    operations in words; text and operator names whole.

    Examples
    --------
    >>> tex_words(r"\\gamma_1 + \\gamma_2 = 1")
    'gamma sub 1 plus gamma sub 2 equals 1'
    >>> tex_words(r"(TA, C)"), tex_words(r"0.5^k"), tex_words(r"\\hat{x}"), tex_words("CE = 0")
    ('(T A, C)', '0.5 to the power k', 'x hat', 'C E equals 0')
    """
    words = " ".join(_words(_TOKEN.findall(tex)))
    words = re.sub(r"\s+([,.;:)\]])", r"\1", words)
    words = re.sub(r"([(\[])\s+", r"\1", words)
    return " ".join(words.split())


# --- headings and links that hold a formula -------------------------------------------------------

_MATH = re.compile(
    r'<span class="math notranslate nohighlight">\s*(?:\\\(|\\\[|\$\$?)(?P<tex>.*?)'
    r"(?:\\\)|\\\]|\$\$?)\s*</span>",
    flags=re.S,
)
_NAMED = re.compile(r"<(?P<tag>h[1-6]|a)\b(?P<attrs>[^>]*)>(?P<inner>.*?)</(?P=tag)>", flags=re.S)
_HEADERLINK = re.compile(r'<a class="headerlink"[^>]*>.*?</a>', flags=re.S)
_TAG = re.compile(r"<[^>]+>")


def spoken_name(inner: str) -> str:
    """The text of an element's HTML with every formula in words: its accessible name."""
    inner = _HEADERLINK.sub("", inner)
    inner = _MATH.sub(lambda m: " " + html.escape(tex_words(html.unescape(m["tex"]))) + " ", inner)
    text = html.unescape(_TAG.sub("", inner))
    text = re.sub(r"\s+([,.;:)!?])", r"\1", " ".join(text.split()))
    return text


def name_formulas(page: str) -> tuple[str, int]:
    """Every heading and link of ``page`` (HTML) that holds a formula, named with the formula in
    words (``aria-label``); elements named already are left as they are. Returns the page and how
    many elements were named.

    Examples
    --------
    >>> page, n = name_formulas('<h2>Why <span class="math notranslate nohighlight">\\\\(M_v\\\\)'
    ...                         '</span> does nothing<a class="headerlink" href="#w">#</a></h2>')
    >>> n, page.split(">")[0]
    (1, '<h2 aria-label="Why M sub v does nothing"')
    """
    count = 0

    def name(match: re.Match) -> str:
        nonlocal count
        tag, attrs, inner = match["tag"], match["attrs"], match["inner"]
        if "aria-label=" in attrs or not _MATH.search(inner):
            return match[0]
        count += 1
        label = html.escape(spoken_name(inner), quote=True)
        return f'<{tag}{attrs} aria-label="{label}">{inner}</{tag}>'

    return _NAMED.sub(name, page), count


def name_formulas_in_site(app: Sphinx, exception: Exception | None) -> None:
    """Name the headings and links holding formulas in every page the build wrote."""
    if exception is not None or app.builder.format != "html":
        return
    for path in Path(app.outdir).rglob("*.html"):
        text = path.read_text(encoding="utf-8")
        if "math notranslate" not in text:
            continue
        named, count = name_formulas(text)
        if count:
            path.write_text(named, encoding="utf-8")


def setup(app: Sphinx) -> dict[str, Any]:
    HTML5Translator.visit_citation = visit_citation  # type: ignore[method-assign]
    # before the pages are printed (_ext/downloads.py, at the default priority 500)
    app.connect("build-finished", name_formulas_in_site, priority=400)
    return {"parallel_read_safe": True, "parallel_write_safe": True, "version": "1"}
