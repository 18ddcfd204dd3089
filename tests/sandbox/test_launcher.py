"""The launcher end to end: policy without bubblewrap, a real course script in the sandbox,
artifacts and logs across the wall, budgets, misuse of the API."""

from __future__ import annotations

import dataclasses
import json
import logging
import time

import pytest

from sandbox.bwrap import SandboxUnavailable
from sandbox.launcher import DANGER, Launcher, NodeUsageError
from sandbox.protocol import Api, Envelope, Exited, Finishing, Outcome, Yield
from tests.sandbox.conftest import TEST_LIMITS, WarmOnlyLauncher, crowbot_info, run_script

COURSE_SCRIPT = """
import time
import rospy
import matplotlib.pyplot as plt
from std_msgs.msg import Int32
from geometry_msgs.msg import Twist

distance = 100
periods = []

def on_distance(msg):
    global distance
    distance = msg.data

rospy.init_node("approach")
rospy.Subscriber("/Distance", Int32, on_distance)
pub = rospy.Publisher("/Control", Twist, queue_size=10)
rate = rospy.Rate(10)
last = time.perf_counter()
while distance > 20 and not rospy.is_shutdown():
    move = Twist()
    move.linear.x = 0.1
    pub.publish(move)
    rate.sleep()
    now = time.perf_counter()
    periods.append(now - last)
    last = now
rospy.loginfo("stopped at %d cm", distance)
rospy.signal_shutdown("reached the wall")
plt.plot(periods)
plt.savefig("periods.png")
with open("periods.csv", "w") as f:
    f.write("\\n".join(f"{p:.6f}" for p in periods))
"""


def distance(cm: int) -> Envelope:
    return Envelope("Distance", "std_msgs/Int32", cm.to_bytes(4, "little", signed=True))


def test_course_script_runs_unchanged_in_the_sandbox(launcher):
    reply, node = run_script(launcher, COURSE_SCRIPT, "approach")
    try:
        assert isinstance(reply, Yield) and reply.wake_at_s == pytest.approx(0.1)
        wakes = []
        for k, cm in enumerate([60, 45, 30, 15], start=1):
            assert [e.type for e in reply.published] == ["geometry_msgs/Twist"]
            reply = node.wake(0.1 * k, [distance(cm)])
            wakes.append(getattr(reply, "wake_at_s", None))
        assert isinstance(reply, Finishing), reply  # its figures are still to come
        assert reply.reason == "reached the wall"
        reply = node.poll_finished(timeout_s=20.0)
        assert isinstance(reply, Exited), reply
        assert reply.outcome is Outcome.FINISHED
        assert reply.reason == "signal_shutdown: reached the wall"
        assert wakes[:3] == pytest.approx([0.2, 0.3, 0.4])
        artifacts = {a.name: a.data for a in reply.artifacts}
        assert artifacts["periods.png"].startswith(b"\x89PNG")
        periods = [float(x) for x in artifacts["periods.csv"].decode().split()]
        assert periods == pytest.approx([0.1] * 4, abs=1e-6)  # simulated, not wall, periods
        assert any("stopped at 15 cm" in line for line in node.logs.take())
    finally:
        node.close()


def test_shutdown_runs_hooks_and_returns_artifacts(launcher):
    code = (
        "import rospy\n"
        "rospy.init_node('spinner')\n"
        "rospy.on_shutdown(lambda: open('bye.txt', 'w').write('hooked'))\n"
        "rospy.spin()\n"
    )
    reply, node = run_script(launcher, code, "spinner")
    try:
        assert isinstance(reply, Yield) and reply.wake_at_s is None  # spin: wake on messages
        exited = node.shutdown("finished: duration reached")
        assert exited.outcome is Outcome.SHUTDOWN
        assert {a.name: a.data for a in exited.artifacts} == {"bye.txt": b"hooked"}
    finally:
        node.close()


def test_driving_a_finished_node_is_a_usage_error(launcher):
    reply, node = run_script(launcher, "x = 1\n")
    try:
        assert isinstance(reply, Exited)
        with pytest.raises(NodeUsageError, match="cannot go from exited to running"):
            node.wake(0.1, [])
        assert node.shutdown("again") is reply  # idempotent
    finally:
        node.close()


def test_without_bubblewrap_the_launcher_refuses(monkeypatch):
    monkeypatch.setenv("PATH", "/nonexistent")
    with pytest.raises(SandboxUnavailable, match="--unsafe-no-sandbox"):
        Launcher(pool_size=0)


@pytest.mark.slow
def test_unsafe_mode_runs_and_says_danger_every_time(caplog):
    launcher = Launcher(pool_size=0, unsafe_no_sandbox=True)
    try:
        for name in ("first", "second"):
            with caplog.at_level(logging.WARNING, logger="robodojo.sandbox"):
                node = launcher.start(name)
            reply = node.load("def step(obs):\n    return (0.1, 0.0)\n", "u.py", Api.STEP,
                              crowbot_info(name))  # fmt: skip
            assert isinstance(reply, Yield), reply
            node.close()
        dangers = [r.getMessage() for r in caplog.records if DANGER in r.getMessage()]
        assert len(dangers) == 2
    finally:
        launcher.close()


@pytest.mark.parametrize(
    "server_dir",
    [
        "/usr/local/lib/python3.11/site-packages/server",  # pip install . into a system Python
        "/usr/lib/python3/dist-packages/server",  # a Debian package
    ],
)
def test_an_installed_server_under_usr_is_covered(monkeypatch, server_dir):
    """/usr is bound into every sandbox; a server package installed below it must be hidden
    under an empty tmpfs, or student code could read the server (reference solutions too)."""
    from sandbox import bwrap

    monkeypatch.setattr(bwrap, "_installed_server_dir", lambda: server_dir)
    command = bwrap.build_command(3, 1024 * 1024, ["x"])
    covered = [command[i + 1] for i, arg in enumerate(command) if arg == "--tmpfs"]
    assert server_dir in covered


SLOW_FIGURE_AFTER_THE_LOOP = """
import time
import matplotlib.pyplot as plt
from matplotlib.artist import Artist
import rospy

def slow():
    start = time.process_time()
    while time.process_time() - start < 1.5:
        pass

class SlowToDraw(Artist):
    # Stands in for a large figure: rendering takes longer than the 1 s step budget.
    def draw(self, renderer):
        slow()

rospy.init_node("plotter")
for _ in range(3):
    rospy.sleep(0.1)
fig = plt.figure()
fig.add_artist(SlowToDraw())
fig.savefig("slow.png")
rospy.sleep(0.1)
"""


@pytest.fixture(scope="module", params=["warm", "cold"])
def drawing_launcher(request):
    """Short steps, and an end budget that 1.5 s of CPU fits even on a loaded machine. A warm
    node has matplotlib imported before the student's code; a cold one imports it then."""
    limits = dataclasses.replace(TEST_LIMITS, shutdown_budget_s=30.0)
    launcher = Launcher(limits=limits, pool_size=1 if request.param == "warm" else 0)
    deadline = time.monotonic() + 60.0
    while request.param == "warm" and launcher.warm_count < 1:
        assert time.monotonic() < deadline, "the warm pool did not fill within 60 s"
        time.sleep(0.05)
    yield launcher
    launcher.close()


@pytest.mark.slow
def test_saving_a_figure_gets_the_end_budget_not_the_step_budget(drawing_launcher):
    launcher = drawing_launcher
    assert launcher.limits.step_budget_s < 1.5 < launcher.limits.shutdown_budget_s
    reply, node = run_script(launcher, SLOW_FIGURE_AFTER_THE_LOOP, "plotter")
    try:
        for k in range(1, 4):
            assert isinstance(reply, Yield), reply
            reply = node.wake(0.1 * k, [])
        assert isinstance(reply, Yield), reply  # the figure was saved; the node slept again
        reply = node.wake(0.4, [])
        if isinstance(reply, Finishing):
            reply = node.poll_finished(timeout_s=20.0)
        assert isinstance(reply, Exited) and reply.outcome is Outcome.FINISHED, reply
        assert [a.name for a in reply.artifacts] == ["slow.png"]
    finally:
        node.close()


@pytest.mark.slow
def test_a_computation_that_is_not_a_figure_still_has_the_step_budget(drawing_launcher):
    code = SLOW_FIGURE_AFTER_THE_LOOP.replace('fig.savefig("slow.png")', "slow()")
    reply, node = run_script(drawing_launcher, code, "spinner")
    try:
        for k in range(1, 4):
            reply = node.wake(0.1 * k, [])
        assert isinstance(reply, Exited) and reply.outcome is Outcome.KILLED, reply
        assert "exceeded its 1 s step budget" in reply.reason
    finally:
        node.close()


COLD_NODE_IMPORTS = """
import json
import sys

HEAVY = ["numpy", "scipy", "skfuzzy", "matplotlib", "rclpy"]
before = sorted(name for name in HEAVY if name in sys.modules)
import numpy as np
import scipy.linalg
import skfuzzy as fuzz
import matplotlib.pyplot as plt

membership = fuzz.trimf(np.arange(11), [0, 5, 10])
plt.plot(membership)
plt.savefig("membership.png")
with open("imports.json", "w") as f:
    json.dump({"before": before, "peak": float(membership.max()),
               "det": float(scipy.linalg.det(np.eye(2)))}, f)
"""


def test_a_cold_node_imports_heavy_libraries_only_when_the_code_does():
    """A node started with an empty pool is Ready without numpy, matplotlib, scipy, scikit-fuzzy
    or rclpy; the student's imports load them inside the sealed process, and a saved figure
    comes back as an artifact."""
    launcher = Launcher(limits=TEST_LIMITS, pool_size=0)
    try:
        reply, node = run_script(launcher, COLD_NODE_IMPORTS, "imports")
        node.close()
    finally:
        launcher.close()
    assert isinstance(reply, Exited) and reply.outcome is Outcome.FINISHED, reply
    artifacts = {a.name: a.data for a in reply.artifacts}
    assert artifacts["membership.png"].startswith(b"\x89PNG")
    assert json.loads(artifacts["imports.json"]) == {"before": [], "peak": 1.0, "det": 1.0}


@pytest.mark.parametrize("call", ["exit()", "quit()", "exit(3)"])
def test_exit_and_quit_end_a_script_as_in_plain_python(launcher, call):
    """The runner starts Python without `site` (-S), which would define exit() and quit();
    the bootstrap gives them back, so a student's script can still call them."""
    reply, node = run_script(launcher, f"import rospy\nrospy.init_node('quitter')\n{call}\n")
    node.close()
    assert isinstance(reply, Exited) and reply.outcome is Outcome.FINISHED, reply
    assert reply.reason.startswith("sys.exit(")


IMPORT_IN_A_LATER_STEP = """
def step(obs):
    if obs.time > 0.15:
        import matplotlib.pyplot
        import numpy
        import skfuzzy  # noqa: F401
    return (0.1, 0.0)
"""


def test_a_cold_node_importing_heavy_libraries_mid_run_gets_the_end_budget():
    """A 50 ms step budget is far less than importing matplotlib, numpy and scikit-fuzzy takes;
    the step that starts the import tells the parent and gets the end budget instead."""
    limits = dataclasses.replace(TEST_LIMITS, step_budget_s=0.05, shutdown_budget_s=30.0)
    launcher = Launcher(limits=limits, pool_size=0)
    node = launcher.start("late")
    try:
        reply = node.load(IMPORT_IN_A_LATER_STEP, "late.py", Api.STEP, crowbot_info("late"))
        for k in range(1, 4):
            assert isinstance(reply, Yield), reply
            reply = node.wake(0.1 * k, [])
        assert isinstance(reply, Yield), reply
    finally:
        node.close()
        launcher.close()


PYPLOT_FIRST_USED_IN_A_LATER_STEP = """
import json
import sys

import skfuzzy.control  # imports matplotlib.pyplot for its visualizer, numpy.f2py (scipy)
import matplotlib.pyplot as plt

# A module each of them imports when its code runs.
RAN = {"matplotlib.pyplot": "matplotlib.figure", "numpy.f2py": "numpy.f2py.crackfortran",
       "numpy.testing": "numpy.testing._private.utils"}
ran_at_import = sorted(name for name, sign in RAN.items() if sign in sys.modules)

def step(obs):
    if obs.time > 0.15 and not plt.get_fignums():
        plt.plot([0.0, 1.0])
        plt.savefig("late.png")
        with open("pyplot.json", "w") as f:
            json.dump({"ran_at_import": ran_at_import, "backend": plt.get_backend()}, f)
    return (0.1, 0.0)
"""


def test_a_cold_node_runs_pyplot_only_when_it_is_used():
    """`import skfuzzy.control` imports matplotlib.pyplot, numpy.f2py and numpy.testing, whose
    code runs only when the controller first uses them: a fuzzy controller that never draws
    does not pay for pyplot (~0.25 s). The step that uses pyplot first has its clock stopped
    while it loads (its load takes far more than the 50 ms step budget here), the backend is
    still Agg and the figure comes back."""
    limits = dataclasses.replace(TEST_LIMITS, step_budget_s=0.05, shutdown_budget_s=30.0)
    launcher = Launcher(limits=limits, pool_size=0)
    node = launcher.start("late")
    try:
        info = crowbot_info("late")
        reply = node.load(PYPLOT_FIRST_USED_IN_A_LATER_STEP, "late.py", Api.STEP, info)
        for k in range(1, 4):
            assert isinstance(reply, Yield), reply
            reply = node.wake(0.1 * k, [])
        assert isinstance(reply, Yield), reply
        exited = node.shutdown("finished: duration reached")
    finally:
        node.close()
        launcher.close()
    assert exited.outcome is Outcome.SHUTDOWN and exited.error is None, exited
    artifacts = {a.name: a.data for a in exited.artifacts}
    assert artifacts["late.png"].startswith(b"\x89PNG")
    assert json.loads(artifacts["pyplot.json"]) == {"ran_at_import": [], "backend": "Agg"}


PYPLOT_THEN_A_SPIN = """
import time
import matplotlib.pyplot as plt

def step(obs):
    if obs.time > 0.15:
        plt.figure()  # pyplot loads here: the step's clock stops meanwhile
        start = time.process_time()
        while time.process_time() - start < 1.5:  # then the controller spins
            pass
    return (0.1, 0.0)
"""


def test_the_step_that_loads_pyplot_keeps_its_budget_for_the_rest():
    """The clock stops for the load only: a step that first uses pyplot and then computes for
    longer than its budget is still stopped."""
    limits = dataclasses.replace(TEST_LIMITS, step_budget_s=0.2, shutdown_budget_s=30.0)
    launcher = Launcher(limits=limits, pool_size=0)
    node = launcher.start("spinner")
    try:
        reply = node.load(PYPLOT_THEN_A_SPIN, "spinner.py", Api.STEP, crowbot_info("spinner"))
        for k in range(1, 4):
            reply = node.wake(0.1 * k, []) if isinstance(reply, Yield) else reply
    finally:
        node.close()
        launcher.close()
    assert isinstance(reply, Exited) and reply.outcome is Outcome.KILLED, reply
    assert "exceeded its 0.2 s step budget at t=0.200 s" in reply.reason


def test_the_sandbox_package_is_compiled_before_nodes_read_it(tmp_path, monkeypatch):
    """Nodes see the package read-only and write no bytecode: the launcher writes it first."""
    from sandbox import bwrap

    package = tmp_path / "sandbox"
    (package / "msgs").mkdir(parents=True)
    (package / "host.py").write_text("X = 1\n")
    (package / "msgs" / "core.py").write_text("Y = 2\n")
    monkeypatch.setattr(bwrap, "sandbox_package_dir", lambda: str(package))
    assert bwrap.precompile_package()
    assert list((package / "__pycache__").glob("host.*.pyc"))
    assert list((package / "msgs" / "__pycache__").glob("core.*.pyc"))


def test_an_unknown_message_type_to_build_ahead_fails_at_once_with_a_sentence():
    """A name the warm nodes could not build is the server's mistake: said when the launcher is
    made, not by every pool process failing to start."""
    with pytest.raises(KeyError, match="sensor_msgs/LaserScn"):
        Launcher(limits=TEST_LIMITS, pool_size=0, message_types=["sensor_msgs/LaserScn"])


WARM_STATE = """
import json
import sys
from sandbox.msgs import _core

with open("state.json", "w") as f:
    json.dump({"built": "sensor_msgs/LaserScan" in _core._REGISTRY,
               "rclpy": "rclpy" in sys.modules}, f)
"""


@pytest.mark.slow
def test_a_warm_node_starts_with_its_message_classes_built_and_no_ros2_module():
    launcher = WarmOnlyLauncher(
        limits=TEST_LIMITS, pool_size=1, message_types=["sensor_msgs/LaserScan"]
    )
    try:
        reply, node = run_script(launcher, WARM_STATE, "state")
        node.close()
    finally:
        launcher.close()
    assert isinstance(reply, Exited) and reply.outcome is Outcome.FINISHED, reply
    artifacts = {a.name: a.data for a in reply.artifacts}
    assert json.loads(artifacts["state.json"]) == {"built": True, "rclpy": False}
