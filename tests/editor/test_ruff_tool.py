"""Ruff as the editor runs it (server/editor/ruff_tool.py, run by the sandboxed host): pyflakes'
findings and syntax errors with the contract's positions and sentences, no style nags, and
formatting."""

from __future__ import annotations

import pytest

from server.editor import ruff_tool
from server.editor.frames import Op


def check(editor, code: str):
    return ruff_tool.diagnostics(editor.host.result(editor.host.submit(Op.RUFF_CHECK, code)))


def test_undefined_names_and_unused_imports(editor):
    found = check(editor, "import os\nprint(distancia)\n")
    assert [(f.rule, f.severity, f.line, f.column, f.end_column) for f in found] == [
        ("F401", "warning", 1, 7, 9),
        ("F821", "error", 2, 6, 15),
    ]
    assert found[1].message == "Undefined name `distancia`."


def test_no_style_nags(editor):
    assert check(editor, "x=1;y =2\nif x==1 :\n  print( x,y )\nimport math\nmath.pi\n") == []


def test_a_syntax_error_is_e999_with_its_line(editor):
    found = check(editor, "x = 1\ndef broken(:\n    pass\n")
    assert found and all(f.rule == "E999" and f.severity == "error" for f in found)
    assert found[0].line == 2 and found[0].message.startswith("Syntax error: ")


def test_ruff_ignores_configuration_near_the_server(editor, tmp_path, monkeypatch):
    """--isolated, in the sandbox's empty project folder: a pyproject.toml in the server's
    working folder does not change what is reported."""
    (tmp_path / "pyproject.toml").write_text('[tool.ruff.lint]\nignore = ["F821"]\n')
    monkeypatch.chdir(tmp_path)
    assert [f.rule for f in check(editor, "print(nope)\n")] == ["F821"]


def test_findings_cut_at_the_output_cap_keep_their_whole_lines():
    line = '{"code": "F821", "message": "Undefined name `b`", "location": {"row": 1, "column": 2}}'
    answer = {"returncode": 0, "stdout": f"{line}\n{line}\n{line[:30]}", "stderr": "",
              "truncated": True}  # fmt: skip
    assert [f.rule for f in ruff_tool.diagnostics(answer)] == ["F821", "F821"]


def test_format_rewrites_indentation_and_spacing(editor):
    assert editor.format("def f( x ):\n  return x*2\n") == "def f(x):\n    return x * 2\n"


def test_format_refuses_a_syntax_error_naming_the_line(editor):
    with pytest.raises(ruff_tool.FormatError) as refused:
        editor.format("x = 1\ndef f(:\n    pass\n")
    assert str(refused.value) == (
        "cannot format: line 2 (column 7) has a syntax error: Expected a parameter or the end "
        "of the parameter list. Fix it and format again."
    )
