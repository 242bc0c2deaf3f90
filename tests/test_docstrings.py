"""Every public module, class, function, method and property of hwpts has a docstring, and no
docstring cites a document outside the repository (issue 12)."""

import importlib
import inspect
import pkgutil
import re

import pytest

import hwpts

OUTSIDE = re.compile(r"\b(BENCHMARKS|PLANT|DESIGN|STYLE)\.md\b")


def _public_objects():
    for info in pkgutil.walk_packages(hwpts.__path__, "hwpts."):
        if any(part.startswith("_") for part in info.name.split(".")[1:]):
            continue
        module = importlib.import_module(info.name)
        yield info.name, module
        for name, obj in vars(module).items():
            if name.startswith("_") or getattr(obj, "__module__", None) != module.__name__:
                continue
            if not (inspect.isclass(obj) or inspect.isfunction(obj)):
                continue
            yield f"{info.name}.{name}", obj
            if inspect.isclass(obj):
                for attr, value in vars(obj).items():
                    if attr.startswith("_"):
                        continue
                    if isinstance(value, (classmethod, staticmethod)):
                        value = value.__func__
                    if isinstance(value, property) or inspect.isfunction(value):
                        yield f"{info.name}.{name}.{attr}", value


def test_every_public_object_has_a_docstring():
    missing = [name for name, obj in _public_objects() if not (obj.__doc__ or "").strip()]
    assert not missing, f"{len(missing)} public objects without a docstring:\n" + "\n".join(missing)


def test_no_docstring_cites_a_file_outside_the_repository():
    cited = [name for name, obj in _public_objects() if OUTSIDE.search(obj.__doc__ or "")]
    assert not cited, "docstrings citing BENCHMARKS.md, PLANT.md, DESIGN.md or STYLE.md: " + ", ".join(cited)


@pytest.mark.filterwarnings("ignore")  # Sphinx's and docutils' own deprecation warnings
def test_the_docs_build_offline_without_warnings(tmp_path):
    """``make docs`` in miniature: Sphinx (the ``docs`` extra) builds the API reference and the
    guide with no warning; skipped when Sphinx is not installed (``make docs`` installs it)."""
    import pathlib

    sphinx_cmd = pytest.importorskip("sphinx.cmd.build")
    pytest.importorskip("myst_parser")
    docs = pathlib.Path(__file__).resolve().parent.parent / "docs"
    warnings = tmp_path / "warnings.txt"
    status = sphinx_cmd.build_main(["-b", "html", "-q", "-w", str(warnings), "-d", str(tmp_path / "doctrees"),
                                    str(docs), str(tmp_path / "html")])
    assert status == 0
    assert warnings.read_text().strip() == ""
    assert (tmp_path / "html" / "_autosummary" / "hwpts.identification.pwarx.html").exists()
