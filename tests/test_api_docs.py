"""The public API is documented: every parameter in numpydoc, runnable examples everywhere."""

import doctest
import importlib
import inspect
import pkgutil

import pytest
from numpydoc.docscrape import FunctionDoc

import uio_teach as ut

# The public modules outside ``ut.__all__``: their ``__all__`` is documented like the rest. Every
# module of ``uio_teach.worked`` (one per worked example) is one of them, found, not listed.
WORKED_MODULES = tuple(f"worked.{info.name}" for info in pkgutil.iter_modules(ut.worked.__path__))
SUBPACKAGE_API = (
    "experiments",
    "lab_params",
    "worked",
    *WORKED_MODULES,
    "luenberger",
    "figure_text",
    "colour_vision",
    "explorers",
    "explorers.widgets",
    "explorers.static",
    "instructor.cli",
    "instructor.config",
    "instructor.figures",
    "instructor.output",
    "folders",
    "grading.grade",
    "grading.rosters",
    "grading.merge",
    "instructor.labs",
    "instructor.book",
)


def public_callables():
    seen = {}
    modules = [ut] + [getattr(ut, m) for m in ("examples", "linalg", "signals")]
    modules += [importlib.import_module(f"uio_teach.{m}") for m in SUBPACKAGE_API]
    for mod in modules:
        for name in getattr(mod, "__all__", []):
            obj = getattr(mod, name)
            if (inspect.isfunction(obj) or inspect.isclass(obj)) and not issubclass(
                obj if inspect.isclass(obj) else type, BaseException
            ):
                seen[f"{mod.__name__}.{name}"] = obj
    for name in getattr(ut, "__all__", []):
        obj = getattr(ut, name)
        if inspect.ismodule(obj):
            for sub in getattr(obj, "__all__", []):
                o = getattr(obj, sub)
                if inspect.isfunction(o):
                    seen[f"{obj.__name__}.{sub}"] = o
    return seen


PUBLIC = public_callables()


@pytest.mark.parametrize("qualname", sorted(k for k, v in PUBLIC.items() if inspect.isfunction(v)))
def test_every_parameter_is_documented(qualname):
    func = PUBLIC[qualname]
    doc = FunctionDoc(func)
    documented = set()
    for param in doc["Parameters"]:
        for part in param.name.split(","):
            documented.add(part.strip().lstrip("*"))
    sig = inspect.signature(func)
    missing = [
        p
        for p in sig.parameters
        if p not in documented and p not in ("self", "cls") and not p.startswith("_")
    ]
    assert not missing, f"{qualname}: parameters not documented: {missing}"
    assert doc["Summary"], f"{qualname} has no summary line"


@pytest.mark.parametrize("qualname", sorted(PUBLIC))
def test_every_public_name_has_examples(qualname):
    obj = PUBLIC[qualname]
    text = inspect.getdoc(obj) or ""
    assert ">>>" in text, f"{qualname} has no runnable example in its docstring"


# Modules whose docstring examples take long (explorers built, lab notebooks written, figures
# drawn): also `slow`.
SLOW_DOCTESTS = {
    "uio_teach.explorers._drag",
    "uio_teach.explorers._figure",
    "uio_teach.explorers.widgets",
    "uio_teach.explorers.static",
    "uio_teach.instructor.labs",
    "uio_teach.instructor.figures",
}


# Modules whose docstring examples start a process: the sandbox's probe runs Python (and the
# package's notebook runner) inside bubblewrap.
PROCESS_DOCTESTS = {"uio_teach.grading.sandbox": ("subprocess", "kernel")}


def _modules():
    names = ["uio_teach"]
    for info in pkgutil.walk_packages(ut.__path__, prefix="uio_teach."):
        if not info.name.endswith("__main__"):
            names.append(info.name)
    params = []
    for name in names:
        marks = [pytest.mark.slow] if name in SLOW_DOCTESTS else []
        marks += [getattr(pytest.mark, m) for m in PROCESS_DOCTESTS.get(name, ())]
        params.append(pytest.param(name, marks=marks))
    return params


@pytest.mark.doctest
@pytest.mark.parametrize("modname", _modules())
def test_docstring_examples_run(modname):
    mod = importlib.import_module(modname)
    result = doctest.testmod(mod, optionflags=doctest.ELLIPSIS | doctest.NORMALIZE_WHITESPACE)
    assert result.failed == 0, f"{result.failed} docstring example(s) failed in {modname}"


def _attribute_docstrings():
    """(label, name, docstring) of every property and module-level attribute docstring."""
    import ast

    found = []
    for info in pkgutil.walk_packages(ut.__path__, prefix="uio_teach."):
        if info.name.endswith("__main__"):
            continue
        mod = importlib.import_module(info.name)
        for cname, cls in vars(mod).items():
            if inspect.isclass(cls) and cls.__module__ == info.name:
                for pname, prop in vars(cls).items():
                    if isinstance(prop, property) and prop.__doc__:
                        found.append((f"{info.name}.{cname}.{pname}", pname, prop.__doc__))
        for node in ast.walk(ast.parse(inspect.getsource(mod))):
            body = getattr(node, "body", None)
            if not isinstance(body, list):
                continue
            for stmt, doc in zip(body, body[1:], strict=False):
                target = (
                    getattr(stmt, "target", None) or (getattr(stmt, "targets", None) or [None])[0]
                )
                if (
                    isinstance(stmt, ast.Assign | ast.AnnAssign)
                    and isinstance(target, ast.Name)
                    and isinstance(doc, ast.Expr)
                    and isinstance(doc.value, ast.Constant)
                    and isinstance(doc.value.value, str)
                ):
                    found.append((f"{info.name}.{target.id}", target.id, doc.value.value))
    return found


def test_no_attribute_docstring_renders_as_a_type():
    """Napoleon reads a property's or constant's first line ``X: text`` as the type ``X``: the
    API page would print "text" and then "Type: X" (half a formula). No first line may do so."""
    from sphinx.ext.napoleon import Config
    from sphinx.ext.napoleon.docstring import NumpyDocstring

    config = Config(napoleon_use_ivar=False)
    docs = _attribute_docstrings()
    assert len(docs) > 50  # the properties of the observers and every tolerance are among them
    typed = [
        label
        for label, name, doc in docs
        if ":type:"
        in str(NumpyDocstring(inspect.cleandoc(doc), config, what="attribute", name=name))
    ]
    assert not typed, f"first lines read as a type on the API page: {typed}"
