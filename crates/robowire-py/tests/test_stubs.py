"""The type stubs (.pyi) describe exactly what the modules export: every public class, method
and parameter name, both ways, so editors complete what exists and nothing else."""

import ast
import dataclasses
import importlib
import inspect
from pathlib import Path

import pytest

import robowire

MODULES = ["zsl1", "zsl1w", "kmc", "unitree", "go2", "g1", "sim", "spline", "device", "record", "policy"]
PACKAGE = Path(robowire.__file__).parent


def stub_classes(module: str):
    """{class name: {member name: parameter names or None}} from the stub, with the members of
    stub-only base classes (``_Session``, …) folded in."""
    tree = ast.parse((PACKAGE / f"{module}.pyi").read_text())
    classes, bases = {}, {}
    for node in tree.body:
        if isinstance(node, ast.ImportFrom) and node.module and node.level == 1:
            for alias in node.names:
                if alias.name.startswith("_"):
                    other = stub_classes(node.module)
                    classes[alias.name] = other[alias.name]
        if isinstance(node, ast.ClassDef):
            members = {}
            for item in node.body:
                if isinstance(item, ast.FunctionDef):
                    args = [a.arg for a in item.args.args + item.args.kwonlyargs if a.arg not in ("self",)]
                    members.setdefault(item.name, args)
                elif isinstance(item, ast.AnnAssign) and isinstance(item.target, ast.Name):
                    members[item.target.id] = None
            classes[node.name] = members
            bases[node.name] = [b.id for b in node.bases if isinstance(b, ast.Name)]
    for name, parents in bases.items():
        for parent in parents:
            if parent in classes:
                classes[name] = {**classes[parent], **classes[name]}
    return classes


def public(names):
    return {n for n in names if not n.startswith("_")}


@pytest.mark.parametrize("module", MODULES)
def test_every_export_has_a_stub_and_every_stub_an_export(module):
    runtime = importlib.import_module(f"robowire.{module}")
    tree = ast.parse((PACKAGE / f"{module}.pyi").read_text())
    stub_names = {n.name for n in tree.body if isinstance(n, (ast.ClassDef, ast.FunctionDef))}
    stub_names |= {t.id for n in tree.body if isinstance(n, ast.AnnAssign) for t in [n.target] if isinstance(t, ast.Name)}
    assert set(runtime.__all__) <= stub_names | {"Frame"}
    assert public(stub_names) - {"Frame"} <= set(runtime.__all__)


def instance_or_class(cls):
    try:
        return cls.zeroed()  # unitree messages: their fields exist on instances
    except AttributeError:
        return cls


@pytest.mark.parametrize("module", MODULES)
def test_members_and_parameter_names_match(module):
    runtime = importlib.import_module(f"robowire.{module}")
    stubs = stub_classes(module)
    for name in runtime.__all__:
        cls = getattr(runtime, name)
        if not inspect.isclass(cls):
            continue
        stub = stubs[name]
        target = instance_or_class(cls)
        missing_in_stub = public(dir(cls)) - set(stub)
        assert not missing_in_stub, f"{module}.{name}: not in the stub: {missing_in_stub}"
        fields = {f.name for f in dataclasses.fields(cls)} if dataclasses.is_dataclass(cls) else set()
        missing_at_runtime = {m for m in public(stub) if not hasattr(target, m) and m not in fields}
        assert not missing_at_runtime, f"{module}.{name}: only in the stub: {missing_at_runtime}"
        for member, params in stub.items():
            if params is None or member.startswith("__") or not hasattr(cls, member):
                continue
            attribute = inspect.getattr_static(cls, member)
            if isinstance(attribute, property) or type(attribute).__name__ == "getset_descriptor":
                continue
            try:
                signature = inspect.signature(getattr(cls, member))
            except (TypeError, ValueError):
                continue
            names = [p for p in signature.parameters if p not in ("self", "fields", "exc", "_exc")]
            assert names == [p for p in params if p not in ("fields", "exc")], f"{module}.{name}.{member}"


def test_the_package_is_typed():
    assert (PACKAGE / "py.typed").exists()
