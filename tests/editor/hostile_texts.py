"""Code nested past what Python can compile, that a student may paste: the editor answers each
quickly, with a sentence, at every layer (tests/editor/test_host.py, tests/api/test_editor.py)."""

DEEPLY_NESTED = {
    "brackets": "x = " + "(" * 5000 + ")" * 5000 + "\n",
    "long-sum": "x = " + "1+" * 100_000 + "1\n",
    "indentation": "".join("    " * i + "if True:\n" for i in range(120)) + "    " * 120 + "pass\n",
}
