"""Request and response models at the edge of the API: what clients send is checked here, field
by field, before anything else sees it (a 422 names the field)."""

from __future__ import annotations

import json
import re
from typing import Annotated, Literal

from pydantic import (
    AfterValidator,
    BaseModel,
    ConfigDict,
    Field,
    JsonValue,
    ValidationInfo,
    field_validator,
)

NAME_PATTERN = r"^[A-Za-z][A-Za-z0-9_]{0,39}$"  # a node name, as in a launch file
ID_PATTERN = r"^[A-Za-z0-9_\-]{1,64}$"
EMAIL_PATTERN = r"^[^@\s]+@[^@\s]+\.[^@\s]+$"  # a plausible address; the invite is the proof
HARD_CODE_CAP = 2 * 1024 * 1024  # [chars] a body bigger than any limit setting; checked first
# A ROS graph name as rosgraph.names.is_legal_name takes it (wiki.ros.org/Names): global "/a/b",
# relative "a/b" or private "~a"; each part starts with a letter.
ROS_NAME_PATTERN = r"^[~/]?[A-Za-z][A-Za-z0-9_]*(/[A-Za-z][A-Za-z0-9_]*)*$"
NAMESPACE_PATTERN = r"^/?([A-Za-z][A-Za-z0-9_]*(/[A-Za-z][A-Za-z0-9_]*)*/?)?$"  # no "~"
MAX_PARAMS_CHARS = 64 * 1024  # [chars] of JSON: a node's parameters are settings, not data


def _ros_name(name: str) -> str:
    if not re.match(ROS_NAME_PATTERN, name):
        raise ValueError(
            f"'{name}' is not a ROS name: parts start with a letter, then letters, digits or _, "
            "joined by '/', with an optional leading '/' (global) or '~' (private)"
        )
    return name


def _namespace(name: str) -> str:
    if not re.match(NAMESPACE_PATTERN, name):
        raise ValueError(f"'{name}' is not a ROS namespace: e.g. 'robot1' or '/robot1/arm'")
    return name


def _argument(text: str) -> str:
    if re.search(r"[\x00-\x1f]", text):
        raise ValueError("an argument is one line of text without control characters")
    return text


def _arg_name(name: str) -> str:
    if not re.match(r"^[A-Za-z_][A-Za-z0-9_\-]{0,63}$", name):
        raise ValueError(
            f"'{name}' is not a launch argument name: letters, digits, _ and - (at most 64)"
        )
    return name


RosName = Annotated[str, Field(max_length=200), AfterValidator(_ros_name)]
Argument = Annotated[str, Field(max_length=256), AfterValidator(_argument)]


class Strict(BaseModel):
    model_config = ConfigDict(extra="forbid")


class NodeCode(Strict):
    name: str = Field(pattern=NAME_PATTERN, description="node name, as in a launch file")
    code: str = Field(max_length=HARD_CODE_CAP, description="Python source")
    params: dict[RosName, JsonValue] = Field(
        default_factory=dict,
        max_length=256,
        description='parameters as <param> gives them: "~speed" private, "/max" global, '
        '"gain" in the node\'s namespace; values are JSON (numbers, text, lists, objects)',
    )
    remaps: dict[RosName, RosName] = Field(
        default_factory=dict, max_length=64, description='{"from": "to"}, as <remap from to>'
    )
    args: list[Argument] = Field(
        default_factory=list,
        max_length=32,
        description='rosrun arguments after the file: "_speed:=0.3", "scan:=base_scan", "5"',
    )
    namespace: Annotated[str, AfterValidator(_namespace)] = Field(
        "/", max_length=200, description='as <node ns>, e.g. "robot1"'
    )

    @field_validator("params")
    @classmethod
    def _settings_sized(cls, params: dict[str, JsonValue]) -> dict[str, JsonValue]:
        if _has_null(params):
            raise ValueError(
                "a parameter cannot be null (the ROS parameter server has no null); leave it "
                "out or give a value"
            )
        size = len(json.dumps(params))
        if size > MAX_PARAMS_CHARS:
            raise ValueError(
                f"the parameters are {size} characters of JSON; the limit is {MAX_PARAMS_CHARS}:"
                " put large data in a workspace file (CSV, YAML) and read it in the node"
            )
        return params


class LaunchRun(Strict):
    file: str = Field(
        min_length=1, max_length=200, description="a launch file of the workspace, e.g. two.launch"
    )
    args: dict[Annotated[str, AfterValidator(_arg_name)], Argument] = Field(
        default_factory=dict, max_length=64, description="<arg> values, as name:=value"
    )


class RunCreate(Strict):
    robot: str | None = Field(None, pattern=ID_PATTERN)
    world: str | None = Field(None, pattern=ID_PATTERN)
    exercise: str | None = Field(None, pattern=ID_PATTERN)
    workspace: str | None = Field(
        None,
        pattern=ID_PATTERN,
        description="your workspace (an exercise or robot id) whose data files every node gets "
        "in its working directory; with launch, the default is the exercise or robot",
    )
    launch: LaunchRun | None = Field(
        None, description="start the nodes of a launch file of your workspace instead of nodes"
    )
    # After launch: its validator sees whether a launch file was given.
    nodes: list[NodeCode] | None = Field(None, min_length=1, max_length=8, validate_default=True)
    clock: Literal["lockstep", "realtime"] | None = None
    duration: float | None = Field(None, gt=0, le=86400, description="[s] of robot time")
    seed: int | None = Field(None, ge=0, le=2**31 - 1)
    case: int | None = Field(
        None,
        ge=0,
        le=63,
        description="an exercise's grading case (0, 1, ...): its seed and start pose, as "
        "`robodojo check` runs them; GET /api/exercises/{id}/check sums up a set of them",
    )
    teleop: bool = Field(False, description="drive with the arrow keys (adds the teleop node)")
    hardware: str | None = Field(
        None, pattern=r"^[a-z][a-z0-9_\-]{0,63}$", description="run on this robot of the bench"
    )

    @field_validator("nodes")
    @classmethod
    def _nodes_or_launch(cls, nodes: list[NodeCode] | None, info: ValidationInfo):
        launch = info.data.get("launch")
        if nodes is None and launch is None:
            raise ValueError("give the nodes to run ([{name, code}]) or a launch file ({file})")
        if nodes is not None and launch is not None:
            raise ValueError(
                "give nodes or a launch file, not both: the launch file names its nodes"
            )
        return nodes


def _has_null(value: JsonValue) -> bool:
    if value is None:
        return True
    if isinstance(value, dict):
        return any(_has_null(v) for v in value.values())
    if isinstance(value, list):
        return any(_has_null(v) for v in value)
    return False


class RunCommand(Strict):
    reason: str | None = Field(None, max_length=200)


class CodeSave(Strict):
    code: str = Field(max_length=HARD_CODE_CAP)


class SessionCreate(Strict):
    token: str = Field(min_length=1, max_length=200)


class UserCreate(Strict):
    name: str = Field(min_length=1, max_length=120)
    role: Literal["student", "instructor"] = "student"
    email: str | None = Field(None, max_length=254)
    course: str | None = Field(None, pattern=ID_PATTERN, description="enrol in this course id")

    @field_validator("email")
    @classmethod
    def _plausible_email(cls, value: str | None) -> str | None:
        if value is not None and not re.match(EMAIL_PATTERN, value):
            raise ValueError(f"'{value}' does not look like an email address (name@domain)")
        return value


class UserUpdate(Strict):
    disabled: bool | None = None
    name: str | None = Field(None, min_length=1, max_length=120)
