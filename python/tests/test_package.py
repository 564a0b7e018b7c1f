"""The package's surface: what the type stubs declare is what the module has, documented."""

import ast
import inspect
from pathlib import Path

import caustica

STUB = Path(caustica.__file__).with_name("_caustica.pyi")


def stub_names():
    tree = ast.parse(STUB.read_text())
    top, members = set(), {}
    # Keyword-option types exist for type checkers only.
    typed_dicts = {"TypedDict"}
    for node in tree.body:
        if isinstance(node, ast.ClassDef) and any(getattr(b, "id", None) in typed_dicts for b in node.bases):
            typed_dicts.add(node.name)
            continue
        if isinstance(node, (ast.FunctionDef, ast.ClassDef)):
            top.add(node.name)
        elif isinstance(node, ast.AnnAssign):
            top.add(node.target.id)
        if isinstance(node, ast.ClassDef):
            members[node.name] = {
                n.name if isinstance(n, ast.FunctionDef) else n.target.id
                for n in node.body
                if isinstance(n, (ast.FunctionDef, ast.AnnAssign))
            }
    return top, members


def test_the_stubs_declare_exactly_the_public_names():
    top, members = stub_names()
    native = caustica._caustica
    public = {n for n in dir(native) if not n.startswith("_") or n == "__version__"}
    assert top == public
    assert set(caustica.__all__) == public
    for cls, declared in members.items():
        if issubclass(getattr(native, cls), BaseException):
            continue  # their attributes are set on each instance raised
        runtime = vars(getattr(native, cls))
        assert {n for n in declared if not n.startswith("_")} == {n for n in runtime if not n.startswith("_")}, cls
        # pyo3 makes the constructor __new__; the stubs spell it __init__ as Python classes do.
        assert all(n in runtime or (n == "__init__" and "__new__" in runtime) for n in declared), cls


def test_every_public_function_class_and_method_has_a_docstring():
    for name in caustica.__all__:
        value = getattr(caustica, name)
        if callable(value):
            assert inspect.getdoc(value), name
        if isinstance(value, type) and not issubclass(value, BaseException):
            for member, attribute in vars(value).items():
                if not member.startswith("_"):
                    assert inspect.getdoc(attribute), f"{name}.{member}"


def test_the_package_is_typed():
    assert Path(caustica.__file__).with_name("py.typed").is_file()
