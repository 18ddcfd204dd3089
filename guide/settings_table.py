"""The operators' settings table, generated from `server.api.settings.Settings` at build time.

The class is the one place a setting is written: its name, type, default and bounds come from
the pydantic model, its unit and reason from the comment beside it in settings.py (`# [s] why`,
continued on the next comment lines while they start in lower case), a group's introduction from
the comment block above its first field, and the `robodojo serve` option from the command's own
parser. Nothing here restates a value.
"""

from __future__ import annotations

import argparse
import ast
import inspect
import io
import re
import tokenize
from dataclasses import dataclass
from pathlib import Path

from server.api import serve
from server.api.settings import Settings

UNIT = re.compile(r"^\[([^\]]+)\]\s*")
BYTE_UNITS = ((1024**3, "GiB"), (1024**2, "MiB"), (1024, "KiB"))


@dataclass(frozen=True)
class SettingRow:
    name: str
    type_name: str
    default: str
    bounds: str
    unit: str
    why: str
    option: str


@dataclass(frozen=True)
class SettingGroup:
    introduction: str  # the comment block above the group's first field ("" for the first)
    rows: tuple[SettingRow, ...]


def _comments_by_line(source: str) -> dict[int, tuple[str, bool]]:
    """Line number -> (comment text, whether the comment is alone on its line)."""
    found: dict[int, tuple[str, bool]] = {}
    lines = source.splitlines()
    for token in tokenize.generate_tokens(io.StringIO(source).readline):
        if token.type == tokenize.COMMENT:
            line = token.start[0]
            alone = lines[line - 1].strip().startswith("#")
            found[line] = (token.string.lstrip("#").strip(), alone)
    return found


def _serve_options() -> dict[str, tuple[str, str]]:
    """Settings field -> (the `robodojo serve` option that sets it, its help), from the real
    parser."""
    parser = argparse.ArgumentParser(prog="robodojo")
    commands = parser.add_subparsers(dest="command")
    serve.add_commands(commands)
    options: dict[str, tuple[str, str]] = {}
    for action in commands.choices["serve"]._actions:
        if action.option_strings and action.dest != "help":
            options[action.dest] = (action.option_strings[0], action.help or "")
    return options


def _bounds(field) -> str:
    parts = []
    for rule in field.metadata:
        for attribute, symbol in (("ge", ">="), ("gt", ">"), ("le", "<="), ("lt", "<")):
            value = getattr(rule, attribute, None)
            if value is not None:
                parts.append(f"{symbol} {value}")
    return ", ".join(parts)


def _default(value: object, unit: str) -> str:
    if value is None:
        return "none"
    if unit == "B" and isinstance(value, int):
        for size, name in BYTE_UNITS:
            if value >= size and value % size == 0:
                return f"{value} ({value // size} {name})"
    if isinstance(value, Path):
        return str(value)
    return repr(value) if isinstance(value, str) else str(value)


def _type_name(annotation: object) -> str:
    text = getattr(annotation, "__name__", None) or str(annotation)
    return text.replace("pathlib.", "").replace("NoneType", "None")


def setting_groups() -> list[SettingGroup]:
    source = Path(inspect.getsourcefile(Settings)).read_text()
    comments = _comments_by_line(source)
    (settings_class,) = [
        node
        for node in ast.parse(source).body
        if isinstance(node, ast.ClassDef) and node.name == Settings.__name__
    ]
    options = _serve_options()
    groups: list[SettingGroup] = []
    introduction, rows = "", []
    previous_end = settings_class.lineno
    for node in settings_class.body:
        if not (isinstance(node, ast.AnnAssign) and isinstance(node.target, ast.Name)):
            previous_end = node.end_lineno or node.lineno
            continue
        name = node.target.id
        if name not in Settings.model_fields:
            continue
        # The comment lines between the previous statement and this field: a continuation of the
        # previous field's comment while they start in lower case, then this group's introduction.
        between = [
            comments[line][0]
            for line in range(previous_end + 1, node.lineno)
            if line in comments and comments[line][1]
        ]
        while between and between[0][:1].islower() and rows:
            last = rows[-1]
            rows[-1] = SettingRow(**{**last.__dict__, "why": f"{last.why} {between.pop(0)}"})
        if between:
            if rows:
                groups.append(SettingGroup(introduction, tuple(rows)))
            introduction, rows = " ".join(between), []
        trailing = comments.get(node.lineno, ("", True))
        why = trailing[0] if not trailing[1] else ""
        unit_match = UNIT.match(why)
        unit = unit_match.group(1) if unit_match else ""
        why = why[unit_match.end() :] if unit_match else why
        field = Settings.model_fields[name]
        option, option_help = options.get(name, ("", ""))
        rows.append(
            SettingRow(
                name=name,
                type_name=_type_name(field.annotation),
                default=_default(field.default, unit),
                bounds=_bounds(field),
                unit=unit,
                why=why or option_help,  # the option's help, where the code has no comment
                option=option,
            )
        )
        previous_end = node.end_lineno or node.lineno
    if rows:
        groups.append(SettingGroup(introduction, tuple(rows)))
    return groups


def _cell(text: str) -> str:
    return text.replace("|", "\\|") if text else "-"


def settings_markdown() -> str:
    prefix = Settings.model_config.get("env_prefix", "")
    parts = []
    for group in setting_groups():
        if group.introduction:
            parts.append(group.introduction + "\n")
        parts.append("| environment variable (option) | default | unit | allowed | why |")
        parts.append("|---|---|---|---|---|")
        for row in group.rows:
            option = f"<br>`{row.option}`" if row.option else ""
            parts.append(
                f"| `{prefix}{row.name.upper()}`{option} | `{row.default}` | {_cell(row.unit)} | "
                f"{_cell(row.bounds)} | {_cell(row.why)} |"
            )
        parts.append("")
    return "\n".join(parts)
