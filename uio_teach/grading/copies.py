"""Copies between groups: a notebook's code, normalised, compared statement by statement.

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

:func:`statements` goes further, for near-copies: the code of all cells as
one program (cell boundaries do not count), imports resolved and dropped
(``np.dot(a, b)``, ``a.dot(b)`` and ``a @ b`` are one product; numpy's and
scipy's ``pinv`` one pseudo-inverse), numbers folded and written one way
(``1.0`` and ``1``, ``0.5`` and ``1/2``), dead code dropped (``if False:``
blocks, variables never read, ``x = None`` placeholders, bare ``print`` and
display lines), every name of its own written alike, and each statement
taken on its own, in any order. :func:`similarity` compares two such
multisets once the code the course gives every group (``given``: the lab's
own cells) is set aside, so an untouched template is never a copy of another.

What it cannot see: a copy rewritten with other algorithms or other
statements (a loop for a vectorised line, another but equal formula), code
moved into functions of different shapes, or work shared as ideas rather
than as code. A similarity is a reason to look, never a verdict.

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
import copy
import hashlib
import io
import tokenize
from collections import Counter
from collections.abc import Iterable, Sequence
from typing import Any

__all__ = [
    "normalised_code",
    "fingerprint",
    "statements",
    "similarity",
    "SIMILAR",
    "MIN_STATEMENTS",
]

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


# near-copies ----------------------------------------------------------------------------------

SIMILAR = 0.8
"""Two hand-ins with at least this share of their own statements alike are "check by hand"."""
MIN_STATEMENTS = 3
"""Hand-ins with fewer statements of their own than this are not compared (too little to say)."""

# calls that compute the same thing, by the module path they resolve to
_SAME_CALL = {
    "numpy.linalg.pinv": "pinv",
    "scipy.linalg.pinv": "pinv",
    "numpy.linalg.inv": "inv",
    "scipy.linalg.inv": "inv",
    "numpy.linalg.solve": "solve",
    "scipy.linalg.solve": "solve",
    "numpy.linalg.matrix_rank": "matrix_rank",
    "numpy.linalg.eigvals": "eigvals",
    "scipy.linalg.eigvals": "eigvals",
    "numpy.array": "array",
    "numpy.asarray": "array",
    "numpy.identity": "numpy.eye",
}
_PRODUCTS = {"numpy.dot", "numpy.matmul"}
_SHOWN = {"print", "display", "pprint"}


def _imports(trees: Iterable[ast.AST]) -> dict[str, str]:
    """Name bound by an import -> the module path it stands for."""
    found: dict[str, str] = {}
    for tree in trees:
        for node in ast.walk(tree):
            if isinstance(node, ast.Import):
                for alias in node.names:
                    if alias.asname:
                        found[alias.asname] = alias.name
                    else:
                        root = alias.name.split(".")[0]
                        found[root] = root
            elif isinstance(node, ast.ImportFrom) and node.module and not node.level:
                for alias in node.names:
                    found[alias.asname or alias.name] = f"{node.module}.{alias.name}"
    return found


def _dotted(node: ast.AST, imports: dict[str, str]) -> str | None:
    parts = []
    while isinstance(node, ast.Attribute):
        parts.append(node.attr)
        node = node.value
    if isinstance(node, ast.Name) and node.id in imports:
        return ".".join([imports[node.id], *reversed(parts)])
    return None


def _number(node: ast.AST) -> complex | float | None:
    if isinstance(node, ast.Constant) and isinstance(node.value, (int, float, complex)):
        if not isinstance(node.value, bool):
            return node.value
    return None


class _Canon(ast.NodeTransformer):
    """Imports resolved and dropped, equal calls written one way, numbers folded, dead code
    and display lines dropped."""

    def __init__(self, imports: dict[str, str]) -> None:
        self.imports = imports

    def visit_Import(self, node: ast.AST) -> None:
        return None

    visit_ImportFrom = visit_Import  # noqa: N815

    def visit_Attribute(self, node: ast.Attribute) -> ast.AST:
        dotted = _dotted(node, self.imports)
        if dotted is not None:
            return ast.Name(_SAME_CALL.get(dotted, dotted), ast.Load())
        return self.generic_visit(node)

    def visit_Name(self, node: ast.Name) -> ast.AST:
        if isinstance(node.ctx, ast.Load) and node.id in self.imports:
            dotted = self.imports[node.id]
            return ast.Name(_SAME_CALL.get(dotted, dotted), ast.Load())
        return node

    def visit_Call(self, node: ast.Call) -> ast.AST:
        self.generic_visit(node)
        func = node.func
        name = func.id if isinstance(func, ast.Name) else None
        if len(node.args) == 2 and not node.keywords and name in _PRODUCTS:
            return ast.BinOp(node.args[0], ast.MatMult(), node.args[1])
        if (
            isinstance(func, ast.Attribute)
            and func.attr == "dot"
            and len(node.args) == 1
            and not node.keywords
        ):
            return ast.BinOp(func.value, ast.MatMult(), node.args[0])
        return node

    def visit_BinOp(self, node: ast.BinOp) -> ast.AST:
        self.generic_visit(node)
        left, right = _number(node.left), _number(node.right)
        if left is not None and right is not None:
            try:
                value = {
                    ast.Add: lambda a, b: a + b,
                    ast.Sub: lambda a, b: a - b,
                    ast.Mult: lambda a, b: a * b,
                    ast.Div: lambda a, b: a / b,
                }[type(node.op)](left, right)
            except (KeyError, ZeroDivisionError, OverflowError):
                return node
            return ast.Constant(value)
        return node

    def visit_UnaryOp(self, node: ast.UnaryOp) -> ast.AST:
        self.generic_visit(node)
        value = _number(node.operand)
        if value is not None and isinstance(node.op, (ast.USub, ast.UAdd)):
            return ast.Constant(-value if isinstance(node.op, ast.USub) else value)
        return node

    def visit_Constant(self, node: ast.Constant) -> ast.AST:
        value = _number(node)
        if isinstance(value, (int, float)) and abs(value) < 1e300:
            return ast.Constant(float(value))
        return node

    def visit_If(self, node: ast.If) -> Any:
        self.generic_visit(node)
        if isinstance(node.test, ast.Constant):  # if False: / if 0: / if True:
            return (node.body if node.test.value else node.orelse) or None
        return node

    def visit_While(self, node: ast.While) -> Any:
        self.generic_visit(node)
        if isinstance(node.test, ast.Constant) and not node.test.value:
            return node.orelse or None
        return node

    def visit_Expr(self, node: ast.Expr) -> Any:
        self.generic_visit(node)
        value = node.value
        if isinstance(value, (ast.Name, ast.Attribute, ast.Constant, ast.Subscript)):
            return None  # a value shown, or a docstring
        if isinstance(value, ast.Call) and isinstance(value.func, ast.Name):
            if value.func.id in _SHOWN:
                return None
        return node


def _units(tree: ast.Module) -> list[str]:
    """Every statement at any depth as a text of its own (a compound one by its header)."""
    out = []
    for node in ast.walk(tree):
        if not isinstance(node, ast.stmt):
            continue
        shell = copy.copy(node)
        for name in ("body", "orelse", "finalbody", "handlers"):
            if isinstance(getattr(shell, name, None), list):
                setattr(shell, name, [ast.Pass()] if name == "body" else [])
        try:
            out.append(ast.unparse(shell))
        except (ValueError, RecursionError, AttributeError):
            out.append(ast.dump(shell))
    return out


def statements(sources: Sequence[str], *, keep: Iterable[str] = ()) -> Counter[str]:
    """A notebook's code as a multiset of normalised statements (see the module's text).

    Parameters
    ----------
    sources : sequence of str
        The code cells, in order (their boundaries do not count).
    keep : iterable of str
        Names written as they are (the lab's answer variables); every other name the code
        binds is written ``_``.

    Returns
    -------
    collections.Counter
        Statement text -> how many times it occurs.

    Examples
    --------
    >>> from uio_teach.grading.copies import statements
    >>> a = ["import numpy as np\\nH = np.dot(E, np.linalg.pinv(C @ E))\\nk = 1.0\\nprint(k)"]
    >>> b = ["from scipy.linalg import pinv\\nk = 2/2\\nif False:\\n    x = 3"]
    >>> b.append("H = E @ pinv(C @ E)")  # another cell
    >>> statements(a, keep={"H"}) == statements(b, keep={"H"})
    True
    """
    trees = []
    texts: Counter[str] = Counter()
    for source in sources:
        lines = [x for x in source.splitlines() if not x.lstrip().startswith(("%", "!"))]
        try:
            trees.append(ast.parse("\n".join(lines)))
        except (SyntaxError, ValueError, RecursionError, MemoryError):
            if _text(source):
                texts[_text(source)] += 1
    imports = _imports(trees)
    body: list[ast.stmt] = []
    canon = _Canon(imports)
    for tree in trees:
        try:
            body += canon.visit(tree).body
        except RecursionError:
            continue
    module = ast.Module(body=body, type_ignores=[])
    keep = set(keep) | {"PARAMS"}
    read = {
        n.id for n in ast.walk(module) if isinstance(n, ast.Name) and isinstance(n.ctx, ast.Load)
    }

    def unused(stmt: ast.stmt) -> bool:
        if isinstance(stmt, ast.Assign):
            names = [t.id for t in stmt.targets if isinstance(t, ast.Name)]
            if len(names) == len(stmt.targets) and not (set(names) & (read | keep)):
                return True  # a variable never read
            if isinstance(stmt.value, ast.Constant) and stmt.value.value is None:
                return True  # a placeholder (a TODO cell's ``x = None``)
        return False

    module.body = [s for s in module.body if not unused(s)]
    bound = _bound([module]) - keep - _BUILTINS
    for node in ast.walk(module):
        if isinstance(node, ast.Name) and node.id in bound:
            node.id = "_"
        elif isinstance(node, ast.arg) and node.arg in bound:
            node.arg, node.annotation = "_", None
        elif isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef, ast.ClassDef)):
            node.name = "_" if node.name in bound else node.name
    texts.update(u for u in _units(module) if u != "pass")
    return texts


def similarity(
    a: Counter[str], b: Counter[str], given: Counter[str] | None = None
) -> tuple[float, int]:
    """How alike two hand-ins' own statements are, once the code every group was given is out.

    Parameters
    ----------
    a, b : collections.Counter
        :func:`statements` of each.
    given : collections.Counter, optional
        :func:`statements` of the code the course gives every group (the lab's cells).

    Returns
    -------
    (float, int)
        The share of statements the two have alike (0 to 1: the multisets' intersection over
        their union), and the smaller number of own statements of the two (below
        :data:`MIN_STATEMENTS` the share says nothing).

    Examples
    --------
    >>> from collections import Counter
    >>> from uio_teach.grading.copies import similarity
    >>> similarity(Counter("abcd"), Counter("abce"), Counter("a"))
    (0.5, 3)
    """
    given = given or Counter()
    own_a, own_b = a - given, b - given
    union = sum((own_a | own_b).values())
    smaller = min(sum(own_a.values()), sum(own_b.values()))
    if not union:
        return 0.0, 0
    return sum((own_a & own_b).values()) / union, smaller
