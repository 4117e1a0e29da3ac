"""The type stubs (sagcal/__init__.pyi) describe the module as it is: every
name exists, functions have the runtime's parameters and defaults, classes
the runtime's attributes, and everything public has a docstring."""

import ast
import inspect
from pathlib import Path

import sagcal

STUBS = ast.parse((Path(sagcal.__file__).parent / "__init__.pyi").read_text())


def stub_functions():
    return {n.name: n for n in STUBS.body if isinstance(n, ast.FunctionDef)}


def stub_classes():
    return {n.name: n for n in STUBS.body if isinstance(n, ast.ClassDef)}


def test_every_public_name_has_a_stub_and_every_stub_a_name():
    stubbed = set(stub_functions()) | set(stub_classes())
    stubbed |= {t.id for n in STUBS.body if isinstance(n, ast.AnnAssign) for t in [n.target]}
    public = {name for name in sagcal.__all__}
    assert public <= stubbed, public - stubbed
    for name in stub_functions().keys() | stub_classes().keys():
        assert name in public, name


def test_function_stubs_have_the_runtime_parameters():
    for name, stub in stub_functions().items():
        runtime = inspect.signature(getattr(sagcal, name))
        args = stub.args
        stubbed = [a.arg for a in args.posonlyargs + args.args] + [a.arg for a in args.kwonlyargs]
        assert stubbed == list(runtime.parameters), name
        defaults = dict(zip([a.arg for a in args.args][len(args.args) - len(args.defaults) :], args.defaults))
        defaults.update({a.arg: d for a, d in zip(args.kwonlyargs, args.kw_defaults) if d is not None})
        for parameter in runtime.parameters.values():
            if parameter.default is inspect.Parameter.empty:
                assert parameter.name not in defaults, (name, parameter.name)
                continue
            stubbed_default = ast.literal_eval(defaults[parameter.name])
            if isinstance(stubbed_default, tuple):  # `()` in the stub, a list at run time
                stubbed_default = list(stubbed_default)
            assert stubbed_default == parameter.default, (name, parameter.name)
        kinds = [p.kind for p in runtime.parameters.values()]
        keyword_only = sum(k is inspect.Parameter.KEYWORD_ONLY for k in kinds)
        assert keyword_only == len(args.kwonlyargs), name


def test_class_stubs_have_the_runtime_attributes_and_docstrings():
    for name, stub in stub_classes().items():
        cls = getattr(sagcal, name)
        assert cls.__doc__, name
        if issubclass(cls, BaseException):
            continue  # an exception's attributes are Python's
        members = {n.name for n in stub.body if isinstance(n, ast.FunctionDef)}
        members |= {n.target.id for n in stub.body if isinstance(n, ast.AnnAssign)}
        runtime = {m for m in dir(cls) if not m.startswith("_")}
        assert {m for m in members if not m.startswith("_")} == runtime, name
        for member in runtime:
            assert getattr(cls, member).__doc__, f"{name}.{member} has no docstring"


def test_functions_have_docstrings_naming_the_command():
    for name in stub_functions():
        doc = getattr(sagcal, name).__doc__
        assert doc and len(doc) > 80, name
    for name in ["calibrate", "diagnose", "localize", "plan", "simulate"]:
        assert f"sagcal {name}" in " ".join(getattr(sagcal, name).__doc__.split()), name
