"""The package itself: the type stubs describe the extension module, the public names exist,
the notebook-style example runs."""
import ast
import inspect
import os
import runpy
from pathlib import Path

import moreau
from moreau import _native

PKG = Path(moreau.__file__).parent
HERE = Path(__file__).resolve().parent


def _stub_names(path: Path):
    tree = ast.parse(path.read_text())
    top = {n.name for n in tree.body if isinstance(n, (ast.FunctionDef, ast.ClassDef))}
    top |= {t.id for n in tree.body if isinstance(n, ast.AnnAssign) for t in [n.target] if isinstance(t, ast.Name)}
    cls = {
        n.name: {m.name for m in n.body if isinstance(m, ast.FunctionDef)}
        for n in tree.body
        if isinstance(n, ast.ClassDef)
    }
    return top, cls


def test_stubs_match_the_extension_module():
    top, cls = _stub_names(PKG / "_native.pyi")
    public = {n for n in dir(_native) if not n.startswith("_")} | {"__version__"}
    assert top - {"_Path", "_Model"} == public
    members = {n for n in dir(_native.System) if not n.startswith("_")}
    assert cls["System"] == members
    for name in ("theta", "simulate", "periodic", "check", "diagnose", "sweep"):
        stub = next(n for n in ast.parse((PKG / "_native.pyi").read_text()).body if getattr(n, "name", None) == name)
        stub_args = [a.arg for a in stub.args.args + stub.args.kwonlyargs]
        sig = inspect.signature(getattr(_native, name))
        assert stub_args == list(sig.parameters), name


def test_public_api_and_typing_marker():
    for name in moreau.__all__:
        assert hasattr(moreau, name), name
    assert (PKG / "py.typed").exists()
    assert issubclass(moreau.MoreauError, ValueError)
    assert moreau.__version__
    # every public function is annotated
    for name in ("theta", "simulate", "periodic", "check", "diagnose", "sweep", "load", "set_allow_large"):
        sig = inspect.signature(getattr(moreau, name))
        assert sig.return_annotation is not inspect.Signature.empty, name


def test_allow_large_is_the_cli_flag():
    try:
        moreau.simulate(moreau.load(HERE.parents[1] / "examples" / "worked-example.toml"), t_end=1e7, dt=1e-3)
    except moreau.MoreauError as e:
        assert "exceeds the limit" in str(e) and "--allow-large" in str(e)
    else:
        raise AssertionError("no budget error")
    moreau.set_allow_large(True)
    try:
        assert _native.allow_large()
    finally:
        moreau.set_allow_large(False)


def test_notebook_example_runs(tmp_path, capsys, monkeypatch):
    monkeypatch.setenv("MOREAU_EXAMPLE_OUT", str(tmp_path))
    monkeypatch.setenv("MPLBACKEND", "Agg")
    runpy.run_path(str(HERE.parent / "examples" / "worked_example.py"), run_name="__main__")
    out = capsys.readouterr().out
    assert "theta = -0.017232  verified: True" in out
    assert "error: key `plant.B`" in out
