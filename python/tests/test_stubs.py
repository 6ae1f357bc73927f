"""The type stubs of the compiled module name every function, class and method it has, and
nothing it lacks: an editor or a type checker reads railfmu/_railfmu.pyi, not the module."""

from __future__ import annotations

import ast
import inspect
from pathlib import Path

from railfmu import _railfmu

STUBS = Path(_railfmu.__file__).resolve().parent / "_railfmu.pyi"
if not STUBS.is_file():
    STUBS = Path(__file__).resolve().parents[1] / "railfmu" / "_railfmu.pyi"


def public(names) -> set:
    return {n for n in names if not n.startswith("_")}


def test_the_stubs_declare_what_the_module_has():
    tree = ast.parse(STUBS.read_text())
    stub_members = {}
    for node in tree.body:
        if isinstance(node, ast.FunctionDef):
            stub_members[node.name] = None
        elif isinstance(node, ast.ClassDef):
            stub_members[node.name] = public(n.name for n in node.body if isinstance(n, ast.FunctionDef))
    module_members = {}
    for name in public(dir(_railfmu)):
        obj = getattr(_railfmu, name)
        if inspect.isclass(obj):
            own = public(k for k in vars(obj) if not (issubclass(obj, BaseException) and k in vars(BaseException)))
            module_members[name] = own
        elif callable(obj):
            module_members[name] = None
    assert set(stub_members) == set(module_members), (
        f"in the module, not the stubs: {sorted(set(module_members) - set(stub_members))}; "
        f"in the stubs, not the module: {sorted(set(stub_members) - set(module_members))}"
    )
    for name, methods in module_members.items():
        if methods is not None and not issubclass(getattr(_railfmu, name), BaseException):
            assert methods == stub_members[name], f"{name}: module {sorted(methods)}, stubs {sorted(stub_members[name] or [])}"
