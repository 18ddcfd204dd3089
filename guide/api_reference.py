"""The API reference page, generated at build time from the app's own OpenAPI schema
(`create_app().openapi()`, what /docs and /openapi.json serve): every route by tag, its
parameters, body and answers, then every schema with its fields."""

from __future__ import annotations

from typing import Any

from server.api.app import create_app

Schema = dict[str, Any]
METHODS = ("get", "post", "put", "patch", "delete")


def _schema_anchor(name: str) -> str:
    return "schema-" + name.lower().replace("_", "-").replace(".", "-")


def type_text(schema: Schema) -> str:
    """A JSON schema as a short phrase: `RunRequest`, `list of string`, `integer (>= 1)`."""
    if "$ref" in schema:
        name = schema["$ref"].rsplit("/", 1)[-1]
        return f"[{name}](#{_schema_anchor(name)})"
    for combiner in ("anyOf", "oneOf", "allOf"):
        if combiner in schema:
            parts = [type_text(part) for part in schema[combiner]]
            return " or ".join(dict.fromkeys(parts))
    kind = schema.get("type")
    if kind == "array":
        return f"list of {type_text(schema.get('items', {}))}"
    if kind == "object" and "additionalProperties" in schema:
        extra = schema["additionalProperties"]
        value = type_text(extra) if isinstance(extra, dict) else "any"
        return f"object of {value}"
    if "enum" in schema:
        return "one of " + ", ".join(f"`{value}`" for value in schema["enum"])
    if "const" in schema:
        return f"`{schema['const']}`"
    text = kind or "any"
    limits = [
        f"{symbol} {schema[key]}"
        for key, symbol in (
            ("minimum", ">="),
            ("exclusiveMinimum", ">"),
            ("maximum", "<="),
            ("exclusiveMaximum", "<"),
            ("minLength", "length >="),
            ("maxLength", "length <="),
        )
        if key in schema
    ]
    if schema.get("format"):
        text += f" ({schema['format']})"
    if limits:
        text += " (" + ", ".join(limits) + ")"
    return text


def _cell(text: str) -> str:
    return " ".join(str(text).split()).replace("|", "\\|") or "-"


def _operation(method: str, path: str, operation: Schema) -> list[str]:
    lines = [f"### `{method.upper()} {path}`", ""]
    if operation.get("summary"):
        lines += [operation["summary"] + ".", ""]
    if operation.get("description"):
        lines += [operation["description"].strip(), ""]
    parameters = operation.get("parameters", [])
    if parameters:
        lines += ["| parameter | in | required | type | description |", "|---|---|---|---|---|"]
        for parameter in parameters:
            lines.append(
                f"| `{parameter['name']}` | {parameter['in']} | "
                f"{'yes' if parameter.get('required') else 'no'} | "
                f"{_cell(type_text(parameter.get('schema', {})))} | "
                f"{_cell(parameter.get('description', ''))} |"
            )
        lines.append("")
    body = operation.get("requestBody")
    if body:
        for media, content in body.get("content", {}).items():
            lines += [f"Body ({media}): {type_text(content.get('schema', {}))}.", ""]
    answers = []
    for code, answer in operation.get("responses", {}).items():
        shapes = [type_text(c.get("schema", {})) for c in answer.get("content", {}).values()]
        shape = f": {shapes[0]}" if shapes and shapes[0] != "any" else ""
        answers.append(f"`{code}` {answer.get('description', '')}{shape}")
    if answers:
        lines += ["Answers: " + "; ".join(answers) + ".", ""]
    return lines


def _schema(name: str, schema: Schema) -> list[str]:
    lines = [f"### {name} {{ #{_schema_anchor(name)} }}", ""]
    if schema.get("description"):
        lines += [" ".join(schema["description"].split()), ""]
    properties = schema.get("properties", {})
    required = set(schema.get("required", []))
    if properties:
        lines += ["| field | type | required | description |", "|---|---|---|---|"]
        for field, spec in properties.items():
            default = f" (default `{spec['default']}`)" if "default" in spec else ""
            lines.append(
                f"| `{field}` | {_cell(type_text(spec))} | {'yes' if field in required else 'no'}"
                f" | {_cell(spec.get('description', ''))}{default} |"
            )
        lines.append("")
    elif "enum" in schema:
        lines += [type_text(schema) + ".", ""]
    return lines


def api_markdown(spec: Schema | None = None) -> str:
    spec = spec or create_app().openapi()
    by_tag: dict[str, list[tuple[str, str, Schema]]] = {}
    for path, operations in spec["paths"].items():
        for method in METHODS:
            if method in operations:
                operation = operations[method]
                tag = (operation.get("tags") or ["other"])[0]
                by_tag.setdefault(tag, []).append((method, path, operation))
    lines = [
        f"The lab's HTTP API, version {spec['info']['version']}: "
        f"{sum(len(v) for v in by_tag.values())} operations. The same schema is served live at "
        "`/openapi.json`, with a page to try the calls at `/docs`. Every error answer is "
        '`{"detail": "a sentence"}`.',
        "",
    ]
    for tag, operations in by_tag.items():
        lines += [f"## {tag.capitalize()}", ""]
        for method, path, operation in operations:
            lines += _operation(method, path, operation)
    lines += ["## Schemas", ""]
    for name, schema in spec.get("components", {}).get("schemas", {}).items():
        lines += _schema(name, schema)
    return "\n".join(lines)
