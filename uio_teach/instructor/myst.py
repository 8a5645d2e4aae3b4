"""MyST Markdown written as plain Jupyter Markdown: roles, directives, labels, equations.

Used by :mod:`uio_teach.instructor.labs`: exercises become quotes titled "Exercise
<number>", ``{eq}`` references become "eq. (3.2)", ``{doc}`` and ``{ref}`` become
"chapter 3" (or the section's title on its own page), ``{cite:p}`` becomes
(Author, year), labelled display equations get a ``\\tag``.

Examples
--------
>>> from uio_teach.instructor.book import BookIndex
>>> from uio_teach.instructor.myst import Converter
>>> conv = Converter(BookIndex(chapters={"pa9": 4}, equations={"eq-x": ("pa9", 2)}), "lab")
>>> conv.inline("see {eq}`eq-x` of {doc}`pa9`")
'see eq. (4.2) of chapter 4'
"""

from __future__ import annotations

import re
from dataclasses import dataclass
from pathlib import Path

from .book import LABELLED_MATH, TARGET, BookIndex

__all__ = ["Converter", "Directive", "tokens", "quote"]

_ROLE = re.compile(r"\{(?P<name>[\w:.-]+)\}`(?P<content>[^`]+)`")
_ADMONITIONS = {
    "note",
    "tip",
    "hint",
    "important",
    "warning",
    "caution",
    "attention",
    "danger",
    "error",
    "seealso",
}

# MyST Markdown -> Jupyter Markdown ---------------------------------------------------------------


@dataclass
class Directive:
    name: str
    arg: str
    options: dict[str, str]
    body: str


def tokens(text: str) -> list[str | Directive]:
    """Split Markdown into plain text and top-level directives, as jupytext's MyST parser does.

    The block parser of :mod:`jupytext.myst` (markdown-it-py with the MyST plugins, and the
    colon fence of mdit-py-plugins) finds the directives; jupytext reads their options.
    """
    # deferred on purpose: jupytext comes with the optional ``instructor`` extra
    from jupytext.myst import get_parser, parse_directive_options
    from mdit_py_plugins.colon_fence import colon_fence_plugin

    lines = text.split("\n")
    out: list[str | Directive] = []
    done = 0
    for token in get_parser().use(colon_fence_plugin).parse(text):
        info = token.info.strip()
        if token.level or token.type not in ("fence", "colon_fence") or not info.startswith("{"):
            continue
        head = re.match(r"^\{(?P<name>[\w:.-]+)\}[ \t]*(?P<arg>.*)$", info)
        if head is None:
            continue
        start, end = token.map
        if start > done:
            out.append("\n".join(lines[done:start]))
        body, options = parse_directive_options(token.content, f"line {start + 1}: ")
        options = {str(k): "" if v is None else str(v) for k, v in options.items()}
        out.append(Directive(head["name"], head["arg"], options, "\n".join(body).strip("\n")))
        done = end
    if done < len(lines):
        out.append("\n".join(lines[done:]))
    return [t for t in out if not isinstance(t, str) or t.strip("\n")] or [text]


def quote(text: str) -> str:
    return "\n".join(f"> {line}" if line.strip() else ">" for line in text.split("\n"))


class Converter:
    """MyST roles, labels and labelled equations of one page, written as plain Markdown."""

    def __init__(self, index: BookIndex, stem: str) -> None:
        self.index = index
        self.stem = stem

    def role(self, m: re.Match[str]) -> str:
        name, content = m.group("name"), m.group("content")
        explicit = re.match(r"^(?P<text>.+?)\s*<(?P<target>[^>]+)>$", content, re.DOTALL)
        target = explicit.group("target") if explicit else content
        if name.startswith("cite"):
            return self.index.cite("t" if name.endswith(":t") else "p", content)
        if name == "math":
            return f"${content}$"
        if name in ("sub", "sup"):
            return f"<{name}>{content}</{name}>"
        if explicit:
            return explicit.group("text")
        if name == "doc":
            return self.index.short_page(Path(target).stem, self.stem)
        if name == "eq":
            if target in self.index.equations:
                stem, k = self.index.equations[target]
                return f"eq. ({self.index.number(stem, k)})"
            return f"eq. ({target})"
        if name in ("ref", "numref"):
            if target in self.index.exercises:
                stem, k = self.index.exercises[target]
                return f"exercise {self.index.number(stem, k)}"
            if target in self.index.sections:
                stem, title = self.index.sections[target]
                if stem == self.stem:
                    return f'section "{title}"'
                return self.index.short_page(stem, self.stem)
            return target
        return content

    def inline(self, text: str) -> str:
        def tag(m: re.Match[str]) -> str:
            label = m.group("label")
            if label in self.index.equations:
                stem, k = self.index.equations[label]
                number = self.index.number(stem, k)
            else:
                number = label
            return f"$${m.group('body').rstrip()} \\tag{{{number}}}$$"

        text = LABELLED_MATH.sub(tag, text)
        lines = [ln for ln in text.split("\n") if not TARGET.match(ln.strip())]
        lines = [ln for ln in lines if not re.match(r"^%( |$)", ln)]  # MyST comments
        text = _ROLE.sub(self.role, "\n".join(lines))
        # "eq. {eq}`x`" in the source: the role already says "eq."
        text = re.sub(r"\b([Ee]q\.|[Ee]quations?)(\s+)eq\. \(", r"\1\2(", text)
        # "equations {eq}`a`, {eq}`b` and {eq}`c`": the word is said once for the whole list
        sep = r"(?:,\s*|\s+and\s+)"
        listed = re.compile(
            rf"(\b(?:[Ee]qs\.|[Ee]quations)\s+\([^()]*\)(?:{sep}\([^()]*\))*{sep})eq\. \("
        )
        while listed.search(text):
            text = listed.sub(r"\1(", text)
        return re.sub(r"\n{3,}", "\n\n", text).strip("\n")

    def directive(self, d: Directive, exercise_number: str | None = None) -> str:
        body = self.markdown(d.body)
        if d.name == "exercise":
            title = f"**Exercise {exercise_number}**" + (f" ({d.arg})" if d.arg else "")
            return quote(f"{title}\n\n{body}")
        if d.name in _ADMONITIONS or d.name == "admonition":
            title = d.arg if d.name == "admonition" and d.arg else d.name.capitalize()
            return quote(f"**{title}.** {body}")
        if d.name == "math":
            return f"$$\n{d.body}\n$$"
        if d.name in ("code", "code-block", "sourcecode"):
            return f"```{d.arg}\n{d.body}\n```"
        if d.name in ("figure", "image"):
            return f"*Figure: {body or d.arg}*"
        return body

    def markdown(self, text: str) -> str:
        parts = []
        for token in tokens(text):
            parts.append(self.inline(token) if isinstance(token, str) else self.directive(token))
        return "\n\n".join(p for p in parts if p.strip())
