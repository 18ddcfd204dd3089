"""The node host: runs one student controller inside the sandboxed child, after `Load`.

    exited = run_node(link, load, workdir)

`run_node` compiles the code under the student's filename, picks the API (a top-level
`def step` and no `init_node` call -> step API, else a rospy script), runs it with the node
clock, the rospy shim and a rospy-style logging handler in place, sends a `Yield` at every
sleep and returns the final `Exited` frame (the runner sends it). Student errors never escape:
they become `Outcome.ERROR` with a traceback cut to the student's frames. A broken pipe to the
parent raises the link's `ProtocolError`.

What run_node sets up for itself (and undoes on return, so tests can run many nodes in one
process): the dialect's compatibility layer on sys.path (sandbox/ros_compat with rospy for a
ROS 1 node, sandbox/ros_compat2 with rclpy for a ROS 2 one: `NodeInfo.ros_version`),
MPLBACKEND=Agg, the `time` patches of a lockstep clock, the working directory, sys.argv =
[filename, *argv], `__main__`, warnings in their default (print-once) form, and a rospy-style
root logging handler.
"""

from __future__ import annotations

import ast
import contextlib
import functools
import logging
import os
import sys
import types
import warnings
from contextlib import ExitStack
from typing import ClassVar, Protocol

from sandbox import ros2_imports, ros_imports, runtime
from sandbox.after_import import AfterImport, BeforeImport, DeferredImport
from sandbox.artifacts import collect_artifacts, write_workspace_files
from sandbox.limits import DEFAULT_LIMITS, Limits
from sandbox.protocol import Api, Clock, Exited, Load, NodeError, Outcome
from sandbox.runtime import LinkLost, NodeFailure, NodeRuntime, ROSInterruptException
from sandbox.step_api import StepController
from sandbox.student_errors import StepError, from_exception, register_source, summary
from sandbox.vclock import NodeClock, TimePatch

ROS_COMPAT_DIR = os.path.join(os.path.dirname(os.path.abspath(__file__)), "ros_compat")
ROS_COMPAT2_DIR = ros2_imports.ROS_COMPAT2_DIR
STEP_MODULE_NAME = "controller"  # __name__ of a step-API module, so a __main__ guard stays idle


class Link(Protocol):
    def send(self, frame: object) -> None: ...

    def receive(self) -> object: ...


# Modules imported ahead by a warm-pool process (sandbox/runner.py), kept out of sys.modules
# until a node of their dialect asks for them: directory -> {module name: module}.
_SET_ASIDE: dict[str, dict[str, types.ModuleType]] = {}


@functools.cache
def _names_provided(directory: str) -> tuple[frozenset[str], str]:
    """The top-level names a layer directory provides (`rclpy`, `std_msgs`, ...), and the
    package it also is (`sandbox.ros_compat2`: a test may import its modules by that name)."""
    tops = frozenset(entry.removesuffix(".py") for entry in os.listdir(directory))
    return tops, "sandbox." + os.path.basename(directory)


def _modules_from(directory: str) -> list[str]:
    """The names in sys.modules of the modules imported from `directory`. A warm process holds
    ~1,000 modules and reading each one's __file__ cost 0.25 ms of every node's start, so only
    the names under the directory's own top-level names are looked at, and none when no such
    package is imported (a submodule is never imported without its package)."""
    tops, package = _names_provided(directory)
    modules = sys.modules
    if package not in modules and tops.isdisjoint(modules):
        return []
    prefix = directory + os.sep
    return [
        name
        for name in [
            name
            for name in modules
            if name.partition(".")[0] in tops or name.startswith(package + ".")
        ]
        if (getattr(modules[name], "__file__", None) or "").startswith(prefix)
    ]


def _forget_modules_from(directory: str) -> None:
    """Drop the modules imported from `directory` (the other dialect's layer), so that
    `std_msgs.msg` means this dialect's package and `import rclpy` in a ROS 1 node fails with
    its sentence: one process may run nodes of both dialects in turn (the tests)."""
    for name in _modules_from(directory):
        del sys.modules[name]


def set_aside_modules_from(directory: str) -> None:
    """Take the modules imported from `directory` out of sys.modules but keep them alive, for
    `install_ros_compat` to put back when a node of that dialect runs. The runner imports rclpy
    ahead this way: a ROS 1 node then finds no ROS 2 module to forget, where deleting them (and
    freeing ~1,000 objects) cost 1-2.5 ms of its start."""
    aside = _SET_ASIDE.setdefault(directory, {})
    for name in _modules_from(directory):
        aside[name] = sys.modules.pop(name)


def install_ros_compat(ros_version: int = 1) -> None:
    """Make `import rospy` (ROS 1) or `import rclpy` (ROS 2) and `from std_msgs.msg import ...`
    find the dialect's layer, and only that one (idempotent)."""
    ours, other = (
        (ROS_COMPAT2_DIR, ROS_COMPAT_DIR) if ros_version == 2 else (ROS_COMPAT_DIR, ROS_COMPAT2_DIR)
    )
    if other in sys.path:
        sys.path[:] = [entry for entry in sys.path if entry != other]
    _forget_modules_from(other)  # imported by an earlier node of the other dialect
    for name, module in _SET_ASIDE.pop(ours, {}).items():  # imported ahead by the runner
        sys.modules.setdefault(name, module)
    if ours not in sys.path:
        sys.path.insert(0, ours)
    # Modules we lack fail with a sentence for this dialect, not "No module named".
    if ros_version == 2:
        ros_imports.uninstall()
        ros2_imports.install()
    else:
        ros2_imports.uninstall()
        ros_imports.install()


def imports_rclpy(tree: ast.Module) -> bool:
    """True when the file imports rclpy (`import rclpy`, `from rclpy.node import Node`...):
    the node is a ROS 2 node (docs/architecture.md, "Dialects")."""
    for node in ast.walk(tree):
        if isinstance(node, ast.Import):
            if any(alias.name.split(".")[0] == "rclpy" for alias in node.names):
                return True
        elif (
            isinstance(node, ast.ImportFrom)
            and node.level == 0
            and (node.module or "").split(".")[0] == "rclpy"
        ):
            return True
    return False


def choose_api(tree: ast.Module, requested: Api) -> Api:
    """The API a file uses: a top-level `def step` without init_node or rclpy is the step API;
    anything else runs as a script (rospy or rclpy)."""
    if requested is not Api.AUTO:
        return requested
    if imports_rclpy(tree):
        return Api.ROSPY
    defines_step = any(
        isinstance(node, ast.FunctionDef | ast.AsyncFunctionDef) and node.name == "step"
        for node in tree.body
    )
    calls_init_node = any(
        isinstance(node, ast.Call)
        and (getattr(node.func, "attr", None) or getattr(node.func, "id", None)) == "init_node"
        for node in ast.walk(tree)
    )
    return Api.STEP if defines_step and not calls_init_node else Api.ROSPY


class _LogHandler(logging.Handler):
    """Python logging in the node prints like rospy: `[WARN] [3.200000]: name: text`."""

    _LEVELS: ClassVar[dict[str, str]] = {"WARNING": "WARN", "CRITICAL": "FATAL"}

    def __init__(self, node: NodeRuntime) -> None:
        super().__init__()
        self._node = node

    def emit(self, record: logging.LogRecord) -> None:
        level = self._LEVELS.get(record.levelname, record.levelname)
        name = "" if record.name == "root" else f"{record.name}: "
        try:
            text = record.getMessage()
        except Exception:  # a bad %-format in the student's call
            text = f"{record.msg} {record.args}"
        self._node.log(level, name + text)


def _show_warning(
    message: Warning | str,
    category: type[Warning],
    filename: str,
    lineno: int,
    file: object = None,
    line: str | None = None,
) -> None:
    """Warnings from the student's code go to the log stream, as in a plain `python` run."""
    sys.stderr.write(warnings.formatwarning(message, category, filename, lineno, line))


def _install_logging(stack: ExitStack, node: NodeRuntime) -> None:
    """Root logging prints rospy-style lines at INFO; the student's own basicConfig() still
    takes over (it replaces our handler, as it would replace nothing in a plain script)."""
    handler = _LogHandler(node)
    root = logging.getLogger()
    saved_level, saved_basic_config = root.level, logging.basicConfig

    def basic_config(**kwargs: object) -> None:
        if root.handlers == [handler]:
            kwargs.setdefault("force", True)
        saved_basic_config(**kwargs)  # type: ignore[arg-type]

    root.addHandler(handler)
    root.setLevel(logging.INFO)
    logging.basicConfig = basic_config
    stack.callback(root.removeHandler, handler)
    stack.callback(root.setLevel, saved_level)
    stack.callback(setattr, logging, "basicConfig", saved_basic_config)


def _note_figure_saving(stack: ExitStack, node: NodeRuntime) -> None:
    """Figure.savefig (which plt.savefig calls) tells the parent first: the step that saves a
    figure gets the end budget (sandbox/limits.py), so plotting after a control loop is not cut
    off by the step budget. A node from the warm pool has matplotlib imported already; a node
    started cold gets the wrapper when the student's code first imports matplotlib."""
    patched: list[tuple[type, object]] = []

    def wrap_savefig(figure_module: types.ModuleType) -> None:
        figure_class = figure_module.Figure
        original = figure_class.savefig

        def savefig(self: object, *args: object, **kwargs: object) -> object:
            node.note_drawing()
            return original(self, *args, **kwargs)

        savefig.__doc__, savefig.__wrapped__ = original.__doc__, original  # type: ignore[attr-defined]
        figure_class.savefig = savefig
        patched.append((figure_class, original))

    def restore() -> None:
        for figure_class, original in patched:
            figure_class.savefig = original  # type: ignore[attr-defined]

    hook = AfterImport("matplotlib.figure", wrap_savefig)
    hook.install()
    stack.callback(restore)
    stack.callback(hook.remove)


# Imported ahead by a warm-pool node; a cold node imports them when the student does, which can
# take longer than a step budget on a loaded machine (matplotlib.pyplot: 0.3-1.5 s).
HEAVY_PACKAGES = {"numpy", "scipy", "matplotlib", "skfuzzy", "pandas", "sklearn", "cv2"}


def _note_heavy_imports(stack: ExitStack, node: NodeRuntime) -> None:
    """A step that starts importing a heavy library gets the end budget, as a step saving a
    figure does: the import is the library's cost, paid once, not the controller's."""
    hook = BeforeImport(HEAVY_PACKAGES, node.note_drawing)
    hook.install()
    stack.callback(hook.remove)


# Modules that libraries import for what controllers rarely use: in a node started cold,
# `import` binds them and their code runs at their first use (sandbox/after_import.py). CPU
# each saves at every start of a node that imports skfuzzy.control and never uses it (issue 18):
DEFERRED_MODULES = (
    "matplotlib.pyplot",  # ~0.25 s: scikit-fuzzy imports it for its visualizer alone
    "numpy.f2py",  # ~0.1 s (charset_normalizer with it): scipy's `from numpy import *`
    "numpy.testing",  # ~0.03 s: the same star import
)


def _defer_imports(stack: ExitStack) -> None:
    """The step that first uses a deferred module has its clock stopped while the module loads
    (NodeRuntime.library_loading), so it keeps its budget for the rest, as an import in an
    earlier step would have left it."""
    for name in DEFERRED_MODULES:
        hook = DeferredImport(name, _library_loading)
        hook.install()
        stack.callback(hook.remove)


def _library_loading() -> contextlib.AbstractContextManager[object]:
    """Through the node running now, if any (a module may be used first by a later node of the
    same process, or after the node: the tests run many in one)."""
    node = runtime.active()
    return node.library_loading() if node is not None else contextlib.nullcontext()


def _environment(stack: ExitStack, node: NodeRuntime, load: Load, workdir: str) -> None:
    """Point the interpreter at this node; every change is undone when `stack` closes."""
    install_ros_compat(load.info.ros_version)
    os.environ["MPLBACKEND"] = "Agg"
    if "matplotlib" in sys.modules:
        sys.modules["matplotlib"].use("Agg")
    for stream in (sys.stdout, sys.stderr):
        with contextlib.suppress(AttributeError, ValueError, OSError):
            stream.reconfigure(line_buffering=True)  # type: ignore[union-attr]
    previous_cwd = os.getcwd()
    os.chdir(workdir)
    stack.callback(os.chdir, previous_cwd)
    saved_argv, saved_main = sys.argv, sys.modules.get("__main__")
    sys.argv = [load.filename, *load.info.argv]  # as rosrun and roslaunch pass them
    stack.callback(setattr, sys, "argv", saved_argv)
    if saved_main is not None:
        stack.callback(sys.modules.__setitem__, "__main__", saved_main)
    else:
        stack.callback(sys.modules.pop, "__main__", None)
    stack.callback(sys.modules.pop, STEP_MODULE_NAME, None)
    stack.enter_context(warnings.catch_warnings())
    warnings.resetwarnings()
    warnings.simplefilter("default")
    warnings.showwarning = _show_warning
    _install_logging(stack, node)
    _note_figure_saving(stack, node)
    _note_heavy_imports(stack, node)
    _defer_imports(stack)
    lockstep = load.info.clock is Clock.LOCKSTEP
    stack.callback(TimePatch(node.clock, node.sleep_for, node.poll, clocks=lockstep).remove)
    runtime.activate(node)
    stack.callback(runtime.activate, None)


def _execute(node: NodeRuntime, load: Load) -> None:
    """Compile and run the student's module (and its steps); raises what the student raised."""
    if node.failure is not None:  # the node's names could not be set up (a bad remap)
        raise node.failure
    tree = compile(load.code, load.filename, "exec", flags=ast.PyCF_ONLY_AST, dont_inherit=True)
    code = compile(tree, load.filename, "exec", dont_inherit=True)
    api = choose_api(tree, load.api)
    module = types.ModuleType("__main__" if api is Api.ROSPY else STEP_MODULE_NAME)
    module.__file__ = load.filename
    sys.modules["__main__" if api is Api.ROSPY else STEP_MODULE_NAME] = module
    if api is Api.STEP:
        node.node_name = "/" + load.info.node_name.strip("/")
        node.implicit_name = True
        exec(code, module.__dict__)
        if not callable(module.__dict__.get("step")):
            raise StepError(
                "the step API needs a function `def step(obs):` at the top level of the file",
                None,
            )
        StepController(node, module.__dict__, tree).run()
    else:
        exec(code, module.__dict__)


def _finish(
    node: NodeRuntime, error: BaseException | None, load: Load
) -> tuple[Outcome, str, NodeError | None]:
    """The outcome, once the student's code has stopped (normally or by `error`)."""
    failure = node.failure
    if isinstance(error, NodeFailure):
        failure = error.original
    elif error is not None and not isinstance(error, ROSInterruptException | SystemExit):
        failure = error
    if failure is None:
        if node.shutdown is not None and node.shutdown.by_parent:
            outcome, reason = Outcome.SHUTDOWN, node.shutdown.reason
        elif isinstance(error, ROSInterruptException) and node.shutdown is None:
            outcome, reason = Outcome.SHUTDOWN, f"ROSInterruptException: {error}"
        elif node.shutdown is not None:
            outcome, reason = Outcome.FINISHED, f"signal_shutdown: {node.shutdown.reason}"
        elif isinstance(error, SystemExit):
            outcome, reason = Outcome.FINISHED, f"sys.exit({error.code!r})"
        else:
            outcome, reason = Outcome.FINISHED, "script ended"
        try:
            node.signal_shutdown(reason)  # on_shutdown hooks run at the end, as rospy's do
        except NodeFailure as hook_error:
            failure = hook_error.original
        else:
            return outcome, reason, None
    problem = from_exception(failure, load.filename)
    return Outcome.ERROR, summary(problem), problem


def run_node(link: Link, load: Load, workdir: str, limits: Limits = DEFAULT_LIMITS) -> Exited:
    """Run the student's code to its end; return the Exited frame for the runner to send."""
    if load.api is Api.LAUNCH:  # a launch file to read, not a node (sandbox/launch2/job.py)
        from sandbox.launch2.job import run_launch

        return run_launch(load, workdir)
    node = NodeRuntime(
        link, load.info, NodeClock(load.info.clock, load.info.start_time_s), load.filename
    )
    register_source(load.filename, load.code)
    error: BaseException | None = None
    inputs = write_workspace_files(workdir, load.files)
    with ExitStack() as stack:
        _environment(stack, node, load, workdir)
        try:
            _execute(node, load)
        except LinkLost as lost:
            raise lost.args[0] from None
        except BaseException as raised:  # the student's, whatever it is
            error = raised
        outcome, reason, problem = _finish(node, error, load)
        sys.stdout.flush()
        sys.stderr.flush()
    artifacts, notes = collect_artifacts(workdir, limits, inputs)
    return Exited(
        outcome=outcome,
        reason=reason,
        error=problem,
        artifacts=artifacts,
        notes=notes,
        published=node.take_outbox(),
    )
