"""The type stubs name exactly what the module has: every public name, class member and the
special methods they promise, so that an editor's completion is the module's truth."""

import ast
import os

import semsegmap as ssm
from semsegmap import _semsegmap

STUB = os.path.join(os.path.dirname(ssm.__file__), "_semsegmap.pyi")


def stub_tree():
    with open(STUB) as f:
        return ast.parse(f.read())


def names_in(body):
    names = set()
    for node in body:
        if isinstance(node, (ast.FunctionDef, ast.ClassDef)):
            names.add(node.name)
        elif isinstance(node, ast.AnnAssign) and isinstance(node.target, ast.Name):
            names.add(node.target.id)
    return names


def public(names):
    return {n for n in names if not n.startswith("_")}


def test_the_stubs_name_every_public_name_and_no_other():
    stubbed = public(names_in(stub_tree().body))
    if not ssm.WITH_SIM:
        stubbed.discard("Simulator")  # in the stubs, only in a build with the simulator
    assert stubbed == public(dir(_semsegmap))


def test_the_stubs_name_every_member_of_every_class():
    for node in stub_tree().body:
        if not isinstance(node, ast.ClassDef) or not hasattr(_semsegmap, node.name):
            continue
        cls = getattr(_semsegmap, node.name)
        stubbed = names_in(node.body)
        assert public(stubbed) == public(vars(cls)), node.name
        for special in stubbed - public(stubbed):
            assert hasattr(cls, special), f"{node.name}.{special}"


def test_the_package_stub_names_the_package_functions():
    with open(os.path.join(os.path.dirname(ssm.__file__), "__init__.pyi")) as f:
        stubbed = public(names_in(ast.parse(f.read()).body))
    assert stubbed == {"data_dir", "shipped_file"}
    assert all(callable(getattr(ssm, n)) for n in stubbed)
