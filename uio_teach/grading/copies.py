"""Copies between groups: a notebook's code, normalised, as one fingerprint.

Two hand-ins are copies when their code is the same once what a copier
changes without changing the computation is set aside: comments, blank lines,
docstrings, formatting (spaces, line breaks, brackets, quotes) and the names
of their own variables, functions and imports. :func:`normalised_code` parses
each code cell, drops the docstrings, renames every name the notebook binds
(except the lab's answer variables, whose names the lab fixes, and
``PARAMS``) to ``_v0``, ``_v1``, ... in the order they first appear, and writes
the tree back in one layout; :func:`fingerprint` hashes that. The cells the
course gives every group alike (``parameters``, ``check`` and the grader's own)
are left out. A cell that is not Python (a typo, a magic) is compared as its
text with comments and spacing removed.

Examples
--------
>>> from uio_teach.grading.copies import normalised_code
>>> a = ["x = E @ pinv(C @ E)  # the gain\\nH = x", "def f(a):\\n    return a + 1"]
>>> b = ["gain = E@pinv(C@E)\\n\\nH = gain", "def g(b):\\n    '''Add one.'''\\n    return (b+1)"]
>>> normalised_code(a, keep={"H"}) == normalised_code(b, keep={"H"})
True
"""

from __future__ import annotations

import ast
import builtins
import hashlib
import io
import tokenize
from collections.abc import Iterable, Sequence

__all__ = ["normalised_code", "fingerprint"]

_BUILTINS = frozenset(dir(builtins))


class _Renamer(ast.NodeTransformer):
    """Rename the names a notebook binds, in order of first appearance; drop docstrings."""

    def __init__(self, bound: set[str]) -> None:
        self.bound = bound
        self.names: dict[str, str] = {}

    def _new(self, name: str) -> str:
        if name not in self.bound:
            return name
        return self.names.setdefault(name, f"_v{len(self.names)}")

    def visit_Name(self, node: ast.Name) -> ast.AST:
        node.id = self._new(node.id)
        return node

    def visit_arg(self, node: ast.arg) -> ast.AST:
        node.arg = self._new(node.arg)
        node.annotation = None
        return node

    def visit_alias(self, node: ast.alias) -> ast.AST:
        if node.asname:
            node.asname = self._new(node.asname)
        elif "." not in node.name and node.name in self.bound:
            node.asname = self._new(node.name)
        return node

    def _body(self, node: ast.AST) -> ast.AST:
        body = getattr(node, "body", None)
        if (
            isinstance(body, list)
            and body
            and isinstance(body[0], ast.Expr)
            and isinstance(body[0].value, ast.Constant)
            and isinstance(body[0].value.value, str)
        ):
            node.body = body[1:] or [ast.Pass()]
        if isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef, ast.ClassDef)):
            node.name = self._new(node.name)
        if isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef)):
            node.returns = None
        return self.generic_visit(node)

    visit_FunctionDef = visit_AsyncFunctionDef = visit_ClassDef = _body  # noqa: N815
    visit_Module = _body  # noqa: N815

    def visit_Global(self, node: ast.Global) -> ast.AST:
        node.names = [self._new(n) for n in node.names]
        return node

    visit_Nonlocal = visit_Global  # noqa: N815


def _bound(trees: Iterable[ast.AST]) -> set[str]:
    names: set[str] = set()
    for tree in trees:
        for node in ast.walk(tree):
            if isinstance(node, ast.Name) and isinstance(node.ctx, (ast.Store, ast.Del)):
                names.add(node.id)
            elif isinstance(node, ast.arg):
                names.add(node.arg)
            elif isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef, ast.ClassDef)):
                names.add(node.name)
            elif isinstance(node, ast.alias):
                names.add(node.asname or node.name.split(".")[0])
    return names


def _text(source: str) -> str:
    """A cell that is not Python: its tokens without comments and spacing, else its words."""
    try:
        tokens = tokenize.generate_tokens(io.StringIO(source).readline)
        kept = [
            t.string
            for t in tokens
            if t.type not in (tokenize.COMMENT, tokenize.NL, tokenize.NEWLINE, tokenize.INDENT)
            and t.type != tokenize.DEDENT
        ]
        return "".join(kept)
    except (tokenize.TokenError, SyntaxError, IndentationError):
        lines = [line.split("#", 1)[0] for line in source.splitlines()]
        return "".join("".join(lines).split())


def normalised_code(sources: Sequence[str], *, keep: Iterable[str] = ()) -> str:
    """The code of a notebook's cells with what a copier changes for free set aside.

    Parameters
    ----------
    sources : sequence of str
        The code cells, in order.
    keep : iterable of str
        Names never renamed (the lab's answer variables).

    Returns
    -------
    str
    """
    parsed: list[ast.AST | str] = []
    for source in sources:
        lines = [x for x in source.splitlines() if not x.lstrip().startswith(("%", "!"))]
        try:
            parsed.append(ast.parse("\n".join(lines)))
        except (SyntaxError, ValueError, RecursionError, MemoryError):
            parsed.append(_text(source))
    trees = [p for p in parsed if not isinstance(p, str)]
    bound = _bound(trees) - set(keep) - {"PARAMS"} - _BUILTINS
    renamer = _Renamer(bound)
    out = []
    for item in parsed:
        if isinstance(item, str):
            text = item
        else:
            try:
                text = ast.unparse(renamer.visit(item))
            except (RecursionError, ValueError):
                text = ast.dump(item)
        if text.strip() and text.strip() != "pass":
            out.append(text)
    return "\n\x00".join(out)


def fingerprint(sources: Sequence[str], *, keep: Iterable[str] = ()) -> str:
    """The SHA-256 of :func:`normalised_code` ("" for a notebook with no code of its own).

    Parameters
    ----------
    sources : sequence of str
    keep : iterable of str

    Returns
    -------
    str

    Examples
    --------
    >>> from uio_teach.grading.copies import fingerprint
    >>> fingerprint(["y = 2 * x  # double"]) == fingerprint(["z=2*x"]), fingerprint([""])
    (True, '')
    """
    code = normalised_code(sources, keep=keep)
    return hashlib.sha256(code.encode("utf-8", "surrogatepass")).hexdigest() if code else ""
