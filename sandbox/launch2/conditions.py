"""launch.conditions: whether an action is visited (launch/conditions/*.py). A condition's
text, once performed, is stripped and lower-cased and must be true, false, 1 or 0."""

from __future__ import annotations

from typing import Any

from sandbox.launch2.context import LaunchContext
from sandbox.launch2.errors import InvalidConditionExpressionError, caller_site
from sandbox.launch2.substitutions import normalize, perform

VALID_TRUE_EXPRESSIONS = ["true", "1"]
VALID_FALSE_EXPRESSIONS = ["false", "0"]


class Condition:
    """launch.Condition: `evaluate(context) -> bool`."""

    def __init__(self) -> None:
        self.site = caller_site()

    def evaluate(self, context: LaunchContext) -> bool:
        raise NotImplementedError


def evaluate_condition_expression(context: LaunchContext, expression: list, site: Any) -> bool:
    text = perform(context, expression).strip().lower()
    if text in VALID_TRUE_EXPRESSIONS:
        return True
    if text in VALID_FALSE_EXPRESSIONS:
        return False
    raise InvalidConditionExpressionError(
        f"a condition's value is '{text}'; it must be one of true, false, 1 or 0 "
        "(a launch argument used in IfCondition/UnlessCondition, e.g. use_x:=true)",
        site,
    )


class IfCondition(Condition):
    def __init__(self, predicate_expression: Any) -> None:
        super().__init__()
        self.expression = normalize(predicate_expression, "IfCondition's expression")

    def evaluate(self, context: LaunchContext) -> bool:
        return evaluate_condition_expression(context, self.expression, self.site)


class UnlessCondition(IfCondition):
    def evaluate(self, context: LaunchContext) -> bool:
        return not evaluate_condition_expression(context, self.expression, self.site)


class LaunchConfigurationEquals(Condition):
    """True when the configuration's value equals `expected_value` (None: not set)."""

    def __init__(self, launch_configuration_name: str, expected_value: Any) -> None:
        super().__init__()
        self.name = launch_configuration_name
        self.expected = None if expected_value is None else normalize(expected_value)

    def evaluate(self, context: LaunchContext) -> bool:
        expected = None if self.expected is None else perform(context, self.expected)
        return context.launch_configurations.get(self.name) == expected


class LaunchConfigurationNotEquals(LaunchConfigurationEquals):
    def evaluate(self, context: LaunchContext) -> bool:
        return not super().evaluate(context)
