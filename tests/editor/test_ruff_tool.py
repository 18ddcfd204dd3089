"""Ruff as the editor runs it (server/editor/ruff_tool.py): pyflakes' findings and syntax errors
with the contract's positions and sentences, no style nags, and formatting."""

from __future__ import annotations

import pytest

from server.editor import ruff_tool


def test_undefined_names_and_unused_imports():
    found = ruff_tool.check("import os\nprint(distancia)\n")
    assert [(f.rule, f.severity, f.line, f.column, f.end_column) for f in found] == [
        ("F401", "warning", 1, 7, 9),
        ("F821", "error", 2, 6, 15),
    ]
    assert found[1].message == "Undefined name `distancia`."


def test_no_style_nags():
    assert ruff_tool.check("x=1;y =2\nif x==1 :\n  print( x,y )\nimport math\nmath.pi\n") == []


def test_a_syntax_error_is_e999_with_its_line():
    found = ruff_tool.check("x = 1\ndef broken(:\n    pass\n")
    assert found and all(f.rule == "E999" and f.severity == "error" for f in found)
    assert found[0].line == 2 and found[0].message.startswith("Syntax error: ")


def test_ruff_ignores_configuration_near_the_server(tmp_path, monkeypatch):
    """--isolated: a pyproject.toml in the working folder does not change what is reported."""
    (tmp_path / "pyproject.toml").write_text('[tool.ruff.lint]\nignore = ["F821"]\n')
    monkeypatch.chdir(tmp_path)
    assert [f.rule for f in ruff_tool.check("print(nope)\n")] == ["F821"]


def test_format_rewrites_indentation_and_spacing():
    assert ruff_tool.format_code("def f( x ):\n  return x*2\n") == ("def f(x):\n    return x * 2\n")


def test_format_refuses_a_syntax_error_naming_the_line():
    with pytest.raises(ruff_tool.FormatError) as refused:
        ruff_tool.format_code("x = 1\ndef f(:\n    pass\n")
    assert str(refused.value) == (
        "cannot format: line 2 (column 7) has a syntax error: Expected a parameter or the end "
        "of the parameter list. Fix it and format again."
    )
