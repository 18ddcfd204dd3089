"""What each roslaunch element does to the plan (xmlloader.py's `_*_tag` methods and
http://wiki.ros.org/roslaunch/XML/<element>): one function per element, called by the
reader in server.runs.launch with the element and its scope."""

from __future__ import annotations

import posixpath
import shlex
from collections.abc import Callable

import yaml

from sandbox.names import (
    canonicalize,
    is_legal_base_name,
    is_legal_name,
    is_private,
    make_global_ns,
    ns_join,
)
from server.runs.launch import (
    ROBOT_PACKAGES,
    LaunchFileError,
    _NodeDraft,
    _Reader,
    _Scope,
)
from server.runs.launch_xml import Element, convert_value, load_yaml
from server.runs.spec import NodeSpec

Handler = Callable[[_Reader, Element, _Scope, int], None]


def _arg(reader: _Reader, element: Element, scope: _Scope, depth: int) -> None:
    """<arg name value|default>: `value` is fixed, `default` may be overridden by the includer
    or the command line; neither declares an arg that must be passed."""
    reader.check_attrs(element, scope, ("name", "value", "default", "doc"))
    name = reader.required(element, scope, "name")
    value, default = reader.attr(element, scope, "value"), reader.attr(element, scope, "default")
    if value is not None and default is not None:
        raise reader.error(
            scope,
            element,
            f'<arg name="{name}"> has both value and default; '
            "keep one (value cannot be overridden, default can)",
        )
    if name in scope.declared and name in scope.args:
        raise reader.error(scope, element, f"arg '{name}' is declared twice in this file")
    scope.declared.add(name)
    if value is not None:
        if name in scope.passed:
            raise reader.error(
                scope,
                element,
                f"arg '{name}' has a fixed value here and cannot be set from outside; "
                "declare it with default=... to make it settable",
            )
        scope.args[name] = value
    else:
        scope.args[name] = scope.passed.get(name, default)


def _param(reader: _Reader, element: Element, scope: _Scope, depth: int, node: str = "") -> None:
    """<param name value|textfile type>: global or relative names go to the parameter server
    now; `~name` waits for the nodes that follow in this scope; inside <node> a name is the
    node's own (`node` is its full name)."""
    reader.check_attrs(element, scope, ("name", "value", "type", "textfile", "binfile", "command"))
    name = reader.required(element, scope, "name").strip()
    if "command" in element.attrs:
        raise reader.error(
            scope,
            element,
            f'<param name="{name}" command=...> runs a program (often xacro for a robot '
            "description); a run does not run programs: the robot comes from the run's "
            "settings, other values can be written with value= or textfile=",
        )
    if "binfile" in element.attrs:
        raise reader.error(scope, element, "binfile= parameters are not supported; use textfile=")
    sources = [key for key in ("value", "textfile") if key in element.attrs]
    if len(sources) != 1:
        raise reader.error(
            scope, element, f'<param name="{name}"> needs exactly one of value= or textfile='
        )
    kind = reader.attr(element, scope, "type") or "auto"
    if sources[0] == "value":
        text = (reader.attr(element, scope, "value") or "").strip()
    else:
        path = reader.required(element, scope, "textfile")
        text = reader.text_of(path, scope.filename, element.line, "textfile")
    try:
        value = convert_value(text, kind)
    except ValueError as error:
        raise reader.error(scope, element, f'<param name="{name}">: {error}') from None
    _check_param_name(reader, element, scope, name)
    if node:
        reader.set_param(node + "/" + name.lstrip("~") if not name.startswith("/") else name, value)
    elif is_private(name):
        scope.private_params[name[1:]] = value
    else:
        reader.set_param(ns_join(scope.ns, name), value)


def _check_param_name(reader: _Reader, element: Element, scope: _Scope, name: str) -> None:
    if not name or not is_legal_name(canonicalize(name)):
        raise reader.error(
            scope,
            element,
            f"'{name}' is not a valid parameter name: letters, digits, '_' and '/', "
            "starting with a letter, '/' or '~'",
        )


def _rosparam(reader: _Reader, element: Element, scope: _Scope, depth: int, node: str = "") -> None:
    """<rosparam command="load|delete" file param ns subst_value>: YAML, inline or from a
    workspace file, loaded at `param` (or merged at the scope's namespace if it is a dict)."""
    reader.check_attrs(element, scope, ("command", "ns", "file", "param", "subst_value"))
    command = reader.attr(element, scope, "command") or "load"
    ns, param = reader.attr(element, scope, "ns") or "", reader.attr(element, scope, "param") or ""
    param = ns_join(ns, param) if ns else param
    base = make_global_ns(node) if node else scope.ns
    full = ns_join(base, param) if param else base
    if command == "dump":
        raise reader.error(
            scope, element, '<rosparam command="dump"> writes a file at launch; not done in a run'
        )
    if command == "delete":
        if "file" in element.attrs:
            raise reader.error(scope, element, 'file= does not go with command="delete"')
        reader.delete_params(full)
        return
    if command != "load":
        raise reader.error(
            scope, element, f"<rosparam> command must be load, delete or dump, got '{command}'"
        )
    file = reader.attr(element, scope, "file")
    if file is not None:
        text = reader.text_of(file, scope.filename, element.line, "rosparam file")
    else:
        text = element.text
    subst = reader.attr(element, scope, "subst_value") or "false"
    if reader.boolean(subst, "subst_value", element, scope):
        text = _substitute_text(reader, element, scope, text)
    try:
        data = load_yaml(text)
    except yaml.YAMLError as error:
        source = f"file '{file}'" if file else "inline YAML"
        raise reader.error(
            scope, element, f"<rosparam> {source} is not valid YAML: {error}"
        ) from None
    if data is None:
        data = {}
    if not param and not isinstance(data, dict):
        raise reader.error(
            scope, element, '<rosparam> needs param="name" for a value that is not a dictionary'
        )
    if is_private(full):
        if isinstance(data, dict) and not param:
            scope.private_params.update(data)
        else:
            scope.private_params[full[1:]] = data
    elif isinstance(data, dict) and not param:
        for key, value in data.items():  # merged into the namespace, key by key (roslaunch)
            reader.set_param(ns_join(full, str(key)), value)
    else:
        reader.set_param(full, data)


def _substitute_text(reader: _Reader, element: Element, scope: _Scope, text: str) -> str:
    probe = Element(element.tag, {"_text": text}, element.line)
    return reader.attr(probe, scope, "_text") or ""


def _remap(reader: _Reader, element: Element, scope: _Scope, depth: int) -> None:
    """<remap from to>: applies to the nodes that follow in this scope (or to its node)."""
    reader.check_attrs(element, scope, ("from", "to"))
    pair = []
    for key in ("from", "to"):
        value = canonicalize(reader.required(element, scope, key))
        if not value or not is_legal_name(value):
            raise reader.error(
                scope,
                element,
                f'<remap {key}="{element.attrs.get(key)}"> is not a valid ROS name; use '
                "letters, digits, '_' and '/', starting with a letter, '/' or '~'",
            )
        pair.append(value)
    scope.add_remap(pair[0], pair[1])


def _group(reader: _Reader, element: Element, scope: _Scope, depth: int) -> None:
    """<group ns clear_params>: a scope; what is set inside stays inside."""
    reader.check_attrs(element, scope, ("ns", "clear_params"))
    ns = reader.attr(element, scope, "ns")
    if ns is not None and not ns.strip():
        raise reader.error(scope, element, '<group ns=""> is empty; name a namespace or drop ns')
    _check_namespace(reader, element, scope, ns)
    reader.read_children(element, scope.child(ns), depth)


def _check_namespace(reader: _Reader, element: Element, scope: _Scope, ns: str | None) -> None:
    if ns is not None and (is_private(ns) or not is_legal_name(canonicalize(ns))):
        raise reader.error(
            scope, element, f"ns=\"{ns}\" is not a valid namespace (letters, digits, '_', '/')"
        )


def _include(reader: _Reader, element: Element, scope: _Scope, depth: int) -> None:
    """<include file ns pass_all_args>: another launch file of the workspace, with the
    <arg>s given inside the element (and all of ours with pass_all_args)."""
    reader.check_attrs(element, scope, ("file", "ns", "clear_params", "pass_all_args"))
    path = reader.required(element, scope, "file")
    ns = reader.attr(element, scope, "ns")
    _check_namespace(reader, element, scope, ns)
    inner = scope.child(ns)
    passed: dict[str, str] = {}
    pass_all = reader.boolean(
        reader.attr(element, scope, "pass_all_args") or "false", "pass_all_args", element, scope
    )
    if pass_all:
        passed.update({k: v for k, v in scope.args.items() if v is not None})
    for child in element.children:
        if child.tag != "arg":
            raise reader.error(
                scope, child, f"<{child.tag}> cannot be inside <include>; only <arg> can"
            )
        if not reader._enabled(child, scope):
            continue
        reader.check_attrs(child, scope, ("name", "value", "default", "doc"))
        name = reader.required(child, scope, "name")
        value = reader.attr(child, scope, "value")
        if value is None:
            value = reader.attr(child, scope, "default")
        if value is None:
            raise reader.error(scope, child, f'<arg name="{name}"> in <include> needs a value')
        passed[name] = value
    target = reader.normalize(path, scope.filename, element.line)
    file_scope = _Scope(ns=inner.ns, filename=target, args={}, passed=passed)
    file_scope.remaps = inner.remaps
    file_scope.private_params = inner.private_params
    outer = scope.filename
    try:
        reader.read_file(target, file_scope, depth + 1, element.line)
    finally:
        scope.filename = outer
    unused = sorted(set(passed) - file_scope.declared)
    if unused and not pass_all:
        raise reader.error(
            scope,
            element,
            f"arg(s) {', '.join(unused)} are not declared by the included file '{target}'",
        )


def _node(reader: _Reader, element: Element, scope: _Scope, depth: int) -> None:
    """<node pkg type name args ns ...>: a workspace file run as a node."""
    reader.check_attrs(
        element,
        scope,
        (
            "pkg",
            "type",
            "name",
            "args",
            "output",
            "respawn",
            "respawn_delay",
            "required",
            "ns",
            "clear_params",
            "cwd",
            "launch-prefix",
            "machine",
        ),
    )
    pkg = reader.required(element, scope, "pkg")
    node_type = reader.required(element, scope, "type")
    name = reader.required(element, scope, "name")
    if ROBOT_PACKAGES.match(pkg) and pkg not in reader.packages:
        raise reader.error(
            scope,
            element,
            f'<node pkg="{pkg}" type="{node_type}"> runs a ROS program that a run does not '
            "have: the robot, its world and the 3D view come from the run's settings; remove "
            "this node",
        )
    for refused in ("machine", "launch-prefix"):
        if element.attrs.get(refused):
            raise reader.error(
                scope, element, f"{refused}= is not supported: every node runs in the run's sandbox"
            )
    if not is_legal_base_name(name):
        raise reader.error(
            scope,
            element,
            f"node name '{name}' must start with a letter and use only letters, digits and '_'",
        )
    ns = reader.attr(element, scope, "ns")
    _check_namespace(reader, element, scope, ns)
    inner = scope.child(ns)
    full = inner.ns + name
    respawn, required = (reader.attr(element, scope, key) for key in ("respawn", "required"))
    if required is not None:
        reader.boolean(required, "required", element, scope)  # checked; the run ends anyway
    if respawn is not None and reader.boolean(respawn, "respawn", element, scope):
        reader.notes.append(
            f"{scope.filename}, line {element.line}: node '{full}' has respawn=\"true\"; "
            "a node that ends is not restarted in a run"
        )
    # The scope's ~params first, then the node's own children in order (roslaunch's order).
    for key, value in inner.private_params.items():
        reader.set_param(full + "/" + key, value)
    node_scope = inner.child(None)
    node_scope.private_params = {}
    for child in element.children:
        if not reader._enabled(child, scope):
            continue
        if child.tag == "remap":
            _remap(reader, child, node_scope, depth)
        elif child.tag == "param":
            _param(reader, child, node_scope, depth, node=full)
        elif child.tag == "rosparam":
            _rosparam(reader, child, node_scope, depth, node=full)
        elif child.tag == "env":
            _env(reader, child, scope, depth)
        else:
            raise reader.error(
                scope,
                child,
                f"<{child.tag}> cannot be inside <node>; it holds <param>, <rosparam>, <remap>",
            )
        for key, value in node_scope.private_params.items():  # a <rosparam param="~x">
            reader.set_param(full + "/" + key, value)
        node_scope.private_params = {}
    path = _node_file(reader, element, scope, pkg, node_type)
    code = reader.text_of(path, scope.filename, element.line, "node file")
    args = reader.attr(element, scope, "args") or ""
    try:
        argv = shlex.split(args)
    except ValueError as error:
        raise reader.error(scope, element, f'args="{args}" cannot be split: {error}') from None
    spec = NodeSpec(
        name=name,
        code=code,
        filename=posixpath.basename(path),
        remaps=tuple(node_scope.remaps),
        args=(*argv, f"__name:={name}"),
        namespace=canonicalize(inner.ns) or "/",
    )
    reader.nodes.append(_NodeDraft(name, inner.ns, spec, (scope.filename, element.line)))


def _node_file(reader: _Reader, element: Element, scope: _Scope, pkg: str, node_type: str) -> str:
    """The workspace file a node's type names: that file name in any folder (in the folder
    of the package `pkg` if the workspace has its package.xml)."""
    matches = sorted(key for key in reader.workspace if posixpath.basename(key) == node_type)
    if len(matches) > 1 and pkg in reader.packages:
        folder = reader.packages[pkg]
        inside = [key for key in matches if folder == "." or key.startswith(folder + "/")]
        matches = inside or matches
    if len(matches) == 1:
        return matches[0]
    if matches:
        raise reader.error(
            scope,
            element,
            f'type="{node_type}" matches {len(matches)} workspace files: '
            f"{', '.join(matches)}; rename one so the name is unique",
        )
    scripts = sorted(key for key in reader.workspace if key.endswith(".py"))
    hint = ""
    if not node_type.endswith(".py") and any(
        posixpath.basename(key) == node_type + ".py" for key in scripts
    ):
        hint = f' (did you mean type="{node_type}.py"?)'
    listing = ", ".join(scripts) if scripts else "none"
    raise reader.error(
        scope,
        element,
        f"no workspace file is named '{node_type}'{hint}; the workspace's Python files: {listing}",
    )


def _env(reader: _Reader, element: Element, scope: _Scope, depth: int) -> None:
    raise reader.error(
        scope,
        element,
        "<env> sets environment variables, which a run does not pass to nodes; "
        "use a <param> instead",
    )


def _machine(reader: _Reader, element: Element, scope: _Scope, depth: int) -> None:
    raise reader.error(
        scope,
        element,
        "<machine> starts nodes on other computers; every node of a run runs "
        "in its sandbox: remove it",
    )


def _test(reader: _Reader, element: Element, scope: _Scope, depth: int) -> None:
    raise reader.error(
        scope,
        element,
        "<test> nodes belong to rostest and are not run; use <node>",
    )


def _master(reader: _Reader, element: Element, scope: _Scope, depth: int) -> None:
    reader.notes.append(
        f"{scope.filename}, line {element.line}: <master> is ignored (as roslaunch)"
    )


ELEMENTS: dict[str, Handler] = {
    "arg": _arg,
    "param": _param,
    "rosparam": _rosparam,
    "remap": _remap,
    "group": _group,
    "include": _include,
    "node": _node,
    "env": _env,
    "machine": _machine,
    "test": _test,
    "master": _master,
}

__all__ = ["ELEMENTS", "LaunchFileError"]
