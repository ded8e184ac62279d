"""The installed package: the built abi3 wheel (not the source tree), stubs covering every
public name of the compiled module, docstrings with units."""

from __future__ import annotations

import ast
import inspect
from pathlib import Path

import tissuesim
import tissuesim._tissuesim as ext
from conftest import ROOT

STUB = Path(tissuesim.__file__).with_name("_tissuesim.pyi")


def test_the_import_is_the_installed_abi3_wheel():
    installed = Path(tissuesim.__file__).resolve()
    assert ROOT / "python" not in installed.parents, f"imported from the source tree: {installed}"
    assert "site-packages" in installed.parts
    assert ".abi3." in Path(ext.__file__).name
    assert STUB.is_file() and STUB.with_name("py.typed").is_file()


def stub_names() -> dict[str, set[str]]:
    """Top-level names of the stub, and for each class the names it declares."""
    tree = ast.parse(STUB.read_text())
    names: dict[str, set[str]] = {"": set()}
    for node in tree.body:
        if isinstance(node, ast.ClassDef):
            names[""].add(node.name)
            members = set()
            for item in node.body:
                if isinstance(item, (ast.FunctionDef, ast.AsyncFunctionDef)):
                    members.add(item.name)
                elif isinstance(item, ast.AnnAssign) and isinstance(item.target, ast.Name):
                    members.add(item.target.id)
                elif isinstance(item, ast.Assign):
                    members.update(t.id for t in item.targets if isinstance(t, ast.Name))
            names[node.name] = members
        elif isinstance(node, (ast.FunctionDef, ast.AnnAssign, ast.Assign)):
            if isinstance(node, ast.FunctionDef):
                names[""].add(node.name)
            elif isinstance(node, ast.AnnAssign):
                names[""].add(node.target.id)
            else:
                names[""].update(t.id for t in node.targets if isinstance(t, ast.Name))
    return names


def test_the_stubs_declare_every_public_name():
    stubs = stub_names()
    missing = []
    for name, obj in vars(ext).items():
        if name.startswith("__") and name != "__version__":
            continue
        if name not in stubs[""]:
            missing.append(name)
            continue
        if inspect.isclass(obj) and not issubclass(obj, BaseException):
            own = {m for m in vars(obj) if not m.startswith("_") and m not in ("value", "name")}
            missing += [f"{name}.{m}" for m in sorted(own - stubs[name])]
    assert not missing, f"not in {STUB.name}: {missing}"


def test_the_package_exports_the_rust_names():
    for name in [
        "World", "Settings", "BodyOptions", "Material", "ToolShape", "Pose", "ToolOptions",
        "GraspOptions", "NeedleOptions", "Blade", "WorldState", "BodyModel", "ContactMode",
        "DivergenceLimits",
    ]:  # fmt: skip
        assert getattr(tissuesim, name) is getattr(ext, name)
    for name in ["load", "default_organ", "lattice_box", "read_obj", "write_vtk", "write_vtu"]:
        assert callable(getattr(tissuesim.mesh, name))
    assert callable(tissuesim.render.read_obj)


def test_world_methods_have_docstrings_and_the_long_ones_say_so():
    for name, member in vars(tissuesim.World).items():
        if not name.startswith("_"):
            assert member.__doc__, f"World.{name} has no docstring"
    assert "GIL released" in tissuesim.World.step.__doc__
    assert "(s)" in tissuesim.World.time.__doc__


def test_option_fields_document_their_units_at_run_time():
    for cls in (
        tissuesim.Settings,
        tissuesim.Material,
        tissuesim.BodyOptions,
        tissuesim.ToolOptions,
        tissuesim.GraspOptions,
        tissuesim.NeedleOptions,
        tissuesim.DivergenceLimits,
    ):
        for name, member in vars(cls).items():
            if isinstance(member, type(tissuesim.Settings.dt)):
                assert member.__doc__, f"{cls.__name__}.{name} has no docstring"
    assert "(s)" in tissuesim.Settings.dt.__doc__
    assert "(Pa)" in tissuesim.Material.youngs_modulus.__doc__
