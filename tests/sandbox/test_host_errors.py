"""Student errors become readable NodeErrors pointing at the student's own lines."""

from __future__ import annotations

from pathlib import Path

import pytest

from sandbox.msgs.std_msgs import Int32
from sandbox.protocol import Outcome
from tests.sandbox.test_host_harness import Parent, crowbot_info, envelope, run

HEADER = "import rospy\nfrom std_msgs.msg import Int32, Bool\nfrom geometry_msgs.msg import Twist\n"
# Line 4 onwards is the test's own code.


def error_of(code: str, tmp_path: Path, **kwargs: object):
    _, exited = run(HEADER + code, tmp_path, filename="student.py", **kwargs)
    assert exited.outcome is Outcome.ERROR, exited
    assert exited.error is not None
    return exited


def test_zero_division_in_a_callback_shows_only_the_students_frames(tmp_path: Path) -> None:
    code = HEADER + (
        "def on_distance(msg):\n"  # 4
        "    ratio = 100 / msg.data\n"  # 5
        "rospy.init_node('divider')\n"  # 6
        "rospy.Subscriber('Distance', Int32, on_distance)\n"  # 7
        "rate = rospy.Rate(10)\n"  # 8
        "while not rospy.is_shutdown():\n"  # 9
        "    try:\n"  # 10
        "        rate.sleep()\n"  # 11
        "    except Exception:\n"  # 12
        "        pass  # must not hide the callback's error\n"  # 13
    )
    parent = Parent(code, tmp_path, filename="student.py")
    parent.next()
    exited = parent.wake(0.1, [envelope("Distance", Int32(0))])
    assert exited.outcome is Outcome.ERROR
    error = exited.error
    assert (error.type, error.message, error.filename, error.line) == (
        "ZeroDivisionError",
        "division by zero",
        "student.py",
        5,
    )
    assert exited.reason == "ZeroDivisionError: division by zero (line 5)"
    assert 'File "student.py", line 5, in on_distance' in error.traceback
    assert "ratio = 100 / msg.data" in error.traceback
    assert "sandbox" not in error.traceback and "runtime" not in error.traceback
    assert error.traceback.count('File "') == 1


def test_error_inside_a_library_points_at_the_calling_line(tmp_path: Path) -> None:
    # numpy's zeros is C code: the student's line is the last frame there is.
    exited = error_of("import numpy as np\n\nx = np.zeros('x')\n", tmp_path)
    assert exited.error.type == "TypeError" and exited.error.line == 6
    assert exited.error.traceback.splitlines() == [
        "Traceback (most recent call last):",
        '  File "student.py", line 6, in <module>',
        "    x = np.zeros('x')",
        "        ^^^^^^^^^^^^^",
        "TypeError: 'str' object cannot be interpreted as an integer",
    ]


def test_error_inside_python_library_code_names_the_library(tmp_path: Path) -> None:
    exited = error_of("import json\ndef load():\n    return json.loads('{')\nload()\n", tmp_path)
    lines = exited.error.traceback.splitlines()
    assert exited.error.type == "JSONDecodeError" and exited.error.line == 6
    assert [line for line in lines if line.startswith("  File")] == [
        '  File "student.py", line 7, in <module>',
        '  File "student.py", line 6, in load',
    ]
    assert lines[-2:] == [
        "  (raised inside json)",
        "json.decoder.JSONDecodeError: Expecting property name enclosed in double quotes: "
        "line 1 column 2 (char 1)",
    ]


def test_syntax_error_gives_line_and_caret(tmp_path: Path) -> None:
    exited = error_of("x = (1,\ny = 2\nwhile True print(x)\n", tmp_path)
    assert exited.error.type == "SyntaxError"
    assert exited.error.filename == "student.py"
    assert exited.error.line == 4
    assert 'File "student.py", line 4' in exited.error.traceback
    assert "^" in exited.error.traceback


def test_missing_module_reads_like_python(tmp_path: Path) -> None:
    exited = error_of("\n\nimport foo\n", tmp_path)
    assert exited.reason == "ModuleNotFoundError: No module named 'foo' (line 6)"


@pytest.mark.parametrize(
    ("code", "message"),
    [
        (
            "pub = rospy.Publisher('Control', Int32, queue_size=1)\n",
            "topic 'Control' carries geometry_msgs/Twist, not std_msgs/Int32",
        ),
        (
            "rospy.Subscriber('Distance', Bool, print)\n",
            "topic 'Distance' carries std_msgs/Int32, not std_msgs/Bool",
        ),
        (
            "rospy.Publisher('/Distance', Int32, queue_size=1)\n",
            "'Distance' is published by the robot; command topics are Control, Leds, Buzzer",
        ),
        (
            "rospy.Publisher('Control', Twist, queue_size=1).publish(Int32(3))\n",
            "publish() on 'Control' expects geometry_msgs/Twist, got std_msgs/Int32",
        ),
        (
            "pub = rospy.Publisher('Buzzer', Bool, queue_size=1)\n"
            "rospy.signal_shutdown('finished')\npub.publish(True)\n",
            "publish() on 'Buzzer' after shutdown (finished)",
        ),
    ],
)
def test_topic_misuse_fails_with_a_sentence(tmp_path: Path, code: str, message: str) -> None:
    exited = error_of("rospy.init_node('n')\n" + code, tmp_path)
    assert exited.error.message == message
    assert exited.error.type.startswith("ROS")
    assert exited.error.line == 4 + code.count("\n")


def test_a_misspelt_robot_topic_is_refused_where_new_topics_are(tmp_path: Path) -> None:
    exited = error_of(
        "rospy.init_node('n')\nrospy.Publisher('Contrl', Twist, queue_size=1)\n",
        tmp_path,
        info=crowbot_info(allow_new_topics=False),
    )
    assert exited.error.message == (
        "unknown topic 'Contrl' on robot crowbot; did you mean 'Control'? its topics are "
        "Distance, Button, Light, Line (sensors) and Control, Leds, Buzzer (commands)"
    )


def test_new_topics_are_allowed_as_in_rospy(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    _, exited = run(
        HEADER + "rospy.init_node('n')\nrospy.Publisher('chatter', Int32).publish(1)\n"
        "rospy.Subscriber('other', Int32, print)\nrospy.Publisher('Contrl', Twist)\n",
        tmp_path,
    )
    assert exited.outcome is Outcome.FINISHED, exited.error
    out = capsys.readouterr().out
    assert "[WARN]" in out and "'Contrl' is not one of the topics of robot crowbot; did you" in out
    assert "chatter" not in out  # no near miss, no warning
    assert exited.published[0].topic == "chatter"


def test_an_error_in_a_shutdown_hook_is_logged_with_its_line(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    _, exited = run(
        HEADER + "rospy.init_node('n')\nrospy.on_shutdown(lambda: [][1])\n",
        tmp_path,
        filename="student.py",
    )
    assert exited.outcome is Outcome.FINISHED  # as rospy: hook errors are printed, not raised
    captured = capsys.readouterr()
    assert "error in shutdown hook" in captured.out and "IndexError" in captured.out
    assert 'File "student.py", line 5' in captured.err


def test_sleeping_inside_a_callback_is_refused(tmp_path: Path) -> None:
    code = (
        HEADER + "rospy.init_node('n')\n"
        "rospy.Subscriber('Distance', Int32, lambda m: rospy.sleep(1))\nrospy.spin()\n"
    )
    parent = Parent(code, tmp_path)
    parent.next()
    exited = parent.wake(0.05, [envelope("Distance", Int32(1))])
    assert exited.outcome is Outcome.ERROR
    assert "sleep in the main loop" in exited.error.message and exited.error.line == 5
