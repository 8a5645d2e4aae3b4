"""What a hand-in folder holds: the hand-ins, and a reason for everything else.

An LMS's bulk download is a folder of notebooks (Canvas), of one folder per
student or group (Moodle's "download submissions in folders"), or of whatever
the students uploaded: archives, scripts, notebooks named ``.IPYNB``, the
files a Mac puts into a zip. :func:`survey` walks the folder to any depth,
without following a link, and sorts every entry it holds into one of two
kinds:

* a **hand-in**: any entry whose name ends in ``.ipynb`` (in any case), at
  any depth; each gets its row in the gradebook (a link, a folder or a
  device of that name too, as a refused row);
* anything else, with **one line saying why it is not graded**: a folder
  (its entries are listed on their own), Jupyter's checkpoints, an archive
  (not opened), a script, another kind of file, a link (not followed), the
  gradebook a run writes into the folder.

:func:`added_since` compares two surveys of one folder: what appeared during a
run is listed as not graded.

Examples
--------
>>> import pathlib, tempfile
>>> from uio_teach.grading.survey import survey
>>> with tempfile.TemporaryDirectory() as tmp:
...     root = pathlib.Path(tmp)
...     (root / "Ann_12_assignsubmission_file_").mkdir()
...     _ = (root / "Ann_12_assignsubmission_file_" / "pa9_g01.IPYNB").write_text("{}")
...     _ = (root / "pa9_g02.zip").write_bytes(b"PK")
...     found = survey(root)
>>> [pathlib.Path(f).name for f in found.handins]
['pa9_g01.IPYNB']
>>> [why.split(":")[0] for _, why in found.others]
['a folder', 'an archive, not opened']
"""

from __future__ import annotations

import os
import stat
from collections.abc import Iterable
from dataclasses import dataclass, field
from pathlib import Path

__all__ = ["Survey", "survey", "added_since", "not_a_handin", "is_handin_name"]

_ARCHIVES = (".zip", ".tar", ".gz", ".tgz", ".bz2", ".xz", ".7z", ".rar")
_SCRIPTS = (".py", ".m", ".r", ".jl")
_SYSTEM = {".ds_store", "thumbs.db", "desktop.ini", "icon\r"}
_SKIPPED = {
    ".ipynb_checkpoints": "Jupyter's checkpoints (earlier saves of a notebook), not a hand-in",
    "__macosx": "what macOS adds to a zip (resource forks), not a hand-in",
    "__pycache__": "Python's compiled files, not a hand-in",
}
MAX_ENTRIES = 100_000
"""The most entries one survey looks at (a larger folder is not a hand-in folder)."""


def is_handin_name(name: str) -> bool:
    """Whether an entry of this name is a hand-in: it ends in ``.ipynb``, in any case.

    Parameters
    ----------
    name : str

    Returns
    -------
    bool

    Examples
    --------
    >>> from uio_teach.grading.survey import is_handin_name
    >>> is_handin_name("pa9_g01.IPYNB"), is_handin_name("pa9_g01.py")
    (True, False)
    """
    return name.lower().endswith(".ipynb") and name.lower() != ".ipynb"


def not_a_handin(name: str, mode: int) -> str:
    """Why an entry that is not a hand-in is not graded, in one line (for the run's summary).

    Parameters
    ----------
    name : str
        The entry's name.
    mode : int
        Its ``st_mode`` (of the entry itself, not of what a link points to).

    Returns
    -------
    str

    Examples
    --------
    >>> import stat
    >>> from uio_teach.grading.survey import not_a_handin
    >>> not_a_handin("pa9_g01.py", stat.S_IFREG)
    'a Python script, not a notebook: the lab is handed in as its .ipynb notebook'
    """
    lower = name.lower()
    if stat.S_ISLNK(mode):
        return "a link: not followed (hand-ins must be files of the hand-in folder)"
    if stat.S_ISDIR(mode):
        return _SKIPPED.get(lower, "a folder: its entries are listed on their own")
    if lower in _SYSTEM or name.startswith("._"):
        return "a file the operating system made, not a hand-in"
    suffix = Path(lower).suffix
    if not stat.S_ISREG(mode):
        return "not a regular file (a device, a pipe or a socket), and not a notebook"
    if suffix in _ARCHIVES or lower.endswith((".tar.gz", ".tar.xz")):
        return (
            "an archive, not opened: unpack the notebooks into the hand-in folder (or ask the "
            "group for its .ipynb) and grade again"
        )
    if suffix == ".py":
        return "a Python script, not a notebook: the lab is handed in as its .ipynb notebook"
    if suffix in _SCRIPTS:
        return f"a script ({suffix}), not a notebook: the lab is handed in as its .ipynb notebook"
    if name.endswith("~") or suffix in (".bak", ".swp", ".tmp"):
        return "a backup or temporary copy, not a hand-in"
    kind = f"a {suffix} file" if suffix else "a file without an extension"
    return f"{kind}, not a notebook: only .ipynb notebooks are graded"


@dataclass
class Survey:
    """What a hand-in folder held.

    Attributes
    ----------
    folder : str
        The folder surveyed.
    handins : list of str
        Every hand-in (an entry named ``*.ipynb``, at any depth), sorted.
    others : list of (str, str)
        Every other entry and why it is not graded, sorted.
    """

    folder: str
    handins: list[str] = field(default_factory=list)
    others: list[tuple[str, str]] = field(default_factory=list)

    @property
    def entries(self) -> int:
        """How many entries the folder held (hand-ins and the rest)."""
        return len(self.handins) + len(self.others)

    def counts(self) -> str:
        """What the folder held, in words (for the run's summary)."""
        folders = sum(1 for _, why in self.others if why.startswith("a folder"))
        rest = len(self.others) - folders
        parts = [f"{len(self.handins)} hand-in{'s' if len(self.handins) != 1 else ''}"]
        if folders:
            parts.append(f"{folders} folder{'s' if folders != 1 else ''}")
        parts.append(f"{rest} other entr{'ies' if rest != 1 else 'y'} not graded")
        return f"{self.entries} entr{'ies' if self.entries != 1 else 'y'}: " + ", ".join(parts)


def survey(folder: str | os.PathLike[str], *, own: Iterable[str | os.PathLike[str]] = ()) -> Survey:
    """Every entry of ``folder`` at any depth: a hand-in, or why it is not one.

    No link is followed (a link named ``*.ipynb`` is a hand-in, refused when
    it is read; any other link is listed as not followed); Jupyter's
    checkpoints, macOS's ``__MACOSX`` and Python's caches are listed once and
    not entered; past :data:`MAX_ENTRIES` the rest is one line.

    Parameters
    ----------
    folder : str or path-like
        The hand-in folder.
    own : iterable of path
        What the grading run itself writes in the folder (the gradebook, its
        exports, its feedback folder): listed as the run's own.

    Returns
    -------
    Survey
    """
    root = os.fspath(folder)
    mine = {os.path.abspath(p) for p in own}
    found = Survey(root)
    stack = [root]
    seen = 0
    while stack:
        current = stack.pop()
        try:
            with os.scandir(current) as it:
                entries = sorted(it, key=lambda e: e.name)
        except OSError as err:
            found.others.append((current, f"a folder that cannot be read ({err.strerror})"))
            continue
        for entry in entries:
            seen += 1
            if seen > MAX_ENTRIES:
                found.others.append((current, f"more than {MAX_ENTRIES} entries: the rest unread"))
                stack.clear()
                break
            path = entry.path
            try:
                mode = entry.stat(follow_symlinks=False).st_mode
            except OSError as err:
                found.others.append((path, f"cannot be read ({err.strerror})"))
                continue
            if os.path.abspath(path) in mine or _is_lock_of(path, mine):
                found.others.append((path, "written by this grading run (its gradebook)"))
                continue
            if is_handin_name(entry.name):
                found.handins.append(path)
                continue
            found.others.append((path, not_a_handin(entry.name, mode)))
            if stat.S_ISDIR(mode) and entry.name.lower() not in _SKIPPED:
                stack.append(path)
    found.handins.sort()
    found.others.sort()
    return found


def _is_lock_of(path: str, mine: set[str]) -> bool:
    """A lock or staging file the run keeps beside one of its own outputs."""
    name = os.path.basename(path)
    parent = os.path.dirname(os.path.abspath(path))
    return any(
        os.path.dirname(p) == parent and name.startswith(f".{os.path.basename(p)}.") for p in mine
    )


def added_since(before: Survey, after: Survey) -> list[tuple[str, str]]:
    """What ``after`` holds that ``before`` did not: the entries added during a run.

    Parameters
    ----------
    before, after : Survey
        Two surveys of one folder, at the start and at the end of a run.

    Returns
    -------
    list of (str, str)
        Each new entry and why it is not graded.

    Examples
    --------
    >>> from uio_teach.grading.survey import Survey, added_since
    >>> added_since(Survey("f", ["f/a.ipynb"]), Survey("f", ["f/a.ipynb", "f/b.ipynb"]))
    [('f/b.ipynb', 'added during the grading run: not graded (grade again with --resume)')]
    """
    known = set(before.handins) | {p for p, _ in before.others}
    added = [
        (p, "added during the grading run: not graded (grade again with --resume)")
        for p in after.handins
        if p not in known
    ]
    added += [
        (p, f"added during the grading run: {why}") for p, why in after.others if p not in known
    ]
    return sorted(added)
