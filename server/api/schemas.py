"""Request and response models at the edge of the API: what clients send is checked here, field
by field, before anything else sees it (a 422 names the field)."""

from __future__ import annotations

import re
from typing import Literal

from pydantic import BaseModel, ConfigDict, Field, field_validator

NAME_PATTERN = r"^[A-Za-z][A-Za-z0-9_]{0,39}$"  # a node name, as in a launch file
ID_PATTERN = r"^[A-Za-z0-9_\-]{1,64}$"
EMAIL_PATTERN = r"^[^@\s]+@[^@\s]+\.[^@\s]+$"  # a plausible address; the invite is the proof
HARD_CODE_CAP = 2 * 1024 * 1024  # [chars] a body bigger than any limit setting; checked first


class Strict(BaseModel):
    model_config = ConfigDict(extra="forbid")


class NodeCode(Strict):
    name: str = Field(pattern=NAME_PATTERN, description="node name, as in a launch file")
    code: str = Field(max_length=HARD_CODE_CAP, description="Python source")


class RunCreate(Strict):
    robot: str | None = Field(None, pattern=ID_PATTERN)
    world: str | None = Field(None, pattern=ID_PATTERN)
    exercise: str | None = Field(None, pattern=ID_PATTERN)
    nodes: list[NodeCode] = Field(min_length=1, max_length=8)
    clock: Literal["lockstep", "realtime"] | None = None
    duration: float | None = Field(None, gt=0, le=86400, description="[s] of robot time")
    seed: int | None = Field(None, ge=0, le=2**31 - 1)
    teleop: bool = Field(False, description="drive with the arrow keys (adds the teleop node)")
    hardware: str | None = Field(
        None, pattern=r"^[a-z][a-z0-9_\-]{0,63}$", description="run on this robot of the bench"
    )


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
