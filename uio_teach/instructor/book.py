"""The book as data: page titles, labels, equation and exercise numbers, the bibliography.

:class:`BookIndex` reads what the book's pages define so that the lab
notebooks can write cross-references out as text ("equation (3.2)", "(De et
al., 2014)"). The table of contents is read with PyYAML, the bibliography with
pybtex (both come with the book's toolchain and with the ``instructor`` extra).
:func:`uio_teach.folders.default_book_dir` finds the chapters in a source checkout
or in the copy installed with the package.

Examples
--------
>>> from uio_teach.folders import default_book_dir
>>> from uio_teach.instructor.book import BookIndex
>>> index = BookIndex.from_book(default_book_dir())
>>> index.chapters["lab_pa9"] > index.chapters["toolbox"] > index.chapters["introduction"]
True
"""

from __future__ import annotations

import os
import re
from collections.abc import Sequence
from dataclasses import dataclass, field
from pathlib import Path

__all__ = [
    "BookIndex",
    "HEADING",
    "TARGET",
    "LABELLED_MATH",
    "fence_states",
    "split_front_matter",
]

_DIRECTIVE = re.compile(r"^(?P<fence>`{3,}|:{3,})\{(?P<name>[\w:.-]+)\}[ \t]*(?P<arg>.*?)\s*$")
_OPTION = re.compile(r"^:(?P<key>[\w-]+):[ \t]*(?P<value>.*?)\s*$")
HEADING = re.compile(r"^(?P<hashes>#{1,6})[ \t]+(?P<text>.*?)\s*#*\s*$")
"""A Markdown heading line, with groups ``hashes`` (its level) and ``text``."""
TARGET = re.compile(r"^\((?P<label>[^)\s]+)\)=\s*$")
"""A MyST target line, ``(label)=``, with group ``label``."""
LABELLED_MATH = re.compile(r"\$\$(?P<body>.+?)\$\$[ \t]*\((?P<label>[\w:.-]+)\)", re.DOTALL)
"""A labelled display equation, ``$$ ... $$ (label)``, with groups ``body`` and ``label``."""


def fence_states(lines: Sequence[str]) -> list[bool]:
    """For each line: True if it is a fence line or inside a code block (no Markdown there).

    Directive fences (```` ```{exercise} ````) nest and their bodies are Markdown;
    plain fences (```` ```python ````) and code directives hold code.

    Parameters
    ----------
    lines : sequence of str
        The lines of a page.

    Returns
    -------
    list of bool
        One per line.

    Examples
    --------
    >>> from uio_teach.instructor.book import fence_states
    >>> fence_states(["# Title", "```python", "# not a heading", "```", "text"])
    [False, True, True, True, False]
    """
    stack: list[tuple[str, bool]] = []
    states = []
    for line in lines:
        m = re.match(r"^(`{3,}|~{3,}|:{3,})(.*)$", line.strip())
        if m:
            fence, rest = m.group(1), m.group(2).strip()
            top = stack[-1][0] if stack else ""
            if stack and not rest and fence[0] == top[0] and len(fence) >= len(top):
                stack.pop()
            else:
                d = re.match(r"^\{([\w:.-]+)\}", rest)
                code = d is None or d.group(1) in ("code-cell", "code", "code-block", "math")
                stack.append((fence, code))
            states.append(True)
            continue
        states.append(any(code for _, code in stack))
    return states


def split_front_matter(text: str) -> tuple[dict, str]:
    """A page's YAML front matter (between two ``---`` lines) as a dict, and the text after it.

    The one reader of front matter in the course: the book index and the
    book's extension that links each chapter's notebook both use it.

    Parameters
    ----------
    text : str
        A MyST page.

    Returns
    -------
    (dict, str)
        The front matter (``{}`` if there is none or it is not a mapping) and the rest.

    Examples
    --------
    >>> from uio_teach.instructor.book import split_front_matter
    >>> split_front_matter("---\\nkernelspec: {name: python3}\\n---\\n# Title\\n")
    ({'kernelspec': {'name': 'python3'}}, '\\n# Title\\n')
    """
    if not text.startswith("---"):
        return {}, text
    end = text.find("\n---", 3)
    if end < 0:
        return {}, text
    # deferred on purpose: PyYAML comes with the optional ``instructor`` extra
    import yaml

    try:
        data = yaml.safe_load(text[3:end])
    except yaml.YAMLError:
        data = None
    return (data if isinstance(data, dict) else {}), text[end + 4 :]


def _strip_braces(text: str) -> str:
    return " ".join(text.replace("{", "").replace("}", "").split())


def _parse_bib(text: str) -> dict[str, dict[str, str]]:
    """BibTeX entries read by pybtex: ``{key: {field: value}}`` (braces removed from values).

    The authors come back as one ``"Last, First and Last, First"`` string.
    """
    from pybtex.database import parse_string  # deferred: the optional ``instructor`` extra

    entries: dict[str, dict[str, str]] = {}
    for key, entry in parse_string(text, "bibtex").entries.items():
        fields = {name.lower(): _strip_braces(value) for name, value in entry.fields.items()}
        for role, persons in entry.persons.items():
            fields[role.lower()] = " and ".join(_strip_braces(str(p)) for p in persons)
        entries[key] = fields
    return entries


@dataclass
class BookIndex:
    """What the book's pages define, so that cross-references can be written out as text.

    Attributes
    ----------
    titles : dict
        Page stem -> page title (its first ``#`` heading).
    chapters : dict
        Page stem -> chapter number (numbered parts of ``_toc.yml``).
    sections : dict
        Section label -> (page stem, heading text).
    equations : dict
        Equation label -> (page stem, number within the page).
    exercises : dict
        Exercise label -> (page stem, number within the page).
    bib : dict
        Citation key -> BibTeX fields.

    Examples
    --------
    >>> from uio_teach.folders import default_book_dir
    >>> from uio_teach.instructor.book import BookIndex
    >>> index = BookIndex.from_book(default_book_dir())
    >>> index.chapters["introduction"], "api" in index.chapters   # numbered parts only
    (1, False)
    >>> index.cite("p", "de2014comparison")
    '(De et al., 2014)'
    """

    titles: dict[str, str] = field(default_factory=dict)
    chapters: dict[str, int] = field(default_factory=dict)
    sections: dict[str, tuple[str, str]] = field(default_factory=dict)
    equations: dict[str, tuple[str, int]] = field(default_factory=dict)
    exercises: dict[str, tuple[str, int]] = field(default_factory=dict)
    bib: dict[str, dict[str, str]] = field(default_factory=dict)

    @classmethod
    def from_book(cls, book_dir: str | os.PathLike[str] | None) -> BookIndex:
        """Scan ``book_dir/*.md``, ``_toc.yml`` and ``references.bib`` (in its parent).

        Parameters
        ----------
        book_dir : str or path-like, optional
            The folder of the chapters; ``None`` gives an empty index.

        Returns
        -------
        BookIndex

        Examples
        --------
        >>> from uio_teach.instructor.book import BookIndex
        >>> BookIndex.from_book(None).titles
        {}
        """
        index = cls()
        if book_dir is None or not Path(book_dir).is_dir():
            return index
        book = Path(book_dir)
        for page in sorted(book.glob("*.md")):
            index._scan_page(page.stem, page.read_text(encoding="utf-8"))
        root = book.parent
        index._read_toc(root / "_toc.yml", root)
        bib = root / "references.bib"
        if bib.is_file():
            index.bib = _parse_bib(bib.read_text(encoding="utf-8"))
        return index

    def _scan_page(self, stem: str, text: str) -> None:
        text = split_front_matter(text)[1]
        lines = text.splitlines()
        pending: list[str] = []
        exercise_count = 0
        verbatim = fence_states(lines)
        for i, line in enumerate(lines):
            stripped = line.strip()
            d = _DIRECTIVE.match(stripped)
            if d and d.group("name") == "exercise":
                exercise_count += 1
                for opt in lines[i + 1 : i + 8]:
                    o = _OPTION.match(opt.strip())
                    if not o:
                        break
                    if o.group("key") == "label":
                        self.exercises[o.group("value")] = (stem, exercise_count)
            if verbatim[i]:
                continue
            target = TARGET.match(stripped)
            if target:
                pending.append(target.group("label"))
                continue
            heading = HEADING.match(line)
            if heading:
                title = heading.group("text")
                if len(heading.group("hashes")) == 1 and stem not in self.titles:
                    self.titles[stem] = title
                for label in pending:
                    self.sections[label] = (stem, title)
            if stripped:
                pending = []
        body = "\n".join(lines)
        found = [(m.start(), m.group("label")) for m in LABELLED_MATH.finditer(body)]
        for m in re.finditer(r"^(`{3,}|:{3,})\{math\}.*\n((?::[\w-]+:.*\n)*)", body, re.M):
            label = re.search(r"^:label:\s*(\S+)", m.group(2), re.M)
            if label:
                found.append((m.start(), label.group(1)))
        for number, (_, label) in enumerate(sorted(found), start=1):
            self.equations[label] = (stem, number)

    def _read_toc(self, toc: Path, root: Path) -> None:
        if not toc.is_file():
            return
        try:
            import yaml  # deferred: the optional ``instructor`` extra

            data = yaml.safe_load(toc.read_text(encoding="utf-8")) or {}
        except Exception:  # a broken toc only costs the chapter numbers
            return
        number = 0
        parts = data.get("parts") or [{"chapters": data.get("chapters") or []}]
        for part in parts:
            if not isinstance(part, dict) or not part.get("numbered"):
                continue
            for chapter in part.get("chapters") or []:
                if isinstance(chapter, dict) and "file" in chapter:
                    number += 1
                    self.chapters[Path(str(chapter["file"])).stem] = number

    # references as text -------------------------------------------------------------------------
    def number(self, stem: str, k: int) -> str:
        """``"7.2"`` for item 2 of chapter 7, ``"2"`` on an unnumbered page.

        Parameters
        ----------
        stem : str
            Page stem.
        k : int
            Number within the page.

        Returns
        -------
        str

        Examples
        --------
        >>> from uio_teach.instructor.book import BookIndex
        >>> BookIndex(chapters={"07_lab": 7}).number("07_lab", 2)
        '7.2'
        """
        chapter = self.chapters.get(stem)
        return f"{chapter}.{k}" if chapter else str(k)

    def page(self, stem: str, here: str) -> str:
        """A page as text: ``chapter 3, *Title*`` (just ``*Title*`` if unnumbered)."""
        title = self.titles.get(stem, stem)
        if stem == here:
            return "this chapter"
        chapter = self.chapters.get(stem)
        return f"chapter {chapter}, *{title}*" if chapter else f"*{title}*"

    def short_page(self, stem: str, here: str) -> str:
        """A page as short plain text: ``chapter 3`` (the title if unnumbered).

        Parameters
        ----------
        stem : str
            The page referred to.
        here : str
            The page the reference is on (``"this chapter"`` if it is ``stem``).

        Returns
        -------
        str

        Examples
        --------
        >>> from uio_teach.instructor.book import BookIndex
        >>> index = BookIndex(chapters={"pa9": 4}, titles={"api": "API"})
        >>> index.short_page("pa9", "lab"), index.short_page("api", "lab")
        ('chapter 4', '*API*')
        """
        if stem == here:
            return "this chapter"
        chapter = self.chapters.get(stem)
        return f"chapter {chapter}" if chapter else f"*{self.titles.get(stem, stem)}*"

    def cite(self, kind: str, keys: str) -> str:
        """A citation as text: ``kind`` ``"p"`` gives (Author, year), ``"t"`` Author (year).

        Parameters
        ----------
        kind : str
            ``"p"`` (parenthetical) or ``"t"`` (textual).
        keys : str
            Comma-separated BibTeX keys.

        Returns
        -------
        str

        Examples
        --------
        >>> from uio_teach.instructor.book import BookIndex
        >>> index = BookIndex(bib={"k": {"author": "Hui, S. and Zak, S. H.", "year": "2005"}})
        >>> index.cite("t", "k"), index.cite("p", "k")
        ('Hui and Zak (2005)', '(Hui and Zak, 2005)')
        """
        parts = []
        for key in (k.strip() for k in keys.split(",")):
            entry = self.bib.get(key)
            if entry is None:
                parts.append((f"[{key}]", ""))
                continue
            who = entry.get("key") or entry.get("title", key)
            if entry.get("author"):
                names = [n.strip() for n in entry["author"].split(" and ")]
                last = [n.split(",")[0] if "," in n else n.split()[-1] for n in names]
                who = " and ".join(last) if len(last) <= 2 else f"{last[0]} et al."
            parts.append((who, entry.get("year", "")))
        if kind.startswith("t"):
            return "; ".join(f"{w} ({y})" if y else w for w, y in parts)
        return "(" + "; ".join(f"{w}, {y}" if y else w for w, y in parts) + ")"
